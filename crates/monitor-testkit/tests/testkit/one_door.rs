//! One door for the words a crew reads (docs/architecture.md, "Words at one door"):
//!
//! 1. **Spelled in one crate.** The words a front end names the library's options in
//!    (`Spelling`, `FieldNames`) are defined in `crates/monitor-words` only, and no engine
//!    crate (the core, the logs, the simulator, the replay, the analyses, the store, the
//!    studies) names them: an engine returns typed values and typed reasons, never a
//!    sentence built for a front end.
//! 2. **No options type carries words.** No struct of the workspace outside the door holds
//!    a spelling (a field of type `Words`, `&dyn Spelling`, `&'static (dyn Spelling ...)`):
//!    a front end passes its spelling to the function that spells.
//! 3. **No sentence is read back to decide.** No code outside the door and the tests asks a
//!    sentence-like value (`because`, `why`, `reason`, `sentence`, `verdict`, `summary`,
//!    `note`, `said`, `brief`, `advice`) whether it starts with, ends with or contains a
//!    text, nor searches or strips it: a decision reads the typed reason.
//!
//! The files are those of the workspace's code folders (git's list), tests excluded
//! (`tests/` folders, benches, and the items carrying `#[cfg(test)]` or `#[test]`, wherever
//! they stand: the code after them is read).

// The architecture suite's file walker (declared once in `main.rs`, beside `architecture`).
use crate::architecture_syntax;

use architecture_syntax::files::{files, is_code, is_test_file, read, verdict};
// The engine crates: they return typed values, never a front end's words.
use architecture_syntax::spelling::ENGINES;
use syn::spanned::Spanned;
use syn::visit::Visit;

/// The door.
const DOOR: &str = "crates/monitor-words/src/";

/// The names of the words a front end spells the library's fields in.
const WORDS_TYPES: [&str; 3] = ["Spelling", "FieldNames", "Words"];

/// The code lines of `text` (the source of `rel`) outside its tests and comments: the
/// items carrying `#[cfg(test)]` or `#[test]` are left out wherever they stand, and the
/// code after them is read (`architecture_syntax::files::code_lines`).
fn code_lines<'t>(rel: &str, text: &'t str) -> impl Iterator<Item = (usize, &'t str)> {
    architecture_syntax::files::code_lines(rel, text)
        .into_iter()
        .filter(|(_, l)| !l.trim_start().starts_with("//"))
}

/// Whether `line` names `word` as a whole identifier.
fn names(line: &str, word: &str) -> bool {
    line.match_indices(word).any(|(at, _)| {
        let before = line[..at].chars().next_back();
        let after = line[at + word.len()..].chars().next();
        let ident = |c: Option<char>| c.is_some_and(|c| c.is_alphanumeric() || c == '_');
        !ident(before) && !ident(after)
    })
}

/// The non-test Rust files of the workspace under `dirs`.
fn sources(dirs: &[&str]) -> Vec<String> {
    files()
        .into_iter()
        .filter(|f| is_code(f) && !is_test_file(f))
        // A test module in a file of its own (`mod tests;` under `#[cfg(test)]`).
        .filter(|f| !(f.ends_with("/tests.rs") || f.ends_with("_tests.rs")))
        .filter(|f| dirs.iter().any(|d| f.starts_with(d)))
        .collect()
}

/// Rule 1's violations among `rels`: an engine line naming a words type.
fn engines_naming_words(rels: &[String], text: &dyn Fn(&str) -> String) -> Vec<String> {
    let mut bad = Vec::new();
    for rel in rels {
        let t = text(rel);
        for (n, line) in code_lines(rel, &t) {
            for w in WORDS_TYPES {
                if names(line, w) {
                    bad.push(format!("{rel}:{n}: names {w}: {}", line.trim()));
                }
            }
        }
    }
    bad
}

#[test]
fn the_words_are_spelled_in_one_crate() {
    let engines = sources(&ENGINES);
    assert!(engines.len() > 50, "found {} engine files", engines.len());
    let mut bad = engines_naming_words(&engines, &read);
    // The trait and the library's own names are defined at the door only.
    for rel in sources(&["crates/", "src/", "sim-host/", "python/", "tools/"]) {
        if rel.starts_with(DOOR) {
            continue;
        }
        let text = read(&rel);
        for (n, line) in code_lines(&rel, &text) {
            let t = line.trim_start();
            if t.starts_with("pub trait Spelling")
                || t.starts_with("trait Spelling")
                || t.contains("struct FieldNames")
                || t.contains("struct Words")
            {
                bad.push(format!(
                    "{rel}:{n}: defines the door's words: {}",
                    line.trim()
                ));
            }
        }
    }
    verdict("the words are spelled in one crate", bad);
}

/// Whether a type names the words (`Words`, `Spelling`), however wrapped (`&dyn Spelling`,
/// `&'static (dyn Spelling + Sync)`, `Option<Words>`).
#[derive(Default)]
struct NamesWords(bool);

impl<'ast> Visit<'ast> for NamesWords {
    fn visit_path_segment(&mut self, s: &'ast syn::PathSegment) {
        self.0 |= s.ident == "Words" || s.ident == "Spelling";
        syn::visit::visit_path_segment(self, s);
    }
}

/// The fields (of structs, enum variants and unions) outside test modules whose type
/// names the words.
struct FieldsHoldingWords<'a> {
    rel: &'a str,
    found: Vec<String>,
}

impl<'ast> Visit<'ast> for FieldsHoldingWords<'_> {
    fn visit_item_mod(&mut self, m: &'ast syn::ItemMod) {
        if !architecture_syntax::is_cfg_test(&m.attrs) {
            syn::visit::visit_item_mod(self, m);
        }
    }

    fn visit_field(&mut self, f: &'ast syn::Field) {
        let mut n = NamesWords::default();
        n.visit_type(&f.ty);
        if n.0 {
            let name = f
                .ident
                .as_ref()
                .map_or("(unnamed)".to_string(), |i| i.to_string());
            self.found.push(format!(
                "{}:{}: a field holding words: {name}",
                self.rel,
                f.span().start().line
            ));
        }
        syn::visit::visit_field(self, f);
    }
}

/// Rule 2's violations in `text` (of `rel`): a field of a type (a struct's, an enum
/// variant's) holding a spelling; a function's parameter is how a spelling is passed, and
/// is not one.
fn fields_holding_words(rel: &str, text: &str) -> Vec<String> {
    let file = syn::parse_file(text).unwrap_or_else(|e| panic!("{rel}: cannot parse: {e}"));
    let mut v = FieldsHoldingWords {
        rel,
        found: Vec::new(),
    };
    v.visit_file(&file);
    v.found
}

#[test]
fn no_options_type_carries_words() {
    let mut bad = Vec::new();
    for rel in sources(&["crates/", "src/", "sim-host/", "python/"]) {
        if rel.starts_with(DOOR) {
            continue;
        }
        bad.extend(fields_holding_words(&rel, &read(&rel)));
    }
    verdict("no options type carries words", bad);
}

/// The sentence-like names rule 3 watches.
const SENTENCES: [&str; 10] = [
    "because", "why", "reason", "sentence", "verdict", "summary", "note", "said", "brief", "advice",
];

/// The text questions rule 3 forbids on a sentence.
const ASKS: [&str; 8] = [
    ".starts_with(",
    ".ends_with(",
    ".contains(",
    ".find(",
    ".rfind(",
    ".strip_prefix(",
    ".strip_suffix(",
    ".split_once(",
];

/// Rule 3's violations in `text` (of `rel`): a sentence-like value asked about its text.
fn sentences_read_back(rel: &str, text: &str) -> Vec<String> {
    let mut bad = Vec::new();
    for (n, line) in code_lines(rel, text) {
        for ask in ASKS {
            for (at, _) in line.match_indices(ask) {
                // The receiver: the identifier (with field accesses) just before the call.
                let before = line[..at]
                    .trim_end_matches(".as_str()")
                    .trim_end_matches(".as_deref()");
                let receiver: String = before
                    .chars()
                    .rev()
                    .take_while(|c| c.is_alphanumeric() || *c == '_' || *c == '.')
                    .collect::<String>()
                    .chars()
                    .rev()
                    .collect();
                let last = receiver.rsplit('.').next().unwrap_or("");
                if SENTENCES.iter().any(|s| last.contains(s)) {
                    bad.push(format!("{rel}:{n}: reads a sentence back: {}", line.trim()));
                }
            }
        }
    }
    bad
}

#[test]
fn no_sentence_is_read_back_to_decide() {
    let mut bad = Vec::new();
    for rel in sources(&["crates/", "src/", "sim-host/", "python/"]) {
        if rel.starts_with(DOOR) {
            continue;
        }
        bad.extend(sentences_read_back(&rel, &read(&rel)));
    }
    verdict("no sentence is read back to decide", bad);
}

#[test]
fn the_rules_catch_what_they_should() {
    // Rule 1: an engine naming the words.
    let text = |_: &str| "pub struct Options {\n    pub words: Words,\n}\n".to_string();
    assert_eq!(engines_naming_words(&["x.rs".into()], &text).len(), 1);
    let clean = |_: &str| "pub struct Options {\n    pub wordsmith: u8,\n}\n".to_string();
    assert!(engines_naming_words(&["x.rs".into()], &clean).is_empty());
    // Rule 2: a field holding a spelling, also as a reference.
    let t = "pub struct A {\n    pub words: Words,\n    spell: &'static (dyn Spelling + Sync),\n}\nenum B { C { sp: Option<Words> } }\nfn f(sp: &dyn Spelling) {}\n#[cfg(test)]\nmod tests { struct D { w: Words } }\n";
    assert_eq!(fields_holding_words("a.rs", t).len(), 3, "{t}");
    // Rule 3: a reason read back, the ladder's old refusal among them; a name asked about
    // its text and test code are not; the code after a test module is read.
    let t = "fn f() {\n    if !t.because.starts_with(\"not physical\") {}\n    let x = why.as_str().contains(\"y\");\n    let ok = name.starts_with(\"a\");\n}\n#[cfg(test)]\nmod tests { fn f() { why.contains(\"z\"); } }\nfn g() -> bool { summary.ends_with(\".\") }\n";
    assert_eq!(sentences_read_back("a.rs", t).len(), 3, "{t}");
}
