//! Commissioning on real running: a window over healthy running whose supply steps ±8 %
//! every 1.5 s is learned from its quasi-steady blocks (the steps close the quasi-steady
//! gate for a while), and the healthy log stays healthy after it; a window with less than
//! the stated minimum of quasi-steady running is refused, saying how much was found.

use monitor_io::log::Channels;
use monitor_io::params::ParamFile;
use monitor_replay::{diagnose_rows, ReplayError, ReplayOptions, Verdict, MIN_LEARNED_S};
use monitor_sim::{simulate_to_vec, Scenario};

fn supply_steps_log(p: &ParamFile, seed: u64) -> Vec<monitor_io::log::Row> {
    let steps: Vec<String> = (1..8)
        .map(|k| {
            let v = if k % 2 == 1 { 1.08 } else { 0.92 };
            format!("{{ t_s = {:.1}, v_scale = {v} }}", 1.5 * k as f64)
        })
        .collect();
    let text = format!(
        "duration_s = 12.0\nsample_rate_hz = 5000.0\nseed = {seed}\n[supply]\nsteps = [{}]\n",
        steps.join(", ")
    );
    let sc = Scenario::from_toml_str(&text, "steps").expect("scenario"); // ok: test
    simulate_to_vec(p, &sc).expect("simulate") // ok: test
}

fn channels() -> Channels {
    Channels {
        voltages: true,
        speed: true,
        encoder: false,
        temperature: false,
    }
}

#[test]
fn a_window_with_supply_steps_inside_is_learned_and_the_log_stays_healthy() {
    for p in [ParamFile::reference_2p2kw(), ParamFile::reference_3hp()] {
        let rows = supply_steps_log(&p, 4);
        let opts = ReplayOptions {
            commission: Some(monitor_replay::CommissionWindow::of(3.0, 6.5)),
            ..ReplayOptions::default()
        };
        let r = diagnose_rows(&p, channels(), &rows, opts).expect("learned"); // ok: test
        assert_eq!(
            r.commissioning.state,
            monitor_replay::CommissioningOutcome::Learned
        );
        let learned = r.commissioning.seconds_evaluated;
        // Less than the window (the steps closed the gate), at least the minimum.
        assert!(
            (MIN_LEARNED_S..3.5).contains(&learned),
            "learned {learned} s"
        );
        // The learned range covers both supply levels (±8 %).
        let v = r.commissioning.voltage_v.expect("voltage span"); // ok: test
        assert!(v[1] / v[0] > 1.12, "{v:?}");
        assert_eq!(r.verdict, Verdict::Healthy, "{:?}", r.verdict_finding);
    }
}

#[test]
fn a_window_with_too_little_steady_running_says_how_much_it_found() {
    let p = ParamFile::reference_2p2kw();
    let rows = supply_steps_log(&p, 5);
    // 0.6 s from 0.3 s: the start, never quasi-steady.
    let opts = ReplayOptions {
        commission: Some(monitor_replay::CommissionWindow::of(0.1, 0.7)),
        ..ReplayOptions::default()
    };
    match diagnose_rows(&p, channels(), &rows, opts) {
        Err(ReplayError::IncompleteCommissioning { not_learned, .. }) => {
            // How much it found, by when, and how much a window needs.
            assert!(
                matches!(
                    not_learned.why,
                    monitor_replay::NotLearnedWhy::TooLittle { learned_s, needed_s, .. }
                        if learned_s < needed_s && needed_s > 0.0
                ),
                "{not_learned:?}"
            );
        }
        other => panic!("not refused: {:?}", other.map(|r| r.commissioning)),
    }
}
