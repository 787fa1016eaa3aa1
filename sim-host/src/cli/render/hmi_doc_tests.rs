//! docs/hmi.md's example screen is the program's: the block after a marker
//! `<!-- hmi-screen: live c@2 6@7 +3 80x24 -->` (the live simulation of the demo's motor;
//! keys at seconds of its time, `+S` more seconds run after the last key; the terminal's
//! size) is rendered here on ratatui's test backend and compared line by line.
//! `UPDATE_DOCS=1 cargo test -p sim-host --bin sim-host docs_hmi` rewrites the block with
//! what the program draws now.

use super::*;
use ratatui::backend::TestBackend;
use ratatui::Terminal;
use sim_host::hmi::live::LiveSim;
use sim_host::hmi::{Key, Source};
use std::path::PathBuf;

/// docs/hmi.md.
fn page() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../docs/hmi.md")
}

/// A marker's recipe: the keys with the times they are pressed at [s], the seconds run
/// after the last key, and the terminal's size.
#[derive(Debug, PartialEq)]
struct Recipe {
    keys: Vec<(char, f64)>,
    after_s: f64,
    size: (u16, u16),
}

/// Reads `live c@2 6@7 +3 80x24`.
fn recipe(spec: &str) -> Recipe {
    let words: Vec<&str> = spec.split_whitespace().collect();
    assert_eq!(words.first(), Some(&"live"), "only the live source: {spec}");
    let mut r = Recipe {
        keys: Vec::new(),
        after_s: 0.0,
        size: (80, 24),
    };
    for w in &words[1..] {
        if let Some((k, t)) = w.split_once('@') {
            let key = k.chars().next().expect("a key");
            r.keys.push((key, t.parse().expect("a time")));
        } else if let Some(s) = w.strip_prefix('+') {
            r.after_s = s.parse().expect("seconds");
        } else if let Some((c, h)) = w.split_once('x') {
            r.size = (c.parse().expect("columns"), h.parse().expect("rows"));
        } else {
            panic!("`{w}` in `{spec}`");
        }
    }
    r
}

/// The screen the recipe leads to, one string per row (trailing blanks trimmed).
fn rendered(r: &Recipe) -> Vec<String> {
    let mut live = LiveSim::demo_motor().expect("reference motor");
    let mut state = live.initial_state();
    let mut now = 0.0;
    let run_to = |live: &mut LiveSim, state: &mut HmiState, now: &mut f64, t: f64| {
        while *now + 0.125 < t {
            live.advance(0.25, state);
            *now += 0.25;
        }
    };
    for &(k, t) in &r.keys {
        run_to(&mut live, &mut state, &mut now, t);
        live.key(Key::Char(k), &mut state);
    }
    let end = now + r.after_s;
    run_to(&mut live, &mut state, &mut now, end);
    let (w, h) = r.size;
    let mut t = Terminal::new(TestBackend::new(w, h)).expect("test terminal");
    t.draw(|f| render(f, &state)).expect("draw");
    let buf = t.backend().buffer();
    (0..h)
        .map(|y| {
            let row: String = (0..w).map(|x| buf[(x, y)].symbol().to_string()).collect();
            row.trim_end().to_string()
        })
        .collect()
}

/// Each marked block of the page: its recipe, and the line range of the block's text
/// (after the opening fence, up to the closing one).
fn marked_blocks(md: &str) -> Vec<(String, std::ops::Range<usize>)> {
    let lines: Vec<&str> = md.lines().collect();
    let mut out = Vec::new();
    for (k, l) in lines.iter().enumerate() {
        let Some(spec) = l
            .trim()
            .strip_prefix("<!-- hmi-screen:")
            .and_then(|s| s.strip_suffix("-->"))
        else {
            continue;
        };
        let open = (k + 1..lines.len())
            .find(|&j| lines[j].starts_with("```"))
            .expect("a block after the marker");
        let close = (open + 1..lines.len())
            .find(|&j| lines[j].starts_with("```"))
            .expect("the block's end");
        out.push((spec.trim().to_string(), open + 1..close));
    }
    out
}

/// The lines that differ, `-` the page's, `+` the program's.
fn diff(page: &[&str], program: &[String]) -> String {
    let mut d = String::new();
    for k in 0..page.len().max(program.len()) {
        let (a, b) = (page.get(k).copied(), program.get(k).map(String::as_str));
        if a.map(str::trim_end) != b {
            d += &format!(
                "line {}:\n- {}\n+ {}\n",
                k + 1,
                a.unwrap_or(""),
                b.unwrap_or("")
            );
        }
    }
    d
}

#[test]
fn docs_hmi_example_screen_is_what_the_program_draws() {
    let md = std::fs::read_to_string(page()).expect("docs/hmi.md");
    let blocks = marked_blocks(&md);
    assert!(
        !blocks.is_empty(),
        "no `<!-- hmi-screen: ... -->` marker in docs/hmi.md"
    );
    let mut lines: Vec<String> = md.lines().map(str::to_string).collect();
    let mut failures = String::new();
    // (From the last block up, so that a rewrite keeps the earlier ranges.)
    for (spec, range) in blocks.iter().rev() {
        let program = rendered(&recipe(spec));
        let shown: Vec<&str> = md.lines().collect::<Vec<_>>()[range.clone()].to_vec();
        let d = diff(&shown, &program);
        if !d.is_empty() {
            failures += &format!("docs/hmi.md, the screen `{spec}`:\n{d}\n");
            lines.splice(range.clone(), program);
        }
    }
    if failures.is_empty() {
        return;
    }
    if std::env::var_os("UPDATE_DOCS").is_some() {
        std::fs::write(page(), lines.join("\n") + "\n").expect("docs/hmi.md rewritten");
        return;
    }
    panic!("{failures}(UPDATE_DOCS=1 rewrites the page with what the program draws)");
}

/// The words of `text` joined by single spaces (a Markdown paragraph's line breaks, the
/// screen's wrapped header).
fn words(text: &str) -> String {
    text.split_whitespace().collect::<Vec<_>>().join(" ")
}

/// The state the screen's header gives (after the time, up to the residuals' title), as
/// the page's prose quotes it.
#[test]
fn docs_hmi_quotes_the_screens_header() {
    let md = std::fs::read_to_string(page()).expect("docs/hmi.md");
    for (spec, _) in marked_blocks(&md) {
        let rows = rendered(&recipe(&spec));
        let top = rows
            .iter()
            .take_while(|r| !r.contains("residuals against"))
            .skip(1)
            .cloned()
            .collect::<Vec<_>>()
            .join(" ");
        let header = top.split(" s  ").nth(1).expect("a time in the header");
        assert!(
            words(&md).contains(&format!("read `{}`", words(header))),
            "docs/hmi.md does not quote the header `{header}`"
        );
    }
}

#[test]
fn a_marker_reads_as_its_recipe() {
    assert_eq!(
        recipe("live c@2 6@7 +3 80x24"),
        Recipe {
            keys: vec![('c', 2.0), ('6', 7.0)],
            after_s: 3.0,
            size: (80, 24),
        }
    );
    let md = "a\n<!-- hmi-screen: live +1 80x24 -->\ntext\n```\nx\ny\n```\n";
    assert_eq!(marked_blocks(md), vec![("live +1 80x24".to_string(), 4..6)]);
    assert_eq!(
        diff(&["a ", "b"], &["a".into(), "c".into()]),
        "line 2:\n- b\n+ c\n"
    );
}
