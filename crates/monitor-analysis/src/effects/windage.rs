//! `windage`: fan and air drag.

use super::{
    declared_values, plausible, sync_speed_mech, About, Contribution, EffectModel, EffectParam,
    EffectValuesError, FitSetup, SetupError,
};
use crate::prep::Prepared;
use crate::simplified_model::{MachineConstants, ModelTerms, SpeedTorque};
use monitor_laws::EffectId;

/// Fan / windage torque.
#[derive(Debug, Clone, Copy)]
pub struct Windage;

/// Windage's parameters.
const PARAMS: [EffectParam; 1] = [EffectParam {
    name: "k_nms2",
    unit: "N m s^2/rad^2",
    doc: "windage coefficient k",
    range: plausible::WINDAGE_RATIO,
    per: Some("the rated torque estimate over the square of the log's highest synchronous speed"),
    basis: plausible::WINDAGE_BASIS,
}];

/// Windage's fitted values ([`PARAMS`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct WindageValues {
    /// The drag coefficient k [N m s^2/rad^2].
    pub k_nms2: f64,
}

impl TryFrom<&[f64]> for WindageValues {
    type Error = EffectValuesError;
    fn try_from(v: &[f64]) -> Result<Self, EffectValuesError> {
        let [k_nms2] = declared_values(EffectId::WINDAGE, &PARAMS, v)?;
        Ok(WindageValues { k_nms2 })
    }
}

/// Windage set up on a log: the log's highest synchronous speed.
struct WindageOnLog {
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
    /// The library's windage law ([`monitor_laws::library::windage_nm`], the simulator's).
    fn torque_nm(&self, wm_rad_s: f64) -> f64 {
        monitor_laws::library::windage_nm(self.k_nms2, wm_rad_s)
    }
}

/// What `Windage` is ([`About`]).
const ABOUT: About = About {
    kind: EffectId::WINDAGE,
    description: "Fan and air drag: a load torque growing with the square of speed.",
    equations: "J dw_m/dt = Kf I_qs - (B + Bl) w_m - k w_m |w_m|  (eq. 29 plus a quadratic drag).",
    parameters: &PARAMS,
};

impl EffectModel for Windage {
    fn about(&self) -> &About {
        &ABOUT
    }
    /// The drag carries its speed-dependent torque itself: B + Bl is free to fall to zero.
    fn takes_viscous_part(&self) -> bool {
        true
    }
    fn load_torque_at(&self, values: &[f64], w_rad_s: f64) -> Option<f64> {
        match values {
            [k] => Some(monitor_laws::library::windage_nm(*k, w_rad_s)),
            _ => None,
        }
    }
    fn setup(&self, d: &Prepared, n: &MachineConstants) -> Result<FitSetup, SetupError> {
        let w = sync_speed_mech(d, n);
        let k = n.torque_scale_nm / (w * w);
        let [k_nms2] = &PARAMS;
        let params = vec![k_nms2.fit(0.01 * k, (-0.1 * k, 2.0 * k), 0.05 * k, k)];
        Ok(FitSetup::new(
            WindageOnLog {
                sync_speed_rad_s: w,
            },
            params,
        )?)
    }
}

impl Contribution for WindageOnLog {
    type Values = WindageValues;
    fn values(&self, v: &[f64]) -> Result<WindageValues, EffectValuesError> {
        WindageValues::try_from(v)
    }
    /// The drag torque on the shaft.
    fn contribute(
        &self,
        p: &WindageValues,
        _d: &Prepared,
        _n: &MachineConstants,
        t: &mut ModelTerms,
    ) {
        t.add_speed_torque(Drag { k_nms2: p.k_nms2 });
    }
    fn describe(&self, p: &WindageValues, _d: &Prepared, n: &MachineConstants) -> String {
        let (k, w) = (p.k_nms2, self.sync_speed_rad_s);
        format!(
            "speed-squared drag k = {:.3e} N m s^2/rad^2: {:.2} N m at synchronous speed ({:.1} % of the rated torque estimate)",
            k,
            k * w * w,
            100.0 * k * w * w / n.torque_scale_nm
        )
    }
}
