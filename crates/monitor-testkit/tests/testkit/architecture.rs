//! The architecture's rules that Cargo cannot state, checked on the sources.
//!
//! Cargo holds the crates' order: each crate's `Cargo.toml` lists the crates it may use
//! (docs/architecture.md draws them), so a library cannot reach the command line, the
//! Python package or a crate above it. What is left for this test:
//!
//! 1. **Modules inside a crate** point one way, as [`INSIDE`] orders them for the crates
//!    with more than one part (the firmware's library, `monitor-io`, `monitor-analysis`,
//!    `monitor-studies`, `monitor-api`, `monitor-store`): a module uses only modules of a
//!    lower layer of its crate; a module the table does not list is in the crate's base
//!    layer. Checked on every `use` and every path (`crate::`, `super::`, `self::`), tests
//!    inside `src/` and the paths inside a macro's body (read from its tokens) included. docs/architecture.md names every crate of `crates/`. No two
//!    files of a crate reach each other (an import circle), but a module and its own
//!    submodules and the circles of [`CIRCLES_LEFT`]: checked in every package of the
//!    workspace (each tracked `Cargo.toml`) with more than one file in `src/`, on the
//!    `crate::`, `super::` and `self::` paths and on the paths that start with a name
//!    such a `use` imported (`render::text::f` after `use super::render;`).
//! 2. **The core stands alone**: `monitor-core` depends on no crate of the workspace (no
//!    `path` dependency) and names none.
//! 3. **Files**: no `.rs` file in `crates/`, `src/`, `sim-host/`, `tests/` or `tools/` over
//!    [`MAX_FILE_LINES`] lines (`wc -l`), but for the few in [`LONG_FILES`], each with
//!    its reason and its own ceiling.
//! 4. **Functions**: no function outside tests over [`MAX_FN_LINES`] lines, counted from
//!    the line of `fn` to the line of its closing brace (`#[cfg(test)]` modules, `#[test]`
//!    functions, `tests/` and `benches/` folders are tests), but for the few in
//!    [`LONG_FUNCTIONS`], each with its reason and its own ceiling. An entry of either list
//!    that is no longer needed fails the test too (the lists only shrink). The caps are
//!    guides: a file or function is split where its parts have different readers.
//! 5. **The repository stands alone**: no tracked `.rs`, `.toml` or `.md` file names the
//!    team's design file or its shared folder ([`FOREIGN`]); a user who clones the
//!    repository has neither. The paper is cited by its title, the design by `docs/`.
//!
//! 8. **Spelled only at the door**: an engine's non-test sources (every engine crate,
//!    `architecture_syntax::spelling::ENGINES`: the core, io, laws, sim, replay, analysis,
//!    store, studies) name none of the front ends' words (`Spelling`, `Words`,
//!    `OptionField`) and decide nothing by reading a sentence back
//!    (`t.because.starts_with("...")`): its reasons are typed values, spelled by
//!    `monitor-words` (`architecture_syntax::spelling`, with its tests).
//! 9. **No engine builds a sentence**: no string of prose (two words side by side, plain
//!    or a `format!`/`write!`/`writeln!`/`concat!` template) in an engine's code but an
//!    error's `#[error("...")]`, a `Display`/`Debug` impl and a programmer's message
//!    (`panic!`, `assert!`, `.expect`), and the files of `SENTENCES_LEFT`
//!    (`architecture_syntax::sentences`, which says why, with its tests).
//!
//! The tests' shared scenarios (`crates/monitor-testkit/src/`, a dev-only crate) are tests
//! for rule 4 and for the unique type names (rule 7, below), and code for the others. A
//! test is a file of `tests/` or `benches/` folders, a `tests.rs` or `*_tests.rs`, and an
//! item carrying `#[cfg(test)]` or `#[test]` wherever it stands: every rule reads the code
//! after a file's first `#[cfg(test)]` (`architecture_syntax::files::code_lines`, the syntax
//! walks skip the test items only).
//!
//! The files are those git tracks (`git ls-files`), or, without git, every file below the
//! workspace outside `target/` and hidden folders.

use crate::architecture_syntax;

use architecture_syntax::allowances::{LONG_FILES, LONG_FUNCTIONS};
use architecture_syntax::circles::{circles, reached, ModPath};
use architecture_syntax::crates::{CRATE_SOURCES, WORKSPACE_CRATES};
use architecture_syntax::files::{
    code_lines, crate_sources, files, is_code, is_shared_scenarios, is_test_file, packages, parse,
    read, verdict, workspace,
};
use architecture_syntax::layers::INSIDE;
use architecture_syntax::{module_of, top_module, LongFunctions, Paths};

use syn::visit::Visit;

/// Import circles still there: (crate's `src/`, the files as `a::b` paths, why). An entry
/// no longer found fails the test (the list only shrinks).
const CIRCLES_LEFT: &[(&str, &[&str], &str)] = &[];

/// Longest `.rs` file [lines].
const MAX_FILE_LINES: usize = 600;
/// Longest non-test function [lines].
const MAX_FN_LINES: usize = 60;
/// References to files outside the repository (spelled in two parts, so that this file
/// does not hold them).
const FOREIGN: [&str; 2] = [concat!("DESIGN", ".md"), concat!("..", "/shared")];
/// The layer of `module` inside the crate of `table` (the base, 1, when not listed).
fn layer(table: &[(&str, u8)], module: &str) -> u8 {
    table
        .iter()
        .find(|(m, _)| *m == module)
        .map_or(1, |(_, r)| *r)
}

/// The firmware's binary-only files (the embassy tasks, `main.rs`), outside its library.
fn firmware_binary(in_src: &str) -> bool {
    in_src == "main.rs" || in_src == "firmware.rs" || in_src.starts_with("firmware/")
}

#[test]
fn modules_inside_a_crate_point_one_way() {
    let mut bad = Vec::new();
    for rel in files() {
        let Some((dir, table)) = INSIDE.iter().find(|(d, _)| rel.starts_with(d)) else {
            continue;
        };
        let in_src = &rel[dir.len()..];
        if !rel.ends_with(".rs")
            || in_src == "lib.rs"
            || (*dir == "src/" && firmware_binary(in_src))
        {
            continue;
        }
        let module = module_of(in_src);
        let Some(own) = module.first().cloned() else {
            continue;
        };
        let rank = layer(table, &own);
        for u in Paths::of(&parse(&rel), module) {
            let Some(target) = top_module(&u) else {
                continue;
            };
            let to = layer(table, &target);
            let listed = table.iter().any(|(m, _)| *m == target);
            if target != own && listed && to >= rank {
                bad.push(format!(
                    "{rel}:{}: layers: `{own}` (layer {rank}) uses `{}` of `{target}` (layer {to}); a module uses only lower layers of its crate ({dir})",
                    u.line,
                    u.segments.join("::")
                ));
            }
        }
    }
    verdict("modules inside a crate point one way", bad);
}

/// The crates whose root (`lib.rs`) is only their table of contents: modules and
/// re-exports, no item of its own; their modules import from the module that defines a
/// name, never from the root's re-exports (an import of the root runs back up to the top).
const ROOT_ONLY_NAMES: [&str; 1] = ["crates/monitor-replay/src/"];

#[test]
fn the_root_only_names_its_modules() {
    let mut bad = Vec::new();
    let all = files();
    for dir in ROOT_ONLY_NAMES {
        let root = parse(&format!("{dir}lib.rs"));
        let mut modules = Vec::new();
        for item in &root.items {
            match item {
                syn::Item::Mod(m) => modules.push(m.ident.to_string()),
                syn::Item::Use(_) => {}
                other => {
                    let name = match other {
                        syn::Item::Fn(f) => f.sig.ident.to_string(),
                        syn::Item::Struct(s) => s.ident.to_string(),
                        syn::Item::Enum(e) => e.ident.to_string(),
                        syn::Item::Const(c) => c.ident.to_string(),
                        syn::Item::Impl(_) => "an impl".to_string(),
                        _ => "an item".to_string(),
                    };
                    bad.push(format!(
                        "{dir}lib.rs: the root holds `{name}` of its own; move it to the module it belongs to"
                    ));
                }
            }
        }
        for rel in all
            .iter()
            .filter(|f| f.starts_with(dir) && f.ends_with(".rs"))
        {
            let in_src = &rel[dir.len()..];
            if in_src == "lib.rs" {
                continue;
            }
            let module = module_of(in_src);
            for u in Paths::of(&parse(rel), module) {
                let Some(target) = top_module(&u) else {
                    continue;
                };
                if !modules.contains(&target) && u.segments.len() > 1 {
                    bad.push(format!(
                        "{rel}:{}: `{}` reaches the crate root's re-export; import it from the module that defines it",
                        u.line,
                        u.segments.join("::")
                    ));
                }
            }
        }
    }
    verdict("the root only names its modules", bad);
}

#[test]
fn no_import_circle_between_files() {
    let mut bad = Vec::new();
    let mut used = vec![false; CIRCLES_LEFT.len()];
    let all = files();
    let dirs = crate_sources();
    for must in CRATE_SOURCES {
        if !dirs.iter().any(|d| d == must) {
            bad.push(format!(
                "{must}: not among the crates checked for circles {dirs:?}"
            ));
        }
    }
    for dir in dirs.iter().map(String::as_str) {
        let in_crate: Vec<(&String, ModPath)> = all
            .iter()
            .filter(|f| f.starts_with(dir) && f.ends_with(".rs") && !is_test_file(f))
            .filter(|f| !f.ends_with("/tests.rs") && !f.ends_with("_tests.rs"))
            .map(|f| {
                let rel = &f[dir.len()..];
                let m = if rel == "main.rs" {
                    Vec::new()
                } else {
                    module_of(rel)
                };
                (f, m)
            })
            .collect();
        let known: std::collections::BTreeSet<ModPath> =
            in_crate.iter().map(|(_, m)| m.clone()).collect();
        let mut edges = std::collections::BTreeMap::new();
        for (f, m) in &in_crate {
            let uses = Paths::of(&parse(f), m.clone());
            // (`main.rs` and `lib.rs` are both the root: their edges add up.)
            let to: std::collections::BTreeSet<ModPath> = edges.remove(m).unwrap_or_default();
            edges.insert(m.clone(), &to | &reached(m, &uses, &known));
        }
        for group in circles(&edges) {
            let names: Vec<String> = group.iter().map(|m| m.join("::")).collect();
            let left = CIRCLES_LEFT
                .iter()
                .position(|(d, files, _)| *d == dir && files.iter().eq(names.iter()));
            match left {
                Some(k) => used[k] = true,
                None => bad.push(format!("{dir}: import circle between {}", names.join(", "))),
            }
        }
    }
    for ((dir, files, _), u) in CIRCLES_LEFT.iter().zip(used) {
        if !u {
            bad.push(format!(
                "{dir}: {files:?} in CIRCLES_LEFT but no longer a circle: drop it"
            ));
        }
    }
    verdict("no import circle between files", bad);
}

/// Every crate of `crates/` (a folder with a `Cargo.toml`) is named in
/// docs/architecture.md, whose picture is the only prose copy of the crates' order.
#[test]
fn the_architecture_doc_names_every_crate() {
    let root = workspace();
    let doc =
        std::fs::read_to_string(root.join("docs/architecture.md")).expect("docs/architecture.md");
    let mut missing = Vec::new();
    for e in std::fs::read_dir(root.join("crates"))
        .expect("crates/")
        .flatten()
    {
        let name = e.file_name().to_string_lossy().to_string();
        if e.path().join("Cargo.toml").is_file() && !doc.contains(&format!("crates/{name}")) {
            missing.push(name);
        }
    }
    assert!(
        missing.is_empty(),
        "docs/architecture.md does not name crates/{missing:?}"
    );
}

/// Every package of the workspace (a tracked `Cargo.toml`'s `[package]`) is in
/// [`WORKSPACE_CRATES`], so that the core's check knows every crate it may not name.
#[test]
fn the_crate_list_names_every_package() {
    let found = packages();
    assert!(found.len() >= WORKSPACE_CRATES.len(), "packages: {found:?}");
    let missing: Vec<String> = found
        .into_iter()
        .map(|(_, name)| name.replace('-', "_"))
        .filter(|n| !WORKSPACE_CRATES.contains(&n.as_str()))
        .collect();
    assert!(missing.is_empty(), "not in WORKSPACE_CRATES: {missing:?}");
}

#[test]
fn monitor_core_uses_nothing_from_the_workspace() {
    let mut bad = Vec::new();
    let manifest = "crates/monitor-core/Cargo.toml";
    let toml: toml::Table = read(manifest).parse().expect("monitor-core's manifest");
    for section in ["dependencies", "dev-dependencies", "build-dependencies"] {
        for (name, spec) in toml
            .get(section)
            .and_then(|s| s.as_table())
            .into_iter()
            .flatten()
        {
            if spec.get("path").is_some() {
                let line = read(manifest)
                    .lines()
                    .position(|l| l.trim_start().starts_with(name.as_str()))
                    .map_or(1, |i| i + 1);
                bad.push(format!(
                    "{manifest}:{line}: core alone: [{section}] `{name}` is a crate of the workspace"
                ));
            }
        }
    }
    for rel in files() {
        if !(rel.starts_with("crates/monitor-core/") && rel.ends_with(".rs")) {
            continue;
        }
        for u in Paths::of(&parse(&rel), Vec::new()) {
            let first = u.segments[0].as_str();
            if WORKSPACE_CRATES.contains(&first) && first != "monitor_core" {
                bad.push(format!(
                    "{rel}:{}: core alone: uses `{}` of the workspace crate `{first}`",
                    u.line,
                    u.segments.join("::")
                ));
            }
        }
    }
    verdict("monitor-core uses nothing from the workspace", bad);
}

#[test]
fn no_rust_file_over_600_lines() {
    let mut bad = Vec::new();
    let mut used = Vec::new();
    for f in files().into_iter().filter(|f| is_code(f)) {
        let n = read(&f).lines().count();
        let allowed = LONG_FILES.iter().find(|(path, _, _)| *path == f);
        let max = allowed.map_or(MAX_FILE_LINES, |(_, max, _)| *max);
        if allowed.is_some() {
            used.push(f.clone());
        }
        if n > max {
            bad.push(format!(
                "{f}:{}: file size: {n} lines, more than {max}",
                max + 1
            ));
        } else if n <= MAX_FILE_LINES && allowed.is_some() {
            bad.push(format!(
                "{f}: file size: {n} lines, within {MAX_FILE_LINES}: drop it from LONG_FILES"
            ));
        }
    }
    for (path, _, _) in LONG_FILES {
        if !used.iter().any(|u| u == path) {
            bad.push(format!(
                "{path}: in LONG_FILES but not a code file of the workspace"
            ));
        }
    }
    verdict("no .rs file over 600 lines", bad);
}

#[test]
fn no_function_over_60_lines_outside_tests() {
    let mut found = Vec::new();
    for rel in files() {
        if !is_code(&rel) || is_test_file(&rel) || is_shared_scenarios(&rel) {
            continue;
        }
        let mut v = LongFunctions {
            rel: &rel,
            max: MAX_FN_LINES,
            found: Vec::new(),
        };
        v.visit_file(&parse(&rel));
        found.extend(v.found);
    }
    let mut bad = Vec::new();
    let mut used = vec![false; LONG_FUNCTIONS.len()];
    for line in found {
        let allowed = LONG_FUNCTIONS
            .iter()
            .enumerate()
            .find(|(_, (path, name, _, _))| {
                line.starts_with(&format!("{path}:")) && line.contains(&format!("`{name}` is "))
            });
        let lines = line
            .split("` is ")
            .nth(1)
            .and_then(|rest| rest.split(' ').next())
            .and_then(|n| n.parse::<usize>().ok());
        match (allowed, lines) {
            (Some((k, (_, _, max, _))), Some(n)) if n <= *max => used[k] = true,
            (Some((k, (_, _, max, _))), _) => {
                used[k] = true;
                bad.push(format!("{line} (its LONG_FUNCTIONS ceiling: {max})"));
            }
            (None, _) => bad.push(line),
        }
    }
    for ((path, name, _, _), u) in LONG_FUNCTIONS.iter().zip(used) {
        if !u {
            bad.push(format!(
                "{path}: `{name}` in LONG_FUNCTIONS but within {MAX_FN_LINES} lines (or gone): drop it"
            ));
        }
    }
    verdict("no function over 60 lines outside tests", bad);
}

#[test]
fn no_reference_to_files_outside_the_repository() {
    let mut bad = Vec::new();
    for rel in files() {
        if !(rel.ends_with(".rs") || rel.ends_with(".toml") || rel.ends_with(".md")) {
            continue;
        }
        for (i, line) in read(&rel).lines().enumerate() {
            for needle in FOREIGN {
                if line.contains(needle) {
                    bad.push(format!(
                        "{rel}:{}: stands alone: names `{needle}`, which a clone of the repository does not have (cite the paper by its title, link docs/)",
                        i + 1
                    ));
                }
            }
        }
    }
    verdict("no reference to files outside the repository", bad);
}

/// The checks themselves can fail: a path against the layers, a foreign reference.
#[test]
fn the_checks_catch_what_they_should() {
    let file: syn::File = syn::parse_str(
        "use crate::replay::Replay; use super::super::sim::x; fn f() { crate::hmi::g(); }",
    )
    .unwrap();
    let tops: Vec<_> = Paths::of(&file, vec!["log".into(), "quality".into()])
        .iter()
        .filter_map(top_module)
        .collect();
    assert_eq!(tops, ["replay", "sim", "hmi"]);
    // `super` from a nested module stays in its top module.
    let file: syn::File = syn::parse_str("use super::Column;").unwrap();
    let u = &Paths::of(&file, vec!["log".into(), "quality".into()])[0];
    assert_eq!(top_module(u).as_deref(), Some("log"));
    // A long function is found, a test function is not.
    let body = "    let x = 1;\n".repeat(MAX_FN_LINES);
    let text = format!("fn long() {{\n{body}}}\n#[cfg(test)]\nmod t {{ fn long() {{\n{body}}} }}");
    let mut v = LongFunctions {
        rel: "x.rs",
        max: MAX_FN_LINES,
        found: Vec::new(),
    };
    v.visit_file(&syn::parse_str(&text).unwrap());
    assert_eq!(v.found.len(), 1, "{:?}", v.found);
    let want = format!(
        "x.rs:1: function size: `long` is {} lines",
        MAX_FN_LINES + 2
    );
    assert!(v.found[0].contains(&want), "{:?}", v.found);
    assert!(FOREIGN.iter().all(|n| !n.is_empty()));
    // The firmware's table puts the supervisor above the panel, and an unlisted module in
    // the base layer.
    let firmware = INSIDE[0].1;
    assert!(layer(firmware, "panel") < layer(firmware, "app"));
    assert_eq!(layer(firmware, "not_a_module"), 1);
    // Two sibling files that reach each other are a circle; a module and its own
    // submodule are not.
    let m = |p: &str| -> ModPath { p.split("::").map(str::to_string).collect() };
    let known: std::collections::BTreeSet<ModPath> =
        [m("a"), m("b"), m("a::c")].into_iter().collect();
    let file: syn::File = syn::parse_str("use super::b::X; use crate::a::c::Y;").unwrap();
    let from_a = reached(&m("a"), &Paths::of(&file, m("a")), &known);
    assert_eq!(from_a, [m("a::c"), m("b")].into_iter().collect());
    let mut edges = std::collections::BTreeMap::new();
    edges.insert(m("a"), from_a);
    edges.insert(m("a::c"), [m("a")].into_iter().collect());
    assert!(circles(&edges).is_empty(), "{:?}", circles(&edges));
    edges.insert(m("b"), [m("a")].into_iter().collect());
    assert_eq!(circles(&edges), vec![vec![m("a"), m("b")]]);
}

/// 6. **Typed errors**: no library function of the core, the firmware or a host library returns
///    `Result<_, String>` (the binary's `cli/` and test modules excepted): a library error
///    is a `thiserror` type with fields, and its text is made where it is shown.
#[test]
fn no_string_errors_in_the_library() {
    let root = workspace();
    let mut bad = Vec::new();
    for f in files() {
        let lib = (f.starts_with("sim-host/src/") && !f.starts_with("sim-host/src/cli/"))
            || (f.starts_with("crates/monitor-") && f.contains("/src/"))
            || f.starts_with("src/")
            || f.starts_with("python/src/");
        if !lib || !f.ends_with(".rs") {
            continue;
        }
        let text = std::fs::read_to_string(root.join(&f)).unwrap_or_default();
        // (A file's test items, wherever they stand, are tests; the code after them is not.)
        for (n, line) in code_lines(&f, &text) {
            let compact: String = line.split_whitespace().collect();
            if compact.contains("Result<") && compact.contains(",String>") {
                bad.push(format!("{f}:{n}: {}", line.trim()));
            }
        }
    }
    assert!(bad.is_empty(), "Result<_, String> in the library: {bad:#?}");
}

/// 7. **Unique names**: no type (`struct`, `enum`, `trait`, `type`, public, crate-visible
///    or private) of the core, the firmware, the host crates, `sim-host` and its benches,
///    the QEMU programs or the Python bindings has the name of another (test modules and
///    the tests' shared scenarios excepted): a name a user or a drives engineer searches for
///    finds one thing.
#[test]
fn no_type_name_is_defined_twice() {
    let root = workspace();
    let mut seen: std::collections::BTreeMap<String, Vec<String>> = Default::default();
    for f in files() {
        let bench = f.contains("/benches/");
        let code_dir = f.starts_with("src/")
            || f.starts_with("sim-host/src/")
            || f.starts_with("python/src/")
            || (f.starts_with("crates/") && f.contains("/src/"))
            || bench;
        if !code_dir
            || !f.ends_with(".rs")
            || (is_test_file(&f) && !bench)
            || is_shared_scenarios(&f)
            || f.ends_with("/tests.rs")
        {
            continue;
        }
        let text = std::fs::read_to_string(root.join(&f)).unwrap_or_default();
        for (n, line) in code_lines(&f, &text) {
            // (An indented `type` is an associated type of an impl or trait, not a
            // definition of its own.)
            if line.trim_start().starts_with("type ") && line.starts_with(char::is_whitespace) {
                continue;
            }
            let mut words = line.split_whitespace().peekable();
            // Any visibility: `pub`, `pub(crate)`, `pub(super)`, or none.
            if words.peek().is_some_and(|w| w.starts_with("pub")) {
                words.next();
            }
            let (Some(kind), Some(name)) = (words.next(), words.next()) else {
                continue;
            };
            if !["struct", "enum", "trait", "type"].contains(&kind) {
                continue;
            }
            let name: String = name
                .chars()
                .take_while(|c| c.is_ascii_alphanumeric() || *c == '_')
                .collect();
            seen.entry(name).or_default().push(format!("{f}:{n}"));
        }
    }
    let twice: Vec<String> = seen
        .iter()
        .filter(|(_, at)| at.len() > 1)
        .map(|(n, at)| format!("{n}: {}", at.join(", ")))
        .collect();
    assert!(seen.len() > 300, "only {} type names found", seen.len());
    assert!(
        twice.is_empty(),
        "type names defined twice in the workspace: {twice:#?}"
    );
}
