//! The main job (`sim-host demo`): the 3 hp reference motor (Krause's textbook machine)
//! started direct-on-line with realistic sensors (12-bit ADC, noise, 1024-line encoder), its
//! sensor streams replayed through the same core the firmware runs, and the lamps r1..r4
//! and the fault candidates followed every 0.25 s.
//!
//! The default run is a day in service ([`DemoStory::Service`]): the healthy residuals are
//! learned (commissioning, 2-4 s); the load rises 40 % at 5 s and falls back at 6.5 s, which
//! the monitor shows as what it is (the amber "operating point moved", a load move in the
//! events, no fault); then the stator resistance rises 50 % at 8.5 s (a loose connection, a
//! burnt contact), which lights the lamps and is named with its size. The load is an unknown
//! input, as in service. [`DemoStory::Paper`] is the paper's own protocol: one Table 1 fault at
//! 5 s with the paper's fixed viscous load, under which a Bl change is a fault.

use crate::experiment::ExperimentError;
use crate::fault_signatures::{scenario, Protocol};
use monitor_core::Fault;
use monitor_io::params::ParamFile;
pub use monitor_replay::MonitorState;
use monitor_replay::{DiagnoseReport, IsolationName, Panel, Replay, ReplayOptions};
use monitor_sim::simulate;

/// Time between two timeline points [s].
pub const TIMELINE_STEP_S: f64 = 0.25;

/// One point of the demo's timeline.
#[derive(Debug, Clone, PartialEq)]
pub struct DemoPoint {
    /// Time [s].
    pub t_s: f64,
    /// Shaft speed from the encoder [rpm].
    pub speed_rpm: f64,
    /// Lamps r1..r4.
    pub lamps: [bool; 4],
    /// What the panel shows: the state, the FAULT lamp, the isolation's conclusion
    /// ([`monitor_replay::Replay::panel`]).
    pub panel: Panel,
    /// The first point at or after the fault's onset.
    pub fault_injected: bool,
    /// The first point at or after a load step: the load's new Bl as a multiple of the
    /// commissioned one.
    pub load_step: Option<f64>,
}

/// Which run the demo tells.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum DemoStory {
    /// A day in service (the default): commissioning, a load step and back, then `fault`
    /// of relative size `change` at [`SERVICE_FAULT_AT_S`]; the load an unknown input.
    Service {
        /// The fault (Table 1's names).
        fault: Fault,
        /// Its relative change (0.5 = +50 %; sensors: gain error).
        change: f64,
    },
    /// The paper's protocol (`demo --paper`): `fault` at 5 s on the paper's fixed viscous
    /// load, commissioning 2-4 s.
    Paper {
        /// The fault.
        fault: Fault,
        /// Its relative change.
        change: f64,
    },
}

/// The service story's load step: the viscous load's Bl times this from
/// [`LOAD_STEP_AT_S`] to [`LOAD_BACK_AT_S`].
pub const LOAD_STEP_SCALE: f64 = 1.4;
/// When the load rises [s].
pub const LOAD_STEP_AT_S: f64 = 5.0;
/// When it falls back [s].
pub const LOAD_BACK_AT_S: f64 = 6.5;
/// When the service story's fault comes [s].
pub const SERVICE_FAULT_AT_S: f64 = 8.5;

impl DemoStory {
    /// The default: the service story with the stator resistance +50 %.
    pub fn service() -> Self {
        DemoStory::Service {
            fault: Fault::Rs,
            change: 0.5,
        }
    }

    /// The injected fault and its change.
    pub fn fault(self) -> (Fault, f64) {
        match self {
            DemoStory::Service { fault, change } | DemoStory::Paper { fault, change } => {
                (fault, change)
            }
        }
    }
}

/// A finished demo run.
#[derive(Debug, Clone)]
pub struct DemoRun {
    /// What was run.
    pub story: DemoStory,
    /// The injected fault and its relative size (sensors: gain error).
    pub fault: Fault,
    /// Relative change (0.5 = +50 %).
    pub change: f64,
    /// Onset of the fault [s].
    pub fault_at_s: f64,
    /// Points every [`TIMELINE_STEP_S`].
    pub points: Vec<DemoPoint>,
    /// The replay's report (final lamps, candidates, first detection).
    pub report: DiagnoseReport,
}

impl DemoRun {
    /// Seconds from the fault's onset to the first point in the red FAULT state (the panel's
    /// FAULT lamp on), `None` when none came.
    pub fn detected_after_s(&self) -> Option<f64> {
        self.points
            .iter()
            .find(|p| p.t_s + 1e-9 >= self.fault_at_s && p.panel.fault_lamp)
            .map(|p| p.t_s - self.fault_at_s)
    }

    /// True when the injected fault is among the final candidates.
    pub fn correct_fault_named(&self) -> bool {
        self.report.isolation.named == Some(IsolationName::expected(self.fault))
    }
}

/// Runs the demo's `story` (the fault's change -0.95..5).
///
/// # Errors
/// Simulator or replay configuration errors (not expected for the reference motor).
pub fn run(story: DemoStory) -> Result<DemoRun, ExperimentError> {
    let params = ParamFile::reference_3hp();
    let (fault, change) = story.fault();
    let (proto, load) = story.protocol();
    let mut sc = scenario(Some((fault, change)), &proto);
    let steps = story.load_steps();
    for &(t_s, scale) in &steps {
        sc.load.steps.push(monitor_sim::LoadStep {
            t_s,
            torque_nm: None,
            bl_scale: Some(scale),
        });
    }
    let opts = ReplayOptions {
        commission: Some(proto.commission),
        timeline_step: const { monitor_replay::TimelineStep::of(TIMELINE_STEP_S) },
        load,
        ..ReplayOptions::default()
    };
    let mut timeline = Timeline {
        next: 0.0,
        announced: false,
        steps_left: &steps,
        fault_at_s: proto.fault_at_s,
    };
    let mut points = Vec::new();
    let mut replay = Replay::new(&params, sc.sensors.channels(), sc.sample_rate_hz, opts)?;
    simulate(&params, &sc, |row| {
        let o = replay.push(row);
        if let Some((fault_injected, load_step)) = timeline.tick(row.t_s) {
            points.push(DemoPoint {
                t_s: row.t_s,
                speed_rpm: f64::from(o.speed_rad_s * 60.0 / std::f32::consts::TAU),
                lamps: o.lamps,
                panel: replay.panel(&o),
                fault_injected,
                load_step,
            });
        }
    })?;
    Ok(DemoRun {
        story,
        fault,
        change,
        fault_at_s: proto.fault_at_s,
        points,
        report: replay.finish(),
    })
}

impl DemoStory {
    /// The protocol the story runs, and what the replay is told of the load: in service
    /// the load is an unknown input; the paper's scenario has its fixed viscous load, and
    /// a Bl change is a fault.
    fn protocol(self) -> (Protocol, monitor_replay::LoadModel) {
        match self {
            DemoStory::Service { .. } => (
                Protocol {
                    duration_s: 11.0,
                    fault_at_s: SERVICE_FAULT_AT_S,
                    ..Protocol::default()
                },
                monitor_replay::LoadModel::Unknown,
            ),
            DemoStory::Paper { .. } => (
                Protocol {
                    duration_s: 8.0,
                    fault_at_s: 5.0,
                    ..Protocol::default()
                },
                monitor_replay::LoadModel::Viscous,
            ),
        }
    }

    /// The story's load steps: (time [s], Bl as a multiple of the file's).
    fn load_steps(self) -> Vec<(f64, f64)> {
        match self {
            DemoStory::Service { .. } => {
                vec![(LOAD_STEP_AT_S, LOAD_STEP_SCALE), (LOAD_BACK_AT_S, 1.0)]
            }
            DemoStory::Paper { .. } => Vec::new(),
        }
    }
}

/// When the demo's timeline takes a point (every [`TIMELINE_STEP_S`]) and what it marks:
/// the first point at or after the fault, a load step since the last point.
struct Timeline<'a> {
    /// The next point's time [s].
    next: f64,
    /// The fault was marked.
    announced: bool,
    /// The load steps not yet marked: (time [s], scale).
    steps_left: &'a [(f64, f64)],
    /// The fault's time [s].
    fault_at_s: f64,
}

impl Timeline<'_> {
    /// At a row of time `t_s`: `None` between points; at a point, whether the fault is
    /// injected here and the scale of a load step here.
    fn tick(&mut self, t_s: f64) -> Option<(bool, Option<f64>)> {
        if t_s + 1e-9 < self.next {
            return None;
        }
        self.next += TIMELINE_STEP_S;
        let fault_injected = !self.announced && t_s >= self.fault_at_s;
        self.announced |= fault_injected;
        let load_step = match self.steps_left.split_first() {
            Some((&(t, scale), rest)) if t_s + 1e-9 >= t => {
                self.steps_left = rest;
                Some(scale)
            }
            _ => None,
        };
        Some((fault_injected, load_step))
    }
}
