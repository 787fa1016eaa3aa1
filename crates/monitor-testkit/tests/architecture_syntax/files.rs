//! The workspace's files as the architecture test reads them: the list ([`files`]), their
//! text and syntax ([`read`], [`parse`]), which are code and which are tests, and the
//! one-line-per-violation failure ([`verdict`]).

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
