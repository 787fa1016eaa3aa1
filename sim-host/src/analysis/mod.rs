//! Model vs measurement: where the paper's simplified model fails, which physical effect is
//! missing, and how much of the error adding it removes.
//!
//! Pipeline ([`Analysis::load`] then [`Analysis::compare`] / [`Analysis::explain`]):
//! 1. [`prep`]: stream the log, block-average to a ~2 kHz working series, estimate the
//!    rotor-flux angle (voltage model), split positive and negative sequences.
//! 2. [`model`]: drive the simplified model (eqs. 23-29) with the measured V_qs and i_f,
//!    predict I_qs, omega_r and the phase currents.
//! 3. [`fit`]: refit the base parameters the data identify (Ra, Ls, B+Bl, J; Kf = Lm^2/Lr
//!    stays nominal since only its ratio to J and B is observable) together with the
//!    configured effects' parameters, because nominal values are never exact.
//! 4. [`metrics`]: per-channel RMS errors, `normalized_rms_error`, worst windows with their
//!    operating condition and dominant error frequency, error spectrum, noise floor.
//! 5. `explain`: every library effect ([`effects`]) not yet in the model is added and fitted
//!    in turn; candidates are ranked by the error on held-back time windows (the fit never
//!    sees them), so a parameter that only fits noise does not win. When the best candidate
//!    explains less than [`EXPLAINED_MIN`] of the held-back error, or the error is already
//!    within [`NOISE_MARGIN`] x the noise floor, the answer is `unexplained: true`.
//!
//! Baseline and the always-present dynamics: a full-order machine always has rotor-flux and
//! stator-current dynamics; the paper's steady-state model does not. The baseline here is
//! eqs. (28)-(29) with the La dI_qs/dt term dropped (the form the parity equations (37)
//! use) and psi_r = Lm i_f. On steady data neither matters (the baseline is exact in steady
//! state in this frame), so `explain` names nothing; where starts or supply steps dominate
//! the log, `flux_dynamics` / `current_dynamics` are the honest answer. Use `--from` to
//! leave a start-up transient out when it is not of interest.

// Sample loops index several parallel series at once; iterators would obscure that.
#![allow(clippy::needless_range_loop)]

pub mod effects;
pub mod fastcsv;
pub mod fit;
pub mod metrics;
pub mod model;
pub mod plot;
pub mod prep;
pub mod report;

use effects::{Effect, Needs};
use fit::{ActiveEffect, FitResult};
use metrics::{ErrorSummary, Weights, WorstWindow};
use model::{BaseParams, Nominal, Prediction};
use prep::{Prepared, ReadOptions, C64};
use serde::Serialize;
use std::path::Path;

/// A candidate explaining less than this fraction of the held-back error is not claimed.
pub const EXPLAINED_MIN: f64 = 0.5;
/// A baseline within this factor of the noise floor has nothing left to explain
/// (1.12 = a model error beyond the noise of half the noise floor).
pub const NOISE_MARGIN: f64 = 1.12;

/// Below this `normalized_rms_error` (0.4 %) the model is as good as the frame estimate and
/// the working-rate reconstruction allow; nothing is claimed even on noise-free data.
pub const MIN_MODEL_ERROR: f64 = 0.004;

/// Fraction of the model error beyond the sensor noise that a candidate removes:
/// `1 - S_with / S_base`, `S = sqrt(max(E^2 - N^2, 0))` (E the held-back error, N the
/// noise floor), clamped to 0..1. A candidate that brings the error down to the noise floor
/// explains everything there was to explain. When the baseline's excess `S_base` is below
/// half the noise floor (the baseline within [`NOISE_MARGIN`] of it) there is nothing to
/// explain and the fraction is 0: a ratio of two noise-sized numbers means nothing.
pub fn explained_fraction(e_base: f64, e_with: f64, noise: f64) -> f64 {
    let s = |e: f64| (e * e - noise * noise).max(0.0).sqrt();
    let sb = s(e_base);
    if sb <= 0.0 || sb < 0.5 * noise {
        return 0.0;
    }
    (1.0 - s(e_with) / sb).clamp(0.0, 1.0)
}
/// Ranking penalty per parameter: a candidate's held-back error is multiplied by
/// `1 + PARAM_PENALTY * n_parameters`, so a richer effect must fit clearly better.
pub const PARAM_PENALTY: f64 = 0.02;
/// Largest number of samples a fit simulates (longer logs are fitted on a coarser series
/// and evaluated on the full working series).
pub const MAX_FIT_SAMPLES: usize = 60_000;
/// Interleaved held-back windows for ranking (the log is cut into 2x this many windows).
pub const HOLDOUT_WINDOWS: usize = 5;
/// LM iterations per fit.
pub const MAX_ITER: usize = 40;

/// Errors of the analysis (one line each).
#[derive(Debug, thiserror::Error)]
pub enum AnalysisError {
    /// Reading the log failed.
    #[error(transparent)]
    Log(#[from] crate::log::LogError),
    /// Unknown effect name.
    #[error("unknown effect '{0}' (known: thermal_drift, saturation, iron_loss, coulomb_friction, windage, load_torque, supply_unbalance, phase_asymmetry, flux_dynamics, current_dynamics)")]
    UnknownEffect(String),
    /// The log lacks what an analysis needs.
    #[error("{0}")]
    Missing(String),
    /// Writing an output failed.
    #[error("cannot write {path}: {message}")]
    Output {
        /// The file.
        path: String,
        /// Why.
        message: String,
    },
}

/// A loaded log with its nominal parameters.
pub struct Analysis {
    /// Working series.
    pub data: Prepared,
    /// Nominal constants.
    pub nominal: Nominal,
    /// The parameter file.
    pub params: crate::params::ParamFile,
}

/// Options shared by `compare` and `explain`.
#[derive(Debug, Clone)]
pub struct Options {
    /// Effects already in the model.
    pub effects: Vec<String>,
    /// Refit the base parameters (default true).
    pub fit_base: bool,
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
}

/// An effect in the model with its fitted values.
#[derive(Debug, Clone, Serialize)]
pub struct FittedEffect {
    /// Name.
    pub effect: String,
    /// Parameters.
    pub parameters: std::collections::BTreeMap<String, ParamValue>,
    /// In words.
    pub summary: String,
}

/// Unbalance / faulty-phase analysis (runs on current-only logs too).
#[derive(Debug, Clone, Serialize)]
pub struct Unbalance {
    /// RMS negative-sequence current / RMS positive-sequence current.
    pub negative_sequence_ratio: f64,
    /// Same for the voltages (null without voltage columns).
    pub voltage_negative_sequence_ratio: Option<f64>,
    /// Phase whose winding most likely differs ("a"/"b"/"c"), null when balanced
    /// (ratio below 1 %) or when the voltage unbalance explains the current unbalance.
    pub suspect_phase: Option<String>,
    /// RMS phase currents [A] a, b, c.
    pub phase_rms_a: [f64; 3],
    /// In words.
    pub summary: String,
}

/// Result of `compare`.
#[derive(Debug, Clone, Serialize)]
pub struct CompareReport {
    /// Effects in the model.
    pub effects: Vec<String>,
    /// Mean normalised RMS error over the channels.
    pub normalized_rms_error: f64,
    /// The error a perfect model would show (sensor noise) on the same measure.
    pub noise_floor: f64,
    /// Per-channel errors.
    pub channels: Vec<metrics::ChannelError>,
    /// Where the model fails most.
    pub worst_windows: Vec<WorstWindow>,
    /// Fitted base parameters.
    pub base_parameters: std::collections::BTreeMap<String, ParamValue>,
    /// Fitted effects.
    pub fitted_effects: Vec<FittedEffect>,
    /// Analyses that could not run and why.
    pub skipped: Vec<String>,
    /// Unbalance analysis.
    pub unbalance: Unbalance,
    /// Rows read, working rate, frame.
    pub data: DataInfo,
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
    pub frame: String,
}

/// One candidate of `explain`.
#[derive(Debug, Clone, Serialize)]
pub struct Candidate {
    /// Effect name.
    pub effect: String,
    /// `normalized_rms_error` over the whole log with this effect added.
    pub normalized_rms_error: f64,
    /// Fraction of the held-back model error beyond the noise floor explained
    /// (see [`explained_fraction`]).
    pub explained_fraction: f64,
    /// `normalized_rms_error` on the held-back windows.
    pub validation_normalized_rms_error: f64,
    /// Number of parameters the effect adds.
    pub n_parameters: usize,
    /// Fitted parameters.
    pub parameters: std::collections::BTreeMap<String, ParamValue>,
    /// In words.
    pub summary: String,
    /// What the effect is.
    pub description: String,
}

/// Result of `explain`.
#[derive(Debug, Clone, Serialize)]
pub struct ExplainReport {
    /// Effects already in the model.
    pub effects: Vec<String>,
    /// Error of the model as configured (whole log).
    pub baseline_normalized_rms_error: f64,
    /// Error of the model as configured on the held-back windows.
    pub baseline_validation_normalized_rms_error: f64,
    /// Noise floor.
    pub noise_floor: f64,
    /// Candidates, best first.
    pub ranking: Vec<Candidate>,
    /// True when no candidate explains the error well.
    pub unexplained: bool,
    /// The conclusion in words.
    pub verdict: String,
    /// Candidates not evaluated and why.
    pub skipped: Vec<String>,
    /// Unbalance analysis.
    pub unbalance: Unbalance,
    /// Facts about the data.
    pub data: DataInfo,
}

/// Everything `compare` computed, for plots and the report.
pub struct CompareOutput {
    /// The JSON-facing report.
    pub report: CompareReport,
    /// The prediction.
    pub prediction: Prediction,
    /// All windows (for error-vs-condition plots).
    pub all_windows: Vec<WorstWindow>,
}

/// Everything `explain` computed.
pub struct ExplainOutput {
    /// The JSON-facing report.
    pub report: ExplainReport,
    /// Prediction of the configured model.
    pub before: Prediction,
    /// Prediction with the top-ranked candidate added (None when nothing was fitted).
    pub after: Option<(String, Prediction)>,
}

fn resolve(names: &[String]) -> Result<Vec<Box<dyn Effect>>, AnalysisError> {
    let mut v: Vec<Box<dyn Effect>> = Vec::new();
    for n in names {
        let e = effects::by_name(n).ok_or_else(|| AnalysisError::UnknownEffect(n.clone()))?;
        if !v.iter().any(|x| x.name() == e.name()) {
            v.push(e);
        }
    }
    Ok(v)
}

fn needs_ok(n: Needs, d: &Prepared) -> Result<(), String> {
    if n.voltages && !d.channels.voltages {
        return Err(
            "needs the voltage columns va_V, vb_V, vc_V (the model is driven by V_qs)".into(),
        );
    }
    if n.speed && !d.channels.speed {
        return Err("needs the speed column wm_rad_s".into());
    }
    Ok(())
}

/// Block-averages a working series by `m` (for fitting long logs).
fn coarsen(d: &Prepared, m: usize) -> Prepared {
    use rayon::prelude::*;
    if m <= 1 {
        return d.clone();
    }
    let avg = |x: &[f64]| -> Vec<f64> {
        x.par_chunks_exact(m)
            .map(|c| c.iter().sum::<f64>() / m as f64)
            .collect()
    };
    // Rotating vectors are averaged in the frame they are constant in (sign +1: the
    // positive-sequence d-q frame, -1: the negative-sequence frame) and rotated back with
    // the block's mean angle; a plain average over a supply period would cancel them.
    // One pass for the three vectors: each sample's rotation is computed once.
    let theta_c = avg(&d.theta);
    let zero = C64::new(0.0, 0.0);
    let has_v = d.v_neg.len() == d.len();
    let rotated: Vec<(C64, C64, C64)> = d
        .theta
        .par_chunks_exact(m)
        .enumerate()
        .zip(&theta_c)
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
        .collect();
    Prepared {
        t_s: avg(&d.t_s),
        dt_s: d.dt_s * m as f64,
        theta: theta_c.clone(),
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
        log_start_s: d.log_start_s,
    }
}

impl Analysis {
    /// Reads the log (streaming, bounded memory) and prepares the working series.
    ///
    /// # Errors
    /// Log errors (one line, naming file, line and column).
    pub fn load(
        log: &Path,
        params: crate::params::ParamFile,
        opts: ReadOptions,
        progress: &mut dyn FnMut(f64),
    ) -> Result<Self, AnalysisError> {
        let dec = prep::decimate_log(log, opts, progress)?;
        let data = prep::frame(&dec, &params);
        Ok(Analysis {
            data,
            nominal: Nominal::from_params(&params),
            params,
        })
    }

    fn info(&self) -> DataInfo {
        let d = &self.data;
        DataInfo {
            rows: d.rows,
            log_rate_hz: d.log_rate_hz,
            working_rate_hz: 1.0 / d.dt_s,
            duration_s: d.t_s.last().copied().unwrap_or(0.0)
                - d.t_s.first().copied().unwrap_or(0.0),
            frame: if d.channels.voltages {
                "rotor-flux frame (voltage-model flux estimate)".into()
            } else {
                "supply frame from the parameter file (current-only log)".into()
            },
        }
    }

    /// The unbalance / faulty-phase analysis (needs only the currents).
    pub fn unbalance(&self) -> Unbalance {
        let d = &self.data;
        let (mut sn, mut sp) = (0.0, 0.0);
        let mut num = C64::new(0.0, 0.0);
        let mut ph = [0.0f64; 3];
        let (mut vn, mut vp) = (0.0, 0.0);
        // Skip the first 10 % (start-up) for the ratios.
        let k0 = d.len() / 10;
        for k in k0..d.len() {
            let ineg = d.i_neg[k];
            let ipos = d.i_ab[k] - ineg;
            sn += ineg.norm_sqr();
            sp += ipos.norm_sqr();
            num += ineg * ipos; // LS for i_neg = c conj(i_pos): c = sum(i_neg i_pos)/sum|i_pos|^2
            let abc = prep::inverse_clarke(d.i_ab[k], d.i0[k]);
            for c in 0..3 {
                ph[c] += abc[c] * abc[c];
            }
            if d.channels.voltages {
                vn += d.v_neg[k].norm_sqr();
                vp += d.vq[k] * d.vq[k] + d.vd[k] * d.vd[k];
            }
        }
        let cnt = (d.len() - k0).max(1) as f64;
        let ratio = (sn / sp.max(1e-12)).sqrt();
        let vratio = if d.channels.voltages {
            Some((vn / vp.max(1e-12)).sqrt())
        } else {
            None
        };
        let c = num / sp.max(1e-12);
        let w = d.omega_s.iter().skip(k0).sum::<f64>() / cnt;
        let (phase, mu) = effects::asymmetry_phase(c, &self.nominal, w);
        // A supply unbalance drives several times more current unbalance than voltage
        // unbalance (|Z1| / |Z2|); if the voltages carry a fifth of it, no winding is suspect.
        // A supply unbalance v2/v1 drives i2/i1 = (v2/v1) |Z1| / |Z2|, Z1 = V1/I1 the
        // positive-sequence impedance, Z2 the machine's negative-sequence impedance; if
        // that accounts for at least half the current unbalance, no winding is suspect.
        let z1 = (vp / sp.max(1e-12)).sqrt();
        let z2 = effects::z2_neg(&self.nominal, w).norm().max(1e-9);
        let supply_explains = vratio
            .map(|v| v > 0.002 && v * z1 / z2 > 0.5 * ratio)
            .unwrap_or(false);
        let phase_rms_a = [
            (ph[0] / cnt).sqrt(),
            (ph[1] / cnt).sqrt(),
            (ph[2] / cnt).sqrt(),
        ];
        // The suspect winding: the phase whose RMS current deviates most from the mean (a
        // winding that lost turns draws more current, one with a bad joint less).
        let mean_rms = phase_rms_a.iter().sum::<f64>() / 3.0;
        let dev: Vec<f64> = phase_rms_a.iter().map(|r| r - mean_rms).collect();
        let kmax = (0..3)
            .max_by(|&a, &b| dev[a].abs().total_cmp(&dev[b].abs()))
            .unwrap_or(0);
        let by_rms = ['a', 'b', 'c'][kmax];
        let _ = phase;
        let suspect = if ratio > 0.01 && !supply_explains {
            Some(by_rms.to_string())
        } else {
            None
        };
        let summary = match (&suspect, supply_explains) {
            (Some(p), _) => format!(
                "negative-sequence current {:.1} % of positive sequence{}: phase {} winding differs (its current is {:.1} % {} the mean; the negative sequence fits about {:.1} % of a winding's impedance {})",
                100.0 * ratio,
                if d.channels.voltages { "" } else { " (current-only log: supply assumed balanced, from the parameter file)" },
                p,
                100.0 * dev[kmax].abs() / mean_rms.max(1e-12),
                if dev[kmax] > 0.0 { "above" } else { "below" },
                100.0 * mu.abs(),
                if mu >= 0.0 { "lost, as by shorted turns" } else { "added" }
            ),
            (None, true) => format!(
                "negative-sequence current {:.1} %, caused by the supply's {:.1} % voltage unbalance (no winding suspected)",
                100.0 * ratio,
                100.0 * vratio.unwrap_or(0.0)
            ),
            (None, false) => format!("currents balanced (negative sequence {:.2} %)", 100.0 * ratio),
        };
        Unbalance {
            negative_sequence_ratio: ratio,
            voltage_negative_sequence_ratio: vratio,
            suspect_phase: suspect,
            phase_rms_a,
            summary,
        }
    }

    fn base_table(&self, b: &BaseParams) -> std::collections::BTreeMap<String, ParamValue> {
        let n = &self.nominal;
        let mut m = std::collections::BTreeMap::new();
        let mut put = |k: &str, v: f64, u: &str, nom: f64| {
            m.insert(
                k.to_string(),
                ParamValue {
                    value: v,
                    unit: u.into(),
                    nominal: Some(nom),
                },
            );
        };
        put("ra_ohm", n.ra_ohm * b.ra_scale, "ohm", n.ra_ohm);
        put("ls_h", n.ls_h * b.ls_scale, "H", n.ls_h);
        put("b_plus_bl_nms", b.btot_nms, "N m s/rad", n.btot_nms);
        put("j_kgm2", n.j_kgm2 * b.j_scale, "kg m^2", n.j_kgm2);
        m
    }

    fn setup_all<'a>(
        &self,
        d: &Prepared,
        list: &'a [Box<dyn Effect>],
    ) -> Result<Vec<ActiveEffect<'a>>, AnalysisError> {
        let mut v = Vec::new();
        for e in list {
            needs_ok(e.needs(), d)
                .map_err(|m| AnalysisError::Missing(format!("effect {}: {m}", e.name())))?;
            let setup = e
                .setup(d, &self.nominal)
                .map_err(|m| AnalysisError::Missing(format!("effect {}: {m}", e.name())))?;
            v.push(ActiveEffect {
                effect: e.as_ref(),
                setup,
            });
        }
        Ok(v)
    }

    /// Fits `active` on the (possibly coarsened) data; returns the fit.
    fn fit_set(
        &self,
        fitdata: &Prepared,
        active: &[ActiveEffect<'_>],
        w: &Weights,
        start: &BaseParams,
        fit_base: bool,
    ) -> FitResult {
        fit::fit(fitdata, &self.nominal, active, w, start, fit_base, MAX_ITER)
    }

    fn fitted_effects(&self, active: &[ActiveEffect<'_>], f: &FitResult) -> Vec<FittedEffect> {
        active
            .iter()
            .zip(&f.effect_params)
            .map(|(a, p)| FittedEffect {
                effect: a.effect.name().to_string(),
                parameters: a
                    .setup
                    .names
                    .iter()
                    .zip(&a.setup.units)
                    .zip(p)
                    .map(|((n, u), v)| {
                        (
                            n.clone(),
                            ParamValue {
                                value: *v,
                                unit: u.to_string(),
                                nominal: None,
                            },
                        )
                    })
                    .collect(),
                summary: a.effect.describe(&a.setup, p, &self.data, &self.nominal),
            })
            .collect()
    }

    /// The noise floor of the fitted model on `d` (output noise plus the inputs' noise
    /// carried through the model, see [`metrics::noise_floor`]).
    fn model_noise_floor(
        &self,
        d: &Prepared,
        active: &[ActiveEffect<'_>],
        f: &FitResult,
        pred: &Prediction,
        w: &Weights,
    ) -> f64 {
        let mut terms = fit::terms(d, &self.nominal, active, f);
        let sigma_v = 0.5 * (metrics::white_noise_sigma(&d.vd) + metrics::white_noise_sigma(&d.vq));
        terms.input_noise = Some(model::InputNoise {
            seed: 0x006e_6f69_7365,
            sigma_v,
            sigma_i: metrics::white_noise_sigma(&d.id),
        });
        let renoised = model::simulate(d, &self.nominal, &f.base, &terms);
        metrics::noise_floor(d, w, Some((pred, &renoised)))
    }

    fn fit_data(&self) -> (Prepared, usize) {
        let m = self.data.len().div_ceil(MAX_FIT_SAMPLES).max(1);
        (coarsen(&self.data, m), m)
    }

    /// `compare`: fit the configured model and measure where it fails.
    ///
    /// # Errors
    /// Unknown effect names; an effect whose needs the log does not meet.
    pub fn compare(&self, opts: &Options) -> Result<CompareOutput, AnalysisError> {
        let d = &self.data;
        let mut skipped = Vec::new();
        let unbalance = self.unbalance();
        let info = self.info();
        if !d.channels.voltages {
            skipped.push("model prediction (I_qs, omega_r, phase currents) skipped: the log has no voltage columns va_V, vb_V, vc_V, and the model is driven by V_qs; the unbalance analysis ran on the currents".into());
            return Ok(CompareOutput {
                report: CompareReport {
                    effects: opts.effects.clone(),
                    normalized_rms_error: f64::NAN,
                    noise_floor: f64::NAN,
                    channels: vec![],
                    worst_windows: vec![],
                    base_parameters: Default::default(),
                    fitted_effects: vec![],
                    skipped,
                    unbalance,
                    data: info,
                },
                prediction: Prediction::default(),
                all_windows: vec![],
            });
        }
        if !d.channels.speed {
            skipped.push("omega_r not compared: the log has no wm_rad_s column (the model still predicts it)".into());
        }
        let list = resolve(&opts.effects)?;
        let (fd, _) = self.fit_data();
        let active_fit = self.setup_all(&fd, &list)?;
        let wf = Weights::new(&fd, 0, MAX_FIT_SAMPLES);
        let f = self.fit_set(
            &fd,
            &active_fit,
            &wf,
            &BaseParams::nominal(&self.nominal),
            opts.fit_base,
        );
        let active = self.setup_all(d, &list)?;
        // Data-dependent set-ups (load steps) are recomputed on the full series; keep the
        // fitted values where the parameter count agrees.
        let f = align(&active, f);
        let pred = fit::predict(d, &self.nominal, &active, &f);
        let w = Weights::new(d, 0, usize::MAX);
        let err: ErrorSummary = metrics::errors(d, &pred, None);
        let (worst, all) = metrics::windows(
            d,
            &pred,
            &w,
            self.params.supply.v_phase_peak(),
            self.nominal.np,
            40,
            3,
        );
        Ok(CompareOutput {
            report: CompareReport {
                effects: list.iter().map(|e| e.name().to_string()).collect(),
                normalized_rms_error: err.normalized_rms_error,
                noise_floor: self.model_noise_floor(d, &active, &f, &pred, &w),
                channels: err.channels,
                worst_windows: worst,
                base_parameters: self.base_table(&f.base),
                fitted_effects: self.fitted_effects(&active, &f),
                skipped,
                unbalance,
                data: info,
            },
            prediction: pred,
            all_windows: all,
        })
    }

    /// `explain`: rank the library effects not in the model by the held-back error they
    /// remove. `progress` gets the fraction of candidates done.
    ///
    /// # Errors
    /// Unknown effect names; a configured effect whose needs the log does not meet.
    pub fn explain(
        &self,
        opts: &Options,
        progress: &(dyn Fn(f64) + Sync),
    ) -> Result<ExplainOutput, AnalysisError> {
        use rayon::prelude::*;
        let d = &self.data;
        let unbalance = self.unbalance();
        let info = self.info();
        let mut skipped = Vec::new();
        let configured = resolve(&opts.effects)?;
        let names: Vec<String> = configured.iter().map(|e| e.name().to_string()).collect();
        if !d.channels.voltages {
            for e in effects::library() {
                if !names.contains(&e.name().to_string()) {
                    skipped.push(format!(
                        "{}: needs the voltage columns va_V, vb_V, vc_V (the model is driven by V_qs); see the unbalance analysis",
                        e.name()
                    ));
                }
            }
            let verdict = format!(
                "current-only log: only the unbalance analysis ran: {}",
                unbalance.summary
            );
            return Ok(ExplainOutput {
                report: ExplainReport {
                    effects: names,
                    baseline_normalized_rms_error: f64::NAN,
                    baseline_validation_normalized_rms_error: f64::NAN,
                    noise_floor: f64::NAN,
                    ranking: vec![],
                    unexplained: unbalance.suspect_phase.is_none(),
                    verdict,
                    skipped,
                    unbalance,
                    data: info,
                },
                before: Prediction::default(),
                after: None,
            });
        }
        let (fd, m) = self.fit_data();
        let wf = Weights::new(&fd, HOLDOUT_WINDOWS, MAX_FIT_SAMPLES);
        let w_full = Weights::new(d, HOLDOUT_WINDOWS, usize::MAX);
        let val_mask: Vec<bool> = w_full.train.iter().map(|t| !t).collect();
        let base_active = self.setup_all(&fd, &configured)?;
        let f0 = self.fit_set(
            &fd,
            &base_active,
            &wf,
            &BaseParams::nominal(&self.nominal),
            opts.fit_base,
        );
        let active_full = self.setup_all(d, &configured)?;
        let f0_full = align(&active_full, f0.clone());
        let before = fit::predict(d, &self.nominal, &active_full, &f0_full);
        let e0 = metrics::errors(d, &before, None).normalized_rms_error;
        let e0v = metrics::errors(d, &before, Some(&val_mask)).normalized_rms_error;
        let noise = self.model_noise_floor(d, &active_full, &f0_full, &before, &w_full);
        // Long logs (fitted on a coarser series): candidates are ranked on that series, so
        // the baseline they are compared with is measured there too.
        let val_mask_c: Vec<bool> = wf.train.iter().map(|t| !t).collect();
        let (_e0r, e0vr, noise_r) = if m == 1 {
            (e0, e0v, noise)
        } else {
            let b = fit::predict(&fd, &self.nominal, &base_active, &f0);
            (
                metrics::errors(&fd, &b, None).normalized_rms_error,
                metrics::errors(&fd, &b, Some(&val_mask_c)).normalized_rms_error,
                self.model_noise_floor(&fd, &base_active, &f0, &b, &wf),
            )
        };
        let lib = effects::library();
        let cands: Vec<&Box<dyn Effect>> = lib
            .iter()
            .filter(|e| !names.contains(&e.name().to_string()))
            .collect();
        // On a long log the fit series is coarse; a dynamics effect whose time constant it
        // cannot resolve (fewer than 3 samples per time constant) is skipped, not ranked.
        let unresolvable = |name: &str| -> Option<String> {
            let tau = match name {
                "current_dynamics" => self.nominal.la_h / self.nominal.ra_ohm,
                "flux_dynamics" => self.nominal.lr_h / self.nominal.rr_ohm,
                _ => return None,
            };
            (fd.dt_s > tau / 3.0).then(|| {
                format!(
                    "the fit series of this long log ({:.0} Hz) cannot resolve a {:.1} ms time constant; analyse a shorter window with --from/--to",
                    1.0 / fd.dt_s,
                    1000.0 * tau
                )
            })
        };
        for c in &cands {
            if let Some(m) = unresolvable(c.name()) {
                skipped.push(format!("{}: {m}", c.name()));
            } else if let Err(m) = needs_ok(c.needs(), d) {
                skipped.push(format!("{}: {m}", c.name()));
            } else if let Err(m) = c.setup(&fd, &self.nominal) {
                // e.g. load_torque on a log without a load change: say so, do not drop it.
                skipped.push(format!("{}: {m}", c.name()));
            }
        }
        let done = std::sync::atomic::AtomicUsize::new(0);
        let total = cands.len().max(1);
        // Predictions are not kept per candidate (memory on long logs); the top one is
        // recomputed from its fitted values.
        type Kept = (Candidate, FitResult, Vec<effects::Setup>);
        let results: Vec<Option<Kept>> = cands
            .par_iter()
            .map(|c| {
                let r = (|| {
                    needs_ok(c.needs(), d).ok()?;
                    if unresolvable(c.name()).is_some() {
                        return None;
                    }
                    let mut set: Vec<ActiveEffect<'_>> = Vec::new();
                    for (a, p) in base_active.iter().zip(&f0.effect_params) {
                        let mut s = a.setup.clone();
                        if s.init.len() == p.len() {
                            s.init = p.clone();
                        }
                        set.push(ActiveEffect {
                            effect: a.effect,
                            setup: s,
                        });
                    }
                    let s = c.setup(&fd, &self.nominal).ok()?;
                    let np = s.init.len();
                    set.push(ActiveEffect {
                        effect: c.as_ref(),
                        setup: s,
                    });
                    let f = self.fit_set(&fd, &set, &wf, &f0.base, opts.fit_base);
                    // Evaluate on the full working series.
                    let mut full: Vec<ActiveEffect<'_>> = Vec::new();
                    for a in &set {
                        full.push(ActiveEffect {
                            effect: a.effect,
                            setup: if m == 1 {
                                a.setup.clone()
                            } else {
                                a.effect.setup(d, &self.nominal).ok()?
                            },
                        });
                    }
                    let (e, ev) = if m == 1 {
                        let pred = fit::predict(d, &self.nominal, &set, &f);
                        (
                            metrics::errors(d, &pred, None).normalized_rms_error,
                            metrics::errors(d, &pred, Some(&val_mask)).normalized_rms_error,
                        )
                    } else {
                        let pred = fit::predict(&fd, &self.nominal, &set, &f);
                        (
                            metrics::errors(&fd, &pred, None).normalized_rms_error,
                            metrics::errors(&fd, &pred, Some(&val_mask_c)).normalized_rms_error,
                        )
                    };
                    let f = align(&full, f);
                    let setups: Vec<effects::Setup> =
                        full.iter().map(|a| a.setup.clone()).collect();
                    let last = full.len() - 1;
                    let fe = self.fitted_effects(&full, &f);
                    let me = fe.get(last)?.clone();
                    let explained = explained_fraction(e0vr, ev, noise_r);
                    Some((
                        Candidate {
                            effect: c.name().to_string(),
                            normalized_rms_error: e,
                            explained_fraction: explained,
                            validation_normalized_rms_error: ev,
                            n_parameters: np,
                            parameters: me.parameters,
                            summary: me.summary,
                            description: c.description().to_string(),
                        },
                        f,
                        setups,
                    ))
                })();
                let k = done.fetch_add(1, std::sync::atomic::Ordering::Relaxed) + 1;
                progress(k as f64 / total as f64);
                r
            })
            .collect();
        let mut ranked: Vec<Kept> = results.into_iter().flatten().collect();
        // Rank by held-back error, each extra parameter costing PARAM_PENALTY of it.
        let score = |c: &Candidate| {
            c.validation_normalized_rms_error * (1.0 + PARAM_PENALTY * c.n_parameters as f64)
        };
        ranked.sort_by(|a, b| {
            score(&a.0)
                .total_cmp(&score(&b.0))
                .then(a.0.n_parameters.cmp(&b.0.n_parameters))
        });
        // supply_unbalance and phase_asymmetry both add a negative-sequence current; on a
        // log at one operating point they fit equally well. When their held-back errors are
        // within 25 %, the measured voltage unbalance decides (the unbalance analysis: does
        // the supply's negative-sequence voltage account for the current unbalance?).
        if ranked.len() >= 2 {
            let pair = [ranked[0].0.effect.as_str(), ranked[1].0.effect.as_str()];
            let is_pair = pair.contains(&"supply_unbalance") && pair.contains(&"phase_asymmetry");
            let close = score(&ranked[1].0) <= 1.25 * score(&ranked[0].0);
            let supply = unbalance.suspect_phase.is_none()
                && unbalance.voltage_negative_sequence_ratio.unwrap_or(0.0) > 0.002;
            let want_first = if supply {
                "supply_unbalance"
            } else {
                "phase_asymmetry"
            };
            if is_pair && close && ranked[0].0.effect != want_first {
                ranked.swap(0, 1);
            }
        }
        // load_torque whose fitted levels are all alike (within 3 % of the rated torque: the
        // step the observer proposed is not there) is a constant torque, the same equation
        // as coulomb_friction at positive speed; when the two are within 10 %, the simpler
        // name, coulomb_friction, goes first (DESIGN-level note in the README).
        if ranked.len() >= 2 {
            let pos = |name: &str| ranked.iter().position(|c| c.0.effect == name);
            if let (Some(lt), Some(cf)) = (pos("load_torque"), pos("coulomb_friction")) {
                let levels: Vec<f64> = ranked[lt].0.parameters.values().map(|p| p.value).collect();
                let spread = levels.iter().fold(f64::NEG_INFINITY, |a, &b| a.max(b))
                    - levels.iter().fold(f64::INFINITY, |a, &b| a.min(b));
                let constant = spread < 0.03 * self.nominal.torque_scale_nm;
                let close = score(&ranked[cf].0) <= 1.10 * score(&ranked[lt].0);
                if lt == 0 && cf == 1 && constant && close {
                    ranked.swap(0, 1);
                }
            }
        }
        let best = ranked
            .first()
            .map(|c| c.0.explained_fraction)
            .unwrap_or(0.0);
        let near_noise = e0v <= (NOISE_MARGIN * noise).max(MIN_MODEL_ERROR);
        let unexplained = best < EXPLAINED_MIN || near_noise;
        let verdict = match ranked.first() {
            _ if near_noise => format!(
                "nothing to explain: the model's error {:.4} (held-back {:.4}) is within {:.2}x the noise floor {:.4} or below {:.3}",
                e0, e0v, NOISE_MARGIN, noise, MIN_MODEL_ERROR
            ),
            Some((c, _, _)) if !unexplained => format!(
                "missing effect: {} explains {:.0} % of the held-back error ({:.4} -> {:.4}); {}. Add it with --effects {}",
                c.effect,
                100.0 * c.explained_fraction,
                e0vr,
                c.validation_normalized_rms_error,
                c.summary,
                names.iter().cloned().chain([c.effect.clone()]).collect::<Vec<_>>().join(",")
            ),
            Some((c, _, _)) => format!(
                "unexplained: the best candidate ({}) explains only {:.0} % of the held-back error (threshold {:.0} %); the error is not one of the library's effects",
                c.effect,
                100.0 * c.explained_fraction,
                100.0 * EXPLAINED_MIN
            ),
            None => "unexplained: no candidate could be fitted".into(),
        };
        let after = if unexplained {
            None
        } else {
            ranked.first().and_then(|(c, f, setups)| {
                let names: Vec<String> = names.iter().cloned().chain([c.effect.clone()]).collect();
                let boxes = resolve(&names).ok()?;
                let active: Vec<ActiveEffect<'_>> = boxes
                    .iter()
                    .zip(setups)
                    .map(|(e, s)| ActiveEffect {
                        effect: e.as_ref(),
                        setup: s.clone(),
                    })
                    .collect();
                Some((c.effect.clone(), fit::predict(d, &self.nominal, &active, f)))
            })
        };
        Ok(ExplainOutput {
            report: ExplainReport {
                effects: names,
                baseline_normalized_rms_error: e0,
                baseline_validation_normalized_rms_error: e0v,
                noise_floor: noise,
                ranking: ranked.into_iter().map(|c| c.0).collect(),
                unexplained,
                verdict,
                skipped,
                unbalance,
                data: info,
            },
            before,
            after,
        })
    }
}

/// Keeps fitted effect values only where the full-series set-up has the same parameter
/// count (data-dependent set-ups such as load steps may differ between the coarse and the
/// full series; then the set-up's initial values stand).
fn align(active: &[ActiveEffect<'_>], mut f: FitResult) -> FitResult {
    for (a, p) in active.iter().zip(f.effect_params.iter_mut()) {
        if p.len() != a.setup.init.len() {
            *p = a.setup.init.clone();
        }
    }
    f
}

#[cfg(test)]
mod tests {
    use super::explained_fraction;

    #[test]
    fn explained_fraction_of_the_excess_over_noise() {
        // Baseline 5x the noise, candidate at the noise floor: everything explained.
        assert!((explained_fraction(0.05, 0.01, 0.01) - 1.0).abs() < 1e-12);
        // Candidate halves the excess: sqrt(0.05^2 - 0.01^2) -> half of it.
        let sb = (0.05f64.powi(2) - 0.01f64.powi(2)).sqrt();
        let e_with = ((0.5 * sb).powi(2) + 0.01f64.powi(2)).sqrt();
        assert!((explained_fraction(0.05, e_with, 0.01) - 0.5).abs() < 1e-9);
        // A baseline within the noise margin has nothing to explain.
        assert_eq!(explained_fraction(0.0105, 0.0100, 0.0100), 0.0);
        // A candidate that makes things worse explains nothing.
        assert_eq!(explained_fraction(0.05, 0.06, 0.01), 0.0);
    }
}
