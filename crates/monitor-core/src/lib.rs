//! # monitor-core
//!
//! The numeric core of the induction-motor drive monitor: everything the firmware runs per
//! sample, `no_std`, no allocation, no reachable panic, single precision. The host harness
//! (`sim-host`) runs exactly this code in its tests and replays.
//!
//! Pipeline (see [`Monitor`]): phase voltages and currents → Clarke ([`frames`]) → frame
//! angle ([`angle`]: phase-a zero crossing, SRF-PLL, or rotor-flux current model) → Park →
//! filtered d-q quantities ([`filter`]) → parity-equation residuals of the paper's
//! simplified D-Q model ([`residuals`], eqs. 36-37) → thresholds with commissioning,
//! debounce and hysteresis ([`threshold`]) → lamps r1..r4 → fault signature matching
//! against Table 1 ([`signature`]). Beside it: encoder speed by the M/T method
//! ([`encoder`]) and the negative-sequence analysis that names a faulty phase
//! ([`sequence`]).
//!
//! Source: the paper in `shared/seed` ("the paper"); corrections in DESIGN.md §2 and in the
//! module docs ([`residuals`] lists the typos).
//!
//! ```
//! use monitor_core::{Abc, Fault, Monitor, MonitorConfig, MotorModel, Sample};
//! // The DESIGN.md 3 hp motor on 220 V, 60 Hz, sampled at 10 kHz.
//! let motor = MotorModel {
//!     rs_ohm: 0.435, rr_ohm: 0.816, ls_h: 0.0713, lr_h: 0.0713, lm_h: 0.0693,
//!     pole_pairs: 2, j_kgm2: 0.089, b_nms: 0.002, bl_nms: 0.045,
//! };
//! let mut monitor = Monitor::new(MonitorConfig::new(motor, 60.0, 220.0, 10_000.0))
//!     .expect("a valid configuration"); // ok: doc example
//! // A NaN current is an impossible reading: no panic, the current sensor is named
//! // at the end of the 25-sample block.
//! let bad = Sample { i_abc: Abc { a: f32::NAN, b: 0.0, c: 0.0 }, ..Sample::default() };
//! for _ in 0..25 {
//!     monitor.update(&bad);
//! }
//! assert_eq!(monitor.output().top(), Some((Fault::CurrentSensor, 1.0)));
//! ```
#![cfg_attr(not(test), no_std)]
#![forbid(unsafe_code)]
#![warn(missing_docs)]
// `!(x > 0.0)` is deliberate throughout: it is true for NaN, so bad values are rejected.
#![allow(clippy::neg_cmp_op_on_partial_ord, clippy::nonminimal_bool)]
// Tests may index, unwrap and panic: that is how they fail.
#![cfg_attr(
    test,
    allow(
        clippy::unwrap_used,
        clippy::expect_used,
        clippy::panic,
        clippy::indexing_slicing
    )
)]

pub mod angle;
pub mod encoder;
pub mod filter;
pub mod frames;
pub mod monitor;
pub mod residuals;
pub mod sequence;
pub mod signature;
pub mod threshold;

pub use angle::AngleSource;
pub use encoder::EncoderConfig;
pub use frames::{Abc, AlphaBeta, Dq, SinCos};
pub use monitor::{
    Commissioning, Monitor, MonitorConfig, MonitorOutput, ResidualForm, Sample, SensorFlags,
    SensorLimits,
};
pub use residuals::{MotorModel, Operating};
pub use sequence::{Phase, Unbalance};
pub use signature::{Diagnosis, Fault, FAULT_COUNT, ROTOR_FLUX_SIGNATURES, TABLE1};
pub use threshold::{Calibration, ThresholdConfig};

#[cfg(test)]
pub(crate) mod testing {
    //! Shared test fixtures.
    use crate::MotorModel;

    /// The DESIGN.md 3 hp textbook machine: Xls = Xlr = 0.754 ohm, Xm = 26.13 ohm at 60 Hz.
    pub(crate) fn motor_3hp() -> MotorModel {
        let w = 2.0 * core::f32::consts::PI * 60.0;
        MotorModel {
            rs_ohm: 0.435,
            rr_ohm: 0.816,
            ls_h: (26.13 + 0.754) / w,
            lr_h: (26.13 + 0.754) / w,
            lm_h: 26.13 / w,
            pole_pairs: 2,
            j_kgm2: 0.089,
            b_nms: 0.002,
            bl_nms: 0.045,
        }
    }
}

/// A configuration the monitor cannot run with, found when it is built. Small and `Copy`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[non_exhaustive]
pub enum ConfigError {
    /// A motor parameter is not positive/finite, or Lm^2 >= Ls Lr.
    MotorParameter,
    /// Sample or tick rate out of range, or below 8x the supply frequency.
    SampleRate,
    /// Supply frequency or voltage out of range.
    Supply,
    /// A filter corner is not positive or too high for the supply or sample rate.
    Filter,
    /// Decimation outside 1..=1000, or fewer than 6 blocks per supply period.
    Decimation,
    /// Encoder settings impossible (zero counts, counter width, windows, max speed).
    Encoder,
    /// Sensor limits or timing not positive/finite.
    Limits,
    /// Threshold settings out of range.
    Threshold,
    /// A stored calibration holds non-finite or out-of-range values.
    Calibration,
}

impl core::fmt::Display for ConfigError {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        f.write_str(match self {
            ConfigError::MotorParameter => {
                "motor parameter out of range (all positive, Lm^2 < Ls*Lr)"
            }
            ConfigError::SampleRate => {
                "sample rate out of range (100 Hz..100 kHz, >= 8x supply, ticks >= samples)"
            }
            ConfigError::Supply => "supply frequency or voltage out of range",
            ConfigError::Filter => "filter corner out of range",
            ConfigError::Decimation => {
                "decimation must be 1..=1000 and leave >= 6 blocks per supply period"
            }
            ConfigError::Encoder => "encoder configuration impossible",
            ConfigError::Limits => "sensor limits or timing out of range",
            ConfigError::Threshold => "threshold configuration out of range",
            ConfigError::Calibration => "calibration values not finite or out of range",
        })
    }
}

/// The larger of two floats in two instructions (`vcmp` + conditional move). The
/// Cortex-M4F has no `vmaxnm`, so `f32::max` becomes a call to the C `fmaxf`; this does
/// not follow IEEE maxNum for NaN (returns `b` when either is NaN), which callers allow.
#[inline(always)]
pub fn maxf(a: f32, b: f32) -> f32 {
    if a > b {
        a
    } else {
        b
    }
}

/// The smaller of two floats; NaN behaviour as [`maxf`] (returns `b`).
#[inline(always)]
pub fn minf(a: f32, b: f32) -> f32 {
    if a < b {
        a
    } else {
        b
    }
}

/// sqrt(x^2 + y^2) via [`sqrt`].
#[inline]
pub fn fast_hypot(x: f32, y: f32) -> f32 {
    sqrt(x * x + y * y)
}

/// Square root for `x >= 0`: micromath's estimate (relative error up to a few 1e-2)
/// refined by two Newton steps `y <- (y + x/y)/2`, which square the error twice: relative
/// error at f32 rounding level (~1e-7). Returns 0 for `x <= 0` and NaN for NaN.
#[inline]
pub fn sqrt(x: f32) -> f32 {
    if !(x > 0.0) {
        return if x.is_nan() { x } else { 0.0 };
    }
    let y = micromath::F32Ext::sqrt(x);
    if y > 0.0 && y.is_finite() {
        let y = 0.5 * (y + x / y);
        0.5 * (y + x / y)
    } else {
        y
    }
}
