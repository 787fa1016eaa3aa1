//! One trigger's ADC codes and encoder count -> the core's [`Sample`].
//!
//! The ADCs deliver, per trigger, three voltage codes (ADC1) and three current codes
//! (ADC2); the encoder timer delivers its 16-bit counter. [`AdcSampler`] scales the
//! codes with the board's [`FrontEnd`], marks a clipped sample (a conversion beyond its
//! channel's linear range, or a code on a rail) as clipped for the core, which holds it out
//! and names no sensor, passes the raw counter on (the core unwraps it,
//! `EncoderConfig::counter_bits = 16`) and stamps the sample with a free-running timestamp
//! in ticks of [`TICK_HZ`].
//!
//! Timestamps: samples are taken by a hardware timer at an exact rate, so the timestamp of
//! sample `n` is `n * ticks_per_sample` (wrapping `u32`). When samples were lost (a DMA
//! overrun), the firmware calls [`AdcSampler::resync`] with the current time so the gap
//! shows up in the timestamps instead of silently compressing time.

use crate::board::{is_saturated_code, CurrentCode, FrontEnd, VoltageCode};
use monitor_core::{Abc, Sample};

/// Timestamp tick rate, Hz (1 MHz: one tick per microsecond; wraps after 71.6 min,
/// which the core's wrapping differences handle).
pub const TICK_HZ: u32 = 1_000_000;

/// Raw readings of one sample (on the board the mean of its oversampled sequences,
/// filtered: `crate::acquisition`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct RawFrame {
    /// Voltage codes of phases a, b, c (ADC1 ranks 1..3).
    pub v: [VoltageCode; 3],
    /// Current codes of phases a, b, c (ADC2 ranks 1..3).
    pub i: [CurrentCode; 3],
    /// TIM4 counter (x4 quadrature, 16 bit, wraps).
    pub encoder_count: u16,
    /// Which of the sample's channels had a conversion at the front end's linear limit
    /// (on the board each conversion is checked, `acquisition::sum_clipped`, and the
    /// flag held through the filter's memory, `acquisition::ClipHold`).
    pub clipped: Clipped,
    /// The sample's latched encoder counts rejected as a step beyond the maximum speed
    /// (`acquisition::EncoderCheck`; 0..=8).
    pub encoder_rejects: u8,
}

/// Which channels of one sample were clipped: a conversion at or beyond the front end's
/// linear limit (`acquisition::LinearRange`). A clipped sample goes to the core as clipped
/// (`Sample::clipped`): its block is held out of the filters and the residuals, and no
/// sensor is named (a DOL start's inrush clips a current front end sized for the running
/// current); the sample path counts it, and thread mode judges whether clipping persists
/// in steady running (`crate::clip_watch`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Clipped {
    /// A voltage channel (ADC1).
    pub voltage: bool,
    /// A current channel (ADC2).
    pub current: bool,
}

impl Clipped {
    /// No channel clipped.
    pub const NONE: Clipped = Clipped {
        voltage: false,
        current: false,
    };

    /// Whether any channel clipped.
    pub const fn any(self) -> bool {
        self.voltage | self.current
    }
}

impl RawFrame {
    /// Which front ends clipped in this frame: its flags (the per-conversion check), or a
    /// code on a rail (a frame built without the check: the mean of eight conversions on the
    /// rail clipped them all).
    #[inline]
    pub fn clips(&self) -> Clipped {
        Clipped {
            voltage: self.clipped.voltage || self.v.iter().any(|c| is_saturated_code(c.0)),
            current: self.clipped.current || self.i.iter().any(|c| is_saturated_code(c.0)),
        }
    }
}

/// Why a sampling configuration was rejected.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SamplingError {
    /// The rate is 0, above 100 kHz, or does not divide [`TICK_HZ`] (timestamps would
    /// drift).
    Rate,
}

/// Converts [`RawFrame`]s (ADC codes and the encoder counter) to [`Sample`]s: the
/// firmware's sampler (the host's counterpart for log rows is `monitor_replay::LogSampler`).
/// No panics, no allocation.
#[derive(Clone, Copy, Debug)]
pub struct AdcSampler {
    front_end: FrontEnd,
    ticks_per_sample: u32,
    next_ticks: u32,
}

impl AdcSampler {
    /// A builder for `sample_rate_hz` (must divide [`TICK_HZ`], 1..=100 000 Hz).
    ///
    /// # Errors
    /// [`SamplingError::Rate`] otherwise.
    pub fn new(front_end: FrontEnd, sample_rate_hz: u32) -> Result<Self, SamplingError> {
        if sample_rate_hz == 0
            || sample_rate_hz > 100_000
            || !TICK_HZ.is_multiple_of(sample_rate_hz)
        {
            return Err(SamplingError::Rate);
        }
        Ok(Self {
            front_end,
            ticks_per_sample: TICK_HZ / sample_rate_hz,
            next_ticks: 0,
        })
    }

    /// Ticks between two samples.
    pub fn ticks_per_sample(&self) -> u32 {
        self.ticks_per_sample
    }

    /// The front end's scaling in force.
    pub fn front_end(&self) -> &FrontEnd {
        &self.front_end
    }

    /// Replaces the front end's scaling (a start-up offset trim,
    /// `crate::app::SamplePath::trim_offsets`).
    pub fn set_front_end(&mut self, front_end: FrontEnd) {
        self.front_end = front_end;
    }

    /// Skips one sample's timestamp (a sample dropped, `adc_rules::IdleDiscard`).
    pub fn skip(&mut self) {
        self.next_ticks = self.next_ticks.wrapping_add(self.ticks_per_sample);
    }

    /// Continue the timestamps from `now_ticks` (after lost samples).
    pub fn resync(&mut self, now_ticks: u32) {
        self.next_ticks = now_ticks;
    }

    /// Scale one frame and stamp it; a frame that clipped ([`RawFrame::clips`]) goes to the
    /// core as clipped. The board never flags an ADC as saturated: a code on a rail is the
    /// front end's clip (held out, no sensor named), and what a sensor's impossible
    /// readings look like the core finds from the values (out of range, the sums).
    #[inline]
    pub fn build(&mut self, raw: &RawFrame) -> Sample {
        let [va, vb, vc] = raw.v;
        let [ia, ib, ic] = raw.i;
        let [sva, svb, svc] = self.front_end.voltage;
        let [sia, sib, sic] = self.front_end.current;
        let ts = self.next_ticks;
        self.next_ticks = ts.wrapping_add(self.ticks_per_sample);
        Sample {
            v_abc: Abc {
                a: sva.apply(va.0),
                b: svb.apply(vb.0),
                c: svc.apply(vc.0),
            },
            i_abc: Abc {
                a: sia.apply(ia.0),
                b: sib.apply(ib.0),
                c: sic.apply(ic.0),
            },
            encoder_count: u32::from(raw.encoder_count),
            timestamp_ticks: ts,
            v_saturated: false,
            i_saturated: false,
            clipped: raw.clips().any(),
        }
    }

    /// The inverse used by simulations: quantize physical values to the codes this front
    /// end would produce (clamped to the 12-bit range: out-of-range values sit on a rail,
    /// which [`RawFrame::clips`] reads as clipped).
    pub fn quantize(&self, v_abc: Abc, i_abc: Abc, encoder_count: u32) -> RawFrame {
        let [sva, svb, svc] = self.front_end.voltage;
        let [sia, sib, sic] = self.front_end.current;
        RawFrame {
            v: [
                VoltageCode(sva.code_of(v_abc.a)),
                VoltageCode(svb.code_of(v_abc.b)),
                VoltageCode(svc.code_of(v_abc.c)),
            ],
            i: [
                CurrentCode(sia.code_of(i_abc.a)),
                CurrentCode(sib.code_of(i_abc.b)),
                CurrentCode(sic.code_of(i_abc.c)),
            ],
            // The hardware counter is 16 bits wide.
            encoder_count: (encoder_count & 0xFFFF) as u16,
            clipped: Clipped::NONE,
            encoder_rejects: 0,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rate_must_divide_tick() {
        assert!(AdcSampler::new(FrontEnd::DEFAULT, 10_000).is_ok());
        assert_eq!(
            AdcSampler::new(FrontEnd::DEFAULT, 7_000).err(),
            Some(SamplingError::Rate)
        );
        assert!(AdcSampler::new(FrontEnd::DEFAULT, 0).is_err());
    }

    #[test]
    fn timestamps_and_saturation() {
        let mut b = AdcSampler::new(FrontEnd::DEFAULT, 10_000).unwrap();
        b.resync(u32::MAX - 50);
        let raw = b.quantize(
            Abc {
                a: 100.0,
                b: -50.0,
                c: -50.0,
            },
            Abc {
                a: 20.0,
                b: 0.0,
                c: -1.0,
            },
            70_000,
        );
        let s = b.build(&raw);
        assert_eq!(s.timestamp_ticks, u32::MAX - 50);
        assert!((s.v_abc.a - 100.0).abs() < 0.1);
        // 20 A on the 10 A front end: on the rail, clipped, no ADC flagged saturated.
        assert!(s.clipped && !s.i_saturated && !s.v_saturated);
        assert_eq!(
            raw.clips(),
            Clipped {
                voltage: false,
                current: true
            }
        );
        assert_eq!(s.encoder_count, 70_000 & 0xFFFF);
        assert_eq!(b.build(&raw).timestamp_ticks, 49);
    }

    /// A clip seen in the conversions marks the sample clipped even where the filtered
    /// codes are inside the range (the mean of eight conversions, two of them clipped); it
    /// is never flagged saturated (which would name the sensor).
    #[test]
    fn a_clipped_sample_goes_to_the_core_clipped_not_saturated() {
        let mut b = AdcSampler::new(FrontEnd::DEFAULT, 10_000).unwrap();
        let mut raw = b.quantize(Abc::default(), Abc::default(), 0);
        assert!(!b.build(&raw).clipped);
        raw.clipped.current = true;
        let s = b.build(&raw);
        assert!(s.clipped && !s.i_saturated && !s.v_saturated);
    }

    /// A voltage conversion clipped (the per-conversion check's flag, the filtered codes
    /// inside the range) marks the sample clipped as a current one does; and both front
    /// ends clipped at once (a start's inrush on the current channels while a transient
    /// clips the voltage ones) too.
    #[test]
    fn a_voltage_clip_and_a_clip_on_both_front_ends_are_clipped() {
        let mut b = AdcSampler::new(FrontEnd::DEFAULT, 10_000).unwrap();
        let mut raw = b.quantize(Abc::default(), Abc::default(), 0);
        raw.clipped.voltage = true;
        assert_eq!(
            raw.clips(),
            Clipped {
                voltage: true,
                current: false
            }
        );
        assert!(b.build(&raw).clipped);
        raw.clipped.current = true;
        assert!(raw.clips().any());
        assert!(b.build(&raw).clipped);
    }

    /// A dropped sample keeps its place in time: sample `n`'s timestamp is `n` periods
    /// (100 us at 10 kHz) from the start, whether or not the ones before it were built.
    #[test]
    fn a_dropped_sample_keeps_its_place_in_time() {
        let mut b = AdcSampler::new(FrontEnd::DEFAULT, 10_000).unwrap();
        let raw = b.quantize(Abc::default(), Abc::default(), 0);
        assert_eq!(b.build(&raw).timestamp_ticks, 0);
        b.skip();
        assert_eq!(b.build(&raw).timestamp_ticks, 200);
        assert_eq!(b.build(&raw).timestamp_ticks, 300);
    }
}
