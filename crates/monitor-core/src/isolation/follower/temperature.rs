//! The follower's view of the winding's temperature (module docs of
//! [`crate::isolation`], "Heating is not a fault", "How sure a name is"): heating taken into
//! the machine with the rate it was seen at, when the temperature counts as judged, and a
//! change inside an average found beyond what the winding can have warmed.

use super::{
    Follower, Isolation, SteadyPoint, AVERAGE_MAX_S, AVERAGE_S, BLOCKS, PROBE_LAG_K, STEP_S,
};

impl Follower {
    /// Takes a further heating of factor `k` into the machine ([`Follower::track`]) and
    /// notes how fast the winding warmed: the step over the time since the last tracking.
    pub(super) fn track_with_rate(&mut self, k: f32) {
        let before = self.isolator.winding_rise_k();
        self.track(k);
        let step = (self.isolator.winding_rise_k() - before).abs();
        let rate = step / crate::math::maxf(self.since_tracked_s, STEP_S);
        if rate.is_finite() {
            self.warming_k_per_s = crate::math::maxf(rate, crate::isolation::HEATING_DRIFT_K_PER_S);
        }
        self.since_tracked_s = 0.0;
    }

    /// After the isolation `result` of `point` (averaged with the spread scale `scale`;
    /// `tracked`: heating was taken into the machine): the winding's temperature is judged
    /// where the machine at it fits (no deviation, or one the friction class explains with
    /// the stator-voltage equations within the healthy scatter: the load moved), where
    /// heating was tracked, and all the time with a temperature channel (the reach of the
    /// heating hypothesis grows with the time since: [`Isolator::set_heating_reach_k`]).
    pub(super) fn note_temperature(
        &mut self,
        (result, point, scale): (&Isolation, &SteadyPoint, f32),
        tracked: bool,
    ) {
        // (The load's move: the friction class named, and the stator-voltage equations
        // alone within the healthy scatter at the point.)
        let friction = matches!(
            result.named(),
            Some(crate::isolation::Named::Friction { .. })
        );
        let load_moved = friction
            && self
                .isolator
                .isolate_points_anchored_from(
                    core::slice::from_ref(&(*point, scale)),
                    None,
                    &mut self.voltage_hints,
                )
                .state
                == crate::isolation::IsolationState::NoDeviation;
        let fits = result.state == crate::isolation::IsolationState::NoDeviation || load_moved;
        if tracked || fits || self.measured_rise_k.is_some() {
            self.since_judged_s = 0.0;
        }
    }

    /// Takes a further heating of factor `k` into the machine judged against: the whole of
    /// it without a measured rise, else only the probe's lag within +-[`PROBE_LAG_K`] of
    /// the measured rise ([`Follower::set_measured_rise_k`]).
    pub(super) fn track(&mut self, k: f32) {
        let Some(measured) = self.measured_rise_k else {
            self.isolator.track_heating(k);
            return;
        };
        let wanted =
            (self.isolator.heating_factor() * k - 1.0) / crate::isolation::COPPER_ALPHA_PER_K;
        let lag = crate::math::minf(
            crate::math::maxf(wanted - measured, -PROBE_LAG_K),
            PROBE_LAG_K,
        );
        if lag.is_finite() && self.isolator.set_winding_rise_k(measured + lag) {
            self.probe_lag_k = lag;
        }
    }

    /// The average holds a change (module docs, "Settling, and the onset of a deviation"):
    /// once it spans at least twice [`AVERAGE_S`], the residuals of its older and newer
    /// halves differ by more than the healthy scatter allows
    /// ([`Isolator::changed_between`]).
    pub(super) fn changed_within(&self) -> bool {
        let half = self.filled / 2;
        if (half as f32) * STEP_S < AVERAGE_S - 0.5 * STEP_S {
            return false;
        }
        // The filled blocks are the `filled` slots before `next`, newest first.
        let mean_of = |from: usize, n: usize| {
            let mut sum = SteadyPoint::default();
            for k in from..from + n {
                let slot = (self.next + BLOCKS - 1 - k) % BLOCKS;
                if let Some(b) = self.blocks.get(slot) {
                    sum.add_scaled(b, 1.0);
                }
            }
            sum.scale(1.0 / n as f32);
            sum
        };
        let (newer, older) = (mean_of(0, half), mean_of(half, half));
        let span_s = half as f32 * STEP_S;
        let scale = crate::math::sqrt(AVERAGE_MAX_S / span_s);
        // (The halves' means are a half's span apart: the winding may have warmed as fast as
        // a winding can in that time.)
        let warming_k = crate::isolation::HEATING_RATE_K_PER_S * span_s;
        self.isolator
            .changed_between((&older, &newer), scale, warming_k)
    }
}
