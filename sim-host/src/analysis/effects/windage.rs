//! `windage`: fan and air drag.

use super::{
    plausible, sync_speed_mech, About, Contribution, EffectModel, FitParam, FitSetup, ParamSpec,
    SetupError,
};
use crate::analysis::prep::Prepared;
use crate::analysis::simplified_model::{MachineConstants, ModelTerms, SpeedTorque};
use monitor_core::EffectKind;

/// Fan / windage torque.
#[derive(Debug, Clone, Copy)]
pub struct Windage;

/// Windage set up on a log: the log's highest synchronous speed.
struct OnLog {
    /// [rad/s], mechanical.
    sync_speed_rad_s: f64,
}

/// A drag torque `k w_m |w_m|` on the shaft.
#[derive(Debug, Clone, Copy)]
struct Drag {
    /// k [N m s^2/rad^2].
    k_nms2: f64,
}

impl SpeedTorque for Drag {
    fn torque_nm(&self, wm_rad_s: f64) -> f64 {
        self.k_nms2 * wm_rad_s * wm_rad_s.abs()
    }
}

/// What `Windage` is ([`About`]).
const ABOUT: About = About {
    kind: EffectKind::Windage,
    description: "Fan and air drag: a load torque growing with the square of speed.",
    equations: "J dw_m/dt = Kf I_qs - (B + Bl) w_m - k w_m |w_m|  (eq. 29 plus a quadratic drag).",
    parameters: &[ParamSpec {
        name: "k_nms2",
        unit: "N m s^2/rad^2",
        description: "windage coefficient k",
    }],
};

impl EffectModel for Windage {
    fn about(&self) -> &About {
        &ABOUT
    }
    fn setup(&self, d: &Prepared, n: &MachineConstants) -> Result<FitSetup, SetupError> {
        let w = sync_speed_mech(d, n);
        let k = n.torque_scale_nm / (w * w);
        let r = plausible::WINDAGE_RATIO;
        Ok(FitSetup::new(OnLog {
            sync_speed_rad_s: w,
        })
        .param(
            FitParam::new(
                "k_nms2",
                "N m s^2/rad^2",
                0.01 * k,
                (-0.1 * k, 2.0 * k),
                0.05 * k,
            )
            .physical_scaled(r, k, plausible::WINDAGE_BASIS),
        ))
    }
}

impl Contribution for OnLog {
    /// The drag torque on the shaft.
    fn contribute(&self, p: &[f64], _d: &Prepared, _n: &MachineConstants, t: &mut ModelTerms) {
        if let &[k_nms2] = p {
            t.add_speed_torque(Drag { k_nms2 });
        }
    }
    fn describe(&self, p: &[f64], _d: &Prepared, n: &MachineConstants) -> String {
        let &[k] = p else {
            return String::new();
        };
        let w = self.sync_speed_rad_s;
        format!(
            "speed-squared drag k = {:.3e} N m s^2/rad^2: {:.2} N m at synchronous speed ({:.1} % of the rated torque estimate)",
            k,
            k * w * w,
            100.0 * k * w * w / n.torque_scale_nm
        )
    }
}
