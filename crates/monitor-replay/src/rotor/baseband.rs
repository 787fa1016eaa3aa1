//! The rotor finding's streaming half ([`RotorFront`]): the current space vector turned back
//! by the supply angle and averaged over blocks of about an eighth of a supply period, so
//! that the supply line sits at 0 Hz and the broken-bar sidebands at -/+ 2 s f of a
//! complex baseband sampled at about 8 f; the last [`super::MAX_STRETCH_S`] of it are kept
//! (bounded memory, a few MB whatever the log's length).
//!
//! It runs inside the sequence analysis' per-row step (`super::super::sequences`), on the
//! angle that analysis already turns (its least-squares reference `theta_ref`): the
//! analysis sums the phase currents times that angle's cos and sin for its least-squares
//! fit anyway, and hands each block the current vector's sum taken from those sums
//! ([`RotorFront::mark`], [`RotorFront::add`], [`RotorFront::close_at`]). The
//! reference turns at the PLL's frequency low-passed at 1 Hz, which follows part of the
//! `2 s f` wobble that large sidebands put into the current vector's angle where the PLL
//! locks to the currents; each block is therefore turned on by the reference's offset
//! from a fixed-frequency frame (`offset`, `theta_ref = w0 t + offset`), so that the
//! record is the current demodulated at the nominal frequency `w0` exactly, and the
//! analysis re-centres it on the supply's own mean frequency per stretch
//! (`super::spectrum`).

use crate::sampler::COUNTS_PER_REV;
#[cfg(test)]
use monitor_core::frames::{AlphaBeta, SinCos};
use monitor_io::log::{Row, ENC_COUNT_UNREADABLE};
use std::collections::VecDeque;

/// Blocks per supply period (at the nominal frequency): the baseband's rate is about 8 f,
/// so it holds -/+ 4 f around the line: the sidebands (within 0.25 f at 12 % slip), the
/// rotation-frequency pair `f -/+ f_r` of any pole count, and the negative sequence at
/// -2 f and the 5th and 7th harmonics at -/+ 6 f folded to -/+ 2 f, away from the line.
pub const BLOCKS_PER_PERIOD: f64 = 8.0;

/// One block of the baseband record.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Block {
    /// Time of the block's middle [s since the log's first row].
    pub t_s: f64,
    /// Mean of `i_alpha_beta e^{-j w0 t}` over the block's good samples [A, peak]: the
    /// current demodulated at the nominal supply frequency `w0`.
    pub z: [f32; 2],
    /// The supply's angular frequency over the block (the sequence analysis' reference)
    /// [rad/s, electrical].
    pub w_supply: f32,
    /// The mechanical speed over the block [rad/s] (from the encoder count where the log
    /// has one, else the mean of `wm_rad_s`); NaN without either.
    pub wm: f32,
}

/// The block being filled.
#[derive(Debug, Clone, Copy, Default)]
struct Open {
    /// Samples offered (good or not, and missing ones bridged over).
    offered: u32,
    /// Good current samples summed.
    used: u32,
    z: [f32; 2],
    t_first: f64,
    t_last: f64,
    offset_first: f64,
    offset_last: f64,
    wm_sum: f64,
    wm_n: u32,
}

/// The streaming demodulator and its record (module docs).
#[derive(Debug, Clone)]
pub struct RotorFront {
    /// Samples per block.
    per_block: u32,
    /// A block's length [s].
    block_s: f64,
    /// Blocks kept at most.
    max_blocks: usize,
    open: Open,
    /// The last good encoder count and its time (carried across blocks, so that the
    /// counts' quantisation cancels over a stretch).
    last_count: Option<(i64, f64)>,
    /// The encoder count and time where the open block's speed is measured from.
    block_count_from: Option<(i64, f64)>,
    blocks: VecDeque<Block>,
}

impl RotorFront {
    /// A demodulator for a log at `sample_rate_hz` of a supply of nominal `f_hz`, keeping
    /// the last `keep_s` seconds.
    pub fn new(sample_rate_hz: f64, f_hz: f64, keep_s: f64) -> Self {
        let per_block = (sample_rate_hz / (BLOCKS_PER_PERIOD * f_hz))
            .round()
            .max(1.0);
        let block_s = per_block / sample_rate_hz;
        RotorFront {
            per_block: per_block as u32,
            block_s,
            max_blocks: ((keep_s / block_s).ceil() as usize).max(16),
            open: Open::default(),
            last_count: None,
            block_count_from: None,
            blocks: VecDeque::new(),
        }
    }

    /// One row at `t` [s]: `i` its current vector (None for a bad current), `sc` the sin
    /// and cos of the reference angle at the row, `offset` the reference's offset from
    /// `w0 t` [rad] (module docs): [`RotorFront::mark`] and [`RotorFront::add`] of
    /// `i e^{-j theta}` (the tests' way in).
    #[cfg(test)]
    pub fn row(&mut self, i: Option<AlphaBeta>, sc: SinCos, t: f64, offset: f64, row: &Row) {
        self.mark(t, || offset, row);
        self.open.offset_last = offset;
        if let Some(i) = i {
            self.add(
                [
                    i.alpha * sc.cos + i.beta * sc.sin,
                    i.beta * sc.cos - i.alpha * sc.sin,
                ],
                1,
            );
        }
    }

    /// Counts one row at `t` [s] into the open block (good or not): its time, the row's
    /// speed, and on a block's first row the reference's offset from `w0 t` [rad]
    /// (`offset()`); its current is added with [`RotorFront::add`], and the block is
    /// closed with [`RotorFront::close_at`] (which takes the last row's offset).
    #[inline]
    pub fn mark(&mut self, t: f64, offset: impl FnOnce() -> f64, row: &Row) {
        let o = &mut self.open;
        if o.offered == 0 {
            o.t_first = t;
            o.offset_first = offset();
        }
        o.offered += 1;
        o.t_last = t;
        match row.enc_count {
            Some(c) if c != ENC_COUNT_UNREADABLE => {
                self.last_count = Some((c, t));
                if self.block_count_from.is_none() {
                    self.block_count_from = Some((c, t));
                }
            }
            _ => {
                if let Some(w) = row.wm_rad_s.filter(|w| w.is_finite()) {
                    o.wm_sum += w;
                    o.wm_n += 1;
                }
            }
        }
    }

    /// Adds `used` good samples' sum of the current vector turned back by the reference
    /// angle, `sum i e^{-j theta}` `[re, im]` [A], to the open block.
    #[inline]
    pub fn add(&mut self, z: [f32; 2], used: u32) {
        let o = &mut self.open;
        o.used += used;
        o.z[0] += z[0];
        o.z[1] += z[1];
    }

    /// Whether the open block is full (the next [`RotorFront::end_of_row`] closes it).
    #[inline]
    pub fn full(&self) -> bool {
        self.open.offered >= self.per_block
    }

    /// `m` samples missing from the stream (a gap the data-quality stage bridges): they
    /// count into the open block's length, so that the blocks stay on the time grid.
    pub fn skip(&mut self, m: u32) {
        if self.open.offered > 0 {
            self.open.offered += m;
        }
    }

    /// Closes the open block when it is full; `w_supply` the reference's frequency now
    /// [rad/s] (the tests' way out of a row; [`RotorFront::close_at`]).
    #[cfg(test)]
    pub fn end_of_row(&mut self, w_supply: f32) {
        if self.open.offered >= self.per_block {
            self.close(w_supply);
        }
    }

    /// Closes the open block when it is full ([`RotorFront::full`]): `w_supply` the
    /// reference's frequency now [rad/s], `offset_last` its offset at the block's last row
    /// [rad].
    pub fn close_at(&mut self, w_supply: f32, offset_last: f64) {
        if self.full() {
            self.open.offset_last = offset_last;
            self.close(w_supply);
        }
    }

    /// A gap the data-quality stage does not bridge: the open block is dropped, and the
    /// record's time jumps (the analysis never reads across it).
    pub fn break_off(&mut self) {
        self.open = Open::default();
        self.last_count = None;
        self.block_count_from = None;
    }

    /// Ends the open block: kept when at least half its samples were good.
    fn close(&mut self, w_supply: f32) {
        let o = std::mem::take(&mut self.open);
        let wm = self.block_speed(&o);
        if 2 * o.used < o.offered || o.used == 0 {
            return;
        }
        let n = o.used as f32;
        // Turned on by the reference's mean offset: the current demodulated at w0.
        let back = 0.5 * (o.offset_first + o.offset_last);
        let (s, c) = back.sin_cos();
        let (s, c) = (s as f32, c as f32);
        let (re, im) = (o.z[0] / n, o.z[1] / n);
        if self.blocks.len() >= self.max_blocks {
            self.blocks.pop_front();
        }
        self.blocks.push_back(Block {
            t_s: 0.5 * (o.t_first + o.t_last),
            z: [re * c - im * s, re * s + im * c],
            w_supply,
            wm,
        });
    }

    /// The mechanical speed over the block `o` [rad/s]: the encoder's count difference
    /// since the last block's end where the log has counts, else the speed column's mean;
    /// NaN without either.
    fn block_speed(&mut self, o: &Open) -> f32 {
        let from = self.block_count_from.take();
        if let (Some((c0, t0)), Some((c1, t1))) = (from, self.last_count) {
            // The next block measures from this one's last count.
            self.block_count_from = Some((c1, t1));
            if t1 > t0 {
                let turns = c1.wrapping_sub(c0) as f64 / f64::from(COUNTS_PER_REV);
                return (turns * std::f64::consts::TAU / (t1 - t0)) as f32;
            }
        }
        if o.wm_n > 0 {
            (o.wm_sum / f64::from(o.wm_n)) as f32
        } else {
            f32::NAN
        }
    }

    /// The record: the kept blocks, oldest first.
    pub fn blocks(&self) -> &VecDeque<Block> {
        &self.blocks
    }

    /// Samples per block.
    pub fn per_block(&self) -> u32 {
        self.per_block
    }

    /// A block's length [s].
    pub fn block_s(&self) -> f64 {
        self.block_s
    }
}
