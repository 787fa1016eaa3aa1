//! The least-squares window's sums ([`FitSums`]): per sample in single precision, four
//! lanes at a time, over a short block; the blocks added up in double precision.
//!
//! [`PhasorFit`]'s sums are double precision because a window holds up to 10^5 samples;
//! a sample's products need not be. Each row adds `[x_a, x_b, x_c, 1]` times `cos`, times
//! `sin` and alone for the currents (the fourth lane gives `sum c`, `sum s` and the count),
//! the same for the voltages, and `[c^2, s^2, c s]`: seven four-lane products and sums,
//! where the double-precision update was 2 x 14 scalar ones. The blocks are at most a few
//! tens of samples (the slow filters' block, [`super::slow::BLOCK_S`], and every window's
//! end): a block's sum is within about 1e-7 of its own size, and the window's phasors
//! (single precision) move by a few 1e-7 relative. The currents' and the voltages' fits
//! share the regressors' sums: the voltages' fit is used only when every sample with a
//! good current had good voltages ([`super::SequenceFront`]).
//!
//! Each block's sums also give the current and voltage vectors turned back by the
//! reference angle, `sum x e^{-j theta}` ([`Demod`]: the Clarke transform of the phases'
//! sums), which the rotor's demodulator and the slow filters read: no further product per
//! row.

use monitor_core::frames::SinCos;
use monitor_core::sequence::PhasorFit;

/// A block's current and voltage vectors turned back by the reference angle and summed,
/// `sum (x_alpha + j x_beta) e^{-j theta}` `[re, im]`, and the samples in each.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub(super) struct Demod {
    pub i: [f32; 2],
    pub v: [f32; 2],
    pub n_i: u32,
    pub n_v: u32,
}

impl Demod {
    /// Adds `o`'s sums and samples.
    pub fn add(&mut self, o: &Demod) {
        for k in 0..2 {
            self.i[k] += o.i[k];
            self.v[k] += o.v[k];
        }
        self.n_i += o.n_i;
        self.n_v += o.n_v;
    }

    /// The sums of the phases' `sum x_p c` (`xc`) and `sum x_p s` (`xs`) turned into
    /// `sum (x_alpha + j x_beta) e^{-j theta}` (the amplitude-invariant Clarke transform).
    fn of(xc: &[f32; 4], xs: &[f32; 4]) -> [f32; 2] {
        const THIRD: f32 = 1.0 / 3.0;
        let inv_sqrt3 = 0.577_350_26_f32;
        let ac = (2.0 * xc[0] - xc[1] - xc[2]) * THIRD;
        let as_ = (2.0 * xs[0] - xs[1] - xs[2]) * THIRD;
        let bc = (xc[1] - xc[2]) * inv_sqrt3;
        let bs = (xs[1] - xs[2]) * inv_sqrt3;
        [ac + bs, bc - as_]
    }
}

/// One block's sums in single precision (module docs).
#[derive(Debug, Clone, Copy, Default)]
struct LaneBlock {
    /// `sum [x_a, x_b, x_c, 1] c`, `... s` and `sum [x_a, x_b, x_c, 1]` of the currents.
    ic: [f32; 4],
    is: [f32; 4],
    i: [f32; 4],
    /// The same of the voltages (the fourth lane counts the samples with good voltages).
    vc: [f32; 4],
    vs: [f32; 4],
    v: [f32; 4],
    /// `sum [c^2, s^2, c s, 0]`.
    g: [f32; 4],
}

/// A least-squares window's sums (module docs): the open block and the window's totals.
#[derive(Debug, Clone, Copy, Default)]
pub(super) struct FitSums {
    block: LaneBlock,
    /// Samples in the window's closed blocks.
    n: u32,
    /// `[sum c^2, sum s^2, sum c s, sum c, sum s]` ([`PhasorFit::from_sums`]).
    g: [f64; 5],
    /// Per phase `[sum x c, sum x s, sum x]` of the currents and of the voltages.
    x_i: [[f64; 3]; 3],
    x_v: [[f64; 3]; 3],
}

impl FitSums {
    /// Adds one sample: `sc` the reference's sin/cos, `i` and `v` the phase currents and
    /// voltages `[a, b, c, 1]` (`v` where good).
    #[inline]
    // Seven arrays indexed alike, lane by lane: the form the vectoriser makes four-lane
    // products and sums of.
    #[allow(clippy::needless_range_loop)]
    pub fn add(&mut self, sc: SinCos, i: [f32; 4], v: Option<[f32; 4]>) {
        let (c, s) = (sc.cos, sc.sin);
        let b = &mut self.block;
        for k in 0..4 {
            b.ic[k] += i[k] * c;
            b.is[k] += i[k] * s;
            b.i[k] += i[k];
        }
        let (gx, gy) = ([c, s, c, 0.0], [c, s, s, 0.0]);
        for k in 0..4 {
            b.g[k] += gx[k] * gy[k];
        }
        if let Some(v) = v {
            for k in 0..4 {
                b.vc[k] += v[k] * c;
                b.vs[k] += v[k] * s;
                b.v[k] += v[k];
            }
        }
    }

    /// Adds the open block to the window's sums and returns its vectors on the reference
    /// angle. A block with a sum that is not finite (a reference angle gone bad) is left
    /// out, as [`PhasorFit::update`] leaves out such a sample.
    pub fn flush(&mut self) -> Demod {
        let b = std::mem::take(&mut self.block);
        let n = b.i[3];
        // Every sum finite: `x * 0` is 0 for a finite `x` and NaN otherwise, so the lanes'
        // totals of those are all 0 exactly when no sum is NaN or infinite (four lanes at
        // once instead of 28 tests).
        let mut zero = [0.0f32; 4];
        for x in [b.ic, b.is, b.i, b.vc, b.vs, b.v, b.g] {
            for (z, x) in zero.iter_mut().zip(x) {
                *z += x * 0.0;
            }
        }
        if n == 0.0 || zero != [0.0; 4] {
            return Demod::default();
        }
        self.n += n as u32;
        let d = f64::from;
        for (k, x) in [d(b.g[0]), d(b.g[1]), d(b.g[2]), d(b.ic[3]), d(b.is[3])]
            .into_iter()
            .enumerate()
        {
            self.g[k] += x;
        }
        for p in 0..3 {
            for (k, x) in [b.ic[p], b.is[p], b.i[p]].into_iter().enumerate() {
                self.x_i[p][k] += d(x);
            }
            for (k, x) in [b.vc[p], b.vs[p], b.v[p]].into_iter().enumerate() {
                self.x_v[p][k] += d(x);
            }
        }
        Demod {
            i: Demod::of(&b.ic, &b.is),
            v: Demod::of(&b.vc, &b.vs),
            n_i: n as u32,
            n_v: b.v[3] as u32,
        }
    }

    /// The window's fits so far (the open block flushed first; its vectors returned).
    pub fn fits(&mut self) -> (PhasorFit, PhasorFit, Demod) {
        let d = self.flush();
        (
            PhasorFit::from_sums(self.n, self.g, self.x_i),
            PhasorFit::from_sums(self.n, self.g, self.x_v),
            d,
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use monitor_core::frames::Abc;

    /// Against the double-precision fit sample by sample: a window of 1667 samples at
    /// 10 kHz with 5 % negative sequence, a 7 % fifth harmonic and offsets, blocks of 10
    /// and one of 7 at the end.
    #[test]
    fn gives_the_double_precision_fit_within_1e_6() {
        let (mut sums, mut fit_i, mut fit_v) =
            (FitSums::default(), PhasorFit::new(), PhasorFit::new());
        let tau = std::f64::consts::TAU;
        for k in 0..1667u32 {
            let th = tau * 60.0 * f64::from(k) / 1e4;
            let sc = SinCos {
                sin: th.sin() as f32,
                cos: th.cos() as f32,
            };
            let ph = |amp: f64, shift: f64, neg: f64| {
                (amp * (th - shift).cos()
                    + neg * (th + shift + 0.7).cos()
                    + 0.07 * amp * (5.0 * (th - shift)).cos()
                    + 0.1) as f32
            };
            let i = [
                ph(10.0, 0.0, 0.5),
                ph(10.0, tau / 3.0, 0.5),
                ph(10.0, -tau / 3.0, 0.5),
            ];
            let v = [
                ph(320.0, 0.2, 3.0),
                ph(320.0, 0.2 + tau / 3.0, 3.0),
                ph(320.0, 0.2 - tau / 3.0, 3.0),
            ];
            sums.add(sc, [i[0], i[1], i[2], 1.0], Some([v[0], v[1], v[2], 1.0]));
            if k % 10 == 9 {
                let d = sums.flush();
                assert_eq!((d.n_i, d.n_v), (10, 10));
            }
            fit_i.update(
                sc,
                Abc {
                    a: i[0],
                    b: i[1],
                    c: i[2],
                },
            );
            fit_v.update(
                sc,
                Abc {
                    a: v[0],
                    b: v[1],
                    c: v[2],
                },
            );
        }
        let (si, sv, _) = sums.fits();
        // |I2/I1| 0.5/10, |V2/V1| 3/320.
        for (a, b, ratio) in [(si, fit_i, 0.05), (sv, fit_v, 3.0 / 320.0)] {
            let (a, b) = (a.solve().unwrap(), b.solve().unwrap());
            assert_eq!(a.samples, 1667);
            let scale = b.positive().norm();
            for (x, y) in a.phases.iter().zip(b.phases) {
                assert!((x - y).norm() < 1e-6 * scale, "{x} {y}");
            }
            let (na, nb) = (a.negative() / a.positive(), b.negative() / b.positive());
            assert!((na - nb).norm() < 1e-6, "{na} {nb}");
            assert!((nb.norm() - ratio).abs() < 2e-3, "{nb}");
        }
    }

    /// The block's vectors on the reference angle against `(alpha + j beta) e^{-j theta}`
    /// summed sample by sample in double precision.
    #[test]
    fn the_blocks_vectors_are_the_clarke_transform_turned_back() {
        let mut sums = FitSums::default();
        let (mut zi, mut zv) = ([0.0f64; 2], [0.0f64; 2]);
        let tau = std::f64::consts::TAU;
        for k in 0..21u32 {
            let th = 0.3 + tau * 60.0 * f64::from(k) / 1e4;
            let ph = |amp: f64, shift: f64| (amp * (th + 0.2 - shift).cos() + 0.4) as f32;
            let i = [ph(10.0, 0.0), ph(9.0, tau / 3.0), ph(11.0, -tau / 3.0)];
            let sc = SinCos {
                sin: th.sin() as f32,
                cos: th.cos() as f32,
            };
            let v = (k % 3 != 0).then_some([2.0 * i[0], 2.0 * i[1], 2.0 * i[2], 1.0]);
            sums.add(sc, [i[0], i[1], i[2], 1.0], v);
            let x = i.map(f64::from);
            let (a, b) = (
                (2.0 * x[0] - x[1] - x[2]) / 3.0,
                (x[1] - x[2]) / 3f64.sqrt(),
            );
            let (c, s) = (f64::from(sc.cos), f64::from(sc.sin));
            let z = [a * c + b * s, b * c - a * s];
            for j in 0..2 {
                zi[j] += z[j];
                if v.is_some() {
                    zv[j] += 2.0 * z[j];
                }
            }
        }
        let d = sums.flush();
        assert_eq!((d.n_i, d.n_v), (21, 14));
        for j in 0..2 {
            assert!((f64::from(d.i[j]) - zi[j]).abs() < 1e-4, "{d:?} {zi:?}");
            assert!((f64::from(d.v[j]) - zv[j]).abs() < 2e-4, "{d:?} {zv:?}");
        }
        // Not trivially small: about 10 A per sample.
        assert!(zi[0].hypot(zi[1]) > 150.0, "{zi:?}");
    }
}
