//! docs/design.md's table of the effects' parameters ("The effects' parameters", §9) is
//! the effects' declarations (`analysis::effects::EffectParam`: name, unit, physical range,
//! its source, meaning) rendered: a parameter added, renamed or given another range
//! without its line there fails here, and the message holds the table to paste.
//! The typed values refuse a count that does not match.

use monitor_analysis::effects::{library, model_of, EffectParam, EffectValuesError, WindageValues};
use monitor_analysis::prep::Prepared;
use monitor_analysis::simplified_model::MachineConstants;
use monitor_io::params::ParamFile;
use std::path::Path;

/// A range bound as the docs write it: whole numbers without a point, others to 3 decimals
/// without trailing zeros.
fn num(x: f64) -> String {
    if x == x.round() && x.abs() < 1e6 {
        return format!("{x:.0}");
    }
    let s = format!("{x:.3}");
    s.trim_end_matches('0').trim_end_matches('.').to_string()
}

/// The physical range in words: `lo .. hi` in the unit, or times what it is relative to.
fn range(p: &EffectParam) -> String {
    let (lo, hi) = p.range;
    if lo.is_infinite() && hi.is_infinite() {
        return "any".into();
    }
    match p.per {
        None => format!("{} .. {}", num(lo), num(hi)),
        Some(per) => format!("{} .. {} × {per}", num(lo), num(hi)),
    }
}

/// A table cell: `|` escaped.
fn cell(s: &str) -> String {
    s.replace('|', "\\|")
}

/// The table the declarations make.
fn rendered() -> String {
    let mut t = String::from(
        "| effect | parameter | unit | physical range | meaning | source of the range |\n\
         |---|---|---|---|---|---|\n",
    );
    for e in library() {
        for p in e.parameters() {
            t.push_str(&format!(
                "| `{}` | `{}` | {} | {} | {} | {} |\n",
                e.kind(),
                p.name,
                cell(p.unit),
                cell(&range(p)),
                cell(p.doc),
                cell(p.basis)
            ));
        }
    }
    t
}

/// The first table after the heading `### The effects' parameters` in docs/design.md.
fn documented() -> String {
    let design =
        std::fs::read_to_string(Path::new(env!("CARGO_MANIFEST_DIR")).join("../../docs/design.md"))
            .expect("docs/design.md");
    let at = design
        .find("### The effects' parameters")
        .expect("the heading \"### The effects' parameters\" in docs/design.md");
    design[at..]
        .lines()
        .skip_while(|l| !l.starts_with('|'))
        .take_while(|l| l.starts_with('|'))
        .map(|l| format!("{l}\n"))
        .collect()
}

#[test]
fn the_docs_table_of_the_effects_parameters_is_the_declarations() {
    let want = rendered();
    assert!(
        documented() == want,
        "docs/design.md's table of the effects' parameters differs from the declarations; the declarations make:\n\n{want}"
    );
}

#[test]
fn each_effects_set_up_keeps_to_its_declarations() {
    let n = MachineConstants::from_params(&ParamFile::reference_2p2kw());
    let d = Prepared::default();
    for e in library() {
        // (load_torque and rotor_asymmetry need a speed column and a log to set up on.)
        let Ok(setup) = e.setup(&d, &n) else { continue };
        let declared: Vec<&str> = e.parameters().iter().map(|p| p.name).collect();
        let used: Vec<&str> = setup.params.iter().map(|p| p.declared.name).collect();
        assert_eq!(used, declared, "{}", e.kind());
        for p in &setup.params {
            assert_eq!(p.name, p.declared.name, "{}", e.kind());
        }
    }
}

#[test]
fn a_count_that_does_not_match_is_an_error_not_a_dropped_effect() {
    let err = WindageValues::try_from(&[1e-3, 2.0][..]).unwrap_err();
    assert_eq!(
        err,
        EffectValuesError::Count {
            effect: monitor_core::EffectKind::Windage.into(),
            expected: 1,
            got: 2
        }
    );
    assert_eq!(
        err.to_string(),
        "windage: 2 fitted values for its 1 parameters"
    );
    let w = WindageValues::try_from(&[1e-3][..]).expect("one value");
    assert_eq!(w.k_nms2, 1e-3);
    // The set-up refuses it too, where the model is built from fitted values.
    let n = MachineConstants::from_params(&ParamFile::reference_2p2kw());
    let d = Prepared::default();
    let setup = model_of(monitor_core::EffectKind::Windage)
        .expect("a library effect")
        .setup(&d, &n)
        .expect("windage sets up on any log");
    let mut terms = Default::default();
    assert!(setup.contribute(&[], &d, &n, &mut terms).is_err());
    assert!(setup.describe(&[1.0, 2.0], &d, &n).is_err());
    assert!(setup.contribute(&[1e-3], &d, &n, &mut terms).is_ok());
}
