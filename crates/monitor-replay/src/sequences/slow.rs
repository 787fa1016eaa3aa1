//! The sequence analysis' slow filters on block means ([`SlowFilters`]): the 2 Hz
//! positive sequences of the currents and the voltages on the PLL's angle (the isolation's
//! steady point), the PLL's frequency low-passed at the sequences' 2 Hz (the steady
//! point's supply frequency: the PLL's own frequency carries the `2f` ripple of a negative
//! sequence, sampled once per block) and at [`super::REFERENCE_FC_HZ`] (the least-squares
//! reference's).
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
//! What the block rate changes against filters stepped every sample: each filter makes
//! exactly what the per-sample filter makes of the block's samples replaced by their mean
//! ([`super::block_filter`]), and its value is given half a block ahead, so the response
//! and the delay are the per-sample filter's; what differs is the variation within a
//! block: the block mean passes the Park frame's `2f` image (a negative sequence) at
//! `sinc(1/4)` = 0.90 and folds the `6f` image of the 5th and 7th harmonics onto `2f`,
//! where the 2 Hz filter passes `(2 Hz/2f)^2` (3e-4 at 60 Hz) of it, and the outputs
//! between two blocks are the first-order prediction (within `(wc T)^2` = 7e-4 of a
//! transient's own size). Rows with a bad current are held out (as before);
//! samples filled across a short gap count into the block's sequences (the Park
//! components of a sample turned back by the supply angle and taken on the PLL's angle
//! turned back as far are the row's own).

use super::block_filter::{BlockState, BlockSvf};
use super::lanes::Demod;
use monitor_core::ConfigError;

/// Corner of the sequence filters and the currents' normaliser [Hz] (the core's
/// `SequenceAnalyzer`'s).
const SEQUENCE_FC_HZ: f32 = 2.0;

/// The slow filters and their open block (module docs).
#[derive(Debug, Clone)]
pub(super) struct SlowFilters {
    /// Samples filled in across short gaps, on the reference angle (module docs).
    filled: Demod,
    /// The 2 Hz filter (the sequences) and the reference's 1 Hz filter, both at the block
    /// rate.
    seq: BlockSvf,
    reference: BlockSvf,
    i: [BlockState; 2],
    v: [BlockState; 2],
    /// The PLL's frequency at 2 Hz and at the reference's corner.
    we: BlockState,
    w: BlockState,
}

impl SlowFilters {
    /// Filters for a log sampled every `dt_s` [s], stepped every `n` samples, for a supply
    /// of nominal angular frequency `w0` [rad/s]; the reference filter's corner
    /// `reference_fc_hz`. Errors: [`BlockSvf::new`]'s.
    pub fn new(dt_s: f64, n: u32, w0: f32, reference_fc_hz: f32) -> Result<Self, ConfigError> {
        Ok(SlowFilters {
            filled: Demod::default(),
            seq: BlockSvf::new(SEQUENCE_FC_HZ, dt_s, n)?,
            reference: BlockSvf::new(reference_fc_hz, dt_s, n)?,
            i: [BlockState::default(); 2],
            v: [BlockState::default(); 2],
            we: BlockState::at(w0),
            w: BlockState::at(w0),
        })
    }

    /// The PLL's frequency low-passed [rad/s] (held over a block).
    #[inline]
    pub fn w_ref(&self) -> f32 {
        self.w.value()
    }

    /// The PLL's frequency low-passed at 2 Hz [rad/s] (held over a block).
    #[inline]
    pub fn we(&self) -> f32 {
        self.we.value()
    }

    /// The positive sequences `(d, q)` of the currents and of the voltages on the PLL's
    /// angle (held over a block).
    #[inline]
    pub fn positive(&self) -> ((f32, f32), (f32, f32)) {
        (
            (self.i[0].value(), self.i[1].value()),
            (self.v[0].value(), self.v[1].value()),
        )
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
    /// the PLL's angle less the reference angle in the block's middle [rad], `w_pll` the
    /// PLL's frequency over the block [rad/s]. Returns true when the reference frequency
    /// moved (the block had a good row).
    pub fn step(&mut self, d: &Demod, phi: f32, w_pll: f32) -> bool {
        let moved = d.n_i > 0;
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
            self.seq.step(&mut self.i[0], dd);
            self.seq.step(&mut self.i[1], q);
        }
        if d.n_v > 0 {
            let (dd, q) = turn(d.v, d.n_v);
            self.seq.step(&mut self.v[0], dd);
            self.seq.step(&mut self.v[1], q);
        }
        if moved {
            self.seq.step(&mut self.we, w_pll);
            self.reference.step(&mut self.w, w_pll);
        }
        moved
    }
}
