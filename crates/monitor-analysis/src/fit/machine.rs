//! The six physical base parameters of the machine (Rs, Rr, the leakage inductances, Lm,
//! J, B + Bl) refitted as factors on the parameter file: the ladder's base rung.
//!
//! [`super::fit`] refits the paper's four (Ra = Rs + (Ls/Lr) Rr, Ls, B + Bl, J), which is
//! what the simplified model's steady state can tell apart. A user's file comes from a
//! nameplate, a data sheet or a no-load and locked-rotor test, and a warm stator moves Rs
//! alone: read as Ra it is a mix of Rs and Rr that says neither. Here every trial point is
//! the file with its values scaled ([`MachineScales::apply`]) and the machine's constants
//! derived again ([`MachineConstants::from_params`]), so the full-order model reads each
//! parameter where it acts (Rs in the stator's transient and the voltage drop, Rr in the
//! slip and the rotor time constant, the leakages in the transient inductance, Lm in the
//! magnetising current).
//!
//! # Priors weighed against the log's noise floor
//! Each factor has a Gaussian prior about the file's value with the standard deviation of
//! what a user's file gets wrong ([`PRIOR_SD`]: a DC resistance at an unknown temperature,
//! a locked-rotor test's split of the leakages, a data sheet's inertia). One standard
//! deviation costs as much as the log's own noise floor `N` in normalized error (the prior
//! residual is `N z`): a parameter moves off the file's value where the log shows it by more
//! than its noise can, and stays where the log cannot tell (Rs against Rr on a log without
//! a transient). A fixed weight (the paper fit's 0.01) held Rs at the file's value on clean
//! logs and let it wander on noisy ones.
//!
//! # Intervals
//! The 95 % interval of each factor is the Gauss-Newton one, `1.96 sqrt(s² κ (JᵀJ)⁻¹_ii)`,
//! J the data residuals' Jacobian at the fit (forward differences), s² their variance per
//! element, and `κ = (1 + ρ)/(1 − ρ)` the variance inflation of residuals correlated from
//! sample to sample with lag-one correlation ρ (an AR(1) model's effective sample size,
//! Bartlett 1946; a model error is structural and correlated over whole events, so its
//! samples are not independent observations). A factor whose interval is wider than
//! [`UNIDENTIFIED_SD`] either way is not identified by the log.

use super::{data_residuals, training_targets, ActiveEffect, EffectValuesError, Gram};
use crate::lm::{self, LeastSquares};
use crate::metrics::Weights;
use crate::prep::Prepared;
use crate::simplified_model::{rotations, simulate_rot, BaseParams, MachineConstants, ModelTerms};
use monitor_io::params::ParamFile;
use rayon::prelude::*;
use serde::Serialize;

/// One of the six physical base parameters of the base rung (JSON `base`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, PartialOrd, Ord)]
#[serde(rename_all = "snake_case")]
pub enum BaseKey {
    /// The stator resistance Rs.
    Rs,
    /// The rotor resistance Rr (referred to the stator).
    Rr,
    /// The stator and rotor leakage inductances Lls and Llr, by one factor (a terminal
    /// measurement cannot split them: the T-equivalent circuit has one parameter more than
    /// the machine shows at its terminals).
    Leakage,
    /// The magnetising inductance Lm.
    Lm,
    /// The inertia J of rotor and load.
    J,
    /// The viscous friction B + Bl.
    B,
}

impl BaseKey {
    /// The six, in the order of the fit's parameter vector.
    pub const ALL: [BaseKey; 6] = [
        BaseKey::Rs,
        BaseKey::Rr,
        BaseKey::Leakage,
        BaseKey::Lm,
        BaseKey::J,
        BaseKey::B,
    ];

    /// The JSON name.
    pub fn name(self) -> &'static str {
        match self {
            BaseKey::Rs => "rs",
            BaseKey::Rr => "rr",
            BaseKey::Leakage => "leakage",
            BaseKey::Lm => "lm",
            BaseKey::J => "j",
            BaseKey::B => "b",
        }
    }

    /// How the parameter is printed (`Rs`, `Rr`, `Lls, Llr`, ...).
    pub fn symbol(self) -> &'static str {
        match self {
            BaseKey::Rs => "Rs",
            BaseKey::Rr => "Rr",
            BaseKey::Leakage => "Lls, Llr",
            BaseKey::Lm => "Lm",
            BaseKey::J => "J",
            BaseKey::B => "B + Bl",
        }
    }

    /// Its place in [`BaseKey::ALL`].
    pub fn index(self) -> usize {
        self as usize
    }
}

impl std::fmt::Display for BaseKey {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

/// The six physical base parameters as factors on the parameter file (1: the file's
/// value), B + Bl as a value [N m s/rad].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MachineScales {
    /// Rs factor.
    pub rs: f64,
    /// Rr factor.
    pub rr: f64,
    /// Lls and Llr factor.
    pub leakage: f64,
    /// Lm factor.
    pub lm: f64,
    /// J factor.
    pub j: f64,
    /// B + Bl [N m s/rad].
    pub b_nms: f64,
}

impl MachineScales {
    /// The file's own values.
    pub fn of_file(p: &ParamFile) -> Self {
        MachineScales {
            rs: 1.0,
            rr: 1.0,
            leakage: 1.0,
            lm: 1.0,
            j: 1.0,
            b_nms: p.motor.b_nms + p.motor.bl_nms,
        }
    }

    fn to_vec(self) -> Vec<f64> {
        vec![self.rs, self.rr, self.leakage, self.lm, self.j, self.b_nms]
    }

    fn from_slice(x: &[f64]) -> Self {
        let g = |i: usize| x.get(i).copied().unwrap_or(1.0);
        MachineScales {
            rs: g(0),
            rr: g(1),
            leakage: g(2),
            lm: g(3),
            j: g(4),
            b_nms: g(5),
        }
    }

    /// These factors with the paper fit's base parameters `b` (relative to the file with
    /// these factors) taken in: Ra's scale on Rs and Rr alike, Ls's on Lm and the leakages
    /// alike, J's on J, B + Bl as fitted.
    pub fn with_paper(&self, b: &BaseParams) -> Self {
        MachineScales {
            rs: self.rs * b.ra_scale,
            rr: self.rr * b.ra_scale,
            leakage: self.leakage * b.ls_scale,
            lm: self.lm * b.ls_scale,
            j: self.j * b.j_scale,
            b_nms: b.btot_nms,
        }
    }

    /// The factor (or, for B + Bl, the value) of `key`.
    pub fn get(&self, key: BaseKey) -> f64 {
        match key {
            BaseKey::Rs => self.rs,
            BaseKey::Rr => self.rr,
            BaseKey::Leakage => self.leakage,
            BaseKey::Lm => self.lm,
            BaseKey::J => self.j,
            BaseKey::B => self.b_nms,
        }
    }

    /// `key`'s relative change from the file `p` (0.19 = +19 %); for B + Bl relative to the
    /// file's B + Bl, or the value itself when the file has none.
    pub fn change(&self, key: BaseKey, p: &ParamFile) -> f64 {
        match key {
            BaseKey::B => {
                let b0 = p.motor.b_nms + p.motor.bl_nms;
                if b0 > 0.0 {
                    self.b_nms / b0 - 1.0
                } else {
                    self.b_nms
                }
            }
            k => self.get(k) - 1.0,
        }
    }

    /// The file `p` with these values: Rs and Rr scaled, the leakages and Lm scaled apart
    /// (Ls = Lls + Lm and Lr = Llr + Lm follow), J scaled, B + Bl set (the file's B kept
    /// up to the total, the rest as Bl).
    pub fn apply(&self, p: &ParamFile) -> ParamFile {
        let mut q = *p;
        let m = &mut q.motor;
        let (lls, llr) = (p.motor.ls_h - p.motor.lm_h, p.motor.lr_h - p.motor.lm_h);
        m.rs_ohm = p.motor.rs_ohm * self.rs;
        m.rr_ohm = p.motor.rr_ohm * self.rr;
        m.lm_h = p.motor.lm_h * self.lm;
        m.ls_h = lls * self.leakage + m.lm_h;
        m.lr_h = llr * self.leakage + m.lm_h;
        m.j_kgm2 = p.motor.j_kgm2 * self.j;
        let btot = self.b_nms.max(0.0);
        m.b_nms = p.motor.b_nms.min(btot);
        m.bl_nms = btot - m.b_nms;
        q
    }
}

/// Prior standard deviations of the factors (Rs, Rr, leakages, Lm, J; B + Bl as a share
/// of its scale, [`super::btot_scale`]): what a user's file gets wrong. Rs: a DC
/// measurement at an unknown winding temperature (±40 K is ±16 %); Rr: a locked-rotor
/// test at line frequency reads the skin effect's Rr (about +20 %); the leakages: the
/// split of the locked-rotor reactance by design class (IEEE 112) and the test's
/// saturation of the leakage paths (25 %); Lm: a no-load test at rated voltage (15 %); J:
/// the coupled load's inertia (30 %); B + Bl: half its scale, as the paper fit's.
pub const PRIOR_SD: [f64; 6] = [0.15, 0.2, 0.25, 0.15, 0.3, 0.5];

/// Bounds of the factors in the fit (B + Bl: 0 up to 50 times its scale).
const FIT_BOUNDS: [(f64, f64); 5] = [(0.4, 3.0), (0.4, 3.0), (0.3, 3.0), (0.4, 2.5), (0.2, 5.0)];

/// A factor whose 95 % interval reaches beyond this either way (as a relative change) is
/// not identified by the log.
pub const UNIDENTIFIED_SD: f64 = 0.5;

/// The base rung's fit: the factors, the effects' values and how the solve ended.
#[derive(Debug, Clone)]
pub struct MachineFit {
    /// The refitted factors.
    pub scales: MachineScales,
    /// The effects' values, one set per effect in the order given.
    pub effect_params: Vec<Vec<f64>>,
    /// How the solver ended.
    pub report: lm::Report,
    /// The effects' values corrected for the inputs' noise (as
    /// [`super::FitResult::corrected`]); `None` where no effect is biased by it.
    pub corrected: Option<Vec<Vec<f64>>>,
}

impl MachineFit {
    /// The file `p` with the refitted values.
    pub fn params(&self, p: &ParamFile) -> ParamFile {
        self.scales.apply(p)
    }
}

struct MachineProblem<'a> {
    d: &'a Prepared,
    file: &'a ParamFile,
    effects: &'a [ActiveEffect<'a>],
    w: &'a Weights,
    rot: crate::simplified_model::Rotations,
    targets: Vec<(usize, [f64; 5])>,
    norm: f64,
    /// The priors' weight (0: no priors, the data alone).
    prior_weight: f64,
    /// The file's B + Bl and its scale's share [`PRIOR_SD`] (the fit's conditioning).
    b0: f64,
    b_sd: f64,
    /// Whether B + Bl has a prior: not with an effect that carries its own speed-dependent
    /// torque ([`crate::effects::EffectModel::takes_viscous_part`]).
    b_prior: bool,
    /// B + Bl's prior standard deviation: the viscous coefficient that carries the rated
    /// torque at synchronous speed (a user's file does not know the load as a viscous
    /// coefficient, `bl_nms = 0`: the load is the usual unknown).
    b_sd_load: f64,
    /// Extra input noise in every simulation (`None`: the log's inputs; SIMEX's refits).
    extra_noise: Option<crate::simplified_model::InputNoise>,
}

impl MachineProblem<'_> {
    /// The machine at `x` and the effects' terms on it (an effect whose values are the
    /// machine's own takes them from the machine, [`EffectModel::derived_from_machine`]).
    fn machine(&self, x: &[f64]) -> Result<(MachineConstants, ModelTerms), EffectValuesError> {
        let n = MachineConstants::from_params(&MachineScales::from_slice(x).apply(self.file));
        let mut terms = ModelTerms::default();
        let mut rest = x.get(6..).unwrap_or(&[]);
        for e in self.effects {
            let k = e.setup.len();
            let (p, tail) = rest.split_at(k.min(rest.len()));
            rest = tail;
            match e.effect.derived_from_machine(&n) {
                Some(own) if own.len() == k => {
                    e.setup.contribute(&own, self.d, &n, &mut terms)?;
                }
                _ => e.setup.contribute(p, self.d, &n, &mut terms)?,
            }
        }
        terms.input_noise = self.extra_noise;
        Ok((n, terms))
    }

    /// The effects' values at `x`, one set per effect (the machine's own where an effect's
    /// values are derived from it).
    fn effect_values(&self, x: &[f64]) -> Vec<Vec<f64>> {
        let n = MachineConstants::from_params(&MachineScales::from_slice(x).apply(self.file));
        let mut out = Vec::with_capacity(self.effects.len());
        let mut rest = x.get(6..).unwrap_or(&[]);
        for e in self.effects {
            let k = e.setup.len();
            let (p, tail) = rest.split_at(k.min(rest.len()));
            rest = tail;
            out.push(match e.effect.derived_from_machine(&n) {
                Some(own) if own.len() == k => own,
                _ => p.to_vec(),
            });
        }
        out
    }

    /// The indices of `x` the fit frees: the six base parameters and the effects' own
    /// values (not those derived from the machine).
    fn free(&self, len: usize) -> Vec<usize> {
        let n = MachineConstants::from_params(self.file);
        let mut free: Vec<usize> = (0..6).collect();
        let mut o = 6;
        for e in self.effects {
            let k = e.setup.len();
            let derived = e
                .effect
                .derived_from_machine(&n)
                .is_some_and(|v| v.len() == k);
            if !derived {
                free.extend(o..o + k);
            }
            o += k;
        }
        free.retain(|&i| i < len);
        free
    }

    fn data_only(&self, x: &[f64]) -> Vec<f64> {
        let Ok((n, terms)) = self.machine(x) else {
            return vec![1e3; self.w.n_channels() * self.targets.len()];
        };
        let b = BaseParams {
            btot_nms: x.get(5).copied().unwrap_or(0.0),
            ..BaseParams::nominal(&n)
        };
        let p = simulate_rot(self.d, &self.rot, &n, &b, &terms);
        data_residuals(self.d, &p, &self.targets, self.w, self.norm, 6)
    }
}

impl LeastSquares for MachineProblem<'_> {
    type Cache = ();
    fn cache(&self, _x: &[f64]) {}
    fn residuals(&self, x: &[f64], _c: &()) -> Vec<f64> {
        let mut r = self.data_only(x);
        if self.prior_weight > 0.0 {
            for (i, sd) in PRIOR_SD.iter().enumerate().take(5) {
                r.push(self.prior_weight * (x[i] - 1.0) / sd);
            }
            if self.b_prior {
                r.push(self.prior_weight * (x[5] - self.b0) / self.b_sd_load.max(1e-12));
            }
        }
        r
    }
}

/// Fits the six physical base parameters (as factors on `file`, from `start`) together
/// with the effects' values (from each set-up's start) on the training samples of `w`,
/// each factor's prior weighing `prior_weight` (the log's noise floor, module doc).
///
/// # Errors
/// [`EffectValuesError`] when an effect refuses its set-up's own values.
pub fn fit_machine(
    d: &Prepared,
    file: &ParamFile,
    effects: &[ActiveEffect<'_>],
    w: &Weights,
    start: &MachineScales,
    prior_weight: f64,
    max_iter: usize,
) -> Result<MachineFit, EffectValuesError> {
    fit_machine_pinned(d, file, effects, w, start, prior_weight, max_iter, None)
}

/// [`fit_machine`] with the base parameter `pin` (if any) held at the file's value: the
/// fit of the same model without that change, for what the others and the effects' values
/// make of the log then.
///
/// # Errors
/// As [`fit_machine`].
#[allow(clippy::too_many_arguments)]
pub fn fit_machine_pinned(
    d: &Prepared,
    file: &ParamFile,
    effects: &[ActiveEffect<'_>],
    w: &Weights,
    start: &MachineScales,
    prior_weight: f64,
    max_iter: usize,
    pin: Option<BaseKey>,
) -> Result<MachineFit, EffectValuesError> {
    let prob = problem(d, file, effects, w, prior_weight);
    let inits: Vec<f64> = effects
        .iter()
        .flat_map(|e| &e.setup.params)
        .map(|q| q.init)
        .collect();
    let (mut x, bounds) = start_and_bounds(&prob, start, effects, &inits);
    if let Some(k) = pin {
        x[k.index()] = MachineScales::of_file(file).get(k);
    }
    prob.machine(&x)?;
    let mut free = prob.free(x.len());
    free.retain(|&i| pin.is_none_or(|k| i != k.index()));
    let (x, report) = lm::solve(&prob, x, &bounds, &free, max_iter);
    let renoised = |nz| MachineProblem {
        extra_noise: Some(nz),
        ..problem(d, file, effects, w, prior_weight)
    };
    let corrected = match effects.iter().any(|e| e.effect.biased_by_input_noise()) {
        true => super::simex::corrected(d, renoised, &x, &bounds, &free, max_iter),
        false => None,
    };
    Ok(MachineFit {
        scales: MachineScales::from_slice(&x),
        effect_params: prob.effect_values(&x),
        report,
        corrected: corrected.map(|c| prob.effect_values(&c)),
    })
}

/// The six base factors refitted (from `mf`'s) around the effects held at `mf`'s values
/// corrected for the inputs' noise ([`MachineFit::corrected`]), to predict with; `mf`
/// itself where nothing was corrected. Arguments and errors as [`fit_machine`]'s.
pub fn around_corrected(
    d: &Prepared,
    file: &ParamFile,
    effects: &[ActiveEffect<'_>],
    w: &Weights,
    mf: MachineFit,
    prior_weight: f64,
    max_iter: usize,
) -> Result<MachineFit, EffectValuesError> {
    let Some(values) = mf.corrected.clone() else {
        return Ok(mf);
    };
    let prob = problem(d, file, effects, w, prior_weight);
    let flat: Vec<f64> = values.iter().flatten().copied().collect();
    let (x, bounds) = start_and_bounds(&prob, &mf.scales, effects, &flat);
    prob.machine(&x)?;
    let free: Vec<usize> = (0..6).collect();
    let (x, report) = lm::solve(&prob, x, &bounds, &free, max_iter);
    Ok(MachineFit {
        scales: MachineScales::from_slice(&x),
        effect_params: values.clone(),
        report,
        corrected: Some(values),
    })
}

/// The machine fit's start (the factors `start`, then the effects' `values`) and bounds:
/// [`FIT_BOUNDS`], B + Bl up to 50 prior deviations, each effect value's its set-up's.
fn start_and_bounds(
    prob: &MachineProblem<'_>,
    start: &MachineScales,
    effects: &[ActiveEffect<'_>],
    values: &[f64],
) -> (Vec<f64>, lm::Bounds) {
    let bs = prob.b_sd / PRIOR_SD[5];
    let mut x = start.to_vec();
    let mut lo: Vec<f64> = FIT_BOUNDS.iter().map(|b| b.0).collect();
    let mut hi: Vec<f64> = FIT_BOUNDS.iter().map(|b| b.1).collect();
    lo.push(0.0);
    hi.push(50.0 * bs);
    let mut scale = vec![0.05, 0.05, 0.05, 0.05, 0.1, 0.2 * bs];
    for (q, v) in effects.iter().flat_map(|e| &e.setup.params).zip(values) {
        x.push(*v);
        lo.push(q.lo);
        hi.push(q.hi);
        scale.push(q.scale);
    }
    (x, lm::Bounds { lo, hi, scale })
}

fn problem<'a>(
    d: &'a Prepared,
    file: &'a ParamFile,
    effects: &'a [ActiveEffect<'a>],
    w: &'a Weights,
    prior_weight: f64,
) -> MachineProblem<'a> {
    let n = MachineConstants::from_params(file);
    let targets = training_targets(d, w);
    MachineProblem {
        d,
        file,
        effects,
        w,
        rot: rotations(d),
        norm: 1.0 / (targets.len().max(1) as f64).sqrt(),
        targets,
        prior_weight,
        b0: n.btot_nms,
        b_sd: PRIOR_SD[5] * super::btot_scale(&n, d),
        b_prior: !effects.iter().any(|e| e.effect.takes_viscous_part()),
        b_sd_load: n.torque_scale_nm / crate::effects::sync_speed_mech(d, &n),
        extra_noise: None,
    }
}

/// The 95 % half-widths of the six factors at the fit `f` on the training samples of `w`
/// (module doc, "Intervals"), in the factors' units (B + Bl in N m s/rad); `None` where the
/// log does not determine the factor at all (it lies in the Jacobian's null space).
///
/// # Errors
/// As [`fit_machine`].
pub fn machine_half_widths(
    d: &Prepared,
    file: &ParamFile,
    effects: &[ActiveEffect<'_>],
    w: &Weights,
    f: &MachineFit,
) -> Result<[Option<f64>; 6], EffectValuesError> {
    let prob = problem(d, file, effects, w, 0.0);
    let mut x = f.scales.to_vec();
    for p in &f.effect_params {
        x.extend_from_slice(p);
    }
    prob.machine(&x)?;
    let bs = prob.b_sd / PRIOR_SD[5];
    let mag: Vec<f64> = (0..x.len())
        .map(|i| match i {
            0..=4 => 1.0,
            5 => x[5].abs().max(0.1 * bs),
            _ => x[i].abs().max(1e-6),
        })
        .collect();
    let r = prob.data_only(&x);
    let free = prob.free(x.len());
    let cols: Vec<Vec<f64>> = free
        .par_iter()
        .map(|&i| i)
        .map(|i| {
            let h = 1e-3 * mag[i];
            let mut xp = x.clone();
            xp[i] += h;
            let rp = prob.data_only(&xp);
            rp.iter()
                .zip(&r)
                .map(|(a, b)| (a - b) / h * mag[i])
                .collect()
        })
        .collect();
    let g = Gram::of(&cols);
    let m = r.len().max(1);
    let s2 = r.iter().map(|v| v * v).sum::<f64>() / (m.saturating_sub(free.len()).max(1)) as f64;
    let kappa = inflation(&r, prob.w.n_channels());
    let mut out = [None; 6];
    for (i, o) in out.iter_mut().enumerate() {
        let inv = g.inverse_diagonal(i);
        if inv.is_finite() && inv >= 0.0 {
            *o = Some(1.96 * (s2 * kappa * inv).sqrt() * mag[i]);
        }
    }
    Ok(out)
}

/// The variance inflation `(1 + rho)/(1 - rho)` of residuals `r` laid out sample by sample
/// with `nc` channels each, rho their mean lag-one correlation over the channels (clamped to
/// 0..0.995).
fn inflation(r: &[f64], nc: usize) -> f64 {
    if nc == 0 || r.len() < 2 * nc {
        return 1.0;
    }
    let n = r.len() / nc;
    let mut rho = 0.0;
    for c in 0..nc {
        let (mut num, mut den) = (0.0, 0.0);
        for t in 0..n {
            let a = r[t * nc + c];
            den += a * a;
            if t + 1 < n {
                num += a * r[(t + 1) * nc + c];
            }
        }
        if den > 0.0 {
            rho += num / den;
        }
    }
    let rho = (rho / nc as f64).clamp(0.0, 0.995);
    (1.0 + rho) / (1.0 - rho)
}

#[cfg(test)]
mod tests;
