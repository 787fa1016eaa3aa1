//! Stage 6 of `explain` (rank): the fitted candidates in order, and what the order says
//! (nothing left to explain, or nothing explained well enough).

use super::baseline::FullSeries;
use super::{EffectCandidate, Standing, EXPLAINED_MIN, EXPLAINS_MIN, NOISE_MARGIN, PARAM_PENALTY};
use crate::effects::{self, EffectEvidence, FitSetup};
use crate::fit::FitResult;
use crate::unbalance::UnbalanceAnalysis;

/// A ranked candidate with its fit, kept to rebuild the best one's prediction.
pub(super) struct RankedCandidate {
    /// The report's entry.
    pub(super) candidate: EffectCandidate,
    /// The fit of the configured model with the candidate.
    pub(super) fit: FitResult,
    /// The set-ups on the working series, in the model's order (the candidate last).
    pub(super) setups: Vec<FitSetup>,
}

impl RankedCandidate {
    /// Held-back error with each extra parameter costing [`PARAM_PENALTY`] of it.
    pub(super) fn score(&self) -> f64 {
        let c = &self.candidate;
        c.validation_normalized_rms_error * (1.0 + PARAM_PENALTY * c.n_parameters as f64)
    }
}

/// What the ranking says: whether the model's error is already at the noise floor, and
/// whether no plausible candidate explains enough of it.
#[derive(Debug, Clone, Copy)]
pub(super) struct CandidateOutcome {
    /// The configured model's whole-log error is within [`NOISE_MARGIN`] of the whole-log
    /// noise floor and its held-back error within [`NOISE_MARGIN`] of the held-back floor:
    /// nothing to explain. One of the two within the band is not enough.
    pub(super) near_noise: bool,
    /// No plausible candidate first explains [`EXPLAINED_MIN`] of the held-back error (or
    /// there is nothing to explain).
    pub(super) unexplained: bool,
}

impl CandidateOutcome {
    /// The outcome of the ranking `ranked` (best first) against the configured model's
    /// measures `full`.
    pub(super) fn of(ranked: &[RankedCandidate], full: &FullSeries) -> Self {
        let best = ranked
            .first()
            .filter(|c| c.candidate.plausible)
            .map(|c| c.candidate.explained_fraction)
            .unwrap_or(0.0);
        let near_noise = full.error <= NOISE_MARGIN * full.noise
            && full.heldback_error <= NOISE_MARGIN * full.heldback_noise;
        CandidateOutcome {
            near_noise,
            unexplained: best < EXPLAINED_MIN || near_noise,
        }
    }
}

/// Ranks by held-back error, each extra parameter costing [`PARAM_PENALTY`] of it,
/// plausible candidates first; then, when the first two are effects that declare each other
/// confusable ([`effects::EffectModel::confused_with`]) and are within the declared
/// factor, the log's evidence ([`effects::EffectModel::evidence`]) decides: a first one it
/// contradicts goes second unless it contradicts the other too. No rule names a particular
/// effect.
pub(super) fn rank(
    ranked: &mut [RankedCandidate],
    unbalance: &UnbalanceAnalysis,
    torque_scale_nm: f64,
) {
    ranked.sort_by(|a, b| {
        b.candidate
            .plausible
            .cmp(&a.candidate.plausible)
            .then(a.score().total_cmp(&b.score()))
            .then(a.candidate.n_parameters.cmp(&b.candidate.n_parameters))
    });
    // Only ever reorders two plausible candidates.
    if ranked.len() < 2 || !ranked[1].candidate.plausible {
        return;
    }
    let (first, second) = (&ranked[0], &ranked[1]);
    // A user's law declares no confusion: only the library's effects are reordered.
    let Some(model) = effects::model_of(first.candidate.effect) else {
        return;
    };
    let Some(conf) = model
        .confused_with()
        .iter()
        .find(|c| c.with == second.candidate.effect)
    else {
        return;
    };
    if second.score() > conf.within * first.score() {
        return;
    }
    let says = |r: &RankedCandidate| {
        let fitted = r.fit.reported().last().map(Vec::as_slice).unwrap_or(&[]);
        effects::model_of(r.candidate.effect).and_then(|m| {
            m.evidence(&EffectEvidence {
                voltage_unbalance: unbalance.voltage_negative_sequence_ratio,
                winding_suspected: unbalance.suspect_phase.is_some(),
                torque_scale_nm,
                fitted,
            })
        })
    };
    if says(first) == Some(false) && says(second) != Some(false) {
        ranked.swap(0, 1);
    }
}

/// Each candidate's standing, in the order of [`rank`]: a plausible fit that explains at
/// least [`EXPLAINS_MIN`] of the held-back error is a candidate and gets its rank (1, 2,
/// ...); a plausible one that explains less has no effect on this log; an implausible one
/// is not plausible whatever it explains. The candidates first, then those without effect,
/// then the implausible ones (each group in the ranking's order), so that an implausible
/// fit never stands ahead of a plausible one.
pub(super) fn stand(ranked: &mut [RankedCandidate]) {
    for r in ranked.iter_mut() {
        let c = &mut r.candidate;
        c.standing = if !c.plausible {
            Standing::NotPlausible
        } else if c.explained_fraction >= EXPLAINS_MIN {
            Standing::Candidate
        } else {
            Standing::NoEffect
        };
    }
    ranked.sort_by_key(|r| r.candidate.standing);
    let mut k = 0;
    for r in ranked.iter_mut() {
        r.candidate.rank = (r.candidate.standing == Standing::Candidate).then(|| {
            k += 1;
            k
        });
    }
}

#[cfg(test)]
mod tests {
    use super::{CandidateOutcome, FullSeries};
    use crate::simplified_model::Prediction;

    fn full(error: f64, noise: f64, heldback_error: f64, heldback_noise: f64) -> FullSeries {
        FullSeries {
            before: Prediction::default(),
            error,
            heldback_error,
            noise,
            heldback_noise,
        }
    }

    #[test]
    fn nothing_to_explain_needs_both_errors_within_the_band() {
        let near = |f: &FullSeries| CandidateOutcome::of(&[], f).near_noise;
        // Both within 1.12x their floors, however small or large the numbers.
        assert!(near(&full(0.0021, 0.0020, 0.0023, 0.0022)));
        assert!(near(&full(0.011, 0.010, 0.020, 0.019)));
        // The issue-62 example: the whole log 13x its floor, the held-back part near its
        // own (and under the former 0.004 cut-off): something to explain.
        assert!(!near(&full(0.0242, 0.0019, 0.0021, 0.0020)));
        // The held-back error beyond the band, the whole log within it.
        assert!(!near(&full(0.0021, 0.0020, 0.0030, 0.0022)));
        // A tiny error far above a tiny floor (a noise-free log) is no floor.
        assert!(!near(&full(0.0010, 0.0001, 0.0010, 0.0001)));
    }
}
