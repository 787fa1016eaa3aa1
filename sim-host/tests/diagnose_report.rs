//! `diagnose --report R.html`: the page a crew prints, checked as a user reads it.
//!
//! On a real recording of a motor with shorted turns (currents only) and on an
//! independent simulator's log (voltages, currents, speed): the page carries the same
//! verdict line as the text, a row per finding, charts (inline SVG) and no text block; an
//! output that is an input is refused and the input kept. In a real browser (headless
//! Chromium, where installed; skipped with a note otherwise) nothing runs off the page at
//! A4's width (794 px) or a phone's (390 px), and a page that does overflow is caught by
//! the same check. Screenshots go to the test's temporary folder.

use assert_cmd::Command;
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
    ]
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
        let verdict = text
            .lines()
            .find(|l| l.starts_with("verdict: "))
            .expect("a verdict line");
        assert!(
            page.contains(&html_escaped(verdict)),
            "{name}: the page's verdict differs from the text's {verdict:?}"
        );
        let findings = text
            .lines()
            .skip_while(|l| *l != "findings:")
            .skip(1)
            .take_while(|l| l.starts_with("  "));
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

/// The title the fit check gives `page` at `width` px.
fn fit_at(chrome: &Path, page: &Path, width: u32) -> String {
    let html = std::fs::read_to_string(page).expect("page");
    let checked = page.with_extension("check.html");
    std::fs::write(
        &checked,
        html.replace("</body>", &format!("{FIT_CHECK}</body>")),
    )
    .expect("write");
    let o = std::process::Command::new(chrome)
        .args([
            "--headless",
            "--no-sandbox",
            "--disable-gpu",
            "--hide-scrollbars",
        ])
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
            let _ = std::process::Command::new(&chrome)
                .args([
                    "--headless",
                    "--no-sandbox",
                    "--disable-gpu",
                    "--hide-scrollbars",
                ])
                .arg(format!("--window-size={width},2600"))
                .arg(format!("--screenshot={}", png.display()))
                .arg(format!("file://{}", out.display()))
                .output();
        }
    }
    eprintln!("screenshots: {}", shots.display());
    // The check can fail: a line too long for a phone runs off the page.
    let wide = shots.join("wide.html");
    let long = "x".repeat(400);
    std::fs::write(&wide, format!("<!doctype html><html><head><meta name=viewport content=\"width=device-width\"><title>t</title></head><body><pre>{long}</pre></body></html>"))
        .expect("write");
    assert!(fit_at(&chrome, &wide, 390).starts_with("overflows"));
}
