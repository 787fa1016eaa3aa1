//! The replay's sequence tracker ([`SequenceTracker`]): the symmetrical components of the
//! currents and voltages, sample by sample.
//!
//! Two analyses run on one PLL (locked to the voltages where logged, else to the
//! amplitude-normalised current vector):
//! - filtered Park sequences ([`SequenceAnalyzer`](monitor_core::sequence::SequenceAnalyzer), 2 Hz) on the PLL's own angle: the
//!   steady point the isolation evaluates ([`SequenceTracker::steady_point`]), stepped
//!   once per block ([`slow`]);
//! - least-squares phasors ([`PhasorFit`](monitor_core::sequence::PhasorFit)) over windows of [`WINDOW_PERIODS`] supply
//!   periods on a reference angle that turns at the PLL's frequency low-passed at
//!   [`REFERENCE_FC_HZ`]: the negative-sequence analysis ([`super::winding`]). The
//!   reference does not follow the `2f` wobble that a large negative sequence puts into the
//!   current vector's angle (a PLL that follows it moves part of the negative sequence into
//!   the angle: on real recordings of shorted turns a 15 % negative sequence read as
//!   2.4 %), and the fit is exact for any offset of it.
//!
//! Per row only what must follow the samples runs: the PLL (its angle is the frame) and
//! the least-squares sums on the reference angle (single precision over short blocks,
//! [`lanes`]). The rest is done once per block of an eighth of a supply period (the rotor
//! demodulator's blocks): the blocks' sums give the current and voltage vectors turned
//! back by the reference angle, which the rotor's demodulator records and the slow
//! quantities (the 2 Hz sequences on the PLL's angle, the currents' normaliser, the
//! reference frequency) are filtered on ([`slow`], where what that changes is stated); the
//! reference angle turns by a step held over a block, whose sin/cos is computed once per
//! block ([`super::trig::Oscillator::turn`]).

mod block_filter;
mod block_pll;
mod lanes;
mod reference;
mod slow;

use crate::stage::{Finish, Stage};
use crate::windows::{SequenceWindow, WindowRow, MIN_WINDOW_FILL, WINDOW_PERIODS};
use block_pll::BlockPll;
use lanes::{Demod, FitSums};
use monitor_core::frames::{clarke, AlphaBeta, SinCos};
use monitor_core::Abc;
use monitor_core::SteadyPoint as IsolationPoint;
use monitor_io::log::quality::MAX_BRIDGED_GAP_S;
use monitor_io::log::Row;
use monitor_io::params::ParamFile;
use reference::{RampSums, Reference};
use slow::SlowFilters;
use std::collections::VecDeque;

/// Missing samples up to this many in a row are filled for the sequence analysis (the
/// vectors turned back at the supply frequency); longer gaps only advance the angle.
pub const FILLED_SAMPLES: usize = 50;

/// Corner of the low-pass on the PLL's frequency that the least-squares reference turns at
/// [Hz]: a second-order filter that passes `2f` wobble at `(1/(2f))^2` (7e-5 at 60 Hz).
pub const REFERENCE_FC_HZ: f32 = 1.0;

/// Largest change of the reference frequency within a window for the window to count as
/// steady (a fraction of its mean): above it the supply frequency moved (a run-up, a
/// drive's ramp) or the PLL was still locking.
pub const STEADY_FREQUENCY_RANGE: f32 = 0.005;

/// The window being filled.
#[derive(Debug, Clone, Copy)]
struct OpenWindow {
    /// The least-squares sums of the currents and the voltages ([`lanes`]).
    sums: FitSums,
    /// Samples offered (good or not).
    offered: u32,
    /// Voltage samples that were bad (the voltages' fit is then not used).
    bad_v: u32,
    from_s: f64,
    to_s: f64,
    /// The reference frequency's and offset's sums and range ([`reference`]).
    ramp: RampSums,
}

impl OpenWindow {
    fn new() -> Self {
        OpenWindow {
            sums: FitSums::default(),
            offered: 0,
            bad_v: 0,
            from_s: 0.0,
            to_s: 0.0,
            ramp: RampSums::default(),
        }
    }
}

/// The sequences of every log, sample by sample (module docs): the filters and the fits,
/// which need nothing but the rows (the monitor's learning and speed, which the windows
/// carry, are the [`WindowBook`]'s), so that they can run on another thread than the
/// monitor.
#[derive(Debug, Clone)]
pub(super) struct SequenceFront {
    dt_s: f64,
    /// The monitor's sample limits `i_max`, `v_max` (infinite ones as `f64::MAX`: a
    /// sample is good when its magnitude is at most the limit, which a non-finite one is
    /// not).
    i_max: f64,
    v_max: f64,
    voltages: bool,
    /// The PLL, stepped once per block ([`block_pll`]).
    pll: BlockPll,
    /// The slow filters ([`slow`]): the positive sequences on the PLL's angle and the
    /// reference frequency.
    slow: SlowFilters,
    /// Time of the last row seen [s].
    last_t: Option<f64>,
    /// The least-squares reference angle and its offset from `w0 t` ([`reference`]).
    reference: Reference,
    /// The open block's vectors on the reference angle from the windows closed within it
    /// ([`lanes::Demod`]).
    block: Demod,
    /// Samples per least-squares window.
    window_len: u32,
    open: OpenWindow,
    /// The windows closed and not yet taken by the book, in order: `None` for one that had
    /// no solution (the book's learning flag restarts all the same).
    closed: VecDeque<Option<SequenceWindow>>,
    /// The rotor finding's demodulated current on the reference angle
    /// ([`super::rotor::RotorFront`]).
    rotor: super::rotor::RotorFront,
}

/// What [`SequenceFront::track`] found at one row: the steady point's vectors (the
/// monitor's speed is added by [`SequenceStep::point`]) and whether the open window was
/// closed before the row's sample (a gap the data-quality stage does not bridge) or after
/// it (full).
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub(super) struct SequenceStep {
    i: (f32, f32),
    v: (f32, f32),
    we_rad_s: f32,
    closed_before: bool,
    closed_after: bool,
}

impl SequenceStep {
    /// What the winding's windows take of the step: whether the open window was closed
    /// before the row's sample and after it, with the monitor's learning and speed after
    /// the row before.
    #[inline]
    pub fn window_row(&self, learning: bool, wr_rad_s: Option<f32>) -> WindowRow {
        WindowRow {
            closed_before: self.closed_before,
            closed_after: self.closed_after,
            learning,
            wr_rad_s,
        }
    }

    /// The steady-state vectors for the isolation: the positive sequences of voltage and
    /// current on the PLL's angle, its frequency, and the monitor's electrical speed
    /// `wr_rad_s` (encoder, filtered).
    pub fn point(&self, wr_rad_s: f32) -> IsolationPoint {
        IsolationPoint {
            i: monitor_core::Dq {
                d: self.i.0,
                q: self.i.1,
            },
            v: monitor_core::Dq {
                d: self.v.0,
                q: self.v.1,
            },
            we_rad_s: self.we_rad_s,
            wr_rad_s,
        }
    }
}

impl SequenceFront {
    /// A tracker for a log at `sample_rate_hz` with (or without) voltage columns; the
    /// sample limits `i_max`, `v_max` are the monitor's. Errors: the filters' checks
    /// ([`Svf`](monitor_core::filter::Svf)`::new`: a sample rate too low for their corners).
    pub fn new(
        params: &ParamFile,
        voltages: bool,
        sample_rate_hz: f64,
        i_max: f64,
        v_max: f64,
    ) -> Result<Self, monitor_core::ConfigError> {
        let dt = (1.0 / sample_rate_hz) as f32;
        let w0 = std::f64::consts::TAU * params.supply.f_hz;
        let rotor = super::rotor::RotorFront::new(
            sample_rate_hz,
            params.supply.f_hz,
            super::rotor::MAX_STRETCH_S,
        );
        let limit = |max: f64| if max == f64::INFINITY { f64::MAX } else { max };
        Ok(SequenceFront {
            dt_s: 1.0 / sample_rate_hz,
            i_max: limit(i_max),
            v_max: limit(v_max),
            voltages,
            // Locks to the voltage vector where logged (normalised by its nominal peak),
            // else to the current vector normalised by its own magnitude (so that the
            // loop's gain holds whatever the currents' scale).
            pll: BlockPll::new(
                dt,
                params.supply.f_hz as f32,
                10.0,
                voltages.then(|| params.supply.v_phase_peak() as f32),
            ),
            slow: SlowFilters::new(
                1.0 / sample_rate_hz,
                rotor.per_block(),
                w0 as f32,
                REFERENCE_FC_HZ,
            )?,
            last_t: None,
            reference: Reference::new(1.0 / sample_rate_hz, w0, w0 as f32),
            block: Demod::default(),
            window_len: ((WINDOW_PERIODS * sample_rate_hz / params.supply.f_hz).round() as u32)
                .max(monitor_core::sequence::PHASOR_FIT_MIN_SAMPLES),
            open: OpenWindow::new(),
            closed: VecDeque::new(),
            rotor,
        })
    }

    /// Feeds one row at `t` [s since the first row]. A row with a bad current is held out
    /// (the monitor holds such samples out itself); a bad voltage leaves the voltages'
    /// analysis alone.
    pub fn track(&mut self, row: &Row, t: f64) -> SequenceStep {
        let (filled, closed_before) = self.bridge(t);
        self.reference.row();
        self.pll.row();
        let o = &mut self.open;
        if o.offered == 0 {
            o.from_s = t;
        }
        o.offered += 1;
        o.to_s = t;
        let r = &self.reference;
        self.rotor.mark(t, || r.offset(), row);
        // Without branches: a NaN fails the comparison, an infinity the finite limit.
        let ok = |x: &[f64; 3], max: f64| {
            let le = |v: f64| u8::from(v.abs() <= max);
            le(x[0]) & le(x[1]) & le(x[2]) != 0
        };
        let lanes = |x: &[f64; 3]| [x[0] as f32, x[1] as f32, x[2] as f32, 1.0];
        if ok(&row.i_abc, self.i_max) {
            let i_abc = lanes(&row.i_abc);
            let v_abc = match &row.v_abc {
                Some(v) if self.voltages && ok(v, self.v_max) => Some(lanes(v)),
                _ => None,
            };
            if self.voltages && v_abc.is_none() {
                self.open.bad_v += 1;
            }
            let sc = self.reference.sin_cos();
            self.open.sums.add(sc, i_abc, v_abc);
            if filled > 0 {
                self.fill(filled, sc, i_abc, v_abc.map(clarke_of));
            }
        }
        if self.rotor.full() {
            self.end_block();
        }
        let closed_after = self.open.offered >= self.window_len;
        if closed_after {
            self.close_window();
        }
        let (i, v) = self.slow.positive();
        SequenceStep {
            i,
            v,
            we_rad_s: self.slow.we(),
            closed_before,
            closed_after,
        }
    }

    /// Samples missing from the stream before the row at `t` [s]: the angles advance over
    /// the missing time at their frequency (as the monitor's frame does), so that the
    /// sequences stay put; a gap the data-quality stage does not bridge ends the window.
    /// Returns the samples to fill in (up to [`FILLED_SAMPLES`]) and whether the window
    /// was closed.
    #[inline]
    fn bridge(&mut self, t: f64) -> (usize, bool) {
        let Some(prev) = self.last_t.replace(t) else {
            return (0, false);
        };
        let missing = t - prev - self.dt_s;
        if missing <= 0.5 * self.dt_s {
            return (0, false);
        }
        self.bridge_gap(missing)
    }

    /// [`SequenceFront::bridge`] over `missing` seconds (more than half a sample).
    fn bridge_gap(&mut self, missing: f64) -> (usize, bool) {
        if missing <= MAX_BRIDGED_GAP_S {
            self.pll.skip(missing as f32, self.reference.frequency());
            self.reference.settle(&mut self.open.ramp);
            self.reference.skip(missing);
            let m = (missing / self.dt_s).round();
            self.rotor.skip(m as u32);
            let filled = if m <= FILLED_SAMPLES as f64 {
                m as usize
            } else {
                0
            };
            return (filled, false);
        }
        if missing > MAX_BRIDGED_GAP_S {
            self.close_window();
            // The block's filters step on what it has; the rotor's record breaks off.
            let b = std::mem::take(&mut self.block);
            let w_pll = self.pll.omega_rad_s();
            let mid = self.pll.end_block(&b, self.reference.frequency());
            self.slow.step(&b, mid, w_pll);
            self.rotor.break_off();
            return (0, true);
        }
        (0, false)
    }

    /// `filled` samples missing before a good row (`sc` the reference's sin/cos, `i_abc`
    /// the phase currents, `v` the voltage vector) into the slow filters (module docs of
    /// [`slow`]).
    fn fill(&mut self, filled: usize, sc: SinCos, i_abc: [f32; 4], v: Option<AlphaBeta>) {
        let back = |x: AlphaBeta| {
            [
                x.alpha * sc.cos + x.beta * sc.sin,
                x.beta * sc.cos - x.alpha * sc.sin,
            ]
        };
        self.slow
            .fill(filled as u32, back(clarke_of(i_abc)), v.map(back));
    }

    /// Ends the rotor's block: the least-squares block's vectors on the reference angle
    /// go to the rotor's record and the slow filters (with the PLL's angle less the
    /// reference's at the block's last row), and the reference turns at the new frequency.
    fn end_block(&mut self) {
        let d = self.open.sums.flush();
        self.block.add(&d);
        let b = std::mem::take(&mut self.block);
        self.rotor.add(b.i, b.n_i);
        self.reference.settle(&mut self.open.ramp);
        let offset = self.reference.offset();
        // The frequency the PLL held over the block, then its step on the block.
        let w_pll = self.pll.omega_rad_s();
        let mid = self.pll.end_block(&b, self.reference.frequency());
        if self.slow.step(&b, mid, w_pll) {
            self.reference.set_frequency(self.slow.w_ref());
        }
        self.rotor.close_at(self.slow.w_ref(), offset);
    }

    /// Ends the open window: solves its fits and queues it for the book (`None` when it
    /// has no solution).
    fn close_window(&mut self) {
        // The window's last block's vectors stay in the rotor's open block.
        self.block.add(&self.open.sums.flush());
        self.reference.settle(&mut self.open.ramp);
        let mut o = std::mem::replace(&mut self.open, OpenWindow::new());
        self.closed.push_back(self.solved(&mut o));
    }

    /// The window `o` solved, `None` when empty or without a solution. (The learning flag
    /// and the monitor's speed are the book's.)
    fn solved(&self, o: &mut OpenWindow) -> Option<SequenceWindow> {
        if o.offered == 0 {
            return None;
        }
        // The voltages' fit shares the currents' regressor sums: it is used only when every
        // sample with a good current had good voltages.
        let (fit_i, fit_v, _) = o.sums.fits();
        let i = fit_i.solve()?;
        let r = &o.ramp;
        let w_mean = (r.w_sum / f64::from(o.offered)) as f32;
        let complete = f64::from(i.samples) >= MIN_WINDOW_FILL * f64::from(self.window_len);
        let steady =
            complete && w_mean > 0.0 && (r.w_max - r.w_min) <= STEADY_FREQUENCY_RANGE * w_mean;
        Some(SequenceWindow {
            from_s: o.from_s,
            to_s: o.to_s,
            i,
            v: (self.voltages && o.bad_v == 0)
                .then(|| fit_v.solve())
                .flatten(),
            we_rad_s: w_mean,
            offset_rad: r.offset_sum / f64::from(o.offered),
            wr_rad_s: None,
            complete,
            steady,
            learning: true,
        })
    }

    /// The rotor finding's demodulated record ([`super::rotor::RotorFront`]).
    pub fn rotor(&self) -> &super::rotor::RotorFront {
        &self.rotor
    }

    /// The next window closed and not yet taken (`Some(None)`: one without a solution).
    pub fn take_closed(&mut self) -> Option<Option<SequenceWindow>> {
        self.closed.pop_front()
    }

    /// Ends the analysis: closes the last window if it holds at least half a window's
    /// samples (true; the book then closes it too).
    pub fn finish(&mut self) -> bool {
        let last = f64::from(self.open.offered) >= 0.5 * f64::from(self.window_len);
        if last {
            self.close_window();
        }
        last
    }
}

/// The current vector of the phase values `[a, b, c, _]` ([`clarke`]).
#[inline]
fn clarke_of(x: [f32; 4]) -> AlphaBeta {
    clarke(Abc {
        a: x[0],
        b: x[1],
        c: x[2],
    })
}

/// The sequence stage: the front ([`SequenceFront`]) the chain runs on each row, or lent to
/// the thread that reads the log (`diagnose`, `pipe.rs`), which runs it beside the chain
/// and gives it back at the end. It hands on each row's [`SequenceStep`], and the windows
/// it closes go to the winding in order ([`SequenceStage::closed`]).
#[derive(Debug)]
pub(super) struct SequenceStage {
    front: Option<SequenceFront>,
}

/// What the sequence stage leaves at the end: the windows it closed and not yet handed on
/// (the last one among them), and the front with the rotor's record (`None`: lent and
/// never given back, a read that ended before its end).
#[derive(Debug)]
pub(super) struct SequencesEnd {
    /// The last window was closed at the end (the monitor's speed then goes with it).
    pub(super) closed_last: bool,
    /// The windows closed and not yet handed on, in order.
    pub(super) closed: Vec<Option<SequenceWindow>>,
    /// The front as it ended.
    pub(super) front: Option<SequenceFront>,
}

impl SequenceStage {
    /// The stage over `front`.
    pub(super) fn new(front: SequenceFront) -> Self {
        SequenceStage { front: Some(front) }
    }

    /// The windows closed and not yet handed on (in order; `None` for one without a
    /// solution).
    #[inline]
    pub(super) fn closed(&mut self) -> impl Iterator<Item = Option<SequenceWindow>> + '_ {
        self.front.iter_mut().flat_map(|f| f.closed.drain(..))
    }

    /// Lends the front to the thread that reads the log ([`SequenceStage::give_back`]).
    pub(super) fn lend(&mut self) -> Option<SequenceFront> {
        self.front.take()
    }

    /// Takes the front back once every row was pushed: its last window is the stage's to
    /// close ([`Finish::finish`]).
    pub(super) fn give_back(&mut self, front: SequenceFront) {
        self.front = Some(front);
    }

    /// The front is here (not lent).
    pub(super) fn present(&self) -> bool {
        self.front.is_some()
    }
}

impl Stage for SequenceStage {
    /// The row's time since the first row [s].
    type Input<'a> = f64;
    type Output = SequenceStep;

    /// The row's step (the default while the front is lent: the chain is then handed the
    /// steps the other thread took).
    #[inline]
    fn update(&mut self, row: &Row, t: f64) -> SequenceStep {
        self.front
            .as_mut()
            .map_or_else(SequenceStep::default, |f| f.track(row, t))
    }
}

impl Finish for SequenceStage {
    type Closing<'a> = ();
    type Finding = SequencesEnd;

    fn finish(mut self, (): ()) -> SequencesEnd {
        let closed_last = self.front.as_mut().is_some_and(SequenceFront::finish);
        let closed = self.closed().collect();
        SequencesEnd {
            closed_last,
            closed,
            front: self.front,
        }
    }
}
