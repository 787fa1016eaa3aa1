//! The rotor finding on synthetic records fed to the demodulator directly: tones of known
//! amplitude at known frequencies (written here from their definition), the memory bound.

use super::*;
use monitor_core::frames::{AlphaBeta, SinCos};
use monitor_io::log::Row;
use std::f64::consts::TAU;

/// A record of `dur_s` at `rate` of a 4-pole 50 Hz machine at slip `s`: the line (10 A) and
/// the given components `(frequency [Hz], amplitude over the line)` of the current vector,
/// demodulated on the exact nominal angle; the speed channel where `speed`.
fn record(rate: f64, dur_s: f64, s: f64, tones: &[(f64, f64)], speed: bool) -> RotorFront {
    let f0 = 50.0;
    let mut front = RotorFront::new(rate, f0, MAX_STRETCH_S);
    let n = (dur_s * rate) as usize;
    for k in 0..n {
        let t = k as f64 / rate;
        let (mut a, mut b) = ((TAU * f0 * t).cos(), (TAU * f0 * t).sin());
        for &(f, amp) in tones {
            a += amp * (TAU * f * t).cos();
            b += amp * (TAU * f * t).sin();
        }
        let i = AlphaBeta {
            alpha: (10.0 * a) as f32,
            beta: (10.0 * b) as f32,
        };
        let th = TAU * f0 * t;
        let sc = SinCos {
            sin: th.sin() as f32,
            cos: th.cos() as f32,
        };
        let row = Row {
            t_s: t,
            v_abc: None,
            i_abc: [0.0; 3],
            wm_rad_s: speed.then_some((1.0 - s) * TAU * f0 / 2.0),
            enc_count: None,
            t_winding_c: None,
        };
        front.row(Some(i), sc, t, 0.0, &row);
        front.end_of_row((TAU * f0) as f32);
    }
    front
}

fn machine() -> monitor_io::params::ParamFile {
    monitor_io::params::ParamFile::reference_2p2kw()
}

/// The lower and upper sidebands of a broken cage at slip `s` (50 Hz), at `lo_db` and
/// `up_db` below the line.
fn sidebands(s: f64, lo_db: f64, up_db: f64) -> [(f64, f64); 2] {
    let lin = |db: f64| 10f64.powf(db / 20.0);
    [
        ((1.0 - 2.0 * s) * 50.0, lin(lo_db)),
        ((1.0 + 2.0 * s) * 50.0, lin(up_db)),
    ]
}

#[test]
fn known_sidebands_read_at_their_level() {
    for (rate, dur, s, lo, up) in [
        (1000.0, 4.0, 0.04, -40.0, -46.0),
        (10_000.0, 2.0, 0.05, -30.0, -36.0),
        (2000.0, 60.0, 0.02, -50.0, -52.0),
    ] {
        let r = rotor_report(
            &record(rate, dur, s, &sidebands(s, lo, up), true),
            &machine(),
            &[],
        );
        assert!(r.judged, "{r:?}");
        assert_eq!(r.slip_source, Some(SlipSource::Speed));
        assert!((r.slip.unwrap() - s).abs() < 1e-5, "{r:?}");
        assert!((r.level_db.unwrap() - lo).abs() < 0.15, "{lo}: {r:?}");
        assert!(
            (r.upper_sideband_db.unwrap() - up).abs() < 0.15,
            "{up}: {r:?}"
        );
        assert_eq!(r.band, Some(band_of(lo)));
        // Within twice 20 s the stretch is one spectrum; a minute is Welch segments.
        assert_eq!(r.segments > 1, dur > 40.0, "{r:?}");
    }
}

#[test]
fn without_a_speed_the_slip_comes_from_a_pair_about_the_line() {
    // The sidebands themselves.
    let s = 0.035;
    let r = rotor_report(
        &record(2000.0, 4.0, s, &sidebands(s, -42.0, -48.0), false),
        &machine(),
        &[],
    );
    assert_eq!(r.slip_source, Some(SlipSource::Sidebands), "{r:?}");
    assert!((r.slip.unwrap() - s).abs() < 0.02 * s, "{r:?}");
    assert!((r.level_db.unwrap() + 42.0).abs() < 0.15, "{r:?}");
    // A healthy cage with the rotation harmonics f -/+ f_r (f_r = f (1 - s) / 2): the slip
    // from them, no sign of broken bars.
    let fr = 50.0 * (1.0 - s) / 2.0;
    let ecc = [
        (50.0 - fr, 10f64.powf(-50.0 / 20.0)),
        (50.0 + fr, 10f64.powf(-52.0 / 20.0)),
    ];
    let r = rotor_report(&record(2000.0, 4.0, s, &ecc, false), &machine(), &[]);
    assert_eq!(r.slip_source, Some(SlipSource::Eccentricity), "{r:?}");
    assert!((r.slip.unwrap() - s).abs() < 0.05 * s, "{r:?}");
    assert_eq!(r.band, Some(RotorBand::NoSign), "{r:?}");
    // Neither: cannot judge, with the largest component the sidebands could be.
    let r = rotor_report(&record(2000.0, 4.0, s, &[], false), &machine(), &[]);
    assert!(!r.judged);
    assert!(r.largest_possible_db.unwrap() < -80.0, "{r:?}");
    let why = r.cannot_judge_because.unwrap();
    assert!(
        matches!(why, RotorCannot::SlipUnknown { largest_db_below } if largest_db_below > 80.0),
        "{why:?}"
    );
}

#[test]
fn what_is_missing_is_said() {
    // 0.5 s at 3 % slip: 2sf = 3 Hz needs 5/3 s.
    let s = 0.03;
    let r = rotor_report(
        &record(2000.0, 0.5, s, &sidebands(s, -40.0, -45.0), true),
        &machine(),
        &[],
    );
    let why = r.cannot_judge_because.unwrap();
    assert!(
        matches!(why, RotorCannot::TooShort { needed_s, .. } if (needed_s - 5.0 / 3.0).abs() < 0.01),
        "{why:?}"
    );
    // No load.
    let r = rotor_report(&record(2000.0, 4.0, 0.001, &[], true), &machine(), &[]);
    let why = r.cannot_judge_because.unwrap();
    assert!(
        matches!(
            why,
            RotorCannot::SlipBelow { .. } | RotorCannot::LoadTooLow { no_load: true }
        ),
        "{why:?}"
    );
    // Nothing at all.
    let r = rotor_report(
        &RotorFront::new(2000.0, 50.0, MAX_STRETCH_S),
        &machine(),
        &[],
    );
    assert_eq!(r.cannot_judge_because, Some(RotorCannot::NoCurrent));
}

#[test]
fn the_record_kept_is_bounded() {
    // 400 s at 1 kHz: only the last MAX_STRETCH_S are kept.
    let front = record(1000.0, 400.0, 0.03, &[], true);
    let kept = front.blocks().len() as f64 * front.block_s();
    assert!(
        kept <= MAX_STRETCH_S + 1.0 && kept > MAX_STRETCH_S - 1.0,
        "{kept}"
    );
    let first = front.blocks().front().unwrap().t_s;
    assert!((first - 100.0).abs() < 1.0, "{first}");
}

/// The streaming part's cost per row (docs/performance.md): 36 M rows of a 10 kHz record,
/// from 4000 rows held in cache. A measurement, run on demand:
/// `cargo test --release -p sim-host --lib rotor::tests::cost_per_row -- --ignored --nocapture`;
/// it fails above 50 ns a row (ten times what it takes).
#[test]
#[ignore]
fn cost_per_row() {
    let (n, rate, reps) = (4000usize, 10_000.0, 9000usize);
    let input: Vec<(AlphaBeta, SinCos, Row)> = (0..n)
        .map(|k| {
            let t = k as f64 / rate;
            let th = TAU * 50.0 * t;
            let i = AlphaBeta {
                alpha: (10.0 * th.cos()) as f32,
                beta: (10.0 * th.sin()) as f32,
            };
            let sc = SinCos {
                sin: th.sin() as f32,
                cos: th.cos() as f32,
            };
            let row = Row {
                t_s: t,
                v_abc: None,
                i_abc: [0.0; 3],
                wm_rad_s: Some(150.0),
                enc_count: None,
                t_winding_c: None,
            };
            (i, sc, row)
        })
        .collect();
    let mut front = RotorFront::new(rate, 50.0, MAX_STRETCH_S);
    let start = std::time::Instant::now();
    for rep in 0..reps {
        for (i, sc, row) in &input {
            let t = row.t_s + rep as f64 * n as f64 / rate;
            front.row(Some(*std::hint::black_box(i)), *sc, t, 0.001, row);
            front.end_of_row(314.0);
        }
    }
    let ns = start.elapsed().as_secs_f64() / (reps * n) as f64 * 1e9;
    let mb =
        front.blocks().len() as f64 * std::mem::size_of::<super::baseband::Block>() as f64 / 1e6;
    eprintln!(
        "{ns:.2} ns per row; {} blocks kept ({mb:.1} MB)",
        front.blocks().len()
    );
    assert!(ns < 50.0, "{ns} ns per row");
}
