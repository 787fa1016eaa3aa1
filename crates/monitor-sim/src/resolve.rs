//! The scenario resolved to the numbers the machine and the loop need: the effects with
//! their machine-dependent defaults, the parameter changes in effect (faults, load steps,
//! winding temperature) and the builder of the [`Machine`] they give.

use super::machine::{LoadLaw, Machine, MachineError, MagLaw, SatLaw, TurnLoop};
use super::{EffectSpec, FaultSpec, LoadKind, Scenario, ScenarioEvent, SimError};
use monitor_core::{FaultTarget, MachineParameter, MotorParameters};
use monitor_io::params::ParamFile;
use monitor_laws::{ActsOn, BoundLaw, LawInputs};
use std::f64::consts::PI;
use std::sync::Arc;

/// The effects of a scenario, resolved to the numbers the machine and the loop need.
#[derive(Debug, Clone, Default)]
pub(super) struct ResolvedEffects {
    pub(super) thermal: Option<Thermal>,
    pub(super) sat: Option<SatLaw>,
    pub(super) rfe: Option<f64>,
    pub(super) coulomb: Option<(f64, f64)>,
    pub(super) windage: f64,
    pub(super) load_torque: Option<f64>,
    pub(super) unbalance: Option<(f64, f64)>,
    /// Shorted turns (`phase_asymmetry`): phase index, fraction mu, fault resistance r_f
    /// [ohm] (`None`: a tenth of the healthy phase's Rs).
    pub(super) asym: Option<(usize, f64, Option<f64>)>,
    /// Rotor resistance asymmetry delta (`rotor_asymmetry`), 0 when off.
    pub(super) rotor_delta: f64,
    /// The saturation law's unsaturated Lm0 over the file's `lm_h`
    /// ([`monitor_io::params::lm0_over_file`]: above 1 where the file holds the rated
    /// point's Lm); 0 read as 1 (no saturation).
    pub(super) lm0_over_file: f64,
    /// A user's law of the magnetising inductance (an expression or a no-load curve), in
    /// place of the library's saturation.
    pub(super) mag_law: Option<MagLaw>,
    /// Users' load-torque laws.
    pub(super) load_laws: Arc<[BoundLaw]>,
    /// Users' laws of the stator resistance (their product over the file's Rs scales it).
    pub(super) stator_laws: Vec<BoundLaw>,
    /// Users' laws of the rotor resistance.
    pub(super) rotor_laws: Vec<BoundLaw>,
}

#[derive(Debug, Clone, Copy)]
pub(super) struct Thermal {
    pub(super) rise_k: Option<f64>,
    pub(super) tau_s: f64,
    pub(super) at_s: f64,
    pub(super) r_th: f64,
    pub(super) alpha: f64,
    pub(super) rotor: bool,
}

/// The machine's rated point on the scenario's supply, which the effects' defaults scale
/// with.
#[derive(Debug, Clone, Copy)]
pub(super) struct RatedPoint {
    /// Phase voltage peak [V].
    pub(super) vpk0: f64,
    /// Supply angular frequency [rad/s].
    pub(super) we0: f64,
    /// Rated torque [N m] ([`rated_torque`]).
    pub(super) t_rated: f64,
    /// Synchronous mechanical speed [rad/s].
    pub(super) w_sync: f64,
    /// The viscous load's Bl [N m s/rad].
    pub(super) bl_base: f64,
}

impl ResolvedEffects {
    /// Resolves the scenario's effects: defaults that depend on the machine and supply
    /// (rated flux `vpk0 / we0`, rated torque `t_rated`, synchronous speed `w_sync`).
    pub(super) fn new(
        scenario: &Scenario,
        m: &MotorParameters,
        rated: RatedPoint,
    ) -> Result<Self, SimError> {
        let mut eff = ResolvedEffects::default();
        for e in &scenario.effects {
            match e {
                EffectSpec::ThermalDrift { .. }
                | EffectSpec::Saturation { .. }
                | EffectSpec::IronLoss { .. } => eff.add_winding_and_core(e, m, rated),
                EffectSpec::CoulombFriction { .. }
                | EffectSpec::Windage { .. }
                | EffectSpec::LoadTorque { .. } => eff.add_shaft(e, scenario, rated)?,
                EffectSpec::SupplyUnbalance { .. }
                | EffectSpec::PhaseAsymmetry { .. }
                | EffectSpec::RotorAsymmetry { .. } => eff.add_asymmetry(e)?,
                EffectSpec::FluxDynamics {}
                | EffectSpec::CurrentDynamics {}
                | EffectSpec::DAxisDynamics {}
                | EffectSpec::CrossCouplingDynamics {} => {}
            }
        }
        eff.add_laws(scenario, m, rated)?;
        Ok(eff)
    }

    /// The scenario's user laws (`simulate --laws`), each at its parameters' values.
    fn add_laws(
        &mut self,
        scenario: &Scenario,
        m: &MotorParameters,
        rated: RatedPoint,
    ) -> Result<(), SimError> {
        let mut load_laws = Vec::new();
        for b in scenario.laws.iter() {
            let key = || format!("laws.{}", b.law.id);
            match b.law.acts_on {
                ActsOn::LoadTorque => load_laws.push(b.clone()),
                ActsOn::StatorResistance => self.stator_laws.push(b.clone()),
                ActsOn::RotorResistance => self.rotor_laws.push(b.clone()),
                ActsOn::MagnetisingInductance | ActsOn::MagnetisingCurve => {
                    if self.sat.is_some() || self.mag_law.is_some() {
                        return Err(SimError::Invalid {
                            key: key(),
                            message: "the magnetising inductance already follows a law (one law of Lm per run)".into(),
                        });
                    }
                    self.mag_law = Some(match b.law.table() {
                        None => MagLaw::Law(b.clone()),
                        Some(t) => {
                            // The stator inductance of the stator flux (no leakage taken
                            // off): the machine runs as its Gamma circuit.
                            let curve = t
                                .curve(
                                    m.rs_ohm,
                                    0.0,
                                    rated.vpk0 * 1.5f64.sqrt(),
                                    rated.we0 / (2.0 * PI),
                                )
                                .map_err(|e| SimError::Invalid {
                                    key: key(),
                                    message: e.to_string(),
                                })?;
                            MagLaw::Curve(Arc::new(curve))
                        }
                    });
                }
            }
        }
        self.load_laws = Arc::from(load_laws);
        Ok(())
    }

    /// True when a user's law sets a resistance.
    pub(super) fn has_resistance_laws(&self) -> bool {
        !self.stator_laws.is_empty() || !self.rotor_laws.is_empty()
    }

    /// The stator's and the rotor's resistance at time `t` [s] by the users' laws, over the
    /// file's values (1 where no law acts).
    pub(super) fn resistance_law_scales(&self, t: f64, m: &MotorParameters) -> (f64, f64) {
        let x = LawInputs {
            t_s: t,
            ..LawInputs::default()
        };
        let scale = |laws: &[BoundLaw], r0: f64| laws.iter().fold(1.0, |a, l| a * l.eval(&x) / r0);
        (
            scale(&self.stator_laws, m.rs_ohm),
            scale(&self.rotor_laws, m.rr_ohm),
        )
    }

    /// The winding's temperature, the main flux's saturation (default: `psi_sat_ratio`
    /// times the rated flux), the core loss (default: `rfe_over_xm` times Xm).
    fn add_winding_and_core(&mut self, e: &EffectSpec, m: &MotorParameters, rated: RatedPoint) {
        let RatedPoint { vpk0, we0, .. } = rated;
        match *e {
            EffectSpec::ThermalDrift {
                rise_k,
                tau_s,
                at_s,
                r_th_k_per_w,
                alpha_per_k,
                rotor,
            } => {
                self.thermal = Some(Thermal {
                    // A loss-driven temperature (a thermal resistance) has no set rise.
                    rise_k: r_th_k_per_w.is_none().then(|| rise_k.unwrap_or(60.0)),
                    tau_s,
                    at_s,
                    r_th: r_th_k_per_w.unwrap_or(0.0),
                    alpha: alpha_per_k,
                    rotor,
                })
            }
            EffectSpec::Saturation {
                psi_sat_wb,
                psi_sat_ratio,
                exponent,
            } => {
                let psi_sat_wb = psi_sat_wb.unwrap_or(psi_sat_ratio * vpk0 / we0);
                self.sat = Some(SatLaw {
                    psi_sat_wb,
                    exponent,
                });
                // The file's Lm at the rated point (a no-load test's) is the law's value
                // there: Lm0 above it.
                let supply = monitor_core::SupplyParameters {
                    v_ll_rms: vpk0 * (1.5f64).sqrt(),
                    f_hz: we0 / (2.0 * PI),
                };
                self.lm0_over_file =
                    monitor_io::params::lm0_over_file(m, &supply, psi_sat_wb, exponent);
            }
            EffectSpec::IronLoss {
                rfe_ohm,
                rfe_over_xm,
            } => self.rfe = Some(rfe_ohm.unwrap_or(rfe_over_xm * we0 * m.lm_h)),
            _ => {}
        }
    }

    /// The shaft's torques: dry friction (default 2 % of the rated torque), windage
    /// (default 5 % of it at synchronous speed), a load torque (default the viscous
    /// load's at synchronous speed; refused on a torque load).
    fn add_shaft(
        &mut self,
        e: &EffectSpec,
        scenario: &Scenario,
        rated: RatedPoint,
    ) -> Result<(), SimError> {
        let RatedPoint {
            t_rated,
            w_sync,
            bl_base,
            ..
        } = rated;
        match *e {
            EffectSpec::CoulombFriction {
                torque_nm,
                omega0_rad_s,
            } => self.coulomb = Some((torque_nm.unwrap_or(0.02 * t_rated), omega0_rad_s)),
            EffectSpec::Windage { k_nms2 } => {
                self.windage = k_nms2.unwrap_or(0.05 * t_rated / (w_sync * w_sync))
            }
            EffectSpec::LoadTorque { torque_nm } => {
                if scenario.load.kind == LoadKind::Torque {
                    return Err(SimError::Invalid {
                        key: "effects.load_torque".into(),
                        message: "the load is already a torque load (load.kind = \"torque\")"
                            .into(),
                    });
                }
                self.load_torque = Some(torque_nm.unwrap_or(bl_base * w_sync));
            }
            _ => {}
        }
        Ok(())
    }

    /// The asymmetries: the supply's unbalance, shorted turns, an unequal rotor cage.
    fn add_asymmetry(&mut self, e: &EffectSpec) -> Result<(), SimError> {
        match *e {
            EffectSpec::SupplyUnbalance {
                fraction,
                angle_deg,
            } => self.unbalance = Some((fraction, angle_deg.to_radians())),
            EffectSpec::PhaseAsymmetry {
                phase,
                fraction,
                fault_resistance_ohm,
            } => self.asym = Some((phase.index(), fraction, fault_resistance_ohm)),
            EffectSpec::RotorAsymmetry { .. } => self.rotor_delta = e.rotor_delta()?,
            _ => {}
        }
        Ok(())
    }
}

/// Multiplicative parameter changes in effect (faults, load steps, winding temperature).
#[derive(Debug, Clone, Copy)]
pub(super) struct ParameterScales {
    pub(super) rs: f64,
    pub(super) rr: f64,
    pub(super) lls: f64,
    pub(super) llr: f64,
    pub(super) b: f64,
    pub(super) bl: f64,
    /// Thermal factors of the stator and rotor resistances.
    pub(super) th_s: f64,
    pub(super) th_r: f64,
    /// The users' laws' factors of the stator and rotor resistances.
    pub(super) law_s: f64,
    pub(super) law_r: f64,
    /// Viscous load: Bl scale from load steps. Torque load: torque [N m].
    pub(super) bl_scale: f64,
    pub(super) torque_nm: f64,
}

impl Default for ParameterScales {
    fn default() -> Self {
        ParameterScales {
            rs: 1.0,
            rr: 1.0,
            lls: 1.0,
            llr: 1.0,
            b: 1.0,
            bl: 1.0,
            th_s: 1.0,
            th_r: 1.0,
            law_s: 1.0,
            law_r: 1.0,
            bl_scale: 1.0,
            torque_nm: 0.0,
        }
    }
}

impl ParameterScales {
    /// Applies a parametric fault to the parameter the core's fault list names for it
    /// ([`monitor_core::Fault::target`]; sensor faults act on the sensors, not here).
    pub(super) fn apply_fault(&mut self, f: &FaultSpec) {
        let k = 1.0 + f.change.unwrap_or(0.0);
        let FaultTarget::Parameter(p) = f.kind.target() else {
            return;
        };
        *match p {
            MachineParameter::Rs => &mut self.rs,
            MachineParameter::Rr => &mut self.rr,
            MachineParameter::StatorLeakage => &mut self.lls,
            MachineParameter::RotorLeakage => &mut self.llr,
            MachineParameter::MachineFriction => &mut self.b,
            MachineParameter::LoadFriction => &mut self.bl,
        } *= k;
    }
}

/// Builds the [`Machine`] for the parameter file's motor, the resolved effects and the
/// parameter changes in effect.
pub(super) struct MachineBuilder<'a> {
    pub(super) m: &'a MotorParameters,
    pub(super) eff: ResolvedEffects,
    pub(super) torque_load: bool,
    pub(super) bl_base: f64,
}

impl MachineBuilder<'_> {
    pub(super) fn build(&self, md: &ParameterScales) -> Result<Machine, MachineError> {
        let m = self.m;
        let model = m.model::<f64>();
        let rs = m.rs_ohm * md.rs * md.th_s * md.law_s;
        let (lls, llr, rr, lm) = self.circuit(md);
        // The fault resistance defaults to a tenth of the healthy phase's (cold) Rs.
        let turn = self.eff.asym.filter(|a| a.1 > 0.0).map(|(ph, mu, rf)| {
            TurnLoop::new(ph, mu, rf.unwrap_or(0.1 * m.rs_ohm), rs, model.lls_h())
        });
        let mut machine = Machine::new(
            rs,
            turn,
            lls,
            llr,
            rr,
            lm,
            self.eff
                .mag_law
                .clone()
                .or(self.eff.sat.map(MagLaw::Saturation)),
            self.eff.rfe,
            model.np(),
            m.j_kgm2,
            m.b_nms * md.b,
            self.load_law(md),
        )?;
        machine.load_laws = Arc::clone(&self.eff.load_laws);
        machine.rr_asym = 2.0 / 3.0 * rr * self.eff.rotor_delta;
        Ok(machine)
    }

    /// The circuit's `(Lls, Llr, Rr, Lm)` [H, H, ohm, H] with the changes in effect: a
    /// Gamma-form file's zero leakage scales Lm instead; a no-load curve makes the machine
    /// its Gamma circuit (below).
    fn circuit(&self, md: &ParameterScales) -> (f64, f64, f64, f64) {
        let m = self.m;
        let model = m.model::<f64>();
        let rr = m.rr_ohm * md.rr * md.th_r * md.law_r;
        let gamma_s = model.lls_h() <= 1e-9 * m.lm_h;
        let gamma_r = model.llr_h() <= 1e-9 * m.lm_h;
        let mut lm = m.lm_h
            * if self.eff.lm0_over_file > 0.0 {
                self.eff.lm0_over_file
            } else {
                1.0
            };
        if gamma_s {
            lm *= md.lls;
        }
        if gamma_r {
            lm *= md.llr;
        }
        let lls = if gamma_s { 0.0 } else { model.lls_h() * md.lls };
        let llr = if gamma_r { 0.0 } else { model.llr_h() * md.llr };
        if !matches!(self.eff.mag_law, Some(MagLaw::Curve(_))) {
            return (lls, llr, rr, lm);
        }
        // A no-load curve is the stator inductance of the stator flux: the machine as its
        // Gamma circuit (no stator leakage; the rotor leakage Ls (Ls Lr / Lm^2 - 1) and the
        // rotor resistance Rr (Ls/Lm)^2 keep its terminal behaviour), Lm the curve's Ls.
        let (ls, lr) = (lls + lm, llr + lm);
        (
            0.0,
            ls * (ls * lr / (lm * lm) - 1.0),
            rr * (ls / lm).powi(2),
            ls,
        )
    }

    /// The load's law with the changes in effect: a torque input, or the viscous term.
    fn load_law(&self, md: &ParameterScales) -> LoadLaw {
        let (c_nm, w0) = self.eff.coulomb.unwrap_or((0.0, 1.0));
        let (bl_nms, torque_nm) = if self.torque_load {
            (0.0, md.torque_nm * md.bl)
        } else {
            (self.bl_base * md.bl_scale * md.bl, 0.0)
        };
        LoadLaw {
            bl_nms,
            torque_nm,
            coulomb_nm: c_nm,
            inv_w0: 1.0 / w0,
            windage: self.eff.windage,
        }
    }

    /// The scenario key a machine that cannot be built is blamed on.
    pub(super) fn blamed_key(&self) -> &'static str {
        if self.eff.asym.is_some() {
            "effects.phase_asymmetry"
        } else {
            "faults"
        }
    }
}

/// The rated torque the effects' defaults scale with: Bl x synchronous speed for a viscous
/// load, the largest torque of a torque load (falling back to the file's Bl).
pub(super) fn rated_torque(
    params: &ParamFile,
    scenario: &Scenario,
    w_sync: f64,
    bl_base: f64,
) -> f64 {
    let m = &params.motor;
    let mut t_rated = bl_base * w_sync;
    if scenario.load.kind == LoadKind::Torque {
        t_rated = scenario
            .load
            .steps
            .iter()
            .filter_map(|s| s.torque_nm)
            .chain(scenario.load.torque_nm)
            .fold(0.0, |a: f64, b| a.max(b.abs()));
    }
    if t_rated <= 0.0 {
        t_rated = m.bl_nms * w_sync;
    }
    t_rated
}

/// The machine's rated point on the scenario's supply (`v_ll` [V RMS], `f0` [Hz]) with
/// `np` pole pairs, which the effects' defaults scale with.
pub(super) fn rated_point(
    params: &ParamFile,
    scenario: &Scenario,
    v_ll: f64,
    f0: f64,
    np: f64,
) -> RatedPoint {
    let vpk0 = v_ll * (2.0f64 / 3.0).sqrt();
    let we0 = 2.0 * PI * f0;
    let bl_base = scenario.load.bl_nms.unwrap_or(params.motor.bl_nms);
    let w_sync = we0 / np;
    RatedPoint {
        vpk0,
        we0,
        t_rated: rated_torque(params, scenario, w_sync, bl_base),
        w_sync,
        bl_base,
    }
}

/// The machine of `builder` at the scales `scales`, after checking that every parameter
/// set the run's faults (`events`) lead to is a machine too.
///
/// # Errors
/// [`SimError::Invalid`] blaming the key the builder names.
pub(super) fn checked_machine(
    builder: &MachineBuilder<'_>,
    scales: ParameterScales,
    events: &[(u64, ScenarioEvent)],
) -> Result<Machine, SimError> {
    let invalid = |e: MachineError| SimError::Invalid {
        key: builder.blamed_key().to_string(),
        message: e.to_string(),
    };
    let machine = builder.build(&scales).map_err(invalid)?;
    let mut scratch = scales;
    for (_, ev) in events {
        if let ScenarioEvent::Fault(f) = ev {
            scratch.apply_fault(f);
            builder.build(&scratch).map_err(invalid)?;
        }
    }
    Ok(machine)
}
