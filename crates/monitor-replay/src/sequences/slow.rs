//! The sequence analysis' slow filters on block means ([`SlowFilters`]): the 2 Hz
//! positive sequences of the currents and the voltages on the PLL's angle (the isolation's
//! steady point), the currents' mean square that normalises them for the PLL, and the
//! PLL's frequency low-passed at [`super::REFERENCE_FC_HZ`] (the least-squares reference's).
//!
//! The quantities move at a few hertz at most, so the filters need not run at the log's
//! rate: they are stepped once per block of an eighth of a supply period (the rotor
//! demodulator's blocks, [`crate::rotor::RotorFront`]; 21 samples at 10 kHz and 60 Hz) on
//! the block's means. The positive sequences' means come from the least-squares sums
//! ([`super::lanes::Demod`]): the block's mean of `x e^{-j theta_ref}` on the reference
//! angle, turned by the mean angle of the PLL less the reference over the block, is the
//! block's mean of the Park components `x e^{-j theta_pll}` where that difference holds
//! still within the block (the middle's difference is the mean of those at the last rows
//! of this block and of the one before); it moves by `(w_pll - w_ref) T`, 0.013 rad in a
//! block when the PLL runs 1 Hz off the reference (a run-up), which changes the mean by
//! `1 - 0.013^2/24`.
//!
//! What the block rate changes against filters stepped every sample: the block mean delays
//! the input by half a block (1 ms) and the outputs are held over a block (at most 2 ms
//! old), against the 2 Hz filters' own delay of `2/wc` = 160 ms; the block mean passes the
//! Park frame's `2f` image (a negative sequence) at `sinc(1/4)` = 0.90 and folds the `6f`
//! image of the 5th and 7th harmonics onto `2f`, where the 2 Hz filter passes
//! `(2 Hz/2f)^2` (3e-4 at 60 Hz) of it; the filters' semi-implicit Euler step at `wc T`
//! = 0.026 instead of 0.0013 moves their step response by about that share of its time
//! scale; steady values are the same. Rows with a bad current are held out (as before);
//! samples filled across a short gap count into the block's sequences (the Park
//! components of a sample turned back by the supply angle and taken on the PLL's angle
//! turned back as far are the row's own).

use super::lanes::Demod;
use monitor_core::filter::{Svf, SvfState};
use monitor_core::frames::AlphaBeta;
use monitor_core::ConfigError;

/// Corner of the sequence filters and the currents' normaliser [Hz] (the core's
/// `SequenceAnalyzer`'s).
const SEQUENCE_FC_HZ: f32 = 2.0;

/// The slow filters and their open block (module docs).
#[derive(Debug, Clone)]
pub(super) struct SlowFilters {
    /// The PLL's frequency summed over the block's good rows [rad/s], and the rows.
    w_sum: f32,
    rows: u32,
    /// The currents' squared magnitude summed (where the PLL locks to the currents).
    m2_sum: f32,
    n_m: u32,
    /// Samples filled in across short gaps, on the reference angle (module docs).
    filled: Demod,
    /// The 2 Hz filter (the sequences and the normaliser) and the reference's 1 Hz filter,
    /// both at the block rate.
    seq: Svf,
    reference: Svf,
    i: [SvfState; 2],
    v: [SvfState; 2],
    ms: SvfState,
    w: SvfState,
    /// `1/sqrt` of the filtered mean square (0 before the first current).
    k: f32,
}

impl SlowFilters {
    /// Filters stepped every `block_s` [s] for a supply of nominal angular frequency `w0`
    /// [rad/s]; the reference filter's corner `reference_fc_hz`. Errors: [`Svf::new`]'s.
    pub fn new(block_s: f64, w0: f32, reference_fc_hz: f32) -> Result<Self, ConfigError> {
        let block = block_s as f32;
        Ok(SlowFilters {
            w_sum: 0.0,
            rows: 0,
            m2_sum: 0.0,
            n_m: 0,
            filled: Demod::default(),
            seq: Svf::new(SEQUENCE_FC_HZ, block)?,
            reference: Svf::new(reference_fc_hz, block)?,
            i: [SvfState::default(); 2],
            v: [SvfState::default(); 2],
            ms: SvfState::default(),
            w: SvfState::at(w0),
            k: 0.0,
        })
    }

    /// The PLL's frequency low-passed [rad/s] (held over a block).
    #[inline]
    pub fn w_ref(&self) -> f32 {
        self.w.y()
    }

    /// The positive sequences `(d, q)` of the currents and of the voltages on the PLL's
    /// angle (held over a block).
    #[inline]
    pub fn positive(&self) -> ((f32, f32), (f32, f32)) {
        (
            (self.i[0].y(), self.i[1].y()),
            (self.v[0].y(), self.v[1].y()),
        )
    }

    /// Whether the normaliser has not started yet (no current seen).
    #[inline]
    pub fn normaliser_unset(&self) -> bool {
        self.ms.y() <= 0.0
    }

    /// The currents' normaliser for the PLL: `1/sqrt` of the current vector's filtered
    /// mean square, with `i` counted into it (the first current starts the filter on its
    /// own square).
    #[inline]
    pub fn normaliser(&mut self, i: AlphaBeta) -> f32 {
        let m2 = i.alpha * i.alpha + i.beta * i.beta;
        if self.normaliser_unset() {
            self.ms.set_y(m2);
            self.k = 1.0 / monitor_core::math::sqrt(m2.max(1e-12));
        }
        self.m2_sum += m2;
        self.n_m += 1;
        self.k
    }

    /// One good row: `w_pll` the PLL's frequency after it [rad/s].
    #[inline]
    pub fn row(&mut self, w_pll: f32) {
        self.w_sum += w_pll;
        self.rows += 1;
    }

    /// `m` samples filled in before a row whose vectors turned back by the reference angle
    /// are `zi`, `zv` (module docs).
    pub fn fill(&mut self, m: u32, zi: [f32; 2], zv: Option<[f32; 2]>) {
        let mf = m as f32;
        self.filled.add(&Demod {
            i: [zi[0] * mf, zi[1] * mf],
            v: zv.map_or([0.0; 2], |z| [z[0] * mf, z[1] * mf]),
            n_i: m,
            n_v: if zv.is_some() { m } else { 0 },
        });
    }

    /// Steps the filters on a block's means: `d` its sums on the reference angle, `phi`
    /// the PLL's angle less the reference angle in the block's middle [rad]. Returns true
    /// when the reference frequency moved (the block had a good row).
    pub fn step(&mut self, d: &Demod, phi: f32) -> bool {
        let mut d = *d;
        d.add(&std::mem::take(&mut self.filled));
        let (s, c) = phi.sin_cos();
        // x e^{-j theta_pll} = x e^{-j theta_ref} e^{-j phi}.
        let turn = |z: [f32; 2], n: u32| {
            let k = 1.0 / n as f32;
            ((z[0] * c + z[1] * s) * k, (z[1] * c - z[0] * s) * k)
        };
        if d.n_i > 0 {
            let (dd, q) = turn(d.i, d.n_i);
            self.seq.update(&mut self.i[0], dd);
            self.seq.update(&mut self.i[1], q);
        }
        if d.n_v > 0 {
            let (dd, q) = turn(d.v, d.n_v);
            self.seq.update(&mut self.v[0], dd);
            self.seq.update(&mut self.v[1], q);
        }
        if self.n_m > 0 {
            let y = self.seq.update(&mut self.ms, self.m2_sum / self.n_m as f32);
            self.k = 1.0 / monitor_core::math::sqrt(y.max(1e-12));
        }
        let moved = self.rows > 0;
        if moved {
            self.reference
                .update(&mut self.w, self.w_sum / self.rows as f32);
        }
        (self.w_sum, self.rows, self.m2_sum, self.n_m) = (0.0, 0, 0.0, 0);
        moved
    }
}
