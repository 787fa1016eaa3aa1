//! The syntax the architecture test (`tests/testkit/architecture.rs`) reads: every path and `use`
//! of a file with the module it is written in ([`Paths`]), the top module a path reaches
//! ([`top_module`]), a file's module path ([`module_of`]), the long functions outside
//! tests ([`LongFunctions`]), and what an engine may not spell ([`spelling`], rule 8, with
//! its tests).

pub mod allowances;
pub mod circles;
pub mod crates;
pub mod files;
pub mod layers;
pub mod sentences;
pub mod sentences_left;
pub mod spelling;

use syn::visit::Visit;

/// True for `#[cfg(test)]` (or a `cfg` naming `test` that only tests build, `all(test, ..)`)
/// and `#[test]`; not for `cfg(not(test))` nor `cfg(any(test, ..))`, which other builds
/// compile too.
pub fn is_cfg_test(attrs: &[syn::Attribute]) -> bool {
    attrs.iter().any(|a| {
        let cfg = match &a.meta {
            syn::Meta::List(l) if a.path().is_ident("cfg") => l.tokens.to_string(),
            _ => String::new(),
        };
        let words: Vec<&str> = cfg
            .split(|c: char| !c.is_alphanumeric() && c != '_')
            .collect();
        (words.contains(&"test") && !words.contains(&"not") && !words.contains(&"any"))
            || a.path().is_ident("test")
    })
}

/// One path as written: the module it is written in (file and inline modules), its
/// leading segments, its line.
#[derive(Debug, Clone)]
pub struct PathUse {
    /// The module it is written in.
    pub module: Vec<String>,
    /// Its leading segments.
    pub segments: Vec<String>,
    /// Its line.
    pub line: usize,
    /// For a `use`, the name it brings into scope (its last segment, its `as` name, or the
    /// module of a `self`); `None` for a glob and for a path written in code.
    pub binds: Option<String>,
}

/// Collects every path and `use` of a file.
pub struct Paths {
    /// The module being visited.
    pub module: Vec<String>,
    /// The paths found.
    pub found: Vec<PathUse>,
    /// Leave out the items that are `mod` declarations (the crate root's rule).
    pub skip_mod_items: bool,
}

impl Paths {
    /// Every path and `use` of `file`, a file of module `module`.
    pub fn of(file: &syn::File, module: Vec<String>) -> Vec<PathUse> {
        let mut p = Paths {
            module,
            found: Vec::new(),
            skip_mod_items: false,
        };
        p.visit_file(file);
        p.found
    }

    fn use_tree(&mut self, tree: &syn::UseTree, mut prefix: Vec<String>, line: usize) {
        match tree {
            syn::UseTree::Path(p) => {
                prefix.push(p.ident.to_string());
                self.use_tree(&p.tree, prefix, line);
            }
            syn::UseTree::Name(n) => {
                let name = n.ident.to_string();
                let binds = if name == "self" {
                    prefix.last().cloned()
                } else {
                    Some(name.clone())
                };
                prefix.push(name);
                self.push(prefix, line, binds);
            }
            syn::UseTree::Rename(r) => {
                prefix.push(r.ident.to_string());
                self.push(prefix, line, Some(r.rename.to_string()));
            }
            syn::UseTree::Glob(_) => self.push(prefix, line, None),
            syn::UseTree::Group(g) => {
                for t in &g.items {
                    self.use_tree(t, prefix.clone(), line);
                }
            }
        }
    }

    fn push(&mut self, segments: Vec<String>, line: usize, binds: Option<String>) {
        if !segments.is_empty() {
            self.found.push(PathUse {
                module: self.module.clone(),
                segments,
                line,
                binds,
            });
        }
    }
}

impl<'ast> Visit<'ast> for Paths {
    fn visit_item_mod(&mut self, m: &'ast syn::ItemMod) {
        if m.content.is_none() && self.skip_mod_items {
            return;
        }
        self.module.push(m.ident.to_string());
        syn::visit::visit_item_mod(self, m);
        self.module.pop();
    }

    fn visit_item_use(&mut self, u: &'ast syn::ItemUse) {
        let line = u.use_token.span.start().line;
        self.use_tree(&u.tree, Vec::new(), line);
    }

    fn visit_path(&mut self, p: &'ast syn::Path) {
        if p.leading_colon.is_none() {
            if let Some(first) = p.segments.first() {
                let line = first.ident.span().start().line;
                let segs = p.segments.iter().map(|s| s.ident.to_string()).collect();
                self.push(segs, line, None);
            }
        }
        syn::visit::visit_path(self, p);
    }

    /// A macro's body is tokens, not syntax `syn` walks: its paths (`crate::a::f` in a
    /// `format!`'s arguments, a `use` a macro expands) are read from the tokens, each run of
    /// names joined by `::` one path.
    fn visit_macro(&mut self, m: &'ast syn::Macro) {
        self.tokens(m.tokens.clone());
        syn::visit::visit_macro(self, m);
    }
}

impl Paths {
    /// Every run `a::b::c` of names in `tokens` (and in its groups) as a path.
    fn tokens(&mut self, tokens: proc_macro2::TokenStream) {
        use proc_macro2::{Spacing, TokenTree};
        let mut run: Vec<String> = Vec::new();
        let mut line = 0;
        let mut colons = 0;
        let mut after_colon = false;
        let flush = |me: &mut Self, run: &mut Vec<String>, line: usize| {
            if !run.is_empty() {
                me.push(std::mem::take(run), line, None);
            }
        };
        for t in tokens {
            match t {
                TokenTree::Ident(i) => {
                    if colons != 2 {
                        flush(self, &mut run, line);
                        after_colon = false;
                    }
                    if run.is_empty() {
                        line = i.span().start().line;
                        if after_colon {
                            // `::a` (a leading colon): an external crate's path.
                            after_colon = false;
                            colons = 0;
                            continue;
                        }
                    }
                    run.push(i.to_string());
                    colons = 0;
                }
                TokenTree::Punct(p) if p.as_char() == ':' => {
                    colons += 1;
                    if run.is_empty() && colons == 2 {
                        after_colon = true;
                    }
                    if p.spacing() == Spacing::Alone && colons == 1 {
                        flush(self, &mut run, line);
                        colons = 0;
                    }
                }
                TokenTree::Group(g) => {
                    flush(self, &mut run, line);
                    colons = 0;
                    self.tokens(g.stream());
                }
                _ => {
                    flush(self, &mut run, line);
                    colons = 0;
                    after_colon = false;
                }
            }
        }
        flush(self, &mut run, line);
    }
}

/// The top-level module a path of a file in module `module` reaches in its own crate, if
/// any: `crate::X`, `super::…::X`, `self::X`, or a bare `X` in the crate root (the
/// caller decides whether a bare name is a module).
pub fn top_module(u: &PathUse) -> Option<String> {
    let s = &u.segments;
    match s.first()?.as_str() {
        "crate" => s.get(1).cloned(),
        "super" => {
            let ups = s.iter().take_while(|x| *x == "super").count();
            let depth = u.module.len().checked_sub(ups)?;
            if depth == 0 {
                s.get(ups).cloned()
            } else {
                u.module.first().cloned()
            }
        }
        "self" => u.module.first().cloned().or_else(|| s.get(1).cloned()),
        first if u.module.is_empty() => Some(first.to_string()),
        _ => None,
    }
}

/// A sim-host library file's module path (`log/quality/report.rs` -> `log::quality::report`).
pub fn module_of(rel_in_src: &str) -> Vec<String> {
    let no_ext = rel_in_src.trim_end_matches(".rs");
    let mut parts: Vec<String> = no_ext.split('/').map(str::to_string).collect();
    if parts.last().is_some_and(|p| p == "mod" || p == "lib") {
        parts.pop();
    }
    parts
}

/// Collects the functions (outside tests) longer than `max` lines.
pub struct LongFunctions<'a> {
    /// The file's path, for the findings.
    pub rel: &'a str,
    /// Longest function allowed [lines].
    pub max: usize,
    /// One line per function found.
    pub found: Vec<String>,
}

impl LongFunctions<'_> {
    fn check(&mut self, attrs: &[syn::Attribute], sig: &syn::Signature, body: &syn::Block) {
        if is_cfg_test(attrs) {
            return;
        }
        let start = sig.fn_token.span.start().line;
        let end = body.brace_token.span.close().end().line;
        let n = end + 1 - start;
        if n > self.max {
            self.found.push(format!(
                "{}:{start}: function size: `{}` is {n} lines (fn to closing brace), more than {}",
                self.rel, sig.ident, self.max
            ));
        }
    }
}

impl<'ast> Visit<'ast> for LongFunctions<'_> {
    fn visit_item_mod(&mut self, m: &'ast syn::ItemMod) {
        if !is_cfg_test(&m.attrs) {
            syn::visit::visit_item_mod(self, m);
        }
    }
    fn visit_item_fn(&mut self, f: &'ast syn::ItemFn) {
        self.check(&f.attrs, &f.sig, &f.block);
        if !is_cfg_test(&f.attrs) {
            syn::visit::visit_item_fn(self, f);
        }
    }
    fn visit_impl_item_fn(&mut self, f: &'ast syn::ImplItemFn) {
        self.check(&f.attrs, &f.sig, &f.block);
        syn::visit::visit_impl_item_fn(self, f);
    }
    fn visit_trait_item_fn(&mut self, f: &'ast syn::TraitItemFn) {
        if let Some(body) = &f.default {
            self.check(&f.attrs, &f.sig, body);
        }
        syn::visit::visit_trait_item_fn(self, f);
    }
    fn visit_item_impl(&mut self, i: &'ast syn::ItemImpl) {
        if !is_cfg_test(&i.attrs) {
            syn::visit::visit_item_impl(self, i);
        }
    }
}

/// A path inside a macro's body is read (a circle made in a `format!`'s arguments is one),
/// and a path with a leading `::` (another crate's) is not a path of the crate.
#[test]
fn the_paths_inside_a_macro_are_read() {
    let file: syn::File =
        syn::parse_str("fn f() { format!(\"{}\", crate::hmi::g(::other::x, super::y::Z)); }")
            .unwrap();
    let found: Vec<Vec<String>> = Paths::of(&file, vec!["log".into()])
        .into_iter()
        .map(|u| u.segments)
        .filter(|s| s.len() > 1)
        .collect();
    let want: Vec<Vec<String>> = [&["crate", "hmi", "g"][..], &["super", "y", "Z"]]
        .iter()
        .map(|p| p.iter().map(|x| x.to_string()).collect())
        .collect();
    assert_eq!(found, want);
}
