//! The ladder's base rung: the machine's six physical base parameters (Rs, Rr, the leakage
//! inductances, Lm, J, B + Bl) refitted as factors on the user's file
//! ([`crate::fit::machine`]), a candidate of every round like an effect; and each one's
//! change against the file ([`BaseChange`]).

use super::climb::Ladder;
use super::refusal::WhyNotPhysical;
use super::report::BaseChange;
use super::rules::BASE_CHANGE_MIN;
use super::rung::{implausible_step, nested, nested_from, setup_list, Fitted, LadderSeries, Rung};
use crate::analysis::{Analysis, AnalysisError, MAX_ITER};
use crate::effects;
use crate::effects::plausible as pl;
use crate::fit::machine::{self, BaseKey, MachineFit, MachineScales, UNIDENTIFIED_SD};
use crate::fit::FitResult;
use crate::metrics;
use crate::simplified_model::BaseParams;

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
                not_separable: None,
                unsteady: None,
                in_place: None,
            }
        })
        .collect()
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

/// The physical range of each base factor on the user's file, with its basis.
const FACTOR_RANGES: [(&str, (f64, f64), &str); 5] = [
    (
        "Rs",
        pl::RA_RATIO,
        "-20 C to 155 C is 0.84-1.53 x the 20 C value, plus 10 % data-sheet tolerance",
    ),
    (
        "Rr",
        pl::RR_RATIO,
        "temperature, the skin effect and data-sheet tolerance",
    ),
    (
        "Lls, Llr",
        pl::LEAKAGE_RATIO,
        "a locked-rotor test's split and the leakage paths' saturation",
    ),
    (
        "Lm",
        pl::LM_RATIO,
        "saturation and a no-load test's tolerance",
    ),
    ("J", pl::J_RATIO, "a factor 3 either way is another machine"),
];

/// Why the factors `s` are not a machine's (empty: they are): Rs and Rr within the
/// temperature range, the inductances within saturation and tolerance, J within a factor 3
/// ([`crate::effects::plausible`]).
fn scales_implausible(s: &MachineScales) -> Vec<WhyNotPhysical> {
    let factors = [s.rs, s.rr, s.leakage, s.lm, s.j];
    FACTOR_RANGES
        .iter()
        .zip(factors)
        .filter(|((_, (lo, hi), _), v)| !(*v >= *lo && *v <= *hi))
        .map(
            |(&(parameter, (low, high), basis), factor)| WhyNotPhysical::BaseFactor {
                parameter,
                factor,
                low,
                high,
                basis,
            },
        )
        .collect()
}

impl<'a> Ladder<'a> {
    /// The base rung as a candidate of the round from `rung` (`an` the analysis of its
    /// base): the six base parameters refitted with the model's effects (from where they
    /// stood) on the fit series, each prior weighing the log's noise floor (`rung.noise`);
    /// its held-back error and what makes it implausible.
    pub(super) fn base_candidate(
        &self,
        an: &Analysis,
        rung: &Rung<'a>,
    ) -> Result<Option<Fitted<'a>>, AnalysisError> {
        let sr = &self.series;
        let Some(set) = nested(an, &[], rung, &sr.fd) else {
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
        let on = an.rebased(mf.params(&sr.file));
        let (fit, hb) = base_prediction(&on, &rung.models, &mf, sr)?;
        let mut why = scales_implausible(&mf.scales);
        for (e, p) in rung.models.iter().zip(&fit.effect_params) {
            if let Ok(s) = e.setup(&an.data, on.setup_constants()) {
                if s.len() == p.len() {
                    let effect = e.kind();
                    why.extend(
                        s.implausible(p)
                            .into_iter()
                            .map(|why| WhyNotPhysical::Effect { effect, why }),
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

    /// The candidate `c` (fitted from `rung`'s model, `an` the analysis of its base)
    /// refitted with every value of the model free and the six base parameters free beside
    /// them ([`machine::fit_machine`], from `c`'s values, the paper fit's base parameters
    /// taken into the factors): its held-back error on the file recentred on the refitted
    /// base, and what makes it implausible there. It adds two parameters to `c`'s (six
    /// base parameters where the paper fit had four).
    pub(super) fn joint_machine(
        &self,
        an: &Analysis,
        c: &Fitted<'a>,
        rung: &Rung<'a>,
    ) -> Result<Fitted<'a>, AnalysisError> {
        let sr = &self.series;
        let Some(set) = nested_from(an, &c.models, &c.fit.effect_params, &[], &sr.fd) else {
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
        let on = an.rebased(mf.params(&sr.file));
        let (fit, hb) = base_prediction(&on, &c.models, &mf, sr)?;
        let set2 = setup_list(&on, &sr.fd, &c.models)?;
        let mut why = scales_implausible(&mf.scales);
        why.extend(implausible_step(&on, &set2, rung, &fit, sr.m)?);
        Ok(Fitted {
            models: c.models.clone(),
            fit,
            n_parameters: c.n_parameters + 2,
            heldback_fit_series: hb,
            implausible: why,
            base: Some(mf.scales),
        })
    }

    /// The base changes of the base rung `c` (its factors against the user's file; `on`
    /// the analysis of its base), with their intervals on the fit series.
    pub(super) fn base_rung_changes(
        &self,
        on: &Analysis,
        c: &Fitted<'_>,
    ) -> Result<Vec<BaseChange>, AnalysisError> {
        let Some(scales) = c.base else {
            return Ok(Vec::new());
        };
        let sr = &self.series;
        let set = setup_list(on, &sr.fd, &c.models)?;
        let mf = MachineFit {
            scales,
            effect_params: c.fit.effect_params.clone(),
            report: c.fit.report,
            corrected: c.fit.corrected.clone(),
        };
        let half = machine::machine_half_widths(&sr.fd, &sr.file, &set, &sr.wf, &mf)?;
        Ok(base_changes(&scales, &sr.file, &half))
    }
}

/// The machine fit `mf` as a fit of the file recentred on it (`on`): the nominal base
/// parameters with its effects' values, and its held-back error on the fit series.
fn base_prediction(
    on: &Analysis,
    models: &[&dyn effects::EffectModel],
    mf: &MachineFit,
    sr: &LadderSeries,
) -> Result<(FitResult, f64), AnalysisError> {
    let set = setup_list(on, &sr.fd, models)?;
    let fit = FitResult {
        base: BaseParams::nominal(&on.constants),
        effect_params: mf.effect_params.clone(),
        report: mf.report,
        corrected: mf.corrected.clone(),
    };
    let pred = crate::fit::predict(&sr.fd, &on.constants, &set, &fit)?;
    let hb = metrics::errors(&sr.fd, &pred, Some(&sr.held_fd)).normalized_rms_error;
    Ok((fit, hb))
}
