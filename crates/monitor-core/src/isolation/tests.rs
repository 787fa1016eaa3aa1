//! Tests of the fault isolation.

use super::*;
use crate::reference::{MOTOR_2P2KW, MOTOR_3HP};
use crate::MotorParameters;

type C = (f64, f64);
fn mul(a: C, b: C) -> C {
    (a.0 * b.0 - a.1 * b.1, a.0 * b.1 + a.1 * b.0)
}
fn div(a: C, b: C) -> C {
    let d = b.0 * b.0 + b.1 * b.1;
    ((a.0 * b.0 + a.1 * b.1) / d, (a.1 * b.0 - a.0 * b.1) / d)
}
fn add(a: C, b: C) -> C {
    (a.0 + b.0, a.1 + b.1)
}

/// The true machine: parameters in f64 with a fault applied the way the simulator
/// applies it (leakages scaled; Lm on a side without leakage).
fn faulty(p: &MotorParameters, f: Option<Fault>, k: f64) -> MotorParameters {
    let mut m = *p;
    let (lls, llr) = (p.ls_h - p.lm_h, p.lr_h - p.lm_h);
    match f {
        Some(Fault::Rs) => m.rs_ohm *= k,
        Some(Fault::Rr) => m.rr_ohm *= k,
        Some(Fault::Ls) if lls <= 1e-9 => {
            m.lm_h *= k;
            m.ls_h = m.lm_h;
            m.lr_h = llr + m.lm_h;
        }
        Some(Fault::Ls) => m.ls_h = lls * k + p.lm_h,
        Some(Fault::Lr) => m.lr_h = llr * k + p.lm_h,
        Some(Fault::B) => m.b_nms *= k,
        Some(Fault::Bl) => m.bl_nms *= k,
        _ => {}
    }
    m
}

/// Steady state of the true machine `m` on `v_peak` at `we` with its viscous load,
/// solved from the equivalent circuit (magnetising branch in parallel with the rotor
/// branch) and the air-gap power `Te = 3/2 Np |Ir|^2 Rr / ws` by bisection on the
/// slip; the sensors read `k` times the truth under a sensor fault.
fn measure(m: &MotorParameters, v_peak: f64, we: f64, f: Option<Fault>, k: f64) -> SteadyPoint {
    let np = (m.poles / 2) as f64;
    let (lls, llr) = (m.ls_h - m.lm_h, m.lr_h - m.lm_h);
    let solve = |s: f64| {
        let zm = (0.0, we * m.lm_h);
        let zr = (m.rr_ohm / s, we * llr);
        let z = add((m.rs_ohm, we * lls), div(mul(zm, zr), add(zm, zr)));
        let i = div((0.0, v_peak), z);
        let ir = div(mul(i, zm), add(zm, zr));
        let te = 1.5 * np * (ir.0 * ir.0 + ir.1 * ir.1) * m.rr_ohm / (s * we);
        let wr = we * (1.0 - s);
        (te - (m.b_nms + m.bl_nms) * wr / np, i, wr)
    };
    let (mut lo, mut hi) = (1e-7, 0.5);
    for _ in 0..100 {
        let mid = 0.5 * (lo + hi);
        if solve(mid).0 > 0.0 {
            hi = mid;
        } else {
            lo = mid;
        }
    }
    let (_, i, wr) = solve(0.5 * (lo + hi));
    let g = |x: Fault| if f == Some(x) { k } else { 1.0 };
    let (gi, gv, gw) = (
        g(Fault::CurrentSensor),
        g(Fault::VoltageSensor),
        g(Fault::SpeedSensor),
    );
    SteadyPoint {
        i: Dq {
            d: (i.0 * gi) as f32,
            q: (i.1 * gi) as f32,
        },
        v: Dq {
            d: 0.0,
            q: (v_peak * gv) as f32,
        },
        we_rad_s: we as f32,
        wr_rad_s: (wr * gw) as f32,
    }
}

/// A third machine with other per-unit values: an 11 kW, 400 V, 50 Hz, 2-pole motor
/// (low Rr, high Lm: slip about 1 %), not one the code was developed on.
fn motor_11kw() -> MotorParameters {
    MotorParameters {
        rs_ohm: 0.42,
        rr_ohm: 0.36,
        ls_h: 0.108,
        lr_h: 0.109,
        lm_h: 0.104,
        poles: 2,
        j_kgm2: 0.04,
        b_nms: 0.003,
        bl_nms: 0.11,
    }
}

fn machines() -> [(&'static str, MotorParameters, f64, f64); 3] {
    let v = |ll: f64| ll * (2.0f64 / 3.0).sqrt();
    [
        ("2.2 kW", MOTOR_2P2KW.motor, v(400.0), 314.159),
        ("3 hp", MOTOR_3HP.motor, v(220.0), 376.99),
        ("11 kW", motor_11kw(), v(400.0), 314.159),
    ]
}

#[test]
fn the_healthy_machine_has_zero_residuals_at_its_steady_state() {
    for (name, m, v, we) in machines() {
        let iso = Isolator::new(m.model(), v as f32, (we / core::f64::consts::TAU) as f32).unwrap(); // ok: test
        let p = measure(&m, v, we, None, 1.0);
        let e = iso.residuals(&p, None).unwrap(); // ok: test
        assert!(e.to_array().iter().all(|x| x.abs() < 1e-4), "{name}: {e:?}");
        assert_eq!(iso.isolate(&p).state, IsolationState::NoDeviation, "{name}");
    }
}

/// Cases that cannot be named alone, and why (asserted: not named wrongly instead).
fn not_separable(name: &str, f: Fault, change: f64) -> bool {
    // The 3 hp machine: Rs, Ls and Lr at 10 % move |V - Z I| by under 0.2 % of |V|,
    // about one spread (below detection); its leakage change of 50 % points where a
    // 3 % Rr change does (0.1-2 deg apart). Rr at 10 %: a 0.3 % speed-sensor error
    // fits too (the rotor circuit depends on Rr/slip; only the torque balance helps).
    (name == "3 hp" && change.abs() < 0.2 && matches!(f, Fault::Rs | Fault::Ls | Fault::Lr))
        || (name == "3 hp" && f == Fault::Ls)
        || (name == "3 hp" && f == Fault::Rr && change.abs() < 0.2)
        || (name == "11 kW" && f == Fault::Rs && change.abs() < 0.2)
}

#[test]
fn every_fault_is_named_alone_with_its_size_or_not_named_at_all() {
    let mut named = 0;
    for (name, m, v, we) in machines() {
        let iso = Isolator::new(m.model(), v as f32, (we / core::f64::consts::TAU) as f32).unwrap(); // ok: test
        for f in Fault::ALL {
            for change in [-0.5f64, 0.5, -0.1, 0.1] {
                let k = 1.0 + change;
                let p = measure(&faulty(&m, Some(f), k), v, we, Some(f), k);
                let out = iso.isolate(&p);
                // Never a wrong fault at probability 0.5 or more.
                for c in &out.candidates {
                    let friction = matches!(f, Fault::B | Fault::Bl)
                        && matches!(c.fault, Fault::B | Fault::Bl);
                    assert!(
                        c.fault == f || friction || c.probability < 0.5,
                        "{name} {f} {change}: {} named at {}",
                        c.fault,
                        c.probability
                    );
                }
                let expected = !matches!(f, Fault::B | Fault::Bl)
                    && !not_separable(name, f, change)
                    && (change.abs() > 0.2
                        || matches!(
                            f,
                            Fault::Rs
                                | Fault::Rr
                                | Fault::CurrentSensor
                                | Fault::VoltageSensor
                                | Fault::SpeedSensor
                        )
                        || name == "2.2 kW"
                        || name == "11 kW");
                if !expected {
                    continue;
                }
                let top = out
                    .named_fault()
                    .unwrap_or_else(|| panic!("{name} {f} {change}: not named: {out:?}")); // ok: test
                assert_eq!(top.fault, f, "{name} {f} {change}: {out:?}");
                assert!(
                    (f64::from(top.change) - change).abs() < 0.2 * change.abs(),
                    "{name} {f} {change}: size {}",
                    top.change
                );
                named += 1;
            }
        }
    }
    // 3 machines x 7 faults x 4 sizes, minus the documented exceptions.
    assert!(named >= 70, "{named} named");
}

#[test]
fn b_and_bl_are_one_friction_class() {
    let (_, m, v, we) = machines()[1];
    let iso = Isolator::new(m.model(), v as f32, 60.0).unwrap(); // ok: test
    let p = measure(&faulty(&m, Some(Fault::Bl), 1.5), v, we, None, 1.0);
    let out = iso.isolate(&p);
    let top2: Vec<Fault> = out.candidates[..2].iter().map(|c| c.fault).collect();
    assert!(
        top2.contains(&Fault::B) && top2.contains(&Fault::Bl),
        "{out:?}"
    );
    assert!(out.separation_deg < 1.0, "{}", out.separation_deg);
    let bl = out
        .candidates
        .iter()
        .find(|c| c.fault == Fault::Bl)
        .unwrap(); // ok: test
    assert!((bl.change - 0.5).abs() < 0.1, "{}", bl.change);
    assert!(
        out.named_fault().is_none(),
        "neither is named alone: {out:?}"
    );
    assert!(
        matches!(out.named(), Some(Named::Friction { .. })),
        "{out:?}"
    );
}

#[test]
fn a_change_no_fault_explains_is_unknown_not_a_wrong_name() {
    // Rs and Lr both changed: no single fault's direction fits.
    let (_, m, v, we) = machines()[1];
    let iso = Isolator::new(m.model(), v as f32, 60.0).unwrap(); // ok: test
    let mut t = faulty(&m, Some(Fault::Rs), 1.6);
    t.lr_h = (m.lr_h - m.lm_h) * 0.4 + m.lm_h;
    t.bl_nms *= 0.6;
    let out = iso.isolate(&measure(&t, v, we, None, 1.0));
    assert!(out.deviation > 10.0);
    assert!(
        out.candidates.iter().all(|c| c.probability < 0.5),
        "{out:?}"
    );
}

#[test]
fn a_learned_baseline_absorbs_a_nameplate_that_is_off() {
    // Nominal parameters 20 % off; learning on the healthy machine at two loads, then
    // an Rr fault is named from the change.
    let (_, m, v, we) = machines()[0];
    let mut off = m;
    off.rs_ohm *= 1.2;
    off.lm_h *= 0.8;
    off.ls_h = off.lm_h;
    off.lr_h = m.lr_h - m.lm_h + off.lm_h;
    let mut iso = Isolator::new(off.model(), v as f32, 50.0).unwrap(); // ok: test
    assert_ne!(
        iso.isolate(&measure(&m, v, we, None, 1.0)).state,
        IsolationState::NoDeviation
    );
    for n in 0..20 {
        let mut load = m;
        load.bl_nms *= 0.95 + 0.005 * n as f64;
        iso.learn(&measure(&load, v, we, None, 1.0));
    }
    assert!(iso.finish_learning());
    let healthy = iso.isolate(&measure(&m, v, we, None, 1.0));
    assert_eq!(healthy.state, IsolationState::NoDeviation, "{healthy:?}");
    let out = iso.isolate(&measure(
        &faulty(&m, Some(Fault::Rr), 1.5),
        v,
        we,
        None,
        1.0,
    ));
    // Learned over a 10 % load range and widened for the nameplate's error away from
    // the learned point, the torque balance no longer tells Rr from a speed-sensor
    // error (directions 0.2 deg apart): they share the probability, neither is named
    // alone, and Rr's size is right.
    let rr = out.candidates.iter().find(|c| c.fault == Fault::Rr);
    let rr = rr.unwrap(); // ok: test
    assert!(rr.probability >= 0.4, "{out:?}");
    assert!((rr.change - 0.5).abs() < 0.05, "{out:?}");
    assert!(
        matches!(out.named_fault().map(|c| c.fault), None | Some(Fault::Rr)),
        "{out:?}"
    );
}

#[test]
fn unusable_points_are_not_judged() {
    let (_, m, v, _) = machines()[1];
    let iso = Isolator::new(m.model(), v as f32, 60.0).unwrap(); // ok: test
    for p in [
        SteadyPoint::default(),
        SteadyPoint {
            i: Dq {
                d: f32::NAN,
                q: 1.0,
            },
            v: Dq { d: 0.0, q: 100.0 },
            we_rad_s: 377.0,
            wr_rad_s: 370.0,
        },
    ] {
        assert_eq!(iso.isolate(&p).state, IsolationState::NotJudged);
    }
    assert!(Isolator::new(m.model(), f32::NAN, 60.0).is_err());
}

/// A supply or a baseline the isolation cannot use is refused with the field it names.
#[test]
fn a_bad_supply_or_baseline_names_its_field() {
    let (_, m, v, we) = machines()[0];
    let f = (we / core::f64::consts::TAU) as f32;
    let check = |r: Result<Isolator, crate::ConfigError>| r.err().map(|e| e.field());
    assert_eq!(
        check(Isolator::new(m.model(), f32::NAN, f)),
        Some("v_phase_peak")
    );
    assert_eq!(
        check(Isolator::new(m.model(), v as f32, 0.0)),
        Some("supply_hz")
    );
    assert_eq!(
        check(Isolator::new(m.model(), v as f32, f32::INFINITY)),
        Some("supply_hz")
    );
    let mut bad_motor = m.model();
    bad_motor.rs_ohm = -1.0;
    assert_eq!(
        check(Isolator::new(bad_motor, v as f32, f)),
        Some("motor.rs_ohm")
    );
    let mut iso = Isolator::new(m.model(), v as f32, f).unwrap(); // ok: test
    let before = iso.baseline();
    let mut b = Baseline::default();
    b.mean.torque = f32::NAN;
    let e = iso.set_baseline(b).unwrap_err(); // ok: test
    assert_eq!(
        (e.kind(), e.field()),
        (crate::ConfigErrorKind::Baseline, "baseline.mean")
    );
    b = Baseline::default();
    b.spread.voltage_q = f32::INFINITY;
    assert_eq!(
        iso.set_baseline(b).map_err(|e| e.field()),
        Err("baseline.spread")
    );
    assert_eq!(iso.baseline(), before, "a refused baseline changes nothing");
    assert_eq!(iso.set_baseline(Baseline::default()), Ok(()));
}

/// The follower's schedule: nothing before half a second of steady running; a load or
/// supply step restarts the average; the baseline learned while commissioning learns
/// goes into force when it ends; an Rr +40 % change is then named with its size, and
/// reported once it has been named for `CONFIRM_S`.
#[test]
fn the_follower_averages_learns_and_isolates_on_schedule() {
    let (_, m, v, we) = machines()[0];
    let iso = Isolator::new(m.model(), v as f32, (we / core::f64::consts::TAU) as f32);
    let mut f = Follower::new(iso.unwrap()); // ok: test
    let healthy = measure(&m, v, we, None, 1.0);
    let dt = 0.01;
    // 0.49 s of steady running: waiting.
    for _ in 0..49 {
        assert_eq!(f.observe(&healthy, dt, true, false), Step::Waiting);
    }
    assert!(f.last().is_none());
    // Learning for 2 s: points go into the baseline, none is isolated.
    let mut learned = 0;
    for _ in 0..200 {
        match f.observe(&healthy, dt, true, true) {
            Step::Learned => learned += 1,
            Step::Waiting => {}
            other => panic!("while learning: {other:?}"), // ok: test
        }
    }
    // One point per STEP_S block once AVERAGE_S is averaged: 0.5..2.49 s.
    assert!((19..=21).contains(&learned), "{learned} points learned");
    assert_eq!(
        f.observe(&healthy, dt, true, false),
        Step::LearningEnded(true)
    );
    assert!(f.learned());
    // A 5 % voltage step: not steady, the average restarts after SETTLE_S (blocks dropped)
    // and gives a result once AVERAGE_S is averaged: 1 s after the step.
    let mut stepped = measure(&m, 1.05 * v, we, None, 1.0);
    let mut steps = 0;
    let first = ((SETTLE_S + AVERAGE_S) / dt) as usize - 1;
    for k in 0..150 {
        if let Step::Isolated(r) = f.observe(&stepped, dt, true, false) {
            assert!(k >= first, "isolated {k} steps after the step");
            assert_eq!(r.state, IsolationState::NoDeviation, "{r:?}");
            steps += 1;
        }
    }
    assert!(steps >= 5, "{steps} isolations in 1 s");
    // An unusable point (a sensor fault) drops the average.
    assert_eq!(f.observe(&stepped, dt, false, false), Step::Waiting);
    let rr = faulty(&m, Some(Fault::Rr), 1.4);
    stepped = measure(&rr, 1.05 * v, we, Some(Fault::Rr), 1.4);
    // Named after SETTLE_S and 0.5 s of averaging, reported after CONFIRM_S more.
    let (mut named, mut unconfirmed) = (None, 0);
    for k in 0..150 {
        match f.observe(&stepped, dt, true, false) {
            Step::Isolated(r) => {
                assert!(k >= 99, "in force {k} steps after the change");
                named = r.named_fault();
            }
            Step::Unconfirmed(r) => {
                assert_eq!(r.named_fault().map(|c| c.fault), Some(Fault::Rr));
                unconfirmed += 1;
            }
            _ => {}
        }
    }
    // One per STEP_S block for CONFIRM_S.
    assert!(unconfirmed >= 4, "{unconfirmed} unconfirmed isolations");
    let c = named.unwrap_or_else(|| panic!("Rr +40 % not named: {:?}", f.last())); // ok: test
    assert_eq!(c.fault, Fault::Rr);
    assert!((c.change - 0.4).abs() < 0.04, "size {}", c.change);
    // Bad time steps count as no time.
    for dt in [f32::NAN, -1.0, f32::INFINITY] {
        assert_eq!(f.observe(&stepped, dt, true, false), Step::Waiting);
    }
}
/// The nominal parameters 15-20 % off (Rs +20 %, Rr -19 %, leakages -13 %, Lm -15 %),
/// learned at the machine's own load; then the load moves to 0.5-1.1 of it, with or
/// without a fault. Before the weight was widened away from the learned point this
/// named wrong faults with confidence (a 10 % load rise with Rr +50 % on the 2.2 kW
/// machine: speed sensor at 0.74; found by hand on a simulated 11 kW log: current
/// sensor at 0.95 for Rr +50 % after a load step to 0.7).
#[test]
fn a_load_change_with_a_fault_and_a_nameplate_that_is_off() {
    let (mut right, mut cases) = (0, 0);
    let mut wrong = Vec::new();
    for (name, m, v, we) in machines() {
        let mut off = m;
        let (lls, llr) = (m.ls_h - m.lm_h, m.lr_h - m.lm_h);
        off.rs_ohm *= 1.2;
        off.rr_ohm *= 0.81;
        off.lm_h *= 0.85;
        off.ls_h = lls * 0.87 + off.lm_h;
        off.lr_h = llr * 0.87 + off.lm_h;
        let hz = (we / core::f64::consts::TAU) as f32;
        let mut iso = Isolator::new(off.model(), v as f32, hz).unwrap(); // ok: test
        for _ in 0..20 {
            iso.learn(&measure(&m, v, we, None, 1.0));
        }
        assert!(iso.finish_learning());
        for load in [0.5, 0.7, 0.9, 1.1] {
            let mut t = m;
            t.bl_nms *= load;
            let healthy = iso.isolate(&measure(&t, v, we, None, 1.0));
            if let Some(Named::Fault(c)) = healthy.named() {
                wrong.push(format!("{name} load {load} healthy: {c:?}"));
            }
            for (f, k) in [
                (Fault::Rr, 1.5),
                (Fault::Rs, 1.5),
                (Fault::CurrentSensor, 0.7),
                (Fault::SpeedSensor, 1.01),
                (Fault::Lr, 0.5),
            ] {
                let out = iso.isolate(&measure(&faulty(&t, Some(f), k), v, we, Some(f), k));
                cases += 1;
                let top = out.candidates[0];
                eprintln!(
                    "{name} load {load} {f} {k}: top {} {:.2} ({:+.2}), second {} {:.2}, unknown {:.2}",
                    top.fault, top.probability, top.change, out.candidates[1].fault,
                    out.candidates[1].probability, out.unknown_probability
                );
                match out.named() {
                    Some(Named::Fault(c)) if c.fault == f => right += 1,
                    Some(Named::Fault(c)) => {
                        wrong.push(format!("{name} load {load} {f} {k}: {c:?}"))
                    }
                    _ => {}
                }
            }
        }
    }
    eprintln!("named right {right} of {cases}");
    assert!(wrong.is_empty(), "{wrong:#?}");
}

/// The machine warmed by `rise_k`: Rs and Rr times 1 + alpha rise.
/// An isolator for `m` on a supply of peak `v` and `we` rad/s, with a baseline learned at
/// its healthy point (spreads at their floor, [`LEARNED_SPREAD_FLOOR`]).
fn floor_isolator(m: &MotorParameters, v: f64, we: f64) -> Isolator {
    let mut iso = Isolator::new(m.model(), v as f32, (we / core::f64::consts::TAU) as f32).unwrap(); // ok: test
    iso.set_baseline(Baseline {
        mean: ParityResiduals::default(),
        spread: LEARNED_SPREAD_FLOOR,
        at: measure(m, v, we, None, 1.0),
    })
    .unwrap(); // ok: test
    iso
}

fn warmed(m: &MotorParameters, rise_k: f64) -> MotorParameters {
    let k = 1.0 + f64::from(COPPER_ALPHA_PER_K) * rise_k;
    MotorParameters {
        rs_ohm: m.rs_ohm * k,
        rr_ohm: m.rr_ohm * k,
        ..*m
    }
}

/// Heating is told from the faults on the three machines, with a baseline learned at the
/// healthy point (spreads at their floor, [`LEARNED_SPREAD_FLOOR`]): a winding 20, 60 or
/// 100 K warmer (Rs and Rr together) is explained by the heating hypothesis alone with its
/// rise within 1 K, and no fault of Table 1 at +-50 % is taken for heating.
#[test]
fn heating_is_explained_and_no_table1_fault_is_taken_for_it() {
    for (name, m, v, we) in machines() {
        let iso = floor_isolator(&m, v, we);
        for rise in [20.0, 60.0, 100.0] {
            let p = measure(&warmed(&m, rise), v, we, None, 1.0);
            let r = iso.isolate(&p);
            let seen = (r.heating.factor - 1.0) / COPPER_ALPHA_PER_K;
            std::eprintln!(
                "{name} +{rise} K: heating p {:.2} misfit {:.2} rise {seen:.1}, top {:?}",
                r.heating.probability,
                r.heating.misfit,
                r.candidates[0]
            );
            // The 3 hp motor's Rs is 1.6 % of its impedance: there heating is the most
            // probable explanation, not always one alone (a speed-sensor error fits too).
            assert!(
                r.heating_explains() || (name == "3 hp" && r.heating_continues()),
                "{name} +{rise} K: {r:?}"
            );
            assert!((f64::from(seen) - rise).abs() <= 1.0, "{name}: {seen}");
        }
        for f in Fault::ALL {
            for change in [0.5, -0.5] {
                let p = measure(
                    &faulty(&m, Some(f), 1.0 + change),
                    v,
                    we,
                    Some(f),
                    1.0 + change,
                );
                let r = iso.isolate(&p);
                std::eprintln!(
                    "{name} {f} {change:+}: heating p {:.2} misfit {:.2}, top {:?} {:.2}",
                    r.heating.probability,
                    r.heating.misfit,
                    r.candidates[0].fault,
                    r.candidates[0].probability
                );
                assert!(
                    !r.heating_explains() && !r.heating_continues(),
                    "{name} {f} {change:+}: {r:?}"
                );
            }
        }
    }
}

/// Evidence across operating points: on the 3 hp motor at rated load an Ls change moves the
/// residuals where an Rr change and a small speed-sensor error do, so one point cannot name
/// it; the same machine seen also at 0.7 and 0.5 of the load separates them, and
/// `isolate_points` names ls with its size. A fault that one point already names keeps its
/// name and size with more points.
#[test]
fn faults_that_coincide_at_one_point_part_over_several() {
    let (_, m, v, we) = machines()[1];
    let iso = Isolator::new(m.model(), v as f32, (we / core::f64::consts::TAU) as f32).unwrap(); // ok: test
    let at_load = |f: Fault, k: f64, load: f64| {
        let mut t = faulty(&m, Some(f), k);
        t.bl_nms *= load;
        (measure(&t, v, we, Some(f), k), 1.0f32)
    };
    for k in [1.5, 0.5] {
        let one = iso.isolate(&at_load(Fault::Ls, k, 1.0).0);
        std::eprintln!(
            "3 hp ls x{k} at one point: {:?}",
            one.candidates[..3]
                .iter()
                .map(|c| (c.fault, c.probability))
                .collect::<std::vec::Vec<_>>()
        );
        assert!(one.named().is_none(), "one point: {one:?}");
        let pts = [
            at_load(Fault::Ls, k, 1.0),
            at_load(Fault::Ls, k, 0.7),
            at_load(Fault::Ls, k, 0.5),
        ];
        let joint = iso.isolate_points(&pts);
        std::eprintln!(
            "3 hp ls x{k} at three points: {:?}",
            joint.candidates[..3]
                .iter()
                .map(|c| (c.fault, c.probability, c.change))
                .collect::<std::vec::Vec<_>>()
        );
        match joint.named() {
            Some(Named::Fault(c)) => {
                assert_eq!(c.fault, Fault::Ls);
                assert!(
                    (f64::from(c.change) - (k - 1.0)).abs() <= 0.1 * (k - 1.0).abs(),
                    "{c:?}"
                );
            }
            other => panic!("three points: {other:?} {joint:?}"), // ok: test
        }
    }
    for f in [Fault::Rs, Fault::Rr, Fault::SpeedSensor] {
        let pts = [at_load(f, 1.3, 1.0), at_load(f, 1.3, 0.7)];
        let joint = iso.isolate_points(&pts);
        match joint.named() {
            Some(Named::Fault(c)) if c.fault == f => {
                assert!((c.change - 0.3).abs() <= 0.03, "{f}: {c:?}")
            }
            other => panic!("{f}: {other:?}"), // ok: test
        }
    }
}

/// The evidence across operating points through the follower, on the 3 hp machine's
/// analytic steady states: healthy at rated load (the anchor), then Ls x1.5 at rated load,
/// where the single point does not name it, and at four lighter load levels 20 % or more
/// apart. The evidence names Ls with its size at every level after the first, and beyond
/// [`MAX_POINTS`] levels it keeps that many.
#[test]
fn the_evidence_names_ls_over_load_levels_and_keeps_max_points() {
    let (_, m, v, we) = machines()[1];
    let iso = Isolator::new(m.model(), v as f32, (we / core::f64::consts::TAU) as f32).unwrap(); // ok: test
    let mut f = Follower::new(iso);
    let mut ev = Evidence::default();
    let at_load = |fault: Option<Fault>, load: f64| {
        let mut t = faulty(&m, fault, 1.5);
        t.bl_nms *= load;
        measure(&t, v, we, fault, 1.5)
    };
    // Three seconds at each point, 10 ms apart.
    let run = |p: SteadyPoint, f: &mut Follower, ev: &mut Evidence| {
        for _ in 0..300 {
            if let Step::Isolated(r) = f.observe(&p, 0.01, true, false) {
                ev.after(f, &r);
            }
        }
    };
    run(at_load(None, 1.0), &mut f, &mut ev);
    run(at_load(Some(Fault::Ls), 1.0), &mut f, &mut ev);
    let single = *f.last().unwrap(); // ok: test
    assert!(single.named_fault().is_none(), "one point: {single:?}");
    assert!(ev.anchored(), "the healthy point is the anchor");
    let mut kept = std::vec::Vec::new();
    for load in [0.75, 0.55, 0.4, 0.3] {
        run(at_load(Some(Fault::Ls), load), &mut f, &mut ev);
        let (joint, n) = ev.named().unwrap(); // ok: test
        let c = joint.named_fault().unwrap(); // ok: test
        assert_eq!(c.fault, Fault::Ls, "{load}: {joint:?}");
        assert!((c.change - 0.5).abs() <= 0.05, "{load}: {c:?}");
        let single = *f.last().unwrap(); // ok: test
        assert_eq!(
            ev.in_force(&single).named_fault().map(|c| c.fault),
            Some(Fault::Ls)
        );
        kept.push(n);
    }
    assert_eq!(kept, [2, 3, MAX_POINTS, MAX_POINTS]);
}

/// A measured rise (a temperature channel) puts the warm machine in force: a winding 60 K
/// warmer is no deviation at all against it, an Rs +30 % fault on that warm winding is
/// the most probable fault with its size against the warm Rs, and a rise that is not finite or beyond what a
/// winding can reach (25 K cooler .. 160 K warmer) is refused without changing anything.
#[test]
fn a_measured_rise_compensates_rs_and_rr() {
    for (name, m, v, we) in machines() {
        let mut iso = floor_isolator(&m, v, we);
        for bad in [f32::NAN, f32::INFINITY, -30.0, 170.0] {
            assert!(!iso.set_winding_rise_k(bad), "{name} {bad}");
            assert_eq!(iso.heating_factor(), 1.0, "{name} {bad}");
        }
        assert!(iso.set_winding_rise_k(60.0));
        assert!((iso.winding_rise_k() - 60.0).abs() < 1e-3, "{name}");
        let warm = warmed(&m, 60.0);
        let r = iso.isolate(&measure(&warm, v, we, None, 1.0));
        assert_eq!(r.state, IsolationState::NoDeviation, "{name}: {r:?}");
        let r = iso.isolate(&measure(
            &faulty(&warm, Some(Fault::Rs), 1.3),
            v,
            we,
            Some(Fault::Rs),
            1.3,
        ));
        // (The most probable fault: on the 3 hp motor, whose Rs is 1.6 % of its impedance,
        // one point leaves it shared with the voltage sensor and friction, as on a cold one.)
        let top = r.candidates[0];
        assert!(
            r.state == IsolationState::Isolated
                && top.fault == Fault::Rs
                && (f64::from(top.change) - 0.3).abs() <= 0.03,
            "{name}: {r:?}"
        );
        // The follower refuses the same rises and keeps none in force.
        let mut fol = Follower::new(iso);
        assert!(!fol.set_measured_rise_k(Some(f32::NAN)));
        assert_eq!(fol.measured_rise_k(), None);
        assert!(fol.set_measured_rise_k(Some(20.0)));
        assert_eq!(fol.measured_rise_k(), Some(20.0));
        assert!((fol.isolator().winding_rise_k() - 20.0).abs() < 1e-3);
        assert!(fol.set_measured_rise_k(None));
        assert_eq!(fol.measured_rise_k(), None);
    }
}
