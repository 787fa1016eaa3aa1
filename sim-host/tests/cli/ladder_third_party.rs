//! `explain --ladder` on logs of a third-party simulator with the parameter file a user has
//! (issue 73's guard). The logs are motulator's induction machine (the version in
//! `tools/motulator-logs/requirements.txt`), made by `tools/motulator-logs/generate.py` into
//! `tests/data/motulator/`: three machines (motulator's 2.2 kW, a 7.5 kW Simscape preset,
//! Krause's 50 hp), direct-on-line starts with variac steps and a long V/f log, 12-bit
//! sensors with noise of about one LSB. Each log's parameter file is what a user derives
//! from the nameplate, a DC resistance, a no-load and a locked-rotor test (IEEE 112): never
//! the simulator's values. `manifest.toml` there says, per log, the hidden effects and their
//! true sizes, the effects the log's physics allows besides them (the dynamics effects on a
//! start; `load_torque` where the load is a torque) and the effects that are the same term
//! on that log.
//!
//! Bars (issue 73, "Done when"), over the manifest's logs:
//! * (a) at least 90 % of the hidden effects named: in the ladder's `final_effects` (or a
//!   same-term equivalent the manifest lists); a warm stator (`warm_stator`, size s) counts
//!   as named when the ladder reports a base change of `rs` within 5 % of s (+20 %:
//!   0.19..0.21);
//! * (b) no effect named that is neither hidden nor allowed on its log;
//! * (c) the whole-log error never rises along the ladder (base and effect rungs), every log;
//! * (d) the end within 2x the noise floor or 5x below the start on at least 90 % of the logs;
//! * (e) no change of `rs` beyond 3 % on the logs whose stator is at the file's temperature;
//! * (f) a fan the ladder does not name is not reported as a change of `B + Bl` that carries
//!   it: the end names windage in that change's place (`final_fit.base[].in_place`) with
//!   the log's `k` within 10 % (issue 87: `kw2p2_fan_saturation` read B + Bl 20 times the
//!   file's as a finding);
//! * (g) no change of `j` beyond 3 % on the logs whose file holds the machine's inertia
//!   exactly (the 2.2 kW files: `tools/motulator-logs/README.md`, "The parameter file a user
//!   has"); the fan's log read J -9 % beside the viscous friction that stood in for its fan.
//! * (h) no change of `rr` reported farther than 3 points from the machine's true change
//!   against the log's file (the manifest's `file_inverse_gamma_off_pct.R_R`: the 2.2 kW
//!   file's R_R is 10.1 % low, so a true +11.2 %); issue 87: beside motulator's saturation
//!   law the ladder reported rr -23 % and -25 % where the machine's is +6 %.
//!
//! The ladder's JSON is read in `outcome` (its module doc says which fields).
//!
//! Part of the full sweeps only: `cargo test` skips it with a note, and
//! ```text
//! MONITOR_FULL_SWEEPS=1 cargo test --release -p sim-host --test cli ladder_third_party:: -- --nocapture
//! ```
//! runs it (14 logs, two of them 40 s long, one at a time; the table goes to stderr).
#![allow(missing_docs)]

use monitor_testkit::analysis_common::in_this_run;
use serde::Deserialize;
use std::collections::BTreeSet;
use std::path::{Path, PathBuf};

mod outcome;
use outcome::{run, Outcome};

/// The folder of the logs, their parameter files and the manifest.
fn data() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/motulator")
}

#[derive(Deserialize)]
struct Manifest {
    log: Vec<Entry>,
    machine: Vec<Machine>,
}

/// One machine's parameter file and its distance from the simulator's machine (the bars
/// read the rotor resistance's).
#[derive(Deserialize)]
struct Machine {
    /// The parameter file.
    params: String,
    /// The file's values in the inverse-Gamma form against the truth (per cent).
    file_inverse_gamma_off_pct: InverseGammaOff,
}

/// The inverse-Gamma form's distance from the truth (the form unique for a machine's
/// terminal behaviour; `tools/motulator-logs/README.md`, "How far each file is").
#[derive(Deserialize)]
struct InverseGammaOff {
    /// The rotor resistance R_R's, per cent (-5.7: the file's is 5.7 % below the machine's).
    #[serde(rename = "R_R")]
    r_r: f64,
}

/// One log as the manifest describes it (the fields the bars need).
#[derive(Deserialize, Clone)]
struct Entry {
    name: String,
    csv: String,
    /// The CSV's size as the generator wrote it (a hand-edited log is refused).
    bytes: u64,
    params: String,
    hidden: Vec<String>,
    allowed: Vec<String>,
    /// (hidden, named, why): on this log `named` is the same term as `hidden`.
    equivalent: Vec<Vec<String>>,
    stator_at_file_temperature: bool,
    /// The stator's resistance over the file's, less one, where it is warm.
    warm_stator: Option<f64>,
    /// The hidden effects' true sizes (the fan's `windage_k_nms2`).
    #[serde(default)]
    sizes: Sizes,
}

/// The manifest's sizes of a log the bars read.
#[derive(Deserialize, Clone, Default)]
struct Sizes {
    /// The fan's `k` of `k w |w|` [N m s^2/rad^2], where the log has one.
    windage_k_nms2: Option<f64>,
}

/// Largest |j change| on the logs of the 2.2 kW files (`kw2p2*.toml`), whose inertia is
/// exact (bar (g)).
const J_STILL: f64 = 0.03;
/// Relative tolerance on the fan's `k` named in the place of a change of B + Bl.
const FAN_TOL: f64 = 0.10;

/// Largest distance of a reported change of `rr` from the machine's true change against its
/// file (bar (h), absolute: 0.03 = 3 points).
const RR_TOL: f64 = 0.03;

/// The pseudo-effect of a warm stator: a base change of rs, not a library effect.
const WARM: &str = "warm_stator";
/// Relative tolerance on a warm stator's base change of rs (its size's 5 %).
const WARM_TOL: f64 = 0.05;
/// Largest |rs change| on a log whose stator is at the file's temperature.
const RS_STILL: f64 = 0.03;

impl Outcome {
    /// The change of `rs` the ladder reports (0 when it reports none).
    fn rs_change(&self) -> f64 {
        self.base
            .iter()
            .find(|b| b.name == "rs")
            .map_or(0.0, |b| b.change)
    }

    /// (a) for one hidden item of this log.
    fn names(&self, hidden: &str) -> bool {
        if hidden == WARM {
            let size = self.entry.warm_stator.unwrap_or(f64::NAN);
            return self
                .base
                .iter()
                .any(|b| b.name == "rs" && (b.change - size).abs() <= WARM_TOL * size.abs());
        }
        self.named.contains(hidden)
            || self
                .entry
                .equivalent
                .iter()
                .any(|e| e.len() >= 2 && e[0] == hidden && self.named.contains(&e[1]))
    }

    /// (b): the effects named that are neither hidden, allowed nor a hidden one's equivalent.
    fn wrong(&self) -> Vec<String> {
        let e = &self.entry;
        self.named
            .iter()
            .filter(|n| {
                !e.hidden.contains(n)
                    && !e.allowed.contains(n)
                    && !e
                        .equivalent
                        .iter()
                        .any(|q| q.len() >= 2 && &q[1] == *n && e.hidden.contains(&q[0]))
            })
            .cloned()
            .collect()
    }

    /// (f): where the log's fan is not named, what is wrong with B + Bl's place (`None`: the
    /// change is no finding and windage is named in its place with the log's `k`).
    fn fan_as_viscous(&self) -> Option<String> {
        let e = &self.entry;
        if !e.hidden.iter().any(|h| h == "windage") || self.named.contains("windage") {
            return None;
        }
        let name = &e.name;
        if self.base.iter().any(|b| b.name == "b") {
            return Some(format!(
                "{name}: B + Bl reported as a change of the machine"
            ));
        }
        let base = self.json["final_fit"]["base"].as_array();
        let b = base.and_then(|l| l.iter().find(|b| b["base"] == "b"));
        let k = b.and_then(|b| b["in_place"]["fitted"]["parameters"]["k_nms2"]["value"].as_f64());
        let truth = e.sizes.windage_k_nms2;
        match (k, truth) {
            (Some(k), Some(t)) if (k / t - 1.0).abs() <= FAN_TOL => None,
            _ => Some(format!(
                "{name}: windage not named in B + Bl's place (k {k:?}, the log's {truth:?})"
            )),
        }
    }

    /// (g): the change of `j` the ladder reports (0 when it reports none).
    fn j_change(&self) -> f64 {
        self.base
            .iter()
            .find(|b| b.name == "j")
            .map_or(0.0, |b| b.change)
    }

    /// (h): the change of `rr` the ladder reports where it is not the machine's: farther
    /// than [`RR_TOL`] from `truth`, the true change of the rotor resistance against the
    /// log's file (`None`: none reported, or the true one).
    fn rr_not_the_machines(&self, truth: f64) -> Option<f64> {
        let b = self.base.iter().find(|b| b.name == "rr")?;
        ((b.change - truth).abs() > RR_TOL).then_some(b.change)
    }

    /// (c): the whole-log error never rises (a relative 1e-9 for rounding).
    fn error_never_rises(&self) -> bool {
        self.errors.windows(2).all(|w| w[1] <= w[0] * (1.0 + 1e-9))
    }

    /// (d): ends within 2x the floor or 5x below the start's error.
    fn ends_low(&self) -> bool {
        match (self.errors.first(), self.errors.last()) {
            (Some(f), Some(l)) => self.end_ratio <= 2.0 || l * 5.0 <= *f,
            _ => false,
        }
    }

    fn base_text(&self) -> String {
        if !self.has_base {
            return "(none in the JSON)".into();
        }
        let b: Vec<String> = self
            .base
            .iter()
            .map(|b| match b.interval {
                Some((lo, hi)) => format!(
                    "{} {:+.0}% [{:+.0},{:+.0}]",
                    b.name,
                    100.0 * b.change,
                    100.0 * lo,
                    100.0 * hi
                ),
                None => format!("{} {:+.0}%", b.name, 100.0 * b.change),
            })
            .collect();
        if b.is_empty() {
            "none".into()
        } else {
            b.join(", ")
        }
    }

    fn non_dynamics(&self, set: &BTreeSet<String>) -> String {
        let v: Vec<&str> = set
            .iter()
            .map(String::as_str)
            .filter(|n| !n.ends_with("_dynamics"))
            .collect();
        if v.is_empty() {
            "-".into()
        } else {
            v.join(",")
        }
    }

    fn details(&self) -> String {
        match &self.failed {
            Some(err) => format!("{}: sim-host failed: {err}", self.entry.name),
            None => {
                let rungs: Vec<String> = self
                    .rungs
                    .iter()
                    .map(|(w, e, r)| format!("{w} (error {e:.3e}, {r:.2}x floor)"))
                    .collect();
                format!(
                    "{}: start error {:.3e}; rungs: [{}]; base changes: {}; stop {}: {}",
                    self.entry.name,
                    self.errors[0],
                    rungs.join(", "),
                    self.base_text(),
                    self.stop,
                    self.stopped_because
                )
            }
        }
    }
}

fn table(outcomes: &[Outcome]) {
    eprintln!(
        "{:<22} {:<30} {:<34} {:<28} {:>7} {:>9} {:>9} {:>6}",
        "log",
        "hidden",
        "named (non-dynamics)",
        "base changes",
        "end/flr",
        "start err",
        "end err",
        "secs"
    );
    for o in outcomes {
        let e = &o.entry;
        let mut named = o.non_dynamics(&o.named);
        let gone = o.non_dynamics(&o.dropped);
        if gone != "-" {
            named += &format!(" (dropped {gone})");
        }
        eprintln!(
            "{:<22} {:<30} {:<34} {:<28} {:>7.2} {:>9.3e} {:>9.3e} {:>6.1}",
            e.name,
            if e.hidden.is_empty() {
                "none (control)".to_string()
            } else {
                e.hidden.join("+")
            },
            named,
            o.base_text(),
            o.end_ratio,
            o.errors.first().copied().unwrap_or(f64::NAN),
            o.errors.last().copied().unwrap_or(f64::NAN),
            o.seconds
        );
    }
}

/// Prints a bar's findings; returns the failure, if any.
fn bar(what: &str, bad: &[String], ok: bool, failure: String) -> Option<String> {
    eprintln!("{what}");
    for b in bad {
        eprintln!("    {b}");
    }
    (!ok).then_some(failure)
}

#[test]
fn the_ladder_names_the_hidden_effects_of_motulators_logs() {
    if !in_this_run("ladder_third_party") {
        return;
    }
    let text = std::fs::read_to_string(data().join("manifest.toml")).expect("the manifest");
    let manifest: Manifest = toml::from_str(&text).expect("a manifest as the generator writes");
    assert!(manifest.log.len() >= 11, "the manifest lists every log");
    for e in &manifest.log {
        let len = std::fs::metadata(data().join(&e.csv)).map_or(0, |m| m.len());
        assert_eq!(
            len, e.bytes,
            "{}: not the generator's file (tools/motulator-logs/generate.py)",
            e.csv
        );
    }
    let t = std::time::Instant::now();
    let mut outcomes = Vec::new();
    for e in &manifest.log {
        let o = run(e);
        eprintln!("  done {} ({:.1} s)", e.name, o.seconds);
        outcomes.push(o);
    }
    eprintln!(
        "{} logs in {:.1} s",
        outcomes.len(),
        t.elapsed().as_secs_f64()
    );
    table(&outcomes);
    for o in &outcomes {
        eprintln!("  {}", o.details());
    }
    let mut failures = Vec::new();
    let crashed: Vec<String> = outcomes
        .iter()
        .filter(|o| o.failed.is_some())
        .map(Outcome::details)
        .collect();
    failures.extend(bar(
        &format!("runs that failed: {}", crashed.len()),
        &crashed,
        crashed.is_empty(),
        format!("sim-host failed on {} logs", crashed.len()),
    ));
    // (a)
    let pairs: Vec<(&Outcome, &str)> = outcomes
        .iter()
        .flat_map(|o| o.entry.hidden.iter().map(move |h| (o, h.as_str())))
        .collect();
    let missed: Vec<String> = pairs
        .iter()
        .filter(|(o, h)| !o.names(h))
        .map(|(o, h)| match *h {
            WARM => format!(
                "{}: warm stator (rs {:+.0} %) missed: base changes {}",
                o.entry.name,
                100.0 * o.entry.warm_stator.unwrap_or(f64::NAN),
                o.base_text()
            ),
            _ => format!(
                "{}: {h} missed; named {}",
                o.entry.name,
                o.non_dynamics(&o.named)
            ),
        })
        .collect();
    let share = 1.0 - missed.len() as f64 / pairs.len().max(1) as f64;
    failures.extend(bar(
        &format!(
            "(a) hidden effects named: {} of {} ({:.0} %; bar 90 %)",
            pairs.len() - missed.len(),
            pairs.len(),
            100.0 * share
        ),
        &missed,
        share >= 0.9,
        format!("(a) {:.0} % of the hidden effects named", 100.0 * share),
    ));
    // (b)
    let wrong: Vec<String> = outcomes
        .iter()
        .filter(|o| !o.wrong().is_empty())
        .map(|o| format!("{}: {} named", o.entry.name, o.wrong().join(", ")))
        .collect();
    failures.extend(bar(
        &format!(
            "(b) logs with an effect named that is neither hidden nor allowed: {}",
            wrong.len()
        ),
        &wrong,
        wrong.is_empty(),
        format!("(b) a wrong effect named on {} logs", wrong.len()),
    ));
    // (c)
    let rising: Vec<String> = outcomes
        .iter()
        .filter(|o| o.failed.is_none() && !o.error_never_rises())
        .map(|o| format!("errors {:?}: {}", o.errors, o.entry.name))
        .collect();
    failures.extend(bar(
        &format!("(c) logs whose whole-log error rises: {}", rising.len()),
        &rising,
        rising.is_empty(),
        format!("(c) the error rose on {} logs", rising.len()),
    ));
    // (d)
    let high: Vec<String> = outcomes
        .iter()
        .filter(|o| !o.ends_low())
        .map(|o| {
            format!(
                "{}: ends at {:.2}x the floor, {:.1}x below the start",
                o.entry.name,
                o.end_ratio,
                o.errors.first().unwrap_or(&f64::NAN) / o.errors.last().unwrap_or(&f64::NAN)
            )
        })
        .collect();
    let low = 1.0 - high.len() as f64 / outcomes.len().max(1) as f64;
    failures.extend(bar(
        &format!(
            "(d) logs ending within 2x the floor or 5x below the start: {:.0} % (bar 90 %)",
            100.0 * low
        ),
        &high,
        low >= 0.9,
        format!("(d) {:.0} % of the logs ended low", 100.0 * low),
    ));
    // (e)
    let moved: Vec<String> = outcomes
        .iter()
        .filter(|o| o.entry.stator_at_file_temperature && o.rs_change().abs() > RS_STILL)
        .map(|o| format!("{}: rs {:+.1} %", o.entry.name, 100.0 * o.rs_change()))
        .collect();
    failures.extend(bar(
        &format!(
            "(e) logs at the file's stator temperature with rs moved beyond 3 %: {}",
            moved.len()
        ),
        &moved,
        moved.is_empty(),
        format!("(e) rs moved beyond 3 % on {} logs", moved.len()),
    ));
    // (f)
    let fans: Vec<String> = outcomes
        .iter()
        .filter_map(Outcome::fan_as_viscous)
        .collect();
    let head = format!(
        "(f) logs with a fan carried as a change of B + Bl: {}",
        fans.len()
    );
    failures.extend(bar(
        &head,
        &fans,
        fans.is_empty(),
        format!("(f) a fan carried as B + Bl on {} logs", fans.len()),
    ));
    // (g)
    let inertia: Vec<String> = outcomes
        .iter()
        .filter(|o| o.entry.params.starts_with("kw2p2"))
        .filter(|o| o.j_change().abs() > J_STILL)
        .map(|o| format!("{}: j {:+.1} %", o.entry.name, 100.0 * o.j_change()))
        .collect();
    failures.extend(bar(
        &format!(
            "(g) logs whose file's inertia is exact with j moved beyond 3 %: {}",
            inertia.len()
        ),
        &inertia,
        inertia.is_empty(),
        format!("(g) j moved beyond 3 % on {} logs", inertia.len()),
    ));
    // (h)
    let rotor: Vec<String> = outcomes
        .iter()
        .filter_map(|o| {
            let m = manifest
                .machine
                .iter()
                .find(|m| m.params == o.entry.params)?;
            // The file's R_R is off by r_r %: the machine's is 1 / (1 + r_r/100) of it.
            let truth = 1.0 / (1.0 + m.file_inverse_gamma_off_pct.r_r / 100.0) - 1.0;
            let rr = o.rr_not_the_machines(truth)?;
            Some(format!(
                "{}: rr {:+.1} % reported, the machine's {:+.1} %",
                o.entry.name,
                100.0 * rr,
                100.0 * truth
            ))
        })
        .collect();
    failures.extend(bar(
        &format!(
            "(h) logs reporting a change of rr more than 3 points from the machine's: {}",
            rotor.len()
        ),
        &rotor,
        rotor.is_empty(),
        format!("(h) rr reported off the machine's on {} logs", rotor.len()),
    ));
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}
