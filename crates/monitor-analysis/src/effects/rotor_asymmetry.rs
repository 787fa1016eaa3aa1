//! `rotor_asymmetry`: an unequal rotor cage (broken rotor bars, a cracked end ring), the
//! library effect for `compare` / `explain` (the MCSA report is
//! `crate::rotor_asymmetry`).
//!
//! # Model (the simplified model's view of the simulator's full-order asymmetry)
//! The simulator gives rotor phase a the resistance Rr (1 + delta) (`monitor_sim`); in
//! alpha-beta that is R_r = Rr I + (2/3) Rr delta u u^T, u along rotor phase a. In the
//! rotor-flux frame of the analysis the rotor current is along q (i_rq = -(Lm/Lr) I_qs), so
//! the slip equation sees the q-q element of R_r:
//! ```text
//!   R_qq / Rr = 1 + (2/3) delta sin^2(g) = 1 + (delta/3) (1 - cos(2 g)),
//!   g = Np theta_m - theta + phi/2   (rotor phase a against the flux's d axis)
//! ```
//! Np theta_m is the integral of the measured electrical speed, theta the analysis frame's
//! angle, phi the unknown angle of the faulty phase (fitted). The rotor resistance term of
//! Ra = Rs + (Ls/Lr) Rr is multiplied by R_qq / Rr: the q current and the torque are then
//! modulated at 2 s f in the rotor-flux frame, which in the stator frame is the (1 - 2s) f
//! sideband, and the 2 s f torque ripple moves the speed, which makes the (1 + 2s) f one.
//! The d row drives the rotor flux phi = psi_r/Lm (exact rotor equation, first order in
//! delta): `tau_r dphi/dt = I_ds - phi + (delta/3) [sin(2g) I_qs + (1 + cos(2g)) (I_ds - phi)]`.
//! The second part matters although it looks second order: in a voltage-fed machine the
//! rotor flux barely ripples (0.3 % of I_ds on the 3 hp motor at delta 0.2, against an
//! I_ds ripple of 6 %), the drive and the I_ds ripple nearly cancel, and the flux's error
//! reaches I_qs with a gain omega (Lm^2/Lr)/Ra of about 18. I_ds - phi is taken as the
//! measured I_ds ripple (phi's own is a tenth of it), and the flux starts in its periodic
//! response to the drive ([`crate::simplified_model::RotorCage::flux_drive_start`]; started from I_ds it rings for
//! a rotor time constant, which a fit "explains" with a 4x shorter one). Approximations:
//! the q row's sin(2g)(I_ds - phi) term (DC and 4 s f only) is left out, and without
//! `flux_dynamics` the model's flux follows the smoothed I_ds at once, which makes the
//! fitted delta about 2x the truth (docs/model-vs-measurement.md, "Broken rotor bars").
//!
//! With all four dynamics effects in the model, the full-order model carries the whole
//! resistance matrix in its rotor flux equation (`simplified_model::RotorCage::asymmetry`), with the same
//! (delta, phi); the terms above are then unused.

use super::{
    declared_values, About, Contribution, EffectModel, EffectParam, EffectValuesError, FitSetup,
    Needs, SetupError,
};
use crate::prep::{zero_phase_lpf, Prepared, I_F_SMOOTH_HZ};
use crate::rotor_asymmetry::{mcsa, spectrum_contradicts};
use crate::simplified_model::{CageAsymmetry, MachineConstants, ModelTerms};
use monitor_core::rotor_cage::broken_bars_of_delta;
use monitor_laws::EffectId;
use std::f64::consts::PI;

/// Physical range of the fitted asymmetry delta: 0..1. One broken bar of a 28-bar cage is
/// delta = 0.12, three adjacent ones 0.47, delta = 1 is n = N/6 (4.7 of 28); a cage
/// beyond that has lost a third of a pole pitch of bars (Bellini et al. 2001 report 1 to
/// 4 broken bars as the range of interest). Without `flux_dynamics` in the model the fit
/// overestimates delta up to about 2x (module doc), which is why the range reaches 1
/// rather than 0.5.
pub const DELTA_RANGE: (f64, f64) = (0.0, 1.0);

/// Basis of [`DELTA_RANGE`].
pub const DELTA_BASIS: &str = "delta = 3n/(N - 3n): up to N/6 adjacent broken bars (4.7 of 28; Kliman et al. 1988, Bellini et al. 2001)";

/// The cage asymmetry's parameters.
const PARAMS: [EffectParam; 2] = [
    EffectParam {
        name: "delta",
        unit: "1",
        doc: "relative rotor phase resistance asymmetry (one rotor phase Rr (1 + delta)); n broken bars of N: delta = 3n/(N - 3n)",
        range: DELTA_RANGE,
        per: None,
        basis: DELTA_BASIS,
    },
    EffectParam {
        name: "phi_rad",
        unit: "rad",
        doc: "twice the angle of the faulty rotor phase at the log's start (a nuisance parameter)",
        range: (f64::NEG_INFINITY, f64::INFINITY),
        per: None,
        basis: "any angle",
    },
];

/// The cage asymmetry's fitted values ([`PARAMS`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RotorAsymmetryValues {
    /// The relative rotor phase resistance asymmetry [1].
    pub delta: f64,
    /// Twice the faulty rotor phase's angle at the log's start [rad].
    pub phi_rad: f64,
}

impl TryFrom<&[f64]> for RotorAsymmetryValues {
    type Error = EffectValuesError;
    fn try_from(v: &[f64]) -> Result<Self, EffectValuesError> {
        let [delta, phi_rad] = declared_values(EffectId::ROTOR_ASYMMETRY, &PARAMS, v)?;
        Ok(RotorAsymmetryValues { delta, phi_rad })
    }
}

/// The library entry (see the module doc).
#[derive(Debug, Clone, Copy)]
pub struct RotorAsymmetry;

/// The cage set up on a log: per working sample, twice the rotor's electrical angle
/// against the analysis frame and the measured I_ds ripple.
struct RotorAsymmetryOnLog {
    /// 2 (Np theta_m - theta) [rad] ([`double_slip_angle`]).
    double_slip_angle: Vec<f64>,
    /// The I_ds ripple [A] ([`id_ripple`]).
    id_ripple: Vec<f64>,
}

/// 2 (Np theta_m - theta) per working sample: twice the measured rotor electrical angle
/// against the analysis frame (empty without a speed column).
fn double_slip_angle(d: &Prepared) -> Vec<f64> {
    if d.omega_r.len() != d.len() || d.theta.len() != d.len() || d.is_empty() {
        return Vec::new();
    }
    let mut th_r = d.theta[0];
    let mut out = Vec::with_capacity(d.len());
    for k in 0..d.len() {
        if k > 0 {
            let dt = d.t_s[k] - d.t_s[k - 1];
            th_r += 0.5 * dt * (d.omega_r[k] + d.omega_r[k - 1]);
        }
        out.push(2.0 * (th_r - d.theta[k]));
    }
    out
}

/// The measured I_ds less its part slower than the asymmetry's 2 s f (zero-phase low-pass
/// at a fifth of the median |2 s f|, at least 0.1 Hz): what I_ds - phi is in the rotor flux
/// equation, phi's own ripple being a tenth of I_ds's (module doc).
fn id_ripple(d: &Prepared, ang: &[f64]) -> Vec<f64> {
    let mut rate: Vec<f64> = ang
        .windows(2)
        .map(|w| ((w[1] - w[0]) / d.dt_s).abs())
        .collect();
    let fc = if rate.is_empty() {
        0.1
    } else {
        let mid = rate.len() / 2;
        let (_, m, _) = rate.select_nth_unstable_by(mid, f64::total_cmp);
        (*m / (2.0 * PI) / 5.0).max(0.1)
    };
    let slow = zero_phase_lpf(&d.id, d.dt_s, fc);
    d.id.iter().zip(slow).map(|(a, b)| a - b).collect()
}

/// A first estimate of (delta, phi) from the measured I_ds ripple `id_ripple`: the rotor
/// flux barely ripples in a voltage-fed machine (the stator voltage holds the flux), so the
/// asymmetry's drive of the flux equation (module doc) and the I_ds ripple nearly cancel:
/// I_ds ripple = -(delta/3) I_qs sin(2g + phi) = A cos 2g + B sin 2g (least squares),
/// A = -(delta/3) I_qs sin phi, B = -(delta/3) I_qs cos phi.
fn initial_estimate(d: &Prepared, ang: &[f64], id_ripple: &[f64]) -> (f64, f64) {
    let (mut cc, mut ss, mut cs, mut yc, mut ys, mut iq) = (0.0, 0.0, 0.0, 0.0, 0.0, 0.0);
    for k in 0..ang.len().min(id_ripple.len()) {
        let (s, c) = ang[k].sin_cos();
        let y = id_ripple[k];
        cc += c * c;
        ss += s * s;
        cs += c * s;
        yc += y * c;
        ys += y * s;
        iq += d.iq_pos[k].abs();
    }
    let det = cc * ss - cs * cs;
    if det.abs() < 1e-12 || ang.is_empty() {
        return (0.05, 0.0);
    }
    let a = (yc * ss - ys * cs) / det;
    let b = (ys * cc - yc * cs) / det;
    let iq = (iq / ang.len() as f64).max(1e-6);
    let delta = 3.0 * a.hypot(b) / iq;
    (delta.clamp(0.02, 1.0), (-a).atan2(-b))
}

/// What `RotorAsymmetry` is ([`About`]).
const ABOUT: About = About {
    kind: EffectId::ROTOR_ASYMMETRY,
    description: "The rotor cage is not symmetric (broken rotor bars, a cracked end ring): the rotor resistance seen by the stator field changes at twice the slip frequency, which modulates the torque and the current: (1 - 2s) f and (1 + 2s) f sidebands in the stator current, 2 s f ripple in speed.",
    equations: "Rr in Ra = Rs + (Ls/Lr) Rr is multiplied by 1 + (delta/3)(1 - cos(2 (Np theta_m - theta) + phi)): the q-q element of the rotor resistance matrix Rr I + (2/3) Rr delta u u^T, u along the faulty rotor phase; Np theta_m integrates the measured speed. In the full-order model (all dynamics effects in) the whole matrix acts in the rotor flux equation.",
    parameters: &PARAMS,
};

impl EffectModel for RotorAsymmetry {
    fn about(&self) -> &About {
        &ABOUT
    }
    fn needs(&self) -> Needs {
        Needs::VOLTAGES_AND_SPEED
    }
    fn setup(&self, d: &Prepared, _n: &MachineConstants) -> Result<FitSetup, SetupError> {
        let ang = double_slip_angle(d);
        if ang.is_empty() {
            return Err(SetupError::NoSpeed {
                because: "the rotor angle",
            });
        }
        let ripple = id_ripple(d, &ang);
        let (delta0, phi0) = initial_estimate(d, &ang, &ripple);
        let [delta, phi_rad] = &PARAMS;
        let params = vec![
            delta.fit(delta0, (0.0, 2.0), 0.05, 1.0),
            phi_rad.fit(phi0, (phi0 - 4.0 * PI, phi0 + 4.0 * PI), 0.3, 1.0),
        ];
        let on_log = RotorAsymmetryOnLog {
            double_slip_angle: ang,
            id_ripple: ripple,
        };
        // The I_ds ripple's phase can be half a turn off through starts and steps (found on
        // the 11 kW machine with its true parameters: the fit ended at delta = 0 and
        // explained nothing).
        Ok(FitSetup::new(on_log, params)?.with_alt_init(vec![vec![delta0, phi0 + PI]])?)
    }
    fn contradicted_by(
        &self,
        d: &Prepared,
        n: &MachineConstants,
        fitted: &[f64],
    ) -> Result<Option<String>, EffectValuesError> {
        // A cage asymmetry is named only when the current spectrum agrees with the fit.
        let v = RotorAsymmetryValues::try_from(fitted)?;
        Ok(spectrum_contradicts(d, n.np, v.delta))
    }
}

impl Contribution for RotorAsymmetryOnLog {
    type Values = RotorAsymmetryValues;
    fn values(&self, v: &[f64]) -> Result<RotorAsymmetryValues, EffectValuesError> {
        RotorAsymmetryValues::try_from(v)
    }
    /// The reduced model's rotor resistance scale and flux drive, and the full-order
    /// model's cage.
    fn contribute(
        &self,
        p: &RotorAsymmetryValues,
        d: &Prepared,
        _n: &MachineConstants,
        t: &mut ModelTerms,
    ) {
        let len = d.len();
        let (delta, phi) = (p.delta, p.phi_rad);
        let (ang, id_ripple) = (&self.double_slip_angle, &self.id_ripple);
        if ang.len() != len || id_ripple.len() != len {
            return;
        }
        t.rotor_cage.asymmetry = Some(CageAsymmetry {
            delta,
            phi_rad: phi,
        });
        t.scale_rotor_resistance(
            ang.iter()
                .map(|a| 1.0 + delta / 3.0 * (1.0 - (a + phi).cos())),
        );
        // The d row of the resistance matrix on the rotor current (module doc):
        // tau_r dphi/dt = i_d - phi + (delta/3) [sin(2g) I_qs + (1 + cos(2g)) (I_ds - phi)],
        // with I_ds - phi taken as the measured I_ds ripple (phi's own ripple is a tenth of
        // it: the two first-order drives nearly cancel in a voltage-fed machine).
        let drive: Vec<f64> = ang
            .iter()
            .zip(&d.iq_pos)
            .zip(id_ripple)
            .map(|((a, iq), idr)| {
                let (sn, cs) = (a + phi).sin_cos();
                delta / 3.0 * (sn * iq + (1.0 + cs) * idr)
            })
            .collect();
        // The flux's periodic response to the drive at the first sample: the drive
        // smoothed as i_f smooths I_ds (which makes the flux's start), over the first second.
        let head = ((1.0 / d.dt_s) as usize).clamp(1, len);
        let start = zero_phase_lpf(&drive[..head], d.dt_s, I_F_SMOOTH_HZ)[0];
        t.drive_rotor_flux(drive.into_iter(), start);
    }
    fn describe(&self, p: &RotorAsymmetryValues, d: &Prepared, n: &MachineConstants) -> String {
        let delta = p.delta;
        let m = mcsa(d, n.np, None, Some(delta));
        let sb = match (m.lower_sideband_db, m.upper_sideband_db) {
            (Some(l), Some(u)) => format!(
                "; current sidebands {l:.1} dB ((1-2s)f) and {u:.1} dB ((1+2s)f) below the fundamental"
            ),
            _ => String::new(),
        };
        format!(
            "rotor cage asymmetry: one rotor phase's resistance {:.1} % above the others (about {:.1} broken bars of a 28-bar cage, {:.1} of 40){sb}",
            100.0 * delta,
            broken_bars_of_delta(delta, 28.0),
            broken_bars_of_delta(delta, 40.0),
        )
    }
}
