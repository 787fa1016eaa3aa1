//! The ladder's base rung: the machine's six physical base parameters (Rs, Rr, the leakage
//! inductances, Lm, J, B + Bl) refitted as factors on the user's file
//! ([`crate::fit::machine`]), a candidate of every round like an effect; and what a change
//! of each means.

use super::round::{Fitted, LadderSeries, Rung};
use crate::effects;
use crate::effects::plausible as pl;
use crate::fit::machine::{self, BaseKey, MachineFit, MachineScales, UNIDENTIFIED_SD};
use crate::fit::FitResult;
use crate::metrics;
use crate::simplified_model::BaseParams;
use crate::{Analysis, AnalysisError, MAX_ITER};
use serde::Serialize;

/// A refitted value that differs from the file's by less than this (3 %) is not a change
/// the ladder names, whatever its interval.
pub const BASE_CHANGE_MIN: f64 = 0.03;

/// One base parameter against the user's file (JSON `ladder[].base[]`, `base_changes[]`).
#[derive(Debug, Clone, Serialize)]
pub struct BaseChange {
    /// Which (`rs`, `rr`, `leakage`, `lm`, `j`, `b`).
    pub base: BaseKey,
    /// The relative change from the file (0.19 = +19 %); for B + Bl where the file has
    /// none, the value itself [N m s/rad].
    pub change: f64,
    /// The 95 % interval of `change` (`None`: the log does not determine it).
    pub interval: Option<[f64; 2]>,
    /// The file's value.
    pub file_value: f64,
    /// The refitted value.
    pub value: f64,
    /// The unit of the two values.
    pub unit: &'static str,
    /// True when the log determines the value within ±[`UNIDENTIFIED_SD`].
    pub identified: bool,
    /// True when the change is one the ladder names: identified, at least
    /// [`BASE_CHANGE_MIN`], and its interval excludes no change.
    pub changed: bool,
}

impl BaseChange {
    /// `change` in words with its interval: `+19 % (±2 %)`.
    pub fn spelled(&self) -> String {
        let half = self
            .interval
            .map(|[lo, hi]| 0.5 * (hi - lo))
            .unwrap_or(f64::INFINITY);
        if self.base == BaseKey::B && (self.file_value == 0.0 || self.change.abs() > 1.0) {
            // A viscous load the file does not hold: the value, not a share of the file's
            // bearing friction.
            return format!(
                "{} {} N m s/rad (the file's {})",
                self.base.symbol(),
                effects::sig(self.value),
                effects::sig(self.file_value)
            );
        }
        if half.is_finite() {
            format!(
                "{} {:+.0} % (±{:.0} %)",
                self.base.symbol(),
                100.0 * self.change,
                (100.0 * half).max(1.0)
            )
        } else {
            format!("{} {:+.0} %", self.base.symbol(), 100.0 * self.change)
        }
    }
}

/// The file's value of `key` and its unit.
fn file_value(key: BaseKey, p: &monitor_io::params::ParamFile) -> (f64, &'static str) {
    let m = &p.motor;
    match key {
        BaseKey::Rs => (m.rs_ohm, "ohm"),
        BaseKey::Rr => (m.rr_ohm, "ohm"),
        BaseKey::Leakage => (m.ls_h - m.lm_h + m.lr_h - m.lm_h, "H (Lls + Llr)"),
        BaseKey::Lm => (m.lm_h, "H"),
        BaseKey::J => (m.j_kgm2, "kg m^2"),
        BaseKey::B => (m.b_nms + m.bl_nms, "N m s/rad"),
    }
}

/// The six base parameters of `s` against the file `p`, with the 95 % half-widths `half`
/// (in the factors' units, [`machine::machine_half_widths`]).
pub fn base_changes(
    s: &MachineScales,
    p: &monitor_io::params::ParamFile,
    half: &[Option<f64>; 6],
) -> Vec<BaseChange> {
    BaseKey::ALL
        .iter()
        .map(|&key| {
            let (fv, unit) = file_value(key, p);
            let change = s.change(key, p);
            // The half-width as a relative change (B + Bl: over the file's value where it
            // has one).
            let rel = half[key.index()].map(|h| match key {
                BaseKey::B if fv > 0.0 => h / fv,
                _ => h,
            });
            let interval = rel.map(|h| [change - h, change + h]);
            let identified = rel.is_some_and(|h| h <= UNIDENTIFIED_SD)
                || (key == BaseKey::B && fv == 0.0 && rel.is_some());
            let excludes_zero = interval.is_some_and(|[lo, hi]| lo > 0.0 || hi < 0.0);
            BaseChange {
                base: key,
                change,
                interval,
                file_value: fv,
                value: if key == BaseKey::B {
                    s.b_nms
                } else {
                    fv * s.get(key)
                },
                unit,
                identified,
                changed: identified && excludes_zero && change.abs() >= BASE_CHANGE_MIN,
            }
        })
        .collect()
}

/// What the changes `c` mean, in a drive engineer's words: each named change with its
/// interval and its likely reading, then the parameters the log does not identify.
pub fn base_in_words(c: &[BaseChange]) -> String {
    let mut parts = resistances_in_words(c);
    for (k, why) in OTHER_READINGS {
        if let Some(x) = c.iter().find(|x| x.base == k && x.changed) {
            parts.push(format!("{}: {why}", x.spelled()));
        }
    }
    let unidentified: Vec<&str> = c
        .iter()
        .filter(|x| !x.identified)
        .map(|x| x.base.symbol())
        .collect();
    let unchanged: Vec<&str> = c
        .iter()
        .filter(|x| x.identified && !x.changed)
        .filter(|x| !matches!(x.base, BaseKey::Rs | BaseKey::Rr) || parts.is_empty())
        .map(|x| x.base.symbol())
        .collect();
    if parts.is_empty() {
        parts.push("no base parameter differs from the file's by more than this log shows".into());
    }
    if !unchanged.is_empty() {
        parts.push(format!("unchanged: {}", unchanged.join(", ")));
    }
    if !unidentified.is_empty() {
        parts.push(format!(
            "not identified by this log (kept near the file's values): {}",
            unidentified.join(", ")
        ));
    }
    parts.join("; ")
}

/// The likely reading of a change of each base parameter other than the resistances.
const OTHER_READINGS: [(BaseKey, &str); 4] = [
    (
        BaseKey::Lm,
        "the magnetising inductance differs from the file's (a no-load test at another voltage, or saturation)",
    ),
    (
        BaseKey::Leakage,
        "the leakage inductances differ from the file's (a locked-rotor test's split or its saturated leakage paths)",
    ),
    (
        BaseKey::J,
        "the inertia differs from the file's (the coupled load's)",
    ),
    (
        BaseKey::B,
        "the viscous friction differs from the file's (a viscous load the file leaves out, bearings, seals)",
    ),
];

/// The changes of Rs and Rr in `c` in words: both risen alike read as a warm machine (its
/// rise in K at copper's 0.393 %/K), else each with its likely reading.
fn resistances_in_words(c: &[BaseChange]) -> Vec<String> {
    let get = |k: BaseKey| c.iter().find(|x| x.base == k);
    let changed = |k: BaseKey| get(k).is_some_and(|x| x.changed);
    let (rs, rr) = (get(BaseKey::Rs), get(BaseKey::Rr));
    let spelled = |x: Option<&BaseChange>| x.map_or_else(String::new, BaseChange::spelled);
    let (a, b) = (rs.map_or(0.0, |x| x.change), rr.map_or(0.0, |x| x.change));
    let alike = a > 0.0 && b > 0.0 && (a - b).abs() <= 0.3 * a.max(b);
    let (rs_changed, rr_changed) = (changed(BaseKey::Rs), changed(BaseKey::Rr));
    if rs_changed && rr_changed && alike {
        return vec![format!(
            "{}, {}: both windings warmer than the file's values, about {:.0} K (copper 0.393 %/K)",
            spelled(rs),
            spelled(rr),
            0.5 * (a + b) / effects::ALPHA_CU_PER_K
        )];
    }
    let mut parts = Vec::new();
    if rs_changed {
        parts.push(format!(
            "{}{}: {}",
            spelled(rs),
            if rr_changed { "" } else { ", Rr unchanged" },
            if a > 0.0 {
                "the file's Rs is cold, or the stator is warm (a loosening connection adds to it too)"
            } else {
                "the file's Rs is higher than the winding's (measured warm, or with its leads)"
            }
        ));
    }
    if rr_changed {
        parts.push(format!(
            "{}{}: the rotor's resistance differs from the file's (a locked-rotor test at line frequency reads the skin effect's Rr; a warm cage)",
            spelled(rr),
            if rs_changed { "" } else { ", Rs unchanged" },
        ));
    }
    parts
}

/// The base parameters' prior weight on a log whose noise floor is `noise` (normalised): the
/// floor, but not below the model's own accuracy on noise-free data
/// ([`crate::fit::IDENTIFIED_MIN`], 0.4 %): on a log without noise the priors would weigh
/// nothing, and the base parameters would take up the model's structural residue (a
/// noise-free log of another simulator read Rs -4 % against its exact file).
pub(super) fn prior_weight(noise: f64) -> f64 {
    if noise.is_finite() {
        noise.max(crate::fit::IDENTIFIED_MIN)
    } else {
        crate::fit::IDENTIFIED_MIN
    }
}

/// Why the factors `s` are not a machine's (empty: they are): Rs and Rr within the
/// temperature range, the inductances within saturation and tolerance, J within a factor 3
/// ([`crate::effects::plausible`]), none pinned at its fit bound.
pub(super) fn scales_implausible(s: &MachineScales) -> Vec<String> {
    let mut why = Vec::new();
    let mut check = |name: &str, v: f64, (lo, hi): (f64, f64), basis: &str| {
        if !(v >= lo && v <= hi) {
            why.push(format!(
                "base: {name} x{} is outside the physical range x{}..x{} ({basis})",
                effects::sig(v),
                effects::sig(lo),
                effects::sig(hi)
            ));
        }
    };
    check(
        "Rs",
        s.rs,
        pl::RA_RATIO,
        "-20 C to 155 C is 0.84-1.53 x the 20 C value, plus 10 % data-sheet tolerance",
    );
    check(
        "Rr",
        s.rr,
        pl::RR_RATIO,
        "temperature, the skin effect and data-sheet tolerance",
    );
    check(
        "Lls, Llr",
        s.leakage,
        pl::LEAKAGE_RATIO,
        "a locked-rotor test's split and the leakage paths' saturation",
    );
    check(
        "Lm",
        s.lm,
        pl::LM_RATIO,
        "saturation and a no-load test's tolerance",
    );
    check(
        "J",
        s.j,
        pl::J_RATIO,
        "a factor 3 either way is another machine",
    );
    why
}

impl Analysis {
    /// The base rung as a candidate of the round from `rung`: the six base parameters
    /// refitted with the model's effects (from where they stood) on the fit series, each
    /// prior weighing the log's noise floor (`rung.noise`); its held-back error and what
    /// makes it implausible. `self` is the analysis of `rung`'s model.
    pub(super) fn base_candidate<'a>(
        &self,
        rung: &Rung<'a>,
        sr: &LadderSeries,
    ) -> Result<Option<Fitted<'a>>, AnalysisError> {
        let Some(set) = self.nested(&[], rung, &sr.fd) else {
            return Ok(None);
        };
        // From where the model stood: the paper fit's base parameters taken into the
        // factors, so the fit can only lower the training cost.
        let start = rung.scales.with_paper(&rung.fit.base);
        let mf = machine::fit_machine(
            &sr.fd,
            &sr.file,
            &set,
            &sr.wf,
            &start,
            prior_weight(rung.noise),
            MAX_ITER,
        )?;
        let an = self.rebased(mf.params(&sr.file));
        let (fit, hb) = an.base_prediction(&rung.models, &mf, sr)?;
        let mut why = scales_implausible(&mf.scales);
        for (e, p) in rung.models.iter().zip(&fit.effect_params) {
            if let Ok(s) = e.setup(&self.data, an.setup_constants()) {
                if s.len() == p.len() {
                    why.extend(
                        s.implausible(p)
                            .into_iter()
                            .map(|w| format!("{}: {w}", e.kind())),
                    );
                }
            }
        }
        Ok(Some(Fitted {
            models: rung.models.clone(),
            fit,
            // Six base parameters where the paper fit had four.
            n_parameters: 2,
            heldback_fit_series: hb,
            implausible: why,
            base: Some(mf.scales),
        }))
    }

    /// The candidate `c` (fitted from `rung`'s model) refitted with every value of the
    /// model free and the six base parameters free beside them ([`machine::fit_machine`],
    /// from `c`'s values, the paper fit's base parameters taken into the factors): its
    /// held-back error on the file recentred on the refitted base, and what makes it
    /// implausible there. It adds two parameters to `c`'s (six base parameters where the
    /// paper fit had four).
    pub(super) fn joint_machine<'a>(
        &self,
        c: &Fitted<'a>,
        rung: &Rung<'a>,
        sr: &LadderSeries,
    ) -> Result<Fitted<'a>, AnalysisError> {
        let Some(set) = self.nested_from(&c.models, &c.fit.effect_params, &[], &sr.fd) else {
            return Ok(c.clone());
        };
        let start = rung.scales.with_paper(&c.fit.base);
        let mf = machine::fit_machine(
            &sr.fd,
            &sr.file,
            &set,
            &sr.wf,
            &start,
            prior_weight(rung.noise),
            MAX_ITER,
        )?;
        let an = self.rebased(mf.params(&sr.file));
        let (fit, hb) = an.base_prediction(&c.models, &mf, sr)?;
        let set2 = an.setup_list(&sr.fd, &c.models)?;
        let mut why = scales_implausible(&mf.scales);
        why.extend(an.implausible_step(&set2, rung, &fit, sr.m)?);
        Ok(Fitted {
            models: c.models.clone(),
            fit,
            n_parameters: c.n_parameters + 2,
            heldback_fit_series: hb,
            implausible: why,
            base: Some(mf.scales),
        })
    }

    /// The machine fit `mf` as a fit of the file recentred on it (`self`): the nominal base
    /// parameters with its effects' values, and its held-back error on the fit series.
    fn base_prediction(
        &self,
        models: &[&dyn effects::EffectModel],
        mf: &MachineFit,
        sr: &LadderSeries,
    ) -> Result<(FitResult, f64), AnalysisError> {
        let set = self.setup_list(&sr.fd, models)?;
        let fit = FitResult {
            base: BaseParams::nominal(&self.constants),
            effect_params: mf.effect_params.clone(),
            report: mf.report,
        };
        let pred = crate::fit::predict(&sr.fd, &self.constants, &set, &fit)?;
        let hb = metrics::errors(&sr.fd, &pred, Some(&sr.held_fd)).normalized_rms_error;
        Ok((fit, hb))
    }

    /// The base changes of the base rung `c` (its factors against the user's file), with
    /// their intervals on the fit series.
    pub(super) fn base_rung_changes(
        &self,
        c: &Fitted<'_>,
        sr: &LadderSeries,
    ) -> Result<Vec<BaseChange>, AnalysisError> {
        let Some(scales) = c.base else {
            return Ok(Vec::new());
        };
        let set = self.setup_list(&sr.fd, &c.models)?;
        let mf = MachineFit {
            scales,
            effect_params: c.fit.effect_params.clone(),
            report: c.fit.report,
        };
        let half = machine::machine_half_widths(&sr.fd, &sr.file, &set, &sr.wf, &mf)?;
        Ok(base_changes(&scales, &sr.file, &half))
    }
}
