//! `diagnose --report R.html`: the page a crew prints, checked as a user reads it.
//!
//! On real recordings of a motor with shorted turns and of the healthy motor (currents
//! only, 1 kHz) and on an independent simulator's log (voltages, currents, speed): the page
//! carries the text's verdict in a banner of at most two lines, a row per finding right
//! below it with each finding's sentence once, charts (inline SVG) that draw every series
//! their legend names (the negative sequence on a log with the currents only too), and no
//! text block; an output that is an input is refused and the input kept. In a real browser
//! (headless Chromium, where installed; skipped with a note otherwise) nothing runs off the
//! page at A4's width (794 px) or a phone's (390 px), and a page that does overflow is
//! caught by the same check; the banner is at most two lines at A4's width, and every
//! legend entry's colour is drawn. Screenshots go to the test's temporary folder.

use crate::chart_legend;

use assert_cmd::Command;
use monitor_testkit::text::verdict_line_of;
use std::path::{Path, PathBuf};

fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("..")
}

/// Runs `diagnose` on `log` with `params` and `--report out`; returns (stdout, stderr).
fn diagnose_with_report(params: &Path, log: &Path, out: &Path) -> (String, String) {
    let o = Command::cargo_bin("sim-host")
        .expect("binary")
        .arg("diagnose")
        .arg("--params")
        .arg(params)
        .arg(log)
        .arg("--report")
        .arg(out)
        .output()
        .expect("run");
    let (so, se) = (
        String::from_utf8_lossy(&o.stdout).to_string(),
        String::from_utf8_lossy(&o.stderr).to_string(),
    );
    assert!(o.status.success(), "diagnose failed: {se}");
    (so, se)
}

/// The cases: (name, parameter file, log).
fn cases() -> Vec<(&'static str, PathBuf, PathBuf)> {
    let r = root();
    vec![
        (
            "itsc_shorted_turns",
            r.join("examples/recordings/itsc/baldor_0p75hp.toml"),
            r.join("examples/recordings/itsc/SC_A0_B0_C1_001.csv"),
        ),
        (
            "motulator_dol",
            r.join("examples/logs/motulator_2p2kw_dol.toml"),
            r.join("examples/logs/motulator_2p2kw_dol.csv"),
        ),
        (
            "itsc_healthy",
            r.join("examples/recordings/itsc/baldor_0p75hp.toml"),
            r.join("examples/recordings/itsc/SC_HLT_001.csv"),
        ),
    ]
}

/// `diagnose --json` of `log`: the document.
fn diagnose_json(params: &Path, log: &Path) -> serde_json::Value {
    let o = Command::cargo_bin("sim-host")
        .expect("binary")
        .arg("diagnose")
        .arg("--params")
        .arg(params)
        .arg(log)
        .arg("--json")
        .output()
        .expect("run");
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    serde_json::from_slice(&o.stdout).expect("JSON")
}

/// The banner's text (tags taken out): `verdict: ...`.
fn banner(page: &str) -> String {
    let b = page
        .split("<p class=\"v ")
        .nth(1)
        .and_then(|b| b.split_once('>'))
        .and_then(|(_, b)| b.split("</p>").next())
        .expect("a banner");
    let mut text = String::new();
    let mut in_tag = false;
    for c in b.chars() {
        match c {
            '<' => {
                in_tag = true;
                // A tag ends a word (`</b><small>`).
                text.push(' ');
            }
            '>' => in_tag = false,
            c if !in_tag => text.push(c),
            _ => {}
        }
    }
    text.split_whitespace().collect::<Vec<_>>().join(" ")
}

fn html_escaped(s: &str) -> String {
    s.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
        .replace('"', "&quot;")
}

#[test]
fn the_page_says_what_the_text_says_with_charts_not_text_blocks() {
    let dir = tempfile::tempdir().expect("tmp");
    for (name, params, log) in cases() {
        let out = dir.path().join(format!("{name}.html"));
        let (text, stderr) = diagnose_with_report(&params, &log, &out);
        assert!(
            stderr.contains("report: "),
            "{name}: says where the report is"
        );
        let page = std::fs::read_to_string(&out).expect("the report");
        let verdict = verdict_line_of(&text);
        let verdict = verdict.as_str();
        assert!(!verdict.is_empty(), "{name}: a verdict line");
        // The banner's verdict (with the fault it names) is how the text's line begins,
        // with the same confidence; the rest of the line, the reasons, is the table's.
        let head = page
            .split("<p class=\"v ")
            .nth(1)
            .and_then(|b| b.split("<b>").nth(1))
            .and_then(|b| b.split("</b>").next())
            .expect("the banner's verdict");
        assert!(
            html_escaped(verdict).starts_with(head),
            "{name}: the banner's verdict {head:?} is not the text's {verdict:?}"
        );
        if let Some(c) = verdict.split("(confidence ").nth(1) {
            let c = &c[..4];
            assert!(
                banner(&page).contains(&format!("confidence {c}")),
                "{name}: the banner lacks the confidence {c}"
            );
        }
        let findings = text
            .lines()
            .skip_while(|l| *l != "findings:")
            .skip(1)
            .take_while(|l| l.starts_with("  "))
            // (A finding's sentence past 160 characters goes on, indented, on lines of its
            // own.)
            .filter(|l| !l.starts_with("      "));
        for f in findings {
            let source = f.split_whitespace().next().unwrap_or_default();
            assert!(
                page.contains(&format!("<td class=k>{source}</td>")),
                "{name}: no row for the finding {source}"
            );
        }
        assert!(page.contains("<svg"), "{name}: no chart");
        assert!(!page.contains("<pre"), "{name}: a text block");
        assert!(page.contains("Data quality"), "{name}: no data quality");
    }
}

/// The banner is at most two lines: the verdict, then the analyses by name; each finding's
/// sentence is said once on the page (the table's row), never again in the banner or below.
#[test]
fn the_banner_is_short_and_each_reason_is_said_once() {
    let dir = tempfile::tempdir().expect("tmp");
    for (name, params, log) in cases() {
        let out = dir.path().join(format!("{name}.html"));
        diagnose_with_report(&params, &log, &out);
        let page = std::fs::read_to_string(&out).expect("the report");
        let b = banner(&page);
        // Two lines of the page's 1000 px at most (about 95 characters each at the
        // banner's size; the browser test measures the lines).
        assert!(
            b.len() <= 190,
            "{name}: a banner of {} characters: {b}",
            b.len()
        );
        let doc = diagnose_json(&params, &log);
        for f in doc["findings"].as_array().expect("findings") {
            let summary = f["summary"].as_str().expect("a summary");
            let n = page.matches(&html_escaped(summary)).count();
            assert_eq!(n, 1, "{name}: {summary:?} is said {n} times");
        }
        // No paragraph, list item or cell of the page says again what another says.
        let b = blocks(&page);
        for (i, x) in b.iter().enumerate() {
            for (j, y) in b.iter().enumerate() {
                assert!(
                    i == j || !y.contains(x.as_str()),
                    "{name}: {x:?} is said again in {y:?}"
                );
            }
        }
    }
}

/// The texts of the page's paragraphs, list items and table cells (tags taken out) of
/// more than a few words: what a reader reads as one statement each.
fn blocks(page: &str) -> Vec<String> {
    // The charts taken out (their elements start with `<p` too: `<polyline`, `<path`).
    let mut html = String::new();
    for (k, part) in page.split("<svg").enumerate() {
        html.push_str(if k == 0 {
            part
        } else {
            part.split_once("</svg>").map_or("", |(_, rest)| rest)
        });
    }
    let mut out = Vec::new();
    for (open, close) in [
        ("<p>", "</p>"),
        ("<p ", "</p>"),
        ("<li", "</li>"),
        ("<td", "</td>"),
    ] {
        for part in html.split(open).skip(1) {
            // `<p>`'s body starts at once; the others' after their attributes.
            let body = if open.ends_with('>') {
                part
            } else {
                match part.split_once('>') {
                    Some((_, body)) => body,
                    None => continue,
                }
            };
            let body = body.split(close).next().unwrap_or("");
            let mut text = String::new();
            let mut in_tag = false;
            for c in body.chars() {
                match c {
                    '<' => in_tag = true,
                    '>' => in_tag = false,
                    c if !in_tag => text.push(c),
                    _ => {}
                }
            }
            let text = text.split_whitespace().collect::<Vec<_>>().join(" ");
            if text.split(' ').count() >= 6 {
                out.push(text);
            }
        }
    }
    out
}

/// Every chart of the page draws what its legend names; on a log with the currents only
/// (the real recordings) the negative sequence over time is a curve, not a legend entry
/// alone.
#[test]
fn every_legend_entry_is_drawn_and_the_negative_sequence_is_a_curve_on_currents_only() {
    let dir = tempfile::tempdir().expect("tmp");
    for (name, params, log) in cases() {
        let out = dir.path().join(format!("{name}.html"));
        diagnose_with_report(&params, &log, &out);
        let page = std::fs::read_to_string(&out).expect("the report");
        let svgs = chart_legend::svgs_of(&page);
        assert!(!svgs.is_empty(), "{name}: no chart");
        for (k, svg) in svgs.iter().enumerate() {
            chart_legend::check(svg, &format!("{name}, chart {k}"));
        }
        let sequence = svgs
            .iter()
            .find(|s| s.contains("<title>Negative sequence of the currents over time</title>"))
            .unwrap_or_else(|| panic!("{name}: no negative-sequence chart"));
        let curve = chart_legend::legend(sequence)
            .expect("a legend")
            .into_iter()
            .find(|e| e.label.starts_with("|I2|/|I1|"))
            .unwrap_or_else(|| panic!("{name}: the negative sequence is not drawn"));
        assert!(curve.points >= 10, "{name}: {curve:?}");
    }
}

#[test]
fn the_motulator_page_draws_the_residuals_lamps_and_events() {
    let dir = tempfile::tempdir().expect("tmp");
    let (_, params, log) = cases().remove(1);
    let out = dir.path().join("m.html");
    diagnose_with_report(&params, &log, &out);
    let page = std::fs::read_to_string(&out).expect("the report");
    // Four charts drawn: the residuals, the lamps, the negative sequence, the rotor or why
    // not. A drawn chart is an SVG after its heading.
    let svgs = page.matches("<svg").count();
    assert!(svgs >= 3, "{svgs} charts drawn on a log with every channel");
    for legend in ["r1", "r4 lit", "evaluating", "|I2|/|I1|"] {
        assert!(page.contains(legend), "no legend {legend:?}");
    }
}

#[test]
fn a_report_over_an_input_is_refused_and_the_input_kept() {
    let dir = tempfile::tempdir().expect("tmp");
    let (_, params, log) = cases().remove(0);
    let copy = dir.path().join("log.csv");
    std::fs::copy(&log, &copy).expect("copy");
    let before = std::fs::read(&copy).expect("read");
    let o = Command::cargo_bin("sim-host")
        .expect("binary")
        .current_dir(dir.path())
        .arg("diagnose")
        .arg("--params")
        .arg(&params)
        .arg("log.csv")
        .args(["--report", "./log.csv"])
        .output()
        .expect("run");
    assert!(!o.status.success());
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(err.contains("refusing to overwrite the input"), "{err}");
    assert_eq!(
        std::fs::read(&copy).expect("read"),
        before,
        "the input changed"
    );
}

/// A script that titles the page `fits`, or `overflows ...` naming what runs past the
/// window's right edge.
const FIT_CHECK: &str = "<script>window.addEventListener('load',()=>{const v=window.innerWidth;const w=document.documentElement.scrollWidth;const bad=[];document.querySelectorAll('body *').forEach(e=>{if(e.getBoundingClientRect().right>v+1)bad.push(e.tagName)});document.title=(w<=v&&bad.length==0)?'fits':'overflows '+w+'>'+v+' '+bad.slice(0,5).join(',')});</script>";

/// A script that titles the page `banner N lines; legends drawn`, or names the legend
/// entries whose colour nothing visible is drawn in: the banner's lines are the distinct
/// tops of its text's boxes (each text node's, line by line), each chart's legend entries
/// are its `<desc>`'s lines,
/// and an entry's colour must be stroked or filled by more visible elements (a box of some
/// size) than the legend has marks of it.
const BANNER_AND_LEGENDS: &str = "<script>window.addEventListener('load',()=>{const v=document.querySelector('.v');const w=document.createTreeWalker(v,NodeFilter.SHOW_TEXT);const tops=[];let t;while(t=w.nextNode()){const r=document.createRange();r.selectNodeContents(t);for(const x of r.getClientRects()){if(x.height>0&&!tops.some(y=>Math.abs(y-x.top)<4))tops.push(x.top)}}const bad=[];document.querySelectorAll('svg').forEach(svg=>{const d=svg.querySelector('desc');if(!d){bad.push('no desc');return}const lines=d.textContent.split('\\n').slice(1).filter(l=>l.trim());const hex=l=>(l.match(/ \\[(#[0-9A-F]{6}) /)||[])[1];const marks={};lines.forEach(l=>{const h=hex(l);marks[h]=(marks[h]||0)+1});lines.forEach(l=>{const h=hex(l);const n=[...svg.querySelectorAll('[stroke=\"'+h+'\"],[fill=\"'+h+'\"]')].filter(e=>{const b=e.getBoundingClientRect();return b.width+b.height>0}).length;if(!h||n<=marks[h])bad.push(l.split(' [')[0])})});document.title='banner '+tops.length+' lines; '+(bad.length?'not drawn: '+bad.join(' | '):'legends drawn')});</script>";

/// Headless Chromium, where installed.
fn chromium() -> Option<PathBuf> {
    [
        "/usr/bin/chromium",
        "/usr/bin/chromium-browser",
        "/usr/bin/google-chrome",
    ]
    .iter()
    .map(PathBuf::from)
    .find(|p| p.is_file())
}

/// Chromium, headless, with a fresh profile and nothing run beside the page (no network
/// of its own, no updates, no sync).
fn headless(chrome: &Path, profile: &Path) -> std::process::Command {
    let mut c = std::process::Command::new(chrome);
    c.args([
        "--headless",
        "--no-sandbox",
        "--disable-gpu",
        "--disable-quic",
        "--no-first-run",
        "--disable-background-networking",
        "--disable-component-update",
        "--disable-sync",
        "--hide-scrollbars",
    ])
    .arg(format!("--user-data-dir={}", profile.display()));
    c
}

/// The title `script` gives `page` at `width` px.
fn title_at(chrome: &Path, page: &Path, width: u32, script: &str) -> String {
    let html = std::fs::read_to_string(page).expect("page");
    let checked = page.with_extension("check.html");
    std::fs::write(
        &checked,
        html.replace("</body>", &format!("{script}</body>")),
    )
    .expect("write");
    let profile = tempfile::tempdir().expect("profile");
    let o = headless(chrome, profile.path())
        .arg(format!("--window-size={width},900"))
        .args(["--virtual-time-budget=3000", "--dump-dom"])
        .arg(format!("file://{}", checked.display()))
        .output()
        .expect("chromium");
    let dom = String::from_utf8_lossy(&o.stdout).to_string();
    dom.split("<title>")
        .nth(1)
        .and_then(|t| t.split("</title>").next())
        .unwrap_or("no title")
        .to_string()
}

/// The title the fit check gives `page` at `width` px.
fn fit_at(chrome: &Path, page: &Path, width: u32) -> String {
    title_at(chrome, page, width, FIT_CHECK)
}

#[test]
fn nothing_runs_off_the_page_at_a4_or_a_phones_width_in_a_browser() {
    let Some(chrome) = chromium() else {
        eprintln!("note: Chromium is not installed: the browser check of the report is skipped");
        return;
    };
    let shots = Path::new(env!("CARGO_TARGET_TMPDIR")).join("diagnose_report");
    std::fs::create_dir_all(&shots).expect("folder");
    for (name, params, log) in cases() {
        let out = shots.join(format!("{name}.html"));
        diagnose_with_report(&params, &log, &out);
        for width in [794, 390] {
            let fit = fit_at(&chrome, &out, width);
            assert_eq!(fit, "fits", "{name} at {width} px");
            let png = shots.join(format!("{name}_{width}.png"));
            let profile = tempfile::tempdir().expect("profile");
            let _ = headless(&chrome, profile.path())
                .arg(format!("--window-size={width},2600"))
                .arg(format!("--screenshot={}", png.display()))
                .arg(format!("file://{}", out.display()))
                .output();
        }
        // At A4's width the banner is two lines at most, and every legend entry is drawn.
        let seen = title_at(&chrome, &out, 794, BANNER_AND_LEGENDS);
        let lines: usize = seen
            .strip_prefix("banner ")
            .and_then(|t| t.split(' ').next())
            .and_then(|n| n.parse().ok())
            .unwrap_or_else(|| panic!("{name}: {seen}"));
        assert!((1..=2).contains(&lines), "{name}: {seen}");
        assert!(seen.ends_with("; legends drawn"), "{name}: {seen}");
    }
    eprintln!("screenshots: {}", shots.display());
    // The checks can fail: a line too long for a phone runs off the page; a banner of three
    // lines is counted as three; a legend entry whose colour is drawn nowhere is named.
    let wide = shots.join("wide.html");
    let long = "x".repeat(400);
    std::fs::write(&wide, format!("<!doctype html><html><head><meta name=viewport content=\"width=device-width\"><title>t</title></head><body><pre>{long}</pre></body></html>"))
        .expect("write");
    assert!(fit_at(&chrome, &wide, 390).starts_with("overflows"));
    let words = "a reason ".repeat(40);
    let bad = shots.join("bad.html");
    std::fs::write(&bad, format!("<!doctype html><html><head><title>t</title></head><body style=\"width:794px\"><p class=\"v\"><b>verdict: healthy: {words}</b></p><svg width=\"100\" height=\"100\"><desc>legend:\nr1 [#1F77B4 line]: 3 points, y from 0 to 1</desc><polyline stroke=\"#1F77B4\" points=\"0,0 10,0\"/></svg></body></html>"))
        .expect("write");
    let seen = title_at(&chrome, &bad, 794, BANNER_AND_LEGENDS);
    let lines: usize = seen
        .strip_prefix("banner ")
        .and_then(|t| t.split(' ').next())
        .and_then(|n| n.parse().ok())
        .unwrap_or(0);
    assert!(lines > 2, "{seen}");
    assert!(seen.ends_with("not drawn: r1"), "{seen}");
}
