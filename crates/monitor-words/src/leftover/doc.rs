//! The leftover's JSON document (`leftover` of `compare` and `explain --ladder`): its typed
//! values with the sentences spelled from them beside them.

use super::{lines, reading};
use monitor_analysis::leftover::{
    Correlate, EquationShare, ErrorSpectrum, KindShare, LawHint, Leftover, ShaftAngle,
    SpectralLine, WindowShare,
};
use serde::Serialize;

/// The leftover `l` as its JSON document carries it: each of [`Leftover`]'s values under
/// its own key, the spectral lines each with its reading in words (`lines[].says`), and
/// the lines a crew reads (`summary`). The fields are [`Leftover`]'s by reference (a field
/// added to it is a compile error in [`LeftoverDoc::new`] until the document carries it).
#[derive(Debug, Clone, Serialize)]
pub struct LeftoverDoc<'a> {
    /// The model's `normalized_rms_error` over the whole log.
    pub error: f64,
    /// Its noise floor.
    pub noise_floor: f64,
    /// `error / noise_floor`.
    pub ratio_to_floor: f64,
    /// The noise-floor band the caller judges by.
    pub band: f64,
    /// Whether the error is within `band` times its floor.
    pub at_floor: bool,
    /// The equations, largest share first.
    pub equations: &'a [EquationShare],
    /// The strata's kinds, largest share first.
    pub in_time: &'a [KindShare],
    /// The strata that hold the most error for their length.
    pub windows: &'a [WindowShare],
    /// How the spectrum was taken, or why it could not be.
    pub spectrum: &'a ErrorSpectrum,
    /// The spectrum's claimed lines, each with its reading in words.
    pub lines: Vec<LineDoc<'a>>,
    /// The envelope's correlation with the speed, the load current and the voltage.
    pub follows: &'a [Correlate],
    /// The error's projection on the shaft angle.
    pub shaft_angle: &'a [ShaftAngle],
    /// The law the leftover points to, if one.
    pub hint: Option<LawHint>,
    /// The leftover as the lines a crew reads ([`lines`]).
    pub summary: Vec<String>,
}

impl<'a> LeftoverDoc<'a> {
    /// The document of `l`.
    pub fn new(l: &'a Leftover) -> Self {
        let Leftover {
            error,
            noise_floor,
            ratio_to_floor,
            band,
            at_floor,
            equations,
            in_time,
            windows,
            spectrum,
            lines: spectral,
            follows,
            shaft_angle,
            hint,
        } = l;
        LeftoverDoc {
            error: *error,
            noise_floor: *noise_floor,
            ratio_to_floor: *ratio_to_floor,
            band: *band,
            at_floor: *at_floor,
            equations,
            in_time,
            windows,
            spectrum,
            lines: spectral.iter().map(LineDoc::new).collect(),
            follows,
            shaft_angle,
            hint: *hint,
            summary: lines(l),
        }
    }
}

/// One spectral line of the leftover as its JSON document carries it (`leftover.lines[]`):
/// its typed values, and its reading in words (`says`, [`reading`]).
#[derive(Debug, Clone, Serialize)]
pub struct LineDoc<'a> {
    /// The line's typed values (frequency, reading, equation, amplitude, share, ...).
    #[serde(flatten)]
    pub line: &'a SpectralLine,
    /// Its reading in words.
    pub says: String,
}

impl<'a> LineDoc<'a> {
    /// The document of the line `x`.
    pub fn new(x: &'a SpectralLine) -> Self {
        LineDoc {
            line: x,
            says: reading(&x.reading),
        }
    }
}
