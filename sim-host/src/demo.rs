//! The main job (`sim-host demo`): the 3 hp reference motor (Krause's textbook machine)
//! started direct-on-line with the paper's viscous load and realistic sensors (12-bit ADC,
//! noise, 1024-line encoder), its sensor streams replayed through the same core the
//! firmware runs, the healthy residuals learned (commissioning, 2-4 s), a Table 1 fault
//! injected at 5 s, and the lamps r1..r4 and the fault candidates followed every 0.25 s.

use crate::experiment::ExperimentError;
use crate::fault_signatures::{scenario, Protocol};
use crate::params::ParamFile;
pub use crate::replay::MonitorState;
use crate::replay::{DiagnoseReport, IsolationName, Panel, Replay, ReplayOptions};
use crate::sim::simulate;
use monitor_core::Fault;

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
    /// ([`crate::replay::Replay::panel`]).
    pub panel: Panel,
    /// The first point at or after the fault's onset.
    pub fault_injected: bool,
}

/// A finished demo run.
#[derive(Debug, Clone)]
pub struct DemoRun {
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
    /// True when the injected fault is among the final candidates.
    pub fn correct_fault_named(&self) -> bool {
        self.report.isolation.named == Some(IsolationName::expected(self.fault))
    }
}

/// Runs the demo with `fault` of relative size `change` (-0.95..5) at 5 s.
///
/// # Errors
/// Simulator or replay configuration errors (not expected for the reference motor).
pub fn run(fault: Fault, change: f64) -> Result<DemoRun, ExperimentError> {
    let params = ParamFile::reference_3hp();
    let proto = Protocol {
        duration_s: 8.0,
        fault_at_s: 5.0,
        ..Protocol::default()
    };
    let sc = scenario(Some((fault, change)), &proto);
    let opts = ReplayOptions {
        commission: Some(proto.commission),
        timeline_step_s: TIMELINE_STEP_S,
        // The paper's scenario: its fixed viscous load, a Bl change is a fault.
        load: crate::replay::LoadModel::Viscous,
        ..ReplayOptions::default()
    };
    let mut next = 0.0;
    let mut announced = false;
    let mut points = Vec::new();
    let mut replay = Replay::new(&params, sc.sensors.channels(), sc.sample_rate_hz, opts)?;
    simulate(&params, &sc, |row| {
        let o = replay.push(row);
        if row.t_s + 1e-9 >= next {
            next += TIMELINE_STEP_S;
            let fault_injected = !announced && row.t_s >= proto.fault_at_s;
            announced |= fault_injected;
            points.push(DemoPoint {
                t_s: row.t_s,
                speed_rpm: f64::from(o.speed_rad_s * 60.0 / std::f32::consts::TAU),
                lamps: o.lamps,
                panel: replay.panel(&o),
                fault_injected,
            });
        }
    })?;
    Ok(DemoRun {
        fault,
        change,
        fault_at_s: proto.fault_at_s,
        points,
        report: replay.finish(),
    })
}
