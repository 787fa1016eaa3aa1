//! `sim-host bench --isolation`'s library part ([`monitor_studies::bench::isolation`]) on a small
//! plan: the 2.2 kW machine, Rr and the current sensor at -50/-10/+10/+50 %, both loads, the
//! rotor-flux mode (16 runs). The bench must find every one, name at least 12 (measured: the
//! current sensor's 8 and Rr's 4 at the file's load; Rr at 0.6 of it is the leading
//! candidate with its size, p 0.65-0.79, below the name's 0.9), never a wrong name; the
//! confusion matrix must count every case once.

use monitor_core::{AngleSource, Fault, IsolationState};
use monitor_replay::{angle_source_name, FaultCandidate, IsolationName, NameGiven};
use monitor_studies::bench::isolation::{motors, run, BenchPlan, CHANGES, LOADS};

#[test]
fn the_bench_finds_names_and_counts() {
    let m = motors().expect("the 11 kW file parses"); // ok: test
    assert_eq!(m.len(), 3);
    let plan = BenchPlan {
        motors: m.into_iter().filter(|m| m.name == "2.2 kW").collect(),
        faults: vec![Fault::Rr, Fault::CurrentSensor],
        changes: CHANGES.to_vec(),
        loads: LOADS.to_vec(),
        modes: vec![AngleSource::RotorFluxCurrentModel],
    };
    let done = std::sync::atomic::AtomicUsize::new(0);
    let b = run(&plan, || {
        done.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
    })
    .expect("the bench runs"); // ok: test
    assert_eq!(done.into_inner(), 16);
    assert_eq!(b.cases.len(), 16);
    let mut right: usize = 0;
    for c in &b.cases {
        assert!(c.detected, "{c:?}");
        assert!(c.wrong_names.is_empty(), "{c:?}");
        if c.right {
            right += 1;
            let err = c.size_error.expect("a size"); // ok: test
            assert!(err <= 0.2, "{c:?}");
            let t = c.time_to_name_s.expect("a time to name"); // ok: test
            assert!(t > 0.0 && t < 3.5, "{c:?}");
        } else {
            // Not named (its calibrated probability under the name's 0.9, issue 48: Rr at
            // 0.6 of the load shares it with a speed reading 0.3-1 % off, p 0.65-0.79; only
            // the torque balance's load term tells them apart, and the load is 0.6 of the
            // file's), but the leading candidate with its size.
            let top = c.candidates.first().expect("a candidate"); // ok: test
            let k = f64::from(top.change.unwrap_or(f32::NAN));
            assert!(
                top.fault == c.fault && (k - c.change).abs() <= 0.2 * c.change.abs(),
                "{c:?}"
            );
        }
    }
    for c in b.cases.iter().filter(|c| !c.right) {
        eprintln!(
            "not named: {} {:+} at {} load: {:?}",
            c.fault,
            c.change,
            c.load_scale,
            c.candidates
                .iter()
                .map(|k| (k.fault, k.probability, k.change))
                .collect::<Vec<_>>()
        );
    }
    assert!(right >= 12, "{right} of 16 named right");
    let s = &b.summaries[0];
    assert_eq!(
        (s.cases, s.detected, s.named_right, s.wrong_named),
        (16, 16, right, 0)
    );
    let conf = &b.confusion[0];
    assert_eq!(
        conf.rows.iter().map(|f| f.name()).collect::<Vec<_>>(),
        ["rr", "current_sensor"]
    );
    assert_eq!(conf.columns.len(), 12);
    let total: u32 = conf.counts.iter().flatten().sum();
    assert_eq!(total, 16);
    let rr = conf
        .columns
        .iter()
        .position(|c| c.name() == "rr")
        .expect("rr column"); // ok: test
    let cs = conf
        .columns
        .iter()
        .position(|c| c.name() == "current_sensor")
        .expect("current_sensor column"); // ok: test
    assert_eq!(conf.counts[0][rr] + conf.counts[1][cs], right as u32);
}

#[test]
fn a_wrong_name_is_counted() {
    // A row in which the isolation named rr for an Ls fault at the end, after naming ls.
    use monitor_studies::bench::isolation::judge;
    use monitor_studies::fault_signatures::Table1Row;
    let name = |n: &str| IsolationName::from_name(n).expect("a name"); // ok: test
    let row = Table1Row {
        fault: Fault::Ls,
        change: 0.5,
        signature: [0; 4],
        paper: [0; 4],
        expected: [0; 4],
        residuals: [0.0; 4],
        candidates: Vec::new(),
        detection_delay_s: Some(0.2),
        named: Some(name("rr")),
        named_change: Some(0.03),
        isolation_candidates: vec![FaultCandidate {
            fault: Fault::Rr,
            probability: 0.7,
            change: Some(0.03),
            phase: None,
        }],
        isolation_state: IsolationState::Isolated,
        name_delay_s: Some(0.8),
        names_given: vec![
            NameGiven {
                name: name("ls"),
                t_s: 0.8,
            },
            NameGiven {
                name: name("rr"),
                t_s: 1.5,
            },
        ],
    };
    let c = judge("3 hp", AngleSource::Pll, 1.0, Fault::Ls, 0.5, &row);
    assert!(!c.right);
    assert_eq!(c.named.name(), "rr");
    assert_eq!(c.wrong_names, ["rr at +1.50 s"]);
    assert_eq!(c.time_to_name_s, Some(0.8));
    assert_eq!(c.size_error, None);
    assert_eq!(angle_source_name(c.mode), "pll");
}

/// Issue 9's small faults: Rs at -10 and +10 % on the 3 hp and the 11 kW machines (0.2 % of
/// |V| on the 3 hp machine), both loads, both angle modes (16 runs). With a 0.5 s
/// exponential average and the learned spreads floored at 0.15 % of |V| none of them was
/// detected; the follower's 2 s mean brings the scatter to 0.02 % and the floor to 0.04 %
/// (`monitor_core::isolation::LEARNED_SPREAD_FLOOR`): every case is named `rs` alone, its
/// size within 20 %, and nothing else is named.
#[test]
fn rs_ten_percent_is_named_on_the_small_and_the_large_machine() {
    let m = motors().expect("the 11 kW file parses"); // ok: test
    let plan = BenchPlan {
        motors: m.into_iter().filter(|m| m.name != "2.2 kW").collect(),
        faults: vec![Fault::Rs],
        changes: vec![-0.1, 0.1],
        loads: LOADS.to_vec(),
        modes: vec![AngleSource::RotorFluxCurrentModel, AngleSource::Pll],
    };
    let b = run(&plan, || {}).expect("the bench runs"); // ok: test
    assert_eq!(b.cases.len(), 16);
    for c in &b.cases {
        assert!(c.right, "{c:?}");
        assert!(c.wrong_names.is_empty(), "{c:?}");
        let err = c.size_error.expect("a size"); // ok: test
        assert!(err <= 0.2, "{c:?}");
    }
}
