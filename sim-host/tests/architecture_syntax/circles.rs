//! Import circles between the files of one crate: which file modules a file's paths reach
//! ([`reached`]), and the groups of files that reach each other ([`circles`]).

use super::PathUse;
use std::collections::{BTreeMap, BTreeSet};

/// A file's module path inside its crate (`log::quality::report` as its parts; the crate
/// root is empty).
pub type ModPath = Vec<String>;

/// The file modules of `known` that the paths `uses` of the file `file` reach (the longest
/// known prefix of each `crate::`, `super::` or `self::` path), the file itself left out.
/// Paths written inside a test module are left out.
pub fn reached(file: &ModPath, uses: &[PathUse], known: &BTreeSet<ModPath>) -> BTreeSet<ModPath> {
    let mut out = BTreeSet::new();
    for u in uses {
        if u.module.iter().any(|m| m == "tests") {
            continue;
        }
        let s = &u.segments;
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
