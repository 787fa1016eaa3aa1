//! The live HMI's model (`sim-host hmi`, the paper's Figures 11 and 12): what the screen
//! shows ([`HmiState`], a sequence of monitor readings [`Snapshot`] and the source's
//! controls), and the three sources that update it ([`Source`]):
//!
//! - [`live::LiveSim`]: the demo's motor simulated as it is watched; keys switch each
//!   Table 1 fault on and off (the paper's `Enable_F_*` switches), step the load and the
//!   supply, and start commissioning;
//! - [`log_replay::LogReplay`]: a log replayed through the data-quality stage and the core
//!   ([`monitor_api::replay::diagnose_file_observed`], the one reader: every format the reader
//!   takes), played back at 1x, 10x or as fast as it is analysed, with pause and seek;
//! - [`status_line::StdinStatus`]: the firmware's defmt status lines
//!   (`cargo fw-run | sim-host hmi --stdin`), parsed by [`status_line::parse`].
//!
//! The keys are one table, [`keys`] (the screen's footer, `--help` and docs/hmi.md use it).
//! Drawing is the binary's (`src/cli/render/hmi.rs`): a pure function of [`HmiState`]; the
//! smallest terminal it fits in, and the note drawn in a smaller one, are [`size`]'s.

mod keys;
pub mod live;
pub mod log_replay;
pub mod size;
pub mod status_line;

pub use keys::{
    fault_key, fault_of_key, key_help, keys, Key, KeyBinding, KeyScope, FAULT_KEY_CHARS,
};

use monitor_api::files::ParamFile;
use monitor_api::replay::{FaultCandidate, IsolationName, IsolationReport, Replay};
use monitor_core::sequence::min_shorted_fraction;
use monitor_core::verdict::Verdict;
use monitor_core::{Fault, IsolationState, MonitorOutput, Phase};
use monitor_studies::demo::MonitorState;
use std::collections::VecDeque;

/// Seconds of residuals the strip chart shows.
pub const HISTORY_S: f64 = 10.0;
/// Interval between two readings of the simulated and replayed monitor [s] (the firmware
/// prints one every [`status_line::STATUS_PERIOD_S`]).
pub const SNAPSHOT_EVERY_S: f64 = 0.05;
/// Messages kept for the screen's event list.
const EVENTS_KEPT: usize = 4;

/// A winding asymmetry as the monitor's negative-sequence analysis names it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Asymmetry {
    /// The phase ([`monitor_core::sequence::suspect_phase`], as `diagnose` names it).
    pub phase: Phase,
    /// |I2|/|I1|.
    pub ratio: f32,
    /// The least fraction of that phase's turns shorted (a bolted short,
    /// [`monitor_core::sequence::min_shorted_fraction`]), when the motor is known.
    pub min_shorted_fraction: Option<f32>,
}

/// One reading of the monitor, from any source. Quantities a source does not give are
/// `None`.
#[derive(Debug, Clone, PartialEq)]
pub struct Snapshot {
    /// Time [s] (simulated, log or firmware time).
    pub t_s: f64,
    /// Normalised residuals r1..r4.
    pub residuals: [f32; 4],
    /// Residual lamps r1..r4.
    pub lamps: [bool; 4],
    /// The fault lamp: lit for the decision table's FAULT ([`Snapshot::call`]) where the
    /// source makes the call.
    pub fault_lamp: bool,
    /// The decision table's verdict at this moment (`monitor_core::verdict`): a replay's
    /// panel ([`monitor_api::replay::Replay::panel`]), the board's `call=`; `None` where the source
    /// gives none (the FAULT lamp is then the lamps' detection).
    pub call: Option<Verdict>,
    /// Threshold band of each residual in force, (centre, half-width).
    pub bands: Option<[(f32, f32); 4]>,
    /// Learned thresholds are in force (else the fixed ones).
    pub learned: bool,
    /// Fault candidates with their probabilities, most probable first.
    pub candidates: Vec<(Fault, f32)>,
    /// Sensors flagged from impossible readings (`current_sensor` ...).
    pub sensor_faults: Vec<Fault>,
    /// A winding asymmetry, when the analysis names a phase.
    pub asymmetry: Option<Asymmetry>,
    /// Shaft speed [rpm].
    pub speed_rpm: f32,
    /// Torque-producing current I_qs [A].
    pub iqs_a: Option<f32>,
    /// Flux-producing current i_ds [A].
    pub ids_a: Option<f32>,
    /// Voltage V_qs [V].
    pub vqs_v: Option<f32>,
    /// Supply (frame) frequency [Hz].
    pub supply_hz: Option<f32>,
    /// What the monitor is doing (the demo's states).
    pub state: MonitorState,
    /// What the isolation concludes (the fault named with its size): the live simulation
    /// and a log replay run it, the firmware's status line carries it (`iso=`).
    pub isolation: Option<IsolationView>,
}

/// The isolation's conclusion as the screen shows it ([`monitor_api::replay::IsolationReport`]).
#[derive(Debug, Clone, PartialEq)]
pub struct IsolationView {
    /// The conclusion.
    pub state: IsolationState,
    /// The fault named (probability >= 0.5) or the friction class `b/bl`.
    pub named: Option<IsolationName>,
    /// Its estimated relative change (0.48 = +48 %; for `b/bl` Bl's).
    pub change: Option<f32>,
    /// The candidates listed, most probable first: for an unknown fault its nearest three.
    pub candidates: Vec<FaultCandidate>,
    /// The winding temperature rise since commissioning the isolation tracks [K]
    /// (`Isolator::winding_rise_k`), when known.
    pub winding_rise_k: Option<f32>,
}

impl IsolationView {
    /// From a replay's isolation report and candidates.
    pub fn new(report: &IsolationReport, candidates: &[FaultCandidate]) -> Self {
        IsolationView {
            state: report.state,
            named: report.named,
            change: report.named_change,
            candidates: candidates.to_vec(),
            winding_rise_k: report.winding_rise_k,
        }
    }

    /// What `replay`'s isolation concludes now.
    pub fn of_replay(replay: &Replay) -> Self {
        let (report, candidates) = replay.isolation_now();
        Self::new(&report, &candidates)
    }

    /// One line: `rr +48 %`, `unknown, nearest rr, ls, lr`, `rr / speed_sensor, not
    /// alone`, `no deviation` or `not judged`; followed by `; windings +54 K (heating)`
    /// once the tracked rise reaches [`monitor_core::isolation::WARMING_K`].
    pub fn text(&self) -> String {
        let rise = self
            .winding_rise_k
            .filter(|r| r.abs() >= monitor_core::isolation::WARMING_K)
            .map(|r| format!("; windings {r:+.0} K (heating)"))
            .unwrap_or_default();
        format!("{}{rise}", self.conclusion())
    }

    /// [`IsolationView::text`] without the winding rise.
    fn conclusion(&self) -> String {
        let sized = |n: IsolationName, x: Option<f32>| {
            let n = n.to_string();
            x.map_or(n.clone(), |c| {
                monitor_studies::fault_signatures::size_text(&n, c)
            })
        };
        let names = |n: usize, sep: &str| {
            self.candidates
                .iter()
                .take(n)
                .map(|c| c.fault.name())
                .collect::<Vec<_>>()
                .join(sep)
        };
        match (self.named, self.state) {
            (Some(n), _) => sized(n, self.change),
            (None, IsolationState::Unknown) if self.candidates.is_empty() => "unknown fault".into(),
            (None, IsolationState::Unknown) => format!("unknown, nearest {}", names(3, ", ")),
            (None, IsolationState::Isolated) if !self.candidates.is_empty() => {
                format!("{}, not alone", names(2, " / "))
            }
            (None, IsolationState::NotJudged) => "not judged".into(),
            _ => "no deviation".into(),
        }
    }
}

impl Snapshot {
    /// The reading of a core output at `t_s`, with the thresholds in force; `params`
    /// sizes a winding asymmetry.
    pub fn from_output(
        t_s: f64,
        out: &MonitorOutput,
        bands: Option<[(f32, f32); 4]>,
        learned: bool,
        params: &ParamFile,
    ) -> Self {
        let candidates = MonitorState::signature(out);
        let s = out.sensor_fault;
        let sensor_faults = [
            (s.current, Fault::CurrentSensor),
            (s.voltage, Fault::VoltageSensor),
            (s.speed, Fault::SpeedSensor),
        ]
        .into_iter()
        .filter_map(|(on, f)| on.then_some(f))
        .collect();
        let we = out.frame_omega_rad_s.abs();
        let asymmetry = out.unbalance.suspect_phase.map(|phase| {
            let ratio = out.unbalance.negative_sequence_ratio;
            let min_shorted_fraction = (we > 1.0).then(|| {
                let slip = 1.0 - out.operating.wr_rad_s / we;
                min_shorted_fraction(&params.motor.model(), we, slip, ratio)
            });
            Asymmetry {
                phase,
                ratio,
                min_shorted_fraction,
            }
        });
        Snapshot {
            t_s,
            residuals: out.residuals,
            lamps: out.lamps,
            fault_lamp: out.fault_detected,
            call: None,
            bands,
            learned,
            candidates,
            sensor_faults,
            asymmetry,
            speed_rpm: out.speed_rad_s * 60.0 / std::f32::consts::TAU,
            iqs_a: Some(out.operating.iqs),
            ids_a: Some(out.operating.i_f),
            vqs_v: Some(out.operating.vqs),
            supply_hz: Some(we / std::f32::consts::TAU),
            state: MonitorState::of(out),
            isolation: None,
        }
    }
}

impl Snapshot {
    /// The reading of a replay's output `out` at `t_s` ([`Snapshot::from_output`]) with
    /// the replay's isolation and its panel ([`Replay::panel`], the demo's and `diagnose`'s
    /// timeline too): the amber state where the load or the voltage has left the
    /// commissioned range ([`Replay::operating_point_moved`]) and neither the isolation nor
    /// a sensor check names a fault, and the FAULT lamp by the one verdict's table (off in
    /// the amber state, while watching, and against the nominal values for a name within the
    /// file's uncertainty; the residual lamps show what they show).
    pub fn from_replay(t_s: f64, out: &MonitorOutput, replay: &Replay, params: &ParamFile) -> Self {
        let learned = replay.calibration().is_some();
        let mut s = Snapshot::from_output(t_s, out, replay.threshold_bands(), learned, params);
        s.isolation = Some(IsolationView::of_replay(replay));
        let panel = replay.panel(out);
        s.state = panel.state;
        s.fault_lamp = panel.fault_lamp;
        s.call = Some(panel.call);
        s
    }
}

/// A playback speed of a log replay.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Speed {
    /// Real time.
    X1,
    /// Ten times real time.
    X10,
    /// As fast as the log is analysed.
    Max,
}

impl Speed {
    /// "1x", "10x", "max".
    pub fn name(self) -> &'static str {
        match self {
            Speed::X1 => "1x",
            Speed::X10 => "10x",
            Speed::Max => "max",
        }
    }

    /// The next speed (1x, 10x, max, 1x ...).
    pub fn next(self) -> Speed {
        match self {
            Speed::X1 => Speed::X10,
            Speed::X10 => Speed::Max,
            Speed::Max => Speed::X1,
        }
    }
}

/// What the live simulation's switches stand at.
#[derive(Debug, Clone, PartialEq)]
pub struct LiveControls {
    /// Faults switched on, with their relative change.
    pub faults: Vec<(Fault, f64)>,
    /// Relative change the next fault is switched on with (0.5 = +50 %).
    pub change: f64,
    /// Load Bl as a multiple of the parameter file's.
    pub load_scale: f64,
    /// Supply voltage as a multiple of the nominal.
    pub voltage_scale: f64,
    /// Supply frequency [Hz].
    pub supply_hz: f64,
    /// The simulation is paused.
    pub paused: bool,
}

/// Where a log replay's playback stands.
#[derive(Debug, Clone, PartialEq)]
pub struct PlaybackControls {
    /// Playback speed.
    pub speed: Speed,
    /// Paused.
    pub paused: bool,
    /// Log time shown [s].
    pub position_s: f64,
    /// Log time analysed so far [s].
    pub analysed_s: f64,
    /// The whole log is analysed.
    pub done: bool,
    /// The analysis' verdict, once done (`fault`, `healthy`, `could_not_judge`).
    pub verdict: Option<String>,
}

/// The firmware link's counters.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct StdinControls {
    /// Lines read.
    pub lines: u64,
    /// Status lines among them.
    pub status_lines: u64,
    /// Standard input has ended.
    pub ended: bool,
    /// The firmware's mode (`commissioned`, `not-commissioned`, `commissioning` ...).
    pub mode: Option<String>,
}

/// What the source's status panel shows.
#[derive(Debug, Clone, PartialEq)]
pub enum Controls {
    /// The live simulation.
    Live(LiveControls),
    /// A log replay.
    Replay(PlaybackControls),
    /// The firmware on standard input.
    Stdin(StdinControls),
}

/// Everything the screen shows: a pure function of this draws it.
#[derive(Debug, Clone, PartialEq)]
pub struct HmiState {
    /// What is watched (the motor, the log's path, "firmware on stdin").
    pub title: String,
    /// The latest reading.
    pub latest: Option<Snapshot>,
    /// Residuals over the last [`HISTORY_S`], oldest first: (time [s], r1..r4).
    pub history: VecDeque<(f64, [f32; 4])>,
    /// Data-quality warnings (and anything else that limits what the screen means).
    pub warnings: Vec<String>,
    /// The last few events (fault switched on, commissioning started ...), newest last.
    pub events: VecDeque<String>,
    /// Events since the start (the list keeps the last few).
    pub events_total: u64,
    /// The source's controls.
    pub controls: Controls,
    /// The user asked to quit.
    pub quit: bool,
}

impl HmiState {
    /// An empty screen for a source.
    pub fn new(title: impl Into<String>, controls: Controls) -> Self {
        HmiState {
            title: title.into(),
            latest: None,
            history: VecDeque::new(),
            warnings: Vec::new(),
            events: VecDeque::new(),
            events_total: 0,
            controls,
            quit: false,
        }
    }

    /// A new reading: the latest, and into the strip chart (a reading earlier than the
    /// last one starts the chart again).
    pub fn push(&mut self, s: Snapshot) {
        if self.history.back().is_some_and(|(t, _)| *t > s.t_s) {
            self.history.clear();
        }
        self.history.push_back((s.t_s, s.residuals));
        while self
            .history
            .front()
            .is_some_and(|(t, _)| *t < s.t_s - HISTORY_S)
        {
            self.history.pop_front();
        }
        self.latest = Some(s);
    }

    /// Adds an event to the list.
    pub fn event(&mut self, text: impl Into<String>) {
        self.events.push_back(text.into());
        self.events_total += 1;
        while self.events.len() > EVENTS_KEPT {
            self.events.pop_front();
        }
    }

    /// One line for a terminal that is not a screen (stdout piped): time, speed, lamps,
    /// state and the top candidate.
    pub fn status_line(&self) -> String {
        let Some(s) = &self.latest else {
            return format!("{}: waiting for the first reading", self.title);
        };
        let lamps: String = s.lamps.iter().map(|l| if *l { '●' } else { '○' }).collect();
        let (lamp, text) = lamp_and_header(
            &s.state,
            s.fault_lamp,
            s.call,
            &s.candidates,
            s.isolation.as_ref(),
        );
        let lamp = if lamp.is_empty() {
            String::new()
        } else {
            format!(" {lamp}")
        };
        format!(
            "{:8.2} s  {:6.0} rpm  {}{}  {}",
            s.t_s, s.speed_rpm, lamps, lamp, text
        )
    }
}

/// The screen's header: the isolated fault with its size alone (`rs +50 %`; the FAULT lamp
/// stands beside it), as the verdict names it; without a named fault, the monitor's state in
/// words ([`state_text`], the lamps' signature candidates).
pub fn header_text(s: &Snapshot) -> String {
    header_of(&s.state, &s.candidates, s.isolation.as_ref())
}

/// [`header_text`] of a state, the lamps' signature candidates (most probable first) and
/// the isolation's conclusion: the one wording of the HMI, the demo and `diagnose`'s
/// timeline. A fault is named only where the isolation names it alone, as the verdict
/// (`monitor_core::verdict`) names it: beside a named fault the lamps' signature is not
/// shown (its tie, `sig. rs p 0.33 / ls p 0.33 / voltage_sensor p 0.33`, would name two
/// faults the isolation ruled out; the lamps' candidates have their own line and panel).
pub fn header_of(
    state: &MonitorState,
    candidates: &[(Fault, f32)],
    isolation: Option<&IsolationView>,
) -> String {
    header_words(state, candidates, isolation, true)
}

/// [`header_of`], the word FAULT left out of a fault's state where `fault_word` is false
/// (the lamp's word stands beside it: [`lamp_and_header`]).
fn header_words(
    state: &MonitorState,
    candidates: &[(Fault, f32)],
    isolation: Option<&IsolationView>,
    fault_word: bool,
) -> String {
    let named = isolation.filter(|i| i.named.is_some());
    match (named, state) {
        (Some(iso), MonitorState::Fault(_)) => iso.text(),
        (Some(iso), MonitorState::Moved(note)) => format!(
            "moved: {} | {}",
            iso.text(),
            monitor_api::words::diagnose::moved_why(note)
        ),
        (Some(iso), _) => format!("{} | named: {}", state_text(state, candidates), iso.text()),
        (None, _) => state_words(state, candidates, fault_word),
    }
}

/// The lamp's word and the header ([`header_of`]) without the word repeated: the plain
/// status line, the demo's and `diagnose`'s state column. The word: `FAULT` with the FAULT
/// lamp lit, the amber `MOVED`; with lamps lit and the FAULT lamp off, the decision table's
/// verdict (`monitor_core::verdict`): `WATCHING` for a name below what a FAULT needs (its
/// size, `replay::MIN_FAULT_CHANGE`, or its confidence) or lamps no single fault explains,
/// `NOT JUDGED` where the data or the parameter file cannot carry a verdict; else empty.
pub fn lamp_and_header(
    state: &MonitorState,
    fault_lamp: bool,
    call: Option<Verdict>,
    candidates: &[(Fault, f32)],
    isolation: Option<&IsolationView>,
) -> (&'static str, String) {
    let lamp = match (state, fault_lamp, call) {
        (MonitorState::Moved(_), _, _) => "MOVED",
        (_, true, _) => "FAULT",
        (MonitorState::Fault(_), false, Some(Verdict::CouldNotJudge)) => "NOT JUDGED",
        (MonitorState::Fault(_), false, Some(Verdict::Watching)) => "WATCHING",
        // Lamps lit with the FAULT lamp off and a fault named, where the source makes no
        // call: a name too small for a FAULT, watched.
        (MonitorState::Fault(_), false, _) if isolation.is_some_and(|i| i.named.is_some()) => {
            "WATCHING"
        }
        (_, false, _) => "",
    };
    // The lamp's word once: beside a lamp's word a fault's state is spelled without it.
    (
        lamp,
        header_words(state, candidates, isolation, lamp.is_empty()),
    )
}

/// The monitor's state in words (the screen and the plain-text line).
pub fn state_text(state: &MonitorState, candidates: &[(Fault, f32)]) -> String {
    state_words(state, candidates, true)
}

/// The lamps' signature candidates as `sig. rs p 0.33 / ls p 0.33` (short: the header fits
/// 80 columns), or `sig. none` (B and Bl as one class,
/// `monitor_studies::fault_signatures::candidates_text`).
fn signature_text(candidates: impl IntoIterator<Item = (Fault, f32)>) -> String {
    let names = monitor_studies::fault_signatures::candidates_text(
        candidates.into_iter().map(|(f, p)| (f, p, None)),
    );
    if names.is_empty() {
        "sig. none".into()
    } else {
        format!("sig. {}", names.join(" / "))
    }
}

/// [`state_text`], a fault's state without the word FAULT where `fault_word` is false.
fn state_words(state: &MonitorState, candidates: &[(Fault, f32)], fault_word: bool) -> String {
    match state {
        MonitorState::Commissioning(x) => format!("commissioning {:.0} %", x * 100.0),
        MonitorState::Transient => "transient (lamps hold)".to_string(),
        MonitorState::Starting => "starting (settling)".to_string(),
        MonitorState::Healthy => "healthy".to_string(),
        MonitorState::Fault(_) => {
            let sig = signature_text(candidates.iter().map(|(f, p)| (*f, *p)));
            if fault_word {
                format!("FAULT ({sig})")
            } else {
                format!("({sig})")
            }
        }
        MonitorState::Moved(note) => format!(
            "operating point moved: {}",
            monitor_api::words::diagnose::moved_why(note)
        ),
    }
}

/// A source of readings for the HMI.
pub trait Source {
    /// Advances the source by `wall_s` seconds of wall-clock time and updates `state`.
    fn advance(&mut self, wall_s: f64, state: &mut HmiState);
    /// Acts on a key; false when the key means nothing to this source.
    fn key(&mut self, key: Key, state: &mut HmiState) -> bool;
    /// The state the screen starts from.
    fn initial_state(&self) -> HmiState;
}

/// Quits on `q`, Esc (every source): true when the key was one of them.
pub fn quit_key(key: Key, state: &mut HmiState) -> bool {
    if matches!(key, Key::Char('q') | Key::Esc) {
        state.quit = true;
        return true;
    }
    false
}

#[cfg(test)]
mod tests;
