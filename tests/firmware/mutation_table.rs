//! docs/firmware.md's table of the review's mutations cites, for each, the lines of the
//! assertions that fail: each cited line must still be one (an `assert`, a checking helper's
//! call, an `expect` or `unwrap`), so a test file edited above a cited line fails here until
//! the table is measured again (issue 82's table pointed at comments, `let`s and signatures).

use std::path::Path;

fn read(rel: &str) -> String {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join(rel);
    std::fs::read_to_string(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()))
}

#[test]
fn every_line_the_mutation_table_cites_is_an_assertion() {
    let docs = read("docs/firmware.md");
    let start = docs
        .find("**The review's mutations**")
        .expect("the table in docs/firmware.md");
    let end = start
        + docs[start..]
            .find("**cargo-mutants over")
            .expect("the end of the table");
    let mut cited = 0;
    let mut wrong = Vec::new();
    for row in docs[start..end].lines().filter(|l| l.starts_with("| ")) {
        let cells: Vec<&str> = row.split(" | ").collect();
        let last = cells.last().copied().unwrap_or("");
        let mut file: Option<String> = None;
        for part in last.split('`').skip(1).step_by(2) {
            let (f, n) = match part.rsplit_once(':') {
                Some((f, n)) if n.chars().all(|c| c.is_ascii_digit()) && !n.is_empty() => (f, n),
                _ => continue,
            };
            if f.ends_with(".rs") {
                file = Some(f.to_string());
            } else if !f.is_empty() {
                continue;
            }
            let Some(f) = &file else { continue };
            let n: usize = n.parse().unwrap();
            let text = read(f);
            let line = text.lines().nth(n - 1).unwrap_or("").trim();
            cited += 1;
            let checks = ["assert", "writes(", "reads(", ".expect(", ".unwrap()"];
            if !checks.iter().any(|c| line.contains(c)) {
                wrong.push(format!("{f}:{n}: {line}"));
            }
        }
    }
    assert!(cited >= 40, "{cited} lines cited");
    assert!(
        wrong.is_empty(),
        "cited lines that are no assertion: {wrong:#?}"
    );
}
