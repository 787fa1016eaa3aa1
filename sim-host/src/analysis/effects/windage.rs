//! `windage`: fan and air drag.

use super::{plausible, sync_speed_mech};
use super::{EffectModel, FitSetup, ParamSpec};
use crate::analysis::prep::Prepared;
use crate::analysis::simplified_model::{EffectTerms, MachineConstants};
use monitor_core::EffectKind;

/// Fan / windage torque.
pub struct Windage;

impl EffectModel for Windage {
    fn kind(&self) -> EffectKind {
        EffectKind::Windage
    }
    fn description(&self) -> &'static str {
        "Fan and air drag: a load torque growing with the square of speed."
    }
    fn equations(&self) -> &'static str {
        "J dw_m/dt = Kf I_qs - (B + Bl) w_m - k w_m |w_m|  (eq. 29 plus a quadratic drag)."
    }
    fn parameters(&self) -> &'static [ParamSpec] {
        &[ParamSpec {
            name: "k_nms2",
            unit: "N m s^2/rad^2",
            description: "windage coefficient k",
        }]
    }
    fn setup(&self, d: &Prepared, n: &MachineConstants) -> Result<FitSetup, String> {
        let w = sync_speed_mech(d, n);
        let k = n.torque_scale_nm / (w * w);
        let mut s = FitSetup::default();
        s.push(
            "k_nms2",
            "N m s^2/rad^2",
            0.01 * k,
            -0.1 * k,
            2.0 * k,
            0.05 * k,
        );
        s.range(
            plausible::WINDAGE_RATIO.0 * k,
            plausible::WINDAGE_RATIO.1 * k,
            plausible::WINDAGE_BASIS,
        );
        s.data.push(w);
        Ok(s)
    }
    fn apply(
        &self,
        _s: &FitSetup,
        p: &[f64],
        _d: &Prepared,
        _n: &MachineConstants,
        terms: &mut EffectTerms,
    ) {
        terms.windage_nms2 = p[0];
    }
    fn describe(&self, s: &FitSetup, p: &[f64], _d: &Prepared, n: &MachineConstants) -> String {
        let w = s.data.first().copied().unwrap_or(1.0);
        format!(
            "speed-squared drag k = {:.3e} N m s^2/rad^2: {:.2} N m at synchronous speed ({:.1} % of the rated torque estimate)",
            p[0],
            p[0] * w * w,
            100.0 * p[0] * w * w / n.torque_scale_nm
        )
    }
}
