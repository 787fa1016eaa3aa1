//! The argument types and parsers several commands share: the frame's angle source, the
//! load and the residual form as clap's values, and the parsers of a fault, an effect and a
//! time.

use clap::ValueEnum;
use monitor_core::{AngleSource, Fault, ResidualForm};

/// Frame angle source on the command line.
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum AngleArg {
    /// Rotor-flux angle from the core's current model (encoder speed, nominal Rr, Lr): the
    /// frame in which the paper's steady-state model is exact.
    RotorFlux,
    /// SRF-PLL on the voltages (voltage orientation).
    Pll,
    /// Phase-a voltage zero crossing + frequency estimate (the paper's hardware).
    ZeroCrossing,
}

impl From<AngleArg> for AngleSource {
    fn from(a: AngleArg) -> Self {
        match a {
            AngleArg::RotorFlux => AngleSource::RotorFluxCurrentModel,
            AngleArg::Pll => AngleSource::Pll,
            AngleArg::ZeroCrossing => AngleSource::ZeroCrossing,
        }
    }
}

impl From<AngleSource> for AngleArg {
    fn from(a: AngleSource) -> Self {
        match a {
            AngleSource::RotorFluxCurrentModel => AngleArg::RotorFlux,
            AngleSource::Pll => AngleArg::Pll,
            AngleSource::ZeroCrossing => AngleArg::ZeroCrossing,
        }
    }
}

/// What is known of the load, on the command line (`diagnose --load`, `hmi --load`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum LoadArg {
    /// The load is an unknown input (real service): a load change is an operating-point
    /// change, reported as a load move; the friction class b/bl is never named.
    Unknown,
    /// The paper's fixed viscous load (Table 1): a B/Bl change is a fault, named `b/bl`.
    Viscous,
}

impl From<LoadArg> for monitor_api::replay::LoadModel {
    fn from(a: LoadArg) -> Self {
        match a {
            LoadArg::Unknown => monitor_api::replay::LoadModel::Unknown,
            LoadArg::Viscous => monitor_api::replay::LoadModel::Viscous,
        }
    }
}

impl From<monitor_api::replay::LoadModel> for LoadArg {
    fn from(a: monitor_api::replay::LoadModel) -> Self {
        match a {
            monitor_api::replay::LoadModel::Unknown => LoadArg::Unknown,
            monitor_api::replay::LoadModel::Viscous => LoadArg::Viscous,
        }
    }
}

/// Residual form on the command line.
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum ResidualArg {
    /// Eq. (37), derivative terms dropped (the paper's).
    Steady,
    /// Eq. (36), with filtered derivatives: valid in transients.
    Full,
}

impl From<ResidualArg> for ResidualForm {
    fn from(a: ResidualArg) -> Self {
        match a {
            ResidualArg::Steady => ResidualForm::Steady,
            ResidualArg::Full => ResidualForm::Full,
        }
    }
}

impl From<ResidualForm> for ResidualArg {
    fn from(a: ResidualForm) -> Self {
        match a {
            ResidualForm::Steady => ResidualArg::Steady,
            ResidualForm::Full => ResidualArg::Full,
        }
    }
}

/// Parses a fault name ([`monitor_core::Fault::name`]).
pub fn parse_fault(s: &str) -> Result<Fault, String> {
    Fault::from_name(s).ok_or_else(|| {
        let names: Vec<&str> = Fault::ALL.iter().map(|f| f.name()).collect();
        format!("unknown fault '{s}' (one of {})", names.join(", "))
    })
}

/// A time on the command line [s]: a finite number >= 0 (negative values reach this
/// parser, so that `--from -5` is refused by name rather than taken for a flag).
pub fn parse_seconds(s: &str) -> Result<f64, String> {
    match s.trim().parse::<f64>() {
        Ok(x) if x.is_finite() && x >= 0.0 => Ok(x),
        Ok(x) => Err(format!(
            "{x} is not a time: give a finite number of seconds >= 0"
        )),
        Err(_) => Err(format!("'{s}' is not a number of seconds")),
    }
}

/// A duration or step on the command line [s]: a finite number > 0.
pub fn parse_positive_seconds(s: &str) -> Result<f64, String> {
    match parse_seconds(s)? {
        x if x > 0.0 => Ok(x),
        x => Err(format!("{x} s: give a finite number of seconds > 0")),
    }
}
