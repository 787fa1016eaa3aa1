//! Shorted turns as they are: the simulator's turn-fault loop (Tallam, Habetler, Harley,
//! IEEE Trans. Ind. Appl. 38(3), 2002) against a phasor solution written here, and the
//! faulty phase named from the negative-sequence change on three motors, no load and full
//! load, 1-3 % supply unbalance: currents only at 1 kHz against a healthy recording, and
//! 10 kHz with voltages. A healthy recording against another names no phase, nor does a
//! 1 % gain mismatch of two current sensors.

use monitor_core::Phase;
use monitor_io::params::ParamFile;
use monitor_replay::{diagnose_rows, HealthyReference, ReplayOptions, UnbalanceReport};
use monitor_sim::{
    simulate_to_vec, simulate_with_truth, EffectSpec, LoadKind, LoadSpec, Scenario, SensorSpec,
};
use rayon::prelude::*;
use std::f64::consts::{PI, TAU};

/// A made-up 11 kW, 400 V, 50 Hz, 4-pole machine with textbook per-unit values (the
/// workspace's reference motors are 2.2 kW and 3 hp; the method was not tuned on this one).
fn motor_11kw() -> ParamFile {
    ParamFile::from_toml_str(
        "[motor]\nrs_ohm = 0.38\nrr_ohm = 0.35\nls_h = 0.0935\nlr_h = 0.0935\nlm_h = 0.09\npoles = 4\nj_kgm2 = 0.09\nb_nms = 0.01\nbl_nms = 0.45\n[supply]\nv_ll_rms = 400.0\nf_hz = 50.0\n",
        "11 kW test machine",
    )
    .expect("11 kW parameters") // ok: test
}

/// The three motors with their rated torque [N m].
fn motors() -> [(ParamFile, f64, &'static str); 3] {
    [
        (ParamFile::reference_3hp(), 12.5, "3 hp"),
        (ParamFile::reference_2p2kw(), 14.6, "2.2 kW"),
        (motor_11kw(), 72.0, "11 kW"),
    ]
}

type C = num_complex::Complex64;

/// The T-equivalent circuit's impedance per phase at slip `s` (textbook).
fn z_t(p: &ParamFile, we: f64, s: f64) -> C {
    let m = &p.motor;
    let (lls, llr) = (m.ls_h - m.lm_h, m.lr_h - m.lm_h);
    let zm = C::new(0.0, we * m.lm_h);
    let zr = C::new(m.rr_ohm / s, we * llr);
    C::new(m.rs_ohm, we * lls) + zm * zr / (zm + zr)
}

/// The symmetrical components I1, I2 (phase peak, complex) of the last `periods` supply
/// periods of three phase currents sampled at `dt`.
fn sequences(i_abc: &[[f64; 3]], dt: f64, f: f64, periods: f64) -> (C, C) {
    let n = (periods / f / dt).round() as usize;
    let rows = &i_abc[i_abc.len() - n..];
    let t0 = (i_abc.len() - n) as f64 * dt;
    let mut ph = [C::new(0.0, 0.0); 3];
    for (k, r) in rows.iter().enumerate() {
        let th = TAU * f * (t0 + k as f64 * dt);
        for j in 0..3 {
            ph[j] += C::from_polar(2.0 * r[j] / n as f64, -th);
        }
    }
    let a = C::from_polar(1.0, TAU / 3.0);
    let i1 = (ph[0] + a * ph[1] + a * a * ph[2]) / 3.0;
    let i2 = (ph[0] + a * a * ph[1] + a * ph[2]) / 3.0;
    (i1, i2)
}

#[test]
fn the_simulated_turn_fault_draws_the_negative_sequence_of_its_phasor_solution() {
    // With V_k = V1 a^-k the loop draws I_f = V_k / Z_f, Z_f = Rs (1 - 2mu/3) + r_f/mu +
    // j we mu Lls/3, whose sequences add (mu/3) I_f a^k... to the machine's V1/Z1:
    // I2/I1 = r a^k / (1 + r), r = (mu/3) Z1/Z_f, Z1 at the run's own slip. Magnitude within
    // 3 %, angle within 2 degrees, every phase.
    let mut failures = Vec::new();
    for (p, rated, name) in motors() {
        for (k, phase) in Phase::ALL.into_iter().enumerate() {
            let (mu, rf) = ([0.03, 0.06, 0.1][k], [0.5, 1.0, 2.0][k] * p.motor.rs_ohm);
            let mut sc = Scenario::steady(3.0, 10_000.0);
            sc.load = LoadSpec {
                kind: LoadKind::Torque,
                torque_nm: Some(0.5 * rated),
                bl_nms: None,
                steps: vec![],
            };
            sc.effects.push(EffectSpec::PhaseAsymmetry {
                phase,
                fraction: mu,
                fault_resistance_ohm: Some(rf),
            });
            let mut i = Vec::new();
            let mut w = Vec::new();
            simulate_with_truth(&p, &sc, |_, t| {
                i.push(t.i_abc);
                w.push(t.wm_rad_s);
            })
            .expect("simulate"); // ok: test
            let f = p.supply.f_hz;
            let we = TAU * f;
            let (i1, i2) = sequences(&i, 1e-4, f, 20.0);
            let wm = w.iter().rev().take(2000).sum::<f64>() / 2000.0;
            let np = f64::from(p.motor.poles) / 2.0;
            let s = 1.0 - np * wm / we;
            let lls = p.motor.ls_h - p.motor.lm_h;
            let rs = p.motor.rs_ohm;
            let zf = C::new(rs * (1.0 - 2.0 * mu / 3.0) + rf / mu, we * mu * lls / 3.0);
            let ak = C::from_polar(1.0, k as f64 * TAU / 3.0);
            // The loop's own positive sequence adds (mu/3) V1/Z_f to I1.
            let r0 = z_t(&p, we, s) / zf * (mu / 3.0);
            let want = r0 * ak / (1.0 + r0);
            let got = i2 / i1;
            let (mg, mw) = (got.norm(), want.norm());
            let dang = ((got.arg() - want.arg() + 3.0 * PI) % TAU - PI).to_degrees();
            eprintln!(
                "{name} phase {}: |I2/I1| {mg:.5} (phasor {mw:.5}), angle off {dang:.2} deg",
                phase.name()
            );
            if (mg / mw - 1.0).abs() > 0.03 || dang.abs() > 2.0 {
                failures.push(format!("{name} {}: {got} vs {want}", phase.name()));
            }
        }
    }
    assert!(failures.is_empty(), "{failures:#?}");
}

/// One recording: `load_nm`, a supply with `unbalance` of its positive sequence at
/// `angle_deg`, shorted turns `short` (phase, mu, r_f over Rs) or none, at `rate_hz`, with
/// or without the voltage columns, with the shaft measured (`shaft`) or not (a field
/// recording of currents).
struct Case {
    load_nm: f64,
    unbalance: f64,
    angle_deg: f64,
    short: Option<(Phase, f64, f64)>,
    rate_hz: f64,
    voltages: bool,
    seed: u64,
    /// Current-sensor gain errors of phases a, b (a mismatch between channels).
    gains: [f64; 2],
    /// A speed column and encoder counts (the board's inputs).
    shaft: bool,
}

fn record(p: &ParamFile, c: &Case) -> (Vec<monitor_io::log::Row>, SensorSpec) {
    let mut sc = Scenario::steady(4.0, c.rate_hz);
    sc.seed = c.seed;
    sc.sensors = SensorSpec {
        voltages: c.voltages,
        speed: c.shaft,
        encoder: c.shaft,
        ..SensorSpec::default()
    };
    // The motor runs up unloaded and takes its load at 0.3 s (a load from standstill
    // above the starting torque, the 11 kW machine's at rated load, leaves it stalled).
    sc.load = LoadSpec {
        kind: LoadKind::Torque,
        torque_nm: Some(0.0),
        bl_nms: None,
        steps: vec![monitor_sim::LoadStep {
            t_s: 0.3,
            torque_nm: Some(c.load_nm),
            bl_scale: None,
        }],
    };
    if c.unbalance > 0.0 {
        sc.effects.push(EffectSpec::SupplyUnbalance {
            fraction: c.unbalance,
            angle_deg: c.angle_deg,
        });
    }
    if let Some((phase, mu, rf_over_rs)) = c.short {
        sc.effects.push(EffectSpec::PhaseAsymmetry {
            phase,
            fraction: mu,
            fault_resistance_ohm: Some(rf_over_rs * p.motor.rs_ohm),
        });
    }
    for (phase, g) in [Phase::A, Phase::B].into_iter().zip(c.gains) {
        if g != 0.0 {
            let mut f =
                monitor_sim::FaultSpec::sensor_gain(monitor_core::Fault::CurrentSensor, 0.0, g);
            f.phase = Some(phase);
            sc.faults.push(f);
        }
    }
    let rows = simulate_to_vec(p, &sc).expect("simulate"); // ok: test
    (rows, sc.sensors)
}

/// The recording from 1.5 s on (past the run-up and the load's step), judged against the
/// healthy runs `baseline` (their mean and spread), or without one.
fn judge(p: &ParamFile, c: &Case, baseline: &[&UnbalanceReport]) -> UnbalanceReport {
    let (rows, sensors) = record(p, c);
    let rows: Vec<_> = rows.into_iter().filter(|r| r.t_s >= 1.5).collect();
    let runs: Vec<_> = baseline.iter().map(|b| b.measured).collect();
    let opts = ReplayOptions {
        unbalance_baseline: HealthyReference::from_runs(&runs),
        ..ReplayOptions::default()
    };
    diagnose_rows(p, sensors.channels(), &rows, opts)
        .expect("replay") // ok: test
        .unbalance
}

#[test]
fn the_shorted_phase_is_named_against_a_healthy_recording() {
    // 2-10 % of one phase's turns through 0.05-0.2 Rs (a low-resistance short, as insulation
    // breakdown makes: the loop draws a few times the rated current), every phase, no load
    // and full load, on 1-3 % supply unbalance; currents only at 1 kHz and with voltages at 10 kHz; three
    // motors. The baseline is three healthy recordings on the same supply (other noise
    // seeds): their mean, and their spread with the default one counted as a run.
    let mut groups = Vec::new();
    for (mi, (_, rated, _)) in motors().iter().enumerate() {
        for (li, load) in [0.0, *rated].into_iter().enumerate() {
            for (ri, (rate_hz, voltages)) in
                [(1000.0, false), (10_000.0, true)].into_iter().enumerate()
            {
                let g = mi * 4 + li * 2 + ri;
                let unb = [0.01, 0.02, 0.03][g % 3];
                let ang = [20.0, 140.0, 250.0, 320.0][g % 4];
                groups.push((mi, load, unb, ang, rate_hz, voltages));
            }
        }
    }
    let base = |load_nm, unbalance, angle_deg, rate_hz, voltages, seed| Case {
        load_nm,
        unbalance,
        angle_deg,
        short: None,
        rate_hz,
        voltages,
        seed,
        gains: [0.0; 2],
        shaft: false,
    };
    let mut jobs = Vec::new();
    for (gi, &(mi, load, unb, ang, rate, volt)) in groups.iter().enumerate() {
        for (k, phase) in Phase::ALL.into_iter().enumerate() {
            for (j, mu) in [0.02, 0.05, 0.1].into_iter().enumerate() {
                let rf = [0.05, 0.1, 0.2][(gi + k + j) % 3];
                jobs.push((gi, mi, Some((phase, mu, rf)), load, unb, ang, rate, volt));
            }
        }
        // A healthy recording against the healthy baseline.
        jobs.push((gi, mi, None, load, unb, ang, rate, volt));
    }
    let baselines: Vec<Vec<UnbalanceReport>> = groups
        .par_iter()
        .map(|&(mi, load, unb, ang, rate, volt)| {
            let p = &motors()[mi].0;
            (101..104)
                .map(|seed| judge(p, &base(load, unb, ang, rate, volt, seed), &[]))
                .collect()
        })
        .collect();
    let results: Vec<_> = jobs
        .par_iter()
        .map(|&(gi, mi, short, load, unb, ang, rate, volt)| {
            let p = &motors()[mi].0;
            let c = Case {
                short,
                ..base(load, unb, ang, rate, volt, 202 + gi as u64)
            };
            (
                gi,
                mi,
                short,
                load,
                rate,
                judge(p, &c, &baselines[gi].iter().collect::<Vec<_>>()),
            )
        })
        .collect();
    let (mut right, mut shorted, mut failures) = (0, 0, Vec::new());
    for (gi, mi, short, load, rate, u) in &results {
        let (_, unb, ang) = (groups[*gi].1, groups[*gi].2, groups[*gi].3);
        let tag = format!(
            "{} load {load} N m, supply {unb} at {ang} deg, {rate} Hz, short {short:?}",
            motors()[*mi].2
        );
        eprintln!(
            "{tag}: suspect {:?} (confidence {:.2}), winding {:.4}, angle {:.1} deg, correction {:.1} +/- {:.1} deg ({:?}){}",
            u.suspect_phase,
            u.phase_confidence,
            u.winding_ratio,
            u.angle_deg,
            u.correction_deg,
            u.correction_uncertainty_deg,
            u.operating_point,
            u.phase_not_judged
                .map(|w| format!(": {w:?}"))
                .unwrap_or_default()
        );
        match short {
            Some((phase, _, _)) => {
                shorted += 1;
                if u.suspect_phase == Some(*phase) {
                    right += 1;
                } else {
                    failures.push(format!("{tag}: got {:?}", u.suspect_phase));
                }
            }
            None if u.suspect_phase.is_some() => {
                failures.push(format!("{tag}: healthy got {:?}", u.suspect_phase))
            }
            None => {}
        }
    }
    eprintln!("phase right in {right} of {shorted}");
    assert!(
        10 * right >= 9 * shorted,
        "{right} of {shorted}: {failures:#?}"
    );
    // A healthy recording never gets a phase.
    let healthy_named = failures.iter().filter(|f| f.contains("healthy")).count();
    assert_eq!(healthy_named, 0, "{failures:#?}");
}

#[test]
fn a_one_percent_current_sensor_mismatch_names_no_phase() {
    // A healthy motor whose current channels a and b differ by 1 % (a +0.5 %, b -0.5 %, and
    // a +1 % alone), with and without voltages, no baseline; and against a healthy
    // baseline recorded before the mismatch.
    let mut failures = Vec::new();
    for (p, rated, name) in motors() {
        for (voltages, rate_hz) in [(false, 1000.0), (true, 10_000.0)] {
            let case = |gains, seed| Case {
                load_nm: 0.5 * rated,
                unbalance: 0.0,
                angle_deg: 0.0,
                short: None,
                rate_hz,
                voltages,
                seed,
                gains,
                shaft: false,
            };
            let clean = judge(&p, &case([0.0, 0.0], 5), &[]);
            for gains in [[0.005, -0.005], [0.01, 0.0]] {
                for base in [&[][..], &[&clean][..]] {
                    let u = judge(&p, &case(gains, 6), base);
                    if u.suspect_phase.is_some() {
                        failures.push(format!(
                            "{name}, voltages {voltages}, gains {gains:?}, baseline {}: {:?}",
                            !base.is_empty(),
                            u
                        ));
                    }
                }
            }
        }
    }
    assert!(failures.is_empty(), "{failures:#?}");
}

#[test]
fn the_monitor_the_board_runs_names_the_phase_on_an_unbalanced_supply() {
    // The core's own negative-sequence result (what the firmware shows: blink codes 11-13,
    // `wind=`): the supply's V2/Z2 taken out with the measured voltages, no baseline, so a
    // phase only above a healthy machine's own asymmetry. Shorted turns (5 % through Rs/20,
    // 10 % through Rs/10) in every phase on a 2 % unbalanced supply at half load, three
    // motors, 10 kHz with the shaft measured (the board's inputs): the right phase or none,
    // and healthy motors on that supply: none.
    use monitor_core::Monitor;
    use monitor_replay::{monitor_config_for_log, LogSampler};
    let mut failures = Vec::new();
    let mut named = 0;
    for (p, rated, name) in motors() {
        let cases = Phase::ALL
            .into_iter()
            .flat_map(|ph| [Some((ph, 0.05, 0.05)), Some((ph, 0.1, 0.1))])
            .chain([None]);
        for short in cases {
            let c = Case {
                load_nm: 0.5 * rated,
                unbalance: 0.02,
                angle_deg: 70.0,
                short,
                rate_hz: 10_000.0,
                voltages: true,
                seed: 9,
                gains: [0.0; 2],
                shaft: true,
            };
            let (rows, _) = record(&p, &c);
            let cfg = monitor_config_for_log(&p, c.rate_hz, &ReplayOptions::default());
            let mut m = Monitor::new(cfg).expect("config"); // ok: test
            let mut sampler = LogSampler::default();
            for r in &rows {
                m.update(&sampler.sample(r));
            }
            let u = m.output().unbalance;
            eprintln!(
                "{name} short {short:?}: phase {:?}, winding {:.4}, total {:.4}",
                u.suspect_phase, u.winding_ratio, u.negative_sequence_ratio
            );
            match (short, u.suspect_phase) {
                (Some((ph, _, _)), Some(got)) if got == ph => named += 1,
                (_, None) => {}
                (_, got) => failures.push(format!("{name} {short:?}: {got:?}")),
            }
        }
    }
    assert!(failures.is_empty(), "{failures:#?}");
    // Measured: 18 of 18 (winding parts 13-56 %); healthy motors 1.2-3.3 %, under the
    // floor of 30 % of the supply's part.
    assert!(named >= 16, "{named} of 18 named");
}
