//! The paper's Table 1 (the fault signature matrix) reproduced end to end, what
//! `sim-host table1` runs: simulate every fault of Table 1 at +50 % and -50 %, measure it
//! with the simulated sensors, run the core, and read the lamps. (The matrices themselves
//! are the core's `monitor_core::TABLE1` and `ROTOR_FLUX_SIGNATURES`.)
//!
//! Protocol (the same for every fault, so the rows are comparable):
//! direct-on-line start of the motor with the paper's viscous load `Bl omega`, default
//! (12-bit, noisy) sensors; commissioning over [`Protocol::commission`] (healthy, steady);
//! the fault switched on at [`Protocol::fault_at_s`]; the signature is the set of lamps lit
//! at the end of the run (steady state under fault). Sensor faults are gain errors on all
//! three phases (current, voltage) or on the speed reading and the encoder.

use crate::experiment::{simulate_and_replay, ExperimentError};
use monitor_core::{AngleSource, Fault, IsolationState};
use monitor_io::params::ParamFile;
use monitor_replay::{
    serialize_state, CommissionWindow, FaultCandidate, IsolationName, NameGiven, ReplayOptions,
};
use monitor_sim::{FaultSpec, LoadStep, Scenario, SensorSpec};
use serde::{Serialize, Serializer};

/// The span a row's residuals are averaged over at the end of the run [s] (the replay's
/// timeline step for Table 1).
pub const RESIDUAL_MEAN_S: f64 = 0.1;

/// Timing of a Table 1 run.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Protocol {
    /// Commissioning window [s].
    pub commission: CommissionWindow,
    /// Fault switch-on time [s].
    pub fault_at_s: f64,
    /// End of the run [s].
    pub duration_s: f64,
    /// Sample rate [Hz].
    pub sample_rate_hz: f64,
    /// Frame angle source.
    pub angle_source: AngleSource,
    /// The viscous load's Bl as a multiple of the parameter file's, from the start (1: the
    /// file's; the replay is still told the file's, as a user's file would not know).
    pub load_scale: f64,
    /// Seed of the sensor noise.
    pub seed: u64,
    /// The voltage ADC's full scale [V] (`None`: the simulator's default, 1.2 x the peak
    /// phase voltage rounded up to 50 V, which a +50 % voltage-sensor gain error drives
    /// into clipping: the readings' fundamental is then about +36 %, not +50 %).
    pub v_range_v: Option<f64>,
}

impl Default for Protocol {
    fn default() -> Self {
        Protocol {
            commission: CommissionWindow::of(2.0, 4.0),
            fault_at_s: 4.5,
            duration_s: 7.5,
            sample_rate_hz: 10_000.0,
            angle_source: AngleSource::RotorFluxCurrentModel,
            load_scale: 1.0,
            seed: 1,
            v_range_v: None,
        }
    }
}

/// One row of the reproduced table.
#[derive(Debug, Clone, Serialize, PartialEq)]
pub struct Table1Row {
    /// The fault injected (JSON: its name).
    pub fault: Fault,
    /// Relative change (+0.5 / -0.5).
    pub change: f64,
    /// Lamps r1..r4 at the end of the run, 0/1.
    pub signature: [u8; 4],
    /// The paper's signature, 0/1.
    pub paper: [u8; 4],
    /// The physically expected signature for the frame used (the core's matrix), 0/1.
    pub expected: [u8; 4],
    /// Normalised residuals r1..r4 at the end of the run.
    pub residuals: [f32; 4],
    /// The lamps' candidates at the end: the signature matching (JSON: pairs `[fault,
    /// probability]`).
    #[serde(serialize_with = "fault_and_probability")]
    pub candidates: Vec<FaultCandidate>,
    /// Time from the fault to the first lamp [s], if any.
    pub detection_delay_s: Option<f64>,
    /// The fault the isolation names at the end (`b/bl` for the friction class), if any
    /// ([`monitor_replay::IsolationReport`]).
    pub named: Option<IsolationName>,
    /// The estimated relative change of the top isolation candidate at the end.
    pub named_change: Option<f32>,
    /// The isolation's candidates at the end (JSON: triples `[fault, probability,
    /// estimated change]`).
    #[serde(serialize_with = "fault_probability_and_change")]
    pub isolation_candidates: Vec<FaultCandidate>,
    /// The isolation's state at the end (JSON `isolated`, `unknown`, `no_deviation`, ...).
    #[serde(serialize_with = "serialize_state")]
    pub isolation_state: IsolationState,
    /// Time from the fault to the first time the isolation named a fault [s] (negative:
    /// something was named before the fault).
    pub name_delay_s: Option<f64>,
    /// Every fault the isolation named during the run (`b/bl` for the friction class),
    /// each with the first time it was named, from the fault on [s] (negative: before the
    /// fault); a name given and later withdrawn stays here.
    pub names_given: Vec<NameGiven>,
}

/// Candidates as `[fault, probability]` pairs (the table's JSON).
fn fault_and_probability<S: Serializer>(c: &[FaultCandidate], s: S) -> Result<S::Ok, S::Error> {
    s.collect_seq(c.iter().map(|c| (c.fault, c.probability)))
}

/// Candidates as `[fault, probability, change]` triples (the table's JSON, the
/// isolation bench's).
pub(crate) fn fault_probability_and_change<S: Serializer>(
    c: &[FaultCandidate],
    s: S,
) -> Result<S::Ok, S::Error> {
    s.collect_seq(c.iter().map(|c| (c.fault, c.probability, c.change)))
}

/// The scenario of one case.
pub fn scenario(fault: Option<(Fault, f64)>, proto: &Protocol) -> Scenario {
    let mut s = Scenario::steady(proto.duration_s, proto.sample_rate_hz);
    s.sensors = SensorSpec::default();
    s.sensors.v_range_v = proto.v_range_v;
    s.seed = proto.seed;
    if proto.load_scale != 1.0 {
        s.load.steps.push(LoadStep {
            t_s: 0.0,
            torque_nm: None,
            bl_scale: Some(proto.load_scale),
        });
    }
    if let Some((f, change)) = fault {
        s.faults
            .push(FaultSpec::at_change(f, proto.fault_at_s, change));
    }
    s
}

/// Runs one case and returns the row.
///
/// # Errors
/// Simulator or replay configuration errors.
pub fn run_case(
    params: &ParamFile,
    fault: Fault,
    change: f64,
    proto: &Protocol,
) -> Result<Table1Row, ExperimentError> {
    let sc = scenario(Some((fault, change)), proto);
    let opts = ReplayOptions {
        angle_source: proto.angle_source,
        commission: Some(proto.commission),
        // Table 1's protocol: the paper's fixed viscous load, a Bl change is a fault.
        load: monitor_replay::LoadModel::Viscous,
        // The row's residuals are the timeline's last point: the mean of the run's last
        // RESIDUAL_MEAN_S.
        timeline_step: const { monitor_replay::TimelineStep::of(RESIDUAL_MEAN_S) },
        ..ReplayOptions::default()
    };
    let mut first_lamp: Option<f64> = None;
    let replay = simulate_and_replay(params, params, &sc, opts, |row, out| {
        if first_lamp.is_none() && row.t_s >= proto.fault_at_s && out.lamps.iter().any(|x| *x) {
            first_lamp = Some(row.t_s - proto.fault_at_s);
        }
    })?;
    let names_given = replay
        .isolation_names()
        .iter()
        .map(|g| NameGiven {
            name: g.name,
            t_s: g.t_s - proto.fault_at_s,
        })
        .collect();
    let rep = replay.finish();
    let signature =
        bits((1..=4).map(|k| rep.lamps.get(&format!("r{k}")).copied().unwrap_or(false)));
    let paper = bits(fault.paper_signature());
    let expected = bits(monitor_core::signature::signatures_for(proto.angle_source)[fault.index()]);
    let residuals = rep.timeline.last().map(|p| p.residuals).unwrap_or_default();
    Ok(Table1Row {
        fault,
        change,
        signature,
        paper,
        expected,
        residuals,
        candidates: rep.signature_candidates,
        detection_delay_s: first_lamp,
        named: rep.isolation.named,
        named_change: rep.isolation.named_change,
        isolation_candidates: rep.candidates,
        isolation_state: rep.isolation.state,
        name_delay_s: rep.isolation.first_named.map(|g| g.t_s - proto.fault_at_s),
        names_given,
    })
}

/// Four lamps as 0/1.
fn bits(lamps: impl IntoIterator<Item = bool>) -> [u8; 4] {
    let mut b = [0u8; 4];
    for (s, l) in b.iter_mut().zip(lamps) {
        *s = u8::from(l);
    }
    b
}

/// Runs all 18 cases (in parallel) in Table 1 order, +50 % before -50 %.
///
/// # Errors
/// The first case that failed.
pub fn run_all(
    params: &ParamFile,
    proto: &Protocol,
    on_done: impl Fn() + Sync,
) -> Result<Vec<Table1Row>, ExperimentError> {
    use rayon::prelude::*;
    let cases: Vec<(Fault, f64)> = Fault::ALL
        .iter()
        .flat_map(|f| [(*f, 0.5), (*f, -0.5)])
        .collect();
    cases
        .par_iter()
        .map(|(f, c)| {
            let r = run_case(params, *f, *c, proto);
            on_done();
            r
        })
        .collect()
}

/// One fault candidate in words, the same on the HMI, the demo and `diagnose`'s text
/// (issue 28: one way to write each number): the fault's name, then its probability as
/// `p 0.33` (never a bare percentage, which reads like a size), then, when known, its
/// size signed with the parameter's name in brackets, e.g. `rr p 0.76 (rr +50 %)`.
///
/// `probability` in [0, 1]; `change` a relative parameter change (0.5 = +50 %).
pub fn candidate_text(name: &str, probability: f32, change: Option<f32>) -> String {
    match change {
        Some(x) => format!("{name} p {probability:.2} ({})", size_text(name, x)),
        None => format!("{name} p {probability:.2}"),
    }
}

/// A fault's size signed with the parameter's name, `rs +50 %` (`change` relative, 0.5 =
/// +50 %; under 10 % to a tenth of a per cent, `b/bl +0.5 %`); the form the HMI, the demo
/// and `diagnose`'s timeline use for a size.
pub fn size_text(name: &str, change: f32) -> String {
    // Under 10 % to a tenth of a per cent: "+0 %" would say nothing.
    let digits = usize::from(change.abs() < 0.095);
    format!("{name} {:+.digits$} %", 100.0 * change)
}

/// Fault candidates in words ([`candidate_text`]), with B and Bl as one friction class
/// `b/bl` (their probabilities added, the size Bl's, the size the isolation names for the
/// class): the two cannot be told apart by the residuals, so they are shown once.
/// `candidates` as (fault, probability in [0, 1], relative change if estimated).
pub fn candidates_text(
    candidates: impl IntoIterator<Item = (Fault, f32, Option<f32>)>,
) -> Vec<String> {
    let mut rows: Vec<(&'static str, f32, Option<f32>)> = Vec::new();
    let mut friction: Option<usize> = None;
    for (f, p, change) in candidates {
        if matches!(f, Fault::B | Fault::Bl) {
            if let Some(row) = friction.and_then(|k| rows.get_mut(k)) {
                row.1 += p;
                if f == Fault::Bl {
                    row.2 = change;
                }
                continue;
            }
            friction = Some(rows.len());
            let change = if f == Fault::Bl { change } else { None };
            rows.push((IsolationName::Friction.name(), p, change));
        } else {
            rows.push((f.name(), p, change));
        }
    }
    rows.into_iter()
        .map(|(n, p, c)| candidate_text(n, p, c))
        .collect()
}

#[cfg(test)]
mod text_tests {
    use super::*;

    #[test]
    fn sizes_are_signed_and_probabilities_are_not_percentages() {
        assert_eq!(size_text("rs", 0.5), "rs +50 %");
        assert_eq!(
            candidate_text("rr", 0.76, Some(0.5)),
            "rr p 0.76 (rr +50 %)"
        );
        // B and Bl: one friction class with Bl's size (a Bl +50 % fault reads as B +300 %).
        assert_eq!(
            candidates_text([(Fault::B, 0.5, Some(3.0)), (Fault::Bl, 0.5, Some(0.5))]),
            ["b/bl p 1.00 (b/bl +50 %)"]
        );
    }
}
