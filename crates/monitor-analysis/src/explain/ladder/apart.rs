//! What the log cannot tell apart: two load laws of the chosen model that fit it only as
//! one load torque of speed ([`AsOne`]), and an effect of the chosen model that a
//! confusable one of the library fits as well in its place ([`Alike`]).
//!
//! Two laws of the shaft's torque of speed alone (windage `k w |w|`, dry friction, a load
//! torque of one level, a user's law of `w`) trade with each other over the speeds a log
//! visits: over a start and a variac's steps, `k w |w|` less a constant of -3 N m follows a
//! pump's `k |w|^2.7` closely enough that each of the two passes the step's test, and the
//! ladder keeps both. Neither is then a finding: the log shows one load torque of speed,
//! and the library's laws are two pieces of it.
//!
//! So the ladder's end fits the law [`monitor_laws::library::speed_power`],
//! `T_ref (|w| / w_ref)^n sign(w)` (the family of windage, `n = 2`, a viscous load, `n = 1`,
//! and a constant torque on a shaft that turns one way, `n = 0`), in place of each pair of
//! load laws of its model, with the base parameters free as in the final fit. Where that
//! one law of two parameters explains the log as well as the pair (its error beyond the
//! noise floor at most [`AS_ONE_WITHIN`] more than the pair's, or within the band the ladder
//! stops in, [`super::rules::FLOOR_BAND`]), the pair is reported as one
//! ([`AsOne`]), with the exponent the log shows and the torque at synchronous speed: the
//! law a user writes (`--laws`) when the library lacks it. A pair the one law cannot
//! follow (a constant load beside a fan over a start: the load at standstill is no power
//! of speed; a load that steps) stays two findings.
//!
//! The library declares which of its effects are confusable and what kind of log tells
//! them apart ([`crate::effects::Confusion`]: a constant load torque and dry friction, by a
//! reversal; a winding's asymmetry and a supply's unbalance, by two supply phases
//! exchanged). For each effect of the chosen model with such a partner outside it, the end
//! fits the model with the partner in its place; where the partner's values are plausible
//! and it fits the log as well (the same [`AS_ONE_WITHIN`]), the two are said to fit this
//! log alike, with what would tell them apart ([`Alike`]). The ladder's choice stands (its
//! values are the ones reported); the other reading is named beside it.
//!
//! A base change can stand in for an effect the same way ([`super::rules::IN_PLACE_OF_BASE`]):
//! a fan's `k w |w|` carried as viscous friction, `B + Bl` twenty times the file's, with the
//! inertia and the rotor resistance moved beside it to bend `B w` towards `k w²` over the
//! start. The round that tried windage judged it beside that `B + Bl` and found it removed
//! little. So the end fits, for each such change, the chosen model with the effect added
//! and the parameter held at the file's value (one value for one); where the effect's
//! values are plausible and it fits the log as well (the same test), the change is no
//! finding, and the effect is named in its place with what tells the two apart ([`InPlace`]).

use super::climb::Ladder;
use super::report::{Alike, AsOne, InPlace};
use super::rules::{AS_ONE_WITHIN, IN_PLACE_OF_BASE, STEP_MIN};
use super::rung::nested_from;
use crate::analysis::{Analysis, AnalysisError, FittedEffect};
use crate::effects::{sync_speed_mech, EffectModel, LawEffect};
use crate::fit::machine::BaseKey;
use crate::fit::machine::MachineFit;
use crate::metrics::Weights;
use crate::prep::Prepared;
use monitor_laws::library::{speed_power, speed_power_nm, SPEED_POWER_REF_RAD_S};
use monitor_laws::EffectId;
use std::sync::Arc;

/// Exponents this close to the law's bounds (0 and 5) are the fit's limits, not a reading.
const EXPONENT_MARGIN: f64 = 0.05;

/// True when a model whose whole-log error is `e` fits the log as well as one at `error`
/// (both over the floor `noise`): its error beyond the floor at most [`AS_ONE_WITHIN`]
/// more, or within the band the ladder stops in (`band`, [`super::rules::FLOOR_BAND`] on a log of up to
/// [`super::rules::BAND_PERIODS`] supply periods): at the floor the log cannot choose
/// (kw7p5_coulomb: 1.02x with dry friction, 1.023x with a constant torque in its place, 28 %
/// more of a sliver beyond the floor).
fn as_well(e: f64, error: f64, noise: f64, band: f64) -> bool {
    e.is_finite()
        && ((e - noise) <= (1.0 + AS_ONE_WITHIN) * (error - noise).max(0.0) || e / noise <= band)
}

impl Ladder<'_> {
    /// The chosen model (fitted as `mf` on `fdata`, set up on `an`) without its effects at
    /// `drop`, with `add` last (from `start`, or from its own starts), refitted as the final
    /// fit is (the base parameters free, no half-widths): its whole-log error, its effects'
    /// values and the fit; `None` when a set-up refuses the series.
    fn refit_with(
        &self,
        an: &Analysis,
        fdata: &Prepared,
        mf: &MachineFit,
        drop: &[usize],
        add: &dyn EffectModel,
        start: Option<&[f64]>,
    ) -> Result<Option<(f64, Vec<FittedEffect>, MachineFit)>, AnalysisError> {
        let mut with: Vec<&dyn EffectModel> = Vec::new();
        let mut values: Vec<Vec<f64>> = Vec::new();
        for (k, m) in self.rung.models.iter().enumerate() {
            if !drop.contains(&k) {
                with.push(*m);
                values.push(mf.effect_params.get(k).cloned().unwrap_or_default());
            }
        }
        let set = match start {
            Some(s) => {
                with.push(add);
                values.push(s.to_vec());
                nested_from(an, &with, &values, &[], fdata)
            }
            None => {
                let set = nested_from(an, &with, &values, &[add], fdata);
                with.push(add);
                set
            }
        };
        let Some(set) = set else {
            return Ok(None);
        };
        let (fit, _) = self.machine_on(an, fdata, &set, false)?;
        let whole = self.on_whole_log(&with, &fit, false)?;
        Ok(Some((whole.error, whole.fitted, fit)))
    }

    /// The effects of the chosen model (fitted as `mf` on `fdata`, set up on `an`;
    /// whole-log `error`, `noise` floor) that a confusable effect of the library outside it
    /// fits as well in its place, with plausible values (module doc).
    ///
    /// # Errors
    /// A model that cannot be set up on the log.
    pub(super) fn alike(
        &self,
        an: &Analysis,
        fdata: &Prepared,
        mf: &MachineFit,
        error: f64,
        noise: f64,
    ) -> Result<Vec<Alike>, AnalysisError> {
        let models = &self.rung.models;
        let mut out = Vec::new();
        if !(error > 0.0 && noise > 0.0) {
            return Ok(out);
        }
        for (k, m) in models.iter().enumerate() {
            for conf in m.confused_with() {
                if m.kind().is_dynamics() || models.iter().any(|x| x.kind() == conf.with) {
                    continue;
                }
                let Some(other) = self.library.iter().find(|x| x.kind() == conf.with) else {
                    continue;
                };
                let Some((e, fitted, _)) =
                    self.refit_with(an, fdata, mf, &[k], other.as_ref(), None)?
                else {
                    continue;
                };
                let plausible = fitted
                    .iter()
                    .find(|e| e.effect == conf.with)
                    .is_some_and(|e| e.plausible);
                if plausible && as_well(e, error, noise, self.series.band.ratio) {
                    out.push(Alike {
                        effect: m.kind(),
                        other: conf.with,
                        apart_by: conf.apart_by,
                        ratio: error / noise,
                        ratio_other: e / noise,
                    });
                }
            }
        }
        Ok(out)
    }

    /// The library effect that fits the log as well as the chosen model's change of the
    /// base parameter `key` (the model fitted as `mf` on `fdata`, set up on `an`; whole-log
    /// `error`, `noise` floor): the model with that effect added and `key` held at the
    /// file's value, refitted as the final fit is, one value for one
    /// ([`IN_PLACE_OF_BASE`] lists which effect may stand where; the module doc). `None`
    /// when none does, or its values there are not plausible.
    ///
    /// # Errors
    /// A model that cannot be set up on the log.
    pub(super) fn in_place(
        &self,
        an: &Analysis,
        fdata: &Prepared,
        mf: &MachineFit,
        key: BaseKey,
        error: f64,
        noise: f64,
    ) -> Result<Option<InPlace>, AnalysisError> {
        let (rung, sr) = (&self.rung, &self.series);
        if !(error > 0.0 && noise > 0.0) {
            return Ok(None);
        }
        for (_, kind, apart_by) in IN_PLACE_OF_BASE.iter().filter(|(k, _, _)| *k == key) {
            let id = EffectId::from(*kind);
            if rung.models.iter().any(|m| m.kind() == id) {
                continue;
            }
            let Some(other) = self.library.iter().find(|x| x.kind() == id) else {
                continue;
            };
            let mut with: Vec<&dyn EffectModel> = rung.models.clone();
            let Some(set) = nested_from(an, &with, &mf.effect_params, &[other.as_ref()], fdata)
            else {
                continue;
            };
            with.push(other.as_ref());
            let w = Weights::new(fdata, 0, usize::MAX);
            let pinned = self.refit_from(fdata, &set, mf, &w, Some(key))?;
            let whole = self.on_whole_log(&with, &pinned, false)?;
            let Some(fitted) = whole.fitted.into_iter().find(|f| f.effect == id) else {
                continue;
            };
            if fitted.plausible && as_well(whole.error, error, noise, sr.band.ratio) {
                return Ok(Some(InPlace {
                    effect: id,
                    apart_by: *apart_by,
                    ratio_with_change: error / noise,
                    ratio_in_place: whole.error / noise,
                    better: sr.band.explained(error, whole.error, noise) >= STEP_MIN,
                    fitted,
                }));
            }
        }
        Ok(None)
    }

    /// The pairs of load laws of speed of the chosen model (fitted as `mf` on `fdata`, its
    /// effects set up on the analysis `an`; whole-log `error`, `noise` floor) that one law
    /// of speed fits as well (module doc).
    ///
    /// # Errors
    /// A model that cannot be set up on the log.
    pub(super) fn as_one(
        &self,
        an: &Analysis,
        fdata: &Prepared,
        mf: &MachineFit,
        error: f64,
        noise: f64,
    ) -> Result<Vec<AsOne>, AnalysisError> {
        let models = &self.rung.models;
        let w_s = sync_speed_mech(fdata, an.setup_constants());
        let loads: Vec<usize> = (0..models.len())
            .filter(|&k| !models[k].kind().is_dynamics())
            .filter(|&k| {
                let v = mf.effect_params.get(k).map_or(&[][..], Vec::as_slice);
                models[k].load_torque_at(v, w_s).is_some()
            })
            .collect();
        let mut out = Vec::new();
        if loads.len() < 2 || !(error > 0.0 && noise > 0.0) {
            return Ok(out);
        }
        let one = LawEffect::new(Arc::new(speed_power()));
        for (a, &i) in loads.iter().enumerate() {
            for &j in &loads[a + 1..] {
                let pair = |w: f64| -> f64 {
                    [i, j]
                        .iter()
                        .filter_map(|&k| models[k].load_torque_at(&mf.effect_params[k], w))
                        .sum()
                };
                let start = one_law_start(pair(SPEED_POWER_REF_RAD_S), pair(w_s), pair(0.5 * w_s));
                let Some((e, _, fit)) =
                    self.refit_with(an, fdata, mf, &[i, j], &one, Some(&start))?
                else {
                    continue;
                };
                let Some([t_ref, n]) = fit.effect_params.last().and_then(|v| v.get(..2)) else {
                    continue;
                };
                let reading = *n > EXPONENT_MARGIN && *n < 5.0 - EXPONENT_MARGIN;
                if reading && as_well(e, error, noise, self.series.band.ratio) {
                    out.push(AsOne {
                        effects: [models[i].kind(), models[j].kind()],
                        exponent: *n,
                        torque_at_sync_nm: speed_power_nm(*t_ref, *n, w_s),
                        sync_speed_rad_s: w_s,
                        error_as_one: e,
                        ratio_as_one: e / noise,
                        error_apart: error,
                    });
                }
            }
        }
        Ok(out)
    }
}

/// Where the one law's fit starts: its torque at the reference speed `t_ref` as the pair
/// gives it, and the exponent the pair shows between half and full synchronous speed
/// (`t_sync`, `t_half`; 2 where the two do not have one sign).
fn one_law_start(t_ref: f64, t_sync: f64, t_half: f64) -> [f64; 2] {
    let ratio = t_sync / t_half;
    let n = if ratio.is_finite() && ratio > 0.0 {
        (ratio.ln() / std::f64::consts::LN_2).clamp(0.0, 4.0)
    } else {
        2.0
    };
    [t_ref, n]
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The start reads the exponent of a power law from its two speeds, and falls back to
    /// windage's where the pair changes sign between them.
    #[test]
    fn the_start_reads_the_pairs_exponent() {
        let law = |w: f64| 3.0 * (w / 100.0).powf(2.7);
        let [t, n] = one_law_start(law(100.0), law(157.0), law(78.5));
        assert!((t - 3.0).abs() < 1e-12);
        assert!((n - 2.7).abs() < 1e-9, "{n}");
        let [_, n] = one_law_start(1.0, 5.0, -1.0);
        assert_eq!(n, 2.0);
    }
}
