//! Host harness for the drive monitor: the induction-motor simulator with fault and effect
//! injection ([`sim`]), measurement logs ([`log`]), the parameter file ([`params`]), replay of
//! logs through the no_std core ([`replay`]) and the model-vs-measurement workflow
//! ([`analysis`]).

pub mod analysis;
pub mod commands;
pub mod log;
pub mod params;
pub mod progress;
pub mod replay;
pub mod service;
pub mod sim;
pub mod table1;
