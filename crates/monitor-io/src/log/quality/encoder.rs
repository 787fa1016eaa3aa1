//! The encoder count in the data-quality stage ([`EncoderTrack`]): counter wraps undone,
//! unreadable cells and jumps no shaft can make marked bad, a counter that was re-zeroed
//! followed.
//!
//! A DAQ's counter channel wraps at its width (16, 24 or 32 bits; 64 bits wrap in the
//! readers' integer arithmetic) and can be re-zeroed when the acquisition restarts. A
//! damaged file holds values that are no count at all. The count between two rows can
//! move by at most
//!
//! `N_max = K * w_max * dt * C / (2 pi) + 2`
//!
//! counts, with `w_max` the largest mechanical speed of the parameter file's sensor range
//! [rad/s], `dt` the time since the last good count [s], `C` the counts per revolution the
//! replay assumes ([`COUNTS_PER_REV`]) and a margin `K` = [`STEP_MARGIN`] for encoders
//! finer than `C`. A step beyond `N_max` that is within `N_max` of a whole wrap `±2^k` is a
//! wrap and is undone (the count handed on stays continuous); any other is a bad cell,
//! judged against the last good count, so one corrupt value costs one row. When
//! [`RESET_RUN`] rows in a row are bad but move plausibly among themselves, the counter was
//! re-zeroed: they become the new reference, and the count handed on continues from the
//! last good one advanced by the run's own motion.
//!
//! A shaft also cannot change its speed from one row to the next by much: a count that
//! lies further than
//!
//! `e_max = 2 + K w_max dt C / (2 pi) / 16`
//!
//! (a sixteenth of `N_max`'s motion part: a quarter of the monitor's own largest believable
//! step) from where the last good count's motion carries it (`last + v dt`, `v` the good
//! counts' rate smoothed over about four rows) is a bad cell too, even within `N_max`. A
//! damaged count a few hundred off the true one, or a burst of two whose second row moves
//! plausibly from the first, used to pass (the second judged against the last good count
//! two rows back, with twice the room) while the true count after it was held out: the
//! count handed on jumped out and back, and the monitor, whose own bound is `N_max / K`,
//! flagged the speed sensor (`crates/monitor-api/tests/api/bad_encoder_cells.rs`). A genuine
//! speed change moves the count by far less: a 2.2 kW motor starting direct-on-line at
//! 2000 rad/s^2 changes its
//! step by 0.3 counts per row at 5 kHz, 1.3 at 1 kHz, against `e_max` of 10 and 43.

/// Counts per revolution the replay assumes for `enc_count` (4 x 1024 lines, the core's
/// `EncoderConfig` default).
pub const COUNTS_PER_REV: f64 = 4096.0;
/// Margin `K` on the largest believable step (encoders up to `K` times finer than
/// [`COUNTS_PER_REV`] pass).
pub const STEP_MARGIN: f64 = 4.0;
/// Consecutive plausible-among-themselves bad steps that make a re-zeroed counter.
pub const RESET_RUN: u32 = 64;
/// Counter widths whose wrap is undone [bits].
const WRAP_BITS: [u32; 3] = [16, 24, 32];
/// The largest departure of a good count from the last good count's motion, as a fraction
/// of `N_max`'s motion part (module docs): a sixteenth, a quarter of the monitor's own bound.
const SPIKE_FRACTION: f64 = 1.0 / 16.0;
/// The smoothing of the good counts' rate: each good step moves it by this fraction of the
/// difference (about four rows' memory: the counts' quantisation averaged, a starting
/// motor's rising rate followed within a fraction of a count).
const RATE_GAIN: f64 = 0.25;

/// What [`EncoderTrack::check`] made of a count.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum EncoderCell {
    /// A good count, continuous with the last (wraps and re-zeroing undone).
    Good(i64),
    /// A bad cell: unreadable, or a jump no shaft can make.
    Bad,
}

/// The encoder count's state across rows; see the module documentation.
#[derive(Debug, Clone, Default)]
pub struct EncoderTrack {
    /// Largest believable speed times counts per radian times the margin [counts/s].
    rate_max: f64,
    /// Last good raw count and its time.
    last: Option<(i64, f64)>,
    /// The good counts' smoothed rate [counts/s], once two good counts were seen.
    rate: Option<f64>,
    /// Offset from raw counts to the continuous count handed on.
    offset: i64,
    /// After a restart: the last count handed on, where the next one continues.
    pending_base: Option<i64>,
    /// The current run of bad but mutually plausible counts: length, last raw, last time.
    run: (u32, i64, f64),
    /// The first raw count of that run, and its time [s].
    run_first: (i64, f64),
    /// Wraps undone.
    pub wraps: u64,
    /// Re-zeroed counters followed.
    pub resets: u64,
}

impl EncoderTrack {
    /// A tracker for a machine whose speed stays within `wm_max_rad_s`.
    pub fn new(wm_max_rad_s: f64) -> Self {
        EncoderTrack {
            rate_max: STEP_MARGIN * wm_max_rad_s * COUNTS_PER_REV / std::f64::consts::TAU,
            ..EncoderTrack::default()
        }
    }

    /// Largest believable step over `dt_s`.
    fn max_step(&self, dt_s: f64) -> i64 {
        (self.rate_max * dt_s.max(0.0)).min(1e15) as i64 + 2
    }

    /// The step `s` over `dt_s` follows the last good count's motion within `e_max` (module
    /// docs); any step does before a rate is known.
    fn follows_motion(&self, s: i64, dt_s: f64) -> bool {
        match self.rate {
            Some(v) if dt_s > 0.0 => {
                let e_max = 2.0 + SPIKE_FRACTION * self.rate_max * dt_s;
                (s as f64 - v * dt_s).abs() <= e_max
            }
            _ => true,
        }
    }

    /// A good step `s` over `dt_s` moves the smoothed rate.
    fn learn_rate(&mut self, s: i64, dt_s: f64) {
        if dt_s > 0.0 {
            let v = s as f64 / dt_s;
            self.rate = Some(self.rate.map_or(v, |r| r + RATE_GAIN * (v - r)));
        }
    }

    /// Forget the reference (a clock reset: time and count start again); the count handed
    /// on continues from the last good one.
    pub fn restart(&mut self) {
        if let Some((raw, _)) = self.last.take() {
            self.pending_base = Some(raw.wrapping_add(self.offset));
        }
        self.rate = None;
        self.run = (0, 0, f64::NAN);
    }

    /// Judges the count `raw` of the row at `t_s` ([`crate::log::ENC_COUNT_UNREADABLE`]
    /// for an unreadable cell).
    pub fn check(&mut self, raw: i64, t_s: f64) -> EncoderCell {
        if raw == crate::log::ENC_COUNT_UNREADABLE {
            return EncoderCell::Bad;
        }
        let Some((last, last_t)) = self.last else {
            // The first count, or the first after a restart: continue from the last one
            // handed on.
            if let Some(base) = self.pending_base.take() {
                self.offset = base.wrapping_sub(raw);
            }
            self.last = Some((raw, t_s));
            return EncoderCell::Good(raw.wrapping_add(self.offset));
        };
        let max = self.max_step(t_s - last_t);
        let d = raw.wrapping_sub(last);
        let step = if d.unsigned_abs() <= max as u64 {
            Some(d)
        } else if self.run.0 > 0 {
            // A wrap is a step from the row before; after bad cells it is a jump.
            None
        } else {
            WRAP_BITS.iter().find_map(|&k| {
                let m = 1i64 << k;
                [d.wrapping_sub(m), d.wrapping_add(m)]
                    .into_iter()
                    .find(|x| x.unsigned_abs() <= max as u64)
            })
        };
        match step {
            Some(s) if self.follows_motion(s, t_s - last_t) => {
                if s != d {
                    self.wraps += 1;
                    self.offset = self.offset.wrapping_add(s.wrapping_sub(d));
                }
                self.learn_rate(s, t_s - last_t);
                self.last = Some((raw, t_s));
                self.run.0 = 0;
                EncoderCell::Good(raw.wrapping_add(self.offset))
            }
            _ => self.jump(raw, t_s, last),
        }
    }

    /// A jump from the last good count: a bad cell, unless it ends a run of
    /// [`RESET_RUN`] mutually plausible ones (a re-zeroed counter).
    fn jump(&mut self, raw: i64, t_s: f64, last: i64) -> EncoderCell {
        let (n, prev, prev_t) = self.run;
        let plausible =
            n > 0 && raw.wrapping_sub(prev).unsigned_abs() <= self.max_step(t_s - prev_t) as u64;
        if !plausible {
            self.run_first = (raw, t_s);
        }
        self.run = (if plausible { n + 1 } else { 1 }, raw, t_s);
        if self.run.0 < RESET_RUN {
            return EncoderCell::Bad;
        }
        // Re-zeroed: the run's latest count is the new reference (its rows were bad cells,
        // filled or held out downstream).
        // The run moved as the shaft did: the count handed on advances by the run's motion
        // and one step of its mean rate (the step into the run is unknown).
        let moved = raw.wrapping_sub(self.run_first.0);
        let step = moved / i64::from(RESET_RUN - 1);
        // The shaft's motion from here on is the run's own (a counter frozen while the
        // shaft turned is followed as frozen: the monitor then sees the stopped reading).
        let span = t_s - self.run_first.1;
        self.rate = (span > 0.0).then(|| moved as f64 / span);
        let handed = last
            .wrapping_add(self.offset)
            .wrapping_add(moved)
            .wrapping_add(step);
        self.offset = handed.wrapping_sub(raw);
        self.resets += 1;
        self.run.0 = 0;
        self.last = Some((raw, t_s));
        EncoderCell::Good(raw.wrapping_add(self.offset))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::log::ENC_COUNT_UNREADABLE;

    /// 150 rad/s at 5 kHz: 19.6 counts per sample.
    fn counts(n: usize) -> Vec<(i64, f64)> {
        (0..n)
            .map(|k| {
                let t = k as f64 / 5000.0;
                (
                    (150.0 * t * COUNTS_PER_REV / std::f64::consts::TAU).round() as i64,
                    t,
                )
            })
            .collect()
    }

    fn run(track: &mut EncoderTrack, xs: &[(i64, f64)]) -> Vec<EncoderCell> {
        xs.iter().map(|&(c, t)| track.check(c, t)).collect()
    }

    #[test]
    fn a_clean_count_passes_unchanged() {
        let xs = counts(5000);
        let mut tr = EncoderTrack::new(628.0);
        let out = run(&mut tr, &xs);
        assert!(out
            .iter()
            .zip(&xs)
            .all(|(o, (c, _))| *o == EncoderCell::Good(*c)));
        assert_eq!((tr.wraps, tr.resets), (0, 0));
    }

    #[test]
    fn one_corrupt_value_costs_one_row() {
        for bad in [ENC_COUNT_UNREADABLE, 0, i64::MAX, -5_000_000, 1 << 40] {
            let mut xs = counts(3000);
            xs[2000].0 = bad;
            let mut tr = EncoderTrack::new(628.0);
            let out = run(&mut tr, &xs);
            assert_eq!(out[2000], EncoderCell::Bad, "{bad}");
            let want = counts(3000);
            for k in (0..3000).filter(|&k| k != 2000) {
                assert_eq!(out[k], EncoderCell::Good(want[k].0), "{bad} at {k}");
            }
        }
    }

    #[test]
    fn a_count_off_its_track_is_bad_even_within_the_largest_step() {
        // 628 rad/s at 5 kHz: N_max is 4 x 82 + 2 counts per row, e_max 2 + 82 / 4.
        for (off, rows) in [(60i64, 1usize), (-60, 1), (300, 2), (-400, 2), (90, 3)] {
            let mut xs = counts(3000);
            for x in &mut xs[2000..2000 + rows] {
                x.0 += off;
            }
            let mut tr = EncoderTrack::new(628.0);
            let out = run(&mut tr, &xs);
            let want = counts(3000);
            for (k, o) in out.iter().enumerate() {
                let bad = (2000..2000 + rows).contains(&k);
                let expected = if bad {
                    EncoderCell::Bad
                } else {
                    EncoderCell::Good(want[k].0)
                };
                assert_eq!(*o, expected, "{off} over {rows} rows, at {k}");
            }
        }
    }

    #[test]
    fn a_motor_starting_hard_passes() {
        // 5000 rad/s^2 from rest to 300 rad/s, at 1 and 5 kHz: the count's steps grow by
        // up to 3.3 counts per row.
        for rate in [1000.0, 5000.0] {
            let xs: Vec<(i64, f64)> = (0..(rate as usize))
                .map(|k| {
                    let t = k as f64 / rate;
                    let theta = if t < 0.06 {
                        2500.0 * t * t
                    } else {
                        9.0 + 300.0 * (t - 0.06)
                    };
                    (
                        (theta * COUNTS_PER_REV / std::f64::consts::TAU).round() as i64,
                        t,
                    )
                })
                .collect();
            let mut tr = EncoderTrack::new(628.0);
            let out = run(&mut tr, &xs);
            assert!(
                out.iter()
                    .zip(&xs)
                    .all(|(o, (c, _))| *o == EncoderCell::Good(*c)),
                "{rate} Hz"
            );
        }
    }

    #[test]
    fn counter_wraps_are_undone() {
        for bits in [16u32, 24, 32, 64] {
            let xs: Vec<(i64, f64)> = counts(40_000)
                .into_iter()
                .map(|(c, t)| {
                    // The counter starts just below its wrap: it wraps within the log.
                    let c = c + (1i128 << bits) as i64 - ((1i64 << 15) - 1);
                    let wrapped = if bits == 64 {
                        c
                    } else {
                        c.rem_euclid(1i64 << bits)
                    };
                    (wrapped, t)
                })
                .collect();
            let mut tr = EncoderTrack::new(628.0);
            let out = run(&mut tr, &xs);
            let first = match out[0] {
                EncoderCell::Good(c) => c,
                EncoderCell::Bad => panic!("first bad"),
            };
            let want = counts(40_000);
            for (k, o) in out.iter().enumerate() {
                assert_eq!(
                    *o,
                    EncoderCell::Good(first + want[k].0),
                    "{bits} bits at {k}"
                );
            }
            if bits < 64 {
                assert!(tr.wraps >= 1, "{bits} bits: no wrap seen");
            }
        }
    }

    #[test]
    fn a_re_zeroed_counter_is_followed_after_a_run() {
        let mut xs = counts(5000);
        let at = xs[3000].0;
        for x in &mut xs[3000..] {
            x.0 -= at;
        }
        let mut tr = EncoderTrack::new(628.0);
        let out = run(&mut tr, &xs);
        assert!(
            out[3000..3000 + RESET_RUN as usize - 1]
                .iter()
                .all(|o| *o == EncoderCell::Bad),
            "{:?}",
            &out[2995..3070]
        );
        assert_eq!(tr.resets, 1);
        // After the run the count moves as the shaft does again.
        let good: Vec<i64> = out[3100..]
            .iter()
            .map(|o| match o {
                EncoderCell::Good(c) => *c,
                EncoderCell::Bad => i64::MIN,
            })
            .collect();
        assert!(good.windows(2).all(|w| (15..=25).contains(&(w[1] - w[0]))));
        // ... and goes on where the shaft is: within a step of the count never re-zeroed.
        let truth = counts(5000);
        let k = 3000 + RESET_RUN as usize - 1;
        assert_eq!(out[k - 1], EncoderCell::Bad);
        match out[k] {
            EncoderCell::Good(c) => assert!((c - truth[k].0).abs() <= 20, "{c} vs {}", truth[k].0),
            EncoderCell::Bad => panic!("the run's end is still bad"),
        }
    }
}
