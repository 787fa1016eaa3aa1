//! The replay's sequence tracker ([`SequenceTracker`]): the symmetrical components of the
//! currents and voltages, sample by sample.
//!
//! Two analyses run on one PLL (locked to the voltages where logged, else to the
//! amplitude-normalised current vector):
//! - filtered Park sequences ([`SequenceAnalyzer`](monitor_core::sequence::SequenceAnalyzer), 2 Hz) on the PLL's own angle: the
//!   steady point the isolation evaluates ([`SequenceTracker::steady_point`]);
//! - least-squares phasors ([`PhasorFit`]) over windows of [`WINDOW_PERIODS`] supply
//!   periods on a reference angle that turns at the PLL's frequency low-passed at
//!   [`REFERENCE_FC_HZ`]: the negative-sequence analysis ([`super::winding`]). The
//!   reference does not follow the `2f` wobble that a large negative sequence puts into the
//!   current vector's angle (a PLL that follows it moves part of the negative sequence into
//!   the angle: on real recordings of shorted turns a 15 % negative sequence read as
//!   2.4 %), and the fit is exact for any offset of it.

use super::trig::Oscillator;
use super::{FILLED_SAMPLES, SENSOR_PHASE_MIN_RATIO};
use monitor_core::angle::SrfPll;
use monitor_core::filter::{Svf, SvfState};
use monitor_core::frames::{clarke, park, AlphaBeta, SinCos};
use monitor_core::sequence::{
    single_phase_gain, Complex32, PhasorFit, SinglePhaseGain, ThreePhasors,
};
use monitor_core::Abc;
use monitor_core::SteadyPoint as IsolationPoint;
use monitor_io::log::quality::MAX_BRIDGED_GAP_S;
use monitor_io::log::Row;
use monitor_io::params::ParamFile;
use std::collections::VecDeque;

/// Supply periods per least-squares window (at the nominal frequency): 0.17 s at 60 Hz,
/// 0.2 s at 50 Hz. Short enough to see a fault switched on and off within a few seconds,
/// long enough that harmonics and noise average out.
pub const WINDOW_PERIODS: f64 = 10.0;

/// Corner of the low-pass on the PLL's frequency that the least-squares reference turns at
/// [Hz]: a second-order filter that passes `2f` wobble at `(1/(2f))^2` (7e-5 at 60 Hz).
pub const REFERENCE_FC_HZ: f32 = 1.0;

/// Largest change of the reference frequency within a window for the window to count as
/// steady (a fraction of its mean): above it the supply frequency moved (a run-up, a
/// drive's ramp) or the PLL was still locking.
pub const STEADY_FREQUENCY_RANGE: f32 = 0.005;

/// Least share of a window's samples the fit must have used (bad samples are held out).
pub const MIN_WINDOW_FILL: f64 = 0.8;

/// One window of the least-squares analysis.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SequenceWindow {
    /// Time of the window's first and last sample [s since the log's first row].
    pub from_s: f64,
    /// See `from_s`.
    pub to_s: f64,
    /// The currents' phase phasors.
    pub i: ThreePhasors,
    /// The voltages' phase phasors, where logged and good in the whole window.
    pub v: Option<ThreePhasors>,
    /// Mean supply angular frequency over the window [rad/s].
    pub we_rad_s: f32,
    /// Mean over the window of the reference angle less `w0 t` (the nominal frequency's
    /// angle), unwrapped [rad]: how far the reference turned from a fixed-frequency frame,
    /// so that windows can be put into one frame ([`SequenceWindow::offset_rad`]).
    pub offset_rad: f64,
    /// The monitor's electrical rotor speed at the window's end [rad/s], where the log
    /// has a speed (encoder or speed column).
    pub wr_rad_s: Option<f32>,
    /// The fit used at least [`MIN_WINDOW_FILL`] of the window's samples.
    pub complete: bool,
    /// Complete, and the supply frequency held still.
    pub steady: bool,
    /// The window lies in the commissioning window's learning.
    pub learning: bool,
}

/// The window being filled.
#[derive(Debug, Clone, Copy)]
struct OpenWindow {
    fit_i: PhasorFit,
    fit_v: PhasorFit,
    /// Samples offered (good or not).
    offered: u32,
    /// Voltage samples that were bad (the voltages' fit is then not used).
    bad_v: u32,
    from_s: f64,
    to_s: f64,
    w_sum: f64,
    offset_sum: f64,
    w_min: f32,
    w_max: f32,
}

impl OpenWindow {
    fn new() -> Self {
        OpenWindow {
            fit_i: PhasorFit::new(),
            fit_v: PhasorFit::new(),
            offered: 0,
            bad_v: 0,
            from_s: 0.0,
            to_s: 0.0,
            w_sum: 0.0,
            offset_sum: 0.0,
            w_min: f32::INFINITY,
            w_max: 0.0,
        }
    }
}

/// The positive sequence of a vector on an angle turning at the supply frequency: the
/// Park components filtered as the core's [`SequenceAnalyzer`](monitor_core::sequence::SequenceAnalyzer) filters them (the steady
/// point needs no more of it).
#[derive(Debug, Clone, Copy)]
struct Positive {
    filter: Svf,
    d: SvfState,
    q: SvfState,
}

impl Positive {
    fn new(fc_hz: f32, dt_s: f32) -> Result<Self, monitor_core::ConfigError> {
        Ok(Positive {
            filter: Svf::new(fc_hz, dt_s)?,
            d: SvfState::default(),
            q: SvfState::default(),
        })
    }

    /// [`SequenceAnalyzer::update`](monitor_core::sequence::SequenceAnalyzer::update)'s positive sequence.
    #[inline]
    fn update(&mut self, x: AlphaBeta, sc: SinCos) {
        let p = park(x, sc);
        self.filter.update(&mut self.d, p.d);
        self.filter.update(&mut self.q, p.q);
    }

    /// [`SequenceAnalyzer::positive`](monitor_core::sequence::SequenceAnalyzer::positive).
    fn value(&self) -> (f32, f32) {
        (self.d.y(), self.q.y())
    }
}

/// The sequences of every log, sample by sample (module docs): the filters and the fits,
/// which need nothing but the rows (the monitor's learning and speed, which the windows
/// carry, are the [`WindowBook`]'s), so that they can run on another thread than the
/// monitor.
#[derive(Debug, Clone)]
pub(super) struct SequenceFront {
    dt_s: f64,
    i_max: f64,
    v_max: f64,
    voltages: bool,
    /// The PLL follows the voltages (else the normalised currents).
    pll_on_voltage: bool,
    pll: SrfPll,
    /// Mean square of the current vector, low-passed: the currents' normaliser for the PLL.
    i_ms: Svf,
    i_ms_state: SvfState,
    /// The positive sequences of the currents and the voltages on the PLL's angle.
    seq: Positive,
    seq_v: Positive,
    /// Time of the last row seen [s].
    last_t: Option<f64>,
    /// The PLL's frequency low-passed (`y`) and the reference angle it turns [rad].
    w_ref: Svf,
    w_ref_state: SvfState,
    theta_ref: f32,
    /// The sin/cos of the PLL's angle and of the reference angle, by rotation.
    osc_pll: Oscillator,
    osc_ref: Oscillator,
    /// The reference angle less `w0 t`, unwrapped [rad], and `w0` [rad/s].
    offset: f64,
    w0: f64,
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

/// The least-squares windows with what the monitor adds to them: whether the commissioning
/// window's learning covered every sample, and the monitor's speed where the window closed.
#[derive(Debug, Clone, Default)]
pub(super) struct WindowBook {
    /// The open window's samples were all offered while learning.
    learning: bool,
    /// Windows closed by the front, not yet booked.
    queue: VecDeque<Option<SequenceWindow>>,
    windows: Vec<SequenceWindow>,
}

impl WindowBook {
    /// An empty book.
    pub fn new() -> Self {
        WindowBook {
            learning: true,
            ..WindowBook::default()
        }
    }

    /// Takes the windows the front closed (in order).
    pub fn take(&mut self, front: &mut SequenceFront) {
        self.queue.extend(front.closed.drain(..));
    }

    /// Queues one window the front closed (the other thread's end of [`WindowBook::take`]).
    pub fn queue(&mut self, w: Option<SequenceWindow>) {
        self.queue.push_back(w);
    }

    /// Books one row's step: `learning` whether the monitor was learning its commissioning
    /// window, `wr_rad_s` its electrical speed, both at the row before (where the log has a
    /// speed).
    pub fn row(&mut self, step: &SequenceStep, learning: bool, wr_rad_s: Option<f32>) {
        if step.closed_before {
            self.close(wr_rad_s);
        }
        self.learning &= learning;
        if step.closed_after {
            self.close(wr_rad_s);
        }
    }

    /// Ends the open window (the front closed it).
    pub fn close(&mut self, wr_rad_s: Option<f32>) {
        if let Some(mut w) = self.queue.pop_front().flatten() {
            w.learning = self.learning;
            w.wr_rad_s = wr_rad_s;
            self.windows.push(w);
        }
        self.learning = true;
    }

    /// The least-squares windows so far (the open one left out).
    pub fn windows(&self) -> &[SequenceWindow] {
        &self.windows
    }
}

impl SequenceFront {
    /// A tracker for a log at `sample_rate_hz` with (or without) voltage columns; the
    /// sample limits `i_max`, `v_max` are the monitor's. Errors: the filters' checks
    /// ([`Svf::new`]: a sample rate too low for their corners).
    pub fn new(
        params: &ParamFile,
        voltages: bool,
        sample_rate_hz: f64,
        i_max: f64,
        v_max: f64,
    ) -> Result<Self, monitor_core::ConfigError> {
        let dt = (1.0 / sample_rate_hz) as f32;
        let f0 = params.supply.f_hz as f32;
        Ok(SequenceFront {
            dt_s: 1.0 / sample_rate_hz,
            i_max,
            v_max,
            voltages,
            pll_on_voltage: voltages,
            // Locks to the voltage vector where logged (normalised by its nominal peak),
            // else to the current vector normalised by its own RMS magnitude (so that the
            // loop's gain holds whatever the currents' scale).
            pll: SrfPll::new(
                dt,
                f0,
                10.0,
                if voltages {
                    params.supply.v_phase_peak() as f32
                } else {
                    1.0
                },
            ),
            i_ms: Svf::new(2.0, dt)?,
            i_ms_state: SvfState::default(),
            seq: Positive::new(2.0, dt)?,
            seq_v: Positive::new(2.0, dt)?,
            last_t: None,
            w_ref: Svf::new(REFERENCE_FC_HZ, dt)?,
            w_ref_state: SvfState::at(core::f32::consts::TAU * f0),
            theta_ref: 0.0,
            osc_pll: Oscillator::default(),
            osc_ref: Oscillator::default(),
            offset: 0.0,
            w0: std::f64::consts::TAU * params.supply.f_hz,
            window_len: ((WINDOW_PERIODS * sample_rate_hz / params.supply.f_hz).round() as u32)
                .max(monitor_core::sequence::PHASOR_FIT_MIN_SAMPLES),
            open: OpenWindow::new(),
            closed: VecDeque::new(),
            rotor: super::rotor::RotorFront::new(
                sample_rate_hz,
                params.supply.f_hz,
                super::rotor::MAX_STRETCH_S,
            ),
        })
    }

    /// Feeds one row at `t` [s since the first row]. A row with a bad current is held out
    /// (the monitor holds such samples out itself); a bad voltage leaves the voltages'
    /// analysis alone.
    pub fn track(&mut self, row: &Row, t: f64) -> SequenceStep {
        let (filled, closed_before) = self.bridge(t);
        let mut step = SequenceStep {
            closed_before,
            ..SequenceStep::default()
        };
        self.theta_ref = monitor_core::frames::wrap_angle(
            self.theta_ref + self.w_ref_state.y() * self.dt_s as f32,
        );
        self.offset += (f64::from(self.w_ref_state.y()) - self.w0) * self.dt_s;
        self.offer_window_sample(t);
        let ok = |x: &[f64; 3], max: f64| x.iter().all(|v| v.is_finite() && v.abs() <= max);
        let abc = |x: &[f64; 3]| Abc {
            a: x[0] as f32,
            b: x[1] as f32,
            c: x[2] as f32,
        };
        if ok(&row.i_abc, self.i_max) {
            let i_abc = abc(&row.i_abc);
            let v_abc = row
                .v_abc
                .as_ref()
                .filter(|v| self.voltages && ok(v, self.v_max))
                .map(abc);
            if self.voltages && v_abc.is_none() {
                self.open.bad_v += 1;
            }
            let (sc_pll, sc) = (
                self.osc_pll.at(self.pll.theta_pll()),
                self.osc_ref.at(self.theta_ref),
            );
            let i = clarke(i_abc);
            self.filtered(i, v_abc.map(clarke), filled, sc_pll);
            self.rotor.row(Some(i), sc, t, self.offset, row);
            self.open.fit_i.update(sc, i_abc);
            if let Some(v) = v_abc {
                self.open.fit_v.update(sc, v);
            }
        } else {
            self.rotor.row(None, SinCos::default(), t, self.offset, row);
        }
        self.rotor.end_of_row(self.w_ref_state.y());
        if self.open.offered >= self.window_len {
            self.close_window();
            step.closed_after = true;
        }
        step.i = self.seq.value();
        step.v = self.seq_v.value();
        step.we_rad_s = self.pll.omega_rad_s();
        step
    }

    /// Samples missing from the stream before the row at `t` [s]: the angles advance over
    /// the missing time at their frequency (as the monitor's frame does), so that the
    /// sequences stay put; a gap the data-quality stage does not bridge ends the window.
    /// Returns the samples to fill in (up to [`FILLED_SAMPLES`]) and whether the window
    /// was closed.
    fn bridge(&mut self, t: f64) -> (usize, bool) {
        let Some(prev) = self.last_t.replace(t) else {
            return (0, false);
        };
        let missing = t - prev - self.dt_s;
        if missing > 0.5 * self.dt_s && missing <= MAX_BRIDGED_GAP_S {
            self.pll.skip(missing as f32);
            self.theta_ref = monitor_core::frames::wrap_angle(
                self.theta_ref + self.w_ref_state.y() * missing as f32,
            );
            self.offset += (f64::from(self.w_ref_state.y()) - self.w0) * missing;
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
            self.rotor.break_off();
            return (0, true);
        }
        (0, false)
    }

    /// Counts a sample into the open window (its time span, the reference's frequency).
    fn offer_window_sample(&mut self, t: f64) {
        let w = self.w_ref_state.y();
        let o = &mut self.open;
        if o.offered == 0 {
            o.from_s = t;
        }
        o.offered += 1;
        o.to_s = t;
        o.w_sum += f64::from(w);
        o.offset_sum += self.offset;
        o.w_min = o.w_min.min(w);
        o.w_max = o.w_max.max(w);
    }

    /// The PLL and the filtered sequences (the isolation's steady point) of the current
    /// vector `i` and the voltage vector `v`; the reference frequency follows the PLL's.
    /// `sc` is the sin/cos of the PLL's angle.
    fn filtered(&mut self, i: AlphaBeta, v: Option<AlphaBeta>, filled: usize, sc: SinCos) {
        match v {
            Some(v) if self.pll_on_voltage => {
                self.pll.update(v, sc);
            }
            _ => {
                let m2 = i.alpha * i.alpha + i.beta * i.beta;
                if self.i_ms_state.y() <= 0.0 {
                    // The first good sample: the loop starts on the current vector.
                    self.i_ms_state.set_y(m2);
                    self.pll.align(i.beta.atan2(i.alpha));
                }
                self.i_ms.update(&mut self.i_ms_state, m2);
                let k = 1.0 / monitor_core::math::sqrt(self.i_ms_state.y().max(1e-12));
                self.pll.update(
                    AlphaBeta {
                        alpha: i.alpha * k,
                        beta: i.beta * k,
                    },
                    sc,
                );
            }
        }
        self.w_ref
            .update(&mut self.w_ref_state, self.pll.omega_rad_s());
        // A few missing samples: the sequence filters get the vectors turned back to the
        // missing instants (a filter that skips a sample of the other sequence's 2f image
        // keeps an error of about that sample's share).
        let w_dt = self.pll.omega_rad_s() * self.dt_s as f32;
        for j in (1..=filled).rev() {
            let back = SinCos::from_angle(j as f32 * w_dt);
            let turn = |x: AlphaBeta| {
                let d = park(x, back);
                AlphaBeta {
                    alpha: d.d,
                    beta: d.q,
                }
            };
            let sc_j = SinCos::from_angle(self.pll.theta_pll() - j as f32 * w_dt);
            self.seq.update(turn(i), sc_j);
            if let Some(v) = v {
                self.seq_v.update(turn(v), sc_j);
            }
        }
        self.seq.update(i, sc);
        if let Some(v) = v {
            self.seq_v.update(v, sc);
        }
    }

    /// Ends the open window: solves its fits and queues it for the book (`None` when it
    /// has no solution).
    fn close_window(&mut self) {
        let o = std::mem::replace(&mut self.open, OpenWindow::new());
        self.closed.push_back(self.solved(&o));
    }

    /// The window `o` solved, `None` when empty or without a solution. (The learning flag
    /// and the monitor's speed are the book's.)
    fn solved(&self, o: &OpenWindow) -> Option<SequenceWindow> {
        if o.offered == 0 {
            return None;
        }
        let i = o.fit_i.solve()?;
        let w_mean = (o.w_sum / f64::from(o.offered)) as f32;
        let complete = f64::from(i.samples) >= MIN_WINDOW_FILL * f64::from(self.window_len);
        let steady =
            complete && w_mean > 0.0 && (o.w_max - o.w_min) <= STEADY_FREQUENCY_RANGE * w_mean;
        Some(SequenceWindow {
            from_s: o.from_s,
            to_s: o.to_s,
            i,
            v: (self.voltages && o.bad_v == 0)
                .then(|| o.fit_v.solve())
                .flatten(),
            we_rad_s: w_mean,
            offset_rad: o.offset_sum / f64::from(o.offered),
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

/// One phase's sensor gain error in a set of phasors (the zero sequence,
/// [`single_phase_gain`]), evidence from [`SENSOR_PHASE_MIN_RATIO`] on: `p`, `n`, `z` the
/// positive, negative and zero sequences with one rotation.
pub(super) fn sensor_phase(p: Complex32, n: Complex32, z: Complex32) -> Option<SinglePhaseGain> {
    single_phase_gain(p, n, z, SENSOR_PHASE_MIN_RATIO)
}
