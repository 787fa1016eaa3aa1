//! The report's plots a person can read (issue 28): over the 5 s motulator log no line is
//! a solid band (fewer than 2 drawn points per pixel column: envelopes over the long span,
//! zoomed panels of a few supply periods), the model "before" is dashed and drawn after
//! the other lines, one unit per error chart, a scatter over one operating point is
//! replaced by a sentence, and the headings are words, not file names. Every chart draws
//! what its legend names (issue 79): each entry has points drawn, no two look alike, an
//! error drawn per supply period is its RMS and says so, and the ladder's steps are whole
//! ticks named by what each step added.

use crate::chart_legend;

use assert_cmd::Command;
use std::path::{Path, PathBuf};

/// Drawn points per pixel column a line may have at most.
const MAX_POINTS_PER_COLUMN: f64 = 2.0;

fn repo() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .parent()
        .expect("workspace")
        .to_path_buf()
}

fn run(args: &[&str]) {
    let logs = repo().join("examples/logs");
    let p = logs.join("motulator_2p2kw_dol.toml");
    let csv = logs.join("motulator_2p2kw_dol.csv");
    let out = Command::cargo_bin("sim-host")
        .expect("binary")
        .args(args)
        .args([
            "--params",
            p.to_str().expect("utf8"),
            csv.to_str().expect("utf8"),
        ])
        .output()
        .expect("runs");
    assert!(
        out.status.success(),
        "{args:?}: {}",
        String::from_utf8_lossy(&out.stderr)
    );
}

/// The point lists of every `<polyline>` of an SVG as (x, y) pixels.
fn polylines(svg: &str) -> Vec<(String, Vec<(f64, f64)>)> {
    svg.split("<polyline")
        .skip(1)
        .filter_map(|p| {
            let tag = p.split('>').next()?;
            let pts = tag.split("points=\"").nth(1)?.split('"').next()?;
            let v = pts
                .split_whitespace()
                .filter_map(|xy| {
                    let (x, y) = xy.split_once(',')?;
                    Some((x.parse().ok()?, y.parse().ok()?))
                })
                .collect();
            Some((tag.to_string(), v))
        })
        .collect()
}

/// The stroke colour of a polyline's tag.
fn stroke(tag: &str) -> &str {
    tag.split("stroke=\"")
        .nth(1)
        .and_then(|s| s.split('"').next())
        .unwrap_or("")
}

/// The largest number of drawn points per pixel column of any line of `svg`: each data
/// colour's points (all its polylines: a dashed line is many) over the columns it spans.
fn points_per_column(svg: &str) -> f64 {
    let lines = polylines(svg);
    let mut colours: Vec<&str> = lines
        .iter()
        .filter(|(t, v)| v.len() > 2 && stroke(t) != "#000000")
        .map(|(t, _)| stroke(t))
        .collect();
    colours.sort_unstable();
    colours.dedup();
    colours
        .iter()
        .map(|c| {
            let v: Vec<(f64, f64)> = lines
                .iter()
                .filter(|(t, _)| stroke(t) == *c)
                .flat_map(|(_, v)| v.iter().copied())
                .collect();
            let lo = v.iter().map(|p| p.0).fold(f64::INFINITY, f64::min);
            let hi = v.iter().map(|p| p.0).fold(f64::NEG_INFINITY, f64::max);
            v.len() as f64 / (hi - lo + 1.0)
        })
        .fold(0.0, f64::max)
}

/// `explain --from 1.5 --report DIR` of the motulator log: (the temporary folder, DIR).
fn explain_report() -> (tempfile::TempDir, PathBuf) {
    let tmp = tempfile::tempdir().expect("tmp");
    let dir = tmp.path().join("e");
    run(&[
        "explain",
        "--from",
        "1.5",
        "--report",
        dir.to_str().expect("utf8"),
    ]);
    (tmp, dir)
}

fn headings(html: &str) -> Vec<String> {
    html.split("<h3>")
        .skip(1)
        .filter_map(|h| h.split("</h3>").next().map(str::to_string))
        .collect()
}

/// Every SVG chart in `dir` held to [`chart_legend::check`]; how many there were.
fn legends_drawn(dir: &Path) -> usize {
    let mut n = 0;
    for e in std::fs::read_dir(dir).expect("dir") {
        let path = e.expect("entry").path();
        if path.extension().is_some_and(|x| x == "svg") {
            let svg = std::fs::read_to_string(&path).expect("svg");
            chart_legend::check(&svg, &path.display().to_string());
            n += 1;
        }
    }
    n
}

fn check_dir(dir: &Path, stems: &[&str]) -> String {
    assert!(legends_drawn(dir) >= stems.len());
    for stem in stems {
        let path = dir.join(format!("{stem}.svg"));
        let svg =
            std::fs::read_to_string(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
        let n = points_per_column(&svg);
        assert!(
            n > 0.0 && n < MAX_POINTS_PER_COLUMN,
            "{stem}: {n:.2} drawn points per pixel column (a solid band from {MAX_POINTS_PER_COLUMN})"
        );
    }
    let html = std::fs::read_to_string(dir.join("report.html")).expect("report");
    let hs = headings(&html);
    assert!(hs.len() >= stems.len(), "{hs:?}");
    for h in &hs {
        assert!(
            h.split_whitespace().count() >= 3 && !h.split_whitespace().any(|w| stems.contains(&w)),
            "a heading that is not words: {h}"
        );
    }
    html
}

#[test]
fn compare_report_draws_envelopes_zooms_and_one_unit_per_axis() {
    let tmp = tempfile::tempdir().expect("tmp");
    let dir = tmp.path().join("r");
    run(&["compare", "--report", dir.to_str().expect("utf8")]);
    let html = check_dir(
        &dir,
        &[
            "overlay_iqs",
            "overlay_omega_r",
            "zoom_iqs_1",
            "zoom_iqs_2",
            "overlay_ia",
            "error_time",
            "error_time_omega_r",
            "error_spectrum",
        ],
    );
    // One unit per error chart.
    let e = std::fs::read_to_string(dir.join("error_time.svg")).expect("svg");
    assert!(e.contains("[A]") && !e.contains("rad/s"));
    // The error over the 5 s log is drawn per supply period as its RMS, and named so: no
    // value below zero (the signed envelope drew down to -25 A under an "RMS" label); the
    // currents themselves are drawn as the periods' means, signed.
    for stem in ["error_time", "error_time_omega_r"] {
        let svg = std::fs::read_to_string(dir.join(format!("{stem}.svg"))).expect("svg");
        let legend = chart_legend::legend(&svg).expect("legend");
        assert!(
            legend[0].label.ends_with("(RMS per supply period)"),
            "{legend:?}"
        );
        let (lo, hi) = legend[0].y_range.expect("drawn");
        assert!(lo >= 0.0 && hi > lo, "{stem}: {lo}..{hi}");
    }
    let o = std::fs::read_to_string(dir.join("overlay_iqs.svg")).expect("svg");
    for entry in chart_legend::legend(&o).expect("legend") {
        assert!(
            entry.label.ends_with("(mean per supply period)"),
            "{entry:?}"
        );
    }
    let w = std::fs::read_to_string(dir.join("error_time_omega_r.svg")).expect("svg");
    assert!(w.contains("[rad/s]") && !w.contains("[A]"));
    // The motulator log runs at one supply voltage: no scatter against it, a sentence.
    assert!(!dir.join("error_vs_voltage.svg").exists());
    assert!(
        html.contains("Not drawn: every window's voltage"),
        "no sentence for the omitted scatter"
    );
}

#[test]
fn explain_report_draws_the_model_before_dashed_and_on_top() {
    let (_tmp, dir) = explain_report();
    check_dir(
        &dir,
        &[
            "before_after_iqs",
            "before_after_omega_r",
            "zoom_before_after_iqs_1",
            "before_after_error",
        ],
    );
    // "model before" is the palette's red (#D62728), dashed (many short segments), and the
    // last data line drawn (after the green model with the effect).
    let svg = std::fs::read_to_string(dir.join("before_after_iqs.svg")).expect("svg");
    let lines = polylines(&svg);
    let red = lines.iter().filter(|(t, _)| t.contains("#D62728")).count();
    assert!(
        red > 20,
        "the model before is not dashed: {red} red segments"
    );
    let last_green = lines
        .iter()
        .rposition(|(t, v)| t.contains("#2CA02C") && v.len() > 2)
        .expect("the model with the effect");
    let first_red = lines
        .iter()
        .position(|(t, _)| t.contains("#D62728"))
        .expect("the model before");
    assert!(
        first_red > last_green,
        "the model before lies under the other lines"
    );
}

/// The numbers (with their sign and decimals) of a text: `0.3008`, `-0.03`, `96`.
fn numbers(text: &str) -> Vec<String> {
    let mut v = Vec::new();
    let mut cur = String::new();
    for ch in text.chars().chain([' ']) {
        if ch.is_ascii_digit() || (ch == '.' && !cur.is_empty()) || (ch == '-' && cur.is_empty()) {
            cur.push(ch);
        } else {
            let n = cur.trim_end_matches('.').to_string();
            if n.chars().any(|c| c.is_ascii_digit()) {
                v.push(n);
            }
            cur.clear();
        }
    }
    v
}

/// The text of every table cell of `html`.
fn cells(html: &str) -> Vec<String> {
    html.split("<td")
        .skip(1)
        .filter_map(|c| {
            c.split_once('>')?
                .1
                .split("</td>")
                .next()
                .map(str::to_string)
        })
        .collect()
}

#[test]
fn explain_report_tables_hold_the_headline_numbers_and_the_spectrum() {
    let (_tmp, dir) = explain_report();
    let html = std::fs::read_to_string(dir.join("report.html")).expect("report");
    let headline = html
        .split("<p class=v>")
        .nth(1)
        .and_then(|h| h.split("</p>").next())
        .expect("headline");
    // The headline's finding: the effect, how much it explains, the errors before and
    // after, and the fitted values (up to the advice "Add it with ...").
    let finding = headline.split("Add it with").next().unwrap_or(headline);
    let table_numbers: Vec<String> = cells(&html).iter().flat_map(|c| numbers(c)).collect();
    let quoted = numbers(finding);
    assert!(quoted.len() >= 3, "{finding}");
    for n in &quoted {
        assert!(
            table_numbers.contains(n),
            "the headline quotes {n}, no table holds it: {finding}"
        );
    }
    // Held-back and whole-log errors before and after.
    assert!(html.contains("<th>held-back windows</th><th>whole log</th>"));
    // The plausibility flags and the motor current signature analysis.
    assert!(html.contains("[not plausible]"));
    assert!(html.contains("motor current signature analysis"));
    assert!(dir.join("mcsa_spectrum.svg").exists());
}

#[test]
fn compare_report_holds_the_advice_flags_and_identifiability() {
    let tmp = tempfile::tempdir().expect("tmp");
    let dir = tmp.path().join("r");
    run(&["compare", "--report", dir.to_str().expect("utf8")]);
    let html = std::fs::read_to_string(dir.join("report.html")).expect("report");
    assert!(html.contains("<h2>Advice</h2>"), "no advice");
    assert!(html.contains("--from 0.7"), "no --from advice");
    assert!(html.contains("[not plausible]") && html.contains("not plausible: j_kgm2"));
    assert!(html.contains("Identifiability: Jacobian rank"));
    // The data-quality stage's line and the worst windows' transients, as the text has them.
    assert!(html.contains("Data quality: clean"));
    assert!(html.contains("transient (start): the direct-on-line start"));
}

/// `explain --ladder --report`: the chart's x axis has one tick per step, named by what the
/// step added (the table's numbers), on one line below the plot, and no other tick there
/// (it numbered them 0.0, 0.2, ... 2.0 and named none).
#[test]
fn the_ladders_chart_names_each_step_on_a_whole_tick() {
    let tmp = tempfile::tempdir().expect("tmp");
    let dir = tmp.path().join("l");
    run(&[
        "explain",
        "--ladder",
        "--from",
        "0.8",
        "--to",
        "3.5",
        "--report",
        dir.to_str().expect("utf8"),
    ]);
    legends_drawn(&dir);
    let svg = std::fs::read_to_string(dir.join("ladder.svg")).expect("svg");
    // The texts of the SVG: (x, y, text).
    let texts: Vec<(f64, f64, String)> = svg
        .split("<text")
        .skip(1)
        .filter_map(|t| {
            let (head, rest) = t.split_once('>')?;
            let attr = |a: &str| -> Option<f64> {
                head.split(&format!(" {a}=\""))
                    .nth(1)?
                    .split('"')
                    .next()?
                    .parse()
                    .ok()
            };
            let text = rest.split("</text>").next()?.trim().to_string();
            Some((attr("x")?, attr("y")?, text))
        })
        .filter(|t| !t.2.is_empty())
        .collect();
    // A step's name is its number, a colon and what it did (a tick of the y axis, `1`, is
    // not one).
    let steps: Vec<&(f64, f64, String)> = texts
        .iter()
        .filter(|t| {
            t.2.split_once(": ")
                .is_some_and(|(k, _)| k.parse::<usize>().is_ok())
        })
        .collect();
    assert!(steps.len() >= 2, "{texts:?}");
    assert_eq!(steps[0].2, "0: as configured");
    assert_eq!(steps[1].2, "1: +load_torque");
    for (k, t) in steps.iter().enumerate() {
        assert!(
            t.2.starts_with(&format!("{k}: ")),
            "step {k} named {:?}",
            t.2
        );
        assert!(
            k == 0 || t.0 > steps[k - 1].0,
            "the steps run left to right: {steps:?}"
        );
    }
    // Every text on the ticks' line is a step's name.
    let line = steps[0].1;
    let on_line: Vec<&String> = texts
        .iter()
        .filter(|t| (t.1 - line).abs() < 1.0)
        .map(|t| &t.2)
        .collect();
    assert_eq!(
        on_line.len(),
        steps.len(),
        "other ticks beside the steps: {on_line:?}"
    );
    // The error over time: the model as configured, each kept step named as on the axis,
    // the chosen model refitted, its floor and the log's events (the load step at 2.5 s).
    let svg = std::fs::read_to_string(dir.join("ladder_time.svg")).expect("the time chart");
    let legend = chart_legend::legend(&svg).expect("a legend");
    let names: Vec<&str> = legend.iter().map(|e| e.label.as_str()).collect();
    assert_eq!(names[0], "0: as configured", "{names:?}");
    for s in &steps[1..] {
        assert!(
            names.contains(&s.2.as_str()),
            "{} not drawn: {names:?}",
            s.2
        );
    }
    assert!(
        names.contains(&"end: refitted on the whole log"),
        "{names:?}"
    );
    assert!(
        names
            .iter()
            .any(|n| n.starts_with("log events ") && n.ends_with("load moves")),
        "{names:?}"
    );
    // It falls in time: the first step's worst supply period is below the start's.
    let top = |label: &str| {
        legend
            .iter()
            .find(|e| e.label == label)
            .and_then(|e| e.y_range)
            .map(|r| r.1)
            .unwrap_or_else(|| panic!("{label}: {legend:?}"))
    };
    assert!(top(&steps[1].2) < top("0: as configured"), "{legend:?}");
    let html = std::fs::read_to_string(dir.join("report.html")).expect("report");
    assert!(html.contains("The ladder over time"), "the report draws it");
}

/// `compare --plot` draws the model it was asked for: each chart's legend names its
/// effects, and the error drawn is that model's (with the load torque, the q current's
/// error over time is a fraction of the paper's model's, which cannot follow the load
/// step).
#[test]
fn compare_draws_the_model_it_was_asked_for() {
    let tmp = tempfile::tempdir().expect("tmp");
    let (paper, lt) = (tmp.path().join("paper"), tmp.path().join("lt"));
    run(&[
        "compare",
        "--from",
        "0.8",
        "--plot",
        paper.to_str().expect("utf8"),
    ]);
    run(&[
        "compare",
        "--from",
        "0.8",
        "--effects",
        "load_torque",
        "--plot",
        lt.to_str().expect("utf8"),
    ]);
    let legend_of = |dir: &Path, stem: &str| {
        let svg = std::fs::read_to_string(dir.join(format!("{stem}.svg"))).expect(stem);
        chart_legend::legend(&svg).expect("a legend")
    };
    for stem in ["error_time", "error_spectrum", "overlay_iqs"] {
        let with = legend_of(&lt, stem);
        assert!(
            with.iter()
                .any(|e| e.label.contains("the paper's model + load_torque")),
            "{stem}: {with:?}"
        );
        let without = legend_of(&paper, stem);
        assert!(
            without
                .iter()
                .any(|e| e.label.contains("the paper's model"))
                && !without.iter().any(|e| e.label.contains("load_torque")),
            "{stem}: {without:?}"
        );
    }
    // The errors drawn: both models meet the load step's transient, but only the paper's
    // keeps an offset after it.
    let range = |dir: &Path| legend_of(dir, "error_time")[0].y_range.expect("drawn");
    let (lt, paper) = (range(&lt), range(&paper));
    assert!(lt.1 < paper.1 && lt.0 < 0.2 * paper.0, "{lt:?} {paper:?}");
}
