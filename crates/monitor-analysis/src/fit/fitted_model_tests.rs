//! Tests of the fitted model's description ([`super::FittedModel`]).

use super::*;
use crate::effects::model_of;
use monitor_laws::EffectId;

#[test]
fn a_fitted_model_says_what_it_is() {
    let n = MachineConstants::from_params(&monitor_io::params::ParamFile::reference_2p2kw());
    let d = Prepared::default();
    let cd = model_of(EffectId::CURRENT_DYNAMICS).expect("a library effect");
    let setup = cd.setup(&d, &n).unwrap();
    let m = FittedModel {
        effects: vec![ActiveEffect {
            effect: cd.as_ref(),
            setup,
        }],
        fit: FitResult {
            base: BaseParams {
                ra_scale: 1.05,
                ls_scale: 0.98,
                btot_nms: 0.01,
                j_scale: 1.2,
            },
            effect_params: vec![vec![0.0321]],
            report: lm::Report {
                iterations: 7,
                cost: 1.5e-5,
                termination: lm::Termination::Converged,
            },
            corrected: None,
        },
    };
    let s = m.to_string();
    assert!(
        s.starts_with("paper's model + current_dynamics; Ra x1.05"),
        "{s}"
    );
    assert!(s.contains("la_h = 0.0321 H"), "{s}");
    assert!(
        s.ends_with("fit converged after 7 iterations, cost 1.50e-5"),
        "{s}"
    );
    // An empty series predicts nothing (and does not panic).
    assert!(m
        .predict(&d, &n)
        .expect("one value per parameter")
        .iq
        .is_empty());
}
