//! Negative-sequence analysis of the phase currents: how unbalanced, and which phase.
//!
//! The current vector of a machine with a (small) asymmetry is
//! `i(t) = I1 e^{j w t} + conj(I2) e^{-j w t}` with the symmetrical-component phasors
//! `I1 = (Ia + a Ib + a^2 Ic)/3`, `I2 = (Ia + a^2 Ib + a Ic)/3`, `a = e^{j 2pi/3}`.
//! Park with any angle `theta` that turns at the supply frequency and low-pass filtering
//! give `P = I1 e^{-j theta0}` and, with `-theta`, `N = conj(I2) e^{j theta0}`; so
//! `I2/I1 = conj(N)/P` whatever the angle's offset `theta0`.
//!
//! Suspect phase: shorted turns as they are (Tallam, Habetler, Harley, "Transient model for
//! induction machines with stator winding turn faults", IEEE Trans. Ind. Appl. 38(3),
//! 2002). A fraction `mu` of phase k's turns is shorted through a fault resistance `r_f`.
//! The shorted turns stay in the winding and link `mu` of its flux; the loop carries the
//! fault current `i_f`. In alpha-beta (amplitude-invariant, isolated neutral) with the
//! MMF current `i_s' = i_s - (2/3) mu i_f u_k`, `u_k = e^{j 2pi k/3}`:
//! ```text
//!   v_s = Rs i_s' + dpsi_s/dt                       (the symmetric machine in i_s')
//!   r_f i_f = mu Rs (i_k - i_f) + mu dlambda_k/dt    (the shorted loop)
//!   =>  Z_f I_f = V_k,   Z_f = Rs (1 - 2mu/3) + r_f/mu + j we mu Lls/3
//! ```
//! The machine itself stays balanced; the terminals draw the loop's current on top, whose
//! negative sequence is `I2 = (mu/3) I_f a^{-k}`; with `V_k = V1 a^{-k}` and `a^{-2k} = a^k`,
//! `I2/I1 = (mu/3)(Z1/Z_f) a^k` (k = 0, 1, 2 for a, b, c; `Z1 = Z(s)` the positive-sequence
//! impedance). `Z_f` is nearly resistive (its angle is below 3 degrees for up to 10 % of the
//! turns on the workspace's reference motors), so the angle of `I2/I1` minus `arg Z1` (the
//! power-factor angle) is a multiple of 120 degrees that names the phase
//! ([`asymmetry_correction_rad`]). The angle depends strongly on load (Z1 is mostly
//! inductive at no load, mostly resistive at full load), which is why the correction is
//! computed at the operating point. With voltages logged the correction needs no model:
//! `arg(I2/V1) = -arg Z_f + k 120 deg`.
//!
//! An earlier form of this module took a shorted turn as a winding that lost part of its
//! impedance, `dZ = -eps Z1`, which gives `I2/I1 = (eps/3)(Z1/Z2) a^k` with the
//! negative-sequence impedance `Z2 = Z(2 - s)`: the angle then differs by `arg Z2`
//! (60-80 degrees), enough to name the neighbouring phase. Recordings of real shorted turns
//! follow the loop above, not that form.
//!
//! The size: `3 |I2| = mu |I_f|`, the shorted loop's ampere-turns as a share of the
//! phase's ([`shorted_turns_mmf_ratio`]); the fraction of turns needs `r_f`, and a bolted
//! short (`r_f = 0`) gives its least value ([`min_shorted_fraction`]).
//!
//! A supply unbalance gives a negative sequence too; this analysis cannot tell the two
//! apart without the voltages or a healthy baseline (see the host's replay). A healthy
//! machine has an inherent asymmetry of a few per cent of `I2/I1`
//! ([`INHERENT_ASYMMETRY_RATIO`]).
//!
//! This is the workspace's one faulty-phase method ([`suspect_phase`]): the monitor, the
//! host's replay of current-only logs and the host's model-vs-measurement analysis all
//! name the phase with it; how probable each phase is, with the uncertainties of the
//! reference and of the healthy machine's own negative sequence, is [`phase_posterior`]'s
//! (`posterior`). Where the slip is not measured (a log with currents only),
//! [`slip_for_current`] estimates it from the current magnitude.

mod phasor_fit;
mod posterior;
mod zero;
pub use phasor_fit::{PhasorFit, ThreePhasors, MIN_SAMPLES as PHASOR_FIT_MIN_SAMPLES};
pub use posterior::{
    least_change, ln_no_short, ln_short, phase_posterior, PhasePosterior, ShortModel,
    LOOP_ANGLE_SD_DEG, NO_SHORT_PRIOR, SHORT_RATIO_MAX, SHORT_RATIO_MIN,
};
pub use zero::{
    phase_phasors, single_phase_gain, SinglePhaseGain, ZeroSequence, MAX_MISALIGNMENT_DEG,
};

use crate::error::ConfigError;
use crate::filter::{Svf, SvfState};
use crate::frames::{park, AlphaBeta, Phase, SinCos};
use crate::machine::MotorModel;
use micromath::F32Ext;
/// A phasor: a complex number `re + j im` (`num_complex::Complex32`).
pub use num_complex::Complex32;

/// Result of the negative-sequence analysis of the currents.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct NegativeSequence {
    /// |I2| / |I1|, dimensionless, >= 0.
    pub negative_sequence_ratio: f32,
    /// arg(I2/I1) [rad], in (-pi, pi].
    pub angle_rad: f32,
    /// The phase whose winding the asymmetry points at; None below the ratio threshold.
    /// The monitor names it from the winding's part ([`winding_asymmetry`]).
    pub suspect_phase: Option<Phase>,
    /// The winding's part `|I2w/I1|` (the supply's `V2/Z2` taken out) where the voltages'
    /// negative sequence is known (the monitor), else the whole ratio.
    pub winding_ratio: f32,
    /// The phase's confidence, 0..1 ([`phase_confidence`]); 0 without a phase.
    pub phase_confidence: f32,
}

/// `conj(N)/P`: a Park pair's negative-sequence phasor over the positive sequence's
/// (`P = pd + j pq` at +theta, `N = nd + j nq` at -theta; module docs), e.g. `I2/I1` or,
/// with the voltages' `N`, `V2/I1` [ohm]. 0 for `|P|` ~ 0.
pub fn over_positive(p: Complex32, n: Complex32) -> Complex32 {
    if !(p.norm_sqr() > 1e-12) {
        return Complex32::new(0.0, 0.0);
    }
    n.conj() / p
}

/// Streaming positive/negative-sequence separation.
#[derive(Debug, Clone, Copy)]
pub struct SequenceAnalyzer {
    filter: Svf,
    pd: SvfState,
    pq: SvfState,
    nd: SvfState,
    nq: SvfState,
}

impl SequenceAnalyzer {
    /// Critically damped second-order filters with corner `fc_hz` (default 2 Hz): the
    /// other sequence appears at twice the supply frequency and is attenuated by
    /// `(fc / 2f)^2` (1.6e-3 at 50 Hz), so a 10:1 positive sequence leaks less than 2 % into
    /// a negative-sequence reading.
    ///
    /// # Errors
    /// [`Svf::new`]'s checks of `fc_hz` [Hz] and the sample period `dt_s` [s].
    pub fn new(fc_hz: f32, dt_s: f32) -> Result<Self, ConfigError> {
        Ok(SequenceAnalyzer {
            filter: Svf::new(fc_hz, dt_s)?,
            pd: SvfState::default(),
            pq: SvfState::default(),
            nd: SvfState::default(),
            nq: SvfState::default(),
        })
    }

    /// Feeds the current vector and the sin/cos of an angle turning at the supply frequency;
    /// returns the new filtered sequences ([`Self::positive`], [`Self::negative`]).
    #[inline]
    pub fn update(&mut self, i: AlphaBeta, sc: SinCos) -> (Complex32, Complex32) {
        let p = park(i, sc);
        let n = park(i, sc.negated());
        let f = self.filter;
        f.update(&mut self.pd, p.d);
        f.update(&mut self.pq, p.q);
        f.update(&mut self.nd, n.d);
        f.update(&mut self.nq, n.q);
        (self.positive(), self.negative())
    }

    /// The filtered Park components `P = I1 e^{-j theta0}` (frame at +theta).
    pub fn positive(&self) -> Complex32 {
        Complex32::new(self.pd.y(), self.pq.y())
    }

    /// `conj(N) = I2 e^{-j theta0}` (same rotation as [`Self::positive`], so
    /// `I2/I1 = conj(N)/P`).
    pub fn negative(&self) -> Complex32 {
        Complex32::new(self.nd.y(), -self.nq.y())
    }

    /// |I1|, the positive-sequence current magnitude (phase peak) [A].
    pub fn positive_magnitude(&self) -> f32 {
        crate::math::fast_hypot(self.pd.y(), self.pq.y())
    }

    /// Ratio, angle and suspect phase, given the model correction `arg Z1` and the
    /// ratio below which no phase is named.
    pub fn result(&self, correction_rad: f32, min_ratio: f32) -> NegativeSequence {
        sequence_result(
            Complex32::new(self.pd.y(), self.pq.y()),
            Complex32::new(self.nd.y(), self.nq.y()),
            correction_rad,
            min_ratio,
        )
    }
}

/// Ratio, angle and suspect phase from the filtered Park components `P = pd + j pq` (frame
/// at +theta) and `N = nd + j nq` (at -theta): `I2/I1 = conj(N)/P` (module docs).
pub fn sequence_result(
    p: Complex32,
    n: Complex32,
    correction_rad: f32,
    min_ratio: f32,
) -> NegativeSequence {
    let p2 = p.norm_sqr();
    let n2 = n.norm_sqr();
    if !(p2 > 1e-12 && n2.is_finite()) {
        return NegativeSequence::default();
    }
    let ratio = crate::math::sqrt(n2 / p2);
    let angle = crate::frames::wrap_angle(F32Ext::atan2(-n.im, n.re) - F32Ext::atan2(p.im, p.re));
    let suspect = (ratio >= min_ratio).then(|| suspect_phase(angle, correction_rad));
    NegativeSequence {
        negative_sequence_ratio: ratio,
        angle_rad: angle,
        suspect_phase: suspect,
        winding_ratio: ratio,
        phase_confidence: if suspect.is_some() {
            phase_confidence(angle, correction_rad)
        } else {
            0.0
        },
    }
}

/// The phase a winding asymmetry sits in (module docs): the angle of `I2/I1` [rad] minus
/// the correction `arg Z1` ([`asymmetry_correction_rad`]) rounded to the nearest multiple
/// of 120 degrees, `k` thirds of a turn naming phase `k` (a, b, c). Assumes shorted turns
/// (a loop through a fault resistance), the common winding fault; any finite angles.
pub fn suspect_phase(i2_over_i1_angle_rad: f32, correction_rad: f32) -> Phase {
    let third = core::f32::consts::TAU / 3.0;
    let k = F32Ext::round(crate::frames::wrap_angle(i2_over_i1_angle_rad - correction_rad) / third)
        as i32;
    Phase::from_turns(k)
}

/// The winding's part of the negative sequence, with the supply's own unbalance taken out.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct WindingAsymmetry {
    /// `|I2w/I1|`: the winding's negative-sequence current over the positive sequence.
    pub ratio: f32,
    /// `|V2/Z2|/|I1|`: the part the supply's voltage unbalance drives (0 without voltages).
    pub supply_ratio: f32,
    /// `arg(I2w/I1)` [rad].
    pub angle_rad: f32,
    /// The shorted-turns phase; `None` when the winding's part is below what the supply's
    /// unbalance and the noise explain ([`winding_asymmetry`]).
    pub suspect_phase: Option<Phase>,
    /// The phase's confidence, 0..1 ([`phase_confidence`]); 0 without a phase.
    pub phase_confidence: f32,
}

/// Share of the supply-driven negative sequence that the model's negative-sequence
/// impedance may be wrong by (magnitude and angle): a winding part below this fraction of
/// `|V2/Z2|` is not evidence (nameplate parameters are commonly 10-30 % off the machine:
/// [`crate::isolation::NAMEPLATE_UNCERTAINTY`]).
pub const SUPPLY_PART_UNCERTAINTY: f32 = 0.3;

/// The workspace's one faulty-phase method on a supply that is itself unbalanced: the
/// negative-sequence current `I2` minus the part the supply's negative-sequence voltage
/// drives through the machine, `V2 / Z2` with `Z2 = Z(2 - s)` ([`equivalent_impedance`]);
/// what is left is the winding's (module docs: `I2w/I1 ~ (mu/3)(Z1/Z_f) a^k`), and
/// [`suspect_phase`] names its phase.
///
/// Inputs as complex numbers in the core's phasor convention, relative to the
/// positive-sequence current: `i2_over_i1 = I2/I1` and, where voltages are measured,
/// `v2_over_i1 = V2/I1` [ohm] (both from Park with one angle: [`SequenceAnalyzer`] gives
/// `I2/I1 = conj(N)/P`). `we` [rad/s], slip `s`.
///
/// "None" when `|I2w/I1|` is below `min_ratio` (noise) or below
/// [`SUPPLY_PART_UNCERTAINTY`] times `|V2/Z2|/|I1|` (what an imperfect `Z2` leaves of the
/// supply's part). Without voltages the supply is assumed balanced.
pub fn winding_asymmetry(
    i2_over_i1: Complex32,
    v2_over_i1: Option<Complex32>,
    m: &MotorModel,
    we: f32,
    s: f32,
    min_ratio: f32,
) -> WindingAsymmetry {
    let mut w = i2_over_i1;
    let mut supply_ratio = 0.0;
    if let Some(v2) = v2_over_i1 {
        let z2 = equivalent_impedance(m, we, 2.0 - s);
        if z2.norm_sqr() > 0.0 {
            let supply = v2 / z2;
            w -= supply;
            supply_ratio = crate::math::fast_hypot(supply.re, supply.im);
        }
    }
    let ratio = crate::math::fast_hypot(w.re, w.im);
    if !(ratio.is_finite() && supply_ratio.is_finite()) {
        return WindingAsymmetry::default();
    }
    let angle = F32Ext::atan2(w.im, w.re);
    let floor = crate::math::maxf(min_ratio, SUPPLY_PART_UNCERTAINTY * supply_ratio);
    let corr = asymmetry_correction_rad(m, we, s);
    let named = ratio >= floor;
    WindingAsymmetry {
        ratio,
        supply_ratio,
        angle_rad: angle,
        suspect_phase: named.then(|| suspect_phase(angle, corr)),
        phase_confidence: if named {
            phase_confidence(angle, corr)
        } else {
            0.0
        },
    }
}

/// The shorted loop's ampere-turns over the positive-sequence current, `mu |I_f| / |I1|`,
/// for a winding part `|I2w/I1| = ratio` (module docs: `3 |I2| = mu |I_f|`). Model-free;
/// `ratio` >= 0, result >= 0.
pub fn shorted_turns_mmf_ratio(ratio: f32) -> f32 {
    3.0 * ratio
}

/// The least fraction `mu` of one phase's turns shorted that draws `|I2w/I1| = ratio` at
/// supply `we` [rad/s] and slip `s`: a bolted short (`r_f = 0`, `Z_f ~ Rs`) in the module
/// docs' relation `|I2/I1| = (mu/3) |Z1| / |Z_f|`, so `mu >= 3 ratio Rs / |Z1|`. A fault
/// resistance means more turns for the same `I2`. 0 when `Z1` is not positive.
pub fn min_shorted_fraction(m: &MotorModel, we: f32, s: f32, ratio: f32) -> f32 {
    let z1 = equivalent_impedance(m, we, s);
    let z1n = crate::math::fast_hypot(z1.re, z1.im);
    if !(z1n > 0.0) {
        return 0.0;
    }
    3.0 * ratio * m.rs_ohm / z1n
}

/// The slip at which the equivalent circuit on a supply of peak phase voltage `v_peak` [V]
/// and angular frequency `we` [rad/s] draws the positive-sequence current magnitude
/// `i1_peak` [A] (phase peak): bisection on 1e-4..0.5 (40 steps, to 5e-13 of the range).
/// For logs without a speed column, where the slip that [`asymmetry_correction_rad`] needs
/// is not measured; a current below the no-load current gives about 1e-4 (no load), one
/// above the current at 50 % slip gives 0.5.
pub fn slip_for_current(m: &MotorModel, v_peak: f32, we: f32, i1_peak: f32) -> f32 {
    let (mut lo, mut hi) = (1e-4f32, 0.5f32);
    for _ in 0..40 {
        let mid = 0.5 * (lo + hi);
        let z = equivalent_impedance(m, we, mid);
        let i = v_peak / crate::math::fast_hypot(z.re, z.im);
        if i < i1_peak {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    0.5 * (lo + hi)
}

/// Impedance of the T-equivalent circuit per phase at slip `s` and supply `we` [rad/s]:
/// `Z = Rs + j we Lls + (j we Lm || (Rr/s + j we Llr))` [ohm].
/// `s` is kept at least 1e-4 in magnitude.
pub fn equivalent_impedance(m: &MotorModel, we: f32, s: f32) -> Complex32 {
    let s = if s.abs() < 1e-4 {
        1e-4f32.copysign(s)
    } else {
        s
    };
    let xm = we * m.lm_h;
    let (rr, xr) = (m.rr_ohm / s, we * (m.lr_h - m.lm_h));
    // (j xm)(rr + j xr) / (rr + j (xm + xr))
    let (nr, ni) = (-xm * xr, xm * rr);
    let (dr, di) = (rr, xm + xr);
    let den = dr * dr + di * di;
    let (pr, pi) = if den > 0.0 {
        ((nr * dr + ni * di) / den, (ni * dr - nr * di) / den)
    } else {
        (0.0, 0.0)
    };
    Complex32::new(m.rs_ohm + pr, we * (m.ls_h - m.lm_h) + pi)
}

/// `arg Z1 = arg Z(s)` [rad], the positive-sequence power-factor angle: the angle between a
/// shorted-turns negative-sequence current `I2/I1` and the `a^k` of the phase it sits in
/// (module docs: `I2/I1 = (mu/3)(Z1/Z_f) a^k` with a nearly resistive loop impedance
/// `Z_f`). Supply `we` [rad/s], slip `s` (kept at least 1e-4 in magnitude).
pub fn asymmetry_correction_rad(m: &MotorModel, we: f32, s: f32) -> f32 {
    let z1 = equivalent_impedance(m, we, s);
    F32Ext::atan2(z1.im, z1.re)
}

/// How far the angle `I2/I1` minus the correction lies inside its phase's 120-degree sector:
/// 1 on the sector's centre, 0 on its border with the next phase (`1 - |dev| / 60 deg`).
/// A reading near 0 names a phase by a hair. The board's measure (the monitor's
/// [`NegativeSequence::phase_confidence`]); the host's reports give a probability
/// instead ([`phase_posterior`]).
pub fn phase_confidence(i2_over_i1_angle_rad: f32, correction_rad: f32) -> f32 {
    let third = core::f32::consts::TAU / 3.0;
    let x = crate::frames::wrap_angle(i2_over_i1_angle_rad - correction_rad) / third;
    let dev = x - F32Ext::round(x);
    crate::math::maxf(0.0, 1.0 - 2.0 * F32Ext::abs(dev))
}

/// A healthy machine's own negative sequence, `|I2/I1|` from its winding and core
/// tolerances (a few per cent on real motors). Without voltages and without a healthy
/// baseline, a winding part below this is not judged: the phase it would name is the
/// machine's build, not a fault.
pub const INHERENT_ASYMMETRY_RATIO: f32 = 0.03;

#[cfg(test)]
mod tests {
    use super::*;
    use crate::frames::{clarke, Abc};
    use core::f32::consts::TAU;

    #[test]
    fn ratio_and_angle_of_a_known_unbalance() {
        // Phase currents with I1 = 10, I2 = 1 at +40 degrees relative to I1 (phasor convention
        // I2 = (Ia + a^2 Ib + a Ic)/3).
        let dt = 1e-4;
        let mut s = SequenceAnalyzer::new(2.0, dt).unwrap();
        let w = TAU * 50.0;
        let phi2 = 40f32.to_radians();
        for k in 0..40000 {
            let t = k as f32 * dt;
            let ph = |shift: f32, neg: bool| {
                if neg {
                    (w * t + phi2 - shift).cos()
                } else {
                    (w * t + shift).cos()
                }
            };
            // Positive sequence: a, b = a lagging 120, c = leading 120. Negative: b leads.
            let i = Abc {
                a: 10.0 * ph(0.0, false) + ph(0.0, true),
                b: 10.0 * ph(-TAU / 3.0, false) + ph(-TAU / 3.0, true),
                c: 10.0 * ph(TAU / 3.0, false) + ph(TAU / 3.0, true),
            };
            let theta = w * t + 0.3;
            s.update(
                clarke(i),
                SinCos {
                    sin: theta.sin(),
                    cos: theta.cos(),
                },
            );
        }
        let u = s.result(0.0, 0.01);
        assert!((u.negative_sequence_ratio - 0.1).abs() < 0.003, "{u:?}");
        assert!((u.angle_rad - phi2).abs() < 0.03, "{u:?}");
        assert_eq!(u.suspect_phase, Some(Phase::A));
    }

    #[test]
    fn correction_follows_the_equivalent_circuit() {
        let w = 2.0 * core::f32::consts::PI * 60.0;
        let m = crate::testing::motor_3hp();
        // No load: Z1 ~ Rs + j Xs is nearly inductive; Z2 ~ Rs + Rr/2 + j(Xls + Xlr).
        let z1 = equivalent_impedance(&m, w, 1e-4);
        assert!((z1.im - 26.884).abs() < 0.05 && z1.re < 0.6, "{z1:?}");
        let c0 = asymmetry_correction_rad(&m, w, 0.001);
        let c5 = asymmetry_correction_rad(&m, w, 0.05);
        // The correction falls with load as Z1 turns resistive.
        assert!(c0 > c5 + 0.3, "{c0} {c5}");
    }
}
