//! A user's law as an expression: checked here (each mistake named with its position),
//! compiled once by the `exmex` crate, evaluated per sample without allocating.
//!
//! The language: numbers (`2`, `0.5`, `1e-3`), the law's parameters and variables, `+ - * /`,
//! `^` (power, right-associative, above unary minus: `-x^2` is `-(x^2)`), parentheses, the
//! functions `sin cos tan asin acos atan sinh cosh tanh exp ln log10 sqrt abs sign` of one
//! argument and `min max` of two (`min(a, b)`), and the constant `pi`. The checked
//! expression is handed to `exmex` fully parenthesised, so its own precedence rules never
//! decide.

use crate::vars::{LawInputs, Variable};
use exmex::prelude::*;
use exmex::{BinOp, MakeOperators, Operator};

mod check;
use check::{lex, Checker, Name};

/// The functions of one argument an expression may call.
pub const UNARY_FUNCTIONS: [&str; 15] = [
    "sin", "cos", "tan", "asin", "acos", "atan", "sinh", "cosh", "tanh", "exp", "ln", "log10",
    "sqrt", "abs", "sign",
];
/// The functions of two arguments.
pub const BINARY_FUNCTIONS: [&str; 2] = ["min", "max"];
/// The constants.
pub const CONSTANTS: [&str; 1] = ["pi"];
/// Most parameters a law may have.
pub const MAX_PARAMS: usize = 12;
/// Most values an expression reads (its parameters and its variables).
const MAX_SLOTS: usize = MAX_PARAMS + Variable::ALL.len();

/// The operators the checked text uses (module doc): `exmex`'s operator type, with the
/// names this module writes (`signum` for `sign`, `min` and `max` between their two
/// operands).
#[derive(Clone, Debug)]
struct LawOps;

impl MakeOperators<f64> for LawOps {
    fn make<'a>() -> Vec<Operator<'a, f64>> {
        let bin = |apply: fn(f64, f64) -> f64, commutes: bool| BinOp {
            apply,
            prio: 0,
            is_commutative: commutes,
        };
        vec![
            Operator::make_bin_unary("+", bin(|a, b| a + b, true), |a| a),
            Operator::make_bin_unary("-", bin(|a, b| a - b, false), |a| -a),
            Operator::make_bin("*", bin(|a, b| a * b, true)),
            Operator::make_bin("/", bin(|a, b| a / b, false)),
            Operator::make_bin("^", bin(f64::powf, false)),
            Operator::make_bin("min", bin(f64::min, true)),
            Operator::make_bin("max", bin(f64::max, true)),
            Operator::make_unary("sin", f64::sin),
            Operator::make_unary("cos", f64::cos),
            Operator::make_unary("tan", f64::tan),
            Operator::make_unary("asin", f64::asin),
            Operator::make_unary("acos", f64::acos),
            Operator::make_unary("atan", f64::atan),
            Operator::make_unary("sinh", f64::sinh),
            Operator::make_unary("cosh", f64::cosh),
            Operator::make_unary("tanh", f64::tanh),
            Operator::make_unary("exp", f64::exp),
            Operator::make_unary("ln", f64::ln),
            Operator::make_unary("log10", f64::log10),
            Operator::make_unary("sqrt", f64::sqrt),
            Operator::make_unary("abs", f64::abs),
            Operator::make_unary("signum", sign),
        ]
    }
}

/// The sign of `a`: -1, 0 or 1 (0 at 0, unlike `f64::signum`), NaN for NaN.
fn sign(a: f64) -> f64 {
    if a > 0.0 {
        1.0
    } else if a < 0.0 {
        -1.0
    } else {
        a * 0.0
    }
}

/// What is wrong with an expression, where (a character position, 1-based), in the user's
/// terms.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum ExprError {
    /// A character the language does not have.
    #[error("unexpected character '{ch}' at position {at}")]
    Character {
        /// The character.
        ch: char,
        /// Its position.
        at: usize,
    },
    /// A number that does not read as one.
    #[error("'{text}' at position {at} is not a number")]
    Number {
        /// The text.
        text: String,
        /// Its position.
        at: usize,
    },
    /// The expression ends where something else was expected.
    #[error("the expression ends where {expected} was expected")]
    End {
        /// What was expected.
        expected: &'static str,
    },
    /// A token where something else was expected.
    #[error("'{found}' at position {at} where {expected} was expected")]
    Unexpected {
        /// The token.
        found: String,
        /// Its position.
        at: usize,
        /// What was expected.
        expected: &'static str,
    },
    /// A name that is neither a parameter, a variable, a function nor `pi`.
    #[error("unknown name '{name}' at position {at}{}", near_list(near))]
    UnknownName {
        /// The name.
        name: String,
        /// Its position.
        at: usize,
        /// Names of the law that are spelled alike.
        near: Vec<String>,
    },
    /// A variable of the language that this law's place does not offer (`theta` in a
    /// resistance's law).
    #[error("'{name}' at position {at} is not a variable of a law acting on {acts_on}")]
    VariableNotHere {
        /// The variable.
        name: &'static str,
        /// Its position.
        at: usize,
        /// Where the law acts.
        acts_on: &'static str,
    },
    /// A function called with another number of arguments than it takes.
    #[error("{name} at position {at} takes {takes} argument{}, not {given}", if *takes == 1 { "" } else { "s" })]
    Arity {
        /// The function.
        name: String,
        /// Its position.
        at: usize,
        /// How many it takes.
        takes: usize,
        /// How many were given.
        given: usize,
    },
    /// A function's name used as a value (`sin + 1`).
    #[error("the function {name} at position {at} needs its argument in parentheses")]
    Bare {
        /// The function.
        name: String,
        /// Its position.
        at: usize,
    },
    /// A parameter declared but never used.
    #[error("parameter '{0}' is declared but the expression does not use it")]
    Unused(String),
    /// More parameters than a law may have.
    #[error("{0} parameters; a law may have at most {MAX_PARAMS}")]
    TooMany(usize),
    /// The compiler refused the checked text (not expected: the check above should catch
    /// every mistake first).
    #[error("the expression does not compile: {0}")]
    Compile(String),
}

/// `; did you mean a or b?`, or nothing.
fn near_list(near: &[String]) -> String {
    match near {
        [] => String::new(),
        [a] => format!("; did you mean '{a}'?"),
        _ => {
            let quoted: Vec<String> = near.iter().map(|n| format!("'{n}'")).collect();
            format!("; did you mean one of {}?", quoted.join(", "))
        }
    }
}

/// A checked and compiled expression (module doc).
#[derive(Debug, Clone)]
pub struct Expression {
    text: String,
    flat: FlatEx<f64, LawOps>,
    /// For each of `exmex`'s variables (in its order), where its value comes from.
    slots: Vec<Name>,
}

impl Expression {
    /// Checks and compiles `text`, a law of the parameters `params` (in the order of the
    /// values [`Expression::eval`] takes) and the variables `vars` of a law acting on
    /// `acts_on`.
    ///
    /// # Errors
    /// [`ExprError`]: the first mistake, with its position; a parameter never used.
    pub fn new(
        text: &str,
        params: &[&str],
        vars: &[Variable],
        acts_on: &'static str,
    ) -> Result<Expression, ExprError> {
        if params.len() > MAX_PARAMS {
            return Err(ExprError::TooMany(params.len()));
        }
        let toks = lex(text)?;
        let mut c = Checker {
            toks: &toks,
            pos: 0,
            params,
            vars,
            acts_on,
            used: Vec::new(),
        };
        let checked = c.expr()?;
        if c.pos < toks.len() {
            return Err(c.unexpected("an operator or the end"));
        }
        for (i, p) in params.iter().enumerate() {
            if !c.used.contains(&Name::Param(i)) {
                return Err(ExprError::Unused((*p).to_string()));
            }
        }
        let flat = FlatEx::<f64, LawOps>::parse(&checked)
            .map_err(|e| ExprError::Compile(e.msg().to_string()))?;
        let slots = flat
            .var_names()
            .iter()
            .map(|n| {
                let n = n.trim_start_matches('{').trim_end_matches('}');
                params
                    .iter()
                    .position(|p| *p == n)
                    .map(Name::Param)
                    .or_else(|| {
                        Variable::ALL
                            .into_iter()
                            .find(|v| v.name() == n)
                            .map(Name::Var)
                    })
                    .ok_or_else(|| ExprError::Compile(format!("unknown variable {n}")))
            })
            .collect::<Result<Vec<_>, _>>()?;
        Ok(Expression {
            text: text.to_string(),
            flat,
            slots,
        })
    }

    /// The expression as the user wrote it.
    pub fn text(&self) -> &str {
        &self.text
    }

    /// True when the expression reads the variable `v`.
    pub fn uses(&self, v: Variable) -> bool {
        self.slots.contains(&Name::Var(v))
    }

    /// The value for the parameters' values `values` at `x` (NaN where the arithmetic has
    /// none, e.g. `ln` of a negative number; a count of values that does not match the
    /// parameters gives NaN too).
    #[inline]
    pub fn eval(&self, values: &[f64], x: &LawInputs) -> f64 {
        let mut buf = [0.0f64; MAX_SLOTS];
        for (b, s) in buf.iter_mut().zip(&self.slots) {
            *b = match *s {
                Name::Param(i) => match values.get(i) {
                    Some(v) => *v,
                    None => return f64::NAN,
                },
                Name::Var(v) => v.of(x),
            };
        }
        self.flat.eval(&buf[..self.slots.len()]).unwrap_or(f64::NAN)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const LOAD: &[Variable] = &[Variable::T, Variable::W, Variable::Theta];

    fn at(t: f64, w: f64, theta: f64) -> LawInputs {
        LawInputs {
            t_s: t,
            w_rad_s: w,
            theta_rad: theta,
            psi_m_wb: 0.0,
        }
    }

    #[test]
    fn evaluates_the_issue_laws() {
        let e = Expression::new(
            "t0 + a * sin(theta + phi)",
            &["t0", "a", "phi"],
            LOAD,
            "load_torque",
        )
        .unwrap();
        let v = e.eval(&[5.0, 2.0, 0.3], &at(0.0, 100.0, 1.1));
        assert!((v - (5.0 + 2.0 * (1.1f64 + 0.3).sin())).abs() < 1e-12);
        assert!(e.uses(Variable::Theta) && !e.uses(Variable::W));
        let e =
            Expression::new("k * abs(w)^n * sign(w)", &["k", "n"], LOAD, "load_torque").unwrap();
        let v = e.eval(&[1e-3, 2.7], &at(0.0, -150.0, 0.0));
        assert!((v + 1e-3 * 150f64.powf(2.7)).abs() < 1e-9, "{v}");
        assert_eq!(e.eval(&[1e-3, 2.7], &at(0.0, 0.0, 0.0)), 0.0);
    }

    #[test]
    fn precedence_is_the_usual_one() {
        let e = |s: &str| Expression::new(s, &["a"], LOAD, "load_torque").unwrap();
        let x = at(2.0, 3.0, 0.0);
        assert_eq!(e("-a^2 + 0*t").eval(&[3.0], &x), -9.0);
        assert_eq!(e("a - t - w").eval(&[10.0], &x), 5.0);
        assert_eq!(e("a / t / w").eval(&[12.0], &x), 2.0);
        assert_eq!(e("t ^ w ^ a").eval(&[2.0], &x), 2f64.powf(9.0));
        assert_eq!(e("t ^ -a").eval(&[1.0], &x), 0.5);
        assert_eq!(e("a * 2e-1 + 1.5E1").eval(&[10.0], &x), 17.0);
        assert_eq!(e("min(a, t) + max(a, w)").eval(&[2.5], &x), 2.0 + 3.0);
        assert!((e("a * pi").eval(&[2.0], &x) - 2.0 * std::f64::consts::PI).abs() < 1e-12);
        assert_eq!(e("a * sign(0 * w)").eval(&[2.0], &x), 0.0);
    }

    #[test]
    fn mistakes_are_named_with_their_position() {
        let err = |s: &str| Expression::new(s, &["t0", "a"], LOAD, "load_torque").unwrap_err();
        assert_eq!(
            err("t0 + a * sin(thetta)"),
            ExprError::UnknownName {
                name: "thetta".into(),
                at: 14,
                near: vec!["theta".into()]
            }
        );
        assert!(matches!(
            err("t0 + a * (w"),
            ExprError::Unexpected { .. } | ExprError::End { .. }
        ));
        assert_eq!(err("t0 + a $ w"), ExprError::Character { ch: '$', at: 8 });
        assert!(matches!(
            err("t0 + a * sin w"),
            ExprError::Bare { at: 10, .. }
        ));
        assert!(matches!(
            err("t0 + a * min(w)"),
            ExprError::Arity {
                takes: 2,
                given: 1,
                ..
            }
        ));
        assert!(matches!(err("t0 + w"), ExprError::Unused(p) if p == "a"));
        assert!(matches!(
            err("t0 + a w"),
            ExprError::Unexpected { at: 8, .. }
        ));
        assert!(matches!(
            Expression::new(
                "r0 * (1 + theta)",
                &["r0"],
                &[Variable::T],
                "stator_resistance"
            )
            .unwrap_err(),
            ExprError::VariableNotHere {
                name: "theta",
                at: 11,
                ..
            }
        ));
        let msg = err("t0 + a * sin(thetta)").to_string();
        assert!(
            msg.contains("position 14") && msg.contains("'theta'"),
            "{msg}"
        );
    }

    #[test]
    fn arithmetic_without_a_value_is_nan_not_a_panic() {
        let e = Expression::new("ln(a - w)", &["a"], LOAD, "load_torque").unwrap();
        assert!(e.eval(&[1.0], &at(0.0, 5.0, 0.0)).is_nan());
        assert!(e.eval(&[], &at(0.0, 5.0, 0.0)).is_nan());
    }
}
