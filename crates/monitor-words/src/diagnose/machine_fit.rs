//! The machine fitted to the log against the parameter file, and the reach of the
//! residuals a "healthy" carries: how large a change of a fault they would have named on
//! this log.

use super::named::pct;
use monitor_core::isolation::NOMINAL_UNCERTAINTY;
use monitor_core::verdict::{Against, FindingSource};
use monitor_replay::{Detail, DiagnoseReport, FitParameter, StartFit};

/// A fitted parameter's name.
fn name(p: FitParameter) -> &'static str {
    match p {
        FitParameter::Rs => "Rs",
        FitParameter::Rr => "Rr",
        FitParameter::Leakage => "the leakage",
        FitParameter::Lm => "Lm",
    }
}

/// The parameter fit's sentence: a fault present from the start, or the machine on the
/// file, with the window and each parameter's change.
pub(super) fn summary(f: &StartFit) -> String {
    let changes: Vec<String> = f
        .changes
        .iter()
        .map(|c| format!("{} {}", name(c.parameter), pct(c.change)))
        .collect();
    let head = format!(
        "the machine fitted to {:.1}..{:.1} s of the log (a start or a load change)",
        f.from_s, f.to_s
    );
    match f.named() {
        Some(_) => format!(
            "{head} departs from the file in one parameter beyond its +/-{:.0} %: {}: a fault present from the start",
            100.0 * NOMINAL_UNCERTAINTY,
            changes.join(", ")
        ),
        None => format!("{head} is the file's: {}", changes.join(", ")),
    }
}

/// The residuals' reach on this log, in brackets after "residuals against ..." (nothing
/// where there is none to say): [`reach_text`].
pub(super) fn reach(rep: &DiagnoseReport, against: Against) -> String {
    reach_text(rep, against).map_or(String::new(), |r| format!(" (reach: {r})"))
}

/// The residuals' reach on this log: against commissioning, the largest of the
/// isolation's detection limits (the smallest change of each fault it names at the
/// commissioned point); against the file, how far the machine fitted to the log is the
/// file's, or that a fault present from the start shows only as far as the file is the
/// machine's. `None` against anything else, or without detection limits.
pub fn reach_text(rep: &DiagnoseReport, against: Against) -> Option<String> {
    match against {
        Against::Commissioning => {
            let mut limits = rep.isolation.detection_limits.clone();
            limits.sort_by(|a, b| b.change.total_cmp(&a.change));
            limits.first().map(|l| {
                format!(
                    "a fault named from {} in {}, less in the others",
                    pct(l.change).trim_start_matches('+'),
                    l.fault.name()
                )
            })
        }
        Against::ParameterFile => {
            let fit = rep.findings.iter().find_map(|f| match &f.detail {
                Detail::MachineFit(m) if f.source() == FindingSource::ParameterFit => Some(m),
                _ => None,
            });
            Some(match fit.filter(|m| m.on_file()) {
                Some(m) => {
                    let widest = m.changes.iter().map(|c| c.reach()).fold(0.0f32, f32::max);
                    format!(
                        "the machine fitted to the log's start is the file's within {}: a fault present from the start beyond that would show",
                        pct(widest).trim_start_matches('+')
                    )
                }
                None => format!(
                    "a fault present from the start within +/-{:.0} % of the file's values is not told from the file's own error; commission, or log a start",
                    100.0 * NOMINAL_UNCERTAINTY
                ),
            })
        }
        _ => None,
    }
}

/// What a healthy verdict could not see on this log, for a fleet's row: the residuals'
/// reach ([`reach_text`]) where the verdict is healthy, else `None`.
pub fn not_seen(rep: &DiagnoseReport) -> Option<String> {
    if rep.verdict != monitor_replay::Verdict::Healthy {
        return None;
    }
    let residuals = rep
        .findings
        .iter()
        .find(|f| f.source() == FindingSource::Residuals && !f.judged_nothing())?;
    reach_text(rep, residuals.finding.against)
}
