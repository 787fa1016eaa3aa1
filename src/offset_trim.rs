//! Offset trim: the zero of each of the six analog channels measured while the motor is
//! off, at start-up and again whenever the shaft stands and the currents are zero.
//!
//! The front end's zero (0 V, 0 A) is nominally at mid-scale (code 2047.5) or at the motor
//! record's offsets; amplifier offsets and reference tolerances move it by a few codes,
//! which the residuals read as a small steady error, and it drifts with temperature and
//! the supply over a year. For the first [`TRIM_SAMPLES`] samples after boot the sample
//! task adds every trigger's codes to an [`OffsetTrim`] (the monitor runs as usual
//! meanwhile); then each channel's mean and spread decide ([`ChannelTrim`]):
//! - **quiet** (spread <= [`QUIET_SPREAD_CODES`]: the motor is off, no supply on the voltage
//!   inputs) and within [`MAX_OFFSET_CODES`] of the zero in force (the motor record's
//!   offset, mid-scale for the built-in default): the mean is the channel's new
//!   offset, put into force in the sample path's front end for this run
//!   ([`crate::app::SamplePath::apply_trim`]) and logged, so it can be written into the
//!   parameter file for the motor record;
//! - quiet but **out of bound**: the sensor or its supply is faulty; the offset is not used
//!   and the channel's sensor is flagged (the FAULT lamp steady, "input invalid", and
//!   `sens=` on the status line);
//! - **not quiet** (the motor was running, or mains on the voltage inputs): nothing is
//!   measured, the record's offsets stay.
//!
//! **The re-trim** ([`TrimKind::Retrim`]). After the start-up trim the accumulator runs on:
//! every window of [`TRIM_SAMPLES`] samples in which the shaft stood (the encoder's count
//! within [`STANDSTILL_COUNTS`] of the window's first; a turn starts the window again) is
//! judged again, but only when all three currents are zero (each current channel quiet and
//! within [`RETRIM_STEP_CODES`] of its zero in force: a standing motor that carries a
//! current, DC braking or a held load, is no zero): then every quiet channel within that
//! step of its zero in force is trimmed again (the voltages too, when no supply is on them).
//! A zero that moved further is [`ChannelTrim::TooFar`]: not used, not flagged (only the
//! start-up trim flags a sensor). The zeros follow a slow drift in steps of at most
//! [`RETRIM_STEP_CODES`].
//!
//! **Bounded against the factory zero.** Judged against the zero in force alone, a current
//! that creeps up by less than a step a window (a drive's DC hold ramped slowly at
//! standstill) would drag the zero along, 20 codes every 0.1 s, without end. So a re-trim is
//! also judged against the **factory zero**, the motor record's (mid-scale for the built-in
//! default), which no trim moves: a zero farther than [`MAX_OFFSET_CODES`] from it (where the
//! start-up trim would call the sensor faulty) is [`ChannelTrim::TooFar`], and a zero within
//! [`RETRIM_STEP_CODES`] of it is taken whatever the zero in force (so a zero a creeping
//! current dragged comes back in one window once the current is gone).
//!
//! Bounded work: six additions, six multiply-adds and a count's comparison per sample.

use crate::board::{FrontEnd, MID_SCALE_CODE};
use crate::sampling::RawFrame;

/// Samples the trim averages: 0.1 s at 10 kHz, five periods of a 50 Hz supply (so a
/// running motor or the mains cannot look quiet).
pub const TRIM_SAMPLES: u32 = 1_000;
/// Largest spread (standard deviation) of a quiet channel, ADC codes: the front end's noise
/// is 1-3 codes; a 1 % sine of full scale has a spread of 29 codes.
pub const QUIET_SPREAD_CODES: f32 = 8.0;
/// Largest distance of a trimmed offset from the zero in force (the motor record's offset,
/// mid-scale by default), ADC codes (100 codes: 2.4 % of the range, about 10 V or 0.24 A
/// with the default front end); beyond it the sensor is flagged instead.
pub const MAX_OFFSET_CODES: f32 = 100.0;
/// Largest step of a re-trim from the zero in force [codes]: 20 codes (about 4 V, 0.1 A with
/// the default front end), far beyond a drift between two standstills, far below a current
/// a standing motor may carry.
pub const RETRIM_STEP_CODES: f32 = 20.0;
/// The encoder's count may move this many counts in a window and the shaft still stands
/// (one count of jitter at an edge).
pub const STANDSTILL_COUNTS: u16 = 1;
/// A re-trim that moves no zero by this much [codes] is not reported (nothing to log).
pub const REPORT_STEP_CODES: f32 = 0.5;

/// What the trim found for one channel.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum ChannelTrim {
    /// Quiet and within bounds: the measured zero, codes.
    Trimmed(f32),
    /// Quiet but farther than [`MAX_OFFSET_CODES`] from the zero in force: the measured
    /// zero, codes (not used; the sensor is flagged).
    OutOfBound(f32),
    /// Not quiet: the measured spread, codes (nothing trimmed).
    NotQuiet(f32),
    /// A re-trim: quiet, but farther than [`RETRIM_STEP_CODES`] from the zero in force: the
    /// measured zero, codes (not used, not flagged).
    TooFar(f32),
}

impl ChannelTrim {
    /// The offset to use, if any.
    pub fn offset(&self) -> Option<f32> {
        match self {
            ChannelTrim::Trimmed(x) => Some(*x),
            _ => None,
        }
    }

    /// The channel's sensor is faulty.
    pub fn out_of_bound(&self) -> bool {
        matches!(self, ChannelTrim::OutOfBound(_))
    }
}

/// Which trim a result is.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum TrimKind {
    /// The first window after boot (a channel out of bound is flagged).
    StartUp,
    /// A later window, the shaft standing and the currents zero.
    Retrim,
}

/// The trim of the six channels.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TrimResult {
    /// The start-up trim or a re-trim.
    pub kind: TrimKind,
    /// Voltage channels a, b, c.
    pub voltage: [ChannelTrim; 3],
    /// Current channels a, b, c.
    pub current: [ChannelTrim; 3],
}

impl TrimResult {
    /// A voltage channel's offset was out of bound.
    pub fn voltage_fault(&self) -> bool {
        self.voltage.iter().any(ChannelTrim::out_of_bound)
    }

    /// A current channel's offset was out of bound.
    pub fn current_fault(&self) -> bool {
        self.current.iter().any(ChannelTrim::out_of_bound)
    }
}

/// The accumulator: sums and sums of squares of the six channels' codes (exact integers)
/// over the current window.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct OffsetTrim {
    sum: [u32; 6],
    sum_sq: [u64; 6],
    n: u32,
    /// The start-up trim is done: the windows are re-trims.
    started: bool,
    /// The window's first encoder count (re-trims: the shaft must stand).
    first_count: Option<u16>,
    /// The zeros in force, codes: va, vb, vc, ia, ib, ic (the record's, then the trims').
    nominal: [f32; 6],
    /// The factory zeros, codes: the record's, which no trim moves (module docs).
    factory: [f32; 6],
}

impl OffsetTrim {
    /// An empty accumulator judging against `front_end`'s zeros.
    pub fn new(front_end: &FrontEnd) -> Self {
        let [va, vb, vc] = front_end.voltage;
        let [ia, ib, ic] = front_end.current;
        let zeros = [va, vb, vc, ia, ib, ic].map(|c| c.offset_code);
        Self {
            sum: [0; 6],
            sum_sq: [0; 6],
            n: 0,
            started: false,
            first_count: None,
            nominal: zeros,
            factory: zeros,
        }
    }

    /// Starts a new window.
    fn restart(&mut self) {
        self.sum = [0; 6];
        self.sum_sq = [0; 6];
        self.n = 0;
        self.first_count = None;
    }

    /// Adds one sample's codes; returns the start-up trim at the [`TRIM_SAMPLES`]th call,
    /// then a re-trim at the end of each window in which the shaft stood and the currents
    /// were zero (module docs); `None` otherwise.
    pub fn add(&mut self, raw: &RawFrame) -> Option<TrimResult> {
        if self.started {
            let first = *self.first_count.get_or_insert(raw.encoder_count);
            let moved = (raw.encoder_count.wrapping_sub(first) as i16).unsigned_abs();
            if moved > STANDSTILL_COUNTS {
                self.restart();
                self.first_count = Some(raw.encoder_count);
            }
        }
        let codes = [
            raw.v[0].0, raw.v[1].0, raw.v[2].0, raw.i[0].0, raw.i[1].0, raw.i[2].0,
        ];
        for ((s, q), c) in self.sum.iter_mut().zip(self.sum_sq.iter_mut()).zip(codes) {
            *s = s.saturating_add(u32::from(c));
            *q = q.saturating_add(u64::from(c) * u64::from(c));
        }
        self.n += 1;
        if self.n < TRIM_SAMPLES {
            return None;
        }
        let kind = if self.started {
            TrimKind::Retrim
        } else {
            TrimKind::StartUp
        };
        let ch = |k: usize| {
            let (s, q) = (
                self.sum.get(k).copied().unwrap_or(0),
                self.sum_sq.get(k).copied().unwrap_or(0),
            );
            let zeros = Zeros {
                in_force: self.nominal.get(k).copied().unwrap_or(MID_SCALE_CODE),
                factory: self.factory.get(k).copied().unwrap_or(MID_SCALE_CODE),
            };
            judge(s, q, self.n, zeros, kind)
        };
        let result = TrimResult {
            kind,
            voltage: [ch(0), ch(1), ch(2)],
            current: [ch(3), ch(4), ch(5)],
        };
        self.started = true;
        self.restart();
        // A re-trim only where the currents are zero.
        let currents_zero = result.current.iter().all(|c| c.offset().is_some());
        if kind == TrimKind::Retrim && !currents_zero {
            return None;
        }
        let channels = result.voltage.iter().chain(result.current.iter());
        for (zero, channel) in self.nominal.iter_mut().zip(channels) {
            if let Some(x) = channel.offset() {
                *zero = x;
            }
        }
        Some(result)
    }
}

/// A channel's zeros, codes: the one in force and the factory's (module docs).
#[derive(Clone, Copy, Debug)]
struct Zeros {
    in_force: f32,
    factory: f32,
}

/// One channel from its sum, sum of squares and count (`n > 0`): mean and spread in codes,
/// then the bounds: at start-up [`MAX_OFFSET_CODES`] around the zero in force (the
/// record's); for a re-trim [`RETRIM_STEP_CODES`] around the zero in force or around the
/// factory zero, and never beyond [`MAX_OFFSET_CODES`] from the factory zero.
fn judge(sum: u32, sum_sq: u64, n: u32, zeros: Zeros, kind: TrimKind) -> ChannelTrim {
    let n64 = u64::from(n.max(1));
    let s = u64::from(sum);
    // n^2 var = n sum_sq - sum^2, exact in integers (>= 0 for any real data).
    let n2_var = n64.saturating_mul(sum_sq).saturating_sub(s * s);
    let spread = monitor_core::math::sqrt(n2_var as f32) / n64 as f32;
    let mean = sum as f32 / n64 as f32;
    let distance = (mean - zeros.in_force).abs();
    let from_factory = (mean - zeros.factory).abs();
    if spread > QUIET_SPREAD_CODES {
        ChannelTrim::NotQuiet(spread)
    } else if kind == TrimKind::Retrim {
        let step = distance <= RETRIM_STEP_CODES || from_factory <= RETRIM_STEP_CODES;
        if step && from_factory <= MAX_OFFSET_CODES {
            ChannelTrim::Trimmed(mean)
        } else {
            ChannelTrim::TooFar(mean)
        }
    } else if distance > MAX_OFFSET_CODES {
        ChannelTrim::OutOfBound(mean)
    } else {
        ChannelTrim::Trimmed(mean)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::board::{CurrentCode, VoltageCode};

    fn frame(v: [u16; 3], i: [u16; 3]) -> RawFrame {
        frame_at(v, i, 0)
    }

    fn frame_at(v: [u16; 3], i: [u16; 3], encoder_count: u16) -> RawFrame {
        RawFrame {
            v: v.map(VoltageCode),
            i: i.map(CurrentCode),
            encoder_count,
            clipped: crate::sampling::Clipped::NONE,
            encoder_rejects: 0,
        }
    }

    /// Both zeros at `x`.
    fn zeros(x: f32) -> Zeros {
        Zeros {
            in_force: x,
            factory: x,
        }
    }

    /// A drive's DC hold ramped slowly at standstill: `ia` up and `ib` down by 5 codes a
    /// window (each window within a step of the zero the last one put into force), to 400
    /// codes (2 A with the default front end). Judged against the zero in force alone the
    /// current zeros followed it all the way; bounded against the factory zero they stop
    /// within `MAX_OFFSET_CODES` of it (the re-trim is then dropped: the currents are not
    /// zero), the voltages' zeros stay, and once the current is gone the zeros come back to
    /// the factory zero in one window.
    #[test]
    fn a_slow_dc_current_at_standstill_cannot_drag_the_zeros() {
        let mut trim = OffsetTrim::new(&FrontEnd::DEFAULT);
        let factory = MID_SCALE_CODE;
        let window = |trim: &mut OffsetTrim, i: [u16; 3]| {
            let mut got = None;
            for _ in 0..TRIM_SAMPLES {
                got = got.or(trim.add(&frame_at([2048; 3], i, 500)));
            }
            got
        };
        assert_eq!(
            window(&mut trim, [2048; 3]).map(|r| r.kind),
            Some(TrimKind::StartUp)
        );
        let mut farthest = 0.0f32;
        let mut retrims = 0;
        for w in 1..=80u16 {
            let dc = 5 * w;
            if let Some(r) = window(&mut trim, [2048 + dc, 2048 - dc, 2048]) {
                retrims += 1;
                for c in r.current {
                    if let Some(x) = c.offset() {
                        farthest = farthest.max((x - factory).abs());
                    }
                }
            }
        }
        let in_force = |t: &OffsetTrim| t.nominal.map(|z| (z - factory).abs());
        assert!(farthest <= MAX_OFFSET_CODES, "{farthest}");
        assert!(
            in_force(&trim).iter().all(|d| *d <= MAX_OFFSET_CODES),
            "{:?}",
            trim.nominal
        );
        // It followed while within the bound (a slow drift is still followed) ...
        assert!(
            retrims >= 19 && farthest >= MAX_OFFSET_CODES - 5.0,
            "{retrims} {farthest}"
        );
        // ... and comes back once the current is gone.
        let back = window(&mut trim, [2048; 3]).expect("a re-trim at the factory zero");
        assert!(
            back.current
                .iter()
                .all(|c| *c == ChannelTrim::Trimmed(2048.0)),
            "{back:?}"
        );
        assert!(
            in_force(&trim).iter().all(|d| *d <= 0.5),
            "{:?}",
            trim.nominal
        );
    }

    #[test]
    fn quiet_channels_are_trimmed_out_of_bound_ones_flagged_running_ones_left() {
        let mut trim = OffsetTrim::new(&FrontEnd::DEFAULT);
        let mut result = None;
        for k in 0..TRIM_SAMPLES {
            // +-1 code of noise around 2050 / 2040; a dead sensor at 1800 (ib); a 50 Hz
            // sine of 300 codes on vc (the mains).
            let noise = (k % 3) as u16; // 0, 1, 2
            let t = k as f32 / 10_000.0;
            let sine = 2047.5 + 300.0 * (std::f32::consts::TAU * 50.0 * t).sin();
            let r = trim.add(&frame(
                [2049 + noise, 2046 + noise, sine as u16],
                [2039 + noise, 1800, 2047],
            ));
            assert_eq!(r.is_some(), k + 1 == TRIM_SAMPLES, "{k}");
            result = result.or(r);
        }
        let r = result.unwrap();
        // The noise 0, 1, 2 repeated (334 x 0, 333 x 1, 333 x 2): +0.999 on average.
        assert!(matches!(r.voltage[0], ChannelTrim::Trimmed(x) if (x - 2050.0).abs() < 0.01));
        assert!(matches!(r.voltage[1], ChannelTrim::Trimmed(x) if (x - 2047.0).abs() < 0.01));
        assert!(matches!(r.voltage[2], ChannelTrim::NotQuiet(s) if (s - 212.1).abs() < 2.0));
        assert!(matches!(r.current[0], ChannelTrim::Trimmed(x) if (x - 2040.0).abs() < 0.01));
        assert_eq!(r.current[1], ChannelTrim::OutOfBound(1800.0));
        assert_eq!(r.current[2], ChannelTrim::Trimmed(2047.0));
        assert!(r.current_fault() && !r.voltage_fault());
        assert_eq!(r.voltage[2].offset(), None);
        assert_eq!(r.current[1].offset(), None);
        assert_eq!(r.kind, TrimKind::StartUp);
        // Then a re-trim, not another start-up trim.
        assert_eq!(trim.add(&frame([2047; 3], [2047; 3])), None);
    }

    /// The zero drifts by 30 codes over the first hour; the shaft stands now and then with
    /// the currents zero: every standstill re-trims, in steps of at most 20 codes, and the
    /// zeros follow. A window in which the shaft turns, or a current flows, re-trims nothing.
    #[test]
    fn the_zeros_are_re_trimmed_whenever_the_shaft_stands_and_the_currents_are_zero() {
        let mut trim = OffsetTrim::new(&FrontEnd::DEFAULT);
        let at = |zero: u16, count: u16| frame_at([zero; 3], [zero; 3], count);
        let mut last = None;
        for _ in 0..TRIM_SAMPLES {
            last = last.or(trim.add(&at(2048, 0)));
        }
        assert_eq!(last.map(|r| r.kind), Some(TrimKind::StartUp));
        // Standstills at a zero 15, then 30 codes away.
        for zero in [2063u16, 2078] {
            let mut got = None;
            for _ in 0..TRIM_SAMPLES {
                got = got.or(trim.add(&at(zero, 500)));
            }
            let r = got.expect("a re-trim at standstill");
            assert_eq!(r.kind, TrimKind::Retrim);
            assert!(
                r.voltage
                    .iter()
                    .chain(r.current.iter())
                    .all(|c| *c == ChannelTrim::Trimmed(f32::from(zero))),
                "{r:?}"
            );
        }
        // The shaft turns: the window starts again at every step, nothing judged.
        for k in 0..3 * TRIM_SAMPLES {
            assert_eq!(trim.add(&at(2078, (k * 7) as u16)), None);
        }
        // A current of 30 codes (0.15 A) through a standing motor: no re-trim.
        let mut got = None;
        for _ in 0..2 * TRIM_SAMPLES {
            got = got.or(trim.add(&frame_at([2078; 3], [2108, 2048, 2078], 900)));
        }
        assert_eq!(got, None);
        // A zero that jumped 40 codes: too far for one step, not flagged.
        let mut got = None;
        for _ in 0..TRIM_SAMPLES {
            got = got.or(trim.add(&frame_at([2118; 3], [2078; 3], 900)));
        }
        let r = got.unwrap();
        assert_eq!(r.voltage[0], ChannelTrim::TooFar(2118.0));
        assert!(!r.voltage_fault() && !r.current_fault());
    }

    #[test]
    fn the_bounds_are_inclusive_and_a_rail_is_out_of_bound() {
        let half = MID_SCALE_CODE;
        assert!(matches!(
            judge(0, 0, 10, zeros(half), TrimKind::StartUp),
            ChannelTrim::OutOfBound(_)
        ));
        let at = |code: u32| {
            judge(
                code * 10,
                u64::from(code * code) * 10,
                10,
                zeros(half),
                TrimKind::StartUp,
            )
        };
        assert!(matches!(
            at((half + MAX_OFFSET_CODES - 0.5) as u32),
            ChannelTrim::Trimmed(_)
        ));
        assert!(matches!(
            at((half + MAX_OFFSET_CODES + 1.5) as u32),
            ChannelTrim::OutOfBound(_)
        ));
        assert!(matches!(at(4095), ChannelTrim::OutOfBound(_)));
        // The bound is around the zero in force (a record's offset), not mid-scale.
        let at_500 = |code: u32| {
            judge(
                code * 10,
                u64::from(code * code) * 10,
                10,
                zeros(500.0),
                TrimKind::StartUp,
            )
        };
        assert_eq!(at_500(560), ChannelTrim::Trimmed(560.0));
        assert_eq!(at_500(2048), ChannelTrim::OutOfBound(2048.0));
    }

    /// The bounds exactly: a spread of exactly `QUIET_SPREAD_CODES` is quiet, a zero exactly
    /// `MAX_OFFSET_CODES` away is trimmed; a voltage channel out of bound is flagged as a
    /// voltage fault, not a current one.
    #[test]
    fn the_bounds_hold_exactly_and_a_voltage_out_of_bound_is_a_voltage_fault() {
        // Codes alternating 2040 and 2056: mean 2048, spread exactly 8.
        let n = 1_000u32;
        let (lo, hi) = (2040u64, 2056u64);
        let sum = n / 2 * (2040 + 2056);
        let sum_sq = u64::from(n / 2) * (lo * lo + hi * hi);
        assert_eq!(
            judge(sum, sum_sq, n, zeros(2048.0), TrimKind::StartUp),
            ChannelTrim::Trimmed(2048.0)
        );
        // A zero exactly 100 codes from the one in force.
        let at = |code: u64| (code as u32 * n, code * code * u64::from(n));
        let (s100, q100) = at(2148);
        assert_eq!(
            judge(s100, q100, n, zeros(2048.0), TrimKind::StartUp),
            ChannelTrim::Trimmed(2148.0)
        );
        // Voltage a at the rail at start-up: a voltage fault.
        let mut trim = OffsetTrim::new(&FrontEnd::DEFAULT);
        let mut got = None;
        for _ in 0..TRIM_SAMPLES {
            got = got.or(trim.add(&frame([4095, 2048, 2048], [2048; 3])));
        }
        let r = got.unwrap();
        assert!(r.voltage_fault() && !r.current_fault(), "{r:?}");
    }

    /// One count of jitter at an encoder edge is a standing shaft: the window goes on and
    /// the zeros are re-trimmed.
    #[test]
    fn one_count_of_jitter_is_a_standing_shaft() {
        let mut trim = OffsetTrim::new(&FrontEnd::DEFAULT);
        for _ in 0..TRIM_SAMPLES {
            trim.add(&frame_at([2048; 3], [2048; 3], 100));
        }
        let mut got = None;
        for k in 0..TRIM_SAMPLES {
            got = got.or(trim.add(&frame_at([2050; 3], [2050; 3], 100 + (k % 2) as u16)));
        }
        assert_eq!(got.map(|r| r.kind), Some(TrimKind::Retrim));
    }
}
