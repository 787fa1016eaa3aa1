//! Offset trim at start-up: the zero of each of the six analog channels measured while the
//! motor is off.
//!
//! The front end's zero (0 V, 0 A) is nominally at mid-scale (code 2047.5) or at the motor
//! record's offsets; amplifier offsets and reference tolerances move it by a few codes,
//! which the residuals read as a small steady error. For the first [`TRIM_SAMPLES`] samples
//! after boot the sample task adds every trigger's codes to an [`OffsetTrim`] (the monitor
//! runs as usual meanwhile); then each channel's mean and spread decide
//! ([`ChannelTrim`]):
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
//! Bounded work: six additions and six multiply-adds per sample for [`TRIM_SAMPLES`]
//! samples, then nothing.

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

/// The trim of the six channels.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TrimResult {
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

/// The accumulator: sums and sums of squares of the six channels' codes (exact integers).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct OffsetTrim {
    sum: [u32; 6],
    sum_sq: [u64; 6],
    n: u32,
    done: bool,
    /// The zeros in force, codes: va, vb, vc, ia, ib, ic.
    nominal: [f32; 6],
}

impl OffsetTrim {
    /// An empty accumulator judging against `front_end`'s zeros.
    pub fn new(front_end: &FrontEnd) -> Self {
        let [va, vb, vc] = front_end.voltage;
        let [ia, ib, ic] = front_end.current;
        Self {
            sum: [0; 6],
            sum_sq: [0; 6],
            n: 0,
            done: false,
            nominal: [va, vb, vc, ia, ib, ic].map(|c| c.offset_code),
        }
    }

    /// Adds one trigger's codes; returns the result at the [`TRIM_SAMPLES`]th call, `None`
    /// before and after.
    pub fn add(&mut self, raw: &RawFrame) -> Option<TrimResult> {
        if self.done {
            return None;
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
        self.done = true;
        let ch = |k: usize| {
            let (s, q, zero) = (
                self.sum.get(k).copied().unwrap_or(0),
                self.sum_sq.get(k).copied().unwrap_or(0),
                self.nominal.get(k).copied().unwrap_or(MID_SCALE_CODE),
            );
            judge(s, q, self.n, zero)
        };
        Some(TrimResult {
            voltage: [ch(0), ch(1), ch(2)],
            current: [ch(3), ch(4), ch(5)],
        })
    }
}

/// One channel from its sum, sum of squares and count (`n > 0`): mean and spread in codes,
/// then the bounds around `zero`, the zero in force.
fn judge(sum: u32, sum_sq: u64, n: u32, zero: f32) -> ChannelTrim {
    let n64 = u64::from(n.max(1));
    let s = u64::from(sum);
    // n^2 var = n sum_sq - sum^2, exact in integers (>= 0 for any real data).
    let n2_var = n64.saturating_mul(sum_sq).saturating_sub(s * s);
    let spread = monitor_core::math::sqrt(n2_var as f32) / n64 as f32;
    let mean = sum as f32 / n64 as f32;
    if spread > QUIET_SPREAD_CODES {
        ChannelTrim::NotQuiet(spread)
    } else if (mean - zero).abs() > MAX_OFFSET_CODES {
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
        RawFrame {
            v: v.map(VoltageCode),
            i: i.map(CurrentCode),
            encoder_count: 0,
            clipped: crate::sampling::Clipped::NONE,
            encoder_rejects: 0,
        }
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
        // Done once.
        assert_eq!(trim.add(&frame([2047; 3], [2047; 3])), None);
    }

    #[test]
    fn the_bounds_are_inclusive_and_a_rail_is_out_of_bound() {
        let half = MID_SCALE_CODE;
        assert!(matches!(judge(0, 0, 10, half), ChannelTrim::OutOfBound(_)));
        let at = |code: u32| judge(code * 10, u64::from(code * code) * 10, 10, half);
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
        let at_500 = |code: u32| judge(code * 10, u64::from(code * code) * 10, 10, 500.0);
        assert_eq!(at_500(560), ChannelTrim::Trimmed(560.0));
        assert_eq!(at_500(2048), ChannelTrim::OutOfBound(2048.0));
    }
}
