//! Across operating points: the follower's schedule, a load change with a nameplate that
//! is off, faults that part over several load levels, and the evidence kept through the
//! follower.

use super::*;

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

/// Evidence across operating points: on the 3 hp motor at rated load an Ls change moves the
/// residuals where an Rr change and a small speed-sensor error do, so one point cannot name
/// it; the same machine seen also at 0.7 and 0.5 of the load separates them, and
/// `isolate_points` names ls with its size. A fault that one point already names keeps its
/// name and size with more points.
#[test]
fn faults_that_coincide_at_one_point_part_over_several() {
    let (_, m, v, we) = machines()[1];
    let iso = commissioned_isolator(&m, v, we, &[1.0, 0.7, 0.5]);
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
    // Over two points Rr and the speed sensor keep their names; the 3 hp machine's Rs
    // (1.6 % of its impedance) is the leading candidate with its size, a rotor-leakage
    // change keeping p 0.2 (below the name's 0.9).
    for f in [Fault::Rs, Fault::Rr, Fault::SpeedSensor] {
        let pts = [at_load(f, 1.3, 1.0), at_load(f, 1.3, 0.7)];
        let joint = iso.isolate_points(&pts);
        let lead = joint.candidates[0];
        assert_eq!(lead.fault, f, "{joint:?}");
        assert!((lead.change - 0.3).abs() <= 0.03, "{f}: {lead:?}");
        match joint.named() {
            Some(Named::Fault(c)) => assert_eq!(c.fault, f),
            None => assert_eq!(f, Fault::Rs, "{joint:?}"),
            other => panic!("{f}: {other:?} {joint:?}"), // ok: test
        }
    }
}

/// The evidence across operating points through the follower, on the 3 hp machine's
/// analytic steady states, commissioned over the load range: healthy at rated load (the
/// anchor), then Ls x1.5 at rated load, where the single point does not name it, and at four
/// lighter load levels (0.75, 0.6, 0.48 and 0.38 of it, 20 % apart). The evidence names Ls with its size
/// at every level after the first, and beyond [`MAX_POINTS`] levels it keeps that many.
#[test]
fn the_evidence_names_ls_over_load_levels_and_keeps_max_points() {
    let (_, m, v, we) = machines()[1];
    // Commissioned over the load range (the file is the machine: learned mean zero).
    let mut f = Follower::new(commissioned_isolator(
        &m,
        v,
        we,
        &[1.0, 0.75, 0.55, 0.4, 0.3],
    ));
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
    for load in [0.75, 0.6, 0.48, 0.38] {
        run(at_load(Some(Fault::Ls), load), &mut f, &mut ev);
        let last = *f.last().unwrap(); // ok: test
        let (joint, n) = ev
            .named()
            .unwrap_or_else(|| panic!("{load}: nothing named over the points: {last:?}")); // ok: test
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
