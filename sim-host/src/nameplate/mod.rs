//! A parameter file from a motor's nameplate (`sim-host params from-nameplate`): the
//! T-equivalent circuit (Rs, Rr, Lls, Llr, Lm), the mechanical constants (J, B, Bl), the
//! pole count and the supply, each with its range under the method's assumptions and its
//! source. A starting point, to be refined with a log of the healthy motor.
//!
//! # The method
//! A nameplate gives seven numbers: output power P, line-to-line voltage V, line current
//! I, frequency f, speed n, power factor cos phi and efficiency eta. The circuit has five
//! unknowns (Rs, Rr, Lls, Llr, Lm) and the losses are split among copper, iron, friction and
//! stray losses that no nameplate separates. The estimation follows the nameplate-only
//! approach of K. Lee, S. Frank, P. K. Sen, L. G. Polese, M. Alahmad and C. Waters,
//! "Estimation of induction motor equivalent circuit parameters from nameplate data",
//! North American Power Symposium (NAPS) 2012: the rated point fixes the input impedance
//! and the rotor copper loss, the stator/rotor leakage split comes from IEEE Std 112 by
//! NEMA design, and the remaining unknowns are closed by typical values. Where they
//! iterate on the loss split, this module states each closing value and its range:
//!
//! 1. Per phase of the star equivalent (the parameter file's convention, `docs/design.md`
//!    section 11): `V_ph = V / sqrt 3`, `Z = V_ph / I` at the angle `acos(cos phi)`. A delta
//!    winding fed with the same line voltage and current has the same star equivalent; its
//!    own phase impedances are three times these.
//! 2. Slip `s = (n_sync - n) / n_sync`, `n_sync = 120 f / poles`; the poles, when not given,
//!    are the largest even number whose synchronous speed is above `n`.
//! 3. Power balance: `P_in = P / eta`; friction and windage `P_fw` = 0.5 % of P (range
//!    0..2 %: an engineering assumption for 4-pole fan-cooled motors of 1 to 50 kW); the air-gap power
//!    `P_ag = (P + P_fw) / (1 - s)`; the rotor copper loss is `s P_ag`; everything else,
//!    `P_in - P_ag`, is put in Rs: `Rs = (P_in - P_ag) / (3 I^2)`. The circuit has no
//!    iron-loss branch, so iron and stray-load losses are lumped into Rs, so that the
//!    file's machine draws the nameplate's input power at the rated point. This Rs is an
//!    effective value: iron and stray-load losses are typically 60 %..100 % of the stator
//!    copper loss, so a real motor's winding DC resistance is about 0.5..0.65 of it. (The
//!    test machines have no iron loss: there the estimate is the winding's value.)
//! 4. The rest of the impedance `Z - Rs = j Xls + (j Xm || (Rr/s + j Xlr))` gives Rr and Xm
//!    for a given total leakage `Xl = Xls + Xlr` (`Xls = a Xl`, `a` by NEMA design from
//!    IEEE Std 112: 0.5 for designs A and D, 0.4 for B, 0.3 for C).
//! 5. The total leakage, the one value the rated point cannot give:
//!    - with the locked-rotor current ratio `IA/IN` (a catalogue value, or the NEMA code
//!      letter's kVA/hp): the `Xl` at which the circuit at standstill draws `IA`; the
//!      range is IEC 60034-1's +20 % tolerance on the locked-rotor current, both ways;
//!    - without it: `Xl = 0.12 Z_b`, `Z_b = V_ph / I` (range 0.06..0.20 Z_b), the mean of
//!      four published machines that are not among the test's (MATLAB/Simscape's
//!      asynchronous-machine presets 10 hp 400 V 50 Hz, 50 hp 400 V 50 Hz, 5 hp 460 V
//!      60 Hz and 10 hp 460 V 60 Hz, as transcribed in the Modelica Buildings library's
//!      `InductionMotors.Data` records: 0.112, 0.127, 0.104, 0.134 Z_b).
//!
//!    Steps 4 and 5 repeat until Xl settles (a fixed point; a few iterations).
//! 6. Mechanics, from empirical power-size relations with a wide uncertainty: the rotor
//!    inertia `J = 0.0016 P_eq^1.45` kg m^2 with `P_eq` [kW] the power of a 4-pole 50 Hz
//!    motor of the same rated torque (a rough power law through typical catalogue rotor
//!    inertias of IEC 4-pole cage motors: about 0.005 kg m^2 at 2.2 kW, 0.08 at 15 kW,
//!    0.3 at 37 kW; range /3..x3; the load's inertia is not included); `B = P_fw / w_m^2`; the load `Bl = P / w_m^2`, the paper's viscous
//!    load ("Fault Diagnosis of Induction Motor Using D-Q Simplified Model and Parity
//!    Equations", Energies 2022, 15(22), 8372) that asks for rated torque at rated speed.
//!
//! Each range is the envelope of the estimates over every combination of the ends of the
//! assumptions' ranges (friction and windage, total leakage, leakage split from the Gamma
//! to the inverse-Gamma model, and efficiency and power factor within IEC 60034-1's
//! tolerances, both ways: the efficiency by 15 % of the losses `1 - eta` (10 % above
//! 150 kW), the power factor by a sixth of `1 - cos phi` (0.02..0.07)). Rs, the losses'
//! small remainder, moves most: a plate efficiency of 0.87 against a true 0.88 is a tenth
//! more loss, and Rs takes most of it. `docs/own-motor.md` has the measured errors on six
//! machines (0.37 kW to 50 hp).

use crate::params::{plausible, ParamError, ParamFile};
use nalgebra::Complex;
use std::f64::consts::TAU;

/// Errors of [`estimate`]: each names the command line option it blames.
#[derive(Debug, thiserror::Error)]
pub enum NameplateError {
    /// A nameplate value no induction machine can have.
    #[error("{field} {message}")]
    Field {
        /// The option blamed (`--efficiency`, `--speed-rpm`, ...).
        field: &'static str,
        /// What is wrong, with the value and the limit (one line).
        message: String,
    },
    /// The estimated circuit is refused by the parameter file's own checks.
    #[error("the estimate is not a plausible machine: {0}")]
    Params(#[from] ParamError),
}

fn field_error(field: &'static str, message: String) -> NameplateError {
    NameplateError::Field { field, message }
}

/// How the stator winding is connected. The nameplate's voltage and current are the line
/// values either way; the parameter file holds the star equivalent, the same for both.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Connection {
    /// Star (wye).
    Star,
    /// Delta: the winding's own phase impedances are 3x the star equivalent's.
    Delta,
}

/// NEMA design letter: the stator share of the total leakage reactance, from IEEE Std 112
/// (A and D: 0.5, B: 0.4, C: 0.3). IEC design N motors are close to NEMA design B.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize)]
pub enum NemaDesign {
    /// Design A: normal torque, high locked-rotor current (Xls = Xlr).
    A,
    /// Design B, the general-purpose motor (and IEC design N): Xls = 0.4 Xl.
    B,
    /// Design C: high starting torque (double cage): Xls = 0.3 Xl.
    C,
    /// Design D: high slip (Xls = Xlr).
    D,
}

impl NemaDesign {
    /// The stator share `Xls / (Xls + Xlr)`, IEEE Std 112.
    pub fn stator_share(self) -> f64 {
        match self {
            NemaDesign::A | NemaDesign::D => 0.5,
            NemaDesign::B => 0.4,
            NemaDesign::C => 0.3,
        }
    }
}

/// A nameplate: the rated point at the rated supply.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct Nameplate {
    /// Rated output (shaft) power [kW], > 0.
    pub power_kw: f64,
    /// Rated line-to-line voltage [V, RMS].
    pub voltage_v: f64,
    /// Rated line current [A, RMS] at that voltage.
    pub current_a: f64,
    /// Rated frequency [Hz].
    pub frequency_hz: f64,
    /// Rated speed [rpm], below synchronous.
    pub speed_rpm: f64,
    /// Rated power factor, 0 < cos phi < 1.
    pub power_factor: f64,
    /// Rated efficiency, 0 < eta < 1 (a fraction, not %).
    pub efficiency: f64,
    /// Number of poles; `None`: inferred from speed and frequency.
    pub poles: Option<u32>,
    /// Winding connection.
    pub connection: Connection,
    /// Locked-rotor current over rated current IA/IN (catalogue, or NEMA code letter);
    /// `None`: the total leakage is the typical 0.12 Z_b.
    pub locked_rotor_ratio: Option<f64>,
    /// NEMA design letter (leakage split).
    pub design: NemaDesign,
}

/// One estimated value: the value, its range under the method's assumptions, and its
/// source (one line).
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct Estimated {
    /// The parameter file's key (`motor.rs_ohm`, ...) or, for a value the file derives,
    /// its name (`lls_h`, `llr_h`).
    pub key: &'static str,
    /// The value written.
    pub value: f64,
    /// Smallest value of the range.
    pub lo: f64,
    /// Largest value of the range.
    pub hi: f64,
    /// Unit.
    pub unit: &'static str,
    /// Where it comes from.
    pub source: String,
}

/// The result of [`estimate`]: the parameter file, each value with its range and source,
/// and the rated point as read.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct NameplateEstimate {
    /// The nameplate, as given.
    pub nameplate: Nameplate,
    /// The parameter file (checked: plausible and within the equations' limits).
    #[serde(skip)]
    pub params: ParamFile,
    /// Poles used.
    pub poles: u32,
    /// Whether the poles were inferred from speed and frequency.
    pub poles_inferred: bool,
    /// Rated slip.
    pub slip: f64,
    /// Every value with its range and source: the file's keys, then Lls and Llr.
    pub values: Vec<Estimated>,
}

/// The closing assumptions of one estimate (module documentation, steps 3 to 5).
#[derive(Debug, Clone, Copy)]
struct Assumptions {
    /// Friction and windage loss over rated output.
    fw_fraction: f64,
    /// Total leakage over Z_b, or the locked-rotor current ratio.
    leakage: Leakage,
    /// Xls / (Xls + Xlr).
    stator_share: f64,
    /// Offsets to the nameplate's efficiency and power factor (within their IEC 60034-1
    /// tolerances).
    d_efficiency: f64,
    d_power_factor: f64,
}

#[derive(Debug, Clone, Copy)]
enum Leakage {
    PerUnit(f64),
    LockedRotorRatio(f64),
}

/// Friction and windage over rated output: nominal, low, high.
const FW_FRACTION: [f64; 3] = [0.005, 0.0, 0.02];
/// Total leakage reactance over Z_b without a locked-rotor ratio: nominal, low, high.
const LEAKAGE_PU: [f64; 3] = [0.12, 0.06, 0.20];
/// IEC 60034-1's tolerance on the locked-rotor current (+20 %), used both ways.
const LOCKED_ROTOR_TOLERANCE: f64 = 0.2;
/// IEC 60034-1 (Table 20) tolerance on the efficiency of a machine up to 150 kW, as a share
/// of the true losses `1 - eta` (-15 %; above 150 kW -10 %), taken both ways (the motor on
/// the bench may beat its plate as well as fall short of it) and as a share of the
/// plate's losses: a true loss `L` is `0.85 L` on a plate at the tolerance's end, so
/// `0.15 / 0.85` (and `0.10 / 0.90`) of the plate's.
const EFFICIENCY_TOLERANCE: [f64; 2] = [0.15 / 0.85, 0.10 / 0.90];
/// IEC 60034-1 (Table 20) tolerance on the power factor: a sixth of the true `1 - cos phi`,
/// at least 0.02 and at most 0.07, both ways; a fifth of the plate's (as above).
const POWER_FACTOR_TOLERANCE: (f64, f64, f64) = (1.0 / 5.0, 0.02, 0.07);

/// The rounding of a nameplate's efficiency and power factor (a percentage or two decimals).
const NAMEPLATE_ROUNDING: f64 = 0.005;

/// The efficiency's and the power factor's tolerance for the nameplate `n`: IEC 60034-1's
/// plus the plate's rounding.
fn plate_tolerances(n: &Nameplate) -> (f64, f64) {
    let share = if n.power_kw <= 150.0 {
        EFFICIENCY_TOLERANCE[0]
    } else {
        EFFICIENCY_TOLERANCE[1]
    };
    let (k, min, max) = POWER_FACTOR_TOLERANCE;
    (
        share * (1.0 - n.efficiency) + NAMEPLATE_ROUNDING,
        (k * (1.0 - n.power_factor)).clamp(min, max) + NAMEPLATE_ROUNDING,
    )
}
/// Largest rated slip accepted (NEMA design D motors reach about 13 %).
const MAX_SLIP: f64 = 0.15;
/// How far P may be from sqrt 3 V I cos phi eta (a ratio) before the nameplate is refused.
const CONSISTENCY: f64 = 0.2;
/// Rotor inertia J = J_COEFF P_eq^J_EXP [kg m^2], P_eq in kW (module documentation).
const J_COEFF: f64 = 0.0016;
const J_EXP: f64 = 1.45;
/// The inertia's range factor (/3 .. x3).
const J_FACTOR: f64 = 3.0;

/// The rated point as the circuit sees it.
#[derive(Debug, Clone, Copy)]
struct Rated {
    v_ph: f64,
    i_a: f64,
    p_out_w: f64,
    f_hz: f64,
    slip: f64,
    poles: u32,
    speed_rad_s: f64,
}

/// One circuit: per-phase star-equivalent values [ohm at the rated frequency] and losses.
#[derive(Debug, Clone, Copy)]
struct RatedCircuit {
    rs: f64,
    rr: f64,
    xls: f64,
    xlr: f64,
    xm: f64,
    p_fw_w: f64,
}

fn positive(field: &'static str, v: f64, unit: &str) -> Result<(), NameplateError> {
    if v.is_finite() && v > 0.0 {
        Ok(())
    } else {
        Err(field_error(
            field,
            format!("must be a positive finite number, got {v}{unit}"),
        ))
    }
}

/// Checks each field on its own, then the consistency of P with sqrt 3 V I cos phi eta.
fn check_fields(n: &Nameplate) -> Result<(), NameplateError> {
    positive("--power-kw", n.power_kw, " kW")?;
    positive("--voltage-v", n.voltage_v, " V")?;
    positive("--current-a", n.current_a, " A")?;
    positive("--frequency-hz", n.frequency_hz, " Hz")?;
    positive("--speed-rpm", n.speed_rpm, " rpm")?;
    for (field, v) in [
        ("--power-factor", n.power_factor),
        ("--efficiency", n.efficiency),
    ] {
        if !(v.is_finite() && v > 0.0 && v < 1.0) {
            return Err(field_error(
                field,
                format!(
                    "{v} is impossible for an induction motor: it must be between 0 and 1, \
                     both excluded (a fraction: 0.85, not 85)"
                ),
            ));
        }
    }
    for (field, v, unit, r) in [
        ("--voltage-v", n.voltage_v, "V", plausible::V_LL_RMS),
        ("--frequency-hz", n.frequency_hz, "Hz", plausible::F_HZ),
    ] {
        if !r.contains(v) {
            return Err(field_error(
                field,
                format!("{v} {unit} is outside {}..{} {unit}", r.lo, r.hi),
            ));
        }
    }
    if let Some(k) = n.locked_rotor_ratio {
        if !(k.is_finite() && (1.5..=15.0).contains(&k)) {
            return Err(field_error(
                "--locked-rotor-ratio",
                format!("{k} is not a locked-rotor current ratio IA/IN (1.5..15; typical 5..9)"),
            ));
        }
    }
    let electrical_kw =
        3f64.sqrt() * n.voltage_v * n.current_a * n.power_factor * n.efficiency / 1000.0;
    let ratio = n.power_kw / electrical_kw;
    if !(ratio > 1.0 - CONSISTENCY && ratio < 1.0 + CONSISTENCY) {
        return Err(field_error(
            "--power-kw",
            format!(
                "{} kW disagrees with sqrt3 x --voltage-v x --current-a x --power-factor x \
                 --efficiency = {electrical_kw:.4} kW (ratio {ratio:.3}; a real nameplate \
                 agrees within {:.0} %): check each value, and that the current is the one \
                 for this voltage",
                n.power_kw,
                100.0 * CONSISTENCY
            ),
        ));
    }
    Ok(())
}

/// The poles (given or inferred) and the rated slip.
fn poles_and_slip(n: &Nameplate) -> Result<(u32, bool, f64), NameplateError> {
    let f = n.frequency_hz;
    let (poles, inferred) = match n.poles {
        Some(p) => {
            if !(plausible::POLES.contains(&p) && p.is_multiple_of(2)) {
                return Err(field_error(
                    "--poles",
                    format!(
                        "{p} is not an even number in {}..={}",
                        plausible::POLES.start(),
                        plausible::POLES.end()
                    ),
                ));
            }
            (p, false)
        }
        None => {
            // The largest pole-pair count whose synchronous speed is above n.
            let k = 60.0 * f / n.speed_rpm;
            let pairs = k.ceil() - 1.0;
            if pairs < 1.0 {
                return Err(field_error(
                    "--speed-rpm",
                    format!(
                        "{} rpm is at or above the synchronous speed of a 2-pole motor at \
                         {f} Hz ({} rpm): an induction motor runs below synchronous speed",
                        n.speed_rpm,
                        60.0 * f
                    ),
                ));
            }
            let poles = (2.0 * pairs).min(f64::from(u32::MAX)) as u32;
            if !plausible::POLES.contains(&poles) {
                return Err(field_error(
                    "--speed-rpm",
                    format!(
                        "{} rpm at {f} Hz would need {poles} poles, more than {}",
                        n.speed_rpm,
                        plausible::POLES.end()
                    ),
                ));
            }
            (poles, true)
        }
    };
    let n_sync = 120.0 * f / f64::from(poles);
    let slip = (n_sync - n.speed_rpm) / n_sync;
    if slip <= 0.0 {
        return Err(field_error(
            "--speed-rpm",
            format!(
                "{} rpm is at or above the synchronous speed {n_sync} rpm of {poles} poles at \
                 {f} Hz: an induction motor runs below synchronous speed",
                n.speed_rpm
            ),
        ));
    }
    if slip > MAX_SLIP {
        let hint = if inferred { "; give --poles" } else { "" };
        return Err(field_error(
            "--speed-rpm",
            format!(
                "{} rpm is a slip of {:.1} % below the synchronous {n_sync} rpm of {poles} \
                 poles at {f} Hz: not a rated speed (rated slips are below {:.0} %){hint}",
                n.speed_rpm,
                100.0 * slip,
                100.0 * MAX_SLIP
            ),
        ));
    }
    Ok((poles, inferred, slip))
}

/// Rr and Xm from `zp = Z - Rs` at slip `s` for a total leakage `xl` (step 4). The rotor
/// branch's conductance is the real part of `1 / (zp - j Xls)`; of the two resistances
/// with that conductance the larger (Rr/s above the rotor leakage, as at rated slip).
fn rotor_and_magnetising(zp: Complex<f64>, s: f64, xls: f64, xlr: f64) -> Option<(f64, f64)> {
    let y = Complex::new(1.0, 0.0) / (zp - Complex::new(0.0, xls));
    let g = y.re;
    let disc = 1.0 - 4.0 * g * g * xlr * xlr;
    if !(g > 0.0 && disc >= 0.0) {
        return None;
    }
    let r = (1.0 + disc.sqrt()) / (2.0 * g);
    let yr = Complex::new(1.0, 0.0) / Complex::new(r, xlr);
    let bm = yr.im - y.im;
    (bm > 0.0 && r.is_finite()).then(|| (r * s, 1.0 / bm))
}

/// The circuit's input impedance at standstill (slip 1).
fn locked_rotor_impedance(rs: f64, rr: f64, xls: f64, xlr: f64, xm: f64) -> f64 {
    let zm = Complex::new(0.0, xm);
    let zr = Complex::new(rr, xlr);
    (Complex::new(rs, xls) + zm * zr / (zm + zr)).norm()
}

/// The circuit under one set of assumptions (steps 3 to 5).
fn circuit(n: &Nameplate, r: &Rated, a: &Assumptions) -> Result<RatedCircuit, NameplateError> {
    let eta = n.efficiency + a.d_efficiency;
    let pf = (n.power_factor + a.d_power_factor).min(0.999);
    let p_in = r.p_out_w / eta;
    let p_fw_w = a.fw_fraction * r.p_out_w;
    let p_ag = (r.p_out_w + p_fw_w) / (1.0 - r.slip);
    let rs = (p_in - p_ag) / (3.0 * r.i_a * r.i_a);
    if rs.is_nan() || rs <= 0.0 {
        return Err(field_error(
            "--efficiency",
            format!(
                "{} is too high for the slip {:.2} %: the rotor copper loss alone (slip x \
                 air-gap power) needs an efficiency below about 1 - slip = {:.3}",
                n.efficiency,
                100.0 * r.slip,
                1.0 - r.slip
            ),
        ));
    }
    let zb = r.v_ph / r.i_a;
    let z = Complex::new(zb * pf, zb * (1.0 - pf * pf).sqrt());
    let zp = z - Complex::new(rs, 0.0);
    let no_circuit = || {
        field_error(
            "--power-factor",
            format!(
                "{} with --efficiency {} and the slip {:.2} %: no T-equivalent circuit has \
                 this rated point (check both)",
                n.power_factor,
                n.efficiency,
                100.0 * r.slip
            ),
        )
    };
    let split = |xl: f64| (a.stator_share * xl, (1.0 - a.stator_share) * xl);
    let solve = |xl: f64| {
        let (xls, xlr) = split(xl);
        rotor_and_magnetising(zp, r.slip, xls, xlr)
    };
    let mut xl = LEAKAGE_PU[0] * zb;
    if let Leakage::PerUnit(x) = a.leakage {
        xl = x * zb;
    }
    let (mut rr, mut xm) = solve(xl).ok_or_else(no_circuit)?;
    if let Leakage::LockedRotorRatio(k) = a.leakage {
        let target = zb / k;
        for _ in 0..50 {
            let lr = |x: f64| {
                let (xls, xlr) = split(x);
                locked_rotor_impedance(rs, rr, xls, xlr, xm)
            };
            if lr(1e-6 * zb) >= target || lr(2.0 * zb) <= target {
                return Err(field_error(
                    "--locked-rotor-ratio",
                    format!(
                        "{k} cannot be reached by this machine's circuit (its resistances \
                         alone allow at most {:.2})",
                        zb / lr(1e-6 * zb)
                    ),
                ));
            }
            let next = bisect(|x| lr(x) - target, 1e-6 * zb, 2.0 * zb);
            let settled = (next - xl).abs() < 1e-9 * zb;
            xl = next;
            (rr, xm) = solve(xl).ok_or_else(no_circuit)?;
            if settled {
                break;
            }
        }
    }
    let (xls, xlr) = split(xl);
    Ok(RatedCircuit {
        rs,
        rr,
        xls,
        xlr,
        xm,
        p_fw_w,
    })
}

/// The root of an increasing `f` in `lo..hi` (f(lo) < 0 < f(hi)), by bisection.
fn bisect(f: impl Fn(f64) -> f64, mut lo: f64, mut hi: f64) -> f64 {
    for _ in 0..200 {
        let mid = 0.5 * (lo + hi);
        if f(mid) < 0.0 {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    0.5 * (lo + hi)
}

/// The rotor inertia estimate [kg m^2] (module documentation, step 6).
fn inertia_kgm2(r: &Rated) -> f64 {
    let torque_nm = r.p_out_w / r.speed_rad_s;
    // The 4-pole 50 Hz motor of the same torque runs at about 1450 rpm.
    let p_eq_kw = torque_nm * 1450.0 * TAU / 60.0 / 1000.0;
    J_COEFF * p_eq_kw.powf(J_EXP)
}

/// The values of one circuit, in the order of [`NameplateEstimate::values`].
fn circuit_values(c: &RatedCircuit, r: &Rated) -> [f64; 11] {
    let w = TAU * r.f_hz;
    let (lm, lls, llr) = (c.xm / w, c.xls / w, c.xlr / w);
    let w2 = r.speed_rad_s * r.speed_rad_s;
    [
        c.rs,
        c.rr,
        lm + lls,
        lm + llr,
        lm,
        inertia_kgm2(r),
        c.p_fw_w / w2,
        r.p_out_w / w2,
        lls,
        llr,
        lls + llr,
    ]
}

/// The keys, units and sources of [`circuit_values`].
fn value_meta(n: &Nameplate) -> [(&'static str, &'static str, String); 11] {
    let leak = match n.locked_rotor_ratio {
        Some(k) => format!(
            "the total leakage at which the circuit at standstill draws IA/IN = {k} (+/-20 %)"
        ),
        None => "total leakage 0.12 Z_b, Z_b = V_ph/I (typical; 0.06..0.20 Z_b)".to_string(),
    };
    let split = format!(
        "NEMA design {:?} split (IEEE Std 112: Xls = {} Xl)",
        n.design,
        n.design.stator_share()
    );
    [
        ("motor.rs_ohm", "ohm", "losses P/eta - (P + P_fw)/(1 - s) over 3 I^2: an effective value with iron and stray losses lumped in (a real winding's DC resistance is about 0.5..0.65 of it)".into()),
        ("motor.rr_ohm", "ohm", format!("rated-point impedance V_ph/I at acos(pf), less Rs, with {leak}")),
        ("motor.ls_h", "H", "lm_h + lls_h".into()),
        ("motor.lr_h", "H", "lm_h + llr_h".into()),
        ("motor.lm_h", "H", format!("rated-point impedance less Rs, with {leak}")),
        ("motor.j_kgm2", "kg m^2", format!("rotor alone, J = {J_COEFF} P_eq^{J_EXP} (a rough power law through typical catalogue values, P_eq the 4-pole 50 Hz power of the same torque, kW; /3..x3): add the load's inertia")),
        ("motor.b_nms", "N m s/rad", "friction and windage 0.5 % of P (0..2 %) at rated speed".into()),
        ("motor.bl_nms", "N m s/rad", "the paper's viscous load at rated torque and speed, P/w_m^2: set it to your load".into()),
        ("lls_h", "H", format!("{leak}; {split}")),
        ("llr_h", "H", format!("{leak}; {split}")),
        ("lls_h + llr_h", "H", leak),
    ]
}

/// The sets of assumptions of the range: the nominal one first, then every combination
/// of the ends of the ranges (and the nominal values) of the five assumptions.
fn assumption_sets(n: &Nameplate) -> Vec<Assumptions> {
    let leakage: [Leakage; 3] = match n.locked_rotor_ratio {
        Some(k) => [
            1.0,
            1.0 - LOCKED_ROTOR_TOLERANCE,
            1.0 + LOCKED_ROTOR_TOLERANCE,
        ]
        .map(|f| Leakage::LockedRotorRatio(k * f)),
        None => LEAKAGE_PU.map(Leakage::PerUnit),
    };
    // Every split from the Gamma model (all leakage on the rotor side) to the inverse-Gamma
    // model (all on the stator side): the terminals cannot tell them apart.
    let shares = [n.design.stator_share(), 0.0, 1.0];
    let (d_eta, d_pf) = plate_tolerances(n);
    let mut sets = Vec::with_capacity(243);
    for fw_fraction in FW_FRACTION {
        for leakage in leakage {
            for stator_share in shares {
                for d_efficiency in [0.0, -d_eta, d_eta] {
                    for d_power_factor in [0.0, -d_pf, d_pf] {
                        sets.push(Assumptions {
                            fw_fraction,
                            leakage,
                            stator_share,
                            d_efficiency,
                            d_power_factor,
                        });
                    }
                }
            }
        }
    }
    sets
}

/// Estimates the parameter file from a nameplate (module documentation).
///
/// # Errors
/// [`NameplateError::Field`] for a nameplate no induction machine can have (efficiency or
/// power factor outside 0..1, speed at or above synchronous, a slip above 15 %, a value
/// not finite or not positive, P off sqrt 3 V I cos phi eta by more than 20 %, an
/// efficiency above 1 - slip), naming the option; [`NameplateError::Params`] when the
/// estimate fails the parameter file's checks.
pub fn estimate(n: &Nameplate) -> Result<NameplateEstimate, NameplateError> {
    check_fields(n)?;
    let (poles, poles_inferred, slip) = poles_and_slip(n)?;
    let rated = Rated {
        v_ph: n.voltage_v / 3f64.sqrt(),
        i_a: n.current_a,
        p_out_w: 1000.0 * n.power_kw,
        f_hz: n.frequency_hz,
        slip,
        poles,
        speed_rad_s: n.speed_rpm * TAU / 60.0,
    };
    let sets = assumption_sets(n);
    let nominal = circuit(n, &rated, &sets[0])?;
    let v0 = circuit_values(&nominal, &rated);
    let (mut lo, mut hi) = (v0, v0);
    for a in &sets[1..] {
        // An end of a range the nameplate cannot reach widens nothing.
        let Ok(c) = circuit(n, &rated, a) else {
            continue;
        };
        for (i, v) in circuit_values(&c, &rated).iter().enumerate() {
            lo[i] = lo[i].min(*v);
            hi[i] = hi[i].max(*v);
        }
    }
    lo[5] = v0[5] / J_FACTOR;
    hi[5] = v0[5] * J_FACTOR;
    let values = value_meta(n)
        .into_iter()
        .enumerate()
        .map(|(i, (key, unit, source))| Estimated {
            key,
            value: v0[i],
            lo: lo[i],
            hi: hi[i],
            unit,
            source,
        })
        .collect();
    let mut e = NameplateEstimate {
        nameplate: *n,
        params: ParamFile::reference_3hp(),
        poles,
        poles_inferred,
        slip,
        values,
    };
    e.params = ParamFile::from_toml_str(&e.to_toml(), "the nameplate estimate")?;
    debug_assert_eq!(rated.poles, e.params.motor.poles);
    Ok(e)
}

/// `x` for a TOML file: five significant digits, always a float (a decimal point or an
/// exponent).
pub fn toml_number(x: f64) -> String {
    let a = x.abs();
    if a == 0.0 {
        return "0.0".to_string();
    }
    if (1e-3..1e6).contains(&a) {
        let digits = (4 - a.log10().floor() as i32).max(1) as usize;
        let t = format!("{x:.digits$}");
        let t = t.trim_end_matches('0');
        if t.ends_with('.') {
            format!("{t}0")
        } else {
            t.to_string()
        }
    } else {
        format!("{x:.4e}")
    }
}

/// One line of a parameter file: `key = value # comment` ([`toml_number`]'s value).
pub fn toml_entry(key: &str, x: f64, comment: &str) -> String {
    format!("{key} = {} # {comment}\n", toml_number(x))
}

impl NameplateEstimate {
    /// The value of `key` (a key of [`NameplateEstimate::values`]).
    pub fn value(&self, key: &str) -> Option<&Estimated> {
        self.values.iter().find(|v| v.key == key)
    }

    /// The parameter file as TOML, each value with its range and source as a comment.
    pub fn to_toml(&self) -> String {
        let n = &self.nameplate;
        let mut s = String::new();
        s.push_str("# Estimated from a nameplate by `sim-host params from-nameplate` (docs/own-motor.md):\n");
        s.push_str(&format!(
            "#   {} kW, {} V, {} A, {} Hz, {} rpm, power factor {}, efficiency {}, {} poles ({}), {} connection\n",
            n.power_kw, n.voltage_v, n.current_a, n.frequency_hz, n.speed_rpm, n.power_factor,
            n.efficiency, self.poles,
            if self.poles_inferred { "inferred from the speed" } else { "given" },
            match n.connection {
                Connection::Star => "star",
                Connection::Delta => "delta",
            },
        ));
        s.push_str(&format!(
            "#   rated slip {:.2} %. Method after Lee, Frank, Sen et al., NAPS 2012 (nameplate-only\n\
             #   estimation); per-phase star-equivalent values.\n",
            100.0 * self.slip
        ));
        if n.connection == Connection::Delta {
            s.push_str(
                "#   Delta winding: its own phase resistances and inductances are 3x these.\n",
            );
        }
        s.push_str("# A starting point: refine it with a log of the healthy motor. Each value: [range] and source.\n");
        s.push_str("[motor]\n");
        for v in self.values.iter().filter(|v| v.key.starts_with("motor.")) {
            let key = v.key.trim_start_matches("motor.");
            s.push_str(&toml_entry(
                key,
                v.value,
                &format!(
                    "[{}..{}] {}; {}",
                    toml_number(v.lo),
                    toml_number(v.hi),
                    v.unit,
                    v.source
                ),
            ));
            if key == "lm_h" {
                s.push_str(&format!(
                    "poles = {} # {}\n",
                    self.poles,
                    if self.poles_inferred {
                        "inferred: the largest even number whose synchronous speed is above the rated speed"
                    } else {
                        "from the nameplate"
                    }
                ));
            }
        }
        for v in self.values.iter().filter(|v| !v.key.starts_with("motor.")) {
            s.push_str(&format!(
                "# {} = {} [{}..{}] {}\n",
                v.key,
                toml_number(v.value),
                toml_number(v.lo),
                toml_number(v.hi),
                v.unit
            ));
        }
        s.push_str("[supply]\n");
        s.push_str(&toml_entry(
            "v_ll_rms",
            n.voltage_v,
            "rated line-to-line voltage [V], from the nameplate",
        ));
        s.push_str(&toml_entry(
            "f_hz",
            n.frequency_hz,
            "rated frequency [Hz], from the nameplate",
        ));
        s
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn plate(speed_rpm: f64, frequency_hz: f64) -> Nameplate {
        Nameplate {
            power_kw: 2.2,
            voltage_v: 400.0,
            current_a: 4.78,
            frequency_hz,
            speed_rpm,
            power_factor: 0.77,
            efficiency: 0.863,
            poles: None,
            connection: Connection::Star,
            locked_rotor_ratio: None,
            design: NemaDesign::B,
        }
    }

    #[test]
    fn poles_are_inferred_from_speed_and_frequency() {
        for (rpm, f, poles) in [
            (2900.0, 50.0, 2),
            (1440.0, 50.0, 4),
            (960.0, 50.0, 6),
            (725.0, 50.0, 8),
            (1750.0, 60.0, 4),
            (3500.0, 60.0, 2),
        ] {
            let (p, inferred, slip) = poles_and_slip(&plate(rpm, f)).unwrap();
            assert_eq!((p, inferred), (poles, true), "{rpm} rpm at {f} Hz");
            let n_sync = 120.0 * f / f64::from(poles);
            assert!((slip - (n_sync - rpm) / n_sync).abs() < 1e-12);
        }
    }

    #[test]
    fn the_rotor_branch_is_recovered_from_a_known_impedance() {
        // Z - Rs of the 3 hp textbook machine at 3 % slip, then back to Rr and Xm.
        let (rr, xls, xlr, xm, s) = (0.816, 0.754, 0.754, 26.13, 0.03);
        let zm = Complex::new(0.0, xm);
        let zr = Complex::new(rr / s, xlr);
        let zp = Complex::new(0.0, xls) + zm * zr / (zm + zr);
        let (rr2, xm2) = rotor_and_magnetising(zp, s, xls, xlr).unwrap();
        assert!((rr2 / rr - 1.0).abs() < 1e-9 && (xm2 / xm - 1.0).abs() < 1e-9);
        // An impedance with no resistive part has no rotor branch.
        assert!(rotor_and_magnetising(Complex::new(0.0, 20.0), s, xls, xlr).is_none());
    }

    #[test]
    fn toml_numbers_are_floats_with_five_digits() {
        assert_eq!(toml_number(400.0), "400.0");
        assert_eq!(toml_number(3.543918), "3.5439");
        assert_eq!(toml_number(0.0073818), "0.0073818");
        assert_eq!(toml_number(4.8508e-4), "4.8508e-4");
        assert_eq!(toml_number(0.0), "0.0");
        for x in [1e-7, 0.00123, 1.0, 123456.7, 2.5e7] {
            let back: f64 = toml_number(x).parse().unwrap();
            assert!((back / x - 1.0).abs() < 1e-4, "{x}");
        }
    }

    #[test]
    fn a_delta_winding_gets_the_same_star_equivalent_and_says_so() {
        let star = estimate(&plate(1438.0, 50.0)).unwrap();
        let delta = estimate(&Nameplate {
            connection: Connection::Delta,
            ..plate(1438.0, 50.0)
        })
        .unwrap();
        assert_eq!(star.params, delta.params);
        assert!(delta.to_toml().contains("3x these") && !star.to_toml().contains("3x these"));
        // The leakage split follows the design letter; the total does not.
        let c = estimate(&Nameplate {
            design: NemaDesign::C,
            ..plate(1438.0, 50.0)
        })
        .unwrap();
        let total = |e: &NameplateEstimate| e.value("lls_h + llr_h").unwrap().value;
        let lls = |e: &NameplateEstimate| e.value("lls_h").unwrap().value;
        assert!((total(&c) / total(&star) - 1.0).abs() < 1e-12);
        assert!((lls(&c) / total(&c) - 0.3).abs() < 1e-9);
        assert!((lls(&star) / total(&star) - 0.4).abs() < 1e-9);
    }
}
