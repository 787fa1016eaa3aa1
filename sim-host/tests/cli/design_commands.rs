//! docs/design.md's command table ("Commands and their JSON", the section the README
//! points to for "every option and every JSON key") is checked against the command line
//! itself: every subcommand `sim-host --help` lists, and every long option its own `--help`
//! lists, is named in that section. A command or an option added without its line there
//! fails here, naming it.

use assert_cmd::Command;
use monitor_testkit::text::help_subcommands as subcommands;
use std::path::Path;

/// The text of `sim-host ARGS`.
fn help(args: &[&str]) -> String {
    let out = Command::cargo_bin("sim-host")
        .expect("the binary")
        .args(args)
        .output()
        .expect("runs");
    String::from_utf8_lossy(&out.stdout).into_owned()
}

/// The long options (`--name`) a help text lists, without `--help` and `--version`.
fn long_options(text: &str) -> Vec<String> {
    text.lines()
        .skip_while(|l| !l.starts_with("Options:"))
        .filter_map(|l| {
            // An option line: "  -o, --out <OUT>" or "      --out <OUT>" (a description's
            // wrapped lines are indented further).
            if l.len() - l.trim_start().len() > 6 {
                return None;
            }
            let l = l.trim_start();
            let rest = if let Some(r) = l.strip_prefix("--") {
                r
            } else if l.starts_with('-') {
                l.split_once(", --")?.1
            } else {
                return None;
            };
            rest.split(|c: char| !(c.is_ascii_alphanumeric() || c == '-'))
                .next()
        })
        .filter(|o| !o.is_empty() && *o != "help" && *o != "version")
        .map(|o| format!("--{o}"))
        .collect()
}

#[test]
fn every_command_and_option_is_in_the_design_command_table() {
    let design =
        std::fs::read_to_string(Path::new(env!("CARGO_MANIFEST_DIR")).join("../docs/design.md"))
            .expect("docs/design.md");
    let start = design
        .find("## 14. Commands and their JSON")
        .expect("the commands section");
    let end = design[start + 3..]
        .find("\n## ")
        .map_or(design.len(), |k| start + 3 + k);
    let section = &design[start..end];
    let top = help(&["--help"]);
    let commands = subcommands(&top);
    assert!(commands.len() >= 10, "commands found: {commands:?}");
    let mut missing = Vec::new();
    for c in &commands {
        if !section.contains(&format!("`{c}")) && !section.contains(&format!("| `{c} ")) {
            missing.push(format!("command `{c}`"));
        }
        let mut texts = vec![help(&[c, "--help"])];
        for sub in subcommands(&texts[0]) {
            texts.push(help(&[c, &sub, "--help"]));
        }
        for t in &texts {
            for o in long_options(t) {
                if !section.contains(&o) {
                    missing.push(format!("`{c}` option {o}"));
                }
            }
        }
    }
    missing.sort();
    missing.dedup();
    assert!(
        missing.is_empty(),
        "not in docs/design.md section 14: {missing:#?}"
    );
}
