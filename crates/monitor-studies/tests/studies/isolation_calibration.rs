//! The isolation's probability is a calibrated probability (issue 48): of the faults it
//! names, at least 95 % are right, on simulated logs the isolation was not tuned on, and
//! the reliability table (bins of probability, count, fraction right) shows it.
//!
//! Each case is drawn from its seed (`calibration_cases::draw`): one of three motors (the 3
//! hp and 2.2 kW reference machines and Krause's 50 hp one), a Table 1 fault at 5-50 %
//! (sensors 5-35 %) or none, the load steady or moving every 3 s (0.7-1.3 of its Bl, the
//! commissioning seeing four levels), the windings cold or warming (10-60 K, time
//! constants 20-300 s, from the log's start or after commissioning), the parameter file
//! true or off the machine as a nameplate's is (Rs, Rr 8-20 %, leakages 10-20 %, Lm 3-8 %,
//! each up or down), the simulator's 12-bit sensors with their default noise or four times
//! it, the rotor-flux angle or the voltage PLL, commissioned (nine cases in ten) or not; 30
//! s at 4 kHz, the fault at 16 s (after a commissioning over 2-14 s with the load moving,
//! 2.5-5.5 s without). The load is an unknown input (`diagnose`'s default), so a change of B
//! or Bl is a load move: for those and for the healthy logs every name is wrong.
//!
//! What is scored: the name the isolation gives at the log's end (`isolation.named`, with
//! its probability `isolation.named_probability`), and every name it gave on the way
//! (`isolation.events`); right when it is the injected fault's. The reliability table
//! bins them by probability.
//!
//! Seeds: the tuning was done on 4_870_000.. (`tuning`, by hand, 400 cases). Measured on
//! 4_890_000.., 4_900_000.. and 4_910_000.. (1200 cases each), each passing; after each, a
//! rule was changed (a size at the end of the range searched is no name; the direction
//! uncertainty against an uncommissioned file; the temperature judged where the load's move
//! explains the deviation, the anchor without a drift allowance), so the measured sweep is
//! on fresh seeds 4_920_000.. (1200 cases, `MONITOR_FULL_SWEEPS=1`, about 2 min in the test
//! profile on 2 cores); `cargo test` runs a small sweep (seeds
//! 4_880_000.., 48 cases, about 6 s). Print the tables with `-- --nocapture`.

use crate::calibration_cases;

use calibration_cases::{draw, motors, right_name, run, CaseOutcome, Scored};
use rayon::prelude::*;

/// The probability bins of the table: [lower, upper).
const BINS: [(f32, f32); 6] = [
    (0.5, 0.6),
    (0.6, 0.7),
    (0.7, 0.8),
    (0.8, 0.9),
    (0.9, 0.95),
    (0.95, 1.01),
];

/// The reliability table of `scored`: per bin, the count and how many were right.
fn table(scored: &[Scored]) -> Vec<(f32, f32, usize, usize)> {
    BINS.iter()
        .map(|&(lo, hi)| {
            let in_bin: Vec<&Scored> = scored.iter().filter(|s| s.p >= lo && s.p < hi).collect();
            let right = in_bin.iter().filter(|s| s.right).count();
            (lo, hi.min(1.0), in_bin.len(), right)
        })
        .collect()
}

/// Prints the table of `scored` under `title`; returns (names at >= 0.5, right).
fn print_table(title: &str, scored: &[Scored]) -> (usize, usize) {
    eprintln!("{title}");
    eprintln!("| probability | names | right | fraction right |");
    eprintln!("|---|---|---|---|");
    let (mut n, mut ok) = (0, 0);
    for (lo, hi, count, right) in table(scored) {
        let frac = if count > 0 {
            format!("{:.2}", right as f64 / count as f64)
        } else {
            "-".into()
        };
        eprintln!("| {lo:.2}-{hi:.2} | {count} | {right} | {frac} |");
        n += count;
        ok += right;
    }
    eprintln!(
        "| all >= 0.5 | {n} | {ok} | {:.3} |",
        ok as f64 / n.max(1) as f64
    );
    (n, ok)
}

/// Runs the cases of seeds `from..from + n`; prints every wrong name and both tables;
/// returns the wrong names at the end and on the way in words, and the two (names, right)
/// counts.
fn sweep(from: u64, n: u64) -> (Vec<String>, (usize, usize), (usize, usize)) {
    let outcomes: Vec<CaseOutcome> = (from..from + n)
        .map(draw)
        .collect::<Vec<_>>()
        .into_par_iter()
        .map(run)
        .collect();
    let mut wrong = Vec::new();
    for o in &outcomes {
        let bad_last = o.last.filter(|(_, s, _)| !s.right);
        let bad_given: Vec<_> = o.given.iter().filter(|(_, s, _)| !s.right).collect();
        if bad_last.is_some() || !bad_given.is_empty() {
            let line = format!(
                "{:?} {}: last {:?}, given {:?}, verdict {}",
                o.case,
                motors()[o.case.motor].0,
                o.last,
                o.given,
                o.verdict
            );
            eprintln!("wrong: {line}");
            wrong.push(line);
        }
    }
    let last: Vec<Scored> = outcomes
        .iter()
        .filter_map(|o| o.last.map(|l| l.1))
        .collect();
    let given: Vec<Scored> = outcomes
        .iter()
        .flat_map(|o| o.given.iter().map(|g| g.1))
        .collect();
    let named_right = outcomes
        .iter()
        .filter(|o| o.last.is_some_and(|l| l.1.right))
        .count();
    let faults = outcomes
        .iter()
        .filter(|o| right_name(o.case.fault).is_some())
        .count();
    eprintln!(
        "{n} cases (seeds {from}..{}): {faults} with a nameable fault, {named_right} named right at the end",
        from + n
    );
    for commissioned in [true, false] {
        let of = |o: &&CaseOutcome| o.case.commissioned == commissioned;
        let last_n = outcomes.iter().filter(of).filter_map(|o| o.last).count();
        let last_ok = outcomes
            .iter()
            .filter(of)
            .filter(|o| o.last.is_some_and(|l| l.1.right))
            .count();
        let given: Vec<Scored> = outcomes
            .iter()
            .filter(of)
            .flat_map(|o| o.given.iter().map(|g| g.1))
            .collect();
        eprintln!(
            "{}: {} cases; names at the end {last_ok} right of {last_n}, on the way {} of {}",
            if commissioned {
                "commissioned"
            } else {
                "not commissioned"
            },
            outcomes.iter().filter(of).count(),
            given.iter().filter(|s| s.right).count(),
            given.len()
        );
    }
    let a = print_table("names at the log's end:", &last);
    let b = print_table("every name given (events):", &given);
    (wrong, a, b)
}

/// At least `bar` of the names at >= 0.5 right (`(names, right)`), and some names.
fn reliable((n, ok): (usize, usize), bar: f64) -> bool {
    n > 0 && ok as f64 >= bar * n as f64
}

/// The measured sweep holds the bar of 95 %; the small one (some 15 names: one wrong name
/// is 6 %) 90 %.
#[test]
fn the_isolations_names_are_right_as_often_as_their_probability_says() {
    let full = std::env::var("MONITOR_FULL_SWEEPS").is_ok_and(|v| v == "1");
    let (from, n, bar) = if full {
        (4_920_000, 1200, 0.95)
    } else {
        (4_880_000, 48, 0.9)
    };
    if !full {
        eprintln!("the small sweep; MONITOR_FULL_SWEEPS=1 runs the measured one");
    }
    let (wrong, last, given) = sweep(from, n);
    assert!(
        reliable(last, bar) && reliable(given, bar),
        "fewer than {bar} of the names right: at the end {last:?}, on the way {given:?}: {wrong:#?}"
    );
}

/// The tuning sweep (seeds 4_870_000..): only by hand, `cargo test -p sim-host --test
/// isolation_calibration tuning -- --ignored --nocapture` (`CALIBRATION_CASES` cases,
/// default 400).
#[test]
#[ignore]
fn tuning() {
    let n = std::env::var("CALIBRATION_CASES")
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(400);
    let _ = sweep(4_870_000, n);
}
