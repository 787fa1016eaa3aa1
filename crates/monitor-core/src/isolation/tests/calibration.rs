//! How sure a name is (issue 48): the rules that keep the isolation's probability
//! calibrated. A name needs [`NAME_PROBABILITY`] and a lead over heating and the unknown
//! fault, not only over the other faults, and a size inside the range searched; heating is
//! bounded by how far a winding can warm in the time; a change inside an average is found
//! across the heating direction.

use super::*;

/// An isolation whose top candidate is `fault` at `p` (the runner-up fault at
/// `second`), with heating at `heat` and the unknown fault at `unknown`.
fn ranked(fault: Fault, p: f32, second: f32, heat: f32, unknown: f32, at_limit: bool) -> Isolation {
    let mut out = Isolation {
        state: IsolationState::Isolated,
        unknown_probability: unknown,
        ..Isolation::default()
    };
    out.heating.probability = heat;
    let others = Fault::ALL.iter().filter(|f| **f != fault);
    for (k, (slot, f)) in out
        .candidates
        .iter_mut()
        .zip(core::iter::once(&fault).chain(others))
        .enumerate()
    {
        slot.fault = *f;
        slot.change = 0.3;
        slot.at_limit = k == 0 && at_limit;
        slot.probability = match k {
            0 => p,
            1 => second,
            _ => 0.0,
        };
    }
    out
}

#[test]
fn a_name_needs_its_probability_a_lead_over_heating_and_the_unknown_fault_and_a_size() {
    let named = |o: &Isolation| o.named_fault().map(|c| c.fault);
    // Alone at 0.95: named.
    assert_eq!(
        named(&ranked(Fault::Rr, 0.95, 0.03, 0.01, 0.01, false)),
        Some(Fault::Rr)
    );
    // At 0.85 (below the name's 0.9): a leading candidate, not a name.
    assert_eq!(
        named(&ranked(Fault::Rr, 0.85, 0.1, 0.03, 0.02, false)),
        None
    );
    // At 0.9 with nothing else: named. With heating or the unknown fault within the margin
    // (the probabilities here need not sum to 1: only the rule is tested), not.
    assert_eq!(
        named(&ranked(Fault::Rr, 0.9, 0.0, 0.0, 0.0, false)),
        Some(Fault::Rr)
    );
    let mut close = ranked(Fault::Rr, 0.9, 0.0, 0.0, 0.0, false);
    close.heating.probability = 0.85;
    assert_eq!(named(&close), None, "heating within the margin");
    let mut unknown = ranked(Fault::Rr, 0.9, 0.0, 0.0, 0.0, false);
    unknown.unknown_probability = 0.82;
    assert_eq!(named(&unknown), None, "the unknown fault within the margin");
    // A size at the end of the range searched is no size.
    assert_eq!(named(&ranked(Fault::Ls, 0.99, 0.01, 0.0, 0.0, true)), None);
    const { assert!(NAME_PROBABILITY >= 0.9) };
}

/// Heating is bounded by how far a winding can warm since its temperature was judged: a
/// second ago, 30 K (20 K plus 10 K/s): a winding 40 K warmer is then no heating (heating
/// takes no part in the ranking), ten seconds ago it is. A step of Rr +30 % (76 K of
/// heating) a second after a healthy point is named Rr.
#[test]
fn heating_is_bounded_by_how_fast_a_winding_warms() {
    for (name, m, v, we) in machines() {
        let mut iso = floor_isolator(&m, v, we);
        let warm = measure(&warmed(&m, 40.0), v, we, None, 1.0);
        iso.set_heating_reach_k(1.0, 0.1);
        let soon = iso.isolate(&warm);
        assert_eq!(soon.heating.probability, 0.0, "{name}: {soon:?}");
        iso.set_heating_reach_k(10.0, 0.1);
        let later = iso.isolate(&warm);
        std::eprintln!(
            "{name} 40 K warmer: heating p {:.2} a second after, {:.2} ten seconds after",
            soon.heating.probability,
            later.heating.probability
        );
        assert!(later.heating_continues(), "{name}: {later:?}");
        iso.set_heating_reach_k(1.0, 0.1);
        let p = measure(&faulty(&m, Some(Fault::Rr), 1.3), v, we, None, 1.0);
        let step = iso.isolate(&p);
        assert_eq!(step.heating.probability, 0.0, "{name}: {step:?}");
        assert_eq!(
            step.named_fault().map(|c| c.fault),
            Some(Fault::Rr),
            "{name}: {step:?}"
        );
    }
}

/// The halves of an average: the same point, or one warmer by the 5 K a winding may have
/// warmed between them, hold no change; a point after a current sensor's 2 % step, after
/// Rs +30 %, or after Rr +20 % (which points almost where heating does) does.
#[test]
fn a_change_inside_an_average_is_found_across_the_heating_direction() {
    for (name, m, v, we) in machines() {
        let iso = floor_isolator(&m, v, we);
        let healthy = measure(&m, v, we, None, 1.0);
        let changed = |p: &SteadyPoint| iso.changed_between((&healthy, p), 1.0, 5.0);
        assert!(!changed(&healthy), "{name}");
        let warm = measure(&warmed(&m, 5.0), v, we, None, 1.0);
        assert!(!changed(&warm), "{name}: 5 K");
        let sensor = measure(&m, v, we, Some(Fault::CurrentSensor), 1.02);
        assert!(changed(&sensor), "{name}: sensor");
        let rs = measure(&faulty(&m, Some(Fault::Rs), 1.3), v, we, None, 1.0);
        assert!(changed(&rs), "{name}: rs");
        let rr = measure(&faulty(&m, Some(Fault::Rr), 1.2), v, we, None, 1.0);
        assert!(changed(&rr), "{name}: rr");
        // Without the warming's allowance the 5 K warmer point is a change too.
        assert!(
            iso.changed_between((&healthy, &warm), 1.0, 0.0),
            "{name}: 5 K, no allowance"
        );
    }
}
