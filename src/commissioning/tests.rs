//! `commissioning`'s unit tests (host).

use super::*;
use monitor_core::Calibration;

fn run(id: u16, stage: RunStage, blocks: u32) -> CommissioningRun {
    CommissioningRun {
        id,
        stage,
        blocks_learned: blocks,
        blocks_needed: 100,
    }
}

fn cal() -> Calibration {
    Calibration {
        mean: [0.0; 4],
        spread: [0.01; 4],
    }
}

#[test]
fn start_progress_store_done() {
    let mut p = CommissioningProcedure::new(2.0, 3_000);
    let idle = CommissioningRun::default();
    assert_eq!(p.button(&idle, 0), Action::Start { duration_s: 2.0 });
    assert!(p.busy());
    assert_eq!(p.button(&idle, 10), Action::None, "no double start");
    assert_eq!(p.on_status(&idle, 50), CommissioningStep::NOTHING);
    // Progress keeps it going however long it takes.
    for k in 0..100u32 {
        let s = p.on_status(&run(1, RunStage::Learning, k), 100 + 1000 * k);
        assert_eq!(s, CommissioningStep::NOTHING);
    }
    let awaiting = run(1, RunStage::AwaitingStorage(cal()), 100);
    let store = Action::Store {
        run: 1,
        record: cal().into(),
    };
    assert_eq!(p.on_status(&awaiting, 200_000).action, store);
    assert_eq!(p.on_status(&awaiting, 200_050).action, Action::None);
    assert_eq!(p.button(&awaiting, 200_100), Action::None, "storing");
    assert_eq!(p.on_status(&awaiting, 201_100).action, store, "retried");
    let s = p.on_status(&run(1, RunStage::Done, 100), 201_150);
    assert_eq!(s.ended, Some(RunEnd::Commissioned { run: 1 }));
    assert!(!p.busy() && p.last_failure().is_none());
}

#[test]
fn no_progress_cancels_and_the_core_says_when_it_is_done() {
    let mut p = CommissioningProcedure::new(2.0, 3_000);
    p.button(&run(7, RunStage::Done, 0), 0);
    p.on_status(&run(8, RunStage::Learning, 0), 50);
    p.on_status(&run(8, RunStage::Learning, 5), 1_000);
    assert_eq!(
        p.on_status(&run(8, RunStage::Learning, 5), 3_950).action,
        Action::None
    );
    let s = p.on_status(&run(8, RunStage::Learning, 5), 4_000);
    assert_eq!(s.action, Action::Cancel { run: 8 });
    assert_eq!(
        p.on_status(&run(8, RunStage::Learning, 5), 4_050).action,
        Action::None
    );
    assert_eq!(
        p.on_status(&run(8, RunStage::Learning, 5), 5_000).action,
        Action::Cancel { run: 8 },
        "repeated while the core still learns"
    );
    let s = p.on_status(
        &run(8, RunStage::Failed(CommissioningFailure::Cancelled), 5),
        5_050,
    );
    assert_eq!(
        s.ended,
        Some(RunEnd::Failed {
            run: Some(8),
            why: Failure::Stalled
        })
    );
    assert_eq!(p.last_failure(), Some(Failure::Stalled));
    // The core may have learned meanwhile: then the result is stored after all.
    p.button(
        &run(8, RunStage::Failed(CommissioningFailure::Cancelled), 5),
        6_000,
    );
    assert_eq!(p.last_failure(), None, "a new start clears it");
    p.on_status(&run(9, RunStage::Learning, 0), 6_050);
    assert_eq!(
        p.on_status(&run(9, RunStage::Learning, 0), 9_050).action,
        Action::Cancel { run: 9 }
    );
    let s = p.on_status(&run(9, RunStage::AwaitingStorage(cal()), 100), 9_100);
    assert!(matches!(s.action, Action::Store { run: 9, .. }));
}

#[test]
fn the_button_cancels_a_learning_run_and_refused_starts_fail() {
    let mut p = CommissioningProcedure::new(10.0, 3_000);
    p.button(&CommissioningRun::default(), 0);
    p.on_status(&run(1, RunStage::Learning, 0), 50);
    assert_eq!(
        p.button(&run(1, RunStage::Learning, 0), 500),
        Action::None,
        "too soon after the start"
    );
    assert_eq!(
        p.button(&run(1, RunStage::Learning, 3), 1_500),
        Action::Cancel { run: 1 }
    );
    let s = p.on_status(
        &run(1, RunStage::Failed(CommissioningFailure::Cancelled), 3),
        1_550,
    );
    assert_eq!(s.ended, Some(RunEnd::CancelledByUser { run: 1 }));
    assert_eq!(p.last_failure(), None, "a cancel is not a failure");
    // The core never starts: NotStarted after a second.
    let before = run(1, RunStage::Failed(CommissioningFailure::Cancelled), 3);
    p.button(&before, 2_000);
    assert_eq!(p.on_status(&before, 2_900).ended, None);
    let s = p.on_status(&before, 3_050);
    assert_eq!(
        s.ended,
        Some(RunEnd::Failed {
            run: None,
            why: Failure::NotStarted
        })
    );
    // Not stored: the core's reason.
    p.button(&before, 4_000);
    p.on_status(&run(2, RunStage::AwaitingStorage(cal()), 100), 4_050);
    let s = p.on_status(
        &run(2, RunStage::Failed(CommissioningFailure::NotStored), 100),
        4_100,
    );
    assert_eq!(
        p.last_failure(),
        Some(Failure::Core(CommissioningFailure::NotStored))
    );
    assert!(s.ended.is_some() && !p.busy());
}

/// The log's names of a failure: the core's reasons as the core names them, the
/// procedure's own two apart from them and from each other.
#[test]
fn each_failure_has_its_own_name_and_the_cores_reasons_keep_theirs() {
    let core = [
        CommissioningFailure::Cancelled,
        CommissioningFailure::Superseded,
        CommissioningFailure::InvalidStatistics,
        CommissioningFailure::NotStored,
    ];
    for why in core {
        assert_eq!(Failure::Core(why).name(), why.name());
    }
    let mut names: Vec<&str> = core.iter().map(|&w| Failure::Core(w).name()).collect();
    names.push(Failure::NotStarted.name());
    names.push(Failure::Stalled.name());
    for (k, a) in names.iter().enumerate() {
        assert!(!a.is_empty());
        assert!(names[k + 1..].iter().all(|b| b != a), "{a} twice");
    }
}

/// The duration the procedure reports is the one it asks the core for: the default
/// 10 s of evaluated running, or the settings' own.
#[test]
fn the_duration_asked_for_is_the_one_reported() {
    let d = CommissioningProcedure::DEFAULT_DURATION_S;
    for duration_s in [d, 2.5] {
        let mut p = CommissioningProcedure::new(duration_s, 3_000);
        assert_eq!(p.duration_s(), duration_s);
        assert_eq!(
            p.button(&CommissioningRun::default(), 0),
            Action::Start { duration_s }
        );
    }
}

/// A run the procedure did not ask for (the core reports it active while the procedure
/// is idle) is followed like its own: its calibration is handed over for storage, and
/// its end is reported.
#[test]
fn a_run_it_did_not_ask_for_is_followed_and_stored() {
    let mut p = CommissioningProcedure::new(10.0, 3_000);
    let s = p.on_status(&run(4, RunStage::AwaitingStorage(cal()), 100), 0);
    assert!(matches!(s.action, Action::Store { run: 4, .. }));
    assert!(p.busy());
    let s = p.on_status(&run(4, RunStage::Done, 100), 50);
    assert_eq!(s.ended, Some(RunEnd::Commissioned { run: 4 }));
    assert!(!p.busy());
}

/// A newer run that replaced the one followed is followed from its own start: its
/// calibration is stored under its own id, its stall time counts from when it was
/// first seen.
#[test]
fn a_newer_run_replaces_the_one_followed() {
    let mut p = CommissioningProcedure::new(10.0, 3_000);
    p.button(&CommissioningRun::default(), 0);
    p.on_status(&run(1, RunStage::Learning, 0), 50);
    let s = p.on_status(&run(2, RunStage::AwaitingStorage(cal()), 100), 100);
    assert!(matches!(s.action, Action::Store { run: 2, .. }));
}

/// The core has the whole [`CommissioningProcedure::START_TIMEOUT_MS`] to start a run:
/// at 1 000 ms after the press the request still waits, 1 ms later it failed.
#[test]
fn the_core_has_the_whole_second_to_start_a_run() {
    let mut p = CommissioningProcedure::new(10.0, 3_000);
    let idle = CommissioningRun::default();
    p.button(&idle, 5_000);
    assert_eq!(p.on_status(&idle, 6_000), CommissioningStep::NOTHING);
    assert_eq!(
        p.on_status(&idle, 6_001).ended,
        Some(RunEnd::Failed {
            run: None,
            why: Failure::NotStarted
        })
    );
}

/// A storage the core still waits for is handed over again [`CommissioningProcedure::RETRY_MS`]
/// after the last, as a cancel is repeated: at 1 000 ms, not a period later.
#[test]
fn a_storage_and_a_cancel_are_repeated_after_the_same_second() {
    let mut p = CommissioningProcedure::new(10.0, 3_000);
    p.button(&CommissioningRun::default(), 0);
    let awaiting = run(1, RunStage::AwaitingStorage(cal()), 100);
    assert!(matches!(
        p.on_status(&awaiting, 10).action,
        Action::Store { .. }
    ));
    assert_eq!(p.on_status(&awaiting, 1_009).action, Action::None);
    assert!(matches!(
        p.on_status(&awaiting, 1_010).action,
        Action::Store { .. }
    ));
    let mut p = CommissioningProcedure::new(10.0, 3_000);
    p.button(&CommissioningRun::default(), 0);
    let learning = run(2, RunStage::Learning, 0);
    p.on_status(&learning, 10);
    assert_eq!(
        p.on_status(&learning, 3_010).action,
        Action::Cancel { run: 2 }
    );
    assert_eq!(p.on_status(&learning, 4_009).action, Action::None);
    assert_eq!(
        p.on_status(&learning, 4_010).action,
        Action::Cancel { run: 2 }
    );
}
