//! `sim-host hmi`: the live terminal HMI ([`sim_host::hmi`] holds the model and the
//! sources, [`super::render::hmi`] draws it). This is the terminal loop only: read keys,
//! advance the source by the wall-clock time, draw; or, when stdout is not a terminal,
//! print one status line every few seconds of the source's time.

use super::diagnose::ReplayArgs;
use super::render::hmi::render;
use anyhow::Context;
use clap::{Args, ValueEnum};
use ratatui::crossterm::event::{self, Event, KeyCode, KeyEventKind, KeyModifiers};
use sim_host::hmi::live::LiveSim;
use sim_host::hmi::log_replay::LogReplay;
use sim_host::hmi::status_line::StdinStatus;
use sim_host::hmi::{key_help, HmiState, Key, Source, Speed};
use std::io::{IsTerminal, Write};
use std::path::PathBuf;
use std::time::{Duration, Instant};

/// Time between two frames.
const FRAME: Duration = Duration::from_millis(50);

/// Arguments of `hmi`.
#[derive(Debug, Args)]
#[command(
    about = "Live terminal HMI: residual lamps, bands, fault candidates, strip chart (simulation, log replay, firmware)",
    long_about = "The paper's HMI (its Figures 11 and 12) in the terminal: the four residual lamps \
r1..r4 and the fault lamp, each residual as a bar against its threshold band (learned or fixed) with \
its value, the fault candidates with their probabilities (and the phase of a winding asymmetry), \
speed, I_qs, i_ds, V_qs and the supply frequency, the monitor's state (transient, commissioning \
with progress, healthy, fault), the data-quality warnings, and a strip chart of the residuals over \
the last 10 s.\n\nThree sources:\n  sim-host hmi\n      live simulation of the demo's \
motor (3 hp reference motor, 12-bit noisy sensors); keys switch each Table 1 fault on and off (the \
paper's Enable_F_* switches), step the load and the supply, and start commissioning\n  \
sim-host hmi LOG --params P.toml\n      replay a log through the data-quality stage and the core, as \
diagnose does, at --speed 1x, 10x or max, with pause and seek\n  cargo fw-run | sim-host hmi \
--stdin\n      the firmware's defmt status lines\n\nA log replay takes diagnose's options, checked by the \
same code with the same messages: --commission START:END, --load unknown|viscous, --baseline \
HEALTHY... (healthy logs of the same motor: the verdict's winding is judged against them), --group \
NAME (TDMS), --angle, --residuals, --parallel-paths, --turn-calibration; a commissioning window \
the log does not complete is shown, not refused. Example:\n  sim-host hmi today.csv --params \
motor.toml --baseline healthy_runs/ --load viscous --speed 10x\n\nA first session: start it, wait for 'healthy', press \
c (commissioning, 3 s), then 6 (load friction Bl +50 %): r2..r4 light and the candidates b/bl \
appear; 6 again clears it.\n\nWhen stdout is not a terminal (or with --plain) one status line is \
printed every --every seconds of the source's time instead. Needs an 80x24 terminal at least.",
    after_help = key_help()
)]
pub struct HmiArgs {
    /// Log to replay (any format the log reader takes); without it, the live simulation.
    #[arg(conflicts_with = "stdin")]
    pub log: Option<PathBuf>,
    /// Motor parameter file (TOML, docs/design.md): the log's motor, or the motor to simulate
    /// live (default: the demo's 3 hp reference motor).
    #[arg(long)]
    pub params: Option<PathBuf>,
    /// Read the firmware's defmt status lines from standard input (`cargo fw-run |
    /// sim-host hmi --stdin`).
    #[arg(long)]
    pub stdin: bool,
    /// Replay speed.
    #[arg(long, value_enum, default_value_t = SpeedArg::X1)]
    pub speed: SpeedArg,
    /// A log replay's options, diagnose's own (the same request, checked the same way).
    #[command(flatten, next_help_heading = "Log replay (as diagnose)")]
    pub replay: ReplayArgs,
    /// Plain text (one status line every --every seconds) even on a terminal.
    #[arg(long)]
    pub plain: bool,
    /// Plain text: seconds of the source's time between two status lines.
    #[arg(long, default_value_t = 1.0, value_parser = parse_every)]
    pub every: f64,
    /// Stop after this many seconds of wall-clock time (scripts, tests).
    #[arg(long, value_name = "SECONDS", allow_negative_numbers = true, value_parser = super::args::parse_positive_seconds)]
    pub duration: Option<f64>,
}

fn parse_every(s: &str) -> Result<f64, String> {
    match s.trim().parse::<f64>() {
        Ok(x) if x.is_finite() && x >= 0.01 => Ok(x),
        _ => Err(format!("'{s}' is not a number of seconds >= 0.01")),
    }
}

/// Replay speed on the command line.
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum SpeedArg {
    /// Real time.
    #[value(name = "1x")]
    X1,
    /// Ten times real time.
    #[value(name = "10x")]
    X10,
    /// As fast as the log is analysed.
    Max,
}

impl From<SpeedArg> for Speed {
    fn from(s: SpeedArg) -> Self {
        match s {
            SpeedArg::X1 => Speed::X1,
            SpeedArg::X10 => Speed::X10,
            SpeedArg::Max => Speed::Max,
        }
    }
}

/// Runs `hmi`.
///
/// # Errors
/// A bad parameter file or log (one line naming it), a terminal that cannot be set up, or
/// stdout that cannot be written.
pub fn run(args: &HmiArgs) -> anyhow::Result<()> {
    let plain_text = args.plain || !std::io::stdout().is_terminal();
    let mut source: Box<dyn Source> = if args.stdin && plain_text {
        Box::new(StdinStatus::stdin().one_at_a_time())
    } else if args.stdin {
        Box::new(StdinStatus::stdin())
    } else if let Some(log) = &args.log {
        let params = args
            .params
            .as_deref()
            .context("a log replay needs --params P.toml (the log's motor)")?;
        // diagnose's request, resolved as diagnose resolves it (the parameter file with its
        // [columns] mapping, the TDMS group, the baseline's healthy reference); a window
        // not learned is shown (the fixed thresholds, the verdict withheld), not refused.
        let mut req = args.replay.request()?;
        req.options.allow_incomplete = true;
        let plan = monitor_api::plan_diagnose(
            monitor_api::ParamsSource::Path(params),
            &monitor_api::LogSource::from(log.as_path()),
            &req,
        )?;
        // Plain text at `max` walks the log at 1x on a clock of its own that does not wait
        // (a status line every --every seconds of the log, none skipped).
        let speed = if plain_text && args.speed == SpeedArg::Max {
            Speed::X1
        } else {
            args.speed.into()
        };
        // A log that cannot be opened is said as diagnose says it (its fields as flags).
        let replay = LogReplay::start_with(plan.params, log, plan.open, plan.options, speed)
            .map_err(|e| match e {
                monitor_api::replay::ReplayError::Log(e) => anyhow::Error::new(e),
                e => anyhow::Error::new(e),
            })?;
        Box::new(replay)
    } else if let Some(p) = &args.params {
        let (p, _) = monitor_api::files::load_params(p)?;
        Box::new(LiveSim::new(
            p,
            monitor_studies::fault_signatures::Protocol::default().sample_rate_hz,
        )?)
    } else {
        Box::new(LiveSim::demo_motor()?)
    };
    let deadline = args
        .duration
        .map(|d| Instant::now() + Duration::from_secs_f64(d.max(0.0)));
    if plain_text {
        let fast = args.stdin || (args.log.is_some() && args.speed == SpeedArg::Max);
        plain(source.as_mut(), args.every, fast, deadline)
    } else {
        screen(source.as_mut(), deadline)
    }
}

/// The terminal back as it was, on every way out of [`screen`] (the panic hook of
/// `ratatui::try_init` covers a panic).
struct Restore;

impl Drop for Restore {
    fn drop(&mut self) {
        let _ = ratatui::try_restore();
        let _ = ratatui::crossterm::execute!(std::io::stdout(), ratatui::crossterm::cursor::Show);
    }
}

/// The full-screen HMI.
fn screen(source: &mut dyn Source, deadline: Option<Instant>) -> anyhow::Result<()> {
    // SIGTERM (and SIGINT from outside: in raw mode Ctrl-C is a key) ends the loop cleanly.
    let signals = super::out::Interruption::catch()?;
    let mut terminal = ratatui::try_init().context("cannot set up the terminal")?;
    let _restore = Restore;
    let mut state = source.initial_state();
    let mut last = Instant::now();
    while !state.quit && !signals.caught() && deadline.is_none_or(|d| Instant::now() < d) {
        let now = Instant::now();
        source.advance((now - last).as_secs_f64(), &mut state);
        last = now;
        terminal.draw(|f| render(f, &state))?;
        let until = now + FRAME;
        while let Some(wait) = until.checked_duration_since(Instant::now()) {
            if !event::poll(wait)? {
                break;
            }
            if let Event::Key(k) = event::read()? {
                if k.kind == KeyEventKind::Release {
                    continue;
                }
                if k.modifiers.contains(KeyModifiers::CONTROL) && k.code == KeyCode::Char('c') {
                    state.quit = true;
                    break;
                }
                if let Some(key) = map_key(k.code) {
                    source.key(key, &mut state);
                }
            }
        }
    }
    Ok(())
}

/// The HMI's key for a terminal key.
fn map_key(code: KeyCode) -> Option<Key> {
    Some(match code {
        KeyCode::Char(c) => Key::Char(c),
        KeyCode::Left => Key::Left,
        KeyCode::Right => Key::Right,
        KeyCode::PageUp => Key::PageUp,
        KeyCode::PageDown => Key::PageDown,
        KeyCode::Home => Key::Home,
        KeyCode::End => Key::End,
        KeyCode::Esc => Key::Esc,
        _ => return None,
    })
}

/// Plain text: a status line every `every` seconds of the source's time, the events and
/// warnings as they come; ends with the source (standard input closed, the log played to
/// its end) or at the deadline. `fast`: the source's clock advances `every` a turn without
/// waiting for the wall clock (a replay at `max`), waiting only for the analysis.
fn plain(
    source: &mut dyn Source,
    every: f64,
    fast: bool,
    deadline: Option<Instant>,
) -> anyhow::Result<()> {
    let mut out = super::out::stdout();
    let mut state = source.initial_state();
    writeln!(out, "{}", state.title)?;
    let (mut printed, mut warnings) = (0u64, 0usize);
    let mut next_t = 0.0;
    let mut last = Instant::now();
    loop {
        let now = Instant::now();
        let shown = state.latest.as_ref().map(|s| s.t_s);
        let step = if fast {
            every
        } else {
            (now - last).as_secs_f64()
        };
        source.advance(step, &mut state);
        last = now;
        let moved = state.latest.as_ref().map(|s| s.t_s) != shown;
        if let Some(s) = &state.latest {
            if s.t_s + 1e-9 >= next_t {
                next_t = (s.t_s / every).floor() * every + every;
                writeln!(out, "{}", state.status_line())?;
            }
        }
        for w in state.warnings.iter().skip(warnings) {
            writeln!(out, "! {w}")?;
        }
        warnings = state.warnings.len();
        let new = usize::try_from(state.events_total - printed).unwrap_or(usize::MAX);
        for e in state
            .events
            .iter()
            .skip(state.events.len().saturating_sub(new))
        {
            writeln!(out, "> {e}")?;
        }
        printed = state.events_total;
        out.flush()?;
        if finished(&state) || deadline.is_some_and(|d| Instant::now() >= d) {
            return Ok(());
        }
        if !(fast && moved) {
            std::thread::sleep(FRAME);
        }
    }
}

/// The source has nothing more to show.
fn finished(state: &HmiState) -> bool {
    use sim_host::hmi::Controls;
    match &state.controls {
        Controls::Live(_) => false,
        Controls::Replay(p) => p.done && (p.position_s >= p.analysed_s || p.paused),
        Controls::Stdin(s) => s.ended,
    }
}
