//! When an identification must not be written ([`refusal`]): a log the start file's motor
//! cannot have drawn (a unit), a fit that leaves much of the current, implausible values.

use super::{Identification, Samples};

/// A fit's current error above this (fraction of the current's RMS) is no identification:
/// ten times what the noise and the model's simplifications leave on a good log (0.3-1 %).
pub const MAX_FIT_ERROR: f64 = 0.1;

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
) -> Option<String> {
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
        let ratio = if i > hi { i / hi } else { lo / i };
        let hint = match (i > hi, ratio) {
            (true, r) if r > 30.0 => " (about a thousand times: currents in mA read as A? give ia_A, ib_A, ic_A unit = \"mA\" in the parameter file's [columns])",
            (false, r) if r > 30.0 => " (about a thousand times too small: currents in A given the unit mA in [columns]?)",
            _ => " (a unit, a current transformer's ratio, or a [columns] mapping to another channel)",
        };
        return Some(format!(
            "the log's current ({i:.3} A, RMS of the current vector) is {} what the parameter file's motor can draw ({lo:.3}..{hi:.3} A from a third of its no-load current to its locked-rotor current){hint}",
            if i > hi { "far above" } else { "far below" }
        ));
    }
    let stalled = matches!(id.solver.termination, crate::lm::Termination::Stalled);
    if id.relative_rms_error > MAX_FIT_ERROR || (stalled && id.relative_rms_error > 0.03) {
        return Some(format!(
            "the fit leaves a current error of {:.1} % of its RMS (solver {}; a good log leaves under 1 %): the model does not fit this log: check the [columns] mapping and units, give from_s to leave out what the model cannot follow, or start from a parameter file of this machine",
            100.0 * id.relative_rms_error,
            id.solver.termination
        ));
    }
    if let Err(e) = id.params.check_plausible() {
        return Some(format!(
            "an identified value is not one of a real machine ({}: {}): a unit or a mapping is likely wrong",
            e.key, e.message
        ));
    }
    None
}
