//! No library crate names a command-line flag in what it says (issue 64, "errors that name
//! fields, not flags"): a report's sentence or an error is spelled by the front end that
//! asked (`monitor_replay::Spelling`, carried as `ReplayOptions::words`), so a string
//! literal in `crates/*/src` that reads like a flag (`"... --commission ..."`) is a
//! sentence the command line would say to a Python user. Comments and docs may name flags.

use std::path::{Path, PathBuf};

/// The `.rs` files under `dir`, recursively.
fn sources(dir: &Path, out: &mut Vec<PathBuf>) {
    let Ok(entries) = std::fs::read_dir(dir) else {
        return;
    };
    for e in entries.flatten() {
        let p = e.path();
        if p.is_dir() {
            sources(&p, out);
        } else if p.extension().is_some_and(|x| x == "rs") {
            out.push(p);
        }
    }
}

/// The code of a line without its comment (`//` outside a string literal), and whether a
/// string literal is still open at its end (`open` on entry: one was open at its start).
/// Char literals of a quote (`'"'`) and one-line raw strings (`r#"..."#`) are kept whole.
fn code_of(line: &str, open: &mut bool) -> String {
    let c: Vec<char> = line.chars().collect();
    let mut code = String::new();
    let mut k = 0;
    while k < c.len() {
        let rest: String = c[k..].iter().take(4).collect();
        if *open {
            if c[k] == '\\' {
                code.extend(c.get(k..k + 2).unwrap_or(&c[k..]));
                k += 2;
                continue;
            }
            *open = c[k] != '"';
        } else if rest.starts_with("'\"'") || rest.starts_with("'\\\"'") {
            let n = if rest.starts_with("'\"'") { 3 } else { 4 };
            code.extend(&c[k..k + n]);
            k += n;
            continue;
        } else if rest.starts_with("r#\"") {
            let tail: String = c[k..].iter().collect();
            let end = tail[3..].find("\"#").map_or(tail.len(), |e| e + 5);
            code.push_str(&tail[..end]);
            k += tail[..end].chars().count();
            continue;
        } else if rest.starts_with("//") {
            break;
        } else if c[k] == '"' {
            *open = true;
        }
        code.push(c[k]);
        k += 1;
    }
    code
}

/// `--` then a lowercase letter: a long flag (`--from`, `--commission`).
fn names_a_flag(text: &str) -> bool {
    text.as_bytes()
        .windows(3)
        .any(|w| w[0] == b'-' && w[1] == b'-' && w[2].is_ascii_lowercase())
}

#[test]
fn no_string_in_a_library_crate_names_a_flag() {
    let crates = Path::new(env!("CARGO_MANIFEST_DIR")).join("..");
    let mut files = Vec::new();
    for c in std::fs::read_dir(&crates).expect("crates/").flatten() {
        sources(&c.path().join("src"), &mut files);
    }
    files.sort();
    assert!(
        files.len() > 50,
        "the library crates' sources: {}",
        files.len()
    );
    let mut found = Vec::new();
    for f in &files {
        let text = std::fs::read_to_string(f).expect("a source file");
        let mut open = false;
        for (n, line) in text.lines().enumerate() {
            let was_open = open;
            let trimmed = line.trim_start();
            if !was_open && (trimmed.starts_with("//") || trimmed.starts_with("#[doc")) {
                continue;
            }
            if names_a_flag(&code_of(line, &mut open)) {
                found.push(format!("{}:{}: {}", f.display(), n + 1, line.trim()));
            }
        }
    }
    assert!(
        found.is_empty(),
        "a library crate names a command-line flag in a string; spell it with \
         monitor_replay::Spelling (options.words) instead:\n{}",
        found.join("\n")
    );
}

#[test]
fn the_check_sees_a_flag_in_a_string_and_not_in_a_comment() {
    let mut open = false;
    assert!(names_a_flag(&code_of(
        r#"    "give --load viscous","#,
        &mut open
    )));
    assert!(!open);
    assert!(!names_a_flag(&code_of(
        r#"    x(); // the command line's --load"#,
        &mut open
    )));
    // A string continued on the next line.
    assert!(!names_a_flag(&code_of(r#"    "the error \"#, &mut open)));
    assert!(open);
    assert!(names_a_flag(&code_of(r#"     or --from","#, &mut open)));
    assert!(!open);
    // A quote as a char, then a comment.
    assert!(!names_a_flag(&code_of(
        r#"    if c == '"' { x } // --load"#,
        &mut open
    )));
    assert!(!open);
    assert!(names_a_flag(&code_of(
        r##"    r#"a "raw" --baseline"#"##,
        &mut open
    )));
    assert!(!open);
}
