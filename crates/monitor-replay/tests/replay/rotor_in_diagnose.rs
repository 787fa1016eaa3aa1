//! Broken rotor bars in `diagnose` (issue 48, the rotor finding, JSON `rotor`): steady
//! records cut from simulated runs of the reference motors with 0, 1 and 2 broken bars of a
//! 28-bar cage (the simulator's asymmetric cage), at three loads, 1-10 kHz, 2-10 s; and
//! synthetic currents with sidebands of known level written here.
//!
//! The second opinion: the level the report reads is checked against the textbook
//! relation of the sidebands to the cage's asymmetry (Bellini, Filippetti, Franceschini,
//! Tassoni, Kliman, IEEE Trans. Ind. Appl. 37(5), 2001: `(I_(1-2s)f + I_(1+2s)f) / I_q =
//! delta / (3 + delta)`, with Kliman's `delta = 3n / (N - 3n)`), the torque current `I_q`
//! taken from the T-equivalent circuit written here at the run's own slip; and on synthetic
//! three-phase currents whose sidebands are set by hand.
//!
//! Every case runs by default (the 36 broken-bar records take under a second).

use monitor_testkit::small_motor;

use monitor_io::log::{Channels, Row};
use monitor_io::params::ParamFile;
use monitor_replay::{diagnose_rows, DiagnoseReport, ReplayOptions, RotorBand, SlipSource};
use monitor_sim::{
    simulate_to_vec, EffectSpec, LoadKind, LoadSpec, LoadStep, Scenario, SensorSpec,
};
use std::f64::consts::TAU;

/// The cage's bars (the parameter file is told it: `rotor_bars`).
const BARS: u32 = 28;

/// The motors: name, parameter file with the bar count, rated torque [N m], the time its
/// direct-on-line start has settled [s].
fn motor(which: &str) -> (ParamFile, f64, f64) {
    let (mut p, rated, settle) = match which {
        "3hp" => (ParamFile::reference_3hp(), 12.2, 2.0),
        "2p2kw" => (ParamFile::reference_2p2kw(), 14.6, 1.2),
        _ => (small_motor::small_0p37kw(), 2.57, 0.8),
    };
    p.motor.rotor_bars = Some(BARS);
    (p, rated, settle)
}

/// The last `record_s` of a run of `which` at `load` times its rated torque with `broken`
/// adjacent broken bars, logged at `rate_hz` (voltages, currents, speed): started
/// direct-on-line at no load, the load on at the settle time, 1.5 s to settle the slip,
/// then the record. The rows are those of a record taken in steady running.
fn record(
    which: &str,
    load: f64,
    broken: f64,
    record_s: f64,
    rate_hz: f64,
    noisy: bool,
) -> Vec<Row> {
    let (p, rated, settle) = motor(which);
    let mut s = Scenario::steady(settle + 1.5 + record_s, rate_hz);
    s.load = LoadSpec {
        kind: LoadKind::Torque,
        torque_nm: Some(0.0),
        bl_nms: None,
        steps: vec![LoadStep {
            t_s: settle,
            torque_nm: Some(load * rated),
            bl_scale: None,
        }],
    };
    if noisy {
        s.sensors = SensorSpec::default();
    }
    if broken > 0.0 {
        s.effects = vec![EffectSpec::RotorAsymmetry {
            delta: None,
            broken_bars: Some(broken),
            bars: Some(f64::from(BARS)),
        }];
    }
    let rows = simulate_to_vec(&p, &s).expect("simulated"); // ok: test
    let keep = (record_s * rate_hz).round() as usize;
    rows[rows.len() - keep..].to_vec()
}

/// `diagnose` of `rows` of `p`'s motor with the given channels, no commissioning.
fn diagnose(p: &ParamFile, rows: &[Row], voltages: bool, speed: bool) -> DiagnoseReport {
    let channels = Channels {
        voltages,
        speed,
        encoder: false,
        temperature: false,
    };
    let rows: Vec<Row> = rows
        .iter()
        .map(|r| Row {
            v_abc: if voltages { r.v_abc } else { None },
            wm_rad_s: if speed { r.wm_rad_s } else { None },
            enc_count: None,
            ..*r
        })
        .collect();
    diagnose_rows(p, channels, &rows, ReplayOptions::default()).expect("diagnosed")
    // ok: test
}

/// The textbook level (second opinion): the sum of the two sidebands over the line,
/// `share delta / (3 + delta)`, `share = I_q / |I_s|` from the T-equivalent circuit at slip
/// `s`: `I_r = I_s j Xm / (Rr/s + j (Xm + Xlr))`, `I_q = (Lr / Lm) |I_r|` (rotor-flux
/// orientation: `psi_rq = Lm i_sq + Lr i_rq = 0`).
fn textbook_sum(p: &ParamFile, s: f64, broken: f64) -> f64 {
    let m = &p.motor;
    let w = TAU * p.supply.f_hz;
    let (xm, xlr) = (w * m.lm_h, w * (m.lr_h - m.lm_h));
    // |I_r| / |I_s| = Xm / |Rr/s + j (Xm + Xlr)|.
    let ir_over_is = xm / (m.rr_ohm / s).hypot(xm + xlr);
    let share = m.lr_h / m.lm_h * ir_over_is;
    let n = f64::from(BARS);
    let delta = 3.0 * broken / (n - 3.0 * broken);
    share * delta / (3.0 + delta)
}

/// The mean slip of `rows` (their speed channel) of `p`'s motor.
fn slip_of(p: &ParamFile, rows: &[Row]) -> f64 {
    let wm = rows.iter().filter_map(|r| r.wm_rad_s).sum::<f64>() / rows.len() as f64;
    1.0 - wm * f64::from(p.motor.poles / 2) / (TAU * p.supply.f_hz)
}

/// One case of the broken-bar sweep: (motor, load, broken bars, record [s], rate [Hz],
/// sensor noise).
type Case = (&'static str, f64, f64, f64, f64, bool);

/// Every case of the sweep.
fn broken_cases() -> Vec<Case> {
    let mut all = Vec::new();
    for which in ["3hp", "2p2kw"] {
        for load in [0.5, 0.75, 1.0] {
            for broken in [1.0, 2.0] {
                for (record_s, rate, noisy) in [
                    (2.0, 10_000.0, false),
                    (4.0, 2000.0, true),
                    (10.0, 1000.0, false),
                ] {
                    all.push((which, load, broken, record_s, rate, noisy));
                }
            }
        }
    }
    all
}

#[test]
fn broken_bars_are_named_with_their_level_and_band() {
    let mut failures = Vec::new();
    for (which, load, broken, record_s, rate, noisy) in broken_cases() {
        let (p, _, _) = motor(which);
        let rows = record(which, load, broken, record_s, rate, noisy);
        let rep = diagnose(&p, &rows, true, true);
        let r = &rep.rotor;
        let s = slip_of(&p, &rows);
        let fs = 2.0 * s * p.supply.f_hz;
        let case =
            format!("{which} load {load} {broken} bars {record_s} s {rate} Hz noise {noisy}");
        eprintln!("{case}: {}", said(r));
        if rep.unbalance.suspect_phase.is_some() && rep.unbalance.phase_confidence >= 0.5 {
            failures.push(format!(
                "{case}: the winding names phase {:?} at {:.2}",
                rep.unbalance.suspect_phase, rep.unbalance.phase_confidence
            ));
        }
        // The resolution rule: 5 bins of 1/T between the line and 2sf.
        if record_s < 5.0 / fs + 0.05 {
            let why = monitor_words::diagnose::Story::rotor_sentence(r);
            if !why.contains("s are needed") || r.judged {
                failures.push(format!(
                    "{case}: 2sf = {fs:.2} Hz needs {:.2} s: {why}",
                    5.0 / fs
                ));
            }
            continue;
        }
        let (Some(level), Some(upper), Some(p_fault)) =
            (r.level_db, r.upper_sideband_db, r.confidence)
        else {
            failures.push(format!("{case}: not judged: {:?}", r.cannot_judge_because));
            continue;
        };
        // Named as broken bars, with the level and a band past "watch".
        let named = r.judged
            && p_fault >= 0.5
            && said(r).contains("broken rotor bars")
            && said(r).contains(&format!("{:.1} dB below", -level));
        if !named || matches!(r.band, Some(RotorBand::NoSign | RotorBand::Watch) | None) {
            failures.push(format!("{case}: not named: {}", said(r)));
        }
        // The textbook's sum of the two sidebands, within 2 dB.
        let sum = 10f64.powf(level / 20.0) + 10f64.powf(upper / 20.0);
        let want = textbook_sum(&p, s, broken);
        let off_db = 20.0 * (sum / want).log10();
        eprintln!("  sidebands {level:.1} / {upper:.1} dB, sum {sum:.4} vs textbook {want:.4} ({off_db:+.2} dB), slip {s:.4} vs {:.4}, bars {:?}", r.slip.unwrap_or(f64::NAN), r.broken_bars);
        if off_db.abs() > 2.0 {
            failures.push(format!(
                "{case}: sidebands' sum {off_db:+.2} dB off the textbook's"
            ));
        }
        // The bars, within half a bar.
        if r.broken_bars.is_none_or(|n| (n - broken).abs() > 0.5) {
            failures.push(format!("{case}: {:?} broken bars", r.broken_bars));
        }
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

#[test]
fn healthy_motors_of_three_sizes_give_no_rotor_finding() {
    let mut failures = Vec::new();
    for which in ["3hp", "2p2kw", "0p37kw"] {
        for (load, record_s, rate, noisy) in [
            (1.0, 4.0, 2000.0, true),
            (0.5, 10.0, 1000.0, false),
            (0.75, 2.0, 10_000.0, true),
        ] {
            let (p, _, _) = motor(which);
            let rows = record(which, load, 0.0, record_s, rate, noisy);
            let r = diagnose(&p, &rows, true, true).rotor;
            let case = format!("healthy {which} load {load} {record_s} s {rate} Hz noise {noisy}");
            eprintln!("{case}: {}", said(&r));
            let fs = 2.0 * slip_of(&p, &rows) * p.supply.f_hz;
            if record_s < 5.0 / fs + 0.05 {
                // Too short for this slip: said so, and no finding.
                if r.judged || !said(&r).contains("s are needed") {
                    failures.push(format!("{case}: {}", said(&r)));
                }
                continue;
            }
            let quiet = r.judged
                && r.band == Some(RotorBand::NoSign)
                && r.confidence.is_some_and(|c| c < 0.01);
            // "no sign" names no fault: no confidence or probability beside it (issue 65:
            // "confidence 0.00" read as "not sure").
            let no_number = !said(&r).contains("confidence") && !said(&r).contains("probab");
            if !quiet || !said(&r).contains("no sign of broken bars") || !no_number {
                failures.push(format!("{case}: {}", said(&r)));
            }
        }
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

/// A deterministic Gaussian source (xorshift64* and Box-Muller), for the synthetic records.
struct Gauss(u64);

impl Gauss {
    fn uniform(&mut self) -> f64 {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        ((self.0.wrapping_mul(0x2545_F491_4F6C_DD1D) >> 11) as f64 + 0.5) / (1u64 << 53) as f64
    }
    fn normal(&mut self) -> f64 {
        let (u, v) = (self.uniform(), self.uniform());
        (-2.0 * u.ln()).sqrt() * (TAU * v).cos()
    }
}

/// A synthetic record of a 4-pole 50 Hz motor at slip `s`: three-phase currents of the
/// line (10 A peak) and the two sidebands `(1 -/+ 2s) f` at `lo_db` and `up_db` below it,
/// each a balanced positive-sequence set with its own phase, plus white noise of `noise`
/// times the line's peak on each phase; the speed channel `(1 - s) w / 2` with a relative
/// `wobble` at 1.3 Hz.
fn synthetic(
    s: f64,
    lo_db: f64,
    up_db: f64,
    noise: f64,
    wobble: f64,
    dur_s: f64,
    g: &mut Gauss,
) -> Vec<Row> {
    let (f, rate, i1) = (50.0, 1000.0, 10.0);
    let lin = |db: f64| i1 * 10f64.powf(db / 20.0);
    let comps = [
        (f, i1, 0.3),
        ((1.0 - 2.0 * s) * f, lin(lo_db), 1.1),
        ((1.0 + 2.0 * s) * f, lin(up_db), -2.0),
    ];
    (0..(dur_s * rate) as usize)
        .map(|k| {
            let t = k as f64 / rate;
            let phase = |j: usize| {
                comps
                    .iter()
                    .map(|&(fc, a, ph)| a * (TAU * fc * t + ph - TAU * j as f64 / 3.0).cos())
                    .sum::<f64>()
            };
            let wm = (1.0 - s) * TAU * f / 2.0 * (1.0 + wobble * (TAU * 1.3 * t).sin());
            Row {
                t_s: t,
                v_abc: None,
                i_abc: [0, 1, 2].map(|j| phase(j) + noise * i1 * g.normal()),
                wm_rad_s: Some(wm),
                enc_count: None,
                t_winding_c: None,
            }
        })
        .collect()
}

/// `diagnose` of a synthetic record (currents and speed, the 2.2 kW machine's file: 50 Hz,
/// 4 poles).
fn diagnose_synthetic(rows: &[Row]) -> monitor_replay::RotorReport {
    let mut p = ParamFile::reference_2p2kw();
    p.motor.rotor_bars = Some(BARS);
    diagnose(&p, rows, false, true).rotor
}

#[test]
fn synthetic_sidebands_are_read_at_their_level_through_noise_and_a_speed_wobble() {
    let mut g = Gauss(7);
    // (slip, lower, upper [dB], noise [x I1], speed wobble, record [s]): the level within
    // 0.5 dB where it stands 10 dB above the noise, the band by Thomson and Fenger's edges.
    for (s, lo, up, noise, wobble, dur) in [
        (0.03, -40.0, -46.0, 0.001, 0.0, 4.0),
        (0.03, -45.0, -50.0, 0.001, 0.004, 4.0),
        (0.04, -51.0, -55.0, 0.002, 0.004, 10.0),
        (0.02, -30.0, -33.0, 0.01, 0.004, 6.0),
    ] {
        let r = diagnose_synthetic(&synthetic(s, lo, up, noise, wobble, dur, &mut g));
        eprintln!("{lo} dB, noise {noise}, wobble {wobble}: {}", said(&r));
        assert!(r.judged, "{}", said(&r));
        assert_eq!(r.slip_source, Some(SlipSource::Speed));
        let level = r.level_db.unwrap();
        assert!((level - lo).abs() < 0.5, "{lo}: {}", said(&r));
        assert!(
            (r.upper_sideband_db.unwrap() - up).abs() < 0.7,
            "{up}: {}",
            said(&r)
        );
        let band = match lo {
            x if x < -54.0 => RotorBand::NoSign,
            x if x < -48.0 => RotorBand::Watch,
            x if x < -42.0 => RotorBand::CrackedBarOrJoint,
            x if x < -36.0 => RotorBand::BrokenBars,
            _ => RotorBand::SeveralBrokenBars,
        };
        assert_eq!(r.band, Some(band), "{}", said(&r));
        // "watch" is a finding below one half, a cracked bar or worse above.
        let p = r.confidence.unwrap();
        assert_eq!(p >= 0.5, lo > -48.0, "{}", said(&r));
    }
}

#[test]
fn the_confidence_is_calibrated_on_records_of_known_sidebands() {
    // 240 synthetic records (ROTOR_CAL_N sets another count): the true lower sideband uniform in -60..-36 dB, the noise
    // log-uniform from 0.1 % to 20 % of the line (from far below to above the sidebands),
    // 4 s at 1 kHz, slip 3 %. "A rotor fault" is the true level above the fault edge; the
    // edge itself is known to about 2 dB between published guidelines, so each record's
    // edge is drawn from N(-48 dB, 2 dB) (the report's stated model). Calibrated: in each
    // band of the reported probability, the share of faults within 0.12 of the mean
    // probability (plus twice its binomial spread), and at least 85 % of those named at
    // >= 0.5 are faults (records gathered about the edge: a calibrated probability names
    // there with the precision its mean says).
    let mut g = Gauss(2026);
    let mut rows = Vec::new();
    let n_records: usize = std::env::var("ROTOR_CAL_N")
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(240);
    for _ in 0..n_records {
        let level = -60.0 + 24.0 * g.uniform();
        let noise = 0.001 * 200f64.powf(g.uniform());
        let edge = -48.0 + 2.0 * g.normal();
        let r = diagnose_synthetic(&synthetic(
            0.03,
            level,
            level - 6.0,
            noise,
            0.0,
            4.0,
            &mut g,
        ));
        let Some(p) = r.confidence else {
            panic!(
                "no confidence at {level:.1} dB, noise {noise}: {}",
                said(&r)
            ); // ok: test
        };
        rows.push((p, level > edge));
    }
    let mut failures = Vec::new();
    eprintln!("| reported probability | records | mean probability | share with a fault |");
    for (lo, hi) in [(0.0, 0.1), (0.1, 0.5), (0.5, 0.9), (0.9, 1.01)] {
        let bin: Vec<&(f64, bool)> = rows.iter().filter(|(p, _)| *p >= lo && *p < hi).collect();
        if bin.is_empty() {
            continue;
        }
        let n = bin.len() as f64;
        let mean = bin.iter().map(|(p, _)| p).sum::<f64>() / n;
        let share = bin.iter().filter(|(_, f)| *f).count() as f64 / n;
        eprintln!(
            "| {lo:.1}-{:.1} | {} | {mean:.3} | {share:.3} |",
            hi.min(1.0),
            bin.len()
        );
        // At and above one half (where a finding becomes a FAULT): the share within 0.1
        // (plus twice its binomial spread) of the mean; below it, never more faults named
        // than there are (at the noise the probability does not presume a sideband
        // hidden beneath it: conservative).
        let spread = (mean * (1.0 - mean) / n).sqrt();
        let off = if lo >= 0.5 {
            (share - mean).abs()
        } else {
            mean - share
        };
        if n >= 10.0 && off > 0.1 + 2.0 * spread {
            failures.push(format!(
                "{lo}..{hi}: mean {mean:.3}, share {share:.3} of {n}"
            ));
        }
    }
    let named: Vec<bool> = rows
        .iter()
        .filter(|(p, _)| *p >= 0.5)
        .map(|(_, f)| *f)
        .collect();
    let right = named.iter().filter(|f| **f).count() as f64 / named.len().max(1) as f64;
    eprintln!(
        "named at >= 0.5: {} records, {:.1} % faults",
        named.len(),
        100.0 * right
    );
    if right < 0.85 {
        failures.push(format!(
            "only {:.1} % of those named are faults",
            100.0 * right
        ));
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

#[test]
fn what_is_missing_is_said() {
    let (p, _, _) = motor("3hp");
    // Too short: 0.6 s at rated load (2sf about 5.5 Hz needs about 0.9 s).
    let rows = record("3hp", 1.0, 1.0, 0.6, 2000.0, false);
    let r = diagnose(&p, &rows, true, true).rotor;
    assert!(
        !r.judged && said(&r).contains("s are needed"),
        "{}",
        said(&r)
    );
    // No load.
    let rows = record("3hp", 0.0, 1.0, 4.0, 2000.0, false);
    let r = diagnose(&p, &rows, true, true).rotor;
    assert!(!r.judged && said(&r).contains("(no load)"), "{}", said(&r));
    // No speed and a healthy cage: the slip is unknown; the bound is given.
    let rows = record("3hp", 1.0, 0.0, 4.0, 2000.0, false);
    let r = diagnose(&p, &rows, true, false).rotor;
    assert!(
        !r.judged && said(&r).contains("the slip is unknown"),
        "{}",
        said(&r)
    );
    assert!(r.largest_possible_db.is_some_and(|x| x < -54.0), "{r:?}");
    assert_eq!(r.confidence, None);
    // No speed and broken bars: the slip from the sideband pair, the level and band read;
    // a pair taken for the rotor's by assumption stays a finding below one half.
    let rows = record("3hp", 1.0, 1.0, 4.0, 2000.0, false);
    let r = diagnose(&p, &rows, false, false).rotor;
    assert_eq!(r.slip_source, Some(SlipSource::Sidebands), "{}", said(&r));
    assert!(
        (r.slip.unwrap() - slip_of(&p, &rows)).abs() < 0.002,
        "{}",
        said(&r)
    );
    assert_eq!(r.band, Some(RotorBand::SeveralBrokenBars), "{}", said(&r));
    assert!(r.confidence.unwrap() < 0.5, "{}", said(&r));
}

/// A record of `which` at 70 % of its rated torque with `broken` bars, the load stepping to
/// the rated torque `step_at_s` into the record; voltages, currents, speed at 5 kHz.
fn record_with_step(which: &str, broken: f64, record_s: f64, step_at_s: f64) -> Vec<Row> {
    let (p, rated, settle) = motor(which);
    let start = settle + 1.5;
    let mut s = Scenario::steady(start + record_s, 5000.0);
    s.sensors = SensorSpec::default();
    let step = |t_s: f64, nm: f64| LoadStep {
        t_s,
        torque_nm: Some(nm),
        bl_scale: None,
    };
    s.load = LoadSpec {
        kind: LoadKind::Torque,
        torque_nm: Some(0.0),
        bl_nms: None,
        steps: vec![step(settle, 0.7 * rated), step(start + step_at_s, rated)],
    };
    if broken > 0.0 {
        s.effects = vec![EffectSpec::RotorAsymmetry {
            delta: None,
            broken_bars: Some(broken),
            bars: Some(f64::from(BARS)),
        }];
    }
    let rows = simulate_to_vec(&p, &s).expect("simulated"); // ok: test
    let keep = (record_s * 5000.0).round() as usize;
    rows[rows.len() - keep..].to_vec()
}

#[test]
fn the_lamps_are_evaluated_on_a_steady_broken_bar_record_and_a_load_step_still_holds_them() {
    // The core's quasi-steady gate closes on the d-q quantities' filtered derivatives; a
    // broken bar's 2 s f torque ripple moves them as a transient would, and held the gate
    // closed until its 5 s timeout (a shorter record: "the lamps were never evaluated").
    // The ripple rule opens it once the operating point's slow trend has been steady
    // (`monitor_core::MonitorConfig::steady_gate_per_s`). A load step (70 % to 100 %)
    // still closes it, with a broken cage and without.
    let mut failures = Vec::new();
    for (which, broken) in [("3hp", 1.0), ("3hp", 2.0), ("2p2kw", 1.0), ("2p2kw", 0.0)] {
        let (p, _, _) = motor(which);
        let rep = diagnose(
            &p,
            &record(which, 1.0, broken, 5.0, 5000.0, true),
            true,
            true,
        );
        let first = rep.timeline.iter().find(|t| t.evaluating).map(|t| t.t_s);
        let never = rep
            .findings
            .iter()
            .any(|f| f.detail == monitor_replay::Detail::ResidualsNeverEvaluated);
        eprintln!("{which} {broken} bars: first evaluated at {first:?} s of a 5 s record");
        if first.is_none_or(|t| t > 3.5) || never {
            failures.push(format!(
                "{which} {broken} bars: first evaluated at {first:?}"
            ));
        }
        let rep = diagnose(&p, &record_with_step(which, broken, 7.0, 4.5), true, true);
        let held = rep
            .timeline
            .iter()
            .filter(|t| t.t_s > 4.5 && t.t_s < 5.5)
            .any(|t| !t.quasi_steady);
        let after = rep.timeline.iter().any(|t| t.t_s > 5.5 && t.evaluating);
        if !held || !after {
            failures.push(format!("{which} {broken} bars, load step at 4.5 s: gate closed after it {held}, evaluated again {after}"));
        }
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

#[test]
fn real_recordings_of_a_healthy_cage_give_no_rotor_fault() {
    // The 26 ITSC recordings (examples/recordings/itsc: a 0.75 hp motor at no load, its
    // cage healthy, shorted turns in 24 of them; currents only, 1 kHz, 5 s). No speed: the
    // slip only from a pair about the line, which here is the bench's own modulation (the
    // short switched on and off, the supply), never a rotor fault at >= 0.5.
    let folder =
        std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples/recordings/itsc");
    let (params, columns) =
        monitor_io::log::mapping::load_params(&folder.join("baldor_0p75hp.toml"))
            .expect("parameter file"); // ok: test
    let mut names: Vec<std::path::PathBuf> = std::fs::read_dir(&folder)
        .expect("the recordings") // ok: test
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| p.extension().is_some_and(|x| x == "csv"))
        .collect();
    names.sort();
    assert_eq!(names.len(), 26);
    let mut failures = Vec::new();
    for path in names {
        let open = monitor_io::log::OpenOptions {
            group: None,
            columns: columns.clone(),
        };
        let file = monitor_io::log::LogFile::open_with(&path, &open).expect("recording"); // ok: test
        let rep =
            monitor_replay::diagnose_log(&params, &file, ReplayOptions::default(), &mut |_| {})
                .expect("diagnose") // ok: test
                .report;
        let r = rep.rotor;
        eprintln!("{}: {}", path.display(), said(&r));
        if r.confidence.is_some_and(|c| c >= 0.5) {
            failures.push(format!("{}: {}", path.display(), said(&r)));
        }
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

/// The rotor's one sentence, as the door spells it for a crew.
fn said(r: &monitor_replay::RotorReport) -> String {
    monitor_words::diagnose::Story::rotor_sentence(r)
}
