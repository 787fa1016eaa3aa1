//! The isolation at one operating point: every fault named alone with its size (or not
//! named), the friction class, the unknown fault, a learned baseline, and the points,
//! supplies and baselines it refuses.

use super::*;

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
    //
    // With the name's probability of 0.9 (issue 48: names below it were right too seldom on
    // the calibration sweep), more stay shared at one point with the default spreads: Rr
    // at 10 % on every machine and at -50 % on the 3 hp one (the speed sensor keeps 0.13-0.39:
    // only the torque balance's load term tells them apart), the 2.2 kW machine's rotor
    // leakage at 10 % (its magnetising inductance keeps 0.24-0.27). They are the leading
    // candidate with their size (asserted below), and never a wrong name.
    (name == "3 hp" && change.abs() < 0.2 && matches!(f, Fault::Rs | Fault::Ls | Fault::Lr))
        || (name == "3 hp" && f == Fault::Ls)
        || (name == "3 hp" && f == Fault::Rr)
        || (f == Fault::Rr && change.abs() < 0.2)
        || (name == "2.2 kW" && f == Fault::Lr && change.abs() < 0.2)
        || (name == "11 kW" && f == Fault::Rs && change.abs() < 0.2)
}

#[test]
fn every_fault_is_named_alone_with_its_size_or_not_named_at_all() {
    let mut named = 0;
    let mut missed = std::vec::Vec::new();
    for (name, m, v, we) in machines() {
        let iso = commissioned_isolator(&m, v, we, &[1.0]);
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
                    // Not named alone, but where it is detected the leading candidate
                    // with its size (the 3 hp machine's small Rs, Ls and Lr changes are
                    // below detection).
                    let lead = out.candidates.first().filter(|c| c.fault == f);
                    let hidden = out.state == IsolationState::NoDeviation
                        || matches!(f, Fault::B | Fault::Bl)
                        || (name == "3 hp" && f == Fault::Ls);
                    assert!(
                        hidden
                            || lead.is_some_and(|c| {
                                (f64::from(c.change) - change).abs() < 0.2 * change.abs()
                            }),
                        "{name} {f} {change}: not leading: {out:?}"
                    );
                    continue;
                }
                let Some(top) = out.named_fault() else {
                    missed.push(std::format!(
                        "{name} {f} {change}: not named: {:?}",
                        out.candidates
                            .iter()
                            .take(2)
                            .map(|c| (c.fault, c.probability, c.change))
                            .collect::<std::vec::Vec<_>>()
                    ));
                    continue;
                };
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
    assert!(missed.is_empty(), "{missed:#?}");
    assert!(named >= 60, "{named} named");
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

/// The searches started from the last result (module docs, "Searches started from the
/// last result") give the same isolation, to the bit, as the searches afresh, for every
/// fault growing step by step on the three machines, at one point and jointly over two
/// load levels: in steps of 4 % (the deviation moves: the whole grid is searched) and of
/// 0.01 % (the hints are used).
#[test]
fn searches_from_the_last_result_give_the_same_isolation() {
    let mut used = 0;
    for (name, m, v, we) in machines() {
        let iso = floor_isolator(&m, v, we);
        for f in Fault::ALL {
            let (mut single, mut joint) = (SearchHints::default(), SearchHints::default());
            for step in 0..60 {
                let k = 0.6 + 0.04 * f64::from(step / 4) + 1e-4 * f64::from(step % 4);
                let p = measure(&faulty(&m, Some(f), k), v, we, Some(f), k);
                let mut light = faulty(&m, Some(f), k);
                light.bl_nms *= 0.7;
                let q = measure(&light, v, we, Some(f), k);
                assert_eq!(
                    iso.isolate_scaled_from(&p, 1.5, &mut single),
                    iso.isolate_scaled(&p, 1.5),
                    "{name} {f} {k}"
                );
                used += usize::from(single.used());
                let points = [(p, 1.0), (q, 1.0)];
                assert_eq!(
                    iso.isolate_points_anchored_from(&points, None, &mut joint),
                    iso.isolate_points_anchored(&points, None),
                    "{name} {f} {k}: joint"
                );
                used += usize::from(joint.used());
            }
        }
    }
    // 3 machines x 9 faults x 60 steps, twice: the small steps used the hints.
    assert!(used > 600, "hints used {used} times");
}
