//! Per-phase sensor redundancy: the zero sequence of three measured phase signals, and
//! the one sensor whose gain error explains it.
//!
//! The three phase currents of a star-connected machine without a neutral conductor sum
//! to zero, whatever the machine's state: a shorted winding, a supply unbalance and every
//! parameter change leave the zero sequence `I0 = (Ia + Ib + Ic)/3` at zero. So do the
//! phase voltages measured against the machine's star point (or a balanced artificial
//! star). A gain error `k` on the sensor of phase `p` alone reads `k Xp` instead of `Xp`
//! and gives the measured set a zero sequence `I0 = (k - 1) Xp / 3`; with the measured
//! phase phasor `Xp_meas = k Xp`,
//!
//! `g_p = 3 I0 / Xp_meas = (k - 1) / k`, a **real** number,
//!
//! while for the two other phases `3 I0 / Xq_meas` is turned by about 120 degrees (their
//! phasors are). The phase whose `g` is nearest the real axis is the sensor's, and its
//! gain error is `k - 1 = g / (1 - g)`. The same error puts `(k - 1) Xp a^(2p) / 3` into the
//! negative sequence (`a = e^{j 2pi/3}`), which the winding-asymmetry analysis would
//! otherwise blame on a winding ([`SinglePhaseGain::corrected_negative`] takes it out).
//!
//! Phasors here use the convention of [`super::SequenceAnalyzer`]: all three carry the
//! same rotation `e^{-j theta0}`, `P = I1 e^{-j theta0}`, `conj(N) = I2 e^{-j theta0}` and
//! [`ZeroSequence::phasor`] `= I0 e^{-j theta0}`, so the phase phasors are
//! `Xa = I0 + I1 + I2`, `Xb = I0 + a^2 I1 + a I2`, `Xc = I0 + a I1 + a^2 I2`.
//!
//! Limits: a log whose third current is computed from the other two (two sensors) has no
//! zero sequence by construction, and a one-phase gain error then shows only as a
//! negative sequence; voltages measured against a supply neutral can carry the supply's
//! own zero sequence. Offsets are not gains: they are DC and do not reach the
//! fundamental-frequency phasors.

use super::Complex32;
use crate::error::ConfigError;
use crate::filter::{Svf, SvfState};
use crate::frames::{Abc, Phase, SinCos};

/// The streaming zero-sequence phasor of three phase signals, demodulated on the same
/// angle as a [`super::SequenceAnalyzer`] and low-passed by the same filters.
#[derive(Debug, Clone, Copy)]
pub struct ZeroSequence {
    filter: Svf,
    d: SvfState,
    q: SvfState,
}

impl ZeroSequence {
    /// Critically damped second-order filters with corner `fc_hz` (as
    /// [`super::SequenceAnalyzer::new`]; the zero sequence's image at `-theta` appears at
    /// twice the supply frequency and is attenuated by `(fc/2f)^2`).
    ///
    /// # Errors
    /// [`Svf::new`]'s checks of `fc_hz` [Hz] and the sample period `dt_s` [s].
    pub fn new(fc_hz: f32, dt_s: f32) -> Result<Self, ConfigError> {
        Ok(ZeroSequence {
            filter: Svf::new(fc_hz, dt_s)?,
            d: SvfState::default(),
            q: SvfState::default(),
        })
    }

    /// Feeds the three phase values and the sin/cos of the analysis angle; returns the new
    /// phasor ([`Self::phasor`]).
    #[inline]
    pub fn update(&mut self, x: Abc, sc: SinCos) -> Complex32 {
        // x0 e^{-j theta}, times 2: a phase signal Re(X e^{j theta}) demodulates to X/2.
        let x0 = (x.a + x.b + x.c) * (2.0 / 3.0);
        let f = self.filter;
        Complex32::new(
            f.update(&mut self.d, x0 * sc.cos),
            f.update(&mut self.q, -x0 * sc.sin),
        )
    }

    /// `I0 e^{-j theta0}` (module docs).
    pub fn phasor(&self) -> Complex32 {
        Complex32::new(self.d.y(), self.q.y())
    }
}

/// One phase sensor's gain error, found from the zero sequence (module docs).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SinglePhaseGain {
    /// The phase whose sensor reads wrong.
    pub phase: Phase,
    /// Its gain error `k - 1` (0.2: the sensor reads 20 % high).
    pub gain_error: f32,
    /// `|3 I0| / |I1|`, the evidence's size.
    pub zero_sequence_ratio: f32,
    /// How far `g_p` is from the real axis [deg] (0 for a pure gain error).
    pub misalignment_deg: f32,
}

/// Largest angle of `g_p` off the real axis still taken as one sensor's gain error [deg]:
/// the other phases are 120 degrees off; noise and a second, smaller error turn it a few.
pub const MAX_MISALIGNMENT_DEG: f32 = 20.0;

/// The operator `a = e^{j 2 pi/3}`.
const A: Complex32 = Complex32::new(-0.5, 0.866_025_4);
/// `a^2 = e^{-j 2 pi/3}`.
const A2: Complex32 = Complex32::new(-0.5, -0.866_025_4);

/// The measured phase phasors `[Xa, Xb, Xc]` from the sequence phasors `p = I1`,
/// `n = I2` and `z = I0` (all with the same rotation; module docs).
pub fn phase_phasors(p: Complex32, n: Complex32, z: Complex32) -> [Complex32; 3] {
    [z + p + n, z + A2 * p + A * n, z + A * p + A2 * n]
}

/// The one phase sensor whose gain error explains the zero sequence `z` of a set with
/// positive and negative sequences `p` and `n` ([`super::SequenceAnalyzer::positive`],
/// [`super::SequenceAnalyzer::negative`], [`ZeroSequence::phasor`]).
///
/// `None` when `|3 I0|/|I1|` is below `min_ratio` (give it the noise floor: 0.005 for 12-bit
/// sensors and a 2 Hz filter), when the nearest phase is more than
/// [`MAX_MISALIGNMENT_DEG`] off (not one sensor's gain: two sensors, a neutral conductor),
/// when the gain would not be positive, or on non-finite input.
pub fn single_phase_gain(
    p: Complex32,
    n: Complex32,
    z: Complex32,
    min_ratio: f32,
) -> Option<SinglePhaseGain> {
    let i1 = crate::math::fast_hypot(p.re, p.im);
    let z3 = 3.0 * crate::math::fast_hypot(z.re, z.im);
    if !(i1 > 1e-9 && z3.is_finite() && n.re.is_finite() && n.im.is_finite()) {
        return None;
    }
    let ratio = z3 / i1;
    if ratio < min_ratio {
        return None;
    }
    let x = phase_phasors(p, n, z);
    let mut best: Option<(Phase, f32, f32)> = None;
    for (phase, xp) in Phase::ALL.into_iter().zip(x) {
        let x2 = xp.norm_sqr();
        if !(x2 > 1e-18) {
            continue;
        }
        // g = 3 z / xp
        let g = Complex32::new(
            3.0 * (z.re * xp.re + z.im * xp.im) / x2,
            3.0 * (z.im * xp.re - z.re * xp.im) / x2,
        );
        let off = micromath::F32Ext::atan2(g.im.abs(), g.re.abs()).to_degrees();
        if best.is_none_or(|(_, _, o)| off < o) {
            best = Some((phase, g.re, off));
        }
    }
    let (phase, g, off) = best?;
    if off > MAX_MISALIGNMENT_DEG || g >= 1.0 {
        return None;
    }
    Some(SinglePhaseGain {
        phase,
        gain_error: g / (1.0 - g),
        zero_sequence_ratio: ratio,
        misalignment_deg: off,
    })
}

impl SinglePhaseGain {
    /// The negative sequence `n` (with its positive sequence `p` and zero sequence `z`)
    /// with this sensor's error taken out: phase `p`'s phasor divided by its gain before the
    /// sequences are formed again (module docs). Returns `n` unchanged on a zero gain.
    pub fn corrected_negative(&self, p: Complex32, n: Complex32, z: Complex32) -> Complex32 {
        let k = 1.0 + self.gain_error;
        if !(k > 0.0) {
            return n;
        }
        let mut x = phase_phasors(p, n, z);
        if let Some(xp) = x.get_mut(self.phase.index()) {
            *xp /= k;
        }
        // I2 = (Xa + a^2 Xb + a Xc) / 3
        (x[0] + A2 * x[1] + A * x[2]) / 3.0
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Sequences of a measured set: the true balanced (or unbalanced) phasors with one
    /// sensor's gain `k`.
    fn sequences(x: [Complex32; 3], phase: usize, k: f32) -> [Complex32; 3] {
        let mut m = x;
        m[phase] = x[phase] * k;
        [
            (m[0] + A * m[1] + A2 * m[2]) / 3.0,
            (m[0] + A2 * m[1] + A * m[2]) / 3.0,
            (m[0] + m[1] + m[2]) / 3.0,
        ]
    }

    fn balanced(amp: f32, phi: f32) -> [Complex32; 3] {
        let at = |a: f32| Complex32::new(amp * (phi + a).cos(), amp * (phi + a).sin());
        let t = core::f32::consts::TAU / 3.0;
        [at(0.0), at(-t), at(t)]
    }

    #[test]
    fn one_sensors_gain_is_found_in_every_phase_and_nothing_without_one() {
        for (phase, k) in [(0, 1.2), (1, 0.7), (2, 1.5), (1, 1.02)] {
            let [p, n, z] = sequences(balanced(5.0, 0.4), phase, k);
            let g = single_phase_gain(p, n, z, 0.005).expect("found"); // ok: test
            assert_eq!(g.phase.index(), phase);
            assert!((g.gain_error - (k - 1.0)).abs() < 1e-3, "{k}: {g:?}");
            // The correction takes the sensor's negative sequence out.
            let c = g.corrected_negative(p, n, z);
            assert!(crate::math::fast_hypot(c.re, c.im) < 1e-4 * 5.0, "{c:?}");
        }
        // A winding asymmetry or a supply unbalance: a negative sequence, and (three wires)
        // no zero sequence: nothing named.
        assert!(single_phase_gain(
            Complex32::new(5.0, 0.0),
            Complex32::new(0.3, 0.1),
            Complex32::new(0.0, 0.0),
            0.005
        )
        .is_none());
        // Two sensors off by opposite amounts: the zero sequence points nowhere near one
        // phase's axis.
        let mut x = balanced(5.0, 0.0);
        x[0] *= 1.1;
        let [p, n, z] = sequences(x, 1, 0.9);
        assert!(single_phase_gain(p, n, z, 0.005).is_none());
        // Non-finite input.
        assert!(single_phase_gain(Complex32::new(f32::NAN, 0.0), n, z, 0.005).is_none());
    }
}
