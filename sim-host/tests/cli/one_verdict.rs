//! One verdict that never contradicts its own report (issue "One verdict from all the
//! evidence"): every log the repository ships (the example logs, the real recordings of
//! shorted turns, and the log of every example scenario, simulated here) goes through
//! `sim-host diagnose` without commissioning, with a commissioning window, and (the
//! recordings) against healthy runs; each report is checked against the rules a reader
//! applies:
//!
//! - "healthy" with a lamp lit at the end that the operating point does not explain, beside a
//!   change no single fault explains, beside a named finding, or beside an analysis the log
//!   kept from judging;
//! - "could not judge" beside a finding that names a fault at a confidence of 0.5 or more;
//! - a FAULT below 0.5, without a named fault, its size, or the phase its finding gives;
//! - a verdict line in the text that differs from the JSON's, or a fleet row whose fault,
//!   phase or confidence differ from the verdict's finding.
//!
//! About 90 runs of the binary (text and JSON) and 16 simulations: 20-40 s in the test
//! profile on 2 cores.

use assert_cmd::Command;
use monitor_testkit::text::verdict_line_of;
use rayon::prelude::*;
use serde_json::Value;
use std::path::{Path, PathBuf};

fn repo() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("..")
}

fn s(p: &Path) -> String {
    p.to_str().expect("utf8").to_string() // ok: test
}

fn run(args: &[String]) -> std::process::Output {
    Command::cargo_bin("sim-host")
        .expect("binary") // ok: test
        .current_dir(repo())
        .args(args)
        .output()
        .expect("run") // ok: test
}

/// One `diagnose` to check: the parameter file, the log and the extra options.
#[derive(Clone, Debug)]
struct Case {
    params: PathBuf,
    log: PathBuf,
    extra: Vec<String>,
}

impl Case {
    fn args(&self, json: bool) -> Vec<String> {
        let mut a = vec![
            "diagnose".to_string(),
            "--params".to_string(),
            s(&self.params),
            s(&self.log),
        ];
        a.extend(self.extra.iter().cloned());
        if json {
            a.push("--json".to_string());
        }
        a
    }

    fn name(&self) -> String {
        format!(
            "{} {}",
            self.log
                .file_name()
                .map_or(String::new(), |n| n.to_string_lossy().to_string()),
            self.extra.join(" ")
        )
    }
}

/// The parameter file a scenario names in its first comment lines (`examples/params/*.toml`),
/// or the reference machine it names (the 2.2 kW or the 3 hp).
fn params_of_scenario(text: &str) -> Option<PathBuf> {
    if let Some(k) = text.find("examples/params/") {
        let rest = &text[k..];
        let end = rest.find(".toml")? + ".toml".len();
        return Some(repo().join(&rest[..end]));
    }
    let file = if text.contains("2.2 kW") {
        "2p2kw.toml"
    } else if text.contains("3 hp") {
        "3hp.toml"
    } else {
        return None;
    };
    Some(repo().join("examples/params").join(file))
}

/// Every example scenario simulated into `dir`, with its parameter file.
fn scenario_logs(dir: &Path) -> Vec<(PathBuf, PathBuf)> {
    let mut scenarios: Vec<PathBuf> = std::fs::read_dir(repo().join("examples/scenarios"))
        .expect("scenarios") // ok: test
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| p.extension().is_some_and(|x| x == "toml"))
        .collect();
    scenarios.sort();
    scenarios
        .par_iter()
        .map(|sc| {
            let text = std::fs::read_to_string(sc).expect("scenario"); // ok: test
            let params = params_of_scenario(&text)
                .unwrap_or_else(|| panic!("{} names no parameter file", sc.display()));
            let out = dir.join(format!(
                "{}.csv",
                sc.file_stem()
                    .map_or(String::new(), |n| n.to_string_lossy().to_string())
            ));
            let o = run(&[
                "simulate".to_string(),
                "--params".to_string(),
                s(&params),
                "--scenario".to_string(),
                s(sc),
                "--out".to_string(),
                s(&out),
            ]);
            assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
            (params, out)
        })
        .collect()
}

/// The cases: each log without options and with a commissioning window; the recordings
/// also against the healthy runs (a healthy run against the other one).
fn cases(dir: &Path) -> Vec<Case> {
    let commission = |w: &str| {
        vec![
            "--commission".to_string(),
            w.to_string(),
            "--allow-incomplete".to_string(),
        ]
    };
    let mut out = Vec::new();
    let logs = repo().join("examples/logs");
    let examples = [
        (
            logs.join("motulator_2p2kw_dol.toml"),
            logs.join("motulator_2p2kw_dol.csv"),
            "1.5:2.4",
        ),
        (
            repo().join("examples/params/daq_2p2kw.toml"),
            logs.join("daq_2p2kw.csv"),
            "2:4",
        ),
    ];
    for (p, l, w) in examples {
        out.push(Case {
            params: p.clone(),
            log: l.clone(),
            extra: Vec::new(),
        });
        out.push(Case {
            params: p,
            log: l,
            extra: commission(w),
        });
    }
    for (p, l) in scenario_logs(dir) {
        out.push(Case {
            params: p.clone(),
            log: l.clone(),
            extra: Vec::new(),
        });
        out.push(Case {
            params: p,
            log: l,
            extra: commission("1.5:3"),
        });
    }
    let itsc = repo().join("examples/recordings/itsc");
    let params = itsc.join("baldor_0p75hp.toml");
    let mut recs: Vec<PathBuf> = std::fs::read_dir(&itsc)
        .expect("recordings") // ok: test
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| p.extension().is_some_and(|x| x == "csv"))
        .collect();
    recs.sort();
    let healthy: Vec<PathBuf> = recs
        .iter()
        .filter(|p| s(p).contains("SC_HLT_"))
        .cloned()
        .collect();
    for r in &recs {
        out.push(Case {
            params: params.clone(),
            log: r.clone(),
            extra: Vec::new(),
        });
        let others: Vec<String> = healthy.iter().filter(|h| *h != r).map(|h| s(h)).collect();
        let mut extra = vec!["--baseline".to_string()];
        extra.extend(others);
        out.push(Case {
            params: params.clone(),
            log: r.clone(),
            extra,
        });
    }
    out
}

/// States of a finding that say something was seen that is no verdict of healthy.
fn speaks_against_healthy(f: &Value) -> bool {
    let fault_source =
        ["residuals", "winding", "rotor"].contains(&f["source"].as_str().unwrap_or(""));
    match f["state"].as_str().unwrap_or("") {
        "named" => true,
        "unexplained" => true,
        "out_of_range" | "not_judged" => fault_source,
        _ => false,
    }
}

/// What contradicts the report in `d` (the JSON) and `text` (the text report); empty when
/// nothing does.
fn contradictions(d: &Value, text: &str) -> Vec<String> {
    let mut bad = Vec::new();
    let verdict = d["verdict"].as_str().unwrap_or("");
    let line = d["verdict_line"].as_str().unwrap_or("");
    let findings = d["findings"].as_array().cloned().unwrap_or_default();
    let last = verdict_line_of(text);
    let last = last.as_str();
    if last != format!("verdict: {line}") {
        bad.push(format!(
            "the text's last line {last:?} is not the JSON's verdict line {line:?}"
        ));
    }
    let confident =
        |f: &Value| f["state"] == "named" && f["confidence"].as_f64().is_some_and(|c| c >= 0.5);
    let residual = findings.iter().find(|f| f["source"] == "residuals");
    let lit = d["lamps"]
        .as_object()
        .is_some_and(|m| m.values().any(|v| v == true));
    match verdict {
        "healthy" => {
            if let Some(f) = findings.iter().find(|f| speaks_against_healthy(f)) {
                bad.push(format!(
                    "healthy beside the {} finding {}",
                    f["source"], f["state"]
                ));
            }
            let explained = residual.is_some_and(|f| f["state"] == "explained");
            if lit && !(explained && line.contains("lamps lit for")) {
                bad.push("healthy with a lamp lit at the end that nothing explains".to_string());
            }
            if d["isolation"]["state"] == "unknown" && !explained {
                bad.push(format!("healthy beside {}", d["isolation"]["verdict"]));
            }
        }
        "could_not_judge" => {
            if let Some(f) = findings.iter().find(|f| confident(f)) {
                bad.push(format!(
                    "could not judge beside {} at {}",
                    f["fault"], f["confidence"]
                ));
            }
        }
        "fault" => {
            let f = &d["verdict_finding"];
            let ok = confident(f) && f["size"].is_number() && f["fault"].is_string();
            if !ok {
                bad.push(format!(
                    "a FAULT without a confident named fault with its size: {f}"
                ));
            }
            let name = f["fault"].as_str().unwrap_or("?");
            let shown = match name {
                "shorted_turns" => "shorted turns",
                "broken_bars" => "broken rotor bars",
                _ => name,
            };
            if !line.contains(shown) {
                bad.push(format!("the FAULT line does not name {name}: {line}"));
            }
            if let Some(p) = f["phase"].as_str() {
                if !line.contains(&format!("phase {p}")) {
                    bad.push(format!("the FAULT line does not give phase {p}: {line}"));
                }
            }
        }
        "watching" => {
            if d["verdict_finding"].is_null() {
                bad.push("watching with no finding".to_string());
            }
        }
        other => bad.push(format!("unknown verdict {other}")),
    }
    bad
}

/// The text's lines about one analysis that tell another story than its finding (issue
/// "One story, spelled at one door"): the winding's `suspect phase` and `winding:` lines
/// against the winding finding, advice to commission residuals that never ran, and the
/// timeline's last state against the verdict.
fn other_stories(d: &Value, text: &str) -> Vec<String> {
    let mut bad = Vec::new();
    let findings = d["findings"].as_array().cloned().unwrap_or_default();
    let of = |source: &str| findings.iter().find(|f| f["source"] == source);
    // The winding: the unbalance line's suspect phase and the winding's sentence.
    if let Some(w) = of("winding") {
        let state = w["state"].as_str().unwrap_or("");
        let confidence = w["confidence"].as_f64().unwrap_or(0.0);
        let suspect = text
            .lines()
            .find_map(|l| {
                l.strip_prefix("unbalance: ")
                    .and_then(|l| l.split_once("suspect phase: "))
            })
            .map(|(_, p)| p.to_string());
        if let Some(p) = suspect {
            let phase = w["phase"].as_str().unwrap_or("?");
            let agrees = match state {
                "named" if confidence >= 0.5 => p.starts_with(phase) && !p.contains("watched"),
                "named" => p.starts_with(phase) && p.contains("watched"),
                _ => p == "none",
            };
            if !agrees {
                bad.push(format!(
                    "suspect phase: {p} beside the winding finding {state} {phase} at {confidence}"
                ));
            }
        }
        for l in text.lines().filter(|l| l.starts_with("winding: ")) {
            let judged = matches!(state, "clear" | "named");
            if judged && l.contains("cannot judge") {
                bad.push(format!("{l:?} beside the winding finding {state}"));
            }
            if state == "clear" && !l.starts_with("winding: no short") {
                bad.push(format!("{l:?} beside a clear winding"));
            }
        }
    }
    // Advice only for what was judged: no thresholds or commissioning advice where the
    // residuals never ran.
    if of("residuals").is_some_and(|f| f["state"] == "unavailable") {
        if let Some(l) = text.lines().find(|l| l.starts_with("thresholds:")) {
            bad.push(format!("{l:?} where the residuals never ran"));
        }
        if !d["commissioning"]["advice"].is_null() {
            bad.push(format!(
                "advice {} where the residuals never ran",
                d["commissioning"]["advice"]
            ));
        }
    }
    // The timeline's last state: no red FAULT at the end of a log judged healthy.
    let last_row = text
        .lines()
        .skip_while(|l| !l.trim_start().starts_with("time speed"))
        .skip(1)
        .take_while(|l| !l.trim().is_empty())
        .last();
    if let Some(row) = last_row {
        if d["verdict"] == "healthy" && row.contains(" FAULT ") {
            bad.push(format!("the timeline ends {row:?} under a healthy verdict"));
        }
    }
    bad
}

/// The fleet's row of a report agrees with its verdict (the same fault, phase and
/// confidence).
fn fleet_row_disagrees(case: &Case) -> Option<String> {
    let (params, columns) = monitor_io::log::mapping::load_params(&case.params).expect("params"); // ok: test
    let file = monitor_io::log::LogFile::open_with(
        &case.log,
        &monitor_io::log::OpenOptions {
            group: None,
            columns,
        },
    )
    .expect("log"); // ok: test
    let report = monitor_replay::diagnose_log(
        &params,
        &file,
        monitor_replay::ReplayOptions::default(),
        &mut |_| {},
    )
    .expect("diagnose") // ok: test
    .report;
    let row = monitor_api::fleet::FleetRow::of_report("m", &case.log, &report);
    let named = report.verdict_finding.as_ref().and_then(|f| f.named());
    let same = row.verdict.as_deref() == Some(report.verdict.name())
        && row.fault.as_deref() == named.map(|n| n.fault.name())
        && row.phase.as_deref() == named.and_then(|n| n.phase).map(|p| p.name())
        && row.confidence.is_some() == named.is_some();
    (!same).then(|| format!("fleet row {row:?} against {:?}", report.verdict))
}

#[test]
fn no_shipped_log_gets_a_verdict_that_contradicts_its_report() {
    let dir = tempfile::tempdir().expect("tmp"); // ok: test
    let cases = cases(dir.path());
    assert!(cases.len() >= 80, "{} cases", cases.len());
    let results: Vec<(String, String, Vec<String>)> = cases
        .par_iter()
        .map(|c| {
            let o = run(&c.args(true));
            assert!(
                o.status.success(),
                "{}: {}",
                c.name(),
                String::from_utf8_lossy(&o.stderr)
            );
            let d: Value = serde_json::from_slice(&o.stdout).expect("json"); // ok: test
            let t = run(&c.args(false));
            let text = String::from_utf8_lossy(&t.stdout).to_string();
            let mut bad = contradictions(&d, &text);
            bad.extend(other_stories(&d, &text));
            if c.extra.is_empty() {
                bad.extend(fleet_row_disagrees(c));
            }
            let v = d["verdict"].as_str().unwrap_or("").to_string();
            (c.name(), v, bad)
        })
        .collect();
    let mut counts = std::collections::BTreeMap::new();
    for (_, v, _) in &results {
        *counts.entry(v.clone()).or_insert(0) += 1;
    }
    eprintln!("{} reports: {counts:?}", results.len());
    let bad: Vec<String> = results
        .into_iter()
        .filter(|(_, _, b)| !b.is_empty())
        .map(|(n, v, b)| format!("{n} ({v}): {}", b.join("; ")))
        .collect();
    assert!(
        bad.is_empty(),
        "{} contradictions:\n{}",
        bad.len(),
        bad.join("\n")
    );
}

/// The checks themselves fail on the contradictions the issue measured.
#[test]
fn the_checks_catch_the_contradictions_the_issue_measured() {
    let healthy_under_lamps = serde_json::json!({
        "verdict": "healthy", "verdict_line": "healthy",
        "lamps": {"r1": false, "r2": true},
        "isolation": {"state": "unknown", "verdict": "A change of 261 standard deviations that no single fault explains"},
        "findings": [{"source": "residuals", "state": "clear"}],
    });
    assert!(!contradictions(&healthy_under_lamps, "verdict: healthy").is_empty());
    let short_left_out = serde_json::json!({
        "verdict": "could_not_judge", "verdict_line": "could not judge: residuals need voltages",
        "lamps": {}, "isolation": {"state": "not_judged"},
        "findings": [{"source": "winding", "state": "named", "fault": "shorted_turns", "confidence": 0.54, "phase": "c"}],
    });
    assert!(!contradictions(
        &short_left_out,
        "verdict: could not judge: residuals need voltages"
    )
    .is_empty());
    let weak_fault = serde_json::json!({
        "verdict": "fault", "verdict_line": "FAULT shorted turns in phase c",
        "lamps": {}, "isolation": {"state": "not_judged"},
        "verdict_finding": {"source": "winding", "state": "named", "fault": "shorted_turns", "confidence": 0.34, "phase": "c", "size": 0.013},
        "findings": [],
    });
    assert!(!contradictions(&weak_fault, "verdict: FAULT shorted turns in phase c").is_empty());
    let other_line = serde_json::json!({
        "verdict": "healthy", "verdict_line": "healthy: residuals",
        "lamps": {}, "isolation": {"state": "no_deviation"}, "findings": [],
    });
    assert!(!contradictions(&other_line, "verdict: healthy").is_empty());
    assert!(contradictions(&other_line, "verdict: healthy: residuals").is_empty());
    // The three stories of the issue: a clear winding that "cannot judge", a watched
    // phase with "suspect phase: none", thresholds advised on a current-only log.
    let clear = serde_json::json!({
        "verdict": "healthy", "commissioning": {"advice": null},
        "findings": [{"source": "winding", "state": "clear"}],
    });
    let said = "unbalance: |I2|/|I1| = 3.10 %, suspect phase: none\nwinding: cannot judge the phase: the negative sequence (3.1 % of I1) is within (least change 12.7 %)\n";
    assert_eq!(other_stories(&clear, said).len(), 2, "{said}");
    let one = "unbalance: |I2|/|I1| = 3.10 %, suspect phase: none\nwinding: no short of more than 35 % of the turns: ...\n";
    assert!(other_stories(&clear, one).is_empty());
    let watched = serde_json::json!({
        "verdict": "watching", "commissioning": {"advice": null},
        "findings": [{"source": "winding", "state": "named", "phase": "c", "confidence": 0.39}],
    });
    assert_eq!(
        other_stories(
            &watched,
            "unbalance: |I2|/|I1| = 9 %, suspect phase: none\n"
        )
        .len(),
        1
    );
    assert!(other_stories(
        &watched,
        "unbalance: |I2|/|I1| = 9 %, suspect phase: c, watched (probability 0.39)\n"
    )
    .is_empty());
    let current_only = serde_json::json!({
        "verdict": "healthy", "commissioning": {"advice": "commission (--commission START:END)"},
        "findings": [{"source": "residuals", "state": "unavailable"}],
    });
    assert_eq!(
        other_stories(&current_only, "thresholds: fixed: |r| > 3.0 %\n").len(),
        2
    );
}
