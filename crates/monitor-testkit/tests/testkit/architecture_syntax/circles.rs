//! Import circles between the files of one crate: which file modules a file's paths reach
//! ([`reached`]), and the groups of files that reach each other ([`circles`]).

use super::PathUse;
use std::collections::{BTreeMap, BTreeSet};

/// A file's module path inside its crate (`log::quality::report` as its parts; the crate
/// root is empty).
pub type ModPath = Vec<String>;

/// The names a file's `use`s bring into scope: (the module the `use` is written in, the
/// name) -> the path it imports.
type Imports<'a> = BTreeMap<(&'a [String], &'a str), &'a [String]>;

/// The file modules of `known` that the paths `uses` of the file `file` reach (the longest
/// known prefix of each `crate::`, `super::` or `self::` path, and of each path that starts
/// with a name such a `use` imported), the file itself left out. Paths written inside a
/// test module are left out.
pub fn reached(file: &ModPath, uses: &[PathUse], known: &BTreeSet<ModPath>) -> BTreeSet<ModPath> {
    let imports: Imports = uses
        .iter()
        .filter_map(|u| {
            Some((
                (u.module.as_slice(), u.binds.as_deref()?),
                u.segments.as_slice(),
            ))
        })
        .collect();
    let mut out = BTreeSet::new();
    for u in uses {
        if u.module.iter().any(|m| m == "tests") {
            continue;
        }
        let s = &written_out(u, &imports);
        let (base, rest): (ModPath, &[String]) = match s.first().map(String::as_str) {
            Some("crate") => (Vec::new(), &s[1..]),
            Some("self") => (u.module.clone(), &s[1..]),
            Some("super") => {
                let ups = s.iter().take_while(|x| *x == "super").count();
                let Some(keep) = u.module.len().checked_sub(ups) else {
                    continue;
                };
                (u.module[..keep].to_vec(), &s[ups..])
            }
            _ => continue,
        };
        let mut cur = base.clone();
        let mut target = known.contains(&base).then(|| base.clone());
        for r in rest {
            cur.push(r.clone());
            if known.contains(&cur) {
                target = Some(cur.clone());
            } else {
                break;
            }
        }
        if let Some(t) = target.filter(|t| t != file) {
            out.insert(t);
        }
    }
    out
}

/// The segments of `u`, a path in code that starts with a name a `use` of its module
/// imported written out through that `use` (`render::text::f` after `use super::render;`
/// is `super::render::text::f`).
fn written_out(u: &PathUse, imports: &Imports) -> Vec<String> {
    let s = &u.segments;
    let first = s.first().map_or("", String::as_str);
    if u.binds.is_some() || matches!(first, "crate" | "self" | "super") {
        return s.clone();
    }
    let Some(path) = imports.get(&(u.module.as_slice(), first)) else {
        return s.clone();
    };
    let mut out = path.to_vec();
    if out.last().is_some_and(|l| l == "self") {
        out.pop();
    }
    out.extend(s[1..].iter().cloned());
    out
}

/// The groups of files (two or more) that reach each other through `edges`, counting only
/// edges between files of which neither is inside the other (a module and its own
/// submodules share one reader by design).
pub fn circles(edges: &BTreeMap<ModPath, BTreeSet<ModPath>>) -> Vec<Vec<ModPath>> {
    let inside = |a: &ModPath, b: &ModPath| a.len() <= b.len() && b[..a.len()] == a[..];
    let mut graph: BTreeMap<&ModPath, Vec<&ModPath>> = BTreeMap::new();
    for (a, bs) in edges {
        for b in bs {
            if !inside(a, b) && !inside(b, a) {
                graph.entry(a).or_default().push(b);
            }
        }
    }
    let reach = |from: &ModPath| {
        let mut seen = BTreeSet::new();
        let mut stack = vec![from];
        while let Some(v) = stack.pop() {
            for w in graph.get(v).into_iter().flatten() {
                if seen.insert(*w) {
                    stack.push(w);
                }
            }
        }
        seen
    };
    let reaches: BTreeMap<&ModPath, BTreeSet<&ModPath>> =
        graph.keys().map(|v| (*v, reach(v))).collect();
    let mut groups: Vec<Vec<ModPath>> = Vec::new();
    for (v, r) in &reaches {
        if groups.iter().any(|g| g.contains(v)) {
            continue;
        }
        let mut g: Vec<ModPath> = r
            .iter()
            .filter(|w| reaches.get(*w).is_some_and(|back| back.contains(v)))
            .map(|w| (*w).clone())
            .collect();
        if !g.is_empty() {
            if !g.contains(v) {
                g.push((*v).clone());
            }
            g.sort();
            groups.push(g);
        }
    }
    groups
}

/// A circle through a module a `use` imported is found: `cli::convert` imports
/// `super::render` and calls `render::text::f`, and `cli::render::text` uses
/// `crate::cli::convert::X` (the shape of a circle the command line had).
#[test]
fn a_circle_through_an_imported_module_is_found() {
    use super::Paths;
    let m = |p: &str| -> ModPath { p.split("::").map(str::to_string).collect() };
    let known: BTreeSet<ModPath> = [
        m("cli"),
        m("cli::convert"),
        m("cli::render"),
        m("cli::render::text"),
    ]
    .into_iter()
    .collect();
    let convert: syn::File =
        syn::parse_str("use super::render; fn run() { render::text::f(); }").unwrap();
    let text: syn::File = syn::parse_str("fn f(c: &crate::cli::convert::X) {}").unwrap();
    let mut edges = BTreeMap::new();
    for (module, file) in [("cli::convert", &convert), ("cli::render::text", &text)] {
        let uses = Paths::of(file, m(module));
        edges.insert(m(module), reached(&m(module), &uses, &known));
    }
    assert!(edges[&m("cli::convert")].contains(&m("cli::render::text")));
    assert_eq!(
        circles(&edges),
        vec![vec![m("cli::convert"), m("cli::render::text")]]
    );
}
