//! The winding finding on simulated logs the verdict has to get right (issue "One verdict
//! from all the evidence", the winding in the verdict):
//!
//! - a short switched on mid-log whose fault current wobbles (as the real recordings'
//!   does) is judged on its own stretch, without any baseline;
//! - a healthy log against a healthy baseline at another load (the speed a few rad/s
//!   apart) names no phase at 0.5 or more, and the report says the least change was
//!   widened;
//! - broken rotor bars (1 and 2 of 28, two loads, a healthy baseline at another load)
//!   name no phase at 0.5 or more: a rotor asymmetry modulates the current at `2 s f`, it
//!   puts no supply-frequency negative sequence into the windings.
//!
//! The logs are written by the simulator (Tallam's shorted loop, `phase_asymmetry`; the
//! broken-bar cage, `rotor_asymmetry`); the parameter file handed to `diagnose` is 10-20 %
//! off the simulated machine where it matters (as a file from a nameplate is), so that the
//! model's negative-sequence impedance leaves a part of the supply's unbalance in the
//! reading that moves with the load.

use monitor_core::Phase;
use monitor_io::log::Row;
use monitor_io::params::ParamFile;
use monitor_replay::{diagnose_rows, Against, HealthyReference, ReplayOptions, UnbalanceReport};
use monitor_sim::{
    simulate_to_vec, EffectSpec, FaultSpec, LoadKind, LoadSpec, Scenario, SensorSpec,
};

/// Run-up left out of every simulated log [s].
const SETTLE_S: f64 = 1.5;

/// What a simulated log is made of.
struct Run {
    load_nm: f64,
    effects: Vec<EffectSpec>,
    sensors: SensorSpec,
    /// Gain errors of the current sensors of phases a and b.
    gains: [f64; 2],
    rate_hz: f64,
    duration_s: f64,
    seed: u64,
}

/// A simulated log from `SETTLE_S` on, its time shifted to start at 0, on a supply
/// unbalanced by 1 % at 30 deg.
fn log(p: &ParamFile, run: &Run) -> Vec<Row> {
    let mut sc = Scenario::steady(SETTLE_S + run.duration_s, run.rate_hz);
    sc.seed = run.seed;
    sc.sensors = run.sensors.clone();
    let load_nm = run.load_nm;
    sc.load = LoadSpec {
        kind: LoadKind::Torque,
        torque_nm: Some(0.0),
        bl_nms: None,
        steps: vec![monitor_sim::LoadStep {
            t_s: 0.3,
            torque_nm: Some(load_nm),
            bl_scale: None,
        }],
    };
    sc.effects = run.effects.clone();
    for (phase, g) in [Phase::A, Phase::B].into_iter().zip(run.gains) {
        if g != 0.0 {
            let mut f = FaultSpec::sensor_gain(monitor_core::Fault::CurrentSensor, 0.0, g);
            f.phase = Some(phase);
            sc.faults.push(f);
        }
    }
    sc.effects.push(EffectSpec::SupplyUnbalance {
        fraction: 0.01,
        angle_deg: 30.0,
    });
    simulate_to_vec(p, &sc)
        .expect("simulate") // ok: test
        .into_iter()
        .filter(|r| r.t_s >= SETTLE_S)
        .map(|r| Row {
            t_s: r.t_s - SETTLE_S,
            ..r
        })
        .collect()
}

fn judge(
    p: &ParamFile,
    sensors: &SensorSpec,
    rows: &[Row],
    base: &[&UnbalanceReport],
) -> UnbalanceReport {
    let runs: Vec<_> = base.iter().map(|b| b.measured).collect();
    let opts = ReplayOptions {
        unbalance_baseline: HealthyReference::from_runs(&runs),
        ..ReplayOptions::default()
    };
    diagnose_rows(p, sensors.channels(), rows, opts)
        .expect("diagnose") // ok: test
        .unbalance
}

/// The parameter file as a nameplate gives it: the rotor resistance 20 % high and the
/// leakages 15 % low (the simulated machine is `p`).
fn nameplate_off(p: &ParamFile) -> ParamFile {
    let mut q = *p;
    let m = &mut q.motor;
    m.rr_ohm *= 1.2;
    let (lls, llr) = (m.ls_h - m.lm_h, m.lr_h - m.lm_h);
    m.ls_h = m.lm_h + 0.85 * lls;
    m.lr_h = m.lm_h + 0.85 * llr;
    q
}

fn currents_only() -> SensorSpec {
    SensorSpec {
        voltages: false,
        speed: false,
        encoder: false,
        ..SensorSpec::default()
    }
}

fn all_channels() -> SensorSpec {
    SensorSpec {
        voltages: true,
        speed: true,
        encoder: false,
        ..SensorSpec::default()
    }
}

/// `|I2|/|I1|` of rows over whole supply periods, by least squares at the supply
/// frequency `f` (a second opinion on where the short is on, written here).
fn ratio_of(rows: &[Row], f: f64) -> f64 {
    use std::f64::consts::TAU;
    let mut ph = [(0.0f64, 0.0f64); 3];
    for r in rows {
        let (s, c) = (TAU * f * r.t_s).sin_cos();
        for (k, x) in r.i_abc.iter().enumerate() {
            ph[k].0 += x * c;
            ph[k].1 -= x * s;
        }
    }
    let a = |k: f64| (TAU / 3.0 * k).sin_cos();
    let seq = |sign: f64| {
        let (mut re, mut im) = (0.0, 0.0);
        for (k, p) in ph.iter().enumerate() {
            let (s, c) = a(sign * k as f64);
            re += p.0 * c - p.1 * s;
            im += p.0 * s + p.1 * c;
        }
        re.hypot(im)
    };
    seq(-1.0) / seq(1.0)
}

#[test]
fn a_short_switched_on_mid_log_with_a_wobbling_current_is_judged_on_its_stretch() {
    // The 3 hp motor at no load, currents only at 1 kHz, 5 s, its current sensors 3 %
    // apart (a zero sequence, as the real recordings' transformers leave). 10 % of phase
    // b's turns shorted from 1.8 s through a resistance that moves every 0.25 s between
    // 0.2 and 0.35 Rs: I2/I1 wobbles between about 27 and 36 %.
    let p = ParamFile::reference_3hp();
    let sensors = currents_only();
    let run = |effects: Vec<EffectSpec>| Run {
        load_nm: 0.0,
        effects,
        sensors: sensors.clone(),
        gains: [0.03, -0.01],
        rate_hz: 1000.0,
        duration_s: 5.0,
        seed: 7,
    };
    let healthy = log(&p, &run(vec![]));
    let rf: [f64; 13] = [
        0.3, 0.2, 0.35, 0.25, 0.3, 0.2, 0.35, 0.25, 0.2, 0.3, 0.35, 0.25, 0.3,
    ];
    let faulty: Vec<Vec<Row>> = [0.2, 0.25, 0.3, 0.35]
        .iter()
        .map(|&k| {
            let short = EffectSpec::PhaseAsymmetry {
                phase: Phase::B,
                fraction: 0.1,
                fault_resistance_ohm: Some(k * p.motor.rs_ohm),
            };
            log(&p, &run(vec![short]))
        })
        .collect();
    let on_s = 1.8;
    let rows: Vec<Row> = healthy
        .iter()
        .enumerate()
        .map(|(n, h)| {
            if h.t_s < on_s {
                return *h;
            }
            let slot = ((h.t_s - on_s) / 0.25) as usize;
            let k = rf[slot % rf.len()];
            let which = ((k - 0.2) / 0.05).round() as usize;
            faulty[which][n]
        })
        .collect();
    let fault_part: Vec<Row> = rows.iter().filter(|r| r.t_s >= on_s).copied().collect();
    let seen = ratio_of(&fault_part, p.supply.f_hz);
    assert!(seen > 0.2 && seen < 0.4, "the short's stretch reads {seen}");
    let u = judge(&p, &sensors, &rows, &[]);
    let judged = u
        .judged_segment
        .and_then(|k| u.segments.get(k))
        .expect("a judged stretch"); // ok: test
    eprintln!("{u:#?}");
    assert_eq!(u.suspect_phase, Some(Phase::B), "{u:?}");
    assert!(u.phase_confidence >= 0.5, "{u:?}");
    // The stretch the short is on, not the healthy one before it, nor a piece of it.
    assert!(
        (judged.from_s - on_s).abs() < 0.4 && judged.to_s - judged.from_s > 2.5,
        "judged {:.2}..{:.2} s",
        judged.from_s,
        judged.to_s
    );
    assert_eq!(u.judged_against, Some(Against::WithinTheLog), "{u:?}");
}

/// The 2.2 kW reference motor at `load` of its rated 14.6 N m, with `effects`, `sensors`
/// at `rate_hz`, 3 s.
fn motor_2p2kw(
    load: f64,
    effects: Vec<EffectSpec>,
    sensors: &SensorSpec,
    rate_hz: f64,
    seed: u64,
) -> Vec<Row> {
    let p = ParamFile::reference_2p2kw();
    log(
        &p,
        &Run {
            load_nm: load * 14.6,
            effects,
            sensors: sensors.clone(),
            gains: [0.0; 2],
            rate_hz,
            duration_s: 3.0,
            seed,
        },
    )
}

/// Mean shaft speed of a log [rad/s] (its speed column).
fn speed(rows: &[Row]) -> f64 {
    rows.iter().filter_map(|r| r.wm_rad_s).sum::<f64>() / rows.len().max(1) as f64
}

#[test]
fn a_healthy_baseline_at_another_load_names_no_phase_and_says_the_least_change_widened() {
    // A healthy 2.2 kW motor at 60 % load judged against a healthy run of it at full load
    // (the speed some rad/s apart), with voltages and speed at 5 kHz, and with the
    // currents alone at 1 kHz; the parameter file 10-20 % off the machine.
    let file = nameplate_off(&ParamFile::reference_2p2kw());
    for (sensors, rate, what) in [
        (all_channels(), 5000.0, "voltages and speed"),
        (currents_only(), 1000.0, "currents only"),
    ] {
        let base = motor_2p2kw(1.0, vec![], &sensors, rate, 11);
        let rows = motor_2p2kw(0.6, vec![], &sensors, rate, 12);
        if sensors.speed {
            let apart = speed(&rows) - speed(&base);
            assert!(apart > 1.5 && apart < 6.0, "{what}: {apart} rad/s apart");
        }
        let reference = judge(&file, &sensors, &base, &[]);
        let u = judge(&file, &sensors, &rows, &[&reference]);
        eprintln!(
            "{what}: {:?} at {:.2}, change {:.2} %, least change {:.2} %; {:?}",
            u.suspect_phase,
            u.phase_confidence,
            100.0 * u.winding_ratio,
            100.0 * u.least_change,
            u.least_change_widened
        );
        assert!(!u.names_a_short(), "{what}: {u:?}");
        // Another operating point (the load moved |I1|, and the speed where it was logged),
        // and the least change widened for it.
        let widened = u.least_change_widened.expect("widened"); // ok: test
        assert!(
            widened.i1_change.is_some_and(|d| d.abs() > 0.05),
            "{what}: {widened:?}"
        );
        if sensors.speed {
            assert!(
                widened.speed_change_rad_s.is_some_and(|d| d.abs() > 1.0),
                "{what}: {widened:?}"
            );
        }
        assert_eq!(u.judged_against, Some(Against::HealthyRuns));
    }
}

#[test]
fn broken_bars_name_no_winding() {
    // 1 and 2 broken bars of 28 at half and full load (a 2 s f modulation of the window
    // phasors, no supply-frequency negative sequence of the stator), against a healthy run
    // at 75 % load and against nothing; voltages and speed at 5 kHz, and the currents
    // alone at 1 kHz.
    let file = nameplate_off(&ParamFile::reference_2p2kw());
    let mut named = Vec::new();
    for (sensors, rate) in [(all_channels(), 5000.0), (currents_only(), 1000.0)] {
        let base = motor_2p2kw(0.75, vec![], &sensors, rate, 21);
        let reference = judge(&file, &sensors, &base, &[]);
        for bars in [1.0, 2.0] {
            for load in [0.5, 1.0] {
                let cage = EffectSpec::RotorAsymmetry {
                    delta: None,
                    broken_bars: Some(bars),
                    bars: Some(28.0),
                };
                let rows = motor_2p2kw(load, vec![cage], &sensors, rate, 22);
                for against in [vec![&reference], vec![]] {
                    let u = judge(&file, &sensors, &rows, &against);
                    eprintln!(
                        "{rate} Hz, {bars} bars, load {load}, {} baseline: {:?} at {:.2} (no short {:.2}), change {:.2} %, least change {:.2} %, {} stretches",
                        against.len(),
                        u.suspect_phase,
                        u.phase_confidence,
                        u.phase_probabilities.no_short,
                        100.0 * u.winding_ratio,
                        100.0 * u.least_change,
                        u.segments.len()
                    );
                    if u.names_a_short() {
                        named.push(format!("{rate} Hz, {bars} bars at {load}: {u:?}"));
                    }
                }
            }
        }
    }
    assert!(named.is_empty(), "{named:#?}");
}
