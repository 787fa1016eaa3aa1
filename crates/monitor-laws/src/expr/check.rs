//! The checker of a law's expression: the lexer (tokens with their positions) and a
//! recursive descent that writes the fully parenthesised text `exmex` compiles, with the
//! first mistake and its position, and near matches for a name it does not know.

use super::{ExprError, BINARY_FUNCTIONS, CONSTANTS, UNARY_FUNCTIONS};
use crate::vars::Variable;

/// A token of the language, with its 1-based position.
#[derive(Debug, Clone, PartialEq)]
pub(super) enum Tok {
    Num(f64),
    Ident(String),
    Op(char),
    Open,
    Close,
    Comma,
}

/// The tokens of `s`, each with its position.
pub(super) fn lex(s: &str) -> Result<Vec<(Tok, usize)>, ExprError> {
    let chars: Vec<char> = s.chars().collect();
    let mut out = Vec::new();
    let mut i = 0;
    while i < chars.len() {
        let c = chars[i];
        let at = i + 1;
        if c.is_whitespace() {
            i += 1;
        } else if c.is_ascii_digit()
            || (c == '.' && chars.get(i + 1).is_some_and(char::is_ascii_digit))
        {
            let start = i;
            while i < chars.len() && (chars[i].is_ascii_digit() || chars[i] == '.') {
                i += 1;
            }
            if i < chars.len() && (chars[i] == 'e' || chars[i] == 'E') {
                let mut j = i + 1;
                if j < chars.len() && (chars[j] == '+' || chars[j] == '-') {
                    j += 1;
                }
                if j < chars.len() && chars[j].is_ascii_digit() {
                    i = j;
                    while i < chars.len() && chars[i].is_ascii_digit() {
                        i += 1;
                    }
                }
            }
            let text: String = chars[start..i].iter().collect();
            match text.parse::<f64>() {
                Ok(v) if v.is_finite() => out.push((Tok::Num(v), at)),
                _ => return Err(ExprError::Number { text, at }),
            }
        } else if c.is_ascii_alphabetic() || c == '_' {
            let start = i;
            while i < chars.len() && (chars[i].is_ascii_alphanumeric() || chars[i] == '_') {
                i += 1;
            }
            out.push((Tok::Ident(chars[start..i].iter().collect()), at));
        } else {
            let t = match c {
                '+' | '-' | '*' | '/' | '^' => Tok::Op(c),
                '(' => Tok::Open,
                ')' => Tok::Close,
                ',' => Tok::Comma,
                _ => return Err(ExprError::Character { ch: c, at }),
            };
            out.push((t, at));
            i += 1;
        }
    }
    Ok(out)
}

/// What a name in an expression is.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) enum Name {
    Param(usize),
    Var(Variable),
}

/// The checker: a recursive descent over the tokens that writes the fully parenthesised
/// text `exmex` compiles, and records the names read.
pub(super) struct Checker<'a> {
    pub(super) toks: &'a [(Tok, usize)],
    pub(super) pos: usize,
    pub(super) params: &'a [&'a str],
    pub(super) vars: &'a [Variable],
    pub(super) acts_on: &'static str,
    pub(super) used: Vec<Name>,
}

impl Checker<'_> {
    fn peek(&self) -> Option<&(Tok, usize)> {
        self.toks.get(self.pos)
    }

    pub(super) fn unexpected(&self, expected: &'static str) -> ExprError {
        match self.peek() {
            None => ExprError::End { expected },
            Some((t, at)) => ExprError::Unexpected {
                found: match t {
                    Tok::Num(v) => format!("{v}"),
                    Tok::Ident(s) => s.clone(),
                    Tok::Op(c) => c.to_string(),
                    Tok::Open => "(".into(),
                    Tok::Close => ")".into(),
                    Tok::Comma => ",".into(),
                },
                at: *at,
                expected,
            },
        }
    }

    /// expr := term (('+' | '-') term)*
    pub(super) fn expr(&mut self) -> Result<String, ExprError> {
        let mut left = self.term()?;
        while let Some((Tok::Op(c @ ('+' | '-')), _)) = self.peek() {
            let c = *c;
            self.pos += 1;
            let right = self.term()?;
            left = format!("({left} {c} {right})");
        }
        Ok(left)
    }

    /// term := unary (('*' | '/') unary)*
    fn term(&mut self) -> Result<String, ExprError> {
        let mut left = self.unary()?;
        while let Some((Tok::Op(c @ ('*' | '/')), _)) = self.peek() {
            let c = *c;
            self.pos += 1;
            let right = self.unary()?;
            left = format!("({left} {c} {right})");
        }
        Ok(left)
    }

    /// unary := ('+' | '-') unary | power
    fn unary(&mut self) -> Result<String, ExprError> {
        match self.peek() {
            Some((Tok::Op('-'), _)) => {
                self.pos += 1;
                let x = self.unary()?;
                Ok(format!("(-{x})"))
            }
            Some((Tok::Op('+'), _)) => {
                self.pos += 1;
                self.unary()
            }
            _ => self.power(),
        }
    }

    /// power := primary ('^' unary)?   (right-associative through `unary`)
    fn power(&mut self) -> Result<String, ExprError> {
        let base = self.primary()?;
        if let Some((Tok::Op('^'), _)) = self.peek() {
            self.pos += 1;
            let exp = self.unary()?;
            return Ok(format!("({base} ^ {exp})"));
        }
        Ok(base)
    }

    /// primary := number | name | function '(' args ')' | '(' expr ')'
    fn primary(&mut self) -> Result<String, ExprError> {
        let Some((tok, at)) = self.peek().cloned() else {
            return Err(ExprError::End {
                expected: "a number, a name or '('",
            });
        };
        match tok {
            Tok::Num(v) => {
                self.pos += 1;
                Ok(decimal(v))
            }
            Tok::Open => {
                self.pos += 1;
                let x = self.expr()?;
                self.close()?;
                Ok(format!("({x})"))
            }
            Tok::Ident(name) => {
                self.pos += 1;
                self.name(&name, at)
            }
            _ => Err(self.unexpected("a number, a name or '('")),
        }
    }

    fn close(&mut self) -> Result<(), ExprError> {
        match self.peek() {
            Some((Tok::Close, _)) => {
                self.pos += 1;
                Ok(())
            }
            _ => Err(self.unexpected("')'")),
        }
    }

    /// A name read at `at`: a function call, `pi`, a parameter or a variable.
    fn name(&mut self, name: &str, at: usize) -> Result<String, ExprError> {
        let unary = UNARY_FUNCTIONS.contains(&name);
        let binary = BINARY_FUNCTIONS.contains(&name);
        if unary || binary {
            if !matches!(self.peek(), Some((Tok::Open, _))) {
                return Err(ExprError::Bare {
                    name: name.into(),
                    at,
                });
            }
            self.pos += 1;
            let mut args = vec![self.expr()?];
            while let Some((Tok::Comma, _)) = self.peek() {
                self.pos += 1;
                args.push(self.expr()?);
            }
            self.close()?;
            let takes = if unary { 1 } else { 2 };
            if args.len() != takes {
                return Err(ExprError::Arity {
                    name: name.into(),
                    at,
                    takes,
                    given: args.len(),
                });
            }
            return Ok(if unary {
                let f = if name == "sign" { "signum" } else { name };
                format!("{f}({})", args[0])
            } else {
                format!("({} {name} {})", args[0], args[1])
            });
        }
        if name == "pi" {
            return Ok(decimal(std::f64::consts::PI));
        }
        if let Some(i) = self.params.iter().position(|p| *p == name) {
            self.used.push(Name::Param(i));
            return Ok(format!("{{{name}}}"));
        }
        if let Some(v) = Variable::ALL.into_iter().find(|v| v.name() == name) {
            if !self.vars.contains(&v) {
                return Err(ExprError::VariableNotHere {
                    name: v.name(),
                    at,
                    acts_on: self.acts_on,
                });
            }
            self.used.push(Name::Var(v));
            return Ok(format!("{{{name}}}"));
        }
        Err(ExprError::UnknownName {
            name: name.into(),
            at,
            near: near_names(name, self.params, self.vars),
        })
    }
}

/// `v` as a decimal `exmex` reads (it takes no exponent), finite `v` only.
fn decimal(v: f64) -> String {
    let s = format!("{v}");
    if s.contains('.') {
        s
    } else {
        format!("{s}.0")
    }
}

/// The law's names (parameters, variables, functions) spelled like `name`: within 2 edits,
/// or sharing its first three letters; the closest first, at most three.
fn near_names(name: &str, params: &[&str], vars: &[Variable]) -> Vec<String> {
    let mut all: Vec<&str> = params.to_vec();
    all.extend(vars.iter().map(|v| v.name()));
    all.extend(UNARY_FUNCTIONS);
    all.extend(BINARY_FUNCTIONS);
    all.extend(CONSTANTS);
    let mut scored: Vec<(usize, &str)> = all
        .into_iter()
        .map(|c| (strsim::damerau_levenshtein(name, c), c))
        .filter(|(d, c)| {
            *d <= 2.min(name.len().max(1)) || (name.len() >= 3 && c.starts_with(&name[..3]))
        })
        .collect();
    scored.sort();
    scored.dedup_by(|a, b| a.1 == b.1);
    scored
        .into_iter()
        .take(3)
        .map(|(_, c)| c.to_string())
        .collect()
}
