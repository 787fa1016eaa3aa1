//! The circuit of a nameplate under one set of the method's closing assumptions (the
//! module documentation's steps 2 to 6), and the sets of assumptions its ranges come from.

use super::{field_error, field_error_naming, Nameplate, NameplateError};
use crate::params::plausible;
use nalgebra::Complex;
use std::f64::consts::TAU;

/// The closing assumptions of one estimate (module documentation, steps 3 to 5).
#[derive(Debug, Clone, Copy)]
pub(super) struct Assumptions {
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
pub(super) enum Leakage {
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
/// Rotor inertia J = J_COEFF P_eq^J_EXP [kg m^2], P_eq in kW (module documentation).
const J_COEFF: f64 = 0.0016;
const J_EXP: f64 = 1.45;
/// The inertia's range factor (/3 .. x3).
pub(super) const J_FACTOR: f64 = 3.0;

/// The rated point as the circuit sees it.
#[derive(Debug, Clone, Copy)]
pub(super) struct Rated {
    pub(super) v_ph: f64,
    pub(super) i_a: f64,
    pub(super) p_out_w: f64,
    pub(super) f_hz: f64,
    pub(super) slip: f64,
    pub(super) poles: u32,
    pub(super) speed_rad_s: f64,
}

/// One circuit: per-phase star-equivalent values [ohm at the rated frequency] and losses.
#[derive(Debug, Clone, Copy)]
pub(super) struct RatedCircuit {
    rs: f64,
    rr: f64,
    xls: f64,
    xlr: f64,
    xm: f64,
    p_fw_w: f64,
}

/// The poles (given or inferred) and the rated slip.
pub(super) fn poles_and_slip(n: &Nameplate) -> Result<(u32, bool, f64), NameplateError> {
    let (poles, inferred) = match n.poles {
        Some(p) => (given_poles(p)?, false),
        None => (inferred_poles(n)?, true),
    };
    Ok((poles, inferred, rated_slip(n, poles, inferred)?))
}

/// The poles `p` given on the command line: an even number in the plausible range.
fn given_poles(p: u32) -> Result<u32, NameplateError> {
    if !(plausible::POLES.contains(&p) && p.is_multiple_of(2)) {
        return Err(field_error(
            "poles",
            format!(
                "{p} is not an even number in {}..={}",
                plausible::POLES.start(),
                plausible::POLES.end()
            ),
        ));
    }
    Ok(p)
}

/// The poles of the largest pole-pair count whose synchronous speed is above the rated
/// speed.
fn inferred_poles(n: &Nameplate) -> Result<u32, NameplateError> {
    let f = n.frequency_hz;
    let k = 60.0 * f / n.speed_rpm;
    let pairs = k.ceil() - 1.0;
    if pairs < 1.0 {
        return Err(field_error(
            "speed_rpm",
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
            "speed_rpm",
            format!(
                "{} rpm at {f} Hz would need {poles} poles, more than {}",
                n.speed_rpm,
                plausible::POLES.end()
            ),
        ));
    }
    Ok(poles)
}

/// The rated slip at `poles` (`inferred`: not given, then the error suggests giving
/// them): above 0 and at most [`MAX_SLIP`].
fn rated_slip(n: &Nameplate, poles: u32, inferred: bool) -> Result<f64, NameplateError> {
    let f = n.frequency_hz;
    let n_sync = 120.0 * f / f64::from(poles);
    let slip = (n_sync - n.speed_rpm) / n_sync;
    if slip <= 0.0 {
        return Err(field_error(
            "speed_rpm",
            format!(
                "{} rpm is at or above the synchronous speed {n_sync} rpm of {poles} poles at \
                 {f} Hz: an induction motor runs below synchronous speed",
                n.speed_rpm
            ),
        ));
    }
    if slip > MAX_SLIP {
        let hint = if inferred { "; give poles" } else { "" };
        return Err(field_error_naming(
            "speed_rpm",
            if inferred { &["poles"] } else { &[] as &[&str] },
            format!(
                "{} rpm is a slip of {:.1} % below the synchronous {n_sync} rpm of {poles} \
                 poles at {f} Hz: not a rated speed (rated slips are below {:.0} %){hint}",
                n.speed_rpm,
                100.0 * slip,
                100.0 * MAX_SLIP
            ),
        ));
    }
    Ok(slip)
}

/// Rr and Xm from `zp = Z - Rs` at slip `s` for a total leakage `xl` (step 4). The rotor
/// branch's conductance is the real part of `1 / (zp - j Xls)`; of the two resistances
/// with that conductance the larger (Rr/s above the rotor leakage, as at rated slip).
pub(super) fn rotor_and_magnetising(
    zp: Complex<f64>,
    s: f64,
    xls: f64,
    xlr: f64,
) -> Option<(f64, f64)> {
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
pub(super) fn circuit(
    n: &Nameplate,
    r: &Rated,
    a: &Assumptions,
) -> Result<RatedCircuit, NameplateError> {
    let (rs, p_fw_w) = stator_resistance(n, r, a)?;
    let pf = (n.power_factor + a.d_power_factor).min(0.999);
    let zb = r.v_ph / r.i_a;
    let z = Complex::new(zb * pf, zb * (1.0 - pf * pf).sqrt());
    let rest = RestOfImpedance {
        zp: z - Complex::new(rs, 0.0),
        slip: r.slip,
        stator_share: a.stator_share,
    };
    let no_circuit = || {
        field_error_naming(
            "power_factor",
            &["efficiency"],
            format!(
                "{} with efficiency {} and the slip {:.2} %: no T-equivalent circuit has \
                 this rated point (check both)",
                n.power_factor,
                n.efficiency,
                100.0 * r.slip
            ),
        )
    };
    let mut xl = LEAKAGE_PU[0] * zb;
    if let Leakage::PerUnit(x) = a.leakage {
        xl = x * zb;
    }
    let (mut rr, mut xm) = rest.solve(xl).ok_or_else(no_circuit)?;
    if let Leakage::LockedRotorRatio(k) = a.leakage {
        let target = zb / k;
        for _ in 0..50 {
            let next = rest.locked_rotor_leakage(rs, rr, xm, zb, k, target)?;
            let settled = (next - xl).abs() < 1e-9 * zb;
            xl = next;
            (rr, xm) = rest.solve(xl).ok_or_else(no_circuit)?;
            if settled {
                break;
            }
        }
    }
    let (xls, xlr) = rest.split(xl);
    Ok(RatedCircuit {
        rs,
        rr,
        xls,
        xlr,
        xm,
        p_fw_w,
    })
}

/// Rs and the friction and windage loss [W] (step 3): the power balance puts everything
/// but the air-gap power in Rs.
fn stator_resistance(
    n: &Nameplate,
    r: &Rated,
    a: &Assumptions,
) -> Result<(f64, f64), NameplateError> {
    let eta = n.efficiency + a.d_efficiency;
    let p_in = r.p_out_w / eta;
    let p_fw_w = a.fw_fraction * r.p_out_w;
    let p_ag = (r.p_out_w + p_fw_w) / (1.0 - r.slip);
    let rs = (p_in - p_ag) / (3.0 * r.i_a * r.i_a);
    if rs.is_nan() || rs <= 0.0 {
        return Err(field_error(
            "efficiency",
            format!(
                "{} is too high for the slip {:.2} %: the rotor copper loss alone (slip x \
                 air-gap power) needs an efficiency below about 1 - slip = {:.3}",
                n.efficiency,
                100.0 * r.slip,
                1.0 - r.slip
            ),
        ));
    }
    Ok((rs, p_fw_w))
}

/// The rated impedance less Rs, `zp = Z - Rs`, at the rated slip, with the leakage split
/// `stator_share`: what steps 4 and 5 solve.
struct RestOfImpedance {
    zp: Complex<f64>,
    slip: f64,
    stator_share: f64,
}

impl RestOfImpedance {
    /// The total leakage `xl` split into Xls and Xlr.
    fn split(&self, xl: f64) -> (f64, f64) {
        (self.stator_share * xl, (1.0 - self.stator_share) * xl)
    }

    /// Rr and Xm for the total leakage `xl` (step 4).
    fn solve(&self, xl: f64) -> Option<(f64, f64)> {
        let (xls, xlr) = self.split(xl);
        rotor_and_magnetising(self.zp, self.slip, xls, xlr)
    }

    /// The total leakage at which the circuit (Rs `rs`, Rr `rr`, Xm `xm`) draws the
    /// locked-rotor impedance `target` = Z_b / `k` at standstill (step 5).
    fn locked_rotor_leakage(
        &self,
        rs: f64,
        rr: f64,
        xm: f64,
        zb: f64,
        k: f64,
        target: f64,
    ) -> Result<f64, NameplateError> {
        let lr = |x: f64| {
            let (xls, xlr) = self.split(x);
            locked_rotor_impedance(rs, rr, xls, xlr, xm)
        };
        if lr(1e-6 * zb) >= target || lr(2.0 * zb) <= target {
            return Err(field_error(
                "locked_rotor_ratio",
                format!(
                    "{k} cannot be reached by this machine's circuit (its resistances \
                     alone allow at most {:.2})",
                    zb / lr(1e-6 * zb)
                ),
            ));
        }
        Ok(bisect(|x| lr(x) - target, 1e-6 * zb, 2.0 * zb))
    }
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
pub(super) fn circuit_values(c: &RatedCircuit, r: &Rated) -> [f64; 11] {
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
pub(super) fn value_meta(n: &Nameplate) -> [(&'static str, &'static str, String); 11] {
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
pub(super) fn assumption_sets(n: &Nameplate) -> Vec<Assumptions> {
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
