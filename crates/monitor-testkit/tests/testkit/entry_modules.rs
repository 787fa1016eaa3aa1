//! Entry modules: a folder whose `mod.rs` is the file a reader opens first (how the part
//! works, its entry, its re-exports) keeps the values its files share in modules of their
//! own, and no file below it imports back up from the `mod.rs` (issue 87, item 6). A part
//! that imports its own entry runs in a circle through the one file meant to be read
//! first, and the shared types drift back into it.
//!
//! Checked on every `crate::`, `super::` and `self::` path of the non-test files below the
//! entry (paths inside `#[cfg(test)]` modules and `tests.rs` files are left out), with the
//! architecture suite's path reader.

// The architecture suite's file walker (declared once in `main.rs`, beside `architecture`).
use crate::architecture_syntax;

use architecture_syntax::circles::{reached, ModPath};
use architecture_syntax::files::{files, parse, verdict};
use architecture_syntax::{module_of, Paths};
use std::collections::BTreeSet;

/// The entry modules: (the crate's `src/`, the module as `a::b`).
const ENTRIES: [(&str, &str); 1] = [("crates/monitor-analysis/src/", "explain::ladder")];

/// `a::b` as a module path.
fn path(p: &str) -> ModPath {
    p.split("::").map(str::to_string).collect()
}

/// The files below `entry` of the crate in `dir` (of `all`) whose paths reach `entry`
/// itself, with the path that does.
fn reaching_up(all: &[String], dir: &str, entry: &ModPath) -> Vec<String> {
    let in_crate: Vec<(&String, ModPath)> = all
        .iter()
        .filter(|f| f.starts_with(dir) && f.ends_with(".rs"))
        .map(|f| (f, module_of(&f[dir.len()..])))
        .collect();
    let known: BTreeSet<ModPath> = in_crate.iter().map(|(_, m)| m.clone()).collect();
    let mut bad = Vec::new();
    for (f, m) in &in_crate {
        let below = m.len() > entry.len() && m[..entry.len()] == entry[..];
        if !below || f.ends_with("/tests.rs") {
            continue;
        }
        let uses = Paths::of(&parse(f), m.clone());
        // A bare `super` is a visibility (`pub(super)`), not an import.
        for u in uses.iter().filter(|u| u.segments.len() > 1) {
            if reached(m, std::slice::from_ref(u), &known).contains(entry) {
                bad.push(format!(
                    "{f}:{}: `{}` imports back up from the entry `{}`; import it from the module that defines it",
                    u.line,
                    u.segments.join("::"),
                    entry.join("::")
                ));
            }
        }
    }
    bad
}

#[test]
fn no_part_imports_back_up_from_its_entry() {
    let all = files();
    let mut bad = Vec::new();
    for (dir, entry) in ENTRIES {
        let entry = path(entry);
        let mut file = entry.clone();
        file.push("mod.rs".into());
        assert!(
            all.iter().any(|f| f == &format!("{dir}{}", file.join("/"))),
            "{dir}{}: no such entry",
            entry.join("/")
        );
        bad.extend(reaching_up(&all, dir, &entry));
    }
    verdict("no part imports back up from its entry", bad);
}

/// The check finds a part that imports its entry's constant, and lets a sibling's pass.
#[test]
fn the_check_catches_a_part_that_imports_its_entry() {
    let known: BTreeSet<ModPath> = [path("e"), path("e::a"), path("e::b")]
        .into_iter()
        .collect();
    let up: syn::File = syn::parse_str("use super::STEP_MIN;").unwrap();
    let uses = Paths::of(&up, path("e::a"));
    assert!(reached(&path("e::a"), &uses, &known).contains(&path("e")));
    let sibling: syn::File = syn::parse_str("use super::b::STEP_MIN;").unwrap();
    let uses = Paths::of(&sibling, path("e::a"));
    assert!(!reached(&path("e::a"), &uses, &known).contains(&path("e")));
}
