//! A user's law file (`--laws FILE`): one `[[law]]` per law, an expression or a table.
//!
//! ```toml
//! [[law]]
//! name = "compressor"                 # the user's name; reports name the law by it
//! acts_on = "load_torque"             # where it acts (crate::ActsOn)
//! expr = "t0 + a * sin(theta + phi)"  # the expression language: crate::expr
//! [law.parameters]                    # each fitted within [low, high]
//! t0 = { start = 5.0, low = 0.0, high = 40.0, unit = "N m" }
//! a = { start = 1.0, low = 0.0, high = 20.0, unit = "N m" }
//! phi = { start = 0.0, low = -3.1416, high = 3.1416, unit = "rad" }
//!
//! [[law]]
//! name = "no-load test"
//! acts_on = "magnetising_curve"       # a measured table in place of an expression
//! table = "noload.csv"                # v_ll_rms_V, i0_rms_A at the rated frequency; a path
//!                                     # relative to the laws file, or absolute
//! ```
//!
//! A law's parameters are ordered as the expression first reads them. Every mistake is
//! refused when the file is read, in one line naming the file, the law and the problem.

use crate::expr::{ExprError, Expression};
use crate::id::{intern, EffectId};
use crate::law::{ActsOn, Law, LawForm, LawOrigin, LawParam};
use crate::table::{NoLoadTable, TableError};
use monitor_core::EffectKind;
use serde::Deserialize;
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::sync::Arc;

/// Why a law file is refused (one line; the CLI prints it as it is, Python raises it as a
/// `ValueError`, a missing file as a `FileNotFoundError`).
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum LawError {
    /// The file does not exist.
    #[error("law file {path}: no such file")]
    NotFound {
        /// The file.
        path: PathBuf,
    },
    /// The file cannot be read.
    #[error("law file {path}: {why}")]
    Read {
        /// The file.
        path: PathBuf,
        /// Why.
        why: String,
    },
    /// Not TOML, or not the law file's form.
    #[error("law file {path}, line {line}: {why}")]
    Syntax {
        /// The file.
        path: PathBuf,
        /// The line (1-based; 0 when unknown).
        line: usize,
        /// Why, as the TOML reader says it.
        why: String,
    },
    /// No law in the file.
    #[error("law file {path}: no [[law]] in it (each law starts with [[law]], then name, acts_on and expr or table)")]
    Empty {
        /// The file.
        path: PathBuf,
    },
    /// A law's own mistake.
    #[error("law file {path}, law '{law}': {why}")]
    Law {
        /// The file.
        path: PathBuf,
        /// The law's name (or its number when it has none).
        law: String,
        /// What is wrong.
        why: Box<LawProblem>,
    },
}

/// What is wrong with one law of a file.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum LawProblem {
    /// No name.
    #[error("it has no name (name = \"...\")")]
    NoName,
    /// A name a command line cannot give back (a comma), or empty.
    #[error(
        "the name may not be empty or hold a comma (a list of effects separates names with commas)"
    )]
    BadName,
    /// A library effect's name.
    #[error("'{0}' is the name of a library effect; give the law a name of its own")]
    LibraryName(String),
    /// Two laws of one name.
    #[error("two laws are named '{0}'")]
    Duplicate(String),
    /// An `acts_on` the laws do not have.
    #[error("acts_on = \"{given}\" is not a place a law acts (one of {})", ActsOn::ALL.map(|a| a.name()).join(", "))]
    ActsOn {
        /// What was given.
        given: String,
    },
    /// An expression where a table belongs, or the other way round, or neither.
    #[error("a law acting on {acts_on} needs {needs}")]
    Form {
        /// Where it acts.
        acts_on: ActsOn,
        /// What it needs.
        needs: &'static str,
    },
    /// A table law with parameters.
    #[error("a table law has no parameters")]
    TableParameters,
    /// A parameter's numbers that do not make a range with a start in it.
    #[error("parameter '{name}': start {start} must lie within low {low} .. high {high}, low below high, all finite")]
    Range {
        /// The parameter.
        name: String,
        /// Its start.
        start: f64,
        /// Its low bound.
        low: f64,
        /// Its high bound.
        high: f64,
    },
    /// The expression's mistake.
    #[error("{0} (variables here: {vars}; parameters: {params})", vars = .1, params = .2)]
    Expr(ExprError, String, String),
    /// The table's mistake.
    #[error("{0}")]
    Table(TableError),
}

/// One law as written.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct LawSpec {
    name: Option<String>,
    acts_on: String,
    expr: Option<String>,
    table: Option<PathBuf>,
    #[serde(default)]
    parameters: BTreeMap<String, ParamSpec>,
}

/// One parameter as written.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct ParamSpec {
    start: f64,
    low: f64,
    high: f64,
    #[serde(default)]
    unit: Option<String>,
}

/// The file as written.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct FileSpec {
    #[serde(default)]
    law: Vec<LawSpec>,
}

/// A user's law file, read and checked.
#[derive(Debug, Clone)]
pub struct LawFile {
    /// The file.
    pub path: PathBuf,
    /// Its laws, in the file's order.
    pub laws: Vec<Arc<Law>>,
}

impl LawFile {
    /// Reads and checks the law file at `path` (module doc).
    ///
    /// # Errors
    /// [`LawError`]: the file, its form, or the first law's mistake.
    pub fn read(path: &Path) -> Result<LawFile, LawError> {
        let text = std::fs::read_to_string(path).map_err(|e| match e.kind() {
            std::io::ErrorKind::NotFound => LawError::NotFound {
                path: path.to_path_buf(),
            },
            _ => LawError::Read {
                path: path.to_path_buf(),
                why: e.to_string(),
            },
        })?;
        LawFile::parse(&text, path)
    }

    /// Checks the law file `text` read from `path` (tables are read relative to its folder).
    ///
    /// # Errors
    /// As [`LawFile::read`].
    pub fn parse(text: &str, path: &Path) -> Result<LawFile, LawError> {
        let spec: FileSpec = toml::from_str(text).map_err(|e| LawError::Syntax {
            path: path.to_path_buf(),
            line: e
                .span()
                .map(|s| text[..s.start.min(text.len())].lines().count().max(1))
                .unwrap_or(0),
            why: e.message().trim().to_string(),
        })?;
        if spec.law.is_empty() {
            return Err(LawError::Empty {
                path: path.to_path_buf(),
            });
        }
        let folder = path.parent().unwrap_or(Path::new("."));
        let mut laws: Vec<Arc<Law>> = Vec::new();
        for (k, s) in spec.law.into_iter().enumerate() {
            let label = s.name.clone().unwrap_or_else(|| format!("#{}", k + 1));
            let law = build(s, folder, path).map_err(|why| LawError::Law {
                path: path.to_path_buf(),
                law: label.clone(),
                why: Box::new(why),
            })?;
            if laws.iter().any(|l| l.id == law.id) {
                return Err(LawError::Law {
                    path: path.to_path_buf(),
                    law: label.clone(),
                    why: Box::new(LawProblem::Duplicate(label)),
                });
            }
            laws.push(Arc::new(law));
        }
        Ok(LawFile {
            path: path.to_path_buf(),
            laws,
        })
    }

    /// The law named `name`.
    pub fn get(&self, name: &str) -> Option<&Arc<Law>> {
        self.laws.iter().find(|l| l.id.name() == name)
    }
}

/// One law from its spec.
fn build(s: LawSpec, folder: &Path, file: &Path) -> Result<Law, LawProblem> {
    let id = EffectId::named(law_name(s.name.as_deref())?);
    let acts_on = ActsOn::from_name(s.acts_on.trim()).ok_or(LawProblem::ActsOn {
        given: s.acts_on.clone(),
    })?;
    let (params, form) = if acts_on.is_table() {
        (Vec::new(), table_form(s, acts_on, folder)?)
    } else {
        expr_form(s, acts_on)?
    };
    Ok(Law {
        id,
        acts_on,
        params,
        form,
        origin: LawOrigin::File {
            path: file.to_path_buf(),
        },
    })
}

/// The law's name, checked: given, not empty, no comma, not a library effect's.
fn law_name(name: Option<&str>) -> Result<&str, LawProblem> {
    let name = name.ok_or(LawProblem::NoName)?.trim();
    if name.is_empty() || name.contains(',') {
        return Err(LawProblem::BadName);
    }
    if EffectKind::from_name(name).is_some() {
        return Err(LawProblem::LibraryName(name.to_string()));
    }
    Ok(name)
}

/// A table law's form: its table read relative to the law file's `folder`.
fn table_form(s: LawSpec, acts_on: ActsOn, folder: &Path) -> Result<LawForm, LawProblem> {
    let (Some(table), None) = (s.table, s.expr) else {
        return Err(LawProblem::Form {
            acts_on,
            needs: "table = \"FILE.csv\" (and no expr)",
        });
    };
    if !s.parameters.is_empty() {
        return Err(LawProblem::TableParameters);
    }
    let path = if table.is_absolute() {
        table
    } else {
        folder.join(table)
    };
    let t = NoLoadTable::read(&path).map_err(LawProblem::Table)?;
    Ok(LawForm::Table(Arc::new(t)))
}

/// Each parameter's start within its bounds, the bounds a range, all finite.
fn check_params(parameters: &BTreeMap<String, ParamSpec>) -> Result<(), LawProblem> {
    for (n, p) in parameters {
        let ok = [p.start, p.low, p.high].iter().all(|v| v.is_finite())
            && p.low < p.high
            && (p.low..=p.high).contains(&p.start);
        if !ok {
            return Err(LawProblem::Range {
                name: n.clone(),
                start: p.start,
                low: p.low,
                high: p.high,
            });
        }
    }
    Ok(())
}

/// An expression law's parameters (in the order the expression first reads them) and form.
fn expr_form(s: LawSpec, acts_on: ActsOn) -> Result<(Vec<LawParam>, LawForm), LawProblem> {
    let (Some(expr), None) = (s.expr, s.table) else {
        return Err(LawProblem::Form {
            acts_on,
            needs: "expr = \"...\" (and no table)",
        });
    };
    check_params(&s.parameters)?;
    let declared: Vec<&str> = s.parameters.keys().map(String::as_str).collect();
    let vars = acts_on.variables();
    let list = |v: Vec<&str>| {
        if v.is_empty() {
            "none".to_string()
        } else {
            v.join(", ")
        }
    };
    let expr_err = |e: ExprError| {
        LawProblem::Expr(
            e,
            list(vars.iter().map(|v| v.name()).collect()),
            list(declared.clone()),
        )
    };
    // Checked with the declared names first, so that a mistake is named before the order.
    Expression::new(&expr, &declared, vars, acts_on.name()).map_err(expr_err)?;
    let mut order: Vec<(usize, &str)> =
        declared.iter().map(|p| (first_use(&expr, p), *p)).collect();
    order.sort();
    let ordered: Vec<&str> = order.into_iter().map(|(_, p)| p).collect();
    let e = Expression::new(&expr, &ordered, vars, acts_on.name()).map_err(expr_err)?;
    let params = ordered
        .iter()
        .map(|n| {
            let p = &s.parameters[*n];
            LawParam {
                name: intern(n),
                unit: intern(p.unit.as_deref().unwrap_or("1")),
                start: p.start,
                low: p.low,
                high: p.high,
            }
        })
        .collect();
    Ok((params, LawForm::Expr(Arc::new(e))))
}

/// Where the name `p` is first read in `expr` as a whole word (the text's length if never).
fn first_use(expr: &str, p: &str) -> usize {
    let b = expr.as_bytes();
    let word = |c: u8| c.is_ascii_alphanumeric() || c == b'_';
    let mut from = 0;
    while let Some(i) = expr[from..].find(p) {
        let at = from + i;
        let end = at + p.len();
        if (at == 0 || !word(b[at - 1])) && (end >= b.len() || !word(b[end])) {
            return at;
        }
        from = at + 1;
    }
    expr.len()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::vars::LawInputs;

    const ISSUE: &str = r#"
[[law]]
name = "compressor"
acts_on = "load_torque"
expr = "t0 + a * sin(theta + phi)"
[law.parameters]
t0 = { start = 5.0, low = 0.0, high = 40.0, unit = "N m" }
a = { start = 1.0, low = 0.0, high = 20.0, unit = "N m" }
phi = { start = 0.0, low = -3.1416, high = 3.1416, unit = "rad" }
"#;

    #[test]
    fn reads_the_issue_form_in_the_expression_order() {
        let f = LawFile::parse(ISSUE, Path::new("/tmp/laws.toml")).unwrap();
        let l = f.get("compressor").unwrap();
        assert_eq!(l.acts_on, ActsOn::LoadTorque);
        let names: Vec<&str> = l.params.iter().map(|p| p.name).collect();
        assert_eq!(names, ["t0", "a", "phi"]);
        assert_eq!(l.params[0].unit, "N m");
        let x = LawInputs {
            theta_rad: 1.0,
            ..Default::default()
        };
        assert!((l.eval(&[5.0, 2.0, 0.5], &x) - (5.0 + 2.0 * 1.5f64.sin())).abs() < 1e-12);
    }

    fn refused(text: &str) -> String {
        LawFile::parse(text, Path::new("laws.toml"))
            .unwrap_err()
            .to_string()
    }

    #[test]
    fn bad_laws_are_one_line_naming_law_and_problem() {
        let e = refused(&ISSUE.replace("sin(theta", "sin(thetaa"));
        assert!(
            e.contains("law 'compressor'") && e.contains("position 14"),
            "{e}"
        );
        assert!(
            e.contains("did you mean 'theta'") && e.contains("variables here: t, w, theta"),
            "{e}"
        );
        let e = refused(&ISSUE.replace("\"load_torque\"", "\"load_torq\""));
        assert!(
            e.contains("is not a place a law acts") && e.contains("load_torque"),
            "{e}"
        );
        let e = refused(&ISSUE.replace("start = 5.0", "start = 50.0"));
        assert!(
            e.contains("parameter 't0'") && e.contains("within low"),
            "{e}"
        );
        let e = refused(&ISSUE.replace("expr =", "exprr ="));
        assert!(e.contains("line ") && e.contains("exprr"), "{e}");
        let e = refused(&ISSUE.replace("\"compressor\"", "\"windage\""));
        assert!(e.contains("library effect"), "{e}");
        let e = refused(&format!("{ISSUE}{ISSUE}"));
        assert!(e.contains("two laws are named 'compressor'"), "{e}");
        assert!(refused("").contains("no [[law]]"));
        for e in [
            refused(&ISSUE.replace("expr =", "table =")),
            refused(ISSUE.replace(" + phi", "").as_str()),
        ] {
            assert!(!e.contains('\n'), "{e}");
        }
    }

    #[test]
    fn a_table_is_read_relative_to_the_law_file() {
        let dir = tempfile::tempdir().unwrap();
        std::fs::write(
            dir.path().join("noload.csv"),
            "v_ll_rms_V,i0_rms_A\n100,0.8\n200,1.7\n300,2.8\n400,4.6\n",
        )
        .unwrap();
        let laws = dir.path().join("laws.toml");
        std::fs::write(
            &laws,
            "[[law]]\nname = \"no-load test\"\nacts_on = \"magnetising_curve\"\ntable = \"noload.csv\"\n",
        )
        .unwrap();
        let f = LawFile::read(&laws).unwrap();
        assert_eq!(f.laws[0].table().map(|t| t.points().len()), Some(4));
        std::fs::write(
            dir.path().join("noload.csv"),
            "v_ll_rms_V,i0_rms_A\n100,0.8\n200,1.7\n",
        )
        .unwrap();
        let e = LawFile::read(&laws).unwrap_err().to_string();
        assert!(
            e.contains("law 'no-load test'") && e.contains("at least 4"),
            "{e}"
        );
        assert!(matches!(
            LawFile::read(&dir.path().join("none.toml")),
            Err(LawError::NotFound { .. })
        ));
    }
}
