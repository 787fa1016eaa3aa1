//! What the ladder did on one log of the third-party guard (`super`): the binary run with
//! the log's parameter file, its JSON document read into an [`Outcome`].
//!
//! The ladder's JSON read here: `start` {error, ...}; `ladder`, the rungs in order, each
//! with `error` and `ratio_to_floor`; an effect rung with `effect`, `added` and perhaps
//! `dropped` (earlier effects a later one explains), a base rung with `base` (rs, rr, lls,
//! llr, lm, j, b), `change` (relative: 0.19 = +19 %) and `interval`; `final_effects`;
//! `base_changes` (a list of {base, change, interval}). A JSON without base changes counts
//! a warm stator as missed.

use super::{data, Entry};
use assert_cmd::Command;
use serde_json::Value;
use std::collections::BTreeSet;

/// A base change: the parameter, its relative change, its interval.
#[derive(Clone, Debug)]
pub(super) struct Base {
    pub(super) name: String,
    pub(super) change: f64,
    pub(super) interval: Option<(f64, f64)>,
}

/// What the ladder did on one log.
pub(super) struct Outcome {
    pub(super) entry: Entry,
    /// Effects in the model at the end (`final_effects`).
    pub(super) named: BTreeSet<String>,
    /// Every effect some rung added, and every effect some rung dropped.
    pub(super) added: BTreeSet<String>,
    pub(super) dropped: BTreeSet<String>,
    pub(super) base: Vec<Base>,
    /// Whether the JSON carries base changes at all (top-level or as rungs).
    pub(super) has_base: bool,
    /// start.error, then each rung's error.
    pub(super) errors: Vec<f64>,
    pub(super) end_ratio: f64,
    /// Each rung: what it did, its error and ratio to the floor.
    pub(super) rungs: Vec<(String, f64, f64)>,
    pub(super) stop: String,
    pub(super) stopped_because: String,
    pub(super) seconds: f64,
    /// The command failed (its stderr).
    pub(super) failed: Option<String>,
    /// The ladder's JSON document.
    pub(super) json: Value,
}

pub(super) fn strings(v: &Value) -> Vec<String> {
    v.as_array()
        .into_iter()
        .flatten()
        .filter_map(|s| s.as_str().map(str::to_string))
        .collect()
}

pub(super) fn num(v: &Value) -> f64 {
    v.as_f64().unwrap_or(f64::NAN)
}

pub(super) fn base_of(v: &Value) -> Option<Base> {
    let name = v["base"].as_str()?.to_string();
    let i = v["interval"].as_array();
    let interval = i.filter(|i| i.len() == 2).map(|i| (num(&i[0]), num(&i[1])));
    Some(Base {
        name,
        change: num(&v["change"]),
        interval,
    })
}

pub(super) fn run(e: &Entry) -> Outcome {
    let t = std::time::Instant::now();
    let out = Command::cargo_bin("sim-host")
        .expect("the sim-host binary")
        .args(["explain", "--ladder", "--json", "--params"])
        .arg(data().join(&e.params))
        .arg(data().join(&e.csv))
        .output()
        .expect("run sim-host");
    let mut o = Outcome {
        entry: e.clone(),
        named: BTreeSet::new(),
        added: BTreeSet::new(),
        dropped: BTreeSet::new(),
        base: Vec::new(),
        has_base: false,
        errors: Vec::new(),
        end_ratio: f64::NAN,
        rungs: Vec::new(),
        stop: "error".into(),
        stopped_because: String::new(),
        seconds: t.elapsed().as_secs_f64(),
        failed: None,
        json: Value::Null,
    };
    if !out.status.success() {
        o.failed = Some(String::from_utf8_lossy(&out.stderr).into_owned());
        return o;
    }
    let j: Value = serde_json::from_slice(&out.stdout).expect("one JSON document");
    o.errors.push(num(&j["start"]["error"]));
    o.end_ratio = num(&j["start"]["ratio_to_floor"]);
    for r in j["ladder"].as_array().into_iter().flatten() {
        o.errors.push(num(&r["error"]));
        o.end_ratio = num(&r["ratio_to_floor"]);
        let what = if let Some(b) = base_of(r) {
            let w = format!("base {} {:+.1} %", b.name, 100.0 * b.change);
            o.base.push(b);
            w
        } else {
            let (a, d) = (strings(&r["added"]), strings(&r["dropped"]));
            o.added.extend(a.iter().cloned());
            o.dropped.extend(d.iter().cloned());
            let mut w = format!("+{}", a.join(" +"));
            if !d.is_empty() {
                w += &format!(" -{}", d.join(" -"));
            }
            w
        };
        o.rungs
            .push((what, num(&r["error"]), num(&r["ratio_to_floor"])));
    }
    if let Some(list) = j["base_changes"].as_array() {
        o.base = list.iter().filter_map(base_of).collect();
        o.has_base = true;
    }
    o.has_base |= !o.base.is_empty();
    o.named = match j.get("final_effects") {
        Some(f) => strings(f).into_iter().collect(),
        None => o.added.difference(&o.dropped).cloned().collect(),
    };
    o.json = j.clone();
    o.stop = j["stop"].as_str().unwrap_or_default().to_string();
    o.stopped_because = j["stopped_because"]
        .as_str()
        .unwrap_or_default()
        .to_string();
    o
}
