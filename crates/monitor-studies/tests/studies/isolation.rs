//! Fault isolation beyond Table 1 (`monitor_core::isolation`, the replay's isolation and
//! the candidates' `change`), end to end: the simulator with its default 12-bit, noisy
//! sensors at 5 kHz -> the core -> the replay's isolation, on both reference motors and on
//! a third machine the code was not developed on (`examples/params/11kw_2pole.toml`).
//!
//! Protocol (`monitor_studies::fault_signatures`): direct-on-line start, the paper's viscous load,
//! commissioning 2..4 s (the isolation's baseline is learned there), the fault at 4.5 s
//! (the 11 kW machine: 3..5 s and 5.5 s, its start settles later).
//!
//! Asserted, as the issue states the bar:
//! - every Table 1 fault except B/Bl at +/-50 %, and Rs, Rr and the three sensors at
//!   +/-10 %, is named alone (probability >= 0.5) with its size within 20 % of the truth,
//!   except the cases listed in [`not_separable`] with the physical reason (those at
//!   +/-50 % must still be the top candidate with their size);
//! - B and Bl are named as the friction class `b/bl`;
//! - no wrong fault is ever named at probability >= 0.5, and nothing is named before the
//!   fault.
//!
//! (The command line's `diagnose` on a load step then a fault, with a parameter file that is
//! off: `sim-host/tests/cli/isolation.rs`.)

use monitor_core::Fault;
use monitor_io::params::ParamFile;
use monitor_replay::{state_name, FaultCandidate, IsolationName};
use monitor_studies::fault_signatures::{run_case, Protocol, Table1Row};
use rayon::prelude::*;
use std::path::Path;

fn machines() -> Vec<(&'static str, ParamFile)> {
    let third = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples/params/11kw_2pole.toml");
    vec![
        ("2.2 kW", ParamFile::reference_2p2kw()),
        ("3 hp", ParamFile::reference_3hp()),
        (
            "11 kW",
            ParamFile::load(&third).expect("the 11 kW parameter file"),
        ), // ok: test
    ]
}

/// The cases that cannot be named alone with these sensors, and why (the core's unit
/// tests show the same on exact steady states). They must not be named wrongly either.
fn not_separable(machine: &str, f: Fault, change: f64) -> Option<&'static str> {
    let small = change.abs() < 0.2;
    match (machine, f) {
        ("3 hp", Fault::Ls) => Some(
            "at this rated load (ws Lr/Rr = 1, where the torque's slope in ws/Rr is zero) a stator-leakage change moves the residuals where a 3 % Rr change and a 0.1 % speed-sensor error do",
        ),
        ("3 hp", Fault::Rr) if small => Some(
            "the same point: Rr +10 % is fitted as well by a stator leakage change (+158 %)",
        ),
        (_, Fault::VoltageSensor) if change > 0.4 => Some(
            "+50 % drives the 12-bit ADC (range 1.2 x peak) into its end stop: the clipped reading's fundamental is about +36 %",
        ),
        _ => None,
    }
}

fn cases() -> Vec<(usize, Fault, f64)> {
    let mut v = Vec::new();
    for m in 0..3 {
        for f in Fault::ALL {
            v.push((m, f, 0.5));
            v.push((m, f, -0.5));
            if matches!(
                f,
                Fault::Rs
                    | Fault::Rr
                    | Fault::CurrentSensor
                    | Fault::VoltageSensor
                    | Fault::SpeedSensor
            ) {
                v.push((m, f, 0.1));
                v.push((m, f, -0.1));
            }
        }
    }
    v
}

fn run(m: usize, f: Fault, change: f64) -> Table1Row {
    let (name, p) = &machines()[m];
    // The 2-pole 11 kW machine's direct-on-line start settles later: commission 3..5 s.
    let late = *name == "11 kW";
    let proto = Protocol {
        sample_rate_hz: 5000.0,
        commission: monitor_replay::CommissionWindow::of(
            if late { 3.0 } else { 2.0 },
            if late { 5.0 } else { 4.0 },
        ),
        fault_at_s: if late { 5.5 } else { 4.5 },
        duration_s: if late { 10.5 } else { 9.5 },
        ..Protocol::default()
    };
    run_case(p, f, change, &proto).unwrap_or_else(|e| panic!("{name} {f} {change}: {e}"))
}

#[test]
fn every_fault_is_named_with_its_size_or_honestly_not_named() {
    let machines = machines();
    let rows: Vec<_> = cases()
        .par_iter()
        .map(|&(m, f, c)| (m, f, c, run(m, f, c)))
        .collect();
    let mut failures = Vec::new();
    let mut named_right = 0;
    for (m, f, change, row) in &rows {
        let name = machines[*m].0;
        let tag = format!("{name} {f} {change:+}");
        // Never a wrong fault at >= 0.5.
        for cand in &row.isolation_candidates {
            let (c, p) = (cand.fault.name(), &cand.probability);
            let friction = matches!(f, Fault::B | Fault::Bl) && (c == "b" || c == "bl");
            if *p >= 0.5 && c != f.name() && !friction {
                failures.push(format!("{tag}: wrong fault {c} at {p:.2}"));
            }
        }
        if let Some(d) = row.name_delay_s {
            if d < 0.0 {
                failures.push(format!(
                    "{tag}: named {:?} {d:.2} s before the fault",
                    row.named
                ));
            }
        }
        let want = match f {
            Fault::B | Fault::Bl => "b/bl",
            _ => f.name(),
        };
        if row.named.map(IsolationName::name) == Some(want) {
            if !matches!(f, Fault::B | Fault::Bl) {
                let size = row.named_change.map(f64::from).unwrap_or(f64::NAN);
                let exempt = not_separable(name, *f, *change).is_some();
                let size_ok = (size - change).abs() <= 0.2 * change.abs(); // false for NaN
                if !size_ok && !exempt {
                    failures.push(format!("{tag}: size {size:+.3}"));
                }
            }
            named_right += 1;
        } else if let Some(why) = not_separable(name, *f, *change) {
            if row.named.is_some() {
                failures.push(format!("{tag} ({why}): named {:?}", row.named));
            }
            // Shared, but still a leading candidate with its size (the issue's "top
            // candidate"): at +/-50 % a fault that is not named alone must not lose the
            // lead to the fault it is confused with by more than a tie (the core's
            // NAME_MARGIN: two faults whose directions coincide share the probability
            // about evenly, and which of them is first by a hundredth is the noise's).
            if change.abs() > 0.4 {
                let top = row
                    .isolation_candidates
                    .first()
                    .map_or(0.0, |c| c.probability);
                let own = row.isolation_candidates.iter().find(|c| c.fault == *f);
                match own {
                    Some(FaultCandidate {
                        probability,
                        change: Some(k),
                        ..
                    }) if *probability >= top - monitor_core::isolation::NAME_MARGIN
                        && (f64::from(*k) - change).abs() <= 0.2 * change.abs() => {}
                    _ => failures.push(format!(
                        "{tag} ({why}): not a leading candidate with its size: {:?}",
                        row.isolation_candidates
                    )),
                }
            }
        } else {
            failures.push(format!(
                "{tag}: named {:?} ({}), candidates {:?}",
                row.named,
                state_name(row.isolation_state),
                row.isolation_candidates
            ));
        }
    }
    eprintln!("named right: {named_right} of {}", rows.len());
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

#[test]
fn healthy_runs_name_nothing() {
    let rows: Vec<_> = (0..3)
        .into_par_iter()
        .map(|m| (m, run(m, Fault::Rs, 0.0)))
        .collect();
    for (m, row) in rows {
        assert_eq!(row.named, None, "{}: {row:?}", machines()[m].0);
        assert!(row.isolation_candidates.is_empty(), "{row:?}");
    }
}
