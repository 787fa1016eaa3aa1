//! `thermal_drift`: winding temperature rise.

use super::{
    declared_values, duration, plausible, About, Contribution, EffectModel, EffectParam,
    EffectValuesError, FitSetup, SetupError,
};
use crate::prep::Prepared;
use crate::simplified_model::{MachineConstants, ModelTerms};
use monitor_laws::EffectId;

/// Copper temperature coefficient of resistance [1/K] (0.393 %/K at 20 C): the stator
/// winding (IEC 60034-1's resistance method of temperature rise uses 235 K + T, the same
/// slope).
pub const ALPHA_CU_PER_K: f64 = 0.00393;
/// Aluminium temperature coefficient of resistance [1/K] (0.403 %/K at 20 C, IEC 60028's
/// 228 K + T for hard-drawn aluminium): the die-cast rotor cage of a low-voltage motor.
pub const ALPHA_AL_PER_K: f64 = 0.00403;

/// How the windings' temperatures are fitted.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Windings {
    /// One rise for both (`rise_k`, `tau_s`): `compare`'s and `explain`'s law, whose base
    /// refit reads Ra = Rs + (Ls/Lr) Rr and cannot tell the file's Rs from its Rr (with
    /// the windings apart, a file with Rr 20 % high and Lm 20 % low took +268 K on the stator
    /// and -99 K on the rotor for them).
    Together,
    /// The stator and the rotor apart (`stator_rise_k`, `rotor_rise_k`, `tau_s`): the
    /// ladder's law, on a base that reads Rs and Rr apart (its base rung): a stator heating
    /// alone (a loosening connection, a winding's own loss) is not a rise of both.
    Apart,
}

/// Winding temperature rise during the log, each winding from the temperature it had when
/// the log began: both windings by one rise ([`Windings::Together`]) or the stator and the
/// rotor apart ([`Windings::Apart`]). A motor already warm at the start is a change of the
/// base parameters (the ladder's base rung reads Rs and Rr against the file), and this
/// effect is the rise on top of it.
#[derive(Debug, Clone, Copy)]
pub struct ThermalDrift {
    /// Which law.
    pub windings: Windings,
}

impl ThermalDrift {
    /// Both windings by one rise (the library's default).
    pub const TOGETHER: ThermalDrift = ThermalDrift {
        windings: Windings::Together,
    };
    /// The stator and the rotor apart (the ladder's).
    pub const APART: ThermalDrift = ThermalDrift {
        windings: Windings::Apart,
    };
}

/// The law of both windings together's parameters.
const PARAMS: [EffectParam; 2] = [
    EffectParam {
        name: "rise_k",
        unit: "K",
        doc: "final winding temperature rise",
        range: plausible::RISE_K,
        per: None,
        basis: plausible::RISE_K_BASIS,
    },
    TAU,
];

/// The thermal time constant.
const TAU: EffectParam = EffectParam {
    name: "tau_s",
    unit: "s",
    doc: "thermal time constant",
    range: plausible::TAU_S,
    per: None,
    basis: plausible::TAU_S_BASIS,
};

/// The law of the windings apart's parameters.
const PARAMS_APART: [EffectParam; 3] = [
    EffectParam {
        name: "stator_rise_k",
        unit: "K",
        doc: "final stator winding temperature rise over the log's start",
        range: plausible::RISE_K,
        per: None,
        basis: plausible::RISE_K_BASIS,
    },
    EffectParam {
        name: "rotor_rise_k",
        unit: "K",
        doc: "final rotor cage temperature rise over the log's start",
        range: plausible::RISE_K,
        per: None,
        basis: plausible::RISE_K_BASIS,
    },
    TAU,
];

/// Thermal drift's fitted values: the stator's and the rotor's rises (equal to one another
/// in copper's terms where the windings are fitted together) and the time constant.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ThermalDriftValues {
    /// The stator's final temperature rise over the log's start [K] (negative: cooling).
    pub stator_rise_k: f64,
    /// The rotor's final temperature rise over the log's start [K] (negative: cooling).
    pub rotor_rise_k: f64,
    /// The thermal time constant [s].
    pub tau_s: f64,
}

impl ThermalDrift {
    /// The values `v` of this law.
    ///
    /// # Errors
    /// [`EffectValuesError`] when `v` does not hold one value per parameter.
    pub fn values_of(&self, v: &[f64]) -> Result<ThermalDriftValues, EffectValuesError> {
        match self.windings {
            Windings::Together => {
                let [rise_k, tau_s] = declared_values(EffectId::THERMAL_DRIFT, &PARAMS, v)?;
                // One rise of the resistances: the cage's aluminium takes it at its own
                // coefficient.
                Ok(ThermalDriftValues {
                    stator_rise_k: rise_k,
                    rotor_rise_k: rise_k * ALPHA_CU_PER_K / ALPHA_AL_PER_K,
                    tau_s,
                })
            }
            Windings::Apart => {
                let [stator_rise_k, rotor_rise_k, tau_s] =
                    declared_values(EffectId::THERMAL_DRIFT, &PARAMS_APART, v)?;
                Ok(ThermalDriftValues {
                    stator_rise_k,
                    rotor_rise_k,
                    tau_s,
                })
            }
        }
    }
}

impl ThermalDriftValues {
    /// The rise at `t` [s] after the log's start of a final rise `rise` [K].
    fn rise_at(&self, rise: f64, t: f64) -> f64 {
        monitor_laws::library::heating_rise_k(rise, self.tau_s.max(1e-6), 0.0, t)
    }
}

/// What `ThermalDrift` is, both windings together ([`About`]).
const ABOUT: About = About {
    kind: EffectId::THERMAL_DRIFT,
    description: "The windings heat up with load, so the stator and rotor resistances rise (copper: +0.393 %/K; 20 -> 90 C is +27 %); a motor already warm when the log starts is a change of the base parameters, this is the rise on top of it.",
    equations: "Rs(t), Rr(t) = R (1 + 0.00393 dT(t)), dT(t) = rise_k (1 - exp(-(t - t0)/tau_s)) from the log's start t0; Ra = Rs + (Ls/Lr) Rr in eq. (28) follows; in the full-order model the rotor time constant Lr/Rr follows too. The ladder fits this law and the stator and the rotor apart (stator_rise_k at copper's 0.393 %/K, rotor_rise_k at the cage's aluminium 0.403 %/K), and names the one the log tells best.",
    parameters: &PARAMS,
};

/// What `ThermalDrift` is, the windings apart ([`About`]).
const ABOUT_APART: About = About {
    kind: EffectId::THERMAL_DRIFT,
    description: "The windings heat up with load, the stator and the rotor apart, so their resistances rise (stator copper +0.393 %/K, rotor aluminium +0.403 %/K); a motor already warm when the log starts is a change of the base parameters, this is the rise on top of it.",
    equations: "Rs(t) = Rs (1 + 0.00393 dTs(t)), Rr(t) = Rr (1 + 0.00403 dTr(t)), dTx(t) = x_rise_k (1 - exp(-(t - t0)/tau_s)) from the log's start t0; Ra = Rs + (Ls/Lr) Rr in eq. (28) follows; in the full-order model the rotor time constant Lr/Rr follows too.",
    parameters: &PARAMS_APART,
};

impl EffectModel for ThermalDrift {
    /// A warming winding's resistance is what the voltages' noise biases upwards (the
    /// trait's doc): 112 K for 50 K on the 3 hp machine at 0.5 V of noise.
    fn biased_by_input_noise(&self) -> bool {
        true
    }
    fn about(&self) -> &About {
        match self.windings {
            Windings::Together => &ABOUT,
            Windings::Apart => &ABOUT_APART,
        }
    }
    fn setup(&self, d: &Prepared, _n: &MachineConstants) -> Result<FitSetup, SetupError> {
        let t = duration(d);
        let tau = TAU.fit(t / 3.0, (t / 200.0, 20.0 * t), t / 3.0, 1.0);
        match self.windings {
            Windings::Together => {
                let [rise_k, _] = &PARAMS;
                let params = vec![rise_k.fit(10.0, (-100.0, 400.0), 20.0, 1.0), tau];
                Ok(FitSetup::new(*self, params)?)
            }
            Windings::Apart => {
                let [stator, rotor, _] = &PARAMS_APART;
                let params = vec![
                    stator.fit(10.0, (-100.0, 400.0), 20.0, 1.0),
                    rotor.fit(10.0, (-100.0, 400.0), 20.0, 1.0),
                    tau,
                ];
                // A rise the log ends in the middle of: also started from a time constant
                // as long as the log (a drift that is still nearly linear at the end).
                let alt = vec![vec![20.0, 5.0, t]];
                Ok(FitSetup::new(*self, params)?.with_alt_init(alt)?)
            }
        }
    }
}

impl Contribution for ThermalDrift {
    type Values = ThermalDriftValues;
    fn values(&self, v: &[f64]) -> Result<ThermalDriftValues, EffectValuesError> {
        self.values_of(v)
    }
    /// The rotor's scale `1 + alpha_al dTr(t)` on both resistances, and the stator's own
    /// `(1 + alpha_cu dTs(t)) / (1 + alpha_al dTr(t))` on Rs.
    fn contribute(
        &self,
        p: &ThermalDriftValues,
        d: &Prepared,
        _n: &MachineConstants,
        t: &mut ModelTerms,
    ) {
        let t0 = d.t_s.first().copied().unwrap_or(0.0);
        let rotor = |t: f64| 1.0 + ALPHA_AL_PER_K * p.rise_at(p.rotor_rise_k, t - t0);
        let stator = |t: f64| 1.0 + ALPHA_CU_PER_K * p.rise_at(p.stator_rise_k, t - t0);
        t.scale_resistances(d.t_s.iter().map(|&t| rotor(t)));
        if self.windings == Windings::Apart {
            t.scale_stator_resistance(d.t_s.iter().map(|&t| stator(t) / rotor(t).max(1e-6)));
        }
    }
    fn describe(&self, p: &ThermalDriftValues, d: &Prepared, _n: &MachineConstants) -> String {
        let t = duration(d);
        let (ds, dr) = (p.rise_at(p.stator_rise_k, t), p.rise_at(p.rotor_rise_k, t));
        let word = |x: f64| if x >= 0.0 { "heats" } else { "cools" };
        match self.windings {
            Windings::Together => format!(
                "winding resistance {} {:.0} % over the run ({:.0} s), consistent with about {:.0} K of {} (copper 0.393 %/K); thermal time constant about {:.3} s",
                if ds >= 0.0 { "rises" } else { "falls" },
                (ALPHA_CU_PER_K * ds * 100.0).abs(),
                t,
                ds.abs(),
                if ds >= 0.0 { "heating" } else { "cooling" },
                p.tau_s
            ),
            Windings::Apart => format!(
                "the windings' temperatures move over the run ({:.0} s): the stator {} by about {:.0} K (Rs {:+.0} %), the rotor {} by about {:.0} K (Rr {:+.0} %); thermal time constant about {:.3} s",
                t,
                word(ds),
                ds.abs(),
                100.0 * ALPHA_CU_PER_K * ds,
                word(dr),
                dr.abs(),
                100.0 * ALPHA_AL_PER_K * dr,
                p.tau_s
            ),
        }
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
        let s = ThermalDrift::TOGETHER.setup(&d, &n).unwrap();
        let why = s.implausible(&[400.0, 0.01]);
        assert_eq!(why.len(), 2, "{why:?}");
        assert!(why[0].starts_with("rise_k = 400 K"), "{why:?}");
        assert!(why[1].starts_with("tau_s = 0.0100 s"), "{why:?}");
        let s = ThermalDrift::APART.setup(&d, &n).unwrap();
        let why = s.implausible(&[400.0, 0.0, 0.01]);
        assert_eq!(why.len(), 2, "{why:?}");
        assert!(why[0].starts_with("stator_rise_k = 400 K"), "{why:?}");
        assert!(why[1].starts_with("tau_s = 0.0100 s"), "{why:?}");
        assert!(s.implausible(&[60.0, 40.0, 600.0]).is_empty());
        // Cooling of a log that starts warm is plausible, cooling below ambient is not.
        assert!(s.implausible(&[-30.0, -20.0, 600.0]).is_empty());
        assert_eq!(s.implausible(&[-80.0, 0.0, 600.0]).len(), 1);
    }

    /// The stator and the rotor apart: a stator-only rise moves Rs alone; the rotor's moves
    /// both resistances' common scale and leaves Rs's own at 1 / (that scale) x its own.
    #[test]
    fn the_stator_and_the_rotor_heat_apart() {
        let d = Prepared {
            t_s: vec![0.0, 1.0, 1e4],
            dt_s: 1.0,
            ..Default::default()
        };
        let n = MachineConstants::from_params(&monitor_io::params::ParamFile::reference_2p2kw());
        let mut t = ModelTerms::default();
        let p = ThermalDriftValues {
            stator_rise_k: 70.0,
            rotor_rise_k: 0.0,
            tau_s: 3.0,
        };
        ThermalDrift::APART.contribute(&p, &d, &n, &mut t);
        assert!(t.resistance.scale.iter().all(|s| (s - 1.0).abs() < 1e-12));
        let end = t.resistance.stator_scale[2];
        assert!((end - (1.0 + 0.00393 * 70.0)).abs() < 1e-9, "{end}");
        assert_eq!(t.resistance.stator_scale[0], 1.0);
        let mut t = ModelTerms::default();
        let p = ThermalDriftValues {
            stator_rise_k: 50.0,
            rotor_rise_k: 50.0,
            tau_s: 3.0,
        };
        ThermalDrift::APART.contribute(&p, &d, &n, &mut t);
        let (r, s) = (t.resistance.scale[2], t.resistance.stator_scale[2]);
        assert!((r - (1.0 + 0.00403 * 50.0)).abs() < 1e-9);
        assert!((r * s - (1.0 + 0.00393 * 50.0)).abs() < 1e-9);
    }
}
