//! Where the leftover lives: the error a fitted model leaves on a log, placed so that a user
//! knows what law to write (`compare`'s end, and `explain --ladder` when it stops above the
//! noise floor).
//!
//! The error of the model's prediction `p` against the log `d` is split four ways
//! ([`locate`]):
//! - **by equation** ([`EquationShare`]): the stator q-axis current (eq. 28), the stator
//!   d-axis current (only for a model that predicts it, [`Prediction::predicts_d_axis`]) and
//!   the mechanics (eq. 29, the rotor speed), each error normalised by the RMS of what it
//!   measures (the stator current vector's for both currents, so that d and q compare); the
//!   share is of the error's mean square beyond each channel's white sensor noise
//!   ([`crate::metrics::white_noise_sigma`]);
//! - **by time** ([`KindShare`], [`WindowShare`]): the log's strata (the start, supply or
//!   speed transients, load moves, steady stretches, as the ladder's held-back split cuts
//!   them), each with its share of the error's energy beside its share of the log's time;
//! - **by frequency** ([`SpectralLine`]): the strongest spectral lines of the error on the steady
//!   stretches (Hann-windowed, averaged over half-overlapping segments; the resolution is
//!   stated), each with its frequency, amplitude, share of the error and its physical
//!   reading ([`LineReading`]: the shaft frequency f_r = w_m / 2 pi and its multiples,
//!   2 s f, the supply frequency's multiples). The frame is the analysis' rotor-flux frame,
//!   which turns at the supply frequency: a stationary-frame line at f +/- f_x appears at
//!   f_x (the (1 +/- 2 s) f sidebands of a rotor asymmetry at 2 s f, a phase current's
//!   offset at f, the negative sequence at 2 f, the 5th and 7th harmonics at 6 f);
//! - **by what it follows** ([`Correlate`], [`ShaftAngle`]): the correlation of the error's
//!   envelope with the speed, the load (active) current and the voltage after the start, and
//!   the error's projection on sin and cos of k theta (k = 1, 2), theta the shaft angle
//!   integrated from the measured speed.
//!
//! From these, the law the leftover points to, if one ([`LawHint`]). Every value is typed;
//! the words are spelled at the door (`monitor-words`).

mod follows;
mod lines;
mod series;
#[cfg(test)]
mod tests;

pub use follows::{Correlate, OperatingVariable, ShaftAngle};
pub use lines::{
    ErrorSpectrum, LineReading, LineReadingOnLog, NoSpectrum, SpectralLine, Stretches,
};

use crate::prep::Prepared;
use crate::simplified_model::{MachineConstants, Prediction};
use crate::strata::StratumKind;
use serde::Serialize;

/// A line of the spectrum is claimed only when its peak stands this many times above the
/// median of the spectrum around it (white noise averaged over one segment exceeds 20 times
/// its median in one bin of 10⁶: a control log claims no line).
pub const LINE_PROMINENCE: f64 = 20.0;
/// ... and carries at least this share (3 %) of the steady stretches' error.
pub const LINE_SHARE_MIN: f64 = 0.03;
/// The most lines reported (the strongest by share).
pub const MAX_LINES: usize = 5;
/// The error follows a variable when the correlation of its envelope with it reaches this
/// magnitude (0.5) and the variable varies ([`VARIES_MIN`]).
pub const FOLLOWS_MIN: f64 = 0.5;
/// A variable varies on a log when its span reaches this share (5 %) of its largest mean
/// magnitude over the envelope's bins.
pub const VARIES_MIN: f64 = 0.05;
/// The error is locked to the shaft angle when its projection on sin and cos of k theta
/// holds at least this share (10 %) of it.
pub const ANGLE_SHARE_MIN: f64 = 0.1;

/// The model's equations the error is split over.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Equation {
    /// The stator q-axis current (eq. 28: the torque-producing current) [A].
    StatorQ,
    /// The stator d-axis current (the flux-producing current) [A]; predicted only by a model
    /// whose stator current is a state.
    StatorD,
    /// The mechanics (eq. 29): the electrical rotor speed omega_r [rad/s].
    Mechanics,
}

impl Equation {
    /// The unit of its error.
    pub fn unit(self) -> &'static str {
        match self {
            Equation::StatorQ | Equation::StatorD => "A",
            Equation::Mechanics => "rad/s",
        }
    }
}

/// One equation's part of the error (JSON `leftover.equations[]`).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct EquationShare {
    /// The equation.
    pub equation: Equation,
    /// RMS of its error over the log, in `unit`.
    pub rms_error: f64,
    /// The unit (`A`, `rad/s`).
    pub unit: &'static str,
    /// `rms_error` over the RMS of what it measures (the stator current vector's, or the
    /// speed's).
    pub normalized: f64,
    /// The channel's white sensor noise [unit].
    pub noise: f64,
    /// Its share (0..1) of the error's mean square beyond the noise, over the equations.
    pub share: f64,
}

/// One stratum of the log and its part of the error (JSON `leftover.windows[]`).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct WindowShare {
    /// What the stratum is.
    pub kind: StratumKind,
    /// Its start [s].
    pub t_start_s: f64,
    /// Its end [s].
    pub t_end_s: f64,
    /// Its share (0..1) of the error's energy over the log (equations normalised as in
    /// [`EquationShare::normalized`], summed).
    pub share: f64,
    /// Its share of the log's time.
    pub time_share: f64,
}

/// The strata of one kind together (JSON `leftover.in_time[]`).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct KindShare {
    /// The kind.
    pub kind: StratumKind,
    /// How many strata of it the log holds.
    pub strata: usize,
    /// Their first start [s].
    pub t_start_s: f64,
    /// Their last end [s].
    pub t_end_s: f64,
    /// Their share of the error's energy.
    pub share: f64,
    /// Their share of the log's time.
    pub time_share: f64,
}

/// The law the leftover points to, when its lines or what it follows name one (JSON
/// `leftover.hint`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(tag = "kind", rename_all = "snake_case")]
pub enum LawHint {
    /// The error is at the shaft frequency (or locked to the shaft angle),
    /// `per_revolution` times a revolution: a load torque of the shaft angle theta (a
    /// compressor's or a crank's), or the shaft's misalignment or eccentricity.
    LoadOfShaftAngle {
        /// Pulses per revolution.
        per_revolution: u32,
    },
    /// The error is at 2 s f (the phase currents' (1 +/- 2 s) f sidebands): the rotor's
    /// asymmetry (broken bars, a cracked end ring).
    RotorAsymmetry,
    /// The error is at twice the supply frequency: a negative sequence (an unbalanced
    /// supply or winding).
    NegativeSequence,
    /// The error is at the supply frequency: an offset in a phase current (a current
    /// sensor's).
    CurrentOffset,
    /// The error is at a higher multiple of the supply frequency: the supply's harmonics
    /// (a converter's) or the saturation's.
    SupplyHarmonics,
    /// The error's size follows the speed: a load torque of the speed w.
    LoadOfSpeed,
    /// The error's size follows the voltage: the magnetising inductance of the flux
    /// psi_m (saturation).
    MagnetisingOfFlux,
}

/// Where the leftover lives (JSON `leftover`).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Leftover {
    /// The model's `normalized_rms_error` over the whole log.
    pub error: f64,
    /// Its noise floor.
    pub noise_floor: f64,
    /// `error / noise_floor`.
    pub ratio_to_floor: f64,
    /// The noise-floor band the caller judges by (`explain`'s and the ladder's:
    /// [`crate::explain::NOISE_MARGIN`]).
    pub band: f64,
    /// Whether the error is within `band` times its floor: then nothing is left to place,
    /// and the words say so.
    pub at_floor: bool,
    /// The equations, largest share first.
    pub equations: Vec<EquationShare>,
    /// The strata's kinds, largest share first.
    pub in_time: Vec<KindShare>,
    /// The strata that hold the most error for their length (at most three, the error's
    /// share at least twice their time's), most first.
    pub windows: Vec<WindowShare>,
    /// How the spectrum was taken, or why it could not be.
    pub spectrum: ErrorSpectrum,
    /// The spectrum's claimed lines, largest share first (at most [`MAX_LINES`]).
    pub lines: Vec<SpectralLine>,
    /// The envelope's correlation with the speed, the load current and the voltage.
    pub follows: Vec<Correlate>,
    /// The error's projection on the shaft angle, once and twice per revolution (empty
    /// without a speed).
    pub shaft_angle: Vec<ShaftAngle>,
    /// The law the leftover points to, if one.
    pub hint: Option<LawHint>,
}

/// How the caller measured the model's error: its `normalized_rms_error` over the whole
/// log, its noise floor, and the band within which it is at the floor.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Measured {
    /// The model's `normalized_rms_error`.
    pub error: f64,
    /// Its noise floor.
    pub noise_floor: f64,
    /// The noise-floor band (a factor on the floor).
    pub band: f64,
}

/// Where the error of the prediction `p` of the log `d` (machine `n`) lives (module doc),
/// the error measured by the caller as `m`. `None` when the prediction does not cover the
/// log or is not finite (a model that diverged: its error places nothing).
pub fn locate(d: &Prepared, n: &MachineConstants, p: &Prediction, m: Measured) -> Option<Leftover> {
    let Measured {
        error,
        noise_floor,
        band,
    } = m;
    let es = series::ErrorSeries::of(d, p)?;
    let strata = crate::strata::strata(d, n);
    let spectrum = lines::spectrum(d, n, p, &es, &strata);
    let (spectrum, lines) = match spectrum {
        Ok((s, l)) => (s, l),
        Err(because) => (ErrorSpectrum::Refused { because }, Vec::new()),
    };
    let (follows, shaft_angle) = follows::follows(d, n, &es, &strata);
    let all = every_stratum(&es, &strata, d);
    let ratio = error / noise_floor;
    let at_floor = ratio <= band;
    let mut out = Leftover {
        error,
        noise_floor,
        ratio_to_floor: ratio,
        band,
        at_floor,
        equations: es.equation_shares(),
        in_time: in_time(&all),
        windows: windows(&all),
        spectrum,
        lines,
        follows,
        shaft_angle,
        hint: None,
    };
    out.hint = (!at_floor).then(|| hint(&out)).flatten();
    Some(out)
}

/// Every stratum of the log (`strata` cover it) with its share of the error's energy and of
/// the log's time: one pass over the samples.
fn every_stratum(
    es: &series::ErrorSeries,
    strata: &[(StratumKind, usize, usize)],
    d: &Prepared,
) -> Vec<WindowShare> {
    let len = es.len();
    let energies: Vec<f64> = strata
        .iter()
        .map(|&(_, a, b)| (a..b.min(len)).map(|k| es.energy_at(k)).sum())
        .collect();
    let total = energies.iter().sum::<f64>().max(f64::MIN_POSITIVE);
    strata
        .iter()
        .zip(energies)
        .filter(|(s, _)| s.1 < len)
        .map(|(&(kind, a, b), e)| {
            let b = b.min(len);
            WindowShare {
                kind,
                t_start_s: d.t_s[a],
                t_end_s: d.t_s[b - 1],
                share: e / total,
                time_share: (b - a) as f64 / len.max(1) as f64,
            }
        })
        .collect()
}

/// The strata's kinds with their shares of the error's energy and of the log's time, from
/// every stratum's ([`every_stratum`]).
fn in_time(all: &[WindowShare]) -> Vec<KindShare> {
    let mut out: Vec<KindShare> = Vec::new();
    for w in all {
        match out.iter_mut().find(|k| k.kind == w.kind) {
            Some(k) => {
                k.strata += 1;
                k.share += w.share;
                k.time_share += w.time_share;
                k.t_start_s = k.t_start_s.min(w.t_start_s);
                k.t_end_s = k.t_end_s.max(w.t_end_s);
            }
            None => out.push(KindShare {
                kind: w.kind,
                strata: 1,
                t_start_s: w.t_start_s,
                t_end_s: w.t_end_s,
                share: w.share,
                time_share: w.time_share,
            }),
        }
    }
    out.sort_by(|a, b| b.share.total_cmp(&a.share));
    out
}

/// The strata that hold the most error for their length (of every stratum's,
/// [`every_stratum`]): share at least twice their time's and 5 %, at most three, the most
/// concentrated first.
fn windows(all: &[WindowShare]) -> Vec<WindowShare> {
    let mut out: Vec<WindowShare> = all
        .iter()
        .filter(|w| w.share >= 2.0 * w.time_share && w.share >= 0.05)
        .cloned()
        .collect();
    out.sort_by(|a, b| (b.share / b.time_share).total_cmp(&(a.share / a.time_share)));
    out.truncate(3);
    out
}

/// The law the leftover `l` points to: its strongest line's reading; else the shaft angle
/// it is locked to; else the variable its size follows most (the speed, the voltage).
fn hint(l: &Leftover) -> Option<LawHint> {
    if let Some(line) = l.lines.first() {
        let k = line.reading.multiple;
        let h = match line.reading.reading {
            LineReading::ShaftFrequency => Some(LawHint::LoadOfShaftAngle { per_revolution: k }),
            LineReading::TwiceSlipFrequency => Some(LawHint::RotorAsymmetry),
            LineReading::SupplyFrequency if k == 1 => Some(LawHint::CurrentOffset),
            LineReading::SupplyFrequency if k == 2 => Some(LawHint::NegativeSequence),
            LineReading::SupplyFrequency => Some(LawHint::SupplyHarmonics),
            LineReading::NotNamed => None,
        };
        if h.is_some() {
            return h;
        }
    }
    if let Some(a) = l
        .shaft_angle
        .iter()
        .filter(|a| a.share >= ANGLE_SHARE_MIN)
        .max_by(|a, b| a.share.total_cmp(&b.share))
    {
        return Some(LawHint::LoadOfShaftAngle {
            per_revolution: a.per_revolution,
        });
    }
    l.follows
        .iter()
        .filter(|c| c.follows())
        .filter(|c| {
            matches!(
                c.variable,
                OperatingVariable::Speed | OperatingVariable::Voltage
            )
        })
        .max_by(|a, b| {
            let r = |c: &Correlate| c.r.map_or(0.0, f64::abs);
            r(a).total_cmp(&r(b))
        })
        .map(|c| match c.variable {
            OperatingVariable::Voltage => LawHint::MagnetisingOfFlux,
            _ => LawHint::LoadOfSpeed,
        })
}
