//! The stage's accumulators over the rows whose cells are all good ([`Signals`]): the
//! clipping count ([`crate::log::clipping`]), the wiring check ([`super::wiring`]), the
//! phase-a current's zero crossings (the supply frequency) and the speed channel's unit
//! ([`super::speed_unit`]). None of them changes a row or decides anything before the end
//! of the read, so the good rows are held a block of [`BLOCK`] at a time, channel by
//! channel, and each accumulator runs through a block in one tight loop. Each sees the same
//! values in the same order as row by row, and the blocks are emptied before anything else
//! reaches an accumulator (a row with bad cells, a break in the sequence, the end of the
//! read): the results are the same, bit for bit.

use super::speed_unit::SpeedScale;
use super::time_base::CrossingCounter;
use super::wiring::WiringCheck;
use crate::log::clipping::ClipTracker;
use crate::log::{Column, Row};

/// Rows held before the accumulators run through them.
pub(super) const BLOCK: usize = 256;

/// The good rows held, channel by channel.
struct Held {
    len: usize,
    /// The rows held have voltages (bit 0), a speed (bit 1): every one or none, a change
    /// empties the block first.
    shape: u8,
    t: [f64; BLOCK],
    /// Voltages a, b, c, currents a, b, c.
    x: [[f64; BLOCK]; 6],
    wm: [f64; BLOCK],
}

/// Rows staged ([`Signals::stage`]), channel by channel.
pub(super) struct Staged<'a> {
    /// Their times [s].
    pub t: &'a [f64],
    /// Voltages a, b, c (not set without voltages), currents a, b, c.
    pub x: [&'a [f64]; 6],
    /// The speed, when the rows have one.
    pub wm: Option<&'a [f64]>,
    /// The rows have voltages.
    pub has_v: bool,
}

/// The channels a row has: voltages (bit 0), a speed (bit 1).
#[inline(always)]
fn shape_of(r: &Row) -> u8 {
    u8::from(r.v_abc.is_some()) | u8::from(r.wm_rad_s.is_some()) << 1
}

/// The accumulators and the block they have not seen yet; see the module documentation.
pub(super) struct Signals {
    held: Box<Held>,
    clips: ClipTracker,
    crossings: CrossingCounter,
    speed: SpeedScale,
    wiring: WiringCheck,
}

impl Signals {
    /// For a machine whose mechanical synchronous speed is `sync_rad_s`.
    pub(super) fn new(sync_rad_s: f64) -> Self {
        Signals {
            held: Box::new(Held {
                len: 0,
                shape: 0,
                t: [0.0; BLOCK],
                x: [[0.0; BLOCK]; 6],
                wm: [0.0; BLOCK],
            }),
            clips: ClipTracker::default(),
            crossings: CrossingCounter::default(),
            speed: SpeedScale::new(sync_rad_s),
            wiring: WiringCheck::default(),
        }
    }

    /// One row whose cells are all good, passed on at `t_s`.
    #[inline]
    pub(super) fn push(&mut self, r: &Row, t_s: f64) {
        let shape = shape_of(r);
        if self.held.len > 0 && self.held.shape != shape {
            self.flush();
        }
        let h = &mut *self.held;
        let k = h.len.min(BLOCK - 1);
        h.shape = shape;
        h.t[k] = t_s;
        if let Some(v) = r.v_abc {
            h.x[0][k] = v[0];
            h.x[1][k] = v[1];
            h.x[2][k] = v[2];
        }
        h.x[3][k] = r.i_abc[0];
        h.x[4][k] = r.i_abc[1];
        h.x[5][k] = r.i_abc[2];
        h.wm[k] = r.wm_rad_s.unwrap_or(0.0);
        h.len = k + 1;
        if h.len == BLOCK {
            self.flush();
        }
    }

    /// Stages the rows at the head of `rows` that have the shape of the first (voltages or
    /// not, a speed or not) and no encoder count, as many as the block has room for: their
    /// channels written behind the rows held, not yet held ([`Signals::take_staged`] holds
    /// them), for the stage to judge them channel by channel.
    pub(super) fn stage(&mut self, rows: &[Row]) -> Staged<'_> {
        let shape = rows.first().map_or(0, shape_of);
        if self.held.len > 0 && self.held.shape != shape {
            self.flush();
        }
        let h = &mut *self.held;
        let from = h.len.min(BLOCK - 1);
        let n = rows
            .iter()
            .take(BLOCK - from)
            .take_while(|r| shape_of(r) == shape && r.enc_count.is_none())
            .count();
        h.shape = shape;
        let rows = &rows[..n];
        let to = from + n;
        let [x0, x1, x2, x3, x4, x5] = &mut h.x;
        let (x0, x1, x2) = (&mut x0[from..to], &mut x1[from..to], &mut x2[from..to]);
        let (x3, x4, x5) = (&mut x3[from..to], &mut x4[from..to], &mut x5[from..to]);
        let (t, wm) = (&mut h.t[from..to], &mut h.wm[from..to]);
        for k in 0..n {
            let r = &rows[k];
            t[k] = r.t_s;
            if let Some(v) = r.v_abc {
                (x0[k], x1[k], x2[k]) = (v[0], v[1], v[2]);
            }
            (x3[k], x4[k], x5[k]) = (r.i_abc[0], r.i_abc[1], r.i_abc[2]);
            wm[k] = r.wm_rad_s.unwrap_or(0.0);
        }
        let x = |c: usize| &h.x[c][from..to];
        Staged {
            t: &h.t[from..to],
            x: [x(0), x(1), x(2), x(3), x(4), x(5)],
            wm: (shape & 2 != 0).then(|| &h.wm[from..to]),
            has_v: shape & 1 != 0,
        }
    }

    /// Holds the first `n` rows staged ([`Signals::stage`]): what [`Signals::push`] of
    /// each would have done.
    pub(super) fn take_staged(&mut self, n: usize) {
        let h = &mut *self.held;
        h.len = (h.len + n).min(BLOCK);
        if h.len == BLOCK {
            self.flush();
        }
    }

    /// Runs the accumulators through the rows held.
    #[inline(never)]
    pub(super) fn flush(&mut self) {
        let h = &mut *self.held;
        let n = std::mem::take(&mut h.len);
        if n == 0 {
            return;
        }
        let x = |c: usize| &h.x[c][..n];
        let v = (h.shape & 1 != 0).then(|| [x(0), x(1), x(2)]);
        let i = [x(3), x(4), x(5)];
        self.clips.push_block(v, i);
        self.crossings.push_all(&h.t[..n], i[0], 1.0);
        if h.shape & 2 != 0 {
            self.speed.push_all(&h.wm[..n]);
        }
        let w = (h.shape & 2 != 0).then(|| &h.wm[..n]);
        self.wiring.push_block(v, i, w);
    }

    /// A row with bad cells (`good(c)`: the cell of `c` is good): its good cells count for
    /// the clipping, and it breaks the wiring check's sequence.
    pub(super) fn bad_row(&mut self, r: &Row, good: impl Fn(Column) -> bool) {
        self.flush();
        self.clips.push(r, good);
        self.wiring.interrupt();
    }

    /// A break in the sequence of rows (a new segment).
    pub(super) fn interrupt(&mut self) {
        self.flush();
        self.wiring.interrupt();
    }

    /// Every row held counted: the accumulators, to read their results.
    pub(super) fn done(&mut self) -> (&ClipTracker, &CrossingCounter, &SpeedScale, &WiringCheck) {
        self.flush();
        (&self.clips, &self.crossings, &self.speed, &self.wiring)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A 50 Hz row at `t`, phase order `order` for the currents, speed `w`, voltages or not.
    fn row(t: f64, swapped: bool, v: bool, w: Option<f64>) -> Row {
        let th = std::f64::consts::TAU * 50.0 * t;
        let ph = |a: f64, k: f64| a * (th - k * std::f64::consts::TAU / 3.0).cos();
        let (b, c) = if swapped { (2.0, 1.0) } else { (1.0, 2.0) };
        Row {
            t_s: t,
            v_abc: v.then(|| [ph(300.0, 0.0), ph(300.0, 1.0), ph(300.0, 2.0)]),
            // Clipped at 9 A: flat tops.
            i_abc: [0.0, b, c].map(|k| ph(10.0, k).clamp(-9.0, 9.0)),
            wm_rad_s: w,
            enc_count: None,
            t_winding_c: None,
        }
    }

    /// The blocks give what the accumulators give row by row, across blocks, a change of
    /// channels and breaks.
    #[test]
    fn blocks_count_as_rows_one_by_one() {
        let mut s = Signals::new(157.0);
        let (mut clips, mut cc, mut speed, mut wiring) = (
            ClipTracker::default(),
            CrossingCounter::default(),
            SpeedScale::new(157.0),
            WiringCheck::default(),
        );
        for k in 0..5000 {
            let t = k as f64 * 1e-4;
            let r = row(t, k >= 3000, k % 1700 > 40, (k % 900 > 30).then_some(150.0));
            if k % 777 == 0 {
                s.interrupt();
                wiring.interrupt();
            }
            s.push(&r, t);
            clips.push(&r, |_| true);
            cc.push(t, r.i_abc[0], 1.0);
            if let Some(w) = r.wm_rad_s {
                speed.push(w);
            }
            wiring.push(&r);
        }
        let (c2, cc2, s2, w2) = s.done();
        assert_eq!(c2, &clips);
        assert_eq!(c2.clipped().len(), 3);
        assert_eq!(cc2.median_period(), cc.median_period());
        assert!(cc.median_period().is_some_and(|p| (p - 0.02).abs() < 1e-3));
        assert_eq!(s2.median_ratio(), speed.median_ratio());
        let ctx = super::super::wiring::WiringContext {
            omega_dt: Some(std::f64::consts::TAU * 50.0 * 1e-4),
            sync_rad_s: 157.0,
        };
        assert_eq!(w2.findings(&ctx), wiring.findings(&ctx));
        assert_eq!(format!("{w2:?}"), format!("{wiring:?}"));
    }
}
