//! `sim-host bench --isolation`: how well the isolation ([`monitor_core::isolation`], as
//! the replay reports it) names every Table 1 fault, sizes it and how soon, on the two
//! reference motors and a third machine the code was not developed on
//! (`examples/params/11kw_2pole.toml`), in both angle modes, with noisy sensors and two load
//! levels.
//!
//! Each case is one run of the Table 1 protocol ([`crate::fault_signatures::run_case`]):
//! direct-on-line start with the paper's viscous load, 12-bit noisy sensors (voltage full scale [`V_RANGE_SCALE`] x the default) at
//! [`SAMPLE_RATE_HZ`] (a different noise seed per case), commissioning in the healthy
//! steady state, then the fault. The load is the parameter file's Bl or [`LOADS`] times it
//! (the replay is told the file's Bl in both: a real load is not the file's). Per case:
//!
//! - **detected**: a lamp lit after the fault, or the isolation saw a deviation (named a
//!   fault, an unknown fault, or candidates it could not separate);
//! - **named right**: the isolation's named fault at the end (probability >= 0.5) is the
//!   true one; B and Bl are right when named as the friction class `b/bl`;
//! - **wrong names**: any other name given at any time of the run (also before the fault),
//!   or another candidate at >= 0.5 at the end: the bar is none;
//! - **size error**: `|estimated - true| / |true|` of the named change (not for `b/bl`,
//!   whose size is Bl's);
//! - **time to name**: from the fault to the first time the right name was given.

use crate::experiment::ExperimentError;
use crate::fault_signatures::{run_case, Protocol, Table1Row};
use monitor_core::{AngleSource, Fault, IsolationState};
use monitor_io::params::{ParamError, ParamFile};
use monitor_replay::{
    serialize_angle_source, serialize_state, CommissionWindow, FaultCandidate, IsolationName,
};
use serde::{Serialize, Serializer};
use std::fmt;

/// Sample rate of every case [Hz] (the bar is stated at 5 kHz).
pub const SAMPLE_RATE_HZ: f64 = 5000.0;
/// The relative fault sizes: -50, -10, +10, +50 %.
pub const CHANGES: [f64; 4] = [-0.5, -0.1, 0.1, 0.5];
/// The load levels: the viscous load's Bl as a multiple of the parameter file's.
pub const LOADS: [f64; 2] = [1.0, 0.6];
/// The two angle modes: the monitor's rotor-flux frame and the paper's voltage PLL.
pub const MODES: [AngleSource; 2] = [AngleSource::RotorFluxCurrentModel, AngleSource::Pll];
/// Columns of the confusion matrix after the nine faults.
pub const EXTRA_COLUMNS: [CaseOutcome; 3] = [
    CaseOutcome::Named(IsolationName::Friction),
    CaseOutcome::Unknown,
    CaseOutcome::Nothing,
];

/// What the isolation concluded at the end of a case: the confusion matrix's column.
/// Serialised as its name ([`CaseOutcome::name`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum CaseOutcome {
    /// A fault, or the friction class, named alone.
    Named(IsolationName),
    /// An unknown fault: no fault of the list explains the change.
    Unknown,
    /// Nothing named alone.
    Nothing,
}

impl CaseOutcome {
    /// The name (`rr`, `b/bl`), `unknown` or `none`.
    pub fn name(self) -> &'static str {
        match self {
            CaseOutcome::Named(n) => n.name(),
            CaseOutcome::Unknown => "unknown",
            CaseOutcome::Nothing => "none",
        }
    }
}

impl fmt::Display for CaseOutcome {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

impl Serialize for CaseOutcome {
    fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        s.serialize_str(self.name())
    }
}

/// The bench's voltage full scale as a multiple of the simulator's default (1.2 x the peak
/// phase voltage, rounded up to 50 V): with the default, a +50 % voltage-sensor gain error
/// clips the readings (flat tops) and their fundamental reads about +36 % (measured on the
/// 2.2 kW and 11 kW machines: +36.2 %), a sensor fault of another kind that the replay does
/// not detect yet. Real front ends are sized with headroom for such a check.
pub const V_RANGE_SCALE: f64 = 1.5;

/// The third machine (the one home of its parameters is the example file).
const MOTOR_11KW: &str = include_str!("../../../../examples/params/11kw_2pole.toml");

/// A motor of the bench and its run's timing.
#[derive(Debug, Clone, Copy)]
pub struct BenchMotor {
    /// Short name (`3 hp`, `2.2 kW`, `11 kW`).
    pub name: &'static str,
    /// Its parameters.
    pub params: ParamFile,
    /// When its runs commission, fault and end.
    pub timing: Timing,
}

/// The timing of a bench run [s from the start].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Timing {
    /// Commissioning window [start, end).
    pub commission: CommissionWindow,
    /// Fault switch-on.
    pub fault_at_s: f64,
    /// End of the run.
    pub duration_s: f64,
}

impl BenchMotor {
    /// The voltage ADC's full scale of the bench [V]: [`V_RANGE_SCALE`] times the sensor
    /// range ([`monitor_io::params::SensorRanges`]), so that a +50 % voltage-sensor gain error
    /// stays on scale.
    pub fn v_range_v(&self) -> f64 {
        V_RANGE_SCALE * self.params.sensor_ranges().v_range_v
    }

    /// The Table 1 protocol for this motor at [`SAMPLE_RATE_HZ`] in `mode`, at `load_scale`
    /// times the file's load, with the noise `seed`.
    pub fn protocol(&self, mode: AngleSource, load_scale: f64, seed: u64) -> Protocol {
        let t = self.timing;
        Protocol {
            commission: t.commission,
            fault_at_s: t.fault_at_s,
            duration_s: t.duration_s,
            sample_rate_hz: SAMPLE_RATE_HZ,
            angle_source: mode,
            load_scale,
            seed,
            v_range_v: Some(self.v_range_v()),
        }
    }
}

/// The three motors: the 3 hp and 2.2 kW reference machines (commissioning 2..4 s, fault at
/// 4.5 s, 9.5 s) and the 2-pole 11 kW machine, whose direct-on-line start settles later
/// (commissioning 3..5 s, fault at 5.5 s, 10.5 s). A fault that stays inside the follower's
/// steadiness band (Rs +-10 %) is seen on a 2 s average that still holds blocks from before
/// it; the average is begun again after that onset and the fault is named on 2 s after it:
/// about 4 s after the fault.
///
/// # Errors
/// The embedded 11 kW parameter file does not parse (a test reads it).
pub fn motors() -> Result<Vec<BenchMotor>, ParamError> {
    let early = Timing {
        commission: CommissionWindow::of(2.0, 4.0),
        fault_at_s: 4.5,
        duration_s: 9.5,
    };
    Ok(vec![
        BenchMotor {
            name: "3 hp",
            params: ParamFile::reference_3hp(),
            timing: early,
        },
        BenchMotor {
            name: "2.2 kW",
            params: ParamFile::reference_2p2kw(),
            timing: early,
        },
        BenchMotor {
            name: "11 kW",
            params: ParamFile::from_toml_str(MOTOR_11KW, "examples/params/11kw_2pole.toml")?,
            timing: Timing {
                commission: CommissionWindow::of(3.0, 5.0),
                fault_at_s: 5.5,
                duration_s: 10.5,
            },
        },
    ])
}

/// What the bench runs: every combination of these.
#[derive(Debug, Clone)]
pub struct BenchPlan {
    /// Motors.
    pub motors: Vec<BenchMotor>,
    /// Faults.
    pub faults: Vec<Fault>,
    /// Relative sizes.
    pub changes: Vec<f64>,
    /// Load levels (multiples of the file's Bl).
    pub loads: Vec<f64>,
    /// Angle modes.
    pub modes: Vec<AngleSource>,
}

impl BenchPlan {
    /// The whole bench: three motors, nine faults, [`CHANGES`], [`LOADS`], [`MODES`]
    /// (432 cases).
    ///
    /// # Errors
    /// As [`motors`].
    pub fn full() -> Result<Self, ParamError> {
        Ok(BenchPlan {
            motors: motors()?,
            faults: Fault::ALL.to_vec(),
            changes: CHANGES.to_vec(),
            loads: LOADS.to_vec(),
            modes: MODES.to_vec(),
        })
    }

    /// Number of cases.
    pub fn len(&self) -> usize {
        self.motors.len()
            * self.faults.len()
            * self.changes.len()
            * self.loads.len()
            * self.modes.len()
    }

    /// True when the plan has no case.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }
}

/// One case's result.
#[derive(Debug, Clone, Serialize, PartialEq)]
pub struct CaseResult {
    /// Motor.
    pub motor: String,
    /// Angle mode (JSON `rotor-flux`, `pll`).
    #[serde(serialize_with = "serialize_angle_source")]
    pub mode: AngleSource,
    /// The true fault (JSON: its name).
    pub fault: Fault,
    /// True relative change.
    pub change: f64,
    /// Load as a multiple of the file's Bl.
    pub load_scale: f64,
    /// A lamp lit after the fault or the isolation saw a deviation.
    pub detected: bool,
    /// The confusion matrix's column: the name at the end (`b/bl` for the friction
    /// class), `unknown`, or `none` (nothing named alone).
    pub named: CaseOutcome,
    /// `named` is the true fault (`b/bl` for B and Bl).
    pub right: bool,
    /// The isolation's estimated change of the named fault at the end.
    pub named_change: Option<f32>,
    /// `|estimated - true| / |true|` when named right (not for `b/bl`).
    pub size_error: Option<f64>,
    /// From the fault to the first time the right name was given [s].
    pub time_to_name_s: Option<f64>,
    /// Wrong names at probability >= 0.5: each name given during the run other than the
    /// true one (`name at +t s` from the fault), and wrong candidates >= 0.5 at the end.
    pub wrong_names: Vec<String>,
    /// The isolation's state at the end.
    #[serde(serialize_with = "serialize_state")]
    pub state: IsolationState,
    /// The candidates at the end (JSON: triples `[fault, probability, estimated change]`).
    #[serde(serialize_with = "crate::fault_signatures::fault_probability_and_change")]
    pub candidates: Vec<FaultCandidate>,
}

/// Judges one case's row (module docs).
pub fn judge(
    motor: &str,
    mode: AngleSource,
    load: f64,
    f: Fault,
    change: f64,
    row: &Table1Row,
) -> CaseResult {
    let want = IsolationName::expected(f);
    let friction = matches!(f, Fault::B | Fault::Bl);
    let named = match (row.named, row.isolation_state) {
        (Some(n), _) => CaseOutcome::Named(n),
        (None, IsolationState::Unknown) => CaseOutcome::Unknown,
        (None, _) => CaseOutcome::Nothing,
    };
    let right = named == CaseOutcome::Named(want);
    let size_error = (right && !friction)
        .then(|| {
            row.named_change
                .map(|x| (f64::from(x) - change).abs() / change.abs())
        })
        .flatten();
    let time_to_name_s = row
        .names_given
        .iter()
        .find(|g| g.name == want && g.t_s >= 0.0)
        .map(|g| g.t_s);
    let wrong_names = wrong_names(row, f, want);
    let detected = detected(row);
    CaseResult {
        motor: motor.to_string(),
        mode,
        fault: f,
        change,
        load_scale: load,
        detected,
        named,
        right,
        named_change: row.named_change,
        size_error,
        time_to_name_s,
        wrong_names,
        state: row.isolation_state,
        candidates: row.isolation_candidates.clone(),
    }
}

/// The wrong names of a case of fault `f` (named `want` when right): each name given
/// during the run other than `want` (`name at +t s` from the fault), then each other
/// candidate at probability >= 0.5 at the end not already listed (B and Bl are one
/// friction class).
fn wrong_names(row: &Table1Row, f: Fault, want: IsolationName) -> Vec<String> {
    let friction = matches!(f, Fault::B | Fault::Bl);
    let mut wrong: Vec<String> = row
        .names_given
        .iter()
        .filter(|g| g.name != want)
        .map(|g| format!("{} at {:+.2} s", g.name, g.t_s))
        .collect();
    for c in &row.isolation_candidates {
        let ok = c.fault == f || (friction && matches!(c.fault, Fault::B | Fault::Bl));
        let (name, p) = (c.fault, c.probability);
        let given = row
            .names_given
            .iter()
            .any(|g| g.name != want && g.name == IsolationName::Fault(name));
        if p >= 0.5 && !ok && !given {
            wrong.push(format!("{name} p={p:.2} at the end"));
        }
    }
    wrong
}

/// Whether a case was detected: a lamp lit after the fault, a name given after it, or the
/// isolation saw a deviation (named a fault, an unknown fault, or candidates it could not
/// separate).
fn detected(row: &Table1Row) -> bool {
    let after_fault = |t: &Option<f64>| t.is_some_and(|t| t >= 0.0);
    row.detection_delay_s.is_some()
        || row.names_given.iter().any(|g| g.t_s >= 0.0)
        || after_fault(&row.name_delay_s)
        || matches!(
            row.isolation_state,
            IsolationState::Isolated | IsolationState::Unknown
        )
}

/// One line of the summary: a motor in one angle mode.
#[derive(Debug, Clone, Serialize, PartialEq)]
pub struct Summary {
    /// Motor.
    pub motor: String,
    /// Angle mode (JSON: its command-line name).
    #[serde(serialize_with = "serialize_angle_source")]
    pub mode: AngleSource,
    /// Cases.
    pub cases: usize,
    /// Cases detected.
    pub detected: usize,
    /// Cases named right.
    pub named_right: usize,
    /// Cases with a wrong name at probability >= 0.5 (the bar: 0).
    pub wrong_named: usize,
    /// Median and largest size error of the cases named right (relative).
    pub size_error_median: Option<f64>,
    /// Largest size error.
    pub size_error_max: Option<f64>,
    /// Median time to name [s].
    pub time_to_name_median_s: Option<f64>,
}

/// A confusion matrix: rows the true faults, columns what was named.
#[derive(Debug, Clone, Serialize, PartialEq)]
pub struct IsolationConfusion {
    /// Angle mode (JSON: its command-line name).
    #[serde(serialize_with = "serialize_angle_source")]
    pub mode: AngleSource,
    /// Row labels (true faults).
    pub rows: Vec<Fault>,
    /// Column labels: the nine faults, `b/bl`, `unknown`, `none`.
    pub columns: Vec<CaseOutcome>,
    /// Counts, `counts[row][column]`.
    pub counts: Vec<Vec<u32>>,
}

/// The whole bench's result (`bench --isolation --json`).
#[derive(Debug, Clone, Serialize)]
pub struct IsolationBench {
    /// Sample rate [Hz].
    pub sample_rate_hz: f64,
    /// Every case.
    pub cases: Vec<CaseResult>,
    /// Per motor and angle mode.
    pub summaries: Vec<Summary>,
    /// One per angle mode, over all motors, sizes and loads.
    pub confusion: Vec<IsolationConfusion>,
    /// Wall time of the run [s].
    pub wall_s: f64,
}

fn median(mut v: Vec<f64>) -> Option<f64> {
    if v.is_empty() {
        return None;
    }
    v.sort_by(f64::total_cmp);
    let n = v.len();
    Some(if n % 2 == 1 {
        v[n / 2]
    } else {
        0.5 * (v[n / 2 - 1] + v[n / 2])
    })
}

/// The summary of the cases of one motor in one mode.
pub fn summarise(motor: &str, mode: AngleSource, cases: &[CaseResult]) -> Summary {
    let mine: Vec<&CaseResult> = cases
        .iter()
        .filter(|c| c.motor == motor && c.mode == mode)
        .collect();
    let sizes: Vec<f64> = mine.iter().filter_map(|c| c.size_error).collect();
    Summary {
        motor: motor.to_string(),
        mode,
        cases: mine.len(),
        detected: mine.iter().filter(|c| c.detected).count(),
        named_right: mine.iter().filter(|c| c.right).count(),
        wrong_named: mine.iter().filter(|c| !c.wrong_names.is_empty()).count(),
        size_error_max: sizes.iter().copied().reduce(f64::max),
        size_error_median: median(sizes),
        time_to_name_median_s: median(mine.iter().filter_map(|c| c.time_to_name_s).collect()),
    }
}

/// The confusion matrix of the cases in `mode` (rows: `faults`).
pub fn confusion(mode: AngleSource, faults: &[Fault], cases: &[CaseResult]) -> IsolationConfusion {
    let columns: Vec<CaseOutcome> = Fault::ALL
        .iter()
        .map(|f| CaseOutcome::Named(IsolationName::Fault(*f)))
        .chain(EXTRA_COLUMNS)
        .collect();
    let counts = faults
        .iter()
        .map(|f| {
            columns
                .iter()
                .map(|col| {
                    cases
                        .iter()
                        .filter(|c| c.mode == mode && c.fault == *f && c.named == *col)
                        .count() as u32
                })
                .collect()
        })
        .collect();
    IsolationConfusion {
        mode,
        rows: faults.to_vec(),
        columns,
        counts,
    }
}

/// Runs the plan's cases in parallel (rayon), calling `on_done` after each.
///
/// # Errors
/// The first case the simulator or the replay refused.
pub fn run(plan: &BenchPlan, on_done: impl Fn() + Sync) -> Result<IsolationBench, ExperimentError> {
    use rayon::prelude::*;
    let start = std::time::Instant::now();
    let mut list = Vec::with_capacity(plan.len());
    for m in &plan.motors {
        for &mode in &plan.modes {
            for &f in &plan.faults {
                for &change in &plan.changes {
                    for &load in &plan.loads {
                        list.push((m, mode, f, change, load));
                    }
                }
            }
        }
    }
    let cases: Vec<CaseResult> = list
        .par_iter()
        .enumerate()
        .map(|(k, (m, mode, f, change, load))| {
            let proto = m.protocol(*mode, *load, 1 + k as u64);
            let row = run_case(&m.params, *f, *change, &proto);
            on_done();
            row.map(|row| judge(m.name, *mode, *load, *f, *change, &row))
        })
        .collect::<Result<_, _>>()?;
    let mut summaries = Vec::new();
    for m in &plan.motors {
        for &mode in &plan.modes {
            summaries.push(summarise(m.name, mode, &cases));
        }
    }
    let confusion = plan
        .modes
        .iter()
        .map(|&mode| confusion(mode, &plan.faults, &cases))
        .collect();
    Ok(IsolationBench {
        sample_rate_hz: SAMPLE_RATE_HZ,
        cases,
        summaries,
        confusion,
        wall_s: start.elapsed().as_secs_f64(),
    })
}
