//! Rule 8, **spelled only at the door**: an engine crate (every one of [`ENGINES`])
//! returns typed values and typed reasons; the sentences a crew reads are spelled by
//! `monitor-words`. So an engine's non-test sources name none of the front ends' words (`Spelling`, `Words`,
//! `FieldNames`, `OptionField`: [`WORDS`]; the replay, which defines `OptionField`, names
//! it: [`WORD_HOMES`]), and decide nothing by reading a sentence back: no
//! `starts_with`, `ends_with`, `contains`, `strip_prefix` or `==` of a string literal on a
//! field or variable that holds a reason or a sentence ([`REASON_NAMES`]).

use super::files::{files, is_test_file, item_attrs, parse, verdict};
use super::is_cfg_test;
use syn::spanned::Spanned;
use syn::visit::Visit;

/// The engine crates' sources (every library crate but the door, `monitor-words` and
/// `monitor-api`, and the dev-only `monitor-testkit`; docs/architecture.md, "Words at one
/// door"): they return typed values and typed reasons. Rules 8 and 9 and `one_door.rs`
/// read this one list.
pub const ENGINES: [&str; 8] = [
    "crates/monitor-core/src/",
    "crates/monitor-io/src/",
    "crates/monitor-laws/src/",
    "crates/monitor-sim/src/",
    "crates/monitor-replay/src/",
    "crates/monitor-analysis/src/",
    "crates/monitor-store/src/",
    "crates/monitor-studies/src/",
];

/// The front ends' words an engine does not name: the door's `Spelling`, `Words` and
/// `FieldNames`, and `OptionField`, the name of an option a front end spells.
pub const WORDS: [&str; 4] = ["Spelling", "Words", "FieldNames", "OptionField"];

/// The engine that defines a word of [`WORDS`], which may name it: `OptionField` is the
/// replay's typed name of an option (the field its `OptionError` names, the one list of
/// `diagnose`'s options), a typed value the door spells, not a spelling.
pub const WORD_HOMES: [(&str, &str); 1] = [("OptionField", "crates/monitor-replay/src/")];

/// Names of fields and variables that hold a reason or a sentence (a name that is one of
/// these, or ends with `_` and one of them).
pub const REASON_NAMES: [&str; 8] = [
    "because", "why", "reason", "reasons", "summary", "verdict", "words", "sentence",
];

/// The string methods that read a sentence back.
const READS: [&str; 5] = [
    "starts_with",
    "ends_with",
    "contains",
    "strip_prefix",
    "find",
];

/// The violations of rule 8 in one file's syntax (`rel` names it in the messages).
pub struct Spelled<'a> {
    /// The file.
    pub rel: &'a str,
    /// What was found, one line each.
    pub found: Vec<String>,
}

/// Whether `name` holds a reason or a sentence ([`REASON_NAMES`]).
fn reason_name(name: &str) -> bool {
    REASON_NAMES
        .iter()
        .any(|r| name == *r || name.ends_with(&format!("_{r}")))
}

/// The name an expression reads a value from, when it is a field (`t.because`) or a
/// variable (`why`), through references and method calls that keep the value
/// (`t.because.as_str()`).
fn read_from(e: &syn::Expr) -> Option<String> {
    match e {
        syn::Expr::Field(f) => match &f.member {
            syn::Member::Named(n) => Some(n.to_string()),
            syn::Member::Unnamed(_) => None,
        },
        syn::Expr::Path(p) => p.path.get_ident().map(|i| i.to_string()),
        syn::Expr::Reference(r) => read_from(&r.expr),
        syn::Expr::Paren(p) => read_from(&p.expr),
        syn::Expr::MethodCall(m) if m.args.is_empty() => read_from(&m.receiver),
        _ => None,
    }
}

/// Whether `e` is a string literal (or a reference to one).
fn string_literal(e: &syn::Expr) -> bool {
    match e {
        syn::Expr::Lit(l) => matches!(l.lit, syn::Lit::Str(_)),
        syn::Expr::Reference(r) => string_literal(&r.expr),
        _ => false,
    }
}

impl Spelled<'_> {
    fn push(&mut self, line: usize, what: String) {
        self.found.push(format!("{}:{line}: {what}", self.rel));
    }
}

impl<'ast> Visit<'ast> for Spelled<'_> {
    /// (Every item carrying `#[cfg(test)]` or `#[test]` is a test; what follows it is not.)
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

    fn visit_ident(&mut self, i: &'ast proc_macro2::Ident) {
        let name = i.to_string();
        let home = WORD_HOMES
            .iter()
            .any(|(w, dir)| *w == name && self.rel.starts_with(dir));
        if WORDS.contains(&name.as_str()) && !home {
            self.push(
                i.span().start().line,
                format!("names `{name}`: an engine returns typed values, the words are spelled at the door (monitor-words)"),
            );
        }
    }

    fn visit_expr_method_call(&mut self, m: &'ast syn::ExprMethodCall) {
        let method = m.method.to_string();
        if READS.contains(&method.as_str()) && m.args.iter().any(string_literal) {
            if let Some(name) = read_from(&m.receiver).filter(|n| reason_name(n)) {
                self.push(
                    m.method.span().start().line,
                    format!("`{name}.{method}(\"...\")` decides by reading a sentence back: match on a typed reason"),
                );
            }
        }
        syn::visit::visit_expr_method_call(self, m);
    }

    fn visit_expr_binary(&mut self, b: &'ast syn::ExprBinary) {
        if matches!(b.op, syn::BinOp::Eq(_) | syn::BinOp::Ne(_)) {
            for (side, other) in [(&*b.left, &*b.right), (&*b.right, &*b.left)] {
                if let Some(name) = read_from(side).filter(|n| reason_name(n)) {
                    if string_literal(other) {
                        let line = b.op.span().start().line;
                        self.push(line, format!("`{name} == \"...\"` decides by reading a sentence back: match on a typed reason"));
                    }
                }
            }
        }
        syn::visit::visit_expr_binary(self, b);
    }
}

/// The violations of rule 8 in the source `text` of file `rel`.
pub fn spelled_in(rel: &str, text: &str) -> Vec<String> {
    let file = syn::parse_file(text).unwrap_or_else(|e| panic!("{rel}: cannot parse: {e}"));
    let mut v = Spelled {
        rel,
        found: Vec::new(),
    };
    v.visit_file(&file);
    v.found
}

#[test]
fn engines_do_not_spell_and_do_not_read_sentences_back() {
    let mut bad = Vec::new();
    for rel in files() {
        let engine = ENGINES.iter().any(|e| rel.starts_with(e));
        if !engine || !rel.ends_with(".rs") || is_test_file(&rel) {
            continue;
        }
        if rel.ends_with("/tests.rs") || rel.ends_with("_tests.rs") {
            continue;
        }
        let mut v = Spelled {
            rel: &rel,
            found: Vec::new(),
        };
        v.visit_file(&parse(&rel));
        bad.extend(v.found);
    }
    verdict("engines spell nothing and read no sentence back", bad);
}

/// The rule catches what it should: the words named, a sentence read back (as the ladder
/// once did, `t.because.starts_with("not physical")`), a sentence compared; not a test,
/// not a string that is no reason.
#[test]
fn the_spelling_rule_catches_what_it_should() {
    let caught = |text: &str| spelled_in("x.rs", text).len();
    assert_eq!(caught("use monitor_replay::{OptionField, Spelling};"), 2);
    // The replay defines `OptionField`: its own name, not a front end's word there.
    let replay = "crates/monitor-replay/src/fields.rs";
    assert_eq!(
        spelled_in(replay, "pub enum OptionField { Params }").len(),
        0
    );
    assert_eq!(spelled_in(replay, "pub struct A { w: Words }").len(), 1);
    assert_eq!(
        caught("pub struct A { pub words: monitor_replay::Words }"),
        1
    );
    assert_eq!(
        caught("fn f(t: &T) -> bool { !t.because.starts_with(\"not physical\") && !t.because.contains(\"diverged\") }"),
        2
    );
    assert_eq!(caught("fn f(why: &str) -> bool { why == \"diverged\" }"), 1);
    assert_eq!(
        caught("fn f(r: &R) -> bool { r.skipped_because.as_str().ends_with(\"x\") }"),
        1
    );
    assert_eq!(
        caught("fn f(name: &str) -> bool { name.ends_with(\"_dynamics\") }"),
        0
    );
    assert_eq!(caught("fn f(t: &T) -> bool { t.because.contains(&x) }"), 0);
    assert_eq!(
        caught("#[cfg(test)]\nmod tests { fn f(t: &T) -> bool { t.summary.contains(\"x\") } }"),
        0
    );
    // The code after a file's first test item is read.
    assert_eq!(
        caught("#[cfg(test)]\nfn helper() {}\nfn f(t: &T) -> bool { t.summary.contains(\"x\") }"),
        1
    );
}
