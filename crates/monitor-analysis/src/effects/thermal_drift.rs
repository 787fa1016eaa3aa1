//! `thermal_drift`: winding temperature rise.

use super::{
    declared_values, duration, plausible, About, Contribution, EffectModel, EffectParam,
    EffectValuesError, FitSetup, SetupError,
};
use crate::prep::Prepared;
use crate::simplified_model::{MachineConstants, ModelTerms};
use monitor_core::EffectKind;

/// Copper temperature coefficient of resistance [1/K] (0.393 %/K at 20 C).
pub const ALPHA_CU_PER_K: f64 = 0.00393;

/// Winding temperature rise: Rs and Rr follow copper's coefficient.
#[derive(Debug, Clone, Copy)]
pub struct ThermalDrift;

/// Thermal drift's parameters.
const PARAMS: [EffectParam; 2] = [
    EffectParam {
        name: "rise_k",
        unit: "K",
        doc: "final winding temperature rise",
        range: plausible::RISE_K,
        per: None,
        basis: plausible::RISE_K_BASIS,
    },
    EffectParam {
        name: "tau_s",
        unit: "s",
        doc: "thermal time constant",
        range: plausible::TAU_S,
        per: None,
        basis: plausible::TAU_S_BASIS,
    },
];

/// Thermal drift's fitted values ([`PARAMS`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ThermalDriftValues {
    /// The final temperature rise [K] (negative: cooling).
    pub rise_k: f64,
    /// The thermal time constant [s].
    pub tau_s: f64,
}

impl TryFrom<&[f64]> for ThermalDriftValues {
    type Error = EffectValuesError;
    fn try_from(v: &[f64]) -> Result<Self, EffectValuesError> {
        let [rise_k, tau_s] = declared_values(EffectKind::ThermalDrift, &PARAMS, v)?;
        Ok(ThermalDriftValues { rise_k, tau_s })
    }
}

/// What `ThermalDrift` is ([`About`]).
const ABOUT: About = About {
    kind: EffectKind::ThermalDrift,
    description: "The windings heat up with load, so the stator and rotor resistances rise (copper: +0.393 %/K; 20 -> 90 C is +27 %).",
    equations: "Rs(t), Rr(t) = R (1 + 0.00393 dT(t)), dT(t) = rise_k (1 - exp(-(t - t0)/tau_s)); Ra = Rs + (Ls/Lr) Rr in eq. (28) follows; in the full-order model the rotor time constant Lr/Rr follows too.",
    parameters: &PARAMS,
};

impl EffectModel for ThermalDrift {
    fn about(&self) -> &About {
        &ABOUT
    }
    fn setup(&self, d: &Prepared, _n: &MachineConstants) -> Result<FitSetup, SetupError> {
        let t = duration(d);
        let [rise_k, tau_s] = &PARAMS;
        let params = vec![
            rise_k.fit(10.0, (-100.0, 400.0), 20.0, 1.0),
            tau_s.fit(t / 3.0, (t / 200.0, 20.0 * t), t / 3.0, 1.0),
        ];
        Ok(FitSetup::new(*self, params)?)
    }
}

impl Contribution for ThermalDrift {
    type Values = ThermalDriftValues;
    fn values(&self, v: &[f64]) -> Result<ThermalDriftValues, EffectValuesError> {
        ThermalDriftValues::try_from(v)
    }
    /// The resistance scale 1 + alpha dT(t) per sample (Rs and Rr alike).
    fn contribute(
        &self,
        p: &ThermalDriftValues,
        d: &Prepared,
        _n: &MachineConstants,
        t: &mut ModelTerms,
    ) {
        let ThermalDriftValues { rise_k, tau_s } = *p;
        let t0 = d.t_s.first().copied().unwrap_or(0.0);
        let tau = tau_s.max(1e-6);
        t.scale_resistances(
            d.t_s
                .iter()
                .map(|t| 1.0 + ALPHA_CU_PER_K * rise_k * (1.0 - (-(t - t0) / tau).exp())),
        );
    }
    fn describe(&self, p: &ThermalDriftValues, d: &Prepared, _n: &MachineConstants) -> String {
        let ThermalDriftValues { rise_k, tau_s } = *p;
        let t = duration(d);
        let dt_end = rise_k * (1.0 - (-t / tau_s.max(1e-6)).exp());
        format!(
            "winding resistance {} {:.0} % over the run ({:.0} s), consistent with about {:.0} K of {} (copper 0.393 %/K); thermal time constant about {:.3} s",
            if dt_end >= 0.0 { "rises" } else { "falls" },
            (ALPHA_CU_PER_K * dt_end * 100.0).abs(),
            t,
            dt_end.abs(),
            if dt_end >= 0.0 { "heating" } else { "cooling" },
            tau_s
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The case: `thermal_drift` "explaining" a gap in the data as 400 K of heating
    /// with a 0.01 s time constant is not plausible, and both values are named; a heat
    /// run of 60 K over 10 min is.
    #[test]
    fn thermal_drift_of_400_k_in_10_ms_is_not_plausible() {
        let d = Prepared {
            t_s: vec![0.0, 5.0],
            dt_s: 5.0,
            ..Default::default()
        };
        let n = MachineConstants::from_params(&monitor_io::params::ParamFile::reference_2p2kw());
        let s = ThermalDrift.setup(&d, &n).unwrap();
        let why = s.implausible(&[400.0, 0.01]);
        assert_eq!(why.len(), 2, "{why:?}");
        assert!(why[0].starts_with("rise_k = 400 K"), "{why:?}");
        assert!(why[1].starts_with("tau_s = 0.0100 s"), "{why:?}");
        assert!(s.implausible(&[60.0, 600.0]).is_empty());
        // Cooling of a log that starts warm is plausible, cooling below ambient is not.
        assert!(s.implausible(&[-30.0, 600.0]).is_empty());
        assert_eq!(s.implausible(&[-80.0, 600.0]).len(), 1);
    }
}
