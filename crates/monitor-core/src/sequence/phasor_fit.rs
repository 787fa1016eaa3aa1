//! Least-squares fundamental phasors of three phase signals over a window: sequences that
//! a large negative sequence cannot bend.
//!
//! Over a window of samples `x_p[n]` of phase `p` and a reference angle `theta[n]` that
//! turns at about the supply frequency (a PLL's, or `w t`), the fit
//!
//! ```text
//!   x_p[n] ~ A_p cos theta[n] + B_p sin theta[n] + D_p          (least squares)
//! ```
//!
//! gives the phase phasor `X_p = A_p - j B_p` (`x = Re(X e^{j theta})`) and the offset
//! `D_p`. The three fits share their regressors, so one 3x3 normal matrix
//! `G = sum [c^2 cs c; cs s^2 s; c s 1]` (`c = cos theta`, `s = sin theta`) serves every
//! phase. The symmetrical components follow (`a = e^{j 2 pi/3}`):
//! `I1 = (Xa + a Xb + a^2 Xc)/3`, `I2 = (Xa + a^2 Xb + a Xc)/3`, `I0 = (Xa + Xb + Xc)/3`,
//! all turned by the same `e^{-j theta0}` (the reference's offset), so `I2/I1` and
//! `I0/I1` do not depend on it, nor on a slow drift of the offset within the window (both
//! phasors are averaged by the same factor).
//!
//! Why a fit and not a filter: a filter on a Park frame separates the sequences only as
//! far as its corner lies below `2f`, and an angle locked to the current vector follows the
//! `2f` wobble that a large negative sequence puts into that vector's angle, so part of the
//! negative sequence goes into the angle (measured on real recordings of shorted turns: a
//! 15 % negative sequence read as 2.4 %). The fit's only assumption is that the reference
//! turns at the supply frequency within the window: a frequency error `dw` scales `I1` and
//! `I2` alike (by `sinc(dw T/2)` over a window `T`), and the ratio stays exact. Harmonics
//! (5th, 7th, ... and their aliases) are orthogonal to the regressors over whole periods.
//!
//! The sums are `f64` (a window of 10^5 samples keeps 1e-12 relative): on the Cortex-M4F
//! that is software floating point, so the board's per-sample path does not call this; the
//! host's replay does, per window of whole supply periods.

use super::Complex32;
use crate::frames::{Abc, SinCos};
use num_complex::Complex64;

/// Fewest samples a window needs before [`PhasorFit::solve`] gives phasors (three
/// unknowns per phase, and enough of a period to tell cos from sin).
pub const MIN_SAMPLES: u32 = 8;

/// The fit's sums over a window (see the module documentation). Feed samples with
/// [`PhasorFit::update`], read the phasors with [`PhasorFit::solve`], start the next
/// window with [`PhasorFit::reset`].
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct PhasorFit {
    /// Samples in the window.
    n: u32,
    /// sum c^2, sum s^2, sum c s, sum c, sum s.
    g: [f64; 5],
    /// Per phase: sum x c, sum x s, sum x.
    x: [[f64; 3]; 3],
}

/// The three phase phasors of a window (`x = Re(X e^{j theta})`), in the
/// reference's frame: every phasor carries the same rotation `e^{-j theta0}`.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct ThreePhasors {
    /// Phases a, b, c.
    pub phases: [Complex32; 3],
    /// Samples the fit used.
    pub samples: u32,
}

/// The operator `a = e^{j 2 pi/3}` (double precision: the sequences are formed in it).
const A: Complex64 = Complex64::new(-0.5, 0.866_025_403_784_438_6);
/// `a^2 = e^{-j 2 pi/3}`.
const A2: Complex64 = Complex64::new(-0.5, -0.866_025_403_784_438_6);
/// 1.
const ONE: Complex64 = Complex64::new(1.0, 0.0);

fn c64(x: Complex32) -> Complex64 {
    Complex64::new(f64::from(x.re), f64::from(x.im))
}

/// `(x + u y + v z)/3` in single precision.
fn combine(x: Complex64, u: Complex64, y: Complex64, v: Complex64, z: Complex64) -> Complex32 {
    let s = (x + u * y + v * z) / 3.0;
    Complex32::new(s.re as f32, s.im as f32)
}

impl ThreePhasors {
    /// The positive-sequence phasor `I1 e^{-j theta0} = (Xa + a Xb + a^2 Xc)/3` (as
    /// [`super::SequenceAnalyzer::positive`]).
    pub fn positive(&self) -> Complex32 {
        let [a, b, c] = self.phases.map(c64);
        combine(a, A, b, A2, c)
    }

    /// The negative-sequence phasor `I2 e^{-j theta0} = (Xa + a^2 Xb + a Xc)/3` (as
    /// [`super::SequenceAnalyzer::negative`]: `I2/I1 = negative / positive`).
    pub fn negative(&self) -> Complex32 {
        let [a, b, c] = self.phases.map(c64);
        combine(a, A2, b, A, c)
    }

    /// The zero-sequence phasor `I0 e^{-j theta0} = (Xa + Xb + Xc)/3` (as
    /// [`super::ZeroSequence::phasor`]).
    pub fn zero(&self) -> Complex32 {
        let [a, b, c] = self.phases.map(c64);
        combine(a, ONE, b, ONE, c)
    }
}

impl PhasorFit {
    /// An empty window.
    pub fn new() -> Self {
        Self::default()
    }

    /// A window's fit from sums formed elsewhere (a host that sums blocks of samples in
    /// its own way and adds the blocks up): `n` samples, `g` = `[sum c^2, sum s^2, sum c s,
    /// sum c, sum s]`, and per phase a, b, c `x[p]` = `[sum x_p c, sum x_p s, sum x_p]`
    /// (module docs). The same fit as [`PhasorFit::update`] on the samples, up to rounding.
    pub fn from_sums(n: u32, g: [f64; 5], x: [[f64; 3]; 3]) -> Self {
        PhasorFit { n, g, x }
    }

    /// Samples in the window so far.
    pub fn samples(&self) -> u32 {
        self.n
    }

    /// Empties the window.
    pub fn reset(&mut self) {
        *self = Self::default();
    }

    /// Adds one sample of the three phases `x` at the reference angle whose sin/cos is
    /// `sc`. A sample with a non-finite value is left out (the caller holds bad samples out
    /// and counts them).
    #[inline]
    pub fn update(&mut self, sc: SinCos, x: Abc) {
        let (c, s) = (f64::from(sc.cos), f64::from(sc.sin));
        let v = [f64::from(x.a), f64::from(x.b), f64::from(x.c)];
        if !(c.is_finite() && s.is_finite() && v.iter().all(|x| x.is_finite())) {
            return;
        }
        self.n = self.n.saturating_add(1);
        let g = &mut self.g;
        g[0] += c * c;
        g[1] += s * s;
        g[2] += c * s;
        g[3] += c;
        g[4] += s;
        for (sums, x) in self.x.iter_mut().zip(v) {
            sums[0] += x * c;
            sums[1] += x * s;
            sums[2] += x;
        }
    }

    /// The phase phasors of the window: the solution of the normal equations (Cramer's rule
    /// on the 3x3 matrix of the module documentation). `None` with fewer than
    /// [`MIN_SAMPLES`] samples, or when the reference did not turn enough within the window
    /// for cos and sin to be told apart (the matrix' determinant below 1e-6 of `n^3`).
    pub fn solve(&self) -> Option<ThreePhasors> {
        if self.n < MIN_SAMPLES {
            return None;
        }
        let n = f64::from(self.n);
        let [cc, ss, cs, c, s] = self.g;
        // G = [[cc, cs, c], [cs, ss, s], [c, s, n]], symmetric.
        let det = cc * (ss * n - s * s) - cs * (cs * n - s * c) + c * (cs * s - ss * c);
        if !(det.is_finite() && det > 1e-6 * n * n * n) {
            return None;
        }
        // The first two rows of G^-1 (the offset's row is not needed): cofactors / det.
        let i00 = (ss * n - s * s) / det;
        let i01 = -(cs * n - c * s) / det;
        let i02 = (cs * s - ss * c) / det;
        let i11 = (cc * n - c * c) / det;
        let i12 = -(cc * s - cs * c) / det;
        let phases = self.x.map(|[xc, xs, x]| {
            let a = i00 * xc + i01 * xs + i02 * x;
            let b = i01 * xc + i11 * xs + i12 * x;
            Complex32::new(a as f32, -b as f32)
        });
        Some(ThreePhasors {
            phases,
            samples: self.n,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use core::f64::consts::TAU;

    /// Three phase signals with positive, negative and zero sequences, harmonics and
    /// offsets, sampled at `fs` for `n` samples with the reference at `f_ref` (the signal
    /// at `f`).
    fn fit(f: f64, f_ref: f64, fs: f64, n: usize, i2: (f64, f64)) -> ThreePhasors {
        let mut p = PhasorFit::new();
        for k in 0..n {
            let t = k as f64 / fs;
            let w = TAU * f * t;
            let ph = |shift: f64| {
                // I1 = 10 at 0, I2 = |i2.0| at i2.1 rad (b leads in the negative sequence),
                // I0 = 0.5 at 1 rad, a 7 % fifth harmonic, an offset.
                10.0 * (w - shift).cos()
                    + i2.0 * (w + i2.1 + shift).cos()
                    + 0.5 * (w + 1.0).cos()
                    + 0.7 * (5.0 * (w - shift)).cos()
                    + 0.3
            };
            let x = Abc {
                a: ph(0.0) as f32,
                b: ph(TAU / 3.0) as f32,
                c: ph(-TAU / 3.0) as f32,
            };
            let th = TAU * f_ref * t + 0.4;
            p.update(
                SinCos {
                    sin: th.sin() as f32,
                    cos: th.cos() as f32,
                },
                x,
            );
        }
        p.solve().unwrap()
    }

    fn ratio(ph: &ThreePhasors) -> (f64, f64) {
        let r = c64(ph.negative()) / c64(ph.positive());
        (r.re, r.im)
    }

    #[test]
    fn a_thirty_percent_negative_sequence_is_read_exactly() {
        // Whole periods and a fraction of one, at 1 and 10 kHz: |I2/I1| = 0.3 at 50 deg.
        // Over whole periods the 7 % fifth harmonic is orthogonal to the regressors; over
        // 7.4 periods it leaks 0.1 % of the ratio.
        for (fs, n, tol) in [
            (1000.0, 1000, 1e-5),
            (1000.0, 167, 5e-4),
            (10_000.0, 1234, 5e-4),
        ] {
            let ph = fit(60.0, 60.0, fs, n, (3.0, 50f64.to_radians()));
            let r = ratio(&ph);
            let (m, a) = (r.0.hypot(r.1), r.1.atan2(r.0).to_degrees());
            assert!((m - 0.3).abs() < tol, "fs {fs} n {n}: {m}");
            assert!((a - 50.0).abs() < 0.2, "fs {fs} n {n}: {a}");
            let z = c64(ph.zero());
            assert!((z.re.hypot(z.im) - 0.5).abs() < 2e-4, "{z:?}");
        }
    }

    #[test]
    fn the_sums_given_directly_give_the_same_fit() {
        // Two halves of a window summed apart and added: the fit of the whole window.
        let (mut first, mut second, mut whole) =
            (PhasorFit::new(), PhasorFit::new(), PhasorFit::new());
        for k in 0..400 {
            let th = TAU * 60.0 * f64::from(k) / 4000.0;
            let sc = SinCos {
                sin: th.sin() as f32,
                cos: th.cos() as f32,
            };
            let x = Abc {
                a: (3.0 * th.cos() + 0.2) as f32,
                b: (3.0 * (th - TAU / 3.0).cos()) as f32,
                c: (2.5 * (th + TAU / 3.0).cos()) as f32,
            };
            whole.update(sc, x);
            if k < 150 {
                first.update(sc, x)
            } else {
                second.update(sc, x)
            }
        }
        let add = |a: [f64; 3], b: [f64; 3]| [a[0] + b[0], a[1] + b[1], a[2] + b[2]];
        let g: [f64; 5] = core::array::from_fn(|k| first.g[k] + second.g[k]);
        let x = core::array::from_fn(|p| add(first.x[p], second.x[p]));
        let joined = PhasorFit::from_sums(first.n + second.n, g, x)
            .solve()
            .unwrap();
        let direct = whole.solve().unwrap();
        assert_eq!(joined.samples, 400);
        let norm = |z: Complex32| f64::from(z.re).hypot(f64::from(z.im));
        for (a, b) in joined.phases.iter().zip(direct.phases) {
            assert!(norm(a - b) < 1e-5, "{a} {b}");
        }
        // Phase c is 5/6 of a and b: the fit sees it.
        assert!((norm(direct.phases[2]) / norm(direct.phases[1]) - 2.5 / 3.0).abs() < 1e-4);
    }

    #[test]
    fn a_reference_off_the_supply_frequency_keeps_the_ratio() {
        // 0.2 Hz off over 10 periods: both phasors shrink alike, the ratio stays.
        let ph = fit(50.2, 50.0, 5000.0, 1000, (2.0, -100f64.to_radians()));
        let r = ratio(&ph);
        assert!((r.0.hypot(r.1) - 0.2).abs() < 2e-3, "{r:?}");
    }

    #[test]
    fn too_few_samples_or_a_still_reference_give_nothing() {
        let mut p = PhasorFit::new();
        for _ in 0..100 {
            p.update(
                SinCos::default(),
                Abc {
                    a: 1.0,
                    b: 2.0,
                    c: 3.0,
                },
            );
        }
        assert_eq!(p.solve(), None);
        p.reset();
        assert_eq!(p.samples(), 0);
        p.update(
            SinCos::default(),
            Abc {
                a: f32::NAN,
                b: 0.0,
                c: 0.0,
            },
        );
        assert_eq!(p.samples(), 0);
        assert_eq!(p.solve(), None);
    }
}
