//! The workspace's files as the architecture test reads them: the list ([`files`]), their
//! text and syntax ([`read`], [`parse`]), which are code and which are tests, and the
//! one-line-per-violation failure ([`verdict`]), and a file's lines outside its tests
//! ([`code_lines`]).

use std::path::{Path, PathBuf};

/// The workspace's folders of Rust code.
pub const CODE_DIRS: [&str; 5] = ["crates/", "src/", "sim-host/", "tests/", "tools/"];

/// The workspace's root folder.
pub fn workspace() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../..")
        .canonicalize()
        .expect("the workspace folder")
}

/// The workspace's files (relative paths with `/`), tracked by git, else found by walking.
pub fn files() -> Vec<String> {
    let root = workspace();
    let git = std::process::Command::new("git")
        .arg("-C")
        .arg(&root)
        .args(["ls-files", "-z"])
        .output();
    if let Ok(out) = git {
        if out.status.success() && !out.stdout.is_empty() {
            return String::from_utf8_lossy(&out.stdout)
                .split('\0')
                .filter(|f| !f.is_empty() && root.join(f).is_file())
                .map(str::to_string)
                .collect();
        }
    }
    let mut found = Vec::new();
    walk(&root, &root, &mut found);
    found
}

fn walk(root: &Path, dir: &Path, found: &mut Vec<String>) {
    let Ok(entries) = std::fs::read_dir(dir) else {
        return;
    };
    for e in entries.flatten() {
        let path = e.path();
        let name = e.file_name().to_string_lossy().to_string();
        if name.starts_with('.') || name == "target" {
            continue;
        }
        if path.is_dir() {
            walk(root, &path, found);
        } else if let Ok(rel) = path.strip_prefix(root) {
            found.push(rel.to_string_lossy().replace('\\', "/"));
        }
    }
}

/// The text of the workspace file `rel`.
pub fn read(rel: &str) -> String {
    std::fs::read_to_string(workspace().join(rel)).unwrap_or_else(|e| panic!("{rel}: {e}"))
}

/// The syntax of the workspace file `rel`.
pub fn parse(rel: &str) -> syn::File {
    syn::parse_file(&read(rel)).unwrap_or_else(|e| {
        let at = e.span().start();
        panic!("{rel}:{}:{}: cannot parse: {e}", at.line, at.column + 1)
    })
}

/// The lines (first, last; from 1) of the items of `file` that are tests: an item, an
/// impl's or a trait's item, a field or a variant carrying `#[cfg(test)]` or `#[test]`, at
/// any depth. Only these: the code after a file's first `#[cfg(test)]` is read.
pub fn test_spans(file: &syn::File) -> Vec<(usize, usize)> {
    use syn::spanned::Spanned;
    use syn::visit::Visit;
    struct Tests(Vec<(usize, usize)>);
    impl Tests {
        fn skip(&mut self, attrs: &[syn::Attribute], span: proc_macro2::Span) -> bool {
            let test = super::is_cfg_test(attrs);
            if test {
                let first = attrs.first().map_or(span, |a| a.pound_token.span);
                self.0.push((first.start().line, span.end().line));
            }
            test
        }
    }
    impl<'ast> Visit<'ast> for Tests {
        fn visit_item(&mut self, i: &'ast syn::Item) {
            if !self.skip(item_attrs(i), i.span()) {
                syn::visit::visit_item(self, i);
            }
        }
        fn visit_impl_item(&mut self, i: &'ast syn::ImplItem) {
            let attrs = match i {
                syn::ImplItem::Const(c) => &c.attrs[..],
                syn::ImplItem::Fn(f) => &f.attrs,
                syn::ImplItem::Type(t) => &t.attrs,
                syn::ImplItem::Macro(m) => &m.attrs,
                _ => &[],
            };
            if !self.skip(attrs, i.span()) {
                syn::visit::visit_impl_item(self, i);
            }
        }
        fn visit_trait_item(&mut self, i: &'ast syn::TraitItem) {
            let attrs = match i {
                syn::TraitItem::Const(c) => &c.attrs[..],
                syn::TraitItem::Fn(f) => &f.attrs,
                syn::TraitItem::Type(t) => &t.attrs,
                syn::TraitItem::Macro(m) => &m.attrs,
                _ => &[],
            };
            if !self.skip(attrs, i.span()) {
                syn::visit::visit_trait_item(self, i);
            }
        }
        fn visit_field(&mut self, f: &'ast syn::Field) {
            if !self.skip(&f.attrs, f.span()) {
                syn::visit::visit_field(self, f);
            }
        }
        fn visit_variant(&mut self, v: &'ast syn::Variant) {
            if !self.skip(&v.attrs, v.span()) {
                syn::visit::visit_variant(self, v);
            }
        }
    }
    let mut t = Tests(Vec::new());
    t.visit_file(file);
    t.0
}

/// The attributes of an item.
pub fn item_attrs(i: &syn::Item) -> &[syn::Attribute] {
    use syn::Item as I;
    match i {
        I::Const(x) => &x.attrs,
        I::Enum(x) => &x.attrs,
        I::ExternCrate(x) => &x.attrs,
        I::Fn(x) => &x.attrs,
        I::ForeignMod(x) => &x.attrs,
        I::Impl(x) => &x.attrs,
        I::Macro(x) => &x.attrs,
        I::Mod(x) => &x.attrs,
        I::Static(x) => &x.attrs,
        I::Struct(x) => &x.attrs,
        I::Trait(x) => &x.attrs,
        I::TraitAlias(x) => &x.attrs,
        I::Type(x) => &x.attrs,
        I::Union(x) => &x.attrs,
        I::Use(x) => &x.attrs,
        _ => &[],
    }
}

/// The lines of `text` (the source of `rel`) outside its tests ([`test_spans`]), each with
/// its number (from 1): a test module, a `#[test]` function, a `#[cfg(test)]` helper are
/// left out wherever they stand, and everything else is read, after them too.
pub fn code_lines<'t>(rel: &str, text: &'t str) -> Vec<(usize, &'t str)> {
    let file = syn::parse_file(text).unwrap_or_else(|e| {
        let at = e.span().start();
        panic!("{rel}:{}:{}: cannot parse: {e}", at.line, at.column + 1)
    });
    let tests = test_spans(&file);
    text.lines()
        .enumerate()
        .map(|(k, l)| (k + 1, l))
        .filter(|(n, _)| !tests.iter().any(|(a, b)| (a..=b).contains(&n)))
        .collect()
}

/// Fails with every violation, one per line.
pub fn verdict(rule: &str, violations: Vec<String>) {
    assert!(
        violations.is_empty(),
        "{} violation(s) of the rule \"{rule}\":\n{}",
        violations.len(),
        violations.join("\n")
    );
}

/// A Rust file of the workspace's code folders.
pub fn is_code(rel: &str) -> bool {
    rel.ends_with(".rs") && CODE_DIRS.iter().any(|d| rel.starts_with(d))
}

/// A file of tests (`tests/` folders and benches).
pub fn is_test_file(rel: &str) -> bool {
    rel.starts_with("tests/") || rel.contains("/tests/") || rel.contains("/benches/")
}

/// A file of the tests' shared scenarios (`crates/monitor-testkit/src/`, a dev-only
/// crate): test code for the functions' length and the unique type names, code otherwise.
pub fn is_shared_scenarios(rel: &str) -> bool {
    rel.starts_with("crates/monitor-testkit/src/")
}

/// The workspace's packages: (the folder of each tracked `Cargo.toml` with a `[package]`,
/// ending in `/`, empty for the root; the package's name).
pub fn packages() -> Vec<(String, String)> {
    files()
        .into_iter()
        .filter(|f| f == "Cargo.toml" || f.ends_with("/Cargo.toml"))
        .filter_map(|f| {
            let toml: toml::Table = read(&f).parse().ok()?;
            let name = toml.get("package")?.get("name")?.as_str()?.to_string();
            Some((f.trim_end_matches("Cargo.toml").to_string(), name))
        })
        .collect()
}

/// The `src/` folders of the workspace's packages with more than one `.rs` file there: the
/// crates whose files can reach each other.
pub fn crate_sources() -> Vec<String> {
    let all = files();
    let mut out: Vec<String> = packages()
        .into_iter()
        .map(|(dir, _)| format!("{dir}src/"))
        .filter(|src| {
            all.iter()
                .filter(|f| f.starts_with(src.as_str()) && f.ends_with(".rs"))
                .count()
                > 1
        })
        .collect();
    out.sort();
    out.dedup();
    out
}

/// The code after a file's first `#[cfg(test)]` is read: only the test items are left out
/// (a test module, a `#[cfg(test)]` helper, a `#[test]` function), not what follows them.
#[test]
fn the_code_after_a_test_item_is_read() {
    let text = "fn a() {}\n#[cfg(test)]\nfn helper() {}\nfn b() {}\n#[cfg(test)]\nmod tests {\n    #[test]\n    fn t() {}\n}\nimpl X {\n    #[cfg(test)]\n    fn only_tests() {}\n    fn c() {}\n}\n#[cfg(not(test))]\nfn d() {}\n";
    let lines: Vec<usize> = code_lines("x.rs", text)
        .into_iter()
        .map(|(n, _)| n)
        .collect();
    assert_eq!(lines, [1, 4, 10, 13, 14, 15, 16], "{text}");
}
