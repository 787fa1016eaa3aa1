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
//! Source: "Fault Diagnosis of Induction Motor Using D-Q Simplified Model and Parity
//! Equations", Energies 2022, 15(22), 8372 (MDPI), doi:10.3390/en15228372 ("the paper");
//! its typos are corrected in the module docs ([`residuals`] lists them) and in
//! `docs/paper-errata.md`; the models and equations with their sources: `docs/design.md`.
//!
//! The crate also holds the vocabulary every part of the workspace shares: [`Fault`] (Table
//! 1's faults), [`EffectKind`] (the effect library's names), [`Phase`], the parameter
//! file's [`MotorParameters`] with its one conversion to [`MotorModel`], the
//! [`reference`](mod@reference) machines (2.2 kW and 3 hp), and the broken-bar relation of
//! the squirrel cage ([`rotor_cage`]). With the `serde` feature (the
//! host enables it) they serialise under the names of the parameter file and the JSON
//! reports (`docs/design.md`). The firmware's status line, its format, writer and parser,
//! is here too ([`status_line`]): the board writes it, the host's HMI reads it.
//!
//! ```
//! use monitor_core::{reference, Abc, Fault, Monitor, MonitorConfig, Sample};
//! // The 3 hp reference motor on 220 V, 60 Hz, sampled at 10 kHz.
//! let motor = reference::MOTOR_3HP.motor.model();
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
pub mod commissioning;
pub mod effect;
pub mod encoder;
pub mod error;
pub mod filter;
pub mod frames;
pub mod isolation;
pub mod machine;
pub mod math;
pub mod monitor;
pub mod motor_record;
pub mod operating_range;
pub mod record;
pub mod residuals;
pub mod rotor_cage;
pub mod sequence;
pub mod signature;
pub mod status_line;
pub mod threshold;
pub mod verdict;

pub use angle::AngleSource;
pub use commissioning::{
    CommissioningError, CommissioningFailure, CommissioningRun, Install, RunStage,
};
pub use effect::EffectKind;
pub use encoder::EncoderConfig;
pub use error::{ConfigCheck, ConfigError, ConfigErrorKind};
pub use frames::{Abc, AlphaBeta, Dq, Phase, Real, SinCos};
pub use isolation::{Isolation, IsolationState, Isolator, Named, SteadyPoint};
pub use machine::{
    reference, LmPoint, MotorModel, MotorParameters, ReferenceMachine, SupplyParameters,
};
pub use monitor::{
    CommissioningState, Monitor, MonitorConfig, MonitorOutput, ResidualForm, Sample, SensorFlags,
    SensorLimits,
};
pub use operating_range::{OperatingPoint, OperatingRange};
pub use residuals::Operating;
pub use sequence::NegativeSequence;
pub use signature::{
    Diagnosis, Fault, FaultEntry, FaultTarget, MachineParameter, SensorChannel, FAULTS,
    FAULT_COUNT, ROTOR_FLUX_SIGNATURES, TABLE1,
};
pub use threshold::{Calibration, ThresholdConfig};

#[cfg(test)]
pub(crate) mod testing {
    //! Shared test fixtures.
    use crate::MotorModel;

    /// The 3 hp reference machine in the core's precision.
    pub(crate) fn motor_3hp() -> MotorModel {
        crate::reference::MOTOR_3HP.motor.model()
    }

    /// Sample `k` at 10 kHz of the 3 hp machine's steady state: a balanced 60 Hz supply of
    /// `v_peak` [V] and a balanced 10 A current lagging by 0.5 rad, the shaft at 1750 rpm
    /// on a 4096-count encoder, microsecond timestamps.
    pub(crate) fn steady_sample(k: u32, v_peak: f32) -> crate::Sample {
        use core::f32::consts::TAU;
        let t = k as f32 * 1e-4;
        let w = TAU * 60.0 * t;
        let ph = |x: f32| crate::Abc {
            a: x.cos(),
            b: (x - TAU / 3.0).cos(),
            c: (x + TAU / 3.0).cos(),
        };
        let scale = |p: crate::Abc<f32>, m: f32| crate::Abc {
            a: m * p.a,
            b: m * p.b,
            c: m * p.c,
        };
        let wm = 1750.0 / 60.0 * TAU;
        crate::Sample {
            v_abc: scale(ph(w), v_peak),
            i_abc: scale(ph(w - 0.5), 10.0),
            encoder_count: (wm * t / TAU * 4096.0) as u32,
            timestamp_ticks: (t * 1e6) as u32,
            v_saturated: false,
            i_saturated: false,
            clipped: false,
        }
    }
}
