//! Issue 86, item 3: no number out of physics printed as a finding. A fitted effect value
//! pinned at a bound of its fit is "at the bound of its fit", not a value the log shows;
//! a saturation law that takes Lm below what a running motor keeps is not plausible. On
//! motulator's 2.2 kW log of a machine without saturation (`kw2p2_control`), `compare
//! --effects saturation` named saturation with its exponent at its fit's bound (14.0) as a
//! finding. About 2 s.

mod analysis_common;
use analysis_common::*;
use monitor_analysis::effects::{EffectModel, Saturation};
use monitor_core::EffectKind;
use monitor_io::params::ParamFile;
use std::path::Path;

#[test]
fn an_effect_value_at_its_fit_bound_or_an_lm_no_motor_keeps_is_no_finding() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../sim-host/tests/data/motulator");
    let p = ParamFile::load(&dir.join("kw2p2.toml")).expect("params"); // ok: test
    let a = analyse(&dir.join("kw2p2_control.csv"), &p, 1.0);
    let s = Saturation.setup(&a.data, &a.constants).expect("set up"); // ok: test
    let psi = &s.params[0];
    let inside = [psi.init, 7.0];
    assert!(s.pinned(&inside).is_empty(), "{:?}", s.pinned(&inside));
    for pinned in [[psi.init, 14.0], [psi.hi, 7.0], [psi.init, 2.0]] {
        let why = s.pinned(&pinned);
        assert_eq!(why.len(), 1, "{pinned:?}: {why:?}");
        assert!(why[0].contains("at the bound of its fit"), "{why:?}");
    }
    // A knee at half the log's flux, as sharp as the fit allows: Lm a few per cent of its
    // unsaturated value, no running motor's.
    let deep = Saturation
        .contradicted_by(&a.data, &a.constants, &[psi.lo, 14.0])
        .expect("values"); // ok: test
    assert!(deep.is_some(), "{deep:?}");
    let mild = Saturation
        .contradicted_by(&a.data, &a.constants, &[2.0 * psi.init, 7.0])
        .expect("values"); // ok: test
    assert!(mild.is_none(), "{mild:?}");
    // What compare reports of it on this log: the exponent ends at its bound, no finding.
    let c = a.compare(&opts(&["saturation"])).expect("compare").report; // ok: test
    let sat = c
        .fitted_effects
        .iter()
        .find(|e| e.effect == EffectKind::Saturation)
        .expect("saturation fitted"); // ok: test
    assert!(!sat.plausible, "{sat:?}");
    assert!(
        sat.implausible_because
            .iter()
            .any(|w| w.contains("at the bound of its fit") || w.contains("unsaturated")),
        "{:?}",
        sat.implausible_because
    );
}
