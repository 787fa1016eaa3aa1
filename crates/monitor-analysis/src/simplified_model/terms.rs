//! What the effects contribute to the model equations: one interface of physical channels.
//!
//! The model ([`super::simulate`]) reads [`ModelTerms`]; each effect of the library
//! (`crate::effects`) writes the channels its physics changes, and several
//! effects on one channel compose (series multiply or add, see each channel). Adding an
//! effect whose physics the channels already carry edits only the effect's own file and
//! the library's registry; the model does not name effects.

use super::InputNoise;
use crate::prep::{Prepared, C64};
use std::sync::Arc;

/// The effects' contributions to the model equations, by physical channel. Every channel's
/// neutral value (empty series, `None`, 0, `false`) is the paper's simplified model; a
/// per-sample series is indexed like the working series it was made for, and a series of
/// another length counts as neutral from its end on.
#[derive(Debug, Clone, Default)]
pub struct ModelTerms {
    /// Stator and rotor resistances.
    pub resistance: Resistance,
    /// The magnetising branch: Lm and the core loss across it.
    pub magnetising: Magnetising,
    /// Torques on the shaft besides the electromagnetic one and the viscous (B + Bl) w_m.
    pub shaft: Shaft,
    /// The negative sequence (an unbalanced supply, an unequal winding).
    pub negative_sequence: NegativeSequenceTerm,
    /// An unequal stator winding (`None`: symmetric).
    pub stator_winding: Option<WindingAsymmetryTerm>,
    /// An unequal rotor cage.
    pub rotor_cage: RotorCage,
    /// Which states of the full-order machine the model integrates.
    pub dynamics: Dynamics,
    /// Extra white noise on the inputs (for the noise floor; `None` in every fit).
    pub input_noise: Option<InputNoise>,
}

/// Resistance channels: per-sample scale series (empty: 1).
#[derive(Debug, Clone, Default)]
pub struct Resistance {
    /// Multiplies Rs and Rr alike [-] (a winding temperature: copper's coefficient holds
    /// for both windings); composes by multiplication.
    pub scale: Vec<f64>,
    /// Multiplies the rotor resistance term of Ra only [-] (the q-q element of an unequal
    /// cage's resistance matrix in the reduced model); composes by multiplication.
    pub rotor_scale: Vec<f64>,
    /// Multiplies Rs only, on top of `scale` [-] (a stator that heats apart from the
    /// rotor); composes by multiplication.
    pub stator_scale: Vec<f64>,
}

/// The magnetising branch.
#[derive(Debug, Clone, Default)]
pub struct Magnetising {
    /// Multiplies Lm per sample in the reduced model and the full-order form in the
    /// analysis frame [-] (empty: 1); composes by multiplication.
    pub lm_scale: Vec<f64>,
    /// The law Lm follows on the model's own magnetising flux in the stationary-frame
    /// full-order model (`None`: linear); that model ignores `lm_scale`.
    pub law: Option<MagnetisingLaw>,
    /// Conductance across the magnetising branch, 1/Rfe [S] (0: no core loss); adds.
    pub core_loss_s: f64,
}

/// A magnetising inductance that falls with the magnetising flux:
/// `Lm = Lm0 / (1 + (|psi_m| / psi_sat)^n)`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SaturationLaw {
    /// Flux linkage at which Lm has halved, psi_sat [Wb] (> 0).
    pub psi_sat_wb: f64,
    /// Sharpness of the knee, n [-] (about 2 to 14).
    pub exponent: f64,
    /// Lm0 over the machine's `lm_h` ([`super::MachineConstants::lm0_over_file`]: above
    /// 1 where the file holds the rated point's Lm).
    pub lm0_over_file: f64,
}

/// The law Lm follows on the magnetising flux in the stationary-frame full-order model: the
/// library's saturation law, or a user's law of any form (an expression of `psi_m`, a
/// no-load test's curve).
#[derive(Debug, Clone)]
pub enum MagnetisingLaw {
    /// The library's `Lm0 / (1 + (|psi_m| / psi_sat)^n)`.
    Power(SaturationLaw),
    /// A user's law, as its shape `Lm(psi_m) / Lm(0)` and its unsaturated value over the
    /// file's `lm_h`: the model's Lm is the fitted unsaturated Lm0 times the shape, so that
    /// a refitted Ls scales the user's curve as it scales the library's.
    Shape(LmShape),
}

impl MagnetisingLaw {
    /// Lm0 over the machine's `lm_h` (the unsaturated start of the full-order forms).
    pub fn lm0_over_file(&self) -> f64 {
        match self {
            MagnetisingLaw::Power(l) => l.lm0_over_file,
            MagnetisingLaw::Shape(s) => s.lm0_over_file,
        }
    }
}

/// A user's magnetising law as a shape ([`MagnetisingLaw::Shape`]).
#[derive(Clone)]
pub struct LmShape {
    /// `L(psi) / L(0)` at the flux `psi` [Wb, peak] (finite and positive where the law is
    /// physical): Lm of the magnetising flux, or with `stator` Ls of the stator flux.
    pub shape: Arc<dyn Fn(f64) -> f64 + Send + Sync>,
    /// The unsaturated Lm over the file's `lm_h` (with `stator`: `Ls(0) - Lls` over it).
    pub lm0_over_file: f64,
    /// The law is the stator inductance Ls of the stator flux (a no-load test's curve, the
    /// Gamma-equivalent circuit: no stator leakage, the machine's leakage on the rotor
    /// side), not Lm of the magnetising flux of the file's T-equivalent circuit.
    pub stator: bool,
}

impl std::fmt::Debug for LmShape {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("LmShape")
            .field("lm0_over_file", &self.lm0_over_file)
            .finish_non_exhaustive()
    }
}

/// A shaft torque that depends only on the speed (friction, drag).
pub trait SpeedTorque: Send + Sync + std::fmt::Debug {
    /// The load torque at mechanical speed `wm_rad_s` [N m] (positive brakes a shaft
    /// turning forwards).
    fn torque_nm(&self, wm_rad_s: f64) -> f64;
}

/// A shaft torque of the working sample and the speed: a law of time, speed and the shaft's
/// angle, each read at the sample (a user's `load_torque` law).
pub trait SampleTorque: Send + Sync + std::fmt::Debug {
    /// The load torque at working sample `k` and mechanical speed `wm_rad_s` [N m]
    /// (positive brakes a shaft turning forwards).
    fn torque_nm(&self, k: usize, wm_rad_s: f64) -> f64;
}

/// Torques on the shaft besides the electromagnetic torque and (B + Bl) w_m: in eq. (29),
/// `J dw_m/dt = Te - (B + Bl) w_m - T_extra(k, w_m)`.
#[derive(Debug, Clone, Default)]
pub struct Shaft {
    /// Load torque per sample, independent of the speed [N m] (empty: 0); adds.
    pub load_nm: Vec<f64>,
    /// Speed-dependent load torques, summed in order.
    pub speed_torques: Vec<Arc<dyn SpeedTorque>>,
    /// Torques of the sample and the speed (users' laws), summed in order.
    pub sample_torques: Vec<Arc<dyn SampleTorque>>,
}

impl Shaft {
    /// `T_extra` at working sample `k` and mechanical speed `w` [rad/s]: the speed
    /// torques, then the sample's load [N m].
    #[inline(always)]
    pub fn extra_nm(&self, k: usize, w: f64) -> f64 {
        let speed: f64 = self
            .speed_torques
            .iter()
            .fold(0.0, |a, s| a + s.torque_nm(w));
        let sample: f64 = self
            .sample_torques
            .iter()
            .fold(0.0, |a, s| a + s.torque_nm(k, w));
        speed + sample + self.load_nm.get(k).copied().unwrap_or(0.0)
    }
}

/// The negative sequence in the two forms of the model.
#[derive(Debug, Clone, Default)]
pub struct NegativeSequenceTerm {
    /// Negative-sequence current the reduced model adds to its balanced current,
    /// stationary frame [A] (empty: 0); adds. The stationary-frame full-order model takes
    /// its negative sequence from the machine itself (`voltage_gain`, the stator winding)
    /// and adds this only when `voltage_gain` is `None`.
    pub current: Vec<C64>,
    /// In the stationary-frame full-order model, the measured negative-sequence voltage
    /// times this gain drives the machine beside the positive sequence [-] (`None`: the
    /// positive sequence alone), so that the negative-sequence current follows from the
    /// machine's own equations (its slip through a start, the 2f torque and speed ripple).
    pub voltage_gain: Option<C64>,
}

/// An unequal rotor cage in the two forms of the model.
#[derive(Debug, Clone, Default)]
pub struct RotorCage {
    /// The stationary-frame full-order model's cage: rotor phase a's resistance
    /// Rr (1 + delta) (`None`: symmetric).
    pub asymmetry: Option<CageAsymmetry>,
    /// Extra drive of the normalised rotor flux phi = psi_r/Lm in the reduced model [A]
    /// (the d-q element of an unequal rotor resistance): phi follows i_f + drive through
    /// the rotor time constant (the fitted one with rotor-flux dynamics, else the nominal
    /// Lr/Rr, as a deviation added to the quasi-static flux); empty: 0; adds.
    pub flux_drive: Vec<f64>,
    /// The flux's periodic response to `flux_drive` at the first sample [A] (added to the
    /// initial phi: a flux started without it rings for a rotor time constant); adds.
    pub flux_drive_start: f64,
}

/// An unequal rotor cage: rotor phase a's resistance is Rr (1 + delta).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CageAsymmetry {
    /// Relative resistance asymmetry delta [-] (>= 0).
    pub delta: f64,
    /// Twice the faulty rotor phase's electrical angle against the analysis frame at the
    /// log's first sample [rad].
    pub phi_rad: f64,
}

/// Which states of the full-order machine the model integrates; each one left out is the
/// paper's simplification of it. All four on: the full-order T-equivalent machine in the
/// stationary frame; the d axis or the q-axis rotor flux on: the full-order form in the
/// analysis frame; else the reduced model.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct Dynamics {
    /// The stator q current's derivative term, La dI_qs/dt of eq. (28), with La [H]
    /// (`None`: I_qs quasi-static).
    pub stator_current_la_h: Option<f64>,
    /// The rotor flux's dynamics with the rotor time constant Lr/Rr [s] (`None`: psi_r =
    /// Lm i_f).
    pub rotor_flux_tau_s: Option<f64>,
    /// I_ds predicted by the d-axis stator equation (else the measured one).
    pub stator_d_axis: bool,
    /// The q-axis rotor flux and the slip coupling between the axes (else psi_qr = 0).
    pub rotor_flux_q_axis: bool,
}

impl Dynamics {
    /// All four states: the full-order machine, run in the stationary frame.
    pub fn is_full_order(&self) -> bool {
        self.stator_d_axis
            && self.rotor_flux_q_axis
            && self.stator_current_la_h.is_some()
            && self.rotor_flux_tau_s.is_some()
    }

    /// The d axis or the q-axis rotor flux: the full-order form (in the analysis frame
    /// unless [`Dynamics::is_full_order`]).
    pub fn needs_full_form(&self) -> bool {
        self.stator_d_axis || self.rotor_flux_q_axis
    }
}

/// `into` composed with `other` sample by sample by `op`; an empty `into` takes `other`.
fn compose<T: Copy>(into: &mut Vec<T>, other: impl Iterator<Item = T>, op: impl Fn(T, T) -> T) {
    if into.is_empty() {
        into.extend(other);
    } else {
        for (a, b) in into.iter_mut().zip(other) {
            *a = op(*a, b);
        }
    }
}

impl ModelTerms {
    /// Multiplies Rs and Rr by `scale` per sample ([`Resistance::scale`]).
    pub fn scale_resistances(&mut self, scale: impl Iterator<Item = f64>) {
        compose(&mut self.resistance.scale, scale, |a, b| a * b);
    }

    /// Multiplies the rotor resistance term of Ra by `scale` per sample
    /// ([`Resistance::rotor_scale`]).
    pub fn scale_rotor_resistance(&mut self, scale: impl Iterator<Item = f64>) {
        compose(&mut self.resistance.rotor_scale, scale, |a, b| a * b);
    }

    /// Multiplies Rs alone by `scale` (per sample, on top of [`ModelTerms::scale_resistances`]).
    pub fn scale_stator_resistance(&mut self, scale: impl Iterator<Item = f64>) {
        compose(&mut self.resistance.stator_scale, scale, |a, b| a * b);
    }

    /// Multiplies Lm by `scale` per sample ([`Magnetising::lm_scale`]).
    pub fn scale_magnetising_inductance(&mut self, scale: impl Iterator<Item = f64>) {
        compose(&mut self.magnetising.lm_scale, scale, |a, b| a * b);
    }

    /// Adds a speed-independent load torque per sample [N m] ([`Shaft::load_nm`]).
    pub fn add_load_torque(&mut self, torque_nm: impl Iterator<Item = f64>) {
        compose(&mut self.shaft.load_nm, torque_nm, |a, b| a + b);
    }

    /// Adds a speed-dependent load torque ([`Shaft::speed_torques`]).
    pub fn add_speed_torque(&mut self, torque: impl SpeedTorque + 'static) {
        self.shaft.speed_torques.push(Arc::new(torque));
    }

    /// Adds a load torque of the sample and the speed ([`Shaft::sample_torques`]).
    pub fn add_sample_torque(&mut self, torque: impl SampleTorque + 'static) {
        self.shaft.sample_torques.push(Arc::new(torque));
    }

    /// Adds a negative-sequence current per sample, stationary frame [A]
    /// ([`NegativeSequenceTerm::current`]).
    pub fn add_negative_sequence_current(&mut self, current: impl Iterator<Item = C64>) {
        compose(&mut self.negative_sequence.current, current, |a, b| a + b);
    }

    /// Adds a drive of the normalised rotor flux per sample [A] and its periodic response
    /// at the first sample ([`RotorCage::flux_drive`]).
    pub fn drive_rotor_flux(&mut self, drive: impl Iterator<Item = f64>, start: f64) {
        compose(&mut self.rotor_cage.flux_drive, drive, |a, b| a + b);
        self.rotor_cage.flux_drive_start += start;
    }

    /// The reduced model's negative-sequence current at sample `k`: the channel's, plus
    /// the unequal stator winding's steady-state description.
    #[inline(always)]
    pub(super) fn reduced_i_neg(&self, d: &Prepared, k: usize) -> C64 {
        let ineg = self
            .negative_sequence
            .current
            .get(k)
            .copied()
            .unwrap_or_default();
        match &self.stator_winding {
            Some(w) => ineg + w.i_neg(d, k),
            None => ineg,
        }
    }
}

/// Shorted turns in one stator phase in the two forms of the model.
///
/// Reduced model: the steady-state description `i_neg = c conj(i_pos)` (`c` from the
/// measured positive-sequence current). Full-order model: the simulator's turn fault (see
/// `monitor_sim`'s machine; Tallam, Habetler, Harley, IEEE Trans. Ind. Appl. 38(3), 2002): the
/// machine stays the symmetric one and the terminals draw the shorted loop's current on
/// top, `(2/3) mu i_f u_k` with `i_f = (u_k . v) / R_f` (the loop's time constant is tens of
/// microseconds, far below a working sample). As a complex vector that is
/// ```text
///   i_loop = |y| v + y conj(v),   y = (mu / (3 R_f)) e^{j 2 th_k}
/// ```
/// whose negative sequence is `y conj(Z1) conj(i_pos)`: the effect fits `c` in both forms
/// and converts it with `y = c / conj(Z1)` (Z1 the positive-sequence impedance at the log's
/// mean operating point), so that the fitted value means the same.
#[derive(Debug, Clone, Copy)]
pub struct WindingAsymmetryTerm {
    /// The steady-state ratio i_neg / conj(i_pos) [-].
    pub c: C64,
    /// The full-order loop admittance `y` [S].
    pub y: C64,
}

impl WindingAsymmetryTerm {
    /// The shorted loop's terminal current for the stator voltage `v` [A].
    #[inline(always)]
    pub(super) fn loop_current(&self, v: C64) -> C64 {
        v * self.y.norm() + self.y * v.conj()
    }

    /// The reduced model's negative-sequence current at sample `k` of `d`.
    #[inline(always)]
    fn i_neg(&self, d: &Prepared, k: usize) -> C64 {
        self.c * (d.i_ab[k] - d.i_neg[k]).conj()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[derive(Debug)]
    struct Linear(f64);
    impl SpeedTorque for Linear {
        fn torque_nm(&self, w: f64) -> f64 {
            self.0 * w
        }
    }

    /// Two effects on one channel compose: scales multiply, torques and currents add, and
    /// the first effect's series is taken as it is.
    #[test]
    fn channels_compose_across_effects() {
        let mut t = ModelTerms::default();
        t.scale_resistances([1.5, 2.0].into_iter());
        assert_eq!(t.resistance.scale, [1.5, 2.0]);
        t.scale_resistances([2.0, 4.0].into_iter());
        assert_eq!(t.resistance.scale, [3.0, 8.0]);
        t.add_load_torque([1.0, 2.0].into_iter());
        t.add_load_torque([0.5, 0.25].into_iter());
        assert_eq!(t.shaft.load_nm, [1.5, 2.25]);
        t.add_speed_torque(Linear(2.0));
        t.add_speed_torque(Linear(0.5));
        // 2 w + 0.5 w at w = 4, plus the sample's load; past the series' end no load.
        assert_eq!(t.shaft.extra_nm(1, 4.0), 10.0 + 2.25);
        assert_eq!(t.shaft.extra_nm(7, 4.0), 10.0);
        t.add_negative_sequence_current([C64::new(1.0, 0.0)].into_iter());
        t.add_negative_sequence_current([C64::new(0.0, 2.0)].into_iter());
        assert_eq!(t.negative_sequence.current, [C64::new(1.0, 2.0)]);
        t.drive_rotor_flux([0.25].into_iter(), 0.5);
        t.drive_rotor_flux([0.5].into_iter(), 0.25);
        assert_eq!(t.rotor_cage.flux_drive, [0.75]);
        assert_eq!(t.rotor_cage.flux_drive_start, 0.75);
    }

    /// The form of the model follows the dynamics channel.
    #[test]
    fn the_dynamics_channel_picks_the_form() {
        let mut dy = Dynamics::default();
        assert!(!dy.needs_full_form() && !dy.is_full_order());
        dy.stator_d_axis = true;
        assert!(dy.needs_full_form() && !dy.is_full_order());
        dy.rotor_flux_q_axis = true;
        dy.stator_current_la_h = Some(0.02);
        assert!(!dy.is_full_order());
        dy.rotor_flux_tau_s = Some(0.1);
        assert!(dy.is_full_order());
    }
}
