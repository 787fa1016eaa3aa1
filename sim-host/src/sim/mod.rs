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
//! Integration: classic fixed-step RK4, an integer number of steps per output sample
//! (h <= `max_step_s`, default 100 us), the supply phasor rotated incrementally (no trig per
//! step). Accuracy on the 2.2 kW reference start (10 kHz, h = 100 us) against a 100x finer
//! run: see [`bench_reference`] (max current error about 1e-5 A).
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
//! name = "thermal_drift"     # see `Effect` for every effect and its parameters
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
//! See [`Effect`]: `thermal_drift`, `saturation`, `iron_loss`, `coulomb_friction`, `windage`,
//! `load_torque`, `supply_unbalance`, `phase_asymmetry`; `flux_dynamics` and
//! `current_dynamics` are properties of the full-order model (always present), so enabling
//! them is a no-op for generation.
//!
//! # Separation of truth and measurement
//! Other code gets only [`Row`]s of sensor readings ([`simulate`]); the true state
//! ([`Truth`]) is available to tests through [`simulate_with_truth`] and never enters a row.

mod model;
mod scenario;
mod sensors;
mod steady;

pub use scenario::{
    Effect, FaultKind, FaultSpec, LoadKind, LoadSpec, LoadStep, Phase, Scenario, SensorFaultMode,
    SensorSpec, SupplySpec, SupplyStep, DEFAULT_MAX_STEP_S,
};
pub use steady::{
    solve_slip, solve_slip_at, steady_state, steady_state_at, SteadyLoad, SteadyState,
};

use crate::log::{Channels, Row};
use crate::params::{MotorParams, ParamFile};
use model::{LoadLaw, Model, SatLaw, Sym2};
use sensors::Sensors;
use std::f64::consts::PI;

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
    /// Copper losses (3/2)(i^T R_s i + Rr |i_r|^2) [W].
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
pub fn default_ranges(m: &MotorParams, v_ll_rms: f64, f_hz: f64) -> (f64, f64) {
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

/// [`simulate`] collecting the rows in memory.
///
/// # Errors
/// As [`simulate`].
pub fn simulate_to_vec(params: &ParamFile, scenario: &Scenario) -> Result<Vec<Row>, SimError> {
    let mut rows = Vec::with_capacity((scenario.duration_s * scenario.sample_rate_hz) as usize + 1);
    simulate(params, scenario, |r| rows.push(*r))?;
    Ok(rows)
}

/// Resolved effect parameters.
#[derive(Debug, Clone, Default)]
struct Effects {
    thermal: Option<Thermal>,
    sat: Option<SatLaw>,
    rfe: Option<f64>,
    coulomb: Option<(f64, f64)>,
    windage: f64,
    load_torque: Option<f64>,
    unbalance: Option<(f64, f64)>,
    asym: Option<(usize, f64)>,
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

/// Multiplicative parameter modifications in effect.
#[derive(Debug, Clone, Copy)]
struct Mods {
    rs: f64,
    rr: f64,
    lls: f64,
    llr: f64,
    b: f64,
    bl: f64,
    th_s: f64,
    th_r: f64,
    /// Viscous load: Bl scale from load steps. Torque load: torque [N m].
    bl_scale: f64,
    torque_nm: f64,
}

impl Default for Mods {
    fn default() -> Self {
        Mods {
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

struct Setup<'a> {
    m: &'a MotorParams,
    eff: Effects,
    torque_load: bool,
    bl_base: f64,
}

impl Setup<'_> {
    fn build(&self, md: &Mods) -> Result<Model, String> {
        let m = self.m;
        let rs = m.rs_ohm * md.rs * md.th_s;
        let rr = m.rr_ohm * md.rr * md.th_r;
        let gamma_s = m.lls_h() <= 1e-9 * m.lm_h;
        let gamma_r = m.llr_h() <= 1e-9 * m.lm_h;
        let mut lm = m.lm_h;
        if gamma_s {
            lm *= md.lls;
        }
        if gamma_r {
            lm *= md.llr;
        }
        let lls = if gamma_s { 0.0 } else { m.lls_h() * md.lls };
        let llr = if gamma_r { 0.0 } else { m.llr_h() * md.llr };
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
        Model::new(
            rs,
            t_mat,
            lls,
            llr,
            rr,
            lm,
            self.eff.sat,
            self.eff.rfe,
            m.pole_pairs(),
            m.j_kgm2,
            m.b_nms * md.b,
            load,
        )
    }
}

#[derive(Debug, Clone, Copy)]
enum Ev {
    Supply(SupplyStep),
    Load(LoadStep),
    Fault(FaultSpec),
}

fn apply_param_fault(md: &mut Mods, f: &FaultSpec) {
    let k = 1.0 + f.change.unwrap_or(0.0);
    match f.kind {
        FaultKind::Rs => md.rs *= k,
        FaultKind::Rr => md.rr *= k,
        FaultKind::Ls => md.lls *= k,
        FaultKind::Lr => md.llr *= k,
        FaultKind::B => md.b *= k,
        FaultKind::Bl => md.bl *= k,
        _ => {}
    }
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
    scenario.validate()?;
    params.check().map_err(|message| SimError::Invalid {
        key: "params".into(),
        message,
    })?;
    let m = &params.motor;
    let v_ll = scenario.supply.v_ll_rms.unwrap_or(params.supply.v_ll_rms);
    let f0 = scenario.supply.f_hz.unwrap_or(params.supply.f_hz);
    let np = m.pole_pairs();
    let vpk0 = v_ll * (2.0f64 / 3.0).sqrt();
    let we0 = 2.0 * PI * f0;
    let bl_base = scenario.load.bl_nms.unwrap_or(m.bl_nms);
    let w_sync = we0 / np;
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

    // Resolve effects.
    let mut eff = Effects::default();
    for e in &scenario.effects {
        match *e {
            Effect::ThermalDrift {
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
            Effect::Saturation {
                psi_sat_wb,
                psi_sat_ratio,
                exponent,
            } => {
                eff.sat = Some(SatLaw {
                    psi_sat_wb: psi_sat_wb.unwrap_or(psi_sat_ratio * vpk0 / we0),
                    exponent,
                })
            }
            Effect::IronLoss {
                rfe_ohm,
                rfe_over_xm,
            } => eff.rfe = Some(rfe_ohm.unwrap_or(rfe_over_xm * we0 * m.lm_h)),
            Effect::CoulombFriction {
                torque_nm,
                omega0_rad_s,
            } => eff.coulomb = Some((torque_nm.unwrap_or(0.02 * t_rated), omega0_rad_s)),
            Effect::Windage { k_nms2 } => {
                eff.windage = k_nms2.unwrap_or(0.05 * t_rated / (w_sync * w_sync))
            }
            Effect::LoadTorque { torque_nm } => {
                if scenario.load.kind == LoadKind::Torque {
                    return Err(SimError::Invalid {
                        key: "effects.load_torque".into(),
                        message: "the load is already a torque load (load.kind = \"torque\")"
                            .into(),
                    });
                }
                eff.load_torque = Some(torque_nm.unwrap_or(bl_base * w_sync));
            }
            Effect::SupplyUnbalance {
                fraction,
                angle_deg,
            } => eff.unbalance = Some((fraction, angle_deg.to_radians())),
            Effect::PhaseAsymmetry { phase, fraction } => {
                eff.asym = Some((phase.index(), fraction))
            }
            Effect::FluxDynamics {} | Effect::CurrentDynamics {} => {}
        }
    }
    let torque_load = scenario.load.kind == LoadKind::Torque || eff.load_torque.is_some();
    let mut md = Mods {
        torque_nm: eff.load_torque.or(scenario.load.torque_nm).unwrap_or(0.0),
        ..Mods::default()
    };
    let setup = Setup {
        m,
        eff,
        torque_load,
        bl_base,
    };

    // Timing and events.
    let rate = scenario.sample_rate_hz;
    let dt = 1.0 / rate;
    let n = (scenario.duration_s * rate).round() as u64;
    let hmax = scenario.max_step_s.unwrap_or(DEFAULT_MAX_STEP_S);
    let nsub = ((dt / hmax) * (1.0 - 1e-12)).ceil().max(1.0) as u32;
    let h = dt / f64::from(nsub);
    let idx = |t: f64| (t * rate - 1e-9).ceil().max(0.0) as u64;
    let mut events: Vec<(u64, Ev)> = Vec::new();
    events.extend(
        scenario
            .supply
            .steps
            .iter()
            .map(|s| (idx(s.t_s), Ev::Supply(*s))),
    );
    events.extend(
        scenario
            .load
            .steps
            .iter()
            .map(|s| (idx(s.t_s), Ev::Load(*s))),
    );
    events.extend(scenario.faults.iter().map(|f| (idx(f.at_s), Ev::Fault(*f))));
    events.sort_by_key(|e| e.0);

    // Check every parameter set the run will pass through, before the first row.
    let invalid = |key: &str, message: String| SimError::Invalid {
        key: key.to_string(),
        message,
    };
    let key_of = || {
        if setup.eff.asym.is_some() {
            "effects.phase_asymmetry"
        } else {
            "faults"
        }
    };
    let mut model = setup.build(&md).map_err(|e| invalid(key_of(), e))?;
    {
        let mut scratch = md;
        for (_, ev) in &events {
            if let Ev::Fault(f) = ev {
                apply_param_fault(&mut scratch, f);
                setup.build(&scratch).map_err(|e| invalid(key_of(), e))?;
            }
        }
    }

    let (dv, di) = default_ranges(m, v_ll, f0);
    let sp = &scenario.sensors;
    let mut sensors = Sensors::new(
        sp,
        sp.v_range_v.unwrap_or(dv),
        sp.i_range_a.unwrap_or(di),
        scenario.seed,
    );

    // Supply state: positive-sequence unit phasor p, rotated by e^{j we h/2} twice per step.
    let mut vpk = vpk0;
    let mut we = we0;
    let (kn, cn, sn) = match setup.eff.unbalance {
        Some((k, phi)) => (k, phi.cos(), phi.sin()),
        None => (0.0, 1.0, 0.0),
    };
    let mut p = [1.0f64, 0.0f64];
    let mut rot = [(0.5 * we * h).cos(), (0.5 * we * h).sin()];
    let sv = |p: [f64; 2], vpk: f64| -> [f64; 2] {
        [
            vpk * (p[0] + kn * (cn * p[0] + sn * p[1])),
            vpk * (p[1] + kn * (sn * p[0] - cn * p[1])),
        ]
    };
    let rotate = |p: [f64; 2], r: [f64; 2]| [p[0] * r[0] - p[1] * r[1], p[0] * r[1] + p[1] * r[0]];

    let mut x = [0.0f64; 6];
    let mut ev_i = 0usize;
    let mut dtemp = 0.0f64;
    let mut max_i2 = 0.0f64;
    let mut last_p_loss = 0.0f64;
    let s3 = 3f64.sqrt() / 2.0;
    for k in 0..n {
        let t = k as f64 * dt;
        let mut rebuild = false;
        while ev_i < events.len() && events[ev_i].0 <= k {
            match events[ev_i].1 {
                Ev::Supply(s) => {
                    if let Some(v) = s.v_scale {
                        vpk = vpk0 * v;
                    }
                    if let Some(f) = s.f_hz {
                        we = 2.0 * PI * f;
                        rot = [(0.5 * we * h).cos(), (0.5 * we * h).sin()];
                    }
                }
                Ev::Load(s) => {
                    if let Some(tq) = s.torque_nm {
                        md.torque_nm = tq;
                    }
                    if let Some(b) = s.bl_scale {
                        md.bl_scale = b;
                    }
                    rebuild = true;
                }
                Ev::Fault(f) => {
                    if f.kind.is_sensor() {
                        sensors.apply_fault(&f);
                    } else {
                        apply_param_fault(&mut md, &f);
                        rebuild = true;
                    }
                }
            }
            ev_i += 1;
        }
        if let Some(th) = setup.eff.thermal {
            let new = match th.rise_k {
                Some(rise) if t >= th.at_s => rise * (1.0 - (-(t - th.at_s) / th.tau_s).exp()),
                Some(_) => 0.0,
                None if t >= th.at_s => {
                    let target = th.r_th * last_p_loss;
                    target + (dtemp - target) * (-dt / th.tau_s).exp()
                }
                None => 0.0,
            };
            if new != dtemp || k == 0 {
                dtemp = new;
                md.th_s = 1.0 + th.alpha * dtemp;
                md.th_r = if th.rotor { md.th_s } else { 1.0 };
                rebuild = true;
            }
        }
        if rebuild {
            let nm = setup.build(&md).map_err(|e| invalid(key_of(), e))?;
            nm.take_guess(&model);
            model = nm;
        }

        // Outputs at t.
        let v = sv(p, vpk);
        let tr = truth(&model, &x, v, t, we, dtemp, s3);
        last_p_loss = tr.p_cu_w + tr.p_fe_w;
        max_i2 = max_i2.max(tr.i_ab[0] * tr.i_ab[0] + tr.i_ab[1] * tr.i_ab[1]);
        let row = sensors.measure(&tr, dt);
        on_row(&row, &tr);

        // Integrate to t + dt.
        for _ in 0..nsub {
            let pm = rotate(p, rot);
            let pe = rotate(pm, rot);
            model.rk4(&mut x, h, sv(p, vpk), sv(pm, vpk), sv(pe, vpk));
            p = pe;
        }
        // Renormalise |p| = 1 (first-order Newton step: no sqrt, |p| drifts by ~1e-16/step).
        let norm = 1.5 - 0.5 * (p[0] * p[0] + p[1] * p[1]);
        p = [p[0] * norm, p[1] * norm];
        if !(x[0].is_finite() && x[2].is_finite() && x[4].is_finite()) {
            return Err(SimError::Diverged { t_s: t + dt });
        }
    }
    let wm = x[4];
    Ok(SimSummary {
        rows: n,
        duration_s: scenario.duration_s,
        sample_rate_hz: rate,
        step_s: h,
        substeps_per_sample: nsub,
        v_range_v: sensors.v_range_v,
        i_range_a: sensors.i_range_a,
        noise_v: sensors.noise_v,
        noise_i: sensors.noise_i,
        final_wm_rad_s: wm,
        final_slip: 1.0 - np * wm / we,
        max_abs_current_a: max_i2.sqrt(),
        effects: scenario
            .effects
            .iter()
            .map(|e| e.name().to_string())
            .collect(),
        faults: scenario.faults.len(),
    })
}

fn truth(model: &Model, x: &[f64; 6], v: [f64; 2], t: f64, we: f64, dtemp: f64, s3: f64) -> Truth {
    let psp = [x[0], x[1]];
    let pr = [x[2], x[3]];
    let c = model.currents(psp, pr);
    let is = model.real_is(c.i_s);
    let ps = model.t_mat.mul(psp);
    let u = model.u(v, is);
    let it = [is[0] + u[0] * model.inv_rfe, is[1] + u[1] * model.inv_rfe];
    let abc = |a: [f64; 2]| [a[0], -0.5 * a[0] + s3 * a[1], -0.5 * a[0] - s3 * a[1]];
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
        p_cu_w: 1.5 * (model.r_s.quad(it) + model.rr * (c.i_r[0].powi(2) + c.i_r[1].powi(2))),
        p_fe_w: 1.5 * (u[0] * u[0] + u[1] * u[1]) * model.inv_rfe,
        p_mech_w: te * wm,
        stored_energy_j: 0.75
            * (ps[0] * is[0] + ps[1] * is[1] + pr[0] * c.i_r[0] + pr[1] * c.i_r[1]),
        temperature_rise_k: dtemp,
    }
}
