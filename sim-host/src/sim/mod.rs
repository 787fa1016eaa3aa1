//! Induction-motor simulator (f64): full-order T-equivalent machine, stiff supply, load,
//! faults, physical effects and sensors, producing rows in the DESIGN.md §3 CSV schema.
//!
//! # Model
//! Full-order machine in the stationary alpha-beta frame (amplitude-invariant Clarke, so
//! alpha = phase a), states psi_s, psi_r (flux linkages [Wb]), omega_m [rad/s] and
//! theta_m [rad] (for the encoder); see [`model`](self) equations below. Starts from
//! standstill with zero flux (direct-on-line start).
//! ```text
//!   dpsi_s/dt = v_s - Rs i_s
//!   dpsi_r/dt = -Rr i_r + j Np omega_m psi_r
//!   [psi_s; psi_r] = [Ls Lm; Lm Lr] [i_s; i_r],   Ls = Lls + Lm,  Lr = Llr + Lm
//!   T_e = (3/2) Np Im(conj(i_s) psi_s)
//!   J domega_m/dt = T_e - B omega_m - T_load,       dtheta_m/dt = omega_m
//! ```
//! Star connection with isolated neutral (no zero-sequence current). Supply: stiff source,
//! v_s = V e^{j theta_e} (+ negative sequence with `supply_unbalance`), V = sqrt(2/3) V_ll,rms,
//! theta_e continuous across frequency steps. Load: `viscous` T_load = Bl omega_m (the
//! paper) or `torque` T_load = T(t) (an active torque, also at standstill), plus
//! `coulomb_friction` and `windage` when enabled.
//!
//! The machine's equations are in [`machine`](self) (private): this module resolves the
//! scenario (effects, events, parameter changes) and runs the integration loop.
//!
//! Integration: classic fixed-step RK4, an integer number of steps per output sample
//! (h <= `max_step_s`, default 100 us), the supply phasor rotated incrementally (no trig per
//! step). Accuracy on the 2.2 kW reference start (10 kHz, h = 100 us) against a 100x finer
//! run: see `crate::bench` (max current error about 1e-6 A).
//!
//! # Scenario TOML
//! ```toml
//! duration_s = 10.0          # simulated time [s]
//! sample_rate_hz = 10000.0   # output rows per second
//! seed = 1                   # noise seed (default 1)
//! # max_step_s = 1e-4        # integrator step cap [s]
//!
//! [supply]                   # optional; defaults to the parameter file's supply
//! # v_ll_rms = 400.0
//! # f_hz = 50.0
//! steps = [{ t_s = 5.0, v_scale = 1.05 }, { t_s = 7.0, f_hz = 45.0 }]
//!
//! [load]
//! kind = "torque"            # or "viscous" (default: Bl*omega, Bl from the parameter file)
//! torque_nm = 0.0            # torque load only; viscous: bl_nms = 0.0975
//! steps = [{ t_s = 2.5, torque_nm = 14.6 }]   # viscous: { t_s = 2.5, bl_scale = 1.5 }
//!
//! [[faults]]                 # parametric: rs rr ls lr b bl, relative change > -1
//! kind = "rs"
//! at_s = 5.0
//! change = 0.5
//!
//! [[faults]]                 # sensor: current_sensor voltage_sensor speed_sensor
//! kind = "current_sensor"
//! at_s = 6.0
//! mode = "gain"              # gain (change) | offset (offset, in V/A/rad/s) | disconnected | stuck
//! change = 0.1
//! phase = "a"                # optional (voltage/current only); default all three phases
//!
//! [[effects]]
//! name = "thermal_drift"     # see `EffectSpec` for every effect and its parameters
//! rise_k = 60.0
//!
//! [sensors]                  # optional; see `SensorSpec`
//! adc_bits = 12
//! v_range_v = 400.0
//! i_range_a = 10.0
//! noise_v = 0.5
//! noise_i = 0.01
//! ```
//! Steps and faults act at the first output sample at or after their time. Unknown keys are
//! errors; messages name the key (and the line for TOML errors).
//!
//! # Faults
//! `rs, rr`: resistance x (1 + change). `ls, lr`: LEAKAGE inductance x (1 + change), the self
//! inductances follow (PSIM convention, DESIGN.md §2); for a Gamma-model machine with no
//! stator leakage (the 2.2 kW reference) `ls` scales the stator inductance Ls = Lm itself
//! (Lm x (1 + change), Lr = Llr + Lm follows); likewise `lr` when Llr = 0. `b`: B x (1 +
//! change). `bl`: Bl x (1 + change), or the load torque for a torque load. Sensor faults:
//! see [`SensorFaultMode`].
//!
//! # Effects
//! See [`EffectSpec`]: `thermal_drift`, `saturation`, `iron_loss`, `coulomb_friction`, `windage`,
//! `load_torque`, `supply_unbalance`, `phase_asymmetry`, `rotor_asymmetry` (the rotor
//! resistance matrix turning with the rotor, see `machine`); `flux_dynamics` and
//! `current_dynamics` are properties of the full-order model (always present), so enabling
//! them is a no-op for generation.
//!
//! # Separation of truth and measurement
//! Other code gets only [`Row`]s of sensor readings ([`simulate`]); the true state
//! ([`Truth`]) is available to tests through [`simulate_with_truth`] and never enters a row.

pub(crate) mod machine;
mod scenario;
mod sensors;
mod steady;

pub use scenario::{
    EffectSpec, FaultSpec, LoadKind, LoadSpec, LoadStep, Scenario, SensorFaultMode, SensorSpec,
    SupplySpec, SupplyStep, Workload, DEFAULT_MAX_STEP_S, MIN_STEP_S, SAMPLE_RATE_RANGE_HZ,
};
pub use steady::{
    solve_slip, solve_slip_at, steady_state, steady_state_at, SteadyLoad, SteadyState,
};

use crate::log::{Channels, Row};
use crate::params::ParamFile;
use machine::{LoadLaw, Machine, SatLaw, Sym2};
use monitor_core::frames::{inverse_clarke, AlphaBeta};
use monitor_core::{Fault, MotorParameters};
use sensors::Sensors;
use std::f64::consts::PI;
use std::ops::ControlFlow;

/// Errors of the simulator. Messages are one line and name the offending key.
#[derive(Debug, thiserror::Error)]
pub enum SimError {
    /// The scenario file could not be read.
    #[error("cannot read scenario {path}: {source}")]
    Io {
        /// The file.
        path: String,
        /// The I/O error.
        source: std::io::Error,
    },
    /// Malformed TOML, an unknown key or a missing key.
    #[error("bad scenario {path}: {message}")]
    Toml {
        /// The file.
        path: String,
        /// Parser message with the line, on one line.
        message: String,
    },
    /// A value out of range or an unphysical combination.
    #[error("bad scenario: {key}: {message}")]
    Invalid {
        /// The key (dotted path), e.g. `faults.change`.
        key: String,
        /// What is wrong.
        message: String,
    },
    /// The state stopped being finite (should not happen for physical parameters).
    #[error("simulation diverged at t = {t_s} s")]
    Diverged {
        /// Time of the first non-finite state [s].
        t_s: f64,
    },
}

/// The true state at an output sample, for tests (never part of a [`Row`]).
///
/// Powers follow the amplitude-invariant convention p = (3/2) v . i.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Truth {
    /// Time [s].
    pub t_s: f64,
    /// Supply phase-to-neutral voltages [V].
    pub v_abc: [f64; 3],
    /// Terminal phase currents [A] (incl. the iron-loss current).
    pub i_abc: [f64; 3],
    /// Supply voltage, alpha-beta [V].
    pub v_ab: [f64; 2],
    /// Terminal current, alpha-beta [A].
    pub i_ab: [f64; 2],
    /// Stator flux linkage [Wb].
    pub psi_s: [f64; 2],
    /// Rotor flux linkage [Wb].
    pub psi_r: [f64; 2],
    /// Current in the stator leakage branch (= terminal current without iron loss) [A].
    pub i_s: [f64; 2],
    /// Rotor current referred to the stator [A].
    pub i_r: [f64; 2],
    /// Mechanical speed [rad/s].
    pub wm_rad_s: f64,
    /// Mechanical angle [rad] (cumulative).
    pub theta_m_rad: f64,
    /// Supply angular frequency in effect [rad/s].
    pub we_rad_s: f64,
    /// Electromagnetic torque [N m].
    pub te_nm: f64,
    /// Load torque (load + Coulomb + windage, without B omega) [N m].
    pub t_load_nm: f64,
    /// Stator resistance in effect (scalar; healthy phases) [ohm].
    pub rs_ohm: f64,
    /// Rotor resistance in effect [ohm].
    pub rr_ohm: f64,
    /// Magnetising inductance in effect [H].
    pub lm_h: f64,
    /// Input power (3/2) v . i [W].
    pub p_in_w: f64,
    /// Copper losses (3/2)(i^T R_s i + i_r^T R_r i_r) [W] (R_r = Rr I for a symmetric cage).
    pub p_cu_w: f64,
    /// Iron losses (3/2)|u|^2/Rfe [W].
    pub p_fe_w: f64,
    /// Air-gap mechanical power T_e omega_m [W].
    pub p_mech_w: f64,
    /// Magnetic energy (3/4)(psi_s . i_s + psi_r . i_r) [J] (exact for linear magnetics).
    pub stored_energy_j: f64,
    /// Winding temperature rise [K] (thermal_drift).
    pub temperature_rise_k: f64,
}

/// What a run did (for the `--json` summary).
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct SimSummary {
    /// Rows produced.
    pub rows: u64,
    /// Simulated time [s].
    pub duration_s: f64,
    /// Output sample rate [Hz].
    pub sample_rate_hz: f64,
    /// Integrator step [s].
    pub step_s: f64,
    /// RK4 steps per output sample.
    pub substeps_per_sample: u32,
    /// Voltage ADC range +/- [V].
    pub v_range_v: f64,
    /// Current ADC range +/- [A].
    pub i_range_a: f64,
    /// Voltage noise [V rms].
    pub noise_v: f64,
    /// Current noise [A rms].
    pub noise_i: f64,
    /// Mechanical speed at the end [rad/s].
    pub final_wm_rad_s: f64,
    /// Slip at the end [-].
    pub final_slip: f64,
    /// Largest true phase current magnitude [A].
    pub max_abs_current_a: f64,
    /// Effects that were on.
    pub effects: Vec<String>,
    /// Number of faults.
    pub faults: usize,
}

impl SensorSpec {
    /// The CSV channels these sensors produce.
    pub fn channels(&self) -> Channels {
        Channels {
            voltages: self.voltages,
            speed: self.speed,
            encoder: self.encoder,
        }
    }
}

/// Default ADC ranges for a motor and supply: (v_range_v, i_range_a).
///
/// v: 1.2 x phase peak rounded up to 50 V (400 V for the 2.2 kW motor, 250 V for 3 hp);
/// i: 2 x the analytic locked-rotor peak current rounded up to 5 A (a direct-on-line start,
/// whose first peaks exceed the steady locked-rotor peak, does not clip).
pub fn default_ranges(m: &MotorParameters, v_ll_rms: f64, f_hz: f64) -> (f64, f64) {
    let vpk = v_ll_rms * (2.0f64 / 3.0).sqrt();
    let v = (1.2 * vpk / 50.0).ceil() * 50.0;
    let lr = steady_state_at(m, v_ll_rms, f_hz, 1.0);
    let i = (2.0 * 2f64.sqrt() * lr.i_phase_rms_a / 5.0).ceil() * 5.0;
    (v, i)
}

/// Runs `scenario` on the machine `params`, calling `on_row` for every output row (constant
/// memory). Returns a summary.
///
/// # Errors
/// [`SimError::Invalid`] for a bad scenario or an unphysical fault/effect combination
/// (checked before the first row), [`SimError::Diverged`] if the state stops being finite.
pub fn simulate(
    params: &ParamFile,
    scenario: &Scenario,
    mut on_row: impl FnMut(&Row),
) -> Result<SimSummary, SimError> {
    simulate_with_truth(params, scenario, |r, _| on_row(r))
}

/// [`simulate`] whose callback may stop the run: after a row for which `on_row` returns
/// `ControlFlow::Break(())` no further row is made (a writer that failed, a user who
/// pressed Ctrl-C). `Ok(None)` when stopped, else the summary.
///
/// # Errors
/// As [`simulate`].
pub fn simulate_while(
    params: &ParamFile,
    scenario: &Scenario,
    mut on_row: impl FnMut(&Row) -> ControlFlow<()>,
) -> Result<Option<SimSummary>, SimError> {
    checked_run(params, scenario)?
        .run(|r, _| on_row(r))
        .map(|(summary, done)| done.then_some(summary))
}

/// [`simulate`] driven from outside as it runs (the live HMI, `sim-host hmi`): after each
/// row `on_row` may push events into the vector it is given; they act from the next row
/// on (their own times are ignored). An event that would make the machine unphysical
/// (checked as the scenario's own faults are, before it acts) is left out and the run
/// goes on. Return `ControlFlow::Break(())` to stop; `Ok(None)` when stopped, else the
/// summary at the scenario's end.
///
/// # Errors
/// As [`simulate`].
pub fn simulate_interactive(
    params: &ParamFile,
    scenario: &Scenario,
    mut on_row: impl FnMut(&Row, &mut Vec<ScenarioEvent>) -> ControlFlow<()>,
) -> Result<Option<SimSummary>, SimError> {
    checked_run(params, scenario)?
        .run_with_events(|r, _, ev| on_row(r, ev))
        .map(|(summary, done)| done.then_some(summary))
}

/// [`simulate`] collecting the rows in memory.
///
/// # Errors
/// As [`simulate`].
pub fn simulate_to_vec(params: &ParamFile, scenario: &Scenario) -> Result<Vec<Row>, SimError> {
    // Reserved up to 1 M rows (about 100 MB): a scenario that validate refuses must not
    // abort on an allocation of its estimated size first.
    let expected = (scenario.duration_s * scenario.sample_rate_hz).clamp(0.0, 1.0e6);
    let mut rows = Vec::with_capacity(expected as usize + 1);
    simulate(params, scenario, |r| rows.push(*r))?;
    Ok(rows)
}

/// The effects of a scenario, resolved to the numbers the machine and the loop need.
#[derive(Debug, Clone, Default)]
struct ResolvedEffects {
    thermal: Option<Thermal>,
    sat: Option<SatLaw>,
    rfe: Option<f64>,
    coulomb: Option<(f64, f64)>,
    windage: f64,
    load_torque: Option<f64>,
    unbalance: Option<(f64, f64)>,
    asym: Option<(usize, f64)>,
    /// Rotor resistance asymmetry delta (`rotor_asymmetry`), 0 when off.
    rotor_delta: f64,
}

#[derive(Debug, Clone, Copy)]
struct Thermal {
    rise_k: Option<f64>,
    tau_s: f64,
    at_s: f64,
    r_th: f64,
    alpha: f64,
    rotor: bool,
}

impl ResolvedEffects {
    /// Resolves the scenario's effects: defaults that depend on the machine and supply
    /// (rated flux `vpk0 / we0`, rated torque `t_rated`, synchronous speed `w_sync`).
    fn new(
        scenario: &Scenario,
        m: &MotorParameters,
        (vpk0, we0): (f64, f64),
        (t_rated, w_sync, bl_base): (f64, f64, f64),
    ) -> Result<Self, SimError> {
        let mut eff = ResolvedEffects::default();
        for e in &scenario.effects {
            match *e {
                EffectSpec::ThermalDrift {
                    rise_k,
                    tau_s,
                    at_s,
                    r_th_k_per_w,
                    alpha_per_k,
                    rotor,
                } => {
                    eff.thermal = Some(Thermal {
                        rise_k: if r_th_k_per_w.is_some() {
                            None
                        } else {
                            Some(rise_k.unwrap_or(60.0))
                        },
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
                    eff.sat = Some(SatLaw {
                        psi_sat_wb: psi_sat_wb.unwrap_or(psi_sat_ratio * vpk0 / we0),
                        exponent,
                    })
                }
                EffectSpec::IronLoss {
                    rfe_ohm,
                    rfe_over_xm,
                } => eff.rfe = Some(rfe_ohm.unwrap_or(rfe_over_xm * we0 * m.lm_h)),
                EffectSpec::CoulombFriction {
                    torque_nm,
                    omega0_rad_s,
                } => eff.coulomb = Some((torque_nm.unwrap_or(0.02 * t_rated), omega0_rad_s)),
                EffectSpec::Windage { k_nms2 } => {
                    eff.windage = k_nms2.unwrap_or(0.05 * t_rated / (w_sync * w_sync))
                }
                EffectSpec::LoadTorque { torque_nm } => {
                    if scenario.load.kind == LoadKind::Torque {
                        return Err(SimError::Invalid {
                            key: "effects.load_torque".into(),
                            message: "the load is already a torque load (load.kind = \"torque\")"
                                .into(),
                        });
                    }
                    eff.load_torque = Some(torque_nm.unwrap_or(bl_base * w_sync));
                }
                EffectSpec::SupplyUnbalance {
                    fraction,
                    angle_deg,
                } => eff.unbalance = Some((fraction, angle_deg.to_radians())),
                EffectSpec::PhaseAsymmetry { phase, fraction } => {
                    eff.asym = Some((phase.index(), fraction))
                }
                EffectSpec::RotorAsymmetry { .. } => eff.rotor_delta = e.rotor_delta()?,
                EffectSpec::FluxDynamics {}
                | EffectSpec::CurrentDynamics {}
                | EffectSpec::DAxisDynamics {}
                | EffectSpec::CrossCouplingDynamics {} => {}
            }
        }
        Ok(eff)
    }
}

/// Multiplicative parameter changes in effect (faults, load steps, winding temperature).
#[derive(Debug, Clone, Copy)]
struct ParameterScales {
    rs: f64,
    rr: f64,
    lls: f64,
    llr: f64,
    b: f64,
    bl: f64,
    /// Thermal factors of the stator and rotor resistances.
    th_s: f64,
    th_r: f64,
    /// Viscous load: Bl scale from load steps. Torque load: torque [N m].
    bl_scale: f64,
    torque_nm: f64,
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
            bl_scale: 1.0,
            torque_nm: 0.0,
        }
    }
}

impl ParameterScales {
    /// Applies a parametric fault (sensor faults act on the sensors, not here).
    fn apply_fault(&mut self, f: &FaultSpec) {
        let k = 1.0 + f.change.unwrap_or(0.0);
        match f.kind {
            Fault::Rs => self.rs *= k,
            Fault::Rr => self.rr *= k,
            Fault::Ls => self.lls *= k,
            Fault::Lr => self.llr *= k,
            Fault::B => self.b *= k,
            Fault::Bl => self.bl *= k,
            Fault::CurrentSensor | Fault::VoltageSensor | Fault::SpeedSensor => {}
        }
    }
}

/// Builds the [`Machine`] for the parameter file's motor, the resolved effects and the
/// parameter changes in effect.
struct MachineBuilder<'a> {
    m: &'a MotorParameters,
    eff: ResolvedEffects,
    torque_load: bool,
    bl_base: f64,
}

impl MachineBuilder<'_> {
    fn build(&self, md: &ParameterScales) -> Result<Machine, String> {
        let m = self.m;
        let model = m.model::<f64>();
        let rs = m.rs_ohm * md.rs * md.th_s;
        let rr = m.rr_ohm * md.rr * md.th_r;
        let gamma_s = model.lls_h() <= 1e-9 * m.lm_h;
        let gamma_r = model.llr_h() <= 1e-9 * m.lm_h;
        let mut lm = m.lm_h;
        if gamma_s {
            lm *= md.lls;
        }
        if gamma_r {
            lm *= md.llr;
        }
        let lls = if gamma_s { 0.0 } else { model.lls_h() * md.lls };
        let llr = if gamma_r { 0.0 } else { model.llr_h() * md.llr };
        let t_mat = match self.eff.asym {
            Some((ph, mu)) => {
                Sym2::scalar_minus_rank1(1.0, 2.0 / 3.0 * mu, ph as f64 * 2.0 * PI / 3.0)
            }
            None => Sym2::scalar(1.0),
        };
        let (c_nm, w0) = self.eff.coulomb.unwrap_or((0.0, 1.0));
        let load = if self.torque_load {
            LoadLaw {
                bl_nms: 0.0,
                torque_nm: md.torque_nm * md.bl,
                coulomb_nm: c_nm,
                inv_w0: 1.0 / w0,
                windage: self.eff.windage,
            }
        } else {
            LoadLaw {
                bl_nms: self.bl_base * md.bl_scale * md.bl,
                torque_nm: 0.0,
                coulomb_nm: c_nm,
                inv_w0: 1.0 / w0,
                windage: self.eff.windage,
            }
        };
        let mut machine = Machine::new(
            rs,
            t_mat,
            lls,
            llr,
            rr,
            lm,
            self.eff.sat,
            self.eff.rfe,
            model.np(),
            m.j_kgm2,
            m.b_nms * md.b,
            load,
        )?;
        machine.rr_asym = 2.0 / 3.0 * rr * self.eff.rotor_delta;
        Ok(machine)
    }

    /// The scenario key a machine that cannot be built is blamed on.
    fn blamed_key(&self) -> &'static str {
        if self.eff.asym.is_some() {
            "effects.phase_asymmetry"
        } else {
            "faults"
        }
    }
}

/// Something the scenario switches at an output sample: a supply step, a load step or a
/// fault (the scenario's `supply.steps`, `load.steps` and `faults`; an interactive run,
/// [`simulate_interactive`], adds them as it goes).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum ScenarioEvent {
    /// A supply step (voltage scale, frequency).
    Supply(SupplyStep),
    /// A load step (Bl scale or load torque).
    Load(LoadStep),
    /// A fault switched on (parametric faults compose multiplicatively: the inverse change
    /// clears one; a sensor fault replaces the channel's previous fault: a gain change of
    /// 0 clears it).
    Fault(FaultSpec),
}

/// The stiff supply: positive-sequence unit phasor `p`, rotated by `e^{j we h/2}` twice per
/// integrator step (no trig per step), plus a negative sequence with `supply_unbalance`.
struct Supply {
    vpk0: f64,
    vpk: f64,
    we: f64,
    h: f64,
    /// Negative-sequence fraction and its angle's cos and sin.
    kn: f64,
    cn: f64,
    sn: f64,
    p: [f64; 2],
    rot: [f64; 2],
}

impl Supply {
    fn new(vpk0: f64, we0: f64, h: f64, unbalance: Option<(f64, f64)>) -> Self {
        let (kn, cn, sn) = match unbalance {
            Some((k, phi)) => (k, phi.cos(), phi.sin()),
            None => (0.0, 1.0, 0.0),
        };
        Supply {
            vpk0,
            vpk: vpk0,
            we: we0,
            h,
            kn,
            cn,
            sn,
            p: [1.0, 0.0],
            rot: [(0.5 * we0 * h).cos(), (0.5 * we0 * h).sin()],
        }
    }

    fn step(&mut self, s: &SupplyStep) {
        if let Some(v) = s.v_scale {
            self.vpk = self.vpk0 * v;
        }
        if let Some(f) = s.f_hz {
            self.we = 2.0 * PI * f;
            self.rot = [
                (0.5 * self.we * self.h).cos(),
                (0.5 * self.we * self.h).sin(),
            ];
        }
    }

    /// Voltage vector (alpha, beta) for the unit phasor `p`.
    #[inline(always)]
    fn voltage(&self, p: [f64; 2]) -> [f64; 2] {
        let (kn, cn, sn) = (self.kn, self.cn, self.sn);
        [
            self.vpk * (p[0] + kn * (cn * p[0] + sn * p[1])),
            self.vpk * (p[1] + kn * (sn * p[0] - cn * p[1])),
        ]
    }

    #[inline(always)]
    fn rotate(p: [f64; 2], r: [f64; 2]) -> [f64; 2] {
        [p[0] * r[0] - p[1] * r[1], p[0] * r[1] + p[1] * r[0]]
    }

    /// Integrates `machine` over one output sample (`nsub` steps of `h`).
    fn integrate(&mut self, machine: &Machine, x: &mut [f64; 6], nsub: u32) {
        for _ in 0..nsub {
            let pm = Self::rotate(self.p, self.rot);
            let pe = Self::rotate(pm, self.rot);
            machine.rk4(
                x,
                self.h,
                self.voltage(self.p),
                self.voltage(pm),
                self.voltage(pe),
            );
            self.p = pe;
        }
        // Renormalise |p| = 1 (first-order Newton step: no sqrt, |p| drifts by ~1e-16/step).
        let norm = 1.5 - 0.5 * (self.p[0] * self.p[0] + self.p[1] * self.p[1]);
        self.p = [self.p[0] * norm, self.p[1] * norm];
    }
}

/// The rated torque the effects' defaults scale with: Bl x synchronous speed for a viscous
/// load, the largest torque of a torque load (falling back to the file's Bl).
fn rated_torque(params: &ParamFile, scenario: &Scenario, w_sync: f64, bl_base: f64) -> f64 {
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

/// The scenario's supply steps, load steps and faults at their output-sample indices.
fn scenario_events(scenario: &Scenario) -> Vec<(u64, ScenarioEvent)> {
    let rate = scenario.sample_rate_hz;
    let idx = |t: f64| (t * rate - 1e-9).ceil().max(0.0) as u64;
    let mut events: Vec<(u64, ScenarioEvent)> = Vec::new();
    events.extend(
        scenario
            .supply
            .steps
            .iter()
            .map(|s| (idx(s.t_s), ScenarioEvent::Supply(*s))),
    );
    events.extend(
        scenario
            .load
            .steps
            .iter()
            .map(|s| (idx(s.t_s), ScenarioEvent::Load(*s))),
    );
    events.extend(
        scenario
            .faults
            .iter()
            .map(|f| (idx(f.at_s), ScenarioEvent::Fault(*f))),
    );
    events.sort_by_key(|e| e.0);
    events
}

/// [`simulate`] that also hands the true state to the callback (for tests; see [`Truth`]).
///
/// # Errors
/// As [`simulate`].
pub fn simulate_with_truth(
    params: &ParamFile,
    scenario: &Scenario,
    mut on_row: impl FnMut(&Row, &Truth),
) -> Result<SimSummary, SimError> {
    checked_run(params, scenario)?
        .run(|r, t| {
            on_row(r, t);
            ControlFlow::Continue(())
        })
        .map(|(summary, _)| summary)
}

/// Checks the scenario and the parameters and resolves the run.
fn checked_run<'a>(params: &'a ParamFile, scenario: &'a Scenario) -> Result<Run<'a>, SimError> {
    scenario.validate()?;
    params.check().map_err(|e| SimError::Invalid {
        key: "params".into(),
        message: e.to_string(),
    })?;
    Run::new(params, scenario)
}

/// One simulation run: the resolved scenario and the state of the loop.
struct Run<'a> {
    scenario: &'a Scenario,
    builder: MachineBuilder<'a>,
    scales: ParameterScales,
    events: Vec<(u64, ScenarioEvent)>,
    machine: Machine,
    sensors: Sensors,
    supply: Supply,
    /// Output rows, RK4 steps per row, output period [s].
    n: u64,
    nsub: u32,
    dt: f64,
    np: f64,
}

impl<'a> Run<'a> {
    /// Resolves the scenario and checks every parameter set the run will pass through,
    /// before the first row.
    fn new(params: &'a ParamFile, scenario: &'a Scenario) -> Result<Self, SimError> {
        let m = &params.motor;
        let v_ll = scenario.supply.v_ll_rms.unwrap_or(params.supply.v_ll_rms);
        let f0 = scenario.supply.f_hz.unwrap_or(params.supply.f_hz);
        let np = m.model::<f64>().np();
        let vpk0 = v_ll * (2.0f64 / 3.0).sqrt();
        let we0 = 2.0 * PI * f0;
        let bl_base = scenario.load.bl_nms.unwrap_or(m.bl_nms);
        let w_sync = we0 / np;
        let t_rated = rated_torque(params, scenario, w_sync, bl_base);
        let eff = ResolvedEffects::new(scenario, m, (vpk0, we0), (t_rated, w_sync, bl_base))?;
        let torque_load = scenario.load.kind == LoadKind::Torque || eff.load_torque.is_some();
        let scales = ParameterScales {
            torque_nm: eff.load_torque.or(scenario.load.torque_nm).unwrap_or(0.0),
            ..ParameterScales::default()
        };
        let builder = MachineBuilder {
            m,
            eff,
            torque_load,
            bl_base,
        };
        let rate = scenario.sample_rate_hz;
        let dt = 1.0 / rate;
        let work = scenario.workload();
        // At most 1e7 (1 s period over the 0.1 us floor of `validate`).
        let nsub = u32::try_from(work.steps_per_row).unwrap_or(u32::MAX);
        let h = dt / f64::from(nsub);
        let events = scenario_events(scenario);
        let invalid = |message: String| SimError::Invalid {
            key: builder.blamed_key().to_string(),
            message,
        };
        let machine = builder.build(&scales).map_err(invalid)?;
        let mut scratch = scales;
        for (_, ev) in &events {
            if let ScenarioEvent::Fault(f) = ev {
                scratch.apply_fault(f);
                builder.build(&scratch).map_err(invalid)?;
            }
        }
        let (dv, di) = default_ranges(m, v_ll, f0);
        let sp = &scenario.sensors;
        let sensors = Sensors::new(
            sp,
            sp.v_range_v.unwrap_or(dv),
            sp.i_range_a.unwrap_or(di),
            scenario.seed,
        );
        let supply = Supply::new(vpk0, we0, h, builder.eff.unbalance);
        Ok(Run {
            scenario,
            builder,
            scales,
            events,
            machine,
            sensors,
            supply,
            n: work.rows,
            nsub,
            dt,
            np,
        })
    }

    /// Applies the events due at output sample `k`; true when the machine must be rebuilt.
    fn apply_events(&mut self, k: u64, next_event: &mut usize) -> bool {
        let mut rebuild = false;
        while *next_event < self.events.len() && self.events[*next_event].0 <= k {
            match self.events[*next_event].1 {
                ScenarioEvent::Supply(s) => self.supply.step(&s),
                ScenarioEvent::Load(s) => {
                    if let Some(tq) = s.torque_nm {
                        self.scales.torque_nm = tq;
                    }
                    if let Some(b) = s.bl_scale {
                        self.scales.bl_scale = b;
                    }
                    rebuild = true;
                }
                ScenarioEvent::Fault(f) => {
                    if f.kind.is_sensor() {
                        self.sensors.apply_fault(&f);
                    } else {
                        self.scales.apply_fault(&f);
                        rebuild = true;
                    }
                }
            }
            *next_event += 1;
        }
        rebuild
    }

    /// The winding temperature rise at time `t` (`thermal_drift`), from the previous one and
    /// the last output sample's losses; `None` when it did not change.
    fn temperature_rise(&self, t: f64, k: u64, dtemp: f64, last_p_loss: f64) -> Option<f64> {
        let th = self.builder.eff.thermal?;
        let new = match th.rise_k {
            Some(rise) if t >= th.at_s => rise * (1.0 - (-(t - th.at_s) / th.tau_s).exp()),
            Some(_) => 0.0,
            None if t >= th.at_s => {
                let target = th.r_th * last_p_loss;
                target + (dtemp - target) * (-self.dt / th.tau_s).exp()
            }
            None => 0.0,
        };
        (new != dtemp || k == 0).then_some(new)
    }

    /// Runs to the end, or until `on_row` breaks; the summary and whether it ran to the end.
    fn run(
        self,
        mut on_row: impl FnMut(&Row, &Truth) -> ControlFlow<()>,
    ) -> Result<(SimSummary, bool), SimError> {
        self.run_with_events(|r, t, _| on_row(r, t))
    }

    /// Queues `added` to act at output sample `k`, leaving out an event that would make
    /// the machine unphysical.
    fn insert_events(&mut self, k: u64, next_event: usize, added: &mut Vec<ScenarioEvent>) {
        for (n, ev) in added.drain(..).enumerate() {
            if let ScenarioEvent::Fault(f) = ev {
                let mut scratch = self.scales;
                scratch.apply_fault(&f);
                if f.validate().is_err() || self.builder.build(&scratch).is_err() {
                    continue;
                }
            }
            let at = (next_event + n).min(self.events.len());
            self.events.insert(at, (k, ev));
        }
    }

    /// [`Run::run`] whose callback may add events ([`simulate_interactive`]).
    fn run_with_events(
        mut self,
        mut on_row: impl FnMut(&Row, &Truth, &mut Vec<ScenarioEvent>) -> ControlFlow<()>,
    ) -> Result<(SimSummary, bool), SimError> {
        let mut added = Vec::new();
        let mut x = [0.0f64; 6];
        let mut next_event = 0usize;
        let mut dtemp = 0.0f64;
        let mut max_i2 = 0.0f64;
        let mut last_p_loss = 0.0f64;
        for k in 0..self.n {
            let t = k as f64 * self.dt;
            let mut rebuild = self.apply_events(k, &mut next_event);
            if let Some(new) = self.temperature_rise(t, k, dtemp, last_p_loss) {
                dtemp = new;
                let alpha = self.builder.eff.thermal.map(|th| th.alpha).unwrap_or(0.0);
                let rotor = self.builder.eff.thermal.is_some_and(|th| th.rotor);
                self.scales.th_s = 1.0 + alpha * dtemp;
                self.scales.th_r = if rotor { self.scales.th_s } else { 1.0 };
                rebuild = true;
            }
            if rebuild {
                let nm = self
                    .builder
                    .build(&self.scales)
                    .map_err(|message| SimError::Invalid {
                        key: self.builder.blamed_key().to_string(),
                        message,
                    })?;
                nm.take_guess(&self.machine);
                self.machine = nm;
            }
            // Outputs at t.
            let v = self.supply.voltage(self.supply.p);
            let tr = truth(&self.machine, &x, v, t, self.supply.we, dtemp);
            last_p_loss = tr.p_cu_w + tr.p_fe_w;
            max_i2 = max_i2.max(tr.i_ab[0] * tr.i_ab[0] + tr.i_ab[1] * tr.i_ab[1]);
            let row = self.sensors.measure(&tr, self.dt);
            if on_row(&row, &tr, &mut added).is_break() {
                return Ok((self.summary(x[4], max_i2.sqrt()), false));
            }
            if !added.is_empty() {
                self.insert_events(k + 1, next_event, &mut added);
            }
            // Integrate to t + dt.
            self.supply.integrate(&self.machine, &mut x, self.nsub);
            if !(x[0].is_finite() && x[2].is_finite() && x[4].is_finite()) {
                return Err(SimError::Diverged { t_s: t + self.dt });
            }
        }
        Ok((self.summary(x[4], max_i2.sqrt()), true))
    }

    fn summary(&self, wm: f64, max_abs_current_a: f64) -> SimSummary {
        let sc = self.scenario;
        SimSummary {
            rows: self.n,
            duration_s: sc.duration_s,
            sample_rate_hz: sc.sample_rate_hz,
            step_s: self.supply.h,
            substeps_per_sample: self.nsub,
            v_range_v: self.sensors.v_range_v,
            i_range_a: self.sensors.i_range_a,
            noise_v: self.sensors.noise_v,
            noise_i: self.sensors.noise_i,
            final_wm_rad_s: wm,
            final_slip: 1.0 - self.np * wm / self.supply.we,
            max_abs_current_a,
            effects: sc
                .effects
                .iter()
                .map(|e| e.kind().name().to_string())
                .collect(),
            faults: sc.faults.len(),
        }
    }
}

fn truth(model: &Machine, x: &[f64; 6], v: [f64; 2], t: f64, we: f64, dtemp: f64) -> Truth {
    let psp = [x[0], x[1]];
    let pr = [x[2], x[3]];
    let c = model.currents(psp, pr);
    let is = model.real_is(c.i_s);
    let ps = model.t_mat.mul(psp);
    let u = model.u(v, is);
    let it = [is[0] + u[0] * model.inv_rfe, is[1] + u[1] * model.inv_rfe];
    let abc = |a: [f64; 2]| {
        inverse_clarke(
            AlphaBeta {
                alpha: a[0],
                beta: a[1],
            },
            0.0,
        )
        .to_array()
    };
    let te = model.torque(pr, c.i_r);
    let wm = x[4];
    Truth {
        t_s: t,
        v_abc: abc(v),
        i_abc: abc(it),
        v_ab: v,
        i_ab: it,
        psi_s: ps,
        psi_r: pr,
        i_s: is,
        i_r: c.i_r,
        wm_rad_s: wm,
        theta_m_rad: x[5],
        we_rad_s: we,
        te_nm: te,
        t_load_nm: model.load.torque(wm),
        rs_ohm: model.rs,
        rr_ohm: model.rr,
        lm_h: c.lm,
        p_in_w: 1.5 * (v[0] * it[0] + v[1] * it[1]),
        p_cu_w: 1.5 * (model.r_s.quad(it) + model.rotor_r(x[5]).quad(c.i_r)),
        p_fe_w: 1.5 * (u[0] * u[0] + u[1] * u[1]) * model.inv_rfe,
        p_mech_w: te * wm,
        stored_energy_j: 0.75
            * (ps[0] * is[0] + ps[1] * is[1] + pr[0] * c.i_r[0] + pr[1] * c.i_r[1]),
        temperature_rise_k: dtemp,
    }
}
