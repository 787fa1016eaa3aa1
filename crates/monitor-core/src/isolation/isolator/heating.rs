//! The heating hypothesis of the isolator (module docs of [`crate::isolation`], "Heating is
//! not a fault"): its reach since the temperature was last judged, its fit, a fault's fit
//! with the tracked temperature's lag, and the change within an average across the heating
//! direction.

use super::*;
use search::{fit_factor, golden};

impl Isolator {
    /// How far the winding's temperature can have moved since it was last judged (a point
    /// found healthy, or heating tracked), `since_s` [s] ago, the winding last seen warming
    /// at `rate_k_per_s` [K/s] (values that are not positive numbers count as 0). Heating is
    /// bounded to a further rise or fall of [`HEATING_ONSET_K`] plus
    /// [`HEATING_RATE_K_PER_S`] times `since_s`: a deviation that needs more heating than a
    /// winding can gain in the time is a step, a fault, and heating does not take part in
    /// the ranking (its fit within the bound misses). A fault is fitted with the tracked
    /// temperature's lag allowed for, one standard deviation [`HEATING_LAG_SIGMA_K`] (on a
    /// machine whose warming was tracked) plus `rate_k_per_s` times `since_s` (module docs,
    /// "Heating is not a fault").
    pub fn set_heating_reach_k(&mut self, since_s: f32, rate_k_per_s: f32) {
        let positive = |x: f32| if x > 0.0 && x.is_finite() { x } else { 0.0 };
        let (since, rate) = (positive(since_s), positive(rate_k_per_s));
        self.heating_reach_k = HEATING_ONSET_K + HEATING_RATE_K_PER_S * since;
        // A winding that never warmed since commissioning lags only by what it may have
        // gained since it was last judged.
        let warm = (self.heating_factor - 1.0).abs() >= COPPER_ALPHA_PER_K;
        let base = if warm { HEATING_LAG_SIGMA_K } else { 0.0 };
        self.lag_sigma_k = crate::math::minf(base + rate * since, self.heating_reach_k);
    }

    /// The heating hypothesis' range of factors relative to the tracked machine: the whole
    /// [`HEATING_K_MIN`]..[`HEATING_K_MAX`], within the reach
    /// ([`Isolator::set_heating_reach_k`]).
    pub(super) fn heating_range(&self) -> (f32, f32) {
        let reach = COPPER_ALPHA_PER_K * self.heating_reach_k;
        let (lo, hi) = (
            HEATING_K_MIN / self.heating_factor,
            HEATING_K_MAX / self.heating_factor,
        );
        if reach.is_finite() {
            (
                crate::math::maxf(lo, 1.0 - reach),
                crate::math::minf(hi, 1.0 + reach),
            )
        } else {
            (lo, hi)
        }
    }

    /// The heating hypothesis' best factor `k` (Rs and Rr of the tracked machine both times
    /// `k`, the total within [`HEATING_K_MIN`]..[`HEATING_K_MAX`]): golden section (the
    /// misfit is unimodal over so narrow a range). Returns `(chi2, k)`.
    #[inline(never)]
    pub(super) fn fit_heating(&self, r: &Reading, w: &Sym3) -> (f32, f32) {
        let (lo, hi) = self.heating_range();
        golden(
            |k| self.warmer(k).chi2_at(r, None, w),
            lo,
            hi,
            HEATING_STEPS,
        )
    }

    /// This isolator with the tracked winding `k` times warmer (Rs and Rr times `k`).
    pub(super) fn warmer(&self, k: f32) -> Isolator {
        let mut t = *self;
        t.heating_factor *= k;
        t
    }

    /// Fault `f`'s fit on a warm machine (one whose heating was tracked): the tracked
    /// temperature lags the winding's (the tracking follows only deviations the isolation
    /// detects), and a fault judged against a lagging temperature would carry the lag into
    /// its direction. The lag is a second, penalised parameter: the misfit adds
    /// `(lag / HEATING_LAG_SIGMA_K)^2` (the tracked temperature's own uncertainty as a
    /// prior), within +-[`HEATING_LAG_K`]. Two rounds of alternating fits, the lag for the
    /// fault's size, then the size on the machine so warmed; returns the better of
    /// `(chi2, k)` and `single`. `hint`: the single fit's grid point, where the size
    /// searches start ([`SearchHints`]).
    #[inline(never)]
    pub(super) fn fit_on_warm(
        &self,
        r: &Reading,
        f: Fault,
        w: &Sym3,
        (single, hint): ((f32, f32), u8),
    ) -> (f32, f32) {
        if !(self.lag_sigma_k > 0.0) {
            return single;
        }
        let lag_max = crate::math::minf(self.heating_reach_k, HEATING_LAG_K * self.lag_sigma_k);
        let d = lag_max * COPPER_ALPHA_PER_K;
        let prior = |k: f32| {
            let lag = (k - 1.0) / (COPPER_ALPHA_PER_K * self.lag_sigma_k);
            lag * lag
        };
        let mut best = single;
        let mut kf = single.1;
        let mut hint = hint;
        for _ in 0..2 {
            let (_, kh) = golden(
                |k| self.warmer(k).chi2_at(r, Some((f, kf)), w) + prior(k),
                1.0 - d,
                1.0 + d,
                LAG_STEPS,
            );
            let ((c, k), next) = self.warmer(kh).fit(r, f, w, hint);
            hint = next;
            kf = k;
            if c + prior(kh) < best.0 {
                best = (c + prior(kh), k);
            }
        }
        best
    }

    /// The winding's temperature is not known: no learned baseline is in force, so the
    /// machine is judged against the parameter file's values, whose temperature the
    /// winding need not have (a motor in service runs 20-100 K above it), and no channel
    /// measures it (a measured rise is in force only after commissioning). Then a fault is
    /// fitted on a machine at any temperature of the heating range
    /// ([`Isolator::fits_beyond_heating`]; module docs, "The temperature unknown").
    pub(super) fn temperature_unknown(&self) -> bool {
        !self.learned_point()
    }

    /// Fault `f`'s fit on a winding of unknown temperature (module docs of
    /// [`crate::isolation`], "The temperature unknown"): the size `k` and the heating factor
    /// (Rs and Rr both times it, within [`Isolator::heating_range`]) fitted together, the
    /// misfit of hypothesis `(f, k)` on the isolator `warm` given by `misfit(warm, f, k)`.
    /// Golden section over the heating factor ([`FREE_STEPS`]) of the size's best fit
    /// ([`fit_factor`], each started from the last one's grid point); returns `(chi2, k)`
    /// and the hint for the next search. `hint`: where the size search starts.
    #[inline(never)]
    pub(super) fn fit_at_any_temperature(
        &self,
        f: Fault,
        misfit: impl Fn(&Isolator, Fault, f32) -> f32,
        hint: u8,
    ) -> ((f32, f32), u8) {
        let (lo, hi) = self.heating_range();
        let best = core::cell::Cell::new((f32::INFINITY, 1.0f32));
        let next = core::cell::Cell::new(hint);
        let _ = golden(
            |kh| {
                let warm = self.warmer(kh);
                let (found, h) = fit_factor(|k| misfit(&warm, f, k), next.get());
                next.set(h);
                if found.0 < best.get().0 {
                    best.set(found);
                }
                found.0
            },
            lo,
            hi,
            FREE_STEPS,
        );
        (best.get(), next.get())
    }

    /// The faults' fits on a winding of unknown temperature (module docs of
    /// [`crate::isolation`], "The temperature unknown"): each fault's `fits` (its fit at the
    /// tracked temperature, replaced by [`Isolator::fit_at_any_temperature`]'s where that is
    /// better), and which of them are seen beyond the heating: where the fault on top of
    /// the winding's best heating `heat` lowers the misfit by at least [`DETECT_CHI2`] (a
    /// change beyond the heated machine detected, as a deviation from the healthy one is).
    /// The others explain nothing the heating alone does not, and take no part in the
    /// ranking. `misfit(warm, f, k)`: the misfit of `(f, k)` on the isolator `warm`;
    /// `hints`: where the size searches start, and whether they are used.
    pub(super) fn fits_beyond_heating(
        &self,
        fits: &mut [(f32, f32); FAULT_COUNT],
        heat: (f32, f32),
        misfit: impl Fn(&Isolator, Fault, f32) -> f32,
        (hints, use_hints): (&SearchHints, bool),
    ) -> [bool; FAULT_COUNT] {
        let mut seen = [false; FAULT_COUNT];
        for ((fit, f), s) in fits.iter_mut().zip(Fault::ALL).zip(seen.iter_mut()) {
            let (free, _) = self.fit_at_any_temperature(f, &misfit, hints.get(f, use_hints));
            if free.0 < fit.0 {
                *fit = free;
            }
            *s = heat.0 - fit.0 >= DETECT_CHI2;
        }
        seen
    }

    /// The residuals at `newer` differ from those at `older` (two means of the same
    /// operating point's blocks, each's spreads the baseline's times `spread_scale`) by more
    /// than the healthy scatter allows: the difference, less a warming of at most
    /// `warming_k` [K] along the heating direction (a winding that warms moves them that
    /// way), has a misfit of [`DETECT_CHI2`] or more under the two means' spreads together.
    /// False where either gives no residuals.
    pub fn changed_between(
        &self,
        (older, newer): (&SteadyPoint, &SteadyPoint),
        spread_scale: f32,
        warming_k: f32,
    ) -> bool {
        let (Some(a), Some(b)) = (self.residuals(older, None), self.residuals(newer, None)) else {
            return false;
        };
        let Some(h) = self.warmer(1.0 + COPPER_ALPHA_PER_K).residuals(newer, None) else {
            return false;
        };
        // Whitened by both means' spreads: sqrt(2) times one's.
        let s = self
            .baseline
            .spread
            .map(|x| x * core::f32::consts::SQRT_2 * crate::math::maxf(spread_scale, 1.0));
        let d = (b - a).zip_map(s, |x, y| x / y).to_array();
        // The heating direction per kelvin.
        let h = (h - b).zip_map(s, |x, y| x / y).to_array();
        let dot = |x: &[f32; 3], y: &[f32; 3]| x.iter().zip(y).map(|(u, v)| u * v).sum::<f32>();
        let hh = dot(&h, &h);
        let reach = if warming_k > 0.0 { warming_k } else { 0.0 };
        let along = if hh > 0.0 {
            crate::math::minf(crate::math::maxf(dot(&d, &h) / hh, -reach), reach)
        } else {
            0.0
        };
        let rest = d
            .iter()
            .zip(h)
            .map(|(x, y)| (x - along * y) * (x - along * y))
            .sum::<f32>();
        rest >= DETECT_CHI2
    }
}

/// Golden-section steps of the heating fit: its bracket (0.90..1.63 of the tracked factor)
/// shrunk by 0.618^20, to 1e-4 of the factor (0.03 K).
pub(super) const HEATING_STEPS: usize = 20;
/// How far the tracked winding temperature may lag the winding's when a fault is fitted,
/// in standard deviations of the lag ([`Isolator::set_heating_reach_k`]).
const HEATING_LAG_K: f32 = 3.0;
/// One standard deviation of the tracked temperature's lag [K]: the prior of a fault's fit
/// on a warm machine ([`Isolator::fit_on_warm`]); 3 K, the lag measured on the 3 hp motor
/// warming 60 K with a 10 s time constant.
pub const HEATING_LAG_SIGMA_K: f32 = 3.0;
/// Golden-section steps of the lag's fit: +-10 K shrunk by 0.618^12, to 0.07 K.
const LAG_STEPS: usize = 12;
/// Golden-section steps of the heating factor in a fault's fit on a winding of unknown
/// temperature ([`Isolator::fit_at_any_temperature`]): the heating range (0.90..1.63 of the
/// file's resistances) shrunk by 0.618^14, to 1e-3 of the factor (0.3 K).
const FREE_STEPS: usize = 14;
