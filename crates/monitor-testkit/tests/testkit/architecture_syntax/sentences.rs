//! Rule 9, **no engine builds a sentence**: an engine crate ([`ENGINES`]) returns typed
//! values and typed reasons; the sentences a crew reads are spelled at the door
//! (`monitor-words`, `monitor-api`, the command line). A sentence is a string literal that
//! holds prose, two words of letters side by side ("not physical", `"{} is out of
//! range"`: [`prose`]), whether plain or the template of `format!`, `write!`, `writeln!`,
//! `concat!` or `format_args!`. In an engine's code outside its tests it stands only where a
//! string is a value's own one-line text, never a reason handed on:
//!
//! - a `thiserror` error's `#[error("...")]` (an attribute, not code): the one line of an
//!   error the caller stopped on, with its fields (the bad value, the file), spelled where
//!   the error is defined so that every front end shows the same line for the same input;
//! - the body of an `impl Display` or `impl Debug`, or of an error type's own `impl` (a
//!   type named `*Error`: the `no_std` core's `RecordError::describe`): the same one line
//!   written by hand;
//! - a programmer's message: `panic!`, `assert!`, `unreachable!` (and their kin) and
//!   `.expect("...")`, which name a broken invariant, not a judgement of a motor;
//! - the files of [`SENTENCES_LEFT`] up to their counts, each with its reason: the
//!   sentences the engines held when the rule came (434 in 69 files: the data-quality
//!   stage's notes, the effects' catalogue and findings, bad input's lines in `String`
//!   fields of errors, the store's column descriptions); the list only shrinks.
//!
//! Anywhere else (a `String` field named `reason`, a `format!` handed to an error's
//! `String` field, a `const` of prose) the engine spelled for a front end.

use super::files::{files, is_test_file, item_attrs, parse, verdict};
use super::is_cfg_test;
use super::sentences_left::SENTENCES_LEFT;
use super::spelling::ENGINES;
use syn::visit::Visit;

/// The macros whose message is a programmer's (a broken invariant).
const PROGRAMMER: [&str; 11] = [
    "panic",
    "assert",
    "assert_eq",
    "assert_ne",
    "debug_assert",
    "debug_assert_eq",
    "debug_assert_ne",
    "unreachable",
    "todo",
    "unimplemented",
    "expect",
];

/// Whether `s` holds prose: two words side by side, each of two letters or more with a
/// small one among them (a word may end with `,`, `.`, `:`, `;`, `)` or begin with `(`;
/// `NOT NULL`, a query's or a schema's keywords, is no prose).
pub fn prose(s: &str) -> bool {
    let word = |w: &str| {
        let w = w
            .trim_start_matches('(')
            .trim_end_matches([',', '.', ':', ';', ')']);
        w.len() >= 2
            && w.chars()
                .all(|c| c.is_alphabetic() || c == '\'' || c == '-')
            && w.chars().any(char::is_lowercase)
    };
    let words: Vec<&str> = s.split(' ').collect();
    words.windows(2).any(|p| word(p[0]) && word(p[1]))
}

/// Where a sentence stands.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord)]
pub enum Place {
    /// An error's `#[error("...")]`.
    ThisError,
    /// The body of an `impl Display` or `impl Debug`, or of an error type's own `impl`.
    Display,
    /// A programmer's message (`panic!`, `assert!`, `.expect`, ...).
    Programmer,
    /// Anywhere else: built for a front end.
    Built,
}

/// One sentence found: the file, its line, where it stands, its text.
#[derive(Debug, Clone)]
pub struct Sentence {
    /// Its line.
    pub line: usize,
    /// Where it stands.
    pub place: Place,
    /// Its text (the literal's value).
    pub text: String,
    /// `format!`, `write!`, ... when it is a macro's template; empty for a plain literal.
    pub by: String,
    /// What it is handed to, for the measure: `error` (an `Err(..)`, a `*Error` value),
    /// `const` (a `const` or `static`), or `code`.
    pub within: &'static str,
}

/// The sentences of one file's code outside its tests.
#[derive(Default)]
pub struct Sentences {
    /// Where the visit stands (the innermost allowed place, if any).
    place: Vec<Place>,
    /// The macro whose tokens are being read.
    by: Vec<String>,
    /// What the visit stands in ([`Sentence::within`]).
    within: Vec<&'static str>,
    /// What was found.
    pub found: Vec<Sentence>,
}

impl Sentences {
    fn here(&self) -> Place {
        self.place.last().copied().unwrap_or(Place::Built)
    }

    fn lit(&mut self, l: &syn::LitStr) {
        let text = l.value();
        if prose(&text) {
            self.found.push(Sentence {
                line: l.span().start().line,
                place: self.here(),
                text,
                by: self.by.last().cloned().unwrap_or_default(),
                within: self.within.last().copied().unwrap_or("code"),
            });
        }
    }

    /// A macro's tokens: its arguments as expressions when they parse as such, else every
    /// string literal among them.
    fn tokens(&mut self, tokens: proc_macro2::TokenStream) {
        use syn::parse::Parser;
        let args = syn::punctuated::Punctuated::<syn::Expr, syn::Token![,]>::parse_terminated;
        match args.parse2(tokens.clone()) {
            Ok(exprs) => exprs.iter().for_each(|e| self.visit_expr(e)),
            Err(_) => {
                for t in tokens {
                    match t {
                        proc_macro2::TokenTree::Literal(l) => {
                            if let Ok(s) = syn::parse_str::<syn::LitStr>(&l.to_string()) {
                                let mut s = s;
                                s.set_span(l.span());
                                self.lit(&s);
                            }
                        }
                        proc_macro2::TokenTree::Group(g) => self.tokens(g.stream()),
                        _ => {}
                    }
                }
            }
        }
    }
}

/// Whether `p` makes an error: a path through a `*Error` type, or `Err` (`err`).
fn error_path(p: &syn::Path, err: bool) -> bool {
    p.segments
        .iter()
        .any(|s| s.ident.to_string().ends_with("Error") || (err && s.ident == "Err"))
}

impl Sentences {
    fn within(&mut self, is: bool, what: &'static str, visit: impl FnOnce(&mut Self)) {
        if is {
            self.within.push(what);
        }
        visit(self);
        if is {
            self.within.pop();
        }
    }
}

impl<'ast> Visit<'ast> for Sentences {
    fn visit_item(&mut self, i: &'ast syn::Item) {
        if !is_cfg_test(item_attrs(i)) {
            syn::visit::visit_item(self, i);
        }
    }

    fn visit_impl_item(&mut self, i: &'ast syn::ImplItem) {
        if !matches!(i, syn::ImplItem::Fn(f) if is_cfg_test(&f.attrs)) {
            syn::visit::visit_impl_item(self, i);
        }
    }

    /// A `Display` or `Debug` impl, and an error type's own impl (`RecordError::describe`,
    /// the one line of a `no_std` error), spell the value's own text.
    fn visit_item_impl(&mut self, i: &'ast syn::ItemImpl) {
        let shown = i.trait_.as_ref().and_then(|(_, p, _)| p.segments.last());
        let error = match &*i.self_ty {
            syn::Type::Path(t) => t
                .path
                .segments
                .last()
                .is_some_and(|s| i.trait_.is_none() && s.ident.to_string().ends_with("Error")),
            _ => false,
        };
        let own_text = error || shown.is_some_and(|s| s.ident == "Display" || s.ident == "Debug");
        if own_text {
            self.place.push(Place::Display);
        }
        syn::visit::visit_item_impl(self, i);
        if own_text {
            self.place.pop();
        }
    }

    /// Attributes are not code: a doc comment is not a sentence built; an `#[error]`'s
    /// is counted apart.
    fn visit_attribute(&mut self, a: &'ast syn::Attribute) {
        if let syn::Meta::List(l) = &a.meta {
            if a.path().is_ident("error") {
                self.place.push(Place::ThisError);
                self.tokens(l.tokens.clone());
                self.place.pop();
            }
        }
    }

    /// A `macro_rules!` body is a template, not code, and is not read (the engines' only
    /// ones, in the core's `status_line.rs`, hold the firmware's status line's format).
    fn visit_item_macro(&mut self, _: &'ast syn::ItemMacro) {}

    fn visit_macro(&mut self, m: &'ast syn::Macro) {
        let name = m
            .path
            .segments
            .last()
            .map_or(String::new(), |s| s.ident.to_string());
        let programmer = PROGRAMMER.contains(&name.as_str());
        if programmer {
            self.place.push(Place::Programmer);
        }
        self.by.push(format!("{name}!"));
        self.tokens(m.tokens.clone());
        self.by.pop();
        if programmer {
            self.place.pop();
        }
    }

    fn visit_expr_method_call(&mut self, c: &'ast syn::ExprMethodCall) {
        let programmer = c.method == "expect" || c.method == "expect_err";
        self.visit_expr(&c.receiver);
        if programmer {
            self.place.push(Place::Programmer);
        }
        c.args.iter().for_each(|a| self.visit_expr(a));
        if programmer {
            self.place.pop();
        }
    }

    fn visit_expr_call(&mut self, c: &'ast syn::ExprCall) {
        let error = matches!(&*c.func, syn::Expr::Path(p) if error_path(&p.path, true));
        self.within(error, "error", |v| syn::visit::visit_expr_call(v, c));
    }

    fn visit_expr_struct(&mut self, e: &'ast syn::ExprStruct) {
        let error = error_path(&e.path, false);
        self.within(error, "error", |v| syn::visit::visit_expr_struct(v, e));
    }

    fn visit_item_const(&mut self, c: &'ast syn::ItemConst) {
        self.within(true, "const", |v| syn::visit::visit_item_const(v, c));
    }

    fn visit_item_static(&mut self, c: &'ast syn::ItemStatic) {
        self.within(true, "const", |v| syn::visit::visit_item_static(v, c));
    }

    fn visit_lit_str(&mut self, l: &'ast syn::LitStr) {
        self.lit(l);
    }
}

/// The sentences of the source `text` (of `rel`) outside its tests.
pub fn sentences_in(rel: &str, text: &str) -> Vec<Sentence> {
    let file = syn::parse_file(text).unwrap_or_else(|e| panic!("{rel}: cannot parse: {e}"));
    let mut v = Sentences::default();
    v.visit_file(&file);
    v.found
}

/// The engines' non-test source files.
fn engine_files() -> Vec<String> {
    files()
        .into_iter()
        .filter(|f| ENGINES.iter().any(|e| f.starts_with(e)) && f.ends_with(".rs"))
        .filter(|f| !is_test_file(f) && !f.ends_with("/tests.rs") && !f.ends_with("_tests.rs"))
        .collect()
}

#[test]
fn no_engine_builds_a_sentence() {
    let mut bad = Vec::new();
    let mut used = vec![false; SENTENCES_LEFT.len()];
    for rel in engine_files() {
        let mut v = Sentences::default();
        v.visit_file(&parse(&rel));
        let built: Vec<&Sentence> = v.found.iter().filter(|s| s.place == Place::Built).collect();
        let left = SENTENCES_LEFT.iter().position(|(f, _, _)| *f == rel);
        if let Some(k) = left {
            used[k] = true;
            let (_, max, _) = SENTENCES_LEFT[k];
            let lines: Vec<String> = built.iter().map(|s| s.line.to_string()).collect();
            if built.len() > max {
                bad.push(format!(
                    "{rel}: {} sentences built, more than its SENTENCES_LEFT ceiling {max} (lines {}): spell the new one at the door",
                    built.len(),
                    lines.join(", ")
                ));
            } else if built.len() < max {
                bad.push(format!(
                    "{rel}: {} sentences built, fewer than its SENTENCES_LEFT ceiling {max}: lower it",
                    built.len()
                ));
            }
            continue;
        }
        for s in built {
            let by = if s.by.is_empty() {
                String::new()
            } else {
                format!(" ({})", s.by)
            };
            bad.push(format!(
                "{rel}:{}: builds a sentence{by}: {:?}: an engine returns a typed value or reason, spelled at the door (monitor-words); or the error's #[error], a Display impl, a programmer's panic/expect",
                s.line, s.text
            ));
        }
    }
    for ((f, _, _), u) in SENTENCES_LEFT.iter().zip(used) {
        if !u {
            bad.push(format!(
                "{f}: in SENTENCES_LEFT but not an engine's source: drop it"
            ));
        }
    }
    verdict("no engine builds a sentence", bad);
}

/// The measure behind rule 9: the engines' sentences by crate and place
/// (`cargo test -p monitor-testkit --test testkit -- --ignored --nocapture sentences_by_crate`).
#[test]
#[ignore]
fn sentences_by_crate() {
    let mut count: std::collections::BTreeMap<(&str, Place, &str), usize> = Default::default();
    for rel in engine_files() {
        let e = ENGINES
            .iter()
            .find(|e| rel.starts_with(*e))
            .copied()
            .unwrap_or("");
        let mut v = Sentences::default();
        v.visit_file(&parse(&rel));
        for s in v.found {
            *count.entry((e, s.place, s.within)).or_default() += 1;
            if s.place == Place::Built {
                println!("{rel}:{}: {} {} {:?}", s.line, s.within, s.by, s.text);
            }
        }
    }
    for ((e, p, w), n) in count {
        println!("{e} {p:?} {w} {n}");
    }
}

/// The rule finds a reason built in an engine (a `format!` into a field, a plain literal),
/// and lets an error's line, a Display, a panic's message, a doc, a test and a word that is
/// no prose pass.
#[test]
fn the_sentence_rule_catches_what_it_should() {
    let built = |text: &str| {
        sentences_in("x.rs", text)
            .into_iter()
            .filter(|s| s.place == Place::Built)
            .count()
    };
    assert_eq!(
        built("fn f(x: f64) -> R { R { because: format!(\"slip {x} out of range\") } }"),
        1
    );
    assert_eq!(built("fn f() -> &'static str { \"not physical\" }"), 1);
    assert_eq!(
        built("fn f(w: &mut W) { writeln!(w, \"the winding is shorted\").ok(); }"),
        1
    );
    assert_eq!(
        built("#[derive(thiserror::Error)]\nenum E { #[error(\"slip {0} out of range\")] S(f64) }"),
        0
    );
    assert_eq!(built("impl std::fmt::Display for X { fn fmt(&self, f: &mut F) -> R { write!(f, \"the winding\") } }"), 0);
    assert_eq!(
        built("fn f(x: Option<u8>) { x.expect(\"checked above\"); assert!(true, \"always so\"); }"),
        0
    );
    assert_eq!(
        built("/// Says not physical.\nfn f() -> &'static str { \"i_a,i_b\" }"),
        0
    );
    assert_eq!(built("fn f() { g(\"{x} Hz\", \"a b\"); }"), 0);
    assert_eq!(built("#[cfg(test)]\nmod tests { fn f() -> &'static str { \"not physical\" } }\nfn g() -> String { format!(\"after the tests\") }"), 1);
    assert_eq!(
        built("impl RecordError { pub const fn describe(self) -> &'static str { \"bad record magic\" } }"),
        0
    );
    assert!(prose("{name} is out of range") && !prose("t,i_a,i_b") && !prose("{x:.3} Hz"));
    assert!(!prose(
        "CREATE INDEX IF NOT EXISTS logs_motor_time ON {TABLE} (motor, log_time_s)"
    ));
}
