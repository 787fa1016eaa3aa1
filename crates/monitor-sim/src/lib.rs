//! Induction-motor simulator (f64): full-order T-equivalent machine, stiff supply, load,
//! faults, physical effects and sensors, producing rows in the log schema (`docs/design.md`).
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
//! v_s = V e^{j theta_e} (+ negative sequence with `supply_unbalance`, + the voltage
//! harmonics of `[supply] harmonics`, each in the sequence of its order), V = sqrt(2/3) V_ll,rms,
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
//! run: see `monitor_studies::bench` (max current error about 1e-6 A).
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
//! # Inverter-fed supply
//! [`pwm::apply_pwm`] adds a two-level PWM inverter's switching ripple (space-vector
//! modulation, regular sampled, a single-pole front end) to the voltages and currents of
//! rows simulated on the sinusoidal supply: a post-processing step, nothing else changes.
//!
//! # Faults
//! `rs, rr`: resistance x (1 + change). `ls, lr`: LEAKAGE inductance x (1 + change), the self
//! inductances follow (PSIM's convention, `docs/design.md`); for a Gamma-model machine with no
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

mod effect_spec;
mod faults;
pub mod machine;
pub mod pwm;
mod resolve;
mod run;
mod scenario;
mod sensors;
mod steady;
mod supply;
mod thermometer;

pub use effect_spec::EffectSpec;
pub use faults::{FaultSpec, SensorFaultMode};
pub use scenario::{
    LoadKind, LoadSpec, LoadStep, Scenario, SupplyHarmonic, SupplySpec, SupplyStep, UserLaws,
    Workload, DEFAULT_MAX_STEP_S, MIN_STEP_S, SAMPLE_RATE_RANGE_HZ,
};
pub use sensors::SensorSpec;
pub use steady::{
    solve_slip, solve_slip_at, steady_state, steady_state_at, SteadyLoad, SteadyState,
};
pub use thermometer::TemperatureSpec;

use monitor_io::log::Row;
use monitor_io::params::ParamFile;
use run::checked_run;
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
    #[error("simulation diverged at t = {t_s} s: {cause}")]
    Diverged {
        /// Time of the first non-finite state [s].
        t_s: f64,
        /// The scenario value it followed (the last step before it, in the scenario's
        /// keys), or what to check when it diverged from the start.
        cause: String,
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
