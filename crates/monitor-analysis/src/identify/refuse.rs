//! When an identification must not be written ([`refusal`]): a log the start file's motor
//! cannot have drawn (a unit), a fit that leaves much of the current, implausible values.

use super::{Identification, Samples};

/// A fit's current error above this (fraction of the current's RMS) is no identification:
/// ten times what the noise and the model's simplifications leave on a good log (0.3-1 %).
pub const MAX_FIT_ERROR: f64 = 0.1;

/// Why an identification must not be written, with the numbers that decided (spelled at
/// the door, `monitor-words`).
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
#[serde(tag = "kind", rename_all = "snake_case")]
pub enum IdentifyRefusal {
    /// The log's current (RMS of the current vector, `i_a`) is outside what the parameter
    /// file's motor can draw, `low_a..high_a` [A] (a third of its no-load current to 1.2
    /// times its locked-rotor current): a unit, a CT ratio or a `[columns]` mapping.
    CurrentOutOfRange {
        /// The log's current [A].
        i_a: f64,
        /// The least the motor draws [A].
        low_a: f64,
        /// The most [A].
        high_a: f64,
    },
    /// The fit leaves `error` of the current's RMS (the solver ended `termination`): the
    /// model does not fit this log.
    PoorFit {
        /// The current error's RMS over the current's.
        error: f64,
        /// How the solver ended.
        termination: crate::lm::Termination,
    },
    /// An identified value is not one of a real machine (`key`: `message`).
    NotAMachine {
        /// The parameter file's key.
        key: &'static str,
        /// What is wrong with it.
        message: String,
    },
}

/// Why the identification must not be written, naming the likely cause; `None` when it
/// may be.
///
/// - The log's current is outside what the parameter file's motor can draw, from a third of
///   its no-load current to 1.2 times its locked-rotor current: a unit (mA read as A, or A
///   as mA), a CT ratio or a `[columns]` mapping.
/// - The fit's current error is above [`MAX_FIT_ERROR`], or the solver stalled above 3 %:
///   a model that does not fit this log (the start, a mapping, another machine).
/// - An identified value is outside the range of real machines
///   (`ParamFile::check_plausible`).
pub fn refusal(
    params: &monitor_io::params::ParamFile,
    samples: &Samples,
    id: &Identification,
) -> Option<IdentifyRefusal> {
    let m = params.motor.model();
    let we = params.supply.omega_rad_s() as f32;
    let v = params.supply.v_phase_peak() as f32;
    let i_at = |s: f32| {
        let z = monitor_core::sequence::equivalent_impedance(&m, we, s);
        f64::from(v / z.re.hypot(z.im))
    };
    let (lo, hi) = (0.3 * i_at(1e-4), 1.2 * i_at(1.0));
    let i = samples.i_rms_a;
    if !(i >= lo && i <= hi) {
        return Some(IdentifyRefusal::CurrentOutOfRange {
            i_a: i,
            low_a: lo,
            high_a: hi,
        });
    }
    let stalled = matches!(id.solver.termination, crate::lm::Termination::Stalled);
    if id.relative_rms_error > MAX_FIT_ERROR || (stalled && id.relative_rms_error > 0.03) {
        return Some(IdentifyRefusal::PoorFit {
            error: id.relative_rms_error,
            termination: id.solver.termination,
        });
    }
    if let Err(e) = id.params.check_plausible() {
        return Some(IdentifyRefusal::NotAMachine {
            key: e.key,
            message: e.message,
        });
    }
    None
}
