//! The one door: every sentence a crew reads is spelled here, and only here.
//!
//! The engines (the replay's stages and its verdict, the analyses and the ladder, the
//! trend) return typed values: findings with their numbers and typed reasons (enums with
//! the numbers that decided, such as a rotor that cannot be judged,
//! `RotorCannot::TooShort { stretch_s, needed_s, .. }`). They never build a sentence, and
//! nothing is decided by reading one back. This crate turns those values into the words of
//! every front end: the command line's text, its HTML report, the terminal HMI, the
//! trend's table and Python's results all take their lines from the functions here, so two
//! lines about one log cannot disagree.
//!
//! A front end says how it names the library's options (the command line by its flags,
//! Python by its keywords) by passing its [`Spelling`] to the function that spells; no
//! options type carries words.
//!
//! Modules, one per engine:
//! - [`analysis`]: what `compare`, `explain` and the ladder share (why an effect was not
//!   fitted, why a dynamics effect is not proposed, the unbalance analysis);
//! - [`compare`]: `compare` (its advice, what it could not run, what the log does not
//!   identify, why its fit is not plausible, and its JSON document);
//! - [`explain`]: `explain` (its conclusion, the base parameters refitted, its sentences
//!   in its JSON document);
//! - [`identify`]: `identify` (why an identification is not written);
//! - [`ladder`]: `explain --ladder` (why it stopped, why a candidate was not kept, each
//!   step, the base changes, what was found, and its JSON document);
//! - [`leftover`]: where a model's remaining error lives (`compare`'s end, the ladder's
//!   stop above the floor): its equations, windows, spectral lines, what it follows, the
//!   law it points to;
//! - [`diagnose`]: one log's report (`sim-host diagnose`, the demo, the HMI, Python's
//!   `diagnose`), its [`diagnose::Story`] and its JSON document;
//! - [`trend`]: a motor's trend (`sim-host trend`, Python's `trend`).

#![forbid(unsafe_code)]

pub mod analysis;
pub mod compare;
pub mod diagnose;
mod errors;
pub mod explain;
pub mod identify;
pub mod ladder;
pub mod laws;
pub mod leftover;
mod spelling;
pub mod trend;

pub use errors::{option_error, replay_error};
pub use monitor_replay::OptionField;
pub use spelling::{FieldNames, Spelling};
