//! A law as a value: its name, where it acts, its parameters and how it is evaluated.

use crate::expr::Expression;
use crate::id::EffectId;
use crate::table::NoLoadTable;
use crate::vars::{LawInputs, Variable};
use serde::Serialize;
use std::path::PathBuf;
use std::sync::Arc;

/// Where a law acts in the machine's equations, and what it is a function of.
///
/// | `acts_on` | the law gives | of |
/// |---|---|---|
/// | `load_torque` | a load torque on the shaft [N m], braking a shaft turning forwards when positive | `t` [s], `w` (mechanical speed, rad/s), `theta` (the shaft's mechanical angle, rad, integrated from the speed, 0 at the analysed span's first sample) |
/// | `stator_resistance` | Rs [ohm] | `t` [s] |
/// | `rotor_resistance` | Rr referred to the stator [ohm] | `t` [s] |
/// | `magnetising_inductance` | Lm [H] | `psi_m` (the magnetising flux linkage, peak, Wb) |
/// | `magnetising_curve` | Lm [H] from a no-load test's table | `psi_m` (as above) |
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum ActsOn {
    /// A load torque on the shaft [N m] of `t`, `w` and `theta`.
    LoadTorque,
    /// The stator resistance Rs [ohm] of `t`.
    StatorResistance,
    /// The rotor resistance Rr [ohm] of `t`.
    RotorResistance,
    /// The magnetising inductance Lm [H] of `psi_m`.
    MagnetisingInductance,
    /// The magnetising inductance Lm [H] of `psi_m`, from a no-load test's table.
    MagnetisingCurve,
}

impl ActsOn {
    /// Every place a law can act, in the table's order.
    pub const ALL: [ActsOn; 5] = [
        ActsOn::LoadTorque,
        ActsOn::StatorResistance,
        ActsOn::RotorResistance,
        ActsOn::MagnetisingInductance,
        ActsOn::MagnetisingCurve,
    ];

    /// The name in a law file (`acts_on = "load_torque"`).
    pub fn name(self) -> &'static str {
        match self {
            ActsOn::LoadTorque => "load_torque",
            ActsOn::StatorResistance => "stator_resistance",
            ActsOn::RotorResistance => "rotor_resistance",
            ActsOn::MagnetisingInductance => "magnetising_inductance",
            ActsOn::MagnetisingCurve => "magnetising_curve",
        }
    }

    /// Parses a name of [`ActsOn::name`].
    pub fn from_name(s: &str) -> Option<ActsOn> {
        ActsOn::ALL.into_iter().find(|a| a.name() == s)
    }

    /// The variables a law acting here may use.
    pub fn variables(self) -> &'static [Variable] {
        match self {
            ActsOn::LoadTorque => &[Variable::T, Variable::W, Variable::Theta],
            ActsOn::StatorResistance | ActsOn::RotorResistance => &[Variable::T],
            ActsOn::MagnetisingInductance | ActsOn::MagnetisingCurve => &[Variable::PsiM],
        }
    }

    /// The unit of the law's value.
    pub fn unit(self) -> &'static str {
        match self {
            ActsOn::LoadTorque => "N m",
            ActsOn::StatorResistance | ActsOn::RotorResistance => "ohm",
            ActsOn::MagnetisingInductance | ActsOn::MagnetisingCurve => "H",
        }
    }

    /// True where the law is a table, not an expression.
    pub fn is_table(self) -> bool {
        self == ActsOn::MagnetisingCurve
    }
}

impl std::fmt::Display for ActsOn {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

/// One parameter of a law: its name, unit, where a fit starts and the bounds it keeps to.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct LawParam {
    /// Its name (in the expression and the reports).
    pub name: &'static str,
    /// Its unit, as the law's author wrote it (`1` or empty: dimensionless).
    pub unit: &'static str,
    /// Where the fit starts; the value `simulate` runs the law at.
    pub start: f64,
    /// The smallest value the fit may take.
    pub low: f64,
    /// The largest.
    pub high: f64,
}

/// How a law is evaluated.
#[derive(Clone)]
pub enum LawForm {
    /// The library's own function of the parameters' values and the inputs.
    Builtin(fn(&[f64], &LawInputs) -> f64),
    /// A user's expression, parsed once.
    Expr(Arc<Expression>),
    /// A no-load test's table (a magnetising curve), turned into Lm(psi_m) for a machine by
    /// [`NoLoadTable::curve`].
    Table(Arc<NoLoadTable>),
}

impl std::fmt::Debug for LawForm {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            LawForm::Builtin(_) => f.write_str("Builtin"),
            LawForm::Expr(e) => write!(f, "Expr({})", e.text()),
            LawForm::Table(t) => write!(f, "Table({} points)", t.points().len()),
        }
    }
}

/// Where a law comes from.
#[derive(Debug, Clone, PartialEq, Serialize)]
#[serde(rename_all = "snake_case", tag = "kind")]
pub enum LawOrigin {
    /// The effect library.
    Library,
    /// A user's law file.
    File {
        /// The file.
        path: PathBuf,
    },
}

/// A law: its identity, where it acts, its parameters and its form (module doc).
#[derive(Debug, Clone)]
pub struct Law {
    /// Its name.
    pub id: EffectId,
    /// Where it acts.
    pub acts_on: ActsOn,
    /// Its parameters, in the order of the values [`Law::eval`] takes.
    pub params: Vec<LawParam>,
    /// How it is evaluated.
    pub form: LawForm,
    /// Where it comes from.
    pub origin: LawOrigin,
}

impl Law {
    /// The law's value for the parameters' values `values` (one per [`Law::params`], in
    /// order) at `x`, in the unit of [`ActsOn::unit`]. A table's law is evaluated through
    /// its curve for a machine ([`NoLoadTable::curve`]): here it is NaN. NaN as well for a
    /// count of values that does not match (never a panic).
    #[inline]
    pub fn eval(&self, values: &[f64], x: &LawInputs) -> f64 {
        if values.len() != self.params.len() {
            return f64::NAN;
        }
        match &self.form {
            LawForm::Builtin(f) => f(values, x),
            LawForm::Expr(e) => e.eval(values, x),
            LawForm::Table(_) => f64::NAN,
        }
    }

    /// The parameters' start values.
    pub fn starts(&self) -> Vec<f64> {
        self.params.iter().map(|p| p.start).collect()
    }

    /// True when the law reads the variable `v`.
    pub fn uses(&self, v: Variable) -> bool {
        match &self.form {
            LawForm::Expr(e) => e.uses(v),
            LawForm::Builtin(_) | LawForm::Table(_) => self.acts_on.variables().contains(&v),
        }
    }

    /// The expression's text (`None` for the library's laws and tables).
    pub fn expression(&self) -> Option<&str> {
        match &self.form {
            LawForm::Expr(e) => Some(e.text()),
            _ => None,
        }
    }

    /// The no-load table (`None` for a law that is not one).
    pub fn table(&self) -> Option<&NoLoadTable> {
        match &self.form {
            LawForm::Table(t) => Some(t),
            _ => None,
        }
    }
}

/// A law with the values of its parameters: what the simulator runs and a fitted model
/// holds.
#[derive(Debug, Clone)]
pub struct BoundLaw {
    /// The law.
    pub law: Arc<Law>,
    /// One value per parameter.
    pub values: Vec<f64>,
}

impl BoundLaw {
    /// The law at its parameters' start values.
    pub fn at_start(law: Arc<Law>) -> Self {
        let values = law.starts();
        BoundLaw { law, values }
    }

    /// The law's value at `x` ([`Law::eval`]).
    #[inline]
    pub fn eval(&self, x: &LawInputs) -> f64 {
        self.law.eval(&self.values, x)
    }
}
