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

mod circuit;
mod toml_text;

use crate::params::{plausible, ParamError, ParamFile};
use circuit::{
    assumption_sets, circuit, circuit_values, poles_and_slip, value_meta, Rated, J_FACTOR,
};
use std::f64::consts::TAU;
pub use toml_text::{toml_entry, toml_number};

/// Errors of [`estimate`]: each names the nameplate's field it blames by its name in
/// [`Nameplate`] (`efficiency`, `speed_rpm`, ...); a front end says it in its own words
/// ([`NameplateError::spelled`]: the command line's `--efficiency`).
#[derive(Debug, thiserror::Error)]
pub enum NameplateError {
    /// A nameplate value no induction machine can have.
    #[error("{field} {message}")]
    Field {
        /// The field blamed (`efficiency`, `speed_rpm`, ...).
        field: &'static str,
        /// What is wrong, with the value and the limit (one line).
        message: String,
        /// The other fields the message names (each by its name, its last occurrence in
        /// `message` the one meant).
        mentions: &'static [&'static str],
    },
    /// The estimated circuit is refused by the parameter file's own checks.
    #[error("the estimate is not a plausible machine: {0}")]
    Params(#[from] ParamError),
}

impl NameplateError {
    /// The message with each field named by `name` (the command line: its flag).
    pub fn spelled(&self, name: &dyn Fn(&str) -> String) -> String {
        match self {
            NameplateError::Field {
                field,
                message,
                mentions,
            } => {
                let mut message = message.clone();
                for m in *mentions {
                    if let Some(at) = message.rfind(m) {
                        message.replace_range(at..at + m.len(), &name(m));
                    }
                }
                format!("{} {message}", name(field))
            }
            e => e.to_string(),
        }
    }
}

fn field_error(field: &'static str, message: String) -> NameplateError {
    NameplateError::Field {
        field,
        message,
        mentions: &[],
    }
}

/// As [`field_error`], the message naming the fields `mentions` too.
fn field_error_naming(
    field: &'static str,
    mentions: &'static [&'static str],
    message: String,
) -> NameplateError {
    NameplateError::Field {
        field,
        message,
        mentions,
    }
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

/// How far P may be from sqrt 3 V I cos phi eta (a ratio) before the nameplate is refused.
const CONSISTENCY: f64 = 0.2;

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
    positive("power_kw", n.power_kw, " kW")?;
    positive("voltage_v", n.voltage_v, " V")?;
    positive("current_a", n.current_a, " A")?;
    positive("frequency_hz", n.frequency_hz, " Hz")?;
    positive("speed_rpm", n.speed_rpm, " rpm")?;
    for (field, v) in [
        ("power_factor", n.power_factor),
        ("efficiency", n.efficiency),
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
        ("voltage_v", n.voltage_v, "V", plausible::V_LL_RMS),
        ("frequency_hz", n.frequency_hz, "Hz", plausible::F_HZ),
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
                "locked_rotor_ratio",
                format!("{k} is not a locked-rotor current ratio IA/IN (1.5..15; typical 5..9)"),
            ));
        }
    }
    let electrical_kw =
        3f64.sqrt() * n.voltage_v * n.current_a * n.power_factor * n.efficiency / 1000.0;
    let ratio = n.power_kw / electrical_kw;
    if !(ratio > 1.0 - CONSISTENCY && ratio < 1.0 + CONSISTENCY) {
        return Err(field_error_naming(
            "power_kw",
            &["voltage_v", "current_a", "power_factor", "efficiency"],
            format!(
                "{} kW disagrees with sqrt3 x voltage_v x current_a x power_factor x \
                 efficiency = {electrical_kw:.4} kW (ratio {ratio:.3}; a real nameplate \
                 agrees within {:.0} %): check each value, and that the current is the one \
                 for this voltage",
                n.power_kw,
                100.0 * CONSISTENCY
            ),
        ));
    }
    Ok(())
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

#[cfg(test)]
mod tests {
    use super::circuit::rotor_and_magnetising;
    use super::*;
    use nalgebra::Complex;

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
