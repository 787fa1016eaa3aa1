//! The negative-sequence analysis names the faulty phase: a phase-asymmetry (shorted
//! turns) run on each of the three phases, at no load and at full load, for the two
//! reference motors. The analysis only sees the sensor rows; it is not told the phase.

use monitor_core::AngleSource;
use monitor_core::Phase;
use monitor_io::params::ParamFile;
use monitor_replay::{diagnose_rows, BaselineSource, ReplayOptions};
use monitor_sim::{simulate_to_vec, EffectSpec, LoadKind, LoadSpec, Scenario, SensorSpec};
use rayon::prelude::*;

fn run(
    params: &ParamFile,
    load_nm: f64,
    phase: Phase,
    fraction: f64,
) -> (Option<String>, f32, Option<monitor_replay::PhaseNotJudged>) {
    let mut sc = Scenario::steady(4.0, 10_000.0);
    sc.sensors = SensorSpec::default();
    sc.load = LoadSpec {
        kind: LoadKind::Torque,
        torque_nm: Some(load_nm),
        bl_nms: None,
        steps: vec![],
    };
    sc.effects.push(EffectSpec::PhaseAsymmetry {
        phase,
        fraction,
        fault_resistance_ohm: None,
    });
    let rows = simulate_to_vec(params, &sc).expect("simulate");
    let opts = ReplayOptions {
        angle_source: AngleSource::RotorFluxCurrentModel,
        ..ReplayOptions::default()
    };
    let rep = diagnose_rows(params, sc.sensors.channels(), &rows, opts).expect("replay");
    (
        rep.unbalance.suspect_phase.map(|p| p.name().to_string()),
        rep.unbalance.negative_sequence_ratio,
        rep.unbalance.phase_not_judged,
    )
}

#[test]
fn suspect_phase_is_the_shorted_phase_for_two_motors_and_two_loads() {
    // Without a healthy baseline: the phase right whenever the winding's part stands clear
    // of a healthy machine's own asymmetry (3 %), "cannot judge the phase" below it, never a
    // wrong phase. Rated torques: 3 hp 220 V 60 Hz 4-pole at ~1710 rpm: 2238 W / 179 rad/s =
    // 12.5 N m; 2.2 kW at ~1430 rpm: 14.6 N m (the reference scenario).
    let motors = [
        (ParamFile::reference_3hp(), 12.5),
        (ParamFile::reference_2p2kw(), 14.6),
    ];
    let mut cases = Vec::new();
    for (m, rated) in &motors {
        for load in [0.0, *rated] {
            for (phase, name) in [(Phase::A, "a"), (Phase::B, "b"), (Phase::C, "c")] {
                // 5 % and 2 % of the phase's turns shorted (through Rs/10).
                for fraction in [0.05, 0.02] {
                    cases.push((*m, load, phase, name, fraction));
                }
            }
        }
    }
    let results: Vec<_> = cases
        .par_iter()
        .map(|(m, load, phase, name, fraction)| {
            let (got, ratio, not_judged) = run(m, *load, *phase, *fraction);
            (m.supply.f_hz, *load, *name, got, ratio, not_judged)
        })
        .collect();
    let (mut named, mut failures) = (0, Vec::new());
    for (f, load, name, got, ratio, not_judged) in &results {
        eprintln!("{f} Hz motor, load {load} N m, shorted phase {name}: suspect {got:?}, |I2|/|I1| = {ratio:.4}, {not_judged:?}");
        match got {
            Some(g) if g == name => named += 1,
            Some(g) => failures.push(format!("{f} Hz, load {load}: {name} named {g}")),
            None if *ratio >= 0.035 || not_judged.is_none() => failures.push(format!(
                "{f} Hz, load {load}, {name}: none at {ratio} without a reason"
            )),
            None => {}
        }
    }
    assert!(failures.is_empty(), "{failures:#?}");
    // The 5 % shorts stand clear of 3 % everywhere, the 2 % ones on the 3 hp machine.
    assert!(named >= 18, "{named} of 24 named");
}

#[test]
fn balanced_machine_names_no_phase() {
    let p = ParamFile::reference_3hp();
    let mut sc = Scenario::steady(3.0, 10_000.0);
    sc.sensors = SensorSpec::default();
    let rows = simulate_to_vec(&p, &sc).expect("simulate");
    let rep =
        diagnose_rows(&p, sc.sensors.channels(), &rows, ReplayOptions::default()).expect("replay");
    assert_eq!(rep.unbalance.suspect_phase, None, "{:?}", rep.unbalance);
    assert!(rep.unbalance.negative_sequence_ratio < 0.005);
}

#[test]
fn diagnose_and_the_analysis_name_the_same_phase() {
    // One faulty-phase method for the whole workspace: the monitor (diagnose) and the
    // model-vs-measurement analysis (compare/explain) agree on the same log.
    use monitor_analysis::{prep::ReadOptions, Analysis};
    use monitor_io::log::Log;
    let dir = tempfile::tempdir().unwrap();
    let p = ParamFile::reference_2p2kw();
    for (phase, name) in [(Phase::B, "b"), (Phase::C, "c")] {
        let mut sc = Scenario::steady(4.0, 10_000.0);
        sc.sensors = SensorSpec::default();
        sc.load = LoadSpec {
            kind: LoadKind::Torque,
            torque_nm: Some(14.6),
            bl_nms: None,
            steps: vec![],
        };
        sc.effects.push(EffectSpec::PhaseAsymmetry {
            phase,
            fraction: 0.05,
            fault_resistance_ohm: None,
        });
        let rows = simulate_to_vec(&p, &sc).expect("simulate");
        let rep = diagnose_rows(&p, sc.sensors.channels(), &rows, ReplayOptions::default())
            .expect("replay");
        let path = dir.path().join(format!("{name}.csv"));
        Log {
            channels: sc.sensors.channels(),
            rows,
        }
        .write(&path)
        .expect("write");
        let opts = ReadOptions {
            from_s: 1.5,
            to_s: f64::INFINITY,
        };
        let a = Analysis::load(&path, p, opts, &mut |_| {}).expect("analysis");
        let u = a.unbalance();
        assert_eq!(rep.unbalance.suspect_phase.map(Phase::name), Some(name));
        assert_eq!(u.suspect_phase.as_deref(), Some(name), "{:?}", u.finding);
    }
}

/// A run on a supply with its own negative sequence (`unbalance` of the positive
/// sequence at `angle_deg`), with shorted turns in `short` (phase, fraction) or none.
fn run_unbalanced(
    params: &ParamFile,
    load_nm: f64,
    unbalance: f64,
    angle_deg: f64,
    short: Option<(Phase, f64)>,
) -> monitor_replay::UnbalanceReport {
    let mut sc = Scenario::steady(4.0, 10_000.0);
    sc.seed = 17 + (1000.0 * unbalance + angle_deg) as u64;
    sc.sensors = SensorSpec::default();
    sc.load = LoadSpec {
        kind: LoadKind::Torque,
        torque_nm: Some(load_nm),
        bl_nms: None,
        steps: vec![],
    };
    sc.effects.push(EffectSpec::SupplyUnbalance {
        fraction: unbalance,
        angle_deg,
    });
    if let Some((phase, fraction)) = short {
        sc.effects.push(EffectSpec::PhaseAsymmetry {
            phase,
            fraction,
            fault_resistance_ohm: None,
        });
    }
    let rows = simulate_to_vec(params, &sc).expect("simulate");
    diagnose_rows(
        params,
        sc.sensors.channels(),
        &rows,
        ReplayOptions::default(),
    )
    .expect("replay")
    .unbalance
}

#[test]
fn on_an_unbalanced_supply_the_shorted_phase_is_named_and_a_healthy_motor_gets_none() {
    // 1-3 % supply unbalance at several angles; 2-10 % of a phase's turns shorted (through
    // Rs/10); no load and rated load; both reference motors; voltages logged (10 kHz), no
    // baseline. The supply's part V2/Z2 is taken out before the phase is named.
    let motors = [
        (ParamFile::reference_3hp(), 12.5),
        (ParamFile::reference_2p2kw(), 14.6),
    ];
    let mut cases = Vec::new();
    let mut k = 0usize;
    for (m, rated) in &motors {
        for load in [0.0, *rated] {
            for (phase, name) in [(Phase::A, "a"), (Phase::B, "b"), (Phase::C, "c")] {
                for fraction in [0.02, 0.05, 0.10] {
                    let unb = [0.01, 0.02, 0.03][k % 3];
                    let ang = [0.0, 135.0, 250.0, 60.0][k % 4];
                    k += 1;
                    cases.push((*m, load, unb, ang, Some((phase, fraction)), Some(name)));
                }
            }
            for (unb, ang) in [(0.01, 30.0), (0.02, 200.0), (0.03, 300.0)] {
                cases.push((*m, load, unb, ang, None, None));
            }
        }
    }
    let results: Vec<_> = cases
        .par_iter()
        .map(|(m, load, unb, ang, short, want)| {
            let u = run_unbalanced(m, *load, *unb, *ang, *short);
            (m.supply.f_hz, *load, *unb, *ang, *short, *want, u)
        })
        .collect();
    let (mut right, mut shorted, mut failures) = (0, 0, Vec::new());
    for (f, load, unb, ang, short, want, u) in &results {
        let tag = format!("{f} Hz motor, load {load}, supply {unb} at {ang} deg, short {short:?}");
        eprintln!(
            "{tag}: suspect {:?}, winding {:.4}, supply part {:.4}",
            u.suspect_phase, u.winding_ratio, u.supply_ratio
        );
        match want {
            Some(name) => {
                shorted += 1;
                if u.suspect_phase.map(Phase::name) == Some(*name) {
                    right += 1;
                } else if u.suspect_phase.is_some() {
                    failures.push(format!("{tag}: wrong phase {:?}", u.suspect_phase));
                }
            }
            None if u.suspect_phase.is_some() => {
                failures.push(format!("{tag}: healthy motor got {:?}", u.suspect_phase))
            }
            None => {}
        }
    }
    // Without a baseline the small shorts are not judged (below a healthy machine's own
    // asymmetry; `turn_fault.rs` judges them against a healthy recording): at least three
    // in four right, and a wrong phase is never named.
    assert!(4 * right >= 3 * shorted, "{right} of {shorted} right");
    assert!(failures.is_empty(), "{failures:#?}");
}

/// A log with a mismatch of two current sensors (a +1.2 %, b -1 %: no single phase to
/// blame) on a 0.5 % unbalanced supply, with `fraction` of phase `shorted`'s turns shorted.
fn mismatched(
    params: &ParamFile,
    shorted: Option<(Phase, f64)>,
    seed: u64,
) -> Vec<monitor_io::log::Row> {
    let mut sc = Scenario::steady(6.0, 5_000.0);
    sc.seed = seed;
    sc.sensors = SensorSpec::default();
    for (phase, change) in [(Phase::A, 0.012), (Phase::B, -0.01)] {
        let mut f =
            monitor_sim::FaultSpec::sensor_gain(monitor_core::Fault::CurrentSensor, 0.0, change);
        f.phase = Some(phase);
        sc.faults.push(f);
    }
    sc.effects.push(EffectSpec::SupplyUnbalance {
        fraction: 0.005,
        angle_deg: 30.0,
    });
    if let Some((phase, fraction)) = shorted {
        sc.effects.push(EffectSpec::PhaseAsymmetry {
            phase,
            fraction,
            fault_resistance_ohm: None,
        });
    }
    simulate_to_vec(params, &sc).expect("simulate") // ok: test
}

/// The winding judged against the healthy machine's own negative sequence (issue 9): a
/// sensor mismatch that, on its own, makes the supply-corrected analysis blame a winding
/// of a healthy motor is taken out by the commissioning window's baseline or by a healthy
/// log (`diagnose --baseline`); the shorted phase is still named against that baseline.
#[test]
fn a_healthy_baseline_takes_the_motors_own_asymmetry_out() {
    let mut failures = Vec::new();
    let mut blamed_without = 0;
    for params in [ParamFile::reference_2p2kw(), ParamFile::reference_3hp()] {
        let channels = SensorSpec::default().channels();
        let replay = |rows: &[monitor_io::log::Row], opts: ReplayOptions| {
            diagnose_rows(&params, channels, rows, opts).expect("replay") // ok: test
        };
        let healthy = mismatched(&params, None, 11);
        let bare = replay(&healthy, ReplayOptions::default());
        blamed_without += usize::from(bare.unbalance.suspect_phase.is_some());
        let commissioned = replay(
            &healthy,
            ReplayOptions {
                commission: Some(monitor_replay::CommissionWindow::of(2.0, 4.0)),
                ..ReplayOptions::default()
            },
        );
        if commissioned.unbalance.suspect_phase.is_some()
            || commissioned.unbalance.baseline != Some(BaselineSource::Commissioning)
        {
            failures.push(format!(
                "{} Hz healthy, commissioned: {:?}",
                params.supply.f_hz, commissioned.unbalance
            ));
        }
        let with_file = ReplayOptions {
            unbalance_baseline: Some(bare.unbalance.measured.into()),
            ..ReplayOptions::default()
        };
        // The healthy motor on another day (another noise seed) against its baseline.
        let again = replay(&mismatched(&params, None, 12), with_file);
        if again.unbalance.suspect_phase.is_some() {
            failures.push(format!(
                "{} Hz healthy again: {:?}",
                params.supply.f_hz, again.unbalance
            ));
        }
        for phase in Phase::ALL {
            let rep = replay(&mismatched(&params, Some((phase, 0.03)), 13), with_file);
            if rep.unbalance.suspect_phase.map(Phase::name) != Some(phase.name())
                || rep.unbalance.baseline != Some(BaselineSource::File)
            {
                failures.push(format!(
                    "{} Hz, 3 % shorted in {}: {:?}",
                    params.supply.f_hz,
                    phase.name(),
                    rep.unbalance
                ));
            }
        }
    }
    assert!(failures.is_empty(), "{failures:#?}");
    // The premise: without a baseline the mismatch alone is blamed on a winding.
    eprintln!("healthy motors blamed without a baseline: {blamed_without} of 2");
}

/// Samples dropped at random (0.1 %, as a DAQ under load does) do not make an unbalance:
/// the sequence analysis fills the missing instants (before, every dropped sample left an
/// error of its 2f image: the voltages read 0.15 % unbalanced and a winding was named).
#[test]
fn dropped_samples_name_no_winding() {
    for params in [ParamFile::reference_2p2kw(), ParamFile::reference_3hp()] {
        let mut sc = Scenario::steady(6.0, 5_000.0);
        sc.sensors = SensorSpec::default();
        let rows = simulate_to_vec(&params, &sc).expect("simulate"); // ok: test
                                                                     // Every 997th row dropped (0.1 %), and one run of 20 rows.
        let dropped: Vec<_> = rows
            .iter()
            .enumerate()
            .filter(|(k, _)| k % 997 != 500 && !(20_000..20_020).contains(k))
            .map(|(_, r)| *r)
            .collect();
        let channels = sc.sensors.channels();
        let clean =
            diagnose_rows(&params, channels, &rows, ReplayOptions::default()).expect("replay"); // ok: test
        let holes =
            diagnose_rows(&params, channels, &dropped, ReplayOptions::default()).expect("replay"); // ok: test
        let (c, h) = (&clean.unbalance, &holes.unbalance);
        assert_eq!(h.suspect_phase, None, "{h:?}");
        let (vc, vh) = (
            c.voltage_negative_sequence_ratio.unwrap_or(1.0),
            h.voltage_negative_sequence_ratio.unwrap_or(1.0),
        );
        assert!((vh - vc).abs() < 2e-4, "V2/V1 {vc} clean, {vh} with holes");
    }
}
