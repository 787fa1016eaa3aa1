//! `identify`: the T-equivalent circuit and the mechanics of a machine from one log of its
//! healthy running (a direct-on-line start, supply or load steps, or steady running at two
//! or more points), starting from a parameter file (e.g. `params from-nameplate`'s).
//!
//! Method (output-error identification, e.g. Ljung, *System Identification*, 2nd ed.,
//! ch. 7; for induction machines Toliyat, Levi and Raina, "A review of RFO induction motor
//! parameter estimation techniques", IEEE Trans. Energy Convers. 18(2), 2003):
//! 1. the simulator's full-order T-equivalent machine ([`model`]) is driven by the log's
//!    phase voltages (amplitude-invariant Clarke) and, when the log has it, by its speed;
//! 2. Levenberg-Marquardt (`crate::lm`) fits Rs, Rr, Lls + Llr and Lm (and,
//!    without a speed channel, J and B + Bl too) to the measured stator currents, the
//!    parameters as `ln(p / p_start)`;
//! 3. with the speed, J and B + Bl follow from the torque balance
//!    `T_e = J domega_m/dt + (B + Bl) omega_m` by linear least squares over 20 ms windows,
//!    `T_e` from the identified electrical model ([`mechanics`]).
//!
//! Each value's 95 % interval is `exp(x +- 1.96 sigma)` around the log-space estimate,
//! `sigma^2` the larger of the diagonal of `s^2 (J^T J)^-1` at the optimum (`s^2` the
//! residual variance: the Gauss-Newton covariance, white residuals) and the block
//! sandwich covariance that takes in the model's error ([`uncertainty`]: what the
//! residual's structure says), scaled to Student's t. A value whose interval is wider
//! than the value itself, or whose direction the data leave flat (a singular `J^T J`), is
//! "not identified", with the reason; the written file keeps the start value for it.
//!
//! What the terminals cannot tell: the split of the leakage into Lls and Llr (the linear
//! T-circuit is terminal-equivalent to the inverse-Gamma circuit for any split); the
//! start file's split is kept, and Rr and Lm are those of that split.

pub mod mechanics;
pub mod model;
mod output;
mod refuse;
mod samples;
pub mod uncertainty;

use crate::lm::{self, Bounds};
use model::{CurrentFit, IdentifiedCircuit, N_PARAMS};
use monitor_io::params::ParamFile;
use serde::Serialize;

pub use output::{inverse_gamma_line, to_toml, without_columns, COLUMNS_COPIED};
pub use refuse::{refusal, IdentifyRefusal, MAX_FIT_ERROR};
pub use samples::{IdentifyError, Samples, MIN_DURATION_S};

/// The identified parameters' names, keys and units, in [`IdentifiedCircuit::to_vec`]'s order.
pub const PARAMS: [(&str, &str, &str); N_PARAMS] = [
    ("Rs", "rs_ohm", "ohm"),
    ("Rr", "rr_ohm", "ohm"),
    ("Lls + Llr", "lls_h + llr_h", "H"),
    ("Lm", "lm_h", "H"),
    ("J", "j_kgm2", "kg m^2"),
    ("B + Bl", "b_nms + bl_nms", "N m s/rad"),
];

/// One parameter's result.
#[derive(Debug, Clone, Serialize)]
pub struct Estimate {
    /// Its name ("Rs", "Lls + Llr", ...).
    pub name: String,
    /// Its parameter-file key (or sum of keys).
    pub key: String,
    /// Unit.
    pub unit: String,
    /// The start file's value.
    pub start: f64,
    /// The identified value; `None`: not identified.
    pub value: Option<f64>,
    /// The 95 % interval (when identified).
    pub lo: Option<f64>,
    /// Upper end of the 95 % interval.
    pub hi: Option<f64>,
    /// Why not identified.
    pub not_identified_because: Option<String>,
}

impl Estimate {
    /// The value the written file gets: the identified one, else the start's.
    pub fn written(&self) -> f64 {
        self.value.unwrap_or(self.start)
    }
}

/// What `identify` found.
#[derive(Debug, Clone, Serialize)]
pub struct Identification {
    /// Per parameter ([`PARAMS`]' order, then "Lls" and "Llr", never identified apart).
    pub estimates: Vec<Estimate>,
    /// The parameter file to write (the start's, the identified values in).
    #[serde(skip)]
    pub params: ParamFile,
    /// The stator leakage share Lls / (Lls + Llr) kept from the start file.
    pub stator_leakage_share: f64,
    /// The identified circuit in its split-free (inverse-Gamma) form, when Rs, Rr, the
    /// leakage and Lm were all identified: the parameters a terminal log determines
    /// whatever the split.
    pub inverse_gamma: Option<InverseGamma>,
    /// Samples fitted, and the log's window [s].
    pub samples: usize,
    /// First and last time fitted [s].
    pub window_s: (f64, f64),
    /// The log had a speed channel (imposed on the model).
    pub speed_imposed: bool,
    /// RMS of the current error at the start and at the optimum, over the measured
    /// current's RMS.
    pub relative_rms_error_start: f64,
    /// At the optimum.
    pub relative_rms_error: f64,
    /// How the solver ended.
    pub solver: lm::Report,
    /// The log's supply where it differs from the start file's (the written file takes the
    /// log's, [`SupplyFromLog`]); `None` where the file's holds.
    pub supply_from_log: Option<SupplyFromLog>,
}

/// The supply the log was recorded on, where it differs from the start file's by more than
/// [`SUPPLY_FREQUENCY_OFF`] in frequency or [`SUPPLY_VOLTAGE_OFF`] in voltage: `identify`
/// reports it and writes the log's into the identified file (a 220 V 60 Hz file given for a
/// 400 V 50 Hz log kept both without a word). JSON `supply_from_log`.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct SupplyFromLog {
    /// The file's line-to-line RMS voltage [V].
    pub file_v_ll_rms: f64,
    /// The log's: the median over the log of the voltage vector's magnitude, as a
    /// line-to-line RMS [V].
    pub log_v_ll_rms: f64,
    /// The file's frequency [Hz].
    pub file_f_hz: f64,
    /// The log's: the voltage vector's mean turn over the log [Hz].
    pub log_f_hz: f64,
}

/// Relative difference of the log's supply frequency from the file's beyond which the log's
/// is taken (the data-quality stage's `SUPPLY_MISMATCH`).
pub const SUPPLY_FREQUENCY_OFF: f64 = 0.05;
/// Relative difference of the log's median voltage from the file's beyond which the log's
/// is taken: a variac's or a grid's +-10 % stays within it.
pub const SUPPLY_VOLTAGE_OFF: f64 = 0.15;

/// The log's supply against `start`'s ([`SupplyFromLog`]), where it differs.
fn supply_from_log(start: &ParamFile, s: &Samples) -> Option<SupplyFromLog> {
    let mut mags: Vec<f64> = s.v_ab.iter().map(|v| v[0].hypot(v[1])).collect();
    mags.sort_by(f64::total_cmp);
    let median = *mags.get(mags.len() / 2)?;
    // The vector's turn, unwrapped, over the whole log.
    let angle = |v: &[f64; 2]| v[1].atan2(v[0]);
    let turned: f64 = s
        .v_ab
        .windows(2)
        .map(|w| {
            let d = angle(&w[1]) - angle(&w[0]);
            (d + std::f64::consts::PI).rem_euclid(std::f64::consts::TAU) - std::f64::consts::PI
        })
        .sum();
    let span = s.dt_s * (s.v_ab.len().saturating_sub(1)) as f64;
    let f = turned.abs() / std::f64::consts::TAU / span.max(f64::MIN_POSITIVE);
    let v_ll = median * 1.5f64.sqrt();
    let (file_v, file_f) = (start.supply.v_ll_rms, start.supply.f_hz);
    let off = |x: f64, y: f64| (x / y - 1.0).abs();
    (median > 0.0
        && (off(f, file_f) > SUPPLY_FREQUENCY_OFF || off(v_ll, file_v) > SUPPLY_VOLTAGE_OFF))
        .then_some(SupplyFromLog {
            file_v_ll_rms: file_v,
            log_v_ll_rms: v_ll,
            file_f_hz: file_f,
            log_f_hz: f,
        })
}

/// The inverse-Gamma equivalent circuit (Slemon, "Modelling of induction machines for
/// electric drives", IEEE Trans. Ind. Appl. 25(6), 1989): the T-circuit with all its
/// leakage moved to the stator side, terminal-equivalent to it for any split,
/// ```text
///   L_sigma = Lls + Lm Llr / Lr,   L_M = Lm^2 / Lr,   R_R = Rr (Lm / Lr)^2,   Lr = Lm + Llr.
/// ```
/// These are what a log of the terminals determines; simulators and drive software that
/// use this form (e.g. motulator) publish their machines in it, so compare with those.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct InverseGamma {
    /// Stator resistance Rs [ohm] (the same in both forms).
    pub rs_ohm: f64,
    /// Rotor resistance R_R [ohm].
    pub r_r_ohm: f64,
    /// Leakage inductance L_sigma [H].
    pub l_sigma_h: f64,
    /// Magnetising inductance L_M [H].
    pub l_m_h: f64,
}

impl InverseGamma {
    /// The inverse-Gamma form of the T-circuit Rs, Rr, Lls, Llr, Lm [ohm, H]; all values
    /// must be positive (Lls, Llr non-negative), else the result is not finite.
    pub fn of_t_circuit(rs_ohm: f64, rr_ohm: f64, lls_h: f64, llr_h: f64, lm_h: f64) -> Self {
        let lr = lm_h + llr_h;
        let k = lm_h / lr;
        InverseGamma {
            rs_ohm,
            r_r_ohm: rr_ohm * k * k,
            l_sigma_h: lls_h + k * llr_h,
            l_m_h: k * lm_h,
        }
    }

    /// Of the identified estimates (Rs, Rr, Lls + Llr, Lm in [`PARAMS`]' order) with the
    /// stator leakage share `share`; `None` when one of them was not identified.
    fn of_estimates(e: &[Estimate], share: f64) -> Option<Self> {
        let v = |k: usize| e.get(k).and_then(|x| x.value);
        let (rs, rr, leak, lm) = (v(0)?, v(1)?, v(2)?, v(3)?);
        Some(Self::of_t_circuit(
            rs,
            rr,
            share * leak,
            (1.0 - share) * leak,
            lm,
        ))
    }
}

/// Maximum Levenberg-Marquardt iterations.
pub const MAX_ITER: usize = 60;

/// The start circuit from a parameter file.
///
/// # Errors
/// [`IdentifyError::NotAMachine`] when it is not a machine (non-positive values).
pub fn start_circuit(p: &ParamFile) -> Result<IdentifiedCircuit, IdentifyError> {
    let m = &p.motor;
    let (lls, llr) = (m.ls_h - m.lm_h, m.lr_h - m.lm_h);
    let leak = lls + llr;
    let ok = [m.rs_ohm, m.rr_ohm, leak, m.lm_h, m.j_kgm2]
        .iter()
        .all(|v| *v > 0.0)
        && lls >= 0.0
        && llr >= 0.0
        && m.poles >= 2;
    if !ok {
        return Err(IdentifyError::NotAMachine {
            rs_ohm: m.rs_ohm,
            rr_ohm: m.rr_ohm,
            lls_h: lls,
            llr_h: llr,
            lm_h: m.lm_h,
            j_kgm2: m.j_kgm2,
            poles: m.poles,
        });
    }
    Ok(IdentifiedCircuit {
        rs_ohm: m.rs_ohm,
        rr_ohm: m.rr_ohm,
        leakage_h: leak,
        lm_h: m.lm_h,
        j_kgm2: m.j_kgm2,
        // A start without friction would pin the log-space scale at 0.
        b_total_nms: (m.b_nms + m.bl_nms).max(1e-4 * m.j_kgm2.max(1e-6)),
        stator_leakage_share: lls / leak,
        np: f64::from(m.poles / 2),
    })
}

/// Relative RMS of residuals (their cost is half the sum of squares).
fn rel_rms(cost: f64, n: usize) -> f64 {
    (2.0 * cost / n.max(1) as f64).sqrt()
}

/// Identifies the circuit and mechanics of `start`'s machine from `s`. `progress` gets the
/// fraction done (0..1).
///
/// # Errors
/// As [`start_circuit`].
pub fn identify(
    start: &ParamFile,
    s: &Samples,
    progress: &mut dyn FnMut(f64),
) -> Result<Identification, IdentifyError> {
    let c0 = start_circuit(start)?;
    let prob = CurrentFit {
        samples: s,
        start: c0,
    };
    let speed = s.wm_rad_s.is_some();
    let free: Vec<usize> = if speed {
        vec![0, 1, 2, 3]
    } else {
        (0..N_PARAMS).collect()
    };
    let ln10 = 10f64.ln();
    let b = Bounds {
        lo: vec![-ln10; N_PARAMS],
        hi: vec![ln10; N_PARAMS],
        scale: vec![1.0; N_PARAMS],
    };
    let x0 = vec![0.0; N_PARAMS];
    let n_res = 2 * s.i_ab.len();
    let cost0 = lm::cost_of(&lm::LeastSquares::residuals(&prob, &x0, &()));
    progress(0.05);
    let (x, solver) = solve_in_rounds(&prob, x0, &b, &free, cost0, progress);
    let sigma = log_sigmas(&prob, &x, &b, &free, solver.cost, n_res);
    let mut estimates = estimates_of(&prob, &x, &free, &sigma);
    if speed {
        let mech = mechanics::fit(&prob.circuit(&x), s);
        estimates[4] = estimate_or(4, c0.j_kgm2, mech.j);
        estimates[5] = estimate_or(5, c0.b_total_nms, mech.b_total);
    }
    progress(1.0);
    let mut params = output::written_params(start, &estimates, c0.stator_leakage_share);
    let supply = supply_from_log(start, s);
    if let Some(l) = supply {
        params.supply.v_ll_rms = l.log_v_ll_rms;
        params.supply.f_hz = l.log_f_hz;
    }
    let inverse_gamma = InverseGamma::of_estimates(&estimates, c0.stator_leakage_share);
    estimates.extend(output::leakage_split(&estimates, start));
    Ok(Identification {
        estimates,
        params,
        stator_leakage_share: c0.stator_leakage_share,
        inverse_gamma,
        samples: s.i_ab.len(),
        window_s: (s.t0_s, s.t0_s + (s.i_ab.len() - 1) as f64 * s.dt_s),
        speed_imposed: speed,
        relative_rms_error_start: rel_rms(cost0, n_res),
        relative_rms_error: rel_rms(solver.cost, n_res),
        solver,
        supply_from_log: supply,
    })
}

/// The fit of `prob` from `x0` (cost `cost0`) over the parameters `free`, solved in six
/// rounds of at most a sixth of [`MAX_ITER`] iterations each, for the progress bar
/// (`progress` from 0.05 to 0.85); the rounds stop when the solver does for another
/// reason than its iteration limit. The optimum and how the solve ended.
fn solve_in_rounds(
    prob: &CurrentFit<'_>,
    x0: Vec<f64>,
    b: &Bounds,
    free: &[usize],
    cost0: f64,
    progress: &mut dyn FnMut(f64),
) -> (Vec<f64>, lm::Report) {
    let rounds = 6;
    let (mut x, mut rep, mut iterations) = (x0, None, 0);
    for k in 0..rounds {
        let (xn, mut r) = lm::solve(prob, x, b, free, MAX_ITER / rounds);
        x = xn;
        iterations += r.iterations;
        r.iterations = iterations;
        let done = r.termination != lm::Termination::IterationLimit;
        rep = Some(r);
        progress(0.05 + 0.8 * (k + 1) as f64 / rounds as f64);
        if done {
            break;
        }
    }
    let solver = rep.unwrap_or(lm::Report {
        iterations: 0,
        cost: cost0,
        termination: lm::Termination::NothingToFit,
    });
    (x, solver)
}

/// The estimate of each parameter of [`PARAMS`] at the optimum `x`, with its log-space
/// standard deviation `sigma` where it was `free` (the others keep the start's value).
fn estimates_of(prob: &CurrentFit<'_>, x: &[f64], free: &[usize], sigma: &[f64]) -> Vec<Estimate> {
    let circuit = prob.circuit(x);
    (0..N_PARAMS)
        .map(|k| {
            let p = circuit.to_vec()[k];
            let sg = free.iter().position(|&i| i == k).map(|a| sigma[a]);
            estimate(k, prob.start.to_vec()[k], p, sg)
        })
        .collect()
}

/// The log-space standard deviations of the free parameters at `x`: the larger of the
/// Gauss-Newton figure (the diagonal of `s^2 (J^T J)^-1`, `s^2 = 2 cost / (n - m)`) and the
/// block sandwich's, which takes in the model's error ([`uncertainty`]); infinite where
/// `J^T J` is singular (a flat direction).
fn log_sigmas(
    prob: &CurrentFit<'_>,
    x: &[f64],
    b: &Bounds,
    free: &[usize],
    cost: f64,
    n: usize,
) -> Vec<f64> {
    let r = lm::LeastSquares::residuals(prob, x, &());
    let cols = lm::jacobian_columns(prob, x, &r, &(), b, free);
    let m = free.len();
    let s2 = 2.0 * cost / (n.saturating_sub(m).max(1)) as f64;
    uncertainty::sigmas_with_model_error(&cols, &r, prob.samples.dt_s, s2, FLAT_RELATIVE_EIGENVALUE)
}

/// Eigenvalue of `J^T J` (log-space parameters), relative to the largest, below which a
/// direction counts as flat. Measured on the 2.2 kW machine at 5 kHz with 12-bit sensors:
/// a start with supply steps has its smallest at 0.13 of the largest, supply steps alone
/// (the start left out) 4e-3; steady running at one point 3e-7 and 1.5e-7 for the two
/// directions the steady state cannot tell (one complex impedance for four parameters):
/// what the fit then "finds" along them comes from the noise and the initial state, not
/// from the machine, however narrow its formal interval.
pub const FLAT_RELATIVE_EIGENVALUE: f64 = 1e-5;

/// `sqrt(diag(s2 A^-1))` of a symmetric `A`, by its eigen-decomposition: directions whose
/// eigenvalue is below `flat` of the largest count as flat (infinite sigma for every
/// parameter they involve by more than 1e-3).
pub fn covariance_sigmas(a: &nalgebra::DMatrix<f64>, s2: f64, flat: f64) -> Vec<f64> {
    let m = a.nrows();
    let eig = a.clone().symmetric_eigen();
    let top = eig.eigenvalues.iter().fold(0.0f64, |t, e| t.max(e.abs()));
    let mut var = vec![0.0; m];
    for (k, &lam) in eig.eigenvalues.iter().enumerate() {
        let flat = lam.is_nan() || lam <= flat * top;
        for (i, v) in var.iter_mut().enumerate() {
            let u = eig.eigenvectors[(i, k)];
            if flat {
                if u.abs() > 1e-3 {
                    *v = f64::INFINITY;
                }
            } else {
                *v += u * u / lam;
            }
        }
    }
    var.iter().map(|v| (s2 * v).sqrt()).collect()
}

/// The estimate of parameter `k` at value `p`, log-space sigma `sigma` (`None`: not fitted).
fn estimate(k: usize, start: f64, p: f64, sigma: Option<f64>) -> Estimate {
    let e = match sigma {
        Some(sg) => mechanics::LogEstimate {
            value: p,
            sigma: sg,
        }
        .judged(),
        None => Err(mechanics::NotIdentified::NotFitted),
    };
    estimate_or(k, start, e)
}

/// The estimate of parameter `k` from a judged value.
fn estimate_or(k: usize, start: f64, e: mechanics::MechanicsJudged) -> Estimate {
    let (name, key, unit) = PARAMS[k];
    let (value, lo, hi, why) = match e {
        Ok((v, lo, hi)) => (Some(v), Some(lo), Some(hi), None),
        Err(why) => (None, None, None, Some(why.to_string())),
    };
    Estimate {
        name: name.into(),
        key: key.into(),
        unit: unit.into(),
        start,
        value,
        lo,
        hi,
        not_identified_because: why,
    }
}
