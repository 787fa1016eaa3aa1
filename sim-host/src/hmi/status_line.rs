//! The firmware's defmt status line, read back (`cargo fw-run | sim-host hmi --stdin`).
//!
//! The line's format, its writer and its parser are the core's one module,
//! [`monitor_core::status_line`] (the firmware writes with it); its fields are documented
//! once, in docs/firmware.md ("The status line"). Here the decoder's output is read line by
//! line: terminal colours taken out, the core's [`parse`](monitor_core::status_line::parse)
//! applied, and the reading turned into the screen's [`Snapshot`]. Fields an older firmware
//! does not print are `None` on the screen. Other log lines with a level (`INFO`, `WARN`,
//! `ERROR`) become events on the screen.

use super::{quit_key, Controls, HmiState, Key, Snapshot, Source, StdinControls};
use monitor_api::replay::{FaultCandidate, IsolationName};
use monitor_core::status_line::StatusReading;
use monitor_core::verdict::Verdict;
use monitor_core::{Fault, IsolationState};
use monitor_studies::demo::MonitorState;
use std::io::BufRead;
use std::sync::mpsc::{channel, Receiver, TryRecvError};

/// Interval between two status lines of the firmware [s] (the time axis when the lines
/// carry no timestamp).
pub const STATUS_PERIOD_S: f64 = 0.1;

/// One status line's fields.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct FirmwareStatus {
    /// The decoder's timestamp [s], when it printed one.
    pub timestamp_s: Option<f64>,
    /// Normalised residuals r1..r4.
    pub residuals: [f32; 4],
    /// Residual lamps.
    pub lamps: [bool; 4],
    /// The fault lamp's cause: any lamp or a sensor fault.
    pub fault: bool,
    /// The two most probable candidates.
    pub candidates: Vec<(Fault, f32)>,
    /// Shaft speed [rad/s].
    pub wm_rad_s: Option<f32>,
    /// Panel mode (`commissioned`, `not-commissioned`, `commissioning`,
    /// `sampling-stalled`, `failed`).
    pub mode: Option<String>,
    /// The latest commissioning run: id, evaluated blocks learned, needed.
    pub run: Option<(u16, u32, u32)>,
    /// I_qs [A].
    pub iqs_a: Option<f32>,
    /// i_ds [A].
    pub ids_a: Option<f32>,
    /// V_qs [V].
    pub vqs_v: Option<f32>,
    /// Frame (supply) frequency [Hz].
    pub supply_hz: Option<f32>,
    /// The quasi-steady gate is open.
    pub steady: Option<bool>,
    /// The lamps are being evaluated.
    pub evaluating: Option<bool>,
    /// Sensor flags: current, voltage, speed.
    pub sensors: Option<[bool; 3]>,
    /// Threshold band centres and half-widths.
    pub band: Option<([f32; 4], [f32; 4])>,
    /// The fault isolation's result (firmware with isolation).
    pub isolation: Option<FirmwareIsolation>,
    /// Shorted turns (`wind=`, `wind_i2=`): the phase named and the winding's part of
    /// |I2/I1|; `None` for `wind=none` or an older firmware.
    pub winding: Option<(monitor_core::Phase, f32)>,
    /// The operating point has left the commissioned range (`moved=`, the firmware's
    /// `RangeWatch::moved`); `None` from an older firmware. With no fault named (`iso=`)
    /// the screen shows the amber "moved" state and no FAULT lamp, as the board's panel.
    pub moved: Option<bool>,
    /// The winding temperature rise since commissioning the isolation tracks [K] (`rise=`).
    pub winding_rise_k: Option<f32>,
    /// The decision table's verdict on the board (`call=`: `healthy`, `fault`, `watching`,
    /// `could_not_judge`; `monitor_core::verdict`; older firmware's `clear` and
    /// `not-commissioned` read as `healthy` and `could_not_judge`), which lights the board's
    /// FAULT lamp for `fault` only; `None` from an older firmware (then `fault=` does).
    pub call: Option<Verdict>,
}

/// The isolation fields of a status line (`iso=`, `iso_change=`, `iso_p=`; the firmware's
/// `drive_monitor::app::isolation_summary`).
#[derive(Debug, Clone, PartialEq, Default)]
pub struct FirmwareIsolation {
    /// The fault named (`rs` .. `speed_sensor`), `b/bl`, `unknown`, `none` or `not-judged`.
    pub named: String,
    /// The named fault's relative change (0.48 for +48 %; the gain error of a sensor).
    pub change: f32,
    /// Its probability (for `unknown`: the unknown fault's).
    pub probability: f32,
}

/// The line without terminal colour sequences (`ESC [ ... letter`).
pub fn strip_ansi(line: &str) -> String {
    let mut out = String::with_capacity(line.len());
    let mut chars = line.chars();
    while let Some(c) = chars.next() {
        if c == '\u{1b}' {
            for d in chars.by_ref() {
                if d.is_ascii_alphabetic() {
                    break;
                }
            }
        } else {
            out.push(c);
        }
    }
    out
}

/// Parses one line of the decoder's output (terminal colours taken out, then the core's
/// [`monitor_core::status_line::parse`]); `None` when it is not a status line.
pub fn parse(line: &str) -> Option<FirmwareStatus> {
    monitor_core::status_line::parse(&strip_ansi(line)).map(FirmwareStatus::from)
}

impl From<StatusReading<'_>> for FirmwareStatus {
    fn from(r: StatusReading<'_>) -> Self {
        FirmwareStatus {
            timestamp_s: r.timestamp_s,
            residuals: r.residuals,
            lamps: r.lamps,
            fault: r.fault,
            candidates: r.candidates.into_iter().flatten().collect(),
            wm_rad_s: r.speed_rad_s,
            mode: r.mode.map(str::to_string),
            run: r.run,
            iqs_a: r.iqs_a,
            ids_a: r.ids_a,
            vqs_v: r.vqs_v,
            supply_hz: r.frame_hz,
            steady: r.quasi_steady,
            evaluating: r.evaluating,
            sensors: r.sensors,
            band: r.band,
            isolation: r
                .isolation
                .map(|(named, change, probability)| FirmwareIsolation {
                    named: named.to_string(),
                    change,
                    probability,
                }),
            winding: r.winding,
            moved: r.moved,
            winding_rise_k: r.winding_rise_k,
            call: r.call,
        }
    }
}

impl FirmwareStatus {
    /// The reading on the screen at `t_s`.
    pub fn snapshot(&self, t_s: f64) -> Snapshot {
        let state = self.state();
        let sensor_faults = self.sensors.map_or(Vec::new(), |s| {
            [
                Fault::CurrentSensor,
                Fault::VoltageSensor,
                Fault::SpeedSensor,
            ]
            .into_iter()
            .zip(s)
            .filter_map(|(f, on)| on.then_some(f))
            .collect()
        });
        Snapshot {
            t_s,
            residuals: self.residuals,
            lamps: self.lamps,
            fault_lamp: self.call.map_or(self.fault, |c| c == Verdict::Fault)
                && !matches!(state, MonitorState::Moved(_)),
            call: self.call,
            bands: self.band.map(|(m, h)| [0, 1, 2, 3].map(|k| (m[k], h[k]))),
            learned: self.mode.as_deref() == Some("commissioned"),
            candidates: self.candidates.clone(),
            sensor_faults,
            asymmetry: self.winding.map(|(phase, ratio)| super::Asymmetry {
                phase,
                ratio,
                min_shorted_fraction: None,
            }),
            speed_rpm: self.wm_rad_s.unwrap_or(0.0) * 60.0 / std::f32::consts::TAU,
            iqs_a: self.iqs_a,
            ids_a: self.ids_a,
            vqs_v: self.vqs_v,
            supply_hz: self.supply_hz,
            state,
            isolation: self.isolation.as_ref().map(|i| super::IsolationView {
                winding_rise_k: self.winding_rise_k,
                ..i.view()
            }),
        }
    }

    /// The monitor's state the fields say: commissioning (with its progress), transient,
    /// starting, fault (the candidates) or healthy, then [`Self::moved_state`].
    fn state(&self) -> MonitorState {
        let commissioning = self.mode.as_deref() == Some("commissioning");
        let state = match self.run {
            Some((_, l, n)) if commissioning && n > 0 => {
                MonitorState::Commissioning((l as f32 / n as f32).min(1.0))
            }
            _ if commissioning => MonitorState::Commissioning(0.0),
            _ if self.steady == Some(false) => MonitorState::Transient,
            _ if self.evaluating == Some(false) => MonitorState::Starting,
            _ if self.fault && !self.candidates.is_empty() => {
                MonitorState::Fault(self.candidates.clone())
            }
            _ => MonitorState::Healthy,
        };
        self.moved_state(state)
    }

    /// `state` as moved when healthy or a fault but the board says the operating point left
    /// the commissioned range (`moved`), with no isolated fault and no sensor fault to name.
    fn moved_state(&self, state: MonitorState) -> MonitorState {
        let named_fault = self
            .isolation
            .as_ref()
            .is_some_and(|i| matches!(i.view().named, Some(IsolationName::Fault(_))));
        let sensor = self.sensors.is_some_and(|s| s.iter().any(|x| *x));
        match state {
            MonitorState::Healthy | MonitorState::Fault(_)
                if self.moved == Some(true) && !named_fault && !sensor =>
            {
                MonitorState::Moved(monitor_api::replay::MovedWhy::BoardSays)
            }
            other => other,
        }
    }
}

impl FirmwareIsolation {
    /// The screen's view of it: the state and the named fault with its size.
    pub fn view(&self) -> super::IsolationView {
        let (state, named) = match self.named.as_str() {
            "unknown" => (IsolationState::Unknown, None),
            "none" => (IsolationState::NoDeviation, None),
            "not-judged" => (IsolationState::NotJudged, None),
            name => (IsolationState::Isolated, IsolationName::from_name(name)),
        };
        super::IsolationView {
            state,
            named,
            change: named.map(|_| self.change),
            candidates: match named {
                Some(IsolationName::Fault(fault)) => vec![FaultCandidate {
                    fault,
                    probability: self.probability,
                    change: Some(self.change),
                    phase: None,
                }],
                _ => Vec::new(),
            },
            winding_rise_k: None,
        }
    }
}

/// A log line that is not a status line but says something (`INFO`, `WARN`, `ERROR`):
/// its message, without the decoder's decorations.
pub fn event_text(line: &str) -> Option<String> {
    let line = strip_ansi(line);
    for level in ["ERROR", "WARN", "INFO"] {
        if let Some(k) = line.find(level) {
            let msg = line[k + level.len()..]
                .trim_start_matches([' ', ']'])
                .trim();
            // The decoder's one-line location suffix, "(crate src/file.rs:12)".
            let msg = match msg.rfind(" (") {
                Some(p) if msg.ends_with(')') && msg[p..].contains(".rs:") => &msg[..p],
                _ => msg,
            };
            let tag = if level == "INFO" { "" } else { level };
            return Some(format!(
                "{tag}{}{msg}",
                if tag.is_empty() { "" } else { " " }
            ));
        }
    }
    None
}

/// The firmware's status lines from standard input (or any reader), read on a thread.
pub struct StdinStatus {
    lines: Receiver<String>,
    controls: StdinControls,
    one_at_a_time: bool,
}

impl StdinStatus {
    /// Reads standard input.
    pub fn stdin() -> Self {
        Self::from_reader(std::io::stdin())
    }

    /// Reads `r` line by line on a thread.
    pub fn from_reader(r: impl std::io::Read + Send + 'static) -> Self {
        let (tx, lines) = channel();
        std::thread::spawn(move || {
            for line in std::io::BufReader::new(r).lines() {
                let Ok(line) = line else { break };
                if tx.send(line).is_err() {
                    break;
                }
            }
        });
        StdinStatus {
            lines,
            controls: StdinControls::default(),
            one_at_a_time: false,
        }
    }

    /// Takes at most one status line per [`Source::advance`] (plain text prints every
    /// reading of a recorded file), instead of every line waiting.
    pub fn one_at_a_time(mut self) -> Self {
        self.one_at_a_time = true;
        self
    }

    /// Takes one line into the state; true for a status line.
    pub fn take_line(&mut self, line: &str, state: &mut HmiState) -> bool {
        let c = &mut self.controls;
        c.lines += 1;
        if let Some(s) = parse(line) {
            let t = s
                .timestamp_s
                .unwrap_or(c.status_lines as f64 * STATUS_PERIOD_S);
            c.status_lines += 1;
            if s.mode.is_some() && s.mode != c.mode {
                if let Some(m) = &s.mode {
                    state.event(format!("{t:.1} s: mode {m}"));
                }
                c.mode.clone_from(&s.mode);
            }
            state.push(s.snapshot(t));
            return true;
        }
        if let Some(e) = event_text(line) {
            state.event(e);
        }
        false
    }
}

impl Source for StdinStatus {
    fn advance(&mut self, _wall_s: f64, state: &mut HmiState) {
        loop {
            match self.lines.try_recv() {
                Ok(line) => {
                    if self.take_line(&line, state) && self.one_at_a_time {
                        break;
                    }
                }
                Err(TryRecvError::Empty) => break,
                Err(TryRecvError::Disconnected) => {
                    if !self.controls.ended {
                        self.controls.ended = true;
                        state.event("standard input ended");
                    }
                    break;
                }
            }
        }
        state.controls = Controls::Stdin(self.controls.clone());
    }

    fn key(&mut self, key: Key, state: &mut HmiState) -> bool {
        quit_key(key, state)
    }

    fn initial_state(&self) -> HmiState {
        HmiState::new(
            "firmware status lines on standard input",
            Controls::Stdin(self.controls.clone()),
        )
    }
}
