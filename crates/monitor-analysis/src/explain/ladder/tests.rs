//! The ladder's own mechanisms on logs of the textbook machine (monitor-testkit: Krause's
//! equations, written apart from this crate's model and the project's simulator).

use super::rung::{nested, setup_list, LadderSeries, Rung};
use super::*;
use crate::effects::EffectModel;
use crate::fit::machine::MachineScales;
use crate::fit::BaseSpec;
use crate::prep::ReadOptions;
use crate::simplified_model::BaseParams;
use monitor_io::params::ParamFile;
use monitor_laws::EffectId;
use monitor_testkit::textbook_machine::{write_log, Machine, Scenario, Supply};
use std::collections::BTreeMap;

/// The 2.2 kW textbook machine driving a fan (its whole load, no viscous load) through a
/// start and two voltage steps, 7 s at 4 kHz, with the file's values.
fn fan_log(dir: &std::path::Path) -> Analysis {
    let m = Machine::kw2p2();
    let mut s = Scenario::new(&m, 7.0, 4000.0);
    s.load = monitor_testkit::textbook_machine::Load::Viscous(0.0);
    s.hidden.windage = Some(0.6 * m.rated_nm / m.w_sync().powi(2));
    s.supply = Supply {
        points: vec![
            (2.0, 1.0, 1.0),
            (2.0, 0.85, 1.0),
            (3.5, 0.85, 1.0),
            (3.5, 1.1, 1.0),
            (5.0, 1.1, 1.0),
            (5.0, 1.0, 1.0),
        ],
    };
    let log = write_log(dir, "fan", &m, &s);
    let p = ParamFile::from_toml_str(&m.params_toml(0.0, 0.0), "textbook").expect("file");
    Analysis::load(&log, p, ReadOptions::default(), &mut |_| {}).expect("load")
}

/// No progress to show.
static NO_PROGRESS: fn(super::LadderProgress) = |_| {};

/// The ladder on the log of `a` at its start, the user having configured `configured`
/// (the effects it never drops).
fn ladder_on<'a>(
    a: &'a Analysis,
    lib: &'a [Box<dyn EffectModel>],
    configured: &[EffectId],
) -> Ladder<'a> {
    let (held, _) = stratified_heldback(&a.data, &a.constants);
    let opts = Options {
        effects: configured.to_vec(),
        fit_base: true,
        laws: Default::default(),
    };
    // (The configured effects' models live as long as the ladder: leaked, in a test.)
    let boxes: &'a [Box<dyn EffectModel>] =
        Box::leak(resolve(configured, &Default::default()).into_boxed_slice());
    Ladder::start(a, lib, boxes, &opts, held, &NO_PROGRESS).expect("start")
}

/// The model of `kinds` fitted nested from `from` (or from scratch) on the ladder's series.
fn rung_of<'a>(
    a: &Analysis,
    lib: &'a [Box<dyn EffectModel>],
    kinds: &[EffectId],
    from: Option<&Rung<'a>>,
    sr: &LadderSeries,
) -> Rung<'a> {
    let models: Vec<&'a dyn EffectModel> = kinds
        .iter()
        .filter_map(|k| lib.iter().find(|e| e.kind() == *k).map(|e| e.as_ref()))
        .collect();
    let set = match from {
        Some(r) => {
            let extra: Vec<&'a dyn EffectModel> = models[r.models.len()..].to_vec();
            nested(a, &extra, r, &sr.fd).expect("set-up")
        }
        None => setup_list(a, &sr.fd, &models).expect("set-up"),
    };
    let start = from.map_or(BaseParams::nominal(&a.constants), |r| r.fit.base);
    let f = a
        .fit_spec(
            &sr.fd,
            &set,
            &sr.wf,
            &start,
            BaseSpec::PAPER.for_effects(&set),
        )
        .expect("fit");
    sr.measure(a, models, f, MachineScales::of_file(&a.params))
        .expect("measure")
}

/// Iron loss taken for a fan's drag before windage was in the model is dropped by the step
/// that adds windage: the model without it loses less than the test's 10 % (stepwise
/// selection both ways). Without the drop the step keeps it.
#[test]
fn a_stand_in_a_later_step_explains_is_dropped() {
    let dir = tempfile::tempdir().expect("tempdir");
    let a = fan_log(dir.path());
    let lib = crate::effects::ladder_library();
    let ladder = ladder_on(&a, &lib, &[]);
    let sr = &ladder.series;
    let full = [
        EffectId::FLUX_DYNAMICS,
        EffectId::CURRENT_DYNAMICS,
        EffectId::D_AXIS_DYNAMICS,
        EffectId::CROSS_COUPLING_DYNAMICS,
    ];
    let with_iron: Vec<EffectId> = full.iter().copied().chain([EffectId::IRON_LOSS]).collect();
    let before = rung_of(&a, &lib, &with_iron, None, sr);
    let mut all = with_iron.clone();
    all.push(EffectId::WINDAGE);
    let next = rung_of(&a, &lib, &all, Some(&before), sr);
    assert!(next.error < before.error, "{} {}", next.error, before.error);
    let step = LadderStep {
        effect: Some(EffectId::WINDAGE),
        added: vec![EffectId::WINDAGE],
        base: Vec::new(),
        dropped: Vec::new(),
        dropped_because: Vec::new(),
        fitted: BTreeMap::new(),
        described: Vec::new(),
        error: next.error,
        heldback_error: next.heldback_error,
        noise_floor: next.noise,
        heldback_noise_floor: next.heldback_noise,
        ratio_to_floor: next.error / next.noise,
        heldback_ratio_to_floor: next.heldback_error / next.heldback_noise,
        significance: 1.0,
        explained: 0.0,
        heldback_explained: 0.0,
        error_over_time: Vec::new(),
    };
    let (after, step) = ladder
        .drop_stand_ins(&a, next, step, &before)
        .expect("drops");
    assert_eq!(step.dropped, vec![EffectId::IRON_LOSS], "{step:?}");
    assert!(!after.kinds.contains(&EffectId::IRON_LOSS));
    assert!(after.kinds.contains(&EffectId::WINDAGE));
    // The step as a whole still lowers the whole-log error.
    assert!(after.error < before.error);
    // Why: the model without it loses less than a step must earn.
    let why = &step.dropped_because;
    assert_eq!(why.len(), 1, "{why:?}");
    assert_eq!(why[0].effect, EffectId::IRON_LOSS);
    assert!(
        why[0].loses < why[0].asks && why[0].asks == STEP_MIN,
        "{why:?}"
    );
}

/// A configured effect (the user's) and the dynamics effects are never dropped, whatever
/// they explain.
#[test]
fn what_the_user_configured_and_the_machine_order_stay() {
    let dir = tempfile::tempdir().expect("tempdir");
    let a = fan_log(dir.path());
    let lib = crate::effects::ladder_library();
    let ladder = ladder_on(&a, &lib, &[EffectId::IRON_LOSS]);
    let sr = &ladder.series;
    let kinds = [
        EffectId::FLUX_DYNAMICS,
        EffectId::CURRENT_DYNAMICS,
        EffectId::D_AXIS_DYNAMICS,
        EffectId::CROSS_COUPLING_DYNAMICS,
        EffectId::IRON_LOSS,
        EffectId::WINDAGE,
    ];
    let before = rung_of(&a, &lib, &kinds[..5], None, sr);
    let next = rung_of(&a, &lib, &kinds, Some(&before), sr);
    let step = LadderStep {
        effect: Some(EffectId::WINDAGE),
        added: vec![EffectId::WINDAGE],
        base: Vec::new(),
        dropped: Vec::new(),
        dropped_because: Vec::new(),
        fitted: BTreeMap::new(),
        described: Vec::new(),
        error: next.error,
        heldback_error: next.heldback_error,
        noise_floor: next.noise,
        heldback_noise_floor: next.heldback_noise,
        ratio_to_floor: next.error / next.noise,
        heldback_ratio_to_floor: next.heldback_error / next.heldback_noise,
        significance: 1.0,
        explained: 0.0,
        heldback_explained: 0.0,
        error_over_time: Vec::new(),
    };
    let (after, step) = ladder
        .drop_stand_ins(&a, next, step, &before)
        .expect("drops");
    assert!(step.dropped.is_empty(), "{:?}", step.dropped);
    assert_eq!(after.kinds, kinds.to_vec());
}

/// The fit copy of a long log keeps the machine's fastest dynamics resolved: a 22 s log at
/// 2 kHz (44 000 samples) with a 3.6 ms stator transient is thinned by 2 (1 kHz, 3.6
/// samples per time constant), where the budget alone (20 000 samples) asked 3 (667 Hz,
/// 2.4 samples); a 10 s log at 2 kHz is not thinned, nor a 40 s one whose transient needs
/// the log's rate; a 60 min log is thinned to the copy's largest size.
#[test]
fn a_long_log_is_thinned_no_further_than_its_dynamics_allow() {
    assert_eq!(fit_thinning(44_000, 5e-4, 3.6e-3), 2);
    assert_eq!(fit_thinning(44_000, 5e-4, 2.9e-3), 1);
    assert_eq!(fit_thinning(20_000, 5e-4, 3.6e-3), 1);
    // A 40 s log at 2 kHz of a small machine (a 2.1 ms stator transient) keeps the log's
    // own rate: at 1 kHz its dynamics were refused (issue 87).
    assert_eq!(fit_thinning(80_000, 5e-4, 2.1e-3), 1);
    // A slow machine's log may be thinned as the budget asks.
    assert_eq!(fit_thinning(80_000, 5e-4, 20e-3), 4);
    // Beyond the copy's largest size the budget wins (the dynamics are then refused).
    let m = fit_thinning(7_200_000, 5e-4, 3.6e-3);
    assert_eq!(m, 7_200_000usize.div_ceil(LADDER_MAX_FIT_SAMPLES));
    // At least 3 samples per time constant wherever the copy allows it.
    for (len, tau) in [(44_000, 3.6e-3), (100_000, 5e-3), (30_000, 2e-3)] {
        let m = fit_thinning(len, 5e-4, tau);
        assert!(tau / (m as f64 * 5e-4) >= 3.0 || len / m > LADDER_MAX_FIT_SAMPLES);
    }
}

/// The noise-floor band narrows with the log's supply periods (issue 87): 1.12x up to 500
/// periods (10 s at 50 Hz, what the band was set on), half the excess at four times as many
/// (1.03x: 40 s at 50 Hz), never narrower; and the step's test reads an excess within the
/// band as nothing to explain, one beyond it as something.
#[test]
fn the_floor_band_narrows_with_the_logs_supply_periods() {
    let short = FloorBand::of_periods(200.0);
    assert_eq!(short.ratio, FLOOR_BAND);
    assert_eq!(short.excess, 0.5);
    assert_eq!(FloorBand::of_periods(f64::NAN), short);
    assert_eq!(FloorBand::of_periods(BAND_PERIODS), short);
    let long = FloorBand::of_periods(4.0 * BAND_PERIODS);
    assert!((long.excess - 0.25).abs() < 1e-12);
    assert!((long.ratio - 1.0326).abs() < 1e-3, "{}", long.ratio);
    let twice = FloorBand::of_periods(2.0 * BAND_PERIODS);
    assert!(twice.ratio < short.ratio && twice.ratio > long.ratio);
    assert_eq!(FloorBand::of_periods(100.0 * BAND_PERIODS), long);
    assert!(BAND_EXCESS_MIN == long.excess);
    // A model error 1.04x its floor (an excess of 0.29 of the floor): nothing to explain on a
    // short log, all of it explained by a model at the floor on a long one.
    assert_eq!(short.explained(1.04, 1.0, 1.0), 0.0);
    assert!((long.explained(1.04, 1.0, 1.0) - 1.0).abs() < 1e-12);
}
