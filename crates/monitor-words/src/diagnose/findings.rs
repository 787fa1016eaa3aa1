//! A finding in words: its sentence (`summary`) and its brief phrase for the verdict's
//! lists, spelled from what it rests on ([`Detail`]) and the report's own analyses.

use super::named::{against_text, fault_text};
use super::{commissioning, isolation, rotor, winding};
use monitor_core::verdict::{FindingSource, NamedFault};
use monitor_io::log::quality::MAX_NOT_JUDGED_FRACTION;
use monitor_replay::{Detail, DiagnoseReport, FileMisfit, FindingReport, RangeDeparture};

use crate::spelling::Spelling;
use serde::Serialize;
use std::borrow::Borrow;

/// The finding's sentence (JSON `findings[].summary`).
pub fn summary(f: &FindingReport, rep: &DiagnoseReport, sp: &dyn Spelling) -> String {
    summary_of(&f.detail, rep, sp)
}

/// A finding as a JSON document carries it (`diagnose`'s `findings[]` and
/// `verdict_finding`, `explain`'s `verdict_finding`): its typed values (`source`, `state`,
/// `fault`, ..., `reason`) and beside them its sentence. `F` is
/// the finding, owned ([`FindingReport`]) or lent (`&FindingReport`).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct FindingDoc<F> {
    /// The finding's typed values.
    #[serde(flatten)]
    pub finding: F,
    /// Its sentence ([`summary`]).
    pub summary: String,
}

impl<F: Borrow<FindingReport>> FindingDoc<F> {
    /// The document of `finding`, one of `rep`'s, its sentence in `sp`'s words.
    pub fn new(finding: F, rep: &DiagnoseReport, sp: &dyn Spelling) -> Self {
        let summary = summary(finding.borrow(), rep, sp);
        FindingDoc { finding, summary }
    }
}

/// The isolation's verdict of the report.
fn iso(rep: &DiagnoseReport, sp: &dyn Spelling) -> String {
    isolation::said(&rep.isolation.said, sp)
}

/// The sentence of `detail`, a finding in `rep`.
fn summary_of(detail: &Detail, rep: &DiagnoseReport, sp: &dyn Spelling) -> String {
    match detail {
        Detail::ResidualsSkipped { need } => need.map_or_else(
            || "residuals r1..r4: need the voltages and the speed".to_string(),
            |s| commissioning::skipped(s).to_string(),
        ),
        Detail::ResidualsNotLearned(n) => commissioning::not_learned(n, sp),
        Detail::ResidualsNeverEvaluated => "the lamps were never evaluated (the motor never ran settled and quasi-steady with voltage)".into(),
        Detail::ResidualsTooLittle { judged_s, needed_s } => format!(
            "the lamps were judged on only {judged_s:.2} s of settled, quasi-steady running ({needed_s:.1} s needed): the log is all start or transient, or ends too soon after commissioning"
        ),
        Detail::ResidualsUnsettled(u) => format!(
            "the operating point had not settled over the last {:.2} s of the log (from {:.2} s) \
             while a residual sat at {:.0} times its band: the quasi-steady gate held the lamps there, \
             so a fault cannot be ruled out (the monitor evaluates the lamps regardless once the gate has \
             been closed for its timeout; a longer log, or a steady stretch, is needed to judge)",
            u.held_s, u.since_s, u.worst_bands
        ),
        Detail::Isolation | Detail::LampsForHeating { .. } => iso(rep, sp),
        Detail::LampsForLoadMove => format!(
            "the lamps lit for a load move (to the paper's model a load change is a Bl change): {}",
            iso(rep, sp)
        ),
        Detail::LampsOutOfRange { first_s } => format!(
            "the lamps lit (first at {first_s:.2} s) only while the load or the voltage was outside the range commissioned: the learned means hold only where they were learned; commission over the whole load and voltage range ({})",
            iso(rep, sp)
        ),
        Detail::Winding => winding::summary(&rep.unbalance, sp),
        Detail::Rotor => rotor::summary(&rep.rotor),
        Detail::OperatingPointUnavailable => {
            "the load and the heating need the voltages and the speed".into()
        }
        Detail::Steady => "steady: no load move, no heating".into(),
        Detail::NoLoadMoveHeatingUnread => {
            "no load move; the heating not read (no steady operating point with voltage was judged)".into()
        }
        Detail::OperatingPointMoved {
            outside,
            load_moves,
            rise_k,
        } => operating_point_moved(outside.as_deref(), *load_moves, *rise_k, rep),
        Detail::Commissioned => "commissioned: the residuals are judged against the healthy motor learned in commissioning, not the file's values".into(),
        Detail::ParameterFitUnavailable => {
            "the residuals against the file need the voltages and the speed".into()
        }
        Detail::FileFits => {
            "the residuals against the file's nominal values stay within their fixed thresholds"
                .into()
        }
        Detail::FileMisfit(m) => format!(
            "the parameter file does not fit this log, or a fault was there from its start: the two look the same here \
             (commission on the healthy motor, or identify it from a healthy log): {}",
            file_misfit(m, rep, sp)
        ),
        Detail::MachineFit(f) => super::machine_fit::summary(f),
        Detail::DataNotTrusted => format!(
            "data quality: {}",
            rep.data_quality.not_trusted_because.join("; ")
        ),
        Detail::DataNotJudged {
            unjudged_s,
            duration_s,
        } => format!(
            "{unjudged_s:.2} s of the {duration_s:.2} s log could not be judged (over {:.0} %): {}",
            100.0 * MAX_NOT_JUDGED_FRACTION,
            rep.data_quality
                .not_judged
                .iter()
                .map(|n| format!("{:.2}..{:.2} s, {}", n.from_s, n.to_s, n.why))
                .collect::<Vec<_>>()
                .join("; ")
        ),
        Detail::DataClean => format!("data quality: {}", rep.data_quality.summary()),
        Detail::ImpossibleReadings {
            current,
            voltage,
            speed,
        } => {
            let which: Vec<&str> = [
                (*current, "current"),
                (*voltage, "voltage"),
                (*speed, "speed (encoder)"),
            ]
            .into_iter()
            .filter_map(|(on, w)| on.then_some(w))
            .collect();
            format!(
                "the {} sensor readings at the end of the log are impossible for any machine (not a number, saturated, phases not summing to zero, or an encoder jump): check the sensors and their wiring; the motor cannot be judged from them",
                which.join(" and ")
            )
        }
        Detail::Distrusted { why, read } => format!(
            "not judged ({}); it read: {}",
            summary_of(why, rep, sp),
            summary_of(read, rep, sp)
        ),
    }
}

/// The sentence of an operating point that moved: outside the commissioned range at the end
/// (`outside`), the load's moves, the windings' rise [K] (since commissioning, or against
/// the file).
fn operating_point_moved(
    outside: Option<&[RangeDeparture]>,
    load_moves: usize,
    rise_k: Option<f32>,
    rep: &DiagnoseReport,
) -> String {
    let mut said = Vec::new();
    if let Some(d) = outside {
        said.push(format!(
            "outside the commissioned range at the end: {}",
            isolation::moved_note(d)
        ));
    }
    if load_moves > 0 {
        said.push(format!(
            "the load moved {load_moves} time{}",
            if load_moves == 1 { "" } else { "s" }
        ));
    }
    if let Some(rise) = rise_k {
        said.push(if commissioned(rep) {
            format!("the windings warmed by {rise:.0} K since commissioning")
        } else {
            format!("the windings are about {rise:.0} K warmer than the parameter file assumes")
        });
    }
    said.join("; ")
}

/// Whether the residuals were judged against a commissioned baseline.
fn commissioned(rep: &DiagnoseReport) -> bool {
    rep.findings.iter().any(|f| {
        f.source() == FindingSource::Residuals
            && f.finding.against == monitor_core::verdict::Against::Commissioning
    })
}

/// Why the parameter file does not fit the log.
fn file_misfit(m: &FileMisfit, rep: &DiagnoseReport, sp: &dyn Spelling) -> String {
    let within = |n: &NamedFault| {
        format!(
            "the nearest single fault, {}, is within the file's own uncertainty (+/-{:.0} %); a file 10-30 % off the machine, or windings 60 K warmer than the file assumes, move the residuals this much",
            fault_text(n),
            100.0 * monitor_core::isolation::NOMINAL_UNCERTAINTY
        )
    };
    match m {
        FileMisfit::NearestWithinFile { named } => within(named),
        FileMisfit::Isolation => iso(rep, sp),
        FileMisfit::FirstPoint(p) => commissioning::first_point_misfit(p, sp),
    }
}

/// The finding's brief phrase for the verdict's lists: what was judged and against what
/// (`residuals against commissioning`), or, for a finding not judged, why.
pub fn brief(f: &FindingReport, rep: &DiagnoseReport, sp: &dyn Spelling) -> String {
    let source = f.source();
    let against = f.finding.against;
    let residuals = || {
        format!(
            "residuals {}",
            against_text(FindingSource::Residuals, against)
        )
    };
    match &f.detail {
        Detail::Distrusted { why, .. } => {
            format!("{}: {}", source.name(), summary_of(why, rep, sp))
        }
        Detail::ResidualsSkipped { .. }
        | Detail::ResidualsNotLearned(_)
        | Detail::ResidualsNeverEvaluated
        | Detail::ResidualsTooLittle { .. }
        | Detail::ResidualsUnsettled(_) => format!("residuals: {}", summary(f, rep, sp)),
        Detail::LampsForHeating { rise_k } => format!(
            "{} (the lamps lit for {}, not a fault)",
            residuals(),
            rise_k.map_or("heating".to_string(), |k| format!("{k:.0} K of heating"))
        ),
        Detail::LampsForLoadMove => {
            format!(
                "{} (the lamps lit for a load move, not a fault)",
                residuals()
            )
        }
        Detail::Isolation => format!("{}{}", residuals(), super::machine_fit::reach(rep, against)),
        Detail::LampsOutOfRange { .. } => residuals(),
        Detail::Winding => winding::brief(&rep.unbalance, against, sp),
        Detail::Rotor => rotor::brief(&rep.rotor),
        Detail::OperatingPointUnavailable
        | Detail::Steady
        | Detail::NoLoadMoveHeatingUnread
        | Detail::OperatingPointMoved { .. } => "operating point".into(),
        Detail::Commissioned
        | Detail::ParameterFitUnavailable
        | Detail::FileFits
        | Detail::FileMisfit(_)
        | Detail::MachineFit(_) => "parameter file".into(),
        Detail::DataNotTrusted
        | Detail::DataNotJudged { .. }
        | Detail::DataClean
        | Detail::ImpossibleReadings { .. } => "data quality".into(),
    }
}
