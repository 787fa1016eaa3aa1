//! How many turns are shorted, on the real recordings (the ITSC data set, MIT license:
//! `examples/recordings/itsc/`; a 0.75 hp motor at no load, double-star winding, 10-40 %
//! of one phase's turns shorted, currents only at 1 kHz). The issue "How many turns".
//!
//! What must hold:
//! - from the model alone (no labels; `parallel_paths` 2 as the motor's connection
//!   says), every one of the 24 fault recordings' level within one step (10 % of the
//!   turns) of the truth, and the estimate growing with the level within each phase;
//! - a calibration learned on run 001's labelled recordings names phase and level right
//!   in at least 12 of run 002's 13 conditions (healthy: no phase named).
//!
//! The model alone is also scored against the issue's "exactly right in at least 18 of
//! 24", printed (`--nocapture`), not asserted: `docs/isolation.md`, "How many turns", says
//! why it is not met.

use monitor_io::log::mapping::load_params;
use monitor_io::log::{LogFile, OpenOptions};
use monitor_replay::{
    diagnose_log, LabelledRun, ReplayOptions, TurnCalibration, TurnLevelOptions, UnbalanceReport,
};
use std::path::{Path, PathBuf};

fn folder() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples/recordings/itsc")
}

/// The 13 conditions of one run: `(name, shorted phase index, level 0..4)`.
fn conditions(run: &str) -> Vec<(String, Option<usize>, u32)> {
    let mut v = vec![(format!("SC_HLT_{run}"), None, 0)];
    for k in 0..3 {
        for lv in 1..=4u32 {
            let mut lvl = [0u32; 3];
            lvl[k] = lv;
            v.push((
                format!("SC_A{}_B{}_C{}_{run}", lvl[0], lvl[1], lvl[2]),
                Some(k),
                lv,
            ));
        }
    }
    v
}

fn judge(name: &str, turn_level: TurnLevelOptions) -> UnbalanceReport {
    let (params, columns) =
        load_params(&folder().join("baldor_0p75hp.toml")).expect("parameter file"); // ok: test
    let file = LogFile::open_with(
        &folder().join(format!("{name}.csv")),
        &OpenOptions {
            group: None,
            columns,
        },
    )
    .expect("the recording as published"); // ok: test
    let opts = ReplayOptions {
        turn_level,
        ..ReplayOptions::default()
    };
    diagnose_log(&params, &file, opts, &mut |_| {})
        .expect("diagnose") // ok: test
        .report
        .unbalance
}

fn double_star() -> TurnLevelOptions {
    TurnLevelOptions {
        parallel_paths: monitor_replay::ParallelPaths::of(2),
        calibration: None,
    }
}

#[test]
fn the_model_alone_sizes_every_short_within_one_step() {
    let (mut exact, mut within, mut covered, mut n) = (0, 0, 0, 0);
    let mut by_phase = vec![Vec::new(); 3];
    for run in ["001", "002"] {
        for (name, phase, lv) in conditions(run).into_iter().filter(|c| c.1.is_some()) {
            let u = judge(&name, double_star());
            let t = u.shorted_turns.expect("a level where a phase is named"); // ok: test
            assert_eq!(t.basis, monitor_replay::LevelBasis::Physics);
            assert_eq!(Some(t.phase.index()), phase, "{name}: the phase");
            let truth = 0.1 * lv as f32;
            let step = (10.0 * t.fraction).round() as i64;
            exact += usize::from(step == i64::from(lv));
            within += usize::from((step - i64::from(lv)).abs() <= 1);
            covered += usize::from(t.low <= truth && truth <= t.high);
            n += 1;
            println!(
                "{name}: {:.0} % ({:.0}-{:.0} %), loop |r| {:.3}, truth {:.0} %",
                100.0 * t.fraction,
                100.0 * t.low,
                100.0 * t.high,
                t.loop_ratio,
                100.0 * truth
            );
            if let Some(k) = phase {
                by_phase[k].push((run, lv, t.fraction));
            }
        }
    }
    println!(
        "model alone: exact {exact} of {n}, within one step {within}, interval covers {covered}"
    );
    assert_eq!(n, 24);
    assert_eq!(within, n, "every level within one step of the truth");
    // Within a phase and a run, a larger short never reads smaller.
    for runs in &by_phase {
        for run in ["001", "002"] {
            let f: Vec<f32> = runs.iter().filter(|r| r.0 == run).map(|r| r.2).collect();
            assert!(
                f.windows(2).all(|w| w[1] > w[0]),
                "{run}: {f:?} grows with the level"
            );
        }
    }
}

#[test]
fn a_calibration_from_run_001_names_phase_and_level_of_run_002() {
    let learned: Vec<LabelledRun> = conditions("001")
        .into_iter()
        .filter_map(|(name, phase, lv)| {
            phase?;
            let t = judge(&name, double_star()).shorted_turns_physics?;
            Some(LabelledRun {
                phase: t.phase,
                fraction: 0.1 * lv as f32,
                loop_ratio: t.loop_ratio,
            })
        })
        .collect();
    assert_eq!(learned.len(), 12, "every labelled fault run read");
    let cal = TurnCalibration::learn(&learned).expect("a calibration"); // ok: test
    let with_cal = TurnLevelOptions {
        parallel_paths: monitor_replay::ParallelPaths::of(2),
        calibration: Some(cal),
    };
    let mut right = 0;
    for (name, phase, lv) in conditions("002") {
        let u = judge(&name, with_cal);
        let said = u.shorted_turns.filter(|_| u.names_a_short()).map(|t| {
            (
                Some(t.phase.index()),
                (10.0 * t.fraction).round() as u32,
                t.basis,
            )
        });
        let (p, l) = said.map_or((None, 0), |s| (s.0, s.1));
        if let Some(s) = said {
            assert_eq!(
                s.2,
                monitor_replay::LevelBasis::Calibration,
                "{name}: says which"
            );
        }
        println!("{name}: said {p:?} level {l}, truth {phase:?} level {lv}");
        right += usize::from(p == phase && l == lv);
    }
    println!("calibrated: phase and level right in {right} of 13");
    assert!(right >= 12, "phase and level right in {right} of 13");
}
