//! Physical laws as values, one form for the library's and a user's: a law's identity
//! ([`EffectId`], open to names the library does not know), where it acts ([`ActsOn`]),
//! its parameters ([`LawParam`]: unit, start, bounds) and how it is evaluated ([`LawForm`]:
//! the library's function, a user's expression, a no-load test's table).
//!
//! The simulator (`monitor_sim`) and the analysis (`monitor_analysis`) both evaluate a law
//! through this crate: the library's closed-form laws are written once
//! ([`library`]), and a user's law file ([`LawFile`], `--laws FILE` on the command line,
//! `laws=` in Python) gives laws of the same type.

mod expr;
mod file;
mod id;
mod law;
pub mod library;
pub mod table;
mod vars;

pub use expr::{ExprError, Expression, BINARY_FUNCTIONS, CONSTANTS, MAX_PARAMS, UNARY_FUNCTIONS};
pub use file::{LawError, LawFile, LawProblem};
pub use id::{intern, EffectId};
pub use law::{ActsOn, BoundLaw, Law, LawForm, LawOrigin, LawParam};
pub use table::{MagnetisingCurve, NoLoadTable, TableError};
pub use vars::{LawInputs, Variable};
