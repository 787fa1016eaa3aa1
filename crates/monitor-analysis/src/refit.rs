//! The base parameters `explain` refits to the log before it judges effects, and what it
//! does when the parameter file does not fit the log at all.
//!
//! The paper's simplified model has four base parameters (eqs. 28-29): Ra = Rs + (Ls/Lr) Rr,
//! the flux coefficient Ls (Psi = Ls i_f; the paper prints "Psi = Ls", a typo), the shaft's
//! B + Bl and J. `explain` always refits them ([`super::fit`]) and reports each with its
//! file value, its refitted value and whether the log identifies it
//! ([`super::fit::jacobian`]: a 10 % change must move the model error by at least
//! [`super::fit::IDENTIFIED_MIN`]).
//!
//! When the refit of a parameter the log identifies lands outside the physical range the
//! file's values allow (for example a coupled load whose inertia the file guesses at a
//! quarter of the truth), every effect fitted on top of it would inherit that flag and none
//! could be named; when, on the file's model, no effect can then be named, the model is
//! *recentred*: the identified base
//! parameters become the machine's constants (the file's Rs and Rr scaled together by the
//! refitted Ra, its Lm, Ls and Lr by the refitted Ls, its J by the refitted J, its Bl set so
//! that B + Bl is the refitted value), and the effects are fitted and judged against that
//! model, with their plausible ranges about it. A base parameter the log does not identify
//! keeps the file's value and is said so beside the verdict. Not recentred: a model without
//! `flux_dynamics` and `current_dynamics` on a log with a start or a supply step, whose base
//! parameters are flagged because they absorb the dynamics it cannot follow (the verdict
//! gives that advice instead).

use super::fit::Jacobian;
use super::simplified_model::{BaseParameter, BaseParams, MachineConstants};
use monitor_io::params::ParamFile;
use serde::Serialize;

/// A refitted value that differs from the file's by less than this fraction is not
/// reported as refitted in words (it is still in the JSON).
pub const REPORT_MIN_CHANGE: f64 = 0.02;

/// One base parameter: the file's value, the value refitted to the log, and whether the
/// log identifies it.
#[derive(Debug, Clone, Serialize)]
pub struct RefittedParameter {
    /// Which (JSON: its key, as in `compare`'s `base_parameters`: `ra_ohm`, `ls_h`,
    /// `b_plus_bl_nms`, `j_kgm2`).
    pub parameter: BaseParameter,
    /// Unit.
    pub unit: &'static str,
    /// The parameter file's value.
    pub configured: f64,
    /// The value refitted to the log.
    pub refitted: f64,
    /// Whether the log identifies it (see the module doc); `false` when no Jacobian could
    /// be formed.
    pub identified: bool,
}

impl RefittedParameter {
    /// Relative change `refitted / configured - 1` (0 when the file's value is 0).
    pub fn change(&self) -> f64 {
        if self.configured.abs() > 0.0 {
            self.refitted / self.configured - 1.0
        } else {
            0.0
        }
    }
}

/// What `explain` did with the base parameters (its report's `base_refit`).
#[derive(Debug, Clone, Serialize)]
pub struct BaseRefit {
    /// The four base parameters, file value against refitted value.
    pub parameters: Vec<RefittedParameter>,
    /// True when the file's values did not fit the log (the refit was outside their
    /// physical range) and the effects were judged against a model recentred on the
    /// identified refitted values (see the module doc).
    pub recentred: bool,
    /// Why the file's values did not fit (empty unless `recentred`).
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub because: Vec<String>,
}

impl BaseRefit {
    /// The refit `b` of the file's constants `n`, with the identifiability of `jac`.
    pub fn new(n: &MachineConstants, b: &BaseParams, jac: Option<&Jacobian>) -> Self {
        let identified = |key: BaseParameter| {
            jac.and_then(|j| j.base.iter().find(|s| s.parameter == key))
                .is_some_and(|s| s.identified)
        };
        let p = |parameter: BaseParameter, configured: f64, refitted: f64| RefittedParameter {
            parameter,
            unit: parameter.unit(),
            configured,
            refitted,
            identified: identified(parameter),
        };
        BaseRefit {
            parameters: vec![
                p(BaseParameter::Ra, n.ra_ohm, n.ra_ohm * b.ra_scale),
                p(BaseParameter::Ls, n.ls_h, n.ls_h * b.ls_scale),
                p(BaseParameter::BPlusBl, n.btot_nms, b.btot_nms),
                p(BaseParameter::J, n.j_kgm2, n.j_kgm2 * b.j_scale),
            ],
            recentred: false,
            because: vec![],
        }
    }

    /// Whether the log identifies base parameter `key`.
    pub fn identifies(&self, key: BaseParameter) -> bool {
        self.parameters
            .iter()
            .any(|r| r.parameter == key && r.identified)
    }

    /// The parameter file with the identified refitted values in place of the file's (the
    /// module doc says how each maps onto the file's parameters). Values the log does not
    /// identify are kept.
    pub fn recentred_params(&self, p: &ParamFile) -> ParamFile {
        let mut q = *p;
        let m = &mut q.motor;
        for r in self.parameters.iter().filter(|r| r.identified) {
            let s = r.change() + 1.0;
            if !(s.is_finite() && s > 0.0) && r.parameter != BaseParameter::BPlusBl {
                continue;
            }
            match r.parameter {
                BaseParameter::Ra => {
                    m.rs_ohm *= s;
                    m.rr_ohm *= s;
                }
                BaseParameter::Ls => {
                    m.ls_h *= s;
                    m.lm_h *= s;
                    m.lr_h *= s;
                }
                BaseParameter::J => m.j_kgm2 *= s,
                BaseParameter::BPlusBl => {
                    let btot = r.refitted.max(0.0);
                    m.b_nms = m.b_nms.min(btot);
                    m.bl_nms = btot - m.b_nms;
                }
            }
        }
        q
    }

    /// The refitted parameters said beside the verdict: identified and changed by
    /// [`REPORT_MIN_CHANGE`] or more.
    pub fn changed(&self) -> impl Iterator<Item = &RefittedParameter> {
        self.parameters
            .iter()
            .filter(|r| r.identified && r.change().abs() >= REPORT_MIN_CHANGE)
    }

    /// The parameters the log does not identify (kept near the file's values).
    pub fn unidentified(&self) -> impl Iterator<Item = &RefittedParameter> {
        self.parameters.iter().filter(|r| !r.identified)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::fit::ParameterSensitivity;

    fn file() -> ParamFile {
        ParamFile::from_toml_str(
            "[motor]\nrs_ohm = 0.435\nrr_ohm = 0.816\nls_h = 0.0713\nlr_h = 0.0713\nlm_h = 0.0693\npoles = 4\nj_kgm2 = 0.089\nb_nms = 0.002\nbl_nms = 0.045\n[supply]\nv_ll_rms = 220.0\nf_hz = 60.0\n",
            "test",
        )
        .expect("valid file") // ok: test
    }

    fn jac(identified: [bool; 4]) -> Jacobian {
        Jacobian {
            n_parameters: 4,
            rank: 4,
            condition_number: 1.0,
            base: BaseParameter::ALL
                .iter()
                .zip(identified)
                .map(|(&parameter, identified)| ParameterSensitivity {
                    parameter,
                    error_change_per_10_percent: if identified { 0.1 } else { 0.0 },
                    identified,
                })
                .collect(),
        }
    }

    #[test]
    fn recentring_moves_identified_parameters_only_and_keeps_ratios() {
        let p = file();
        let n = MachineConstants::from_params(&p);
        let b = BaseParams {
            ra_scale: 1.5,
            ls_scale: 0.8,
            btot_nms: 0.1,
            j_scale: 2.0,
        };
        let r = BaseRefit::new(&n, &b, Some(&jac([true, true, true, false])));
        let q = r.recentred_params(&p);
        let nq = MachineConstants::from_params(&q);
        // Ra = Rs + (Ls/Lr) Rr scales with Rs and Rr together; Ls with Lm, Ls, Lr.
        assert!((nq.ra_ohm / n.ra_ohm - 1.5).abs() < 1e-9);
        assert!((nq.ls_h / n.ls_h - 0.8).abs() < 1e-9);
        assert!((q.motor.rs_ohm / q.motor.rr_ohm - p.motor.rs_ohm / p.motor.rr_ohm).abs() < 1e-12);
        assert!((nq.btot_nms - 0.1).abs() < 1e-12);
        // J is not identified: kept.
        assert_eq!(q.motor.j_kgm2, p.motor.j_kgm2);
        // Said beside the verdict: Ra's +50 % among the changes, J as not identified.
        let ra = r.changed().find(|x| x.parameter == BaseParameter::Ra);
        assert!(ra.is_some_and(|x| (x.change() - 0.5).abs() < 1e-9), "{r:?}");
        let unidentified: Vec<BaseParameter> = r.unidentified().map(|x| x.parameter).collect();
        assert_eq!(unidentified, [BaseParameter::J], "{r:?}");
    }

    #[test]
    fn without_a_jacobian_nothing_is_identified_or_moved() {
        let p = file();
        let n = MachineConstants::from_params(&p);
        let b = BaseParams {
            ra_scale: 1.5,
            ls_scale: 1.0,
            btot_nms: n.btot_nms,
            j_scale: 1.0,
        };
        let r = BaseRefit::new(&n, &b, None);
        assert!(r.parameters.iter().all(|x| !x.identified));
        assert_eq!(r.recentred_params(&p).motor.rs_ohm, p.motor.rs_ohm);
    }
}
