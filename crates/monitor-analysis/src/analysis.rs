//! A loaded log with its nominal parameters ([`Analysis`]), the options and errors `compare`,
//! `explain` and `identify` share, and the fitting steps they are built from.

use crate::base_range::base_values;
use crate::effects::EffectModel;
use crate::fit::{ActiveEffect, FitResult};
use crate::metrics::Weights;
use crate::prep::{Prepared, ReadOptions, C64};
use crate::simplified_model::{BaseParams, MachineConstants, Prediction};
use crate::{effects, fit, metrics, prep, simplified_model, unbalance};
use monitor_laws::EffectId;
use serde::Serialize;
use std::path::Path;

/// Largest number of samples a fit simulates (longer logs are fitted on a coarser series
/// and evaluated on the full working series).
pub const MAX_FIT_SAMPLES: usize = 60_000;
/// LM iterations per fit.
pub const MAX_ITER: usize = 40;

/// Errors of the analysis (one line each).
#[derive(Debug, thiserror::Error)]
pub enum AnalysisError {
    /// Reading the log failed.
    #[error(transparent)]
    Log(#[from] monitor_io::log::LogError),
    /// Unknown effect name (`known`: the library's and the user's laws, comma separated).
    #[error("unknown effect '{name}' (known: {known})")]
    UnknownEffect {
        /// The name given.
        name: String,
        /// The names known.
        known: String,
    },
    /// A configured effect cannot be set up on the log (a channel it needs is missing, or
    /// the log holds nothing it could fit).
    #[error("effect {effect}: {source}")]
    Effect {
        /// Which effect.
        effect: EffectId,
        /// Why not.
        source: effects::SetupError,
    },
    /// Fitted values that do not match the effects they are for.
    #[error(transparent)]
    Values(#[from] effects::EffectValuesError),
}

/// The effect names of `registry` (the library's, then the user's laws), comma separated
/// (for messages).
pub fn known_effects(registry: &effects::Registry) -> String {
    registry
        .names()
        .iter()
        .map(|e| e.name())
        .collect::<Vec<_>>()
        .join(", ")
}

/// Parses an effect name of `registry` (the library's or a user's law).
///
/// # Errors
/// [`AnalysisError::UnknownEffect`] listing the known names.
pub fn parse_effect(name: &str, registry: &effects::Registry) -> Result<EffectId, AnalysisError> {
    registry
        .find(name)
        .ok_or_else(|| AnalysisError::UnknownEffect {
            name: name.to_string(),
            known: known_effects(registry),
        })
}

/// A loaded log with its nominal parameters.
pub struct Analysis {
    /// Working series (shared: a model recentred on refitted base parameters reads the
    /// same series, [`Analysis::recentred`]).
    pub data: std::sync::Arc<Prepared>,
    /// Machine constants from the parameter file.
    pub constants: MachineConstants,
    /// The parameter file.
    pub params: monitor_io::params::ParamFile,
    /// What the data-quality stage found in the log and what the analysis did about it.
    pub quality: monitor_io::log::quality::DataQuality,
    /// The constants the effects are set up with when they are not `constants`: the user's
    /// file's, for a model the ladder rebased on refitted base parameters
    /// ([`Analysis::rebased`]), so that an effect's data-dependent set-up (the load
    /// segments an observer finds, the plausible ranges) is the same on every rung.
    pub(crate) setup_origin: Option<MachineConstants>,
}

/// Options shared by `compare` and `explain`.
#[derive(Debug, Clone)]
pub struct Options {
    /// Effects already in the model.
    pub effects: Vec<EffectId>,
    /// Refit the base parameters (default true).
    pub fit_base: bool,
    /// The effects the analysis may use: the library's and a user's laws (`--laws`).
    pub laws: effects::Registry,
}

/// One fitted parameter.
#[derive(Debug, Clone, Serialize)]
pub struct ParamValue {
    /// Value.
    pub value: f64,
    /// Unit.
    pub unit: String,
    /// Nominal value from the parameter file (base parameters only).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub nominal: Option<f64>,
    /// False when the value is outside the physical range of motors of this size
    /// ([`effects::plausible`]).
    pub plausible: bool,
    /// Why the value is not plausible (absent when it is).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub implausible_because: Option<String>,
}

/// An effect in the model with its fitted values.
#[derive(Debug, Clone, Serialize)]
pub struct FittedEffect {
    /// Which effect.
    pub effect: EffectId,
    /// Parameters.
    pub parameters: std::collections::BTreeMap<String, ParamValue>,
    /// In words; for values outside their physical range, that the fit is not physical
    /// and why ([`effects::not_physical`]).
    pub summary: String,
    /// False when a fitted value is outside its physical range.
    pub plausible: bool,
    /// Why not (one entry per value out of range; empty when plausible).
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub implausible_because: Vec<String>,
}

/// Facts about the analysed data.
#[derive(Debug, Clone, Serialize)]
pub struct DataInfo {
    /// Rows of the log analysed.
    pub rows: u64,
    /// Log sample rate [Hz].
    pub log_rate_hz: f64,
    /// Working (decimated) rate [Hz].
    pub working_rate_hz: f64,
    /// Duration [s].
    pub duration_s: f64,
    /// Reference frame.
    pub frame: AnalysisFrame,
}

/// The frame the analysis projects the log into (JSON: a phrase, as before).
#[derive(Debug, Clone, Copy, Serialize, PartialEq, Eq)]
pub enum AnalysisFrame {
    /// The rotor-flux frame of a voltage-model flux estimate (a log with voltages).
    #[serde(rename = "rotor-flux frame (voltage-model flux estimate)")]
    RotorFlux,
    /// The supply's frame at the parameter file's frequency (a current-only log).
    #[serde(rename = "supply frame from the parameter file (current-only log)")]
    Supply,
}

impl AnalysisFrame {
    /// The frame in words (as in the JSON).
    pub fn describe(self) -> &'static str {
        match self {
            AnalysisFrame::RotorFlux => "rotor-flux frame (voltage-model flux estimate)",
            AnalysisFrame::Supply => "supply frame from the parameter file (current-only log)",
        }
    }
}

/// The effect models of `kinds` in `registry`, each once, in the order given (a name the
/// registry does not have is left out: names are parsed against it first,
/// [`parse_effect`]).
pub(crate) fn resolve(
    kinds: &[EffectId],
    registry: &effects::Registry,
) -> Vec<Box<dyn EffectModel>> {
    let mut v: Vec<Box<dyn EffectModel>> = Vec::new();
    for &k in kinds {
        if !v.iter().any(|x| x.kind() == k) {
            v.extend(registry.model_of(k));
        }
    }
    v
}

/// Block-averages a working series by `m` (for fitting long logs).
pub(crate) fn coarsen(d: &Prepared, m: usize) -> Prepared {
    use rayon::prelude::*;
    if m <= 1 {
        return d.clone();
    }
    let avg = |x: &[f64]| -> Vec<f64> {
        x.par_chunks_exact(m)
            .map(|c| c.iter().sum::<f64>() / m as f64)
            .collect()
    };
    let theta_c = avg(&d.theta);
    let rotated = rotating_block_means(d, m, &theta_c);
    let has_v = d.v_neg.len() == d.len();
    Prepared {
        t_s: avg(&d.t_s),
        dt_s: d.dt_s * m as f64,
        theta: theta_c,
        omega_s: avg(&d.omega_s),
        vd: avg(&d.vd),
        vq: avg(&d.vq),
        id: avg(&d.id),
        i_f: avg(&d.i_f),
        iq: avg(&d.iq),
        iq_pos: avg(&d.iq_pos),
        i_ab: rotated.iter().map(|r| r.0).collect(),
        i0: avg(&d.i0),
        v_neg: if has_v {
            rotated.iter().map(|r| r.1).collect()
        } else {
            vec![]
        },
        i_neg: rotated.iter().map(|r| r.2).collect(),
        omega_r: avg(&d.omega_r),
        channels: d.channels,
        rows: d.rows,
        log_rate_hz: d.log_rate_hz,
        // The block mean's gain is the working series': the averages above are taken in
        // the rotating frame (a coarse sample as the mean of `m` working samples' would
        // scale the voltage and the current by `cos(w dt / 2)` more, 0.3 % at 50 Hz from
        // 2 to 1 kHz, and the fit's base parameters would absorb it).
        block_rows: d.block_rows,
        log_start_s: d.log_start_s,
    }
}

/// The block means of `d`'s rotating vectors over blocks of `m` (the current i_ab, the
/// negative-sequence voltage and current), each block's mean angle `theta_c`. Rotating
/// vectors are averaged in the frame they are constant in (the positive-sequence d-q frame
/// for i_ab, the negative-sequence frame for the others) and rotated back with the block's
/// mean angle; a plain average over a supply period would cancel them. One pass for the
/// three vectors: each sample's rotation is computed once.
pub(crate) fn rotating_block_means(
    d: &Prepared,
    m: usize,
    theta_c: &[f64],
) -> Vec<(C64, C64, C64)> {
    use rayon::prelude::*;
    let zero = C64::new(0.0, 0.0);
    let has_v = d.v_neg.len() == d.len();
    d.theta
        .par_chunks_exact(m)
        .enumerate()
        .zip(theta_c)
        .map(|((b, th), &tc)| {
            let (mut si, mut sv, mut sn) = (zero, zero, zero);
            for (j, &t) in th.iter().enumerate() {
                let k = b * m + j;
                let r = C64::from_polar(1.0, -t); // e^{-j theta}
                let rc = r.conj(); // e^{+j theta}
                si += d.i_ab[k] * r;
                if has_v {
                    sv += d.v_neg[k] * rc;
                }
                sn += d.i_neg[k] * rc;
            }
            let back = C64::from_polar(1.0, tc);
            let mf = m as f64;
            (si / mf * back, sv / mf * back.conj(), sn / mf * back.conj())
        })
        .collect()
}

impl Analysis {
    /// Reads the log (streaming, bounded memory) and prepares the working series.
    ///
    /// # Errors
    /// Log errors (one line, naming file, line and column).
    pub fn load(
        log: &Path,
        params: monitor_io::params::ParamFile,
        opts: ReadOptions,
        progress: &mut dyn FnMut(f64),
    ) -> Result<Self, AnalysisError> {
        Self::load_file(
            &monitor_io::log::LogFile::open(log)?,
            params,
            opts,
            progress,
        )
    }

    /// [`Analysis::load`] on a log already opened (any format, a TDMS group chosen:
    /// [`monitor_io::log::LogFile::open_with`]).
    ///
    /// # Errors
    /// As [`Analysis::load`].
    pub fn load_file(
        log: &monitor_io::log::LogFile,
        params: monitor_io::params::ParamFile,
        opts: ReadOptions,
        progress: &mut dyn FnMut(f64),
    ) -> Result<Self, AnalysisError> {
        let (dec, quality) = prep::decimate_file(log, &params, opts, progress)?;
        let data = prep::voltage_model_flux_frame(&dec, &params);
        Ok(Analysis {
            data: std::sync::Arc::new(data),
            constants: MachineConstants::from_params(&params),
            params,
            quality,
            setup_origin: None,
        })
    }

    pub(crate) fn info(&self) -> DataInfo {
        let d = &self.data;
        DataInfo {
            rows: d.rows,
            log_rate_hz: d.log_rate_hz,
            working_rate_hz: 1.0 / d.dt_s,
            duration_s: d.t_s.last().copied().unwrap_or(0.0)
                - d.t_s.first().copied().unwrap_or(0.0),
            // (The voltage-model estimator, not the monitor's current model.)
            frame: if d.channels.voltages {
                AnalysisFrame::RotorFlux
            } else {
                AnalysisFrame::Supply
            },
        }
    }

    pub(crate) fn base_table(
        &self,
        b: &BaseParams,
    ) -> std::collections::BTreeMap<String, ParamValue> {
        let n = &self.constants;
        let noms = [n.ra_ohm, n.ls_h, n.btot_nms, n.j_kgm2];
        base_values(n, b, &self.data)
            .iter()
            .zip(noms)
            .map(|(v, nom)| {
                let reason = v.implausible_because();
                (
                    v.key.key().to_string(),
                    ParamValue {
                        value: v.value,
                        unit: v.key.unit().to_string(),
                        nominal: Some(nom),
                        plausible: reason.is_none(),
                        implausible_because: reason,
                    },
                )
            })
            .collect()
    }

    pub(crate) fn setup_all<'a>(
        &self,
        d: &Prepared,
        list: &'a [Box<dyn EffectModel>],
    ) -> Result<Vec<ActiveEffect<'a>>, AnalysisError> {
        let mut v = Vec::new();
        for e in list {
            let setup = e
                .needs()
                .met_by(d)
                .and_then(|()| e.setup(d, &self.constants))
                .map_err(|source| AnalysisError::Effect {
                    effect: e.kind(),
                    source,
                })?;
            v.push(ActiveEffect {
                effect: e.as_ref(),
                setup,
            });
        }
        Ok(v)
    }

    /// Fits `active` on the (possibly coarsened) data; returns the fit.
    pub(crate) fn fit_set(
        &self,
        fitdata: &Prepared,
        active: &[ActiveEffect<'_>],
        w: &Weights,
        start: &BaseParams,
        fit_base: bool,
    ) -> Result<FitResult, effects::EffectValuesError> {
        fit::fit(
            fitdata,
            &self.constants,
            active,
            w,
            start,
            fit_base,
            MAX_ITER,
        )
    }

    /// [`Analysis::fit_set`] with the base parameters as `spec` says.
    pub(crate) fn fit_spec(
        &self,
        fitdata: &Prepared,
        active: &[ActiveEffect<'_>],
        w: &Weights,
        start: &BaseParams,
        spec: fit::BaseSpec,
    ) -> Result<FitResult, effects::EffectValuesError> {
        self.fit_spec_iter(fitdata, active, w, start, spec, MAX_ITER)
    }

    /// [`Analysis::fit_spec`] with at most `max_iter` iterations.
    pub(crate) fn fit_spec_iter(
        &self,
        fitdata: &Prepared,
        active: &[ActiveEffect<'_>],
        w: &Weights,
        start: &BaseParams,
        spec: fit::BaseSpec,
        max_iter: usize,
    ) -> Result<FitResult, effects::EffectValuesError> {
        fit::fit_spec(fitdata, &self.constants, active, w, start, spec, max_iter)
    }

    /// The effects `active` with their fitted values in `f`, as the JSON reports them.
    pub(crate) fn fitted_effects(
        &self,
        active: &[ActiveEffect<'_>],
        f: &FitResult,
    ) -> Result<Vec<FittedEffect>, effects::EffectValuesError> {
        if active.len() != f.reported().len() {
            return Err(effects::EffectValuesError::Effects {
                expected: active.len(),
                got: f.reported().len(),
            });
        }
        active
            .iter()
            .zip(f.reported())
            .map(|(a, p)| {
                let mut why = a.setup.implausible(p);
                why.extend(a.setup.pinned(p));
                let summary = if why.is_empty() {
                    a.setup.describe(p, &self.data, &self.constants)?
                } else {
                    effects::not_physical(&why)
                };
                Ok(FittedEffect {
                    effect: a.effect.kind(),
                    parameters: parameter_table(&a.setup.params, p),
                    summary,
                    plausible: why.is_empty(),
                    implausible_because: why,
                })
            })
            .collect()
    }

    /// The fitted model's prediction on `d` and the same model run with the inputs' noise
    /// added again ([`Analysis::renoised`]): the pair [`metrics::noise_floor`] and
    /// [`metrics::noise_floor_on`] take. The two runs are independent and share the cores.
    pub(crate) fn predict_and_renoised(
        &self,
        d: &Prepared,
        active: &[ActiveEffect<'_>],
        f: &FitResult,
    ) -> Result<(Prediction, Prediction), effects::EffectValuesError> {
        let (p, r) = rayon::join(
            || fit::predict(d, &self.constants, active, f),
            || self.renoised(d, active, f),
        );
        Ok((p?, r?))
    }

    /// The fitted model run with the inputs' sensor noise added again (white, the level
    /// measured on the inputs), for [`metrics::noise_floor`].
    pub(crate) fn renoised(
        &self,
        d: &Prepared,
        active: &[ActiveEffect<'_>],
        f: &FitResult,
    ) -> Result<Prediction, effects::EffectValuesError> {
        let mut terms = fit::terms(d, &self.constants, active, f)?;
        terms.input_noise = Some(metrics::input_noise(d, 0x006e_6f69_7365));
        Ok(simplified_model::simulate(
            d,
            &self.constants,
            &f.base,
            &terms,
        ))
    }

    pub(crate) fn fit_data(&self) -> (Prepared, usize) {
        let m = self.data.len().div_ceil(MAX_FIT_SAMPLES).max(1);
        (coarsen(&self.data, m), m)
    }
}

/// The JSON table of an effect's parameters `params` with their fitted values `p`: keyed by
/// each parameter's name, with its declared unit and its plausibility.
pub(crate) fn parameter_table(
    params: &[effects::FitParam],
    p: &[f64],
) -> std::collections::BTreeMap<String, ParamValue> {
    params
        .iter()
        .zip(p)
        .map(|(q, v)| {
            let reason = q.implausible_because(*v);
            (
                q.name.clone(),
                ParamValue {
                    value: *v,
                    unit: q.unit().to_string(),
                    nominal: None,
                    plausible: reason.is_none(),
                    implausible_because: reason,
                },
            )
        })
        .collect()
}

/// Keeps fitted effect values only where the full-series set-up has the same parameter
/// count (data-dependent set-ups such as load steps may differ between the coarse and the
/// full series; then the set-up's initial values stand).
pub(crate) fn align(active: &[ActiveEffect<'_>], mut f: FitResult) -> FitResult {
    for values in std::iter::once(&mut f.effect_params).chain(f.corrected.as_mut()) {
        for (a, p) in active.iter().zip(values.iter_mut()) {
            if p.len() != a.setup.len() {
                *p = a.setup.init();
            }
        }
    }
    f
}

impl Analysis {
    /// The unbalance / faulty-phase analysis ([`unbalance`]; needs only the currents).
    pub fn unbalance(&self) -> unbalance::UnbalanceAnalysis {
        unbalance::analyse(&self.data, &self.constants)
    }
}

impl Analysis {
    /// The same log judged against the parameter file `params` (a model recentred on
    /// refitted base parameters): the working series is shared, not copied.
    pub fn recentred(&self, params: monitor_io::params::ParamFile) -> Analysis {
        Analysis {
            data: std::sync::Arc::clone(&self.data),
            constants: MachineConstants::from_params(&params),
            params,
            quality: self.quality.clone(),
            setup_origin: None,
        }
    }

    /// [`Analysis::recentred`] with the effects still set up on this analysis' constants
    /// (the ladder's rungs: an effect's set-up is the same whatever base parameters the
    /// model has).
    pub(crate) fn rebased(&self, params: monitor_io::params::ParamFile) -> Analysis {
        Analysis {
            setup_origin: Some(*self.setup_constants()),
            ..self.recentred(params)
        }
    }

    /// The constants effects are set up with ([`Analysis::setup_origin`]).
    pub(crate) fn setup_constants(&self) -> &MachineConstants {
        self.setup_origin.as_ref().unwrap_or(&self.constants)
    }
}
