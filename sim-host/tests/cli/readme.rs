//! The README's walkthroughs print what the README shows: every code block that starts with
//! `$ sim-host ...` is run (from the repository's root, with the binary for `sim-host`), and
//! every output line the block shows must appear in the command's output, in order. A line
//! `...` skips any number of lines; `...` inside a line stands for any text there; `# ...`
//! lines are comments. Commands
//! that write files write them into a temporary folder (`--out NAME` is rewritten there, and
//! so is `NAME` where a later walkthrough reads it).

use std::path::{Path, PathBuf};

fn repo() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("..")
}

/// One walkthrough: the command's arguments and the lines shown after it.
struct Walkthrough {
    line: usize,
    args: Vec<String>,
    shown: Vec<String>,
}

/// The `$ sim-host` blocks of a Markdown text.
fn walkthroughs(md: &str) -> Vec<Walkthrough> {
    let mut out = Vec::new();
    let lines: Vec<&str> = md.lines().collect();
    let mut k = 0;
    while k < lines.len() {
        if !lines[k].starts_with("```") {
            k += 1;
            continue;
        }
        let start = k + 1;
        let mut end = start;
        while end < lines.len() && !lines[end].starts_with("```") {
            end += 1;
        }
        let block = &lines[start..end.min(lines.len())];
        let mut i = 0;
        while i < block.len() {
            let Some(cmd) = block[i].strip_prefix("$ sim-host ") else {
                i += 1;
                continue;
            };
            let line = start + i + 1;
            let mut text = cmd.to_string();
            while text.ends_with('\\') && i + 1 < block.len() {
                text.pop();
                i += 1;
                text.push(' ');
                text.push_str(block[i].trim());
            }
            i += 1;
            let mut shown = Vec::new();
            while i < block.len() && !block[i].starts_with("$ ") {
                // `# ...` lines are the reader's comments, not output.
                if !block[i].starts_with('#') {
                    shown.push(block[i].to_string());
                }
                i += 1;
            }
            out.push(Walkthrough {
                line,
                args: text.split_whitespace().map(str::to_string).collect(),
                shown,
            });
        }
        k = end + 1;
    }
    out
}

/// Whether `actual` matches the shown line `want` (`...` inside it: any text).
fn matches(want: &str, actual: &str) -> bool {
    let parts: Vec<&str> = want.split("...").collect();
    if parts.len() == 1 {
        return want.trim_end() == actual.trim_end();
    }
    let mut rest = actual;
    for (j, p) in parts.iter().enumerate() {
        let p = if j + 1 == parts.len() {
            p.trim_end()
        } else {
            p
        };
        if p.is_empty() {
            continue;
        }
        if j == 0 {
            let Some(r) = rest.strip_prefix(p) else {
                return false;
            };
            rest = r;
        } else {
            let Some(at) = rest.find(p) else {
                return false;
            };
            rest = &rest[at + p.len()..];
        }
    }
    parts
        .last()
        .is_none_or(|l| l.trim_end().is_empty() || rest.trim_end().is_empty())
}

fn check(file: &str) -> usize {
    let md = std::fs::read_to_string(repo().join(file)).expect("read the markdown");
    let tmp = tempfile::tempdir().expect("tempdir");
    let mut failures = Vec::new();
    let runs = walkthroughs(&md);
    // Files a walkthrough wrote (`--out NAME`), read by the later ones by that name.
    let mut written: Vec<String> = Vec::new();
    for w in &runs {
        let mut args = w.args.clone();
        for k in 0..args.len() {
            if args[k] == "--out" && k + 1 < args.len() {
                written.push(args[k + 1].clone());
            }
        }
        for a in args.iter_mut() {
            if written.contains(a) {
                let name = Path::new(a.as_str())
                    .file_name()
                    .map(|n| n.to_os_string())
                    .unwrap_or_default();
                *a = tmp.path().join(name).display().to_string();
            }
        }
        let o = assert_cmd::Command::cargo_bin("sim-host")
            .expect("binary")
            .current_dir(repo())
            .args(&args)
            .output()
            .expect("run");
        let stdout = String::from_utf8_lossy(&o.stdout).to_string();
        if !o.status.success() {
            failures.push(format!(
                "{file}:{}: `sim-host {}` failed: {}",
                w.line,
                w.args.join(" "),
                String::from_utf8_lossy(&o.stderr)
            ));
            continue;
        }
        let actual: Vec<&str> = stdout.lines().collect();
        let mut at = 0;
        for want in w.shown.iter().filter(|l| !l.trim().is_empty()) {
            if want.trim() == "..." {
                continue;
            }
            match actual[at..].iter().position(|a| matches(want, a)) {
                Some(p) => at += p + 1,
                None => {
                    failures.push(format!(
                        "{file}:{}: `sim-host {}` does not print (in order):\n  {want}\nIt printed:\n{stdout}",
                        w.line,
                        w.args.join(" ")
                    ));
                    break;
                }
            }
        }
    }
    assert!(failures.is_empty(), "{}", failures.join("\n\n"));
    runs.len()
}

/// The blocks after a marker `<!-- output: sim-host ARGS -->`: the command's arguments, the
/// marker's line and the block's lines (a program's output shown without its `$` line).
fn marked_outputs(md: &str) -> Vec<Walkthrough> {
    let lines: Vec<&str> = md.lines().collect();
    let mut out = Vec::new();
    for (k, l) in lines.iter().enumerate() {
        let Some(cmd) = l
            .trim()
            .strip_prefix("<!-- output: sim-host ")
            .and_then(|c| c.strip_suffix("-->"))
        else {
            continue;
        };
        let Some(open) = (k + 1..lines.len()).find(|&j| lines[j].starts_with("```")) else {
            continue;
        };
        let close = (open + 1..lines.len())
            .find(|&j| lines[j].starts_with("```"))
            .unwrap_or(lines.len());
        out.push(Walkthrough {
            line: k + 1,
            args: cmd.split_whitespace().map(str::to_string).collect(),
            shown: lines[open + 1..close]
                .iter()
                .map(|l| l.to_string())
                .collect(),
        });
    }
    out
}

/// Every marked output block of `file` is printed by its command, line by line in order
/// (the walkthroughs' rules); the number of blocks.
fn check_marked(file: &str) -> usize {
    let md = std::fs::read_to_string(repo().join(file)).expect("read the markdown");
    let blocks = marked_outputs(&md);
    let mut failures = Vec::new();
    for b in &blocks {
        let o = assert_cmd::Command::cargo_bin("sim-host")
            .expect("binary")
            .current_dir(repo())
            .args(&b.args)
            .output()
            .expect("run");
        let stdout = String::from_utf8_lossy(&o.stdout).to_string();
        let actual: Vec<&str> = stdout.lines().collect();
        let mut at = 0;
        for want in b
            .shown
            .iter()
            .filter(|l| !l.trim().is_empty() && l.trim() != "...")
        {
            match actual[at..].iter().position(|a| matches(want, a)) {
                Some(p) => at += p + 1,
                None => {
                    failures.push(format!(
                        "{file}:{}: `sim-host {}` does not print (in order):\n  {want}\nIt printed:\n{stdout}",
                        b.line,
                        b.args.join(" ")
                    ));
                    break;
                }
            }
        }
    }
    assert!(failures.is_empty(), "{}", failures.join("\n\n"));
    blocks.len()
}

/// docs/hmi.md's blocks of program output (the keys `hmi --help` lists) are what the
/// program prints; its screen is checked by the binary's own test
/// (`cli::render::hmi::doc_tests`).
#[test]
fn docs_hmi_output_blocks_are_what_the_program_prints() {
    assert!(
        check_marked("docs/hmi.md") >= 1,
        "no `<!-- output: ... -->` in docs/hmi.md"
    );
}

#[test]
fn the_readme_walkthroughs_print_what_the_readme_shows() {
    let n = check("README.md");
    assert!(n >= 4, "only {n} walkthroughs found");
}

/// The walkthroughs of docs/ print what the pages show (the same rules as the README's), so
/// that the documentation and the program cannot drift apart.
#[test]
fn the_docs_walkthroughs_print_what_the_docs_show() {
    let mut n = 0;
    for page in [
        "docs/model-vs-measurement.md",
        "docs/own-motor.md",
        "docs/your-own-law.md",
    ] {
        n += check(page);
    }
    assert!(n >= 5, "only {n} walkthroughs found in docs/");
}

/// The README names every command `sim-host --help` lists (as `` `command``, in its table),
/// so that a newcomer finds each one.
#[test]
fn the_readme_names_every_command() {
    let o = assert_cmd::Command::cargo_bin("sim-host")
        .expect("binary")
        .arg("--help")
        .output()
        .expect("run");
    let help = String::from_utf8_lossy(&o.stdout).to_string();
    let commands: Vec<&str> = help
        .lines()
        .skip_while(|l| !l.starts_with("Commands:"))
        .skip(1)
        .take_while(|l| l.starts_with("  "))
        .filter_map(|l| l.split_whitespace().next())
        .filter(|c| *c != "help")
        .collect();
    assert!(commands.len() >= 10, "commands found: {commands:?}");
    let md = std::fs::read_to_string(repo().join("README.md")).expect("read the README");
    let missing: Vec<&&str> = commands
        .iter()
        .filter(|c| !md.contains(&format!("| `{c}")))
        .collect();
    assert!(
        missing.is_empty(),
        "README.md's command table does not name {missing:?}"
    );
}

#[test]
fn shown_lines_match_with_elisions() {
    assert!(matches("a ... c", "a b c"));
    assert!(matches("verdict: FAULT rs +...", "verdict: FAULT rs +50 %"));
    assert!(!matches(
        "verdict: FAULT rs +5...",
        "verdict: FAULT lr -50 %"
    ));
    assert!(matches("x", "x  "));
    assert!(!matches("x", "y"));
    let w = walkthroughs("```\n$ sim-host demo \\\n   --paper\nline\n...\n```\n");
    assert_eq!(w.len(), 1);
    assert_eq!(w[0].args, ["demo", "--paper"]);
    assert_eq!(w[0].shown, ["line", "..."]);
    let m = marked_outputs("<!-- output: sim-host hmi --help -->\n\n```\n  q  quit\n```\n");
    assert_eq!(m.len(), 1);
    assert_eq!(m[0].line, 1);
    assert_eq!(m[0].args, ["hmi", "--help"]);
    assert_eq!(m[0].shown, ["  q  quit"]);
}
