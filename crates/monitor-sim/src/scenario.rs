//! The scenario file: what to simulate (supply, load, faults, effects, sensors, timing).
//!
//! See the module documentation of [`crate`] for the TOML format.

use super::{EffectSpec, FaultSpec, SensorSpec, SimError};
use serde::{Deserialize, Serialize};
use std::path::Path;

/// A whole scenario: timing, supply, load, faults, physical effects and sensors.
///
/// Built from TOML ([`Scenario::load`], [`Scenario::from_toml_str`]) or in code
/// ([`Scenario::steady`], [`Scenario::reference_2p2kw`]) and then edited through the public
/// fields. Unknown keys are an error everywhere.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Scenario {
    /// Simulated time [s], > 0. Rows are produced at `t = k / sample_rate_hz` for
    /// `k = 0 .. round(duration_s * sample_rate_hz)` (end excluded).
    pub duration_s: f64,
    /// Output sample rate [Hz], > 0.
    pub sample_rate_hz: f64,
    /// Seed of the sensor-noise generator (ChaCha8); the same seed gives the same rows.
    #[serde(default = "default_seed")]
    pub seed: u64,
    /// Largest integrator step [s] (fixed-step RK4, an integer number of steps per output
    /// sample). Default [`DEFAULT_MAX_STEP_S`] = 100 us: max current error about 1e-5 A on
    /// the 2.2 kW reference start against a 100x finer run.
    #[serde(default)]
    pub max_step_s: Option<f64>,
    /// Supply: overrides of the parameter file's supply and steps. Default: the file's supply.
    #[serde(default)]
    pub supply: SupplySpec,
    /// Mechanical load. Default: the paper's viscous load `Bl * omega` with the file's Bl.
    #[serde(default)]
    pub load: LoadSpec,
    /// Faults switched on at given times.
    #[serde(default)]
    pub faults: Vec<FaultSpec>,
    /// Physical effects (on for the whole run unless the effect has its own `at_s`).
    #[serde(default)]
    pub effects: Vec<EffectSpec>,
    /// Sensor chain (ADC, errors, noise, encoder). Default: [`SensorSpec::default`].
    #[serde(default)]
    pub sensors: SensorSpec,
    /// Users' laws the run injects (`simulate --laws FILE`: each law of the file at its
    /// parameters' start values); not written in a scenario file.
    #[serde(skip)]
    pub laws: UserLaws,
}

/// Users' laws a run injects ([`Scenario::laws`]): load torques of time, speed and the
/// shaft's angle, resistances of time, the magnetising inductance of its flux (an
/// expression or a no-load curve), evaluated by the same [`monitor_laws::Law`] the analysis
/// fits.
#[derive(Debug, Clone, Default)]
pub struct UserLaws(pub Vec<monitor_laws::BoundLaw>);

impl UserLaws {
    /// The laws.
    pub fn iter(&self) -> std::slice::Iter<'_, monitor_laws::BoundLaw> {
        self.0.iter()
    }
}

impl PartialEq for UserLaws {
    /// The same laws (by name) at the same values.
    fn eq(&self, other: &Self) -> bool {
        self.0.len() == other.0.len()
            && self
                .0
                .iter()
                .zip(&other.0)
                .all(|(a, b)| a.law.id == b.law.id && a.values == b.values)
    }
}

/// Default largest integrator step [s].
pub const DEFAULT_MAX_STEP_S: f64 = 1.0e-4;

/// Output sample rates a scenario may ask for [Hz]: 1 Hz ..= 1 MHz. The monitor reads logs
/// of 1 kHz to 50 kHz; the simulator writes outside that band too (slow rates for long
/// thermal runs, fast ones for other tools); above 1 MHz there is nothing left to resolve
/// (the model has no PWM switching) and a second of output would be about 100 MB.
pub const SAMPLE_RATE_RANGE_HZ: (f64, f64) = (1.0, 1.0e6);

/// Smallest `max_step_s` [s]: 0.1 us. Fixed-step RK4 at the default 100 us is already
/// accurate to about 1e-5 A on the reference start (a 100x finer run is the accuracy
/// reference, 1 us); a step a thousand times finer than that adds only rounding error
/// and makes a 10 s run take 1e8 steps.
pub const MIN_STEP_S: f64 = 1.0e-7;

/// What a scenario costs before it runs ([`Scenario::workload`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Workload {
    /// Output rows: round(duration_s * sample_rate_hz).
    pub rows: u64,
    /// RK4 steps per output row: ceil(sample period / max_step_s), >= 1.
    pub steps_per_row: u64,
    /// Integrator steps of the whole run: rows * steps_per_row (as f64: it may be huge).
    pub steps: f64,
}

fn default_seed() -> u64 {
    1
}

/// Supply section: a stiff three-phase source.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SupplySpec {
    /// Line-to-line RMS voltage [V] at t = 0 (default: the parameter file's `v_ll_rms`).
    #[serde(default)]
    pub v_ll_rms: Option<f64>,
    /// Frequency [Hz] at t = 0 (default: the parameter file's `f_hz`).
    #[serde(default)]
    pub f_hz: Option<f64>,
    /// Steps, applied at the first output sample at or after `t_s`, phase-continuous.
    #[serde(default)]
    pub steps: Vec<SupplyStep>,
    /// Voltage harmonics of the supply (a grid's 5th and 7th, a few per cent each),
    /// `harmonics = [{ order = 5, fraction = 0.03 }]`: each follows the fundamental's
    /// phase and frequency and scales with its voltage steps.
    #[serde(default)]
    pub harmonics: Vec<SupplyHarmonic>,
}

/// One voltage harmonic of the supply: `fraction` of the fundamental's amplitude at
/// `order` times its frequency, in the sequence of its order (5, 11, 17, ...: negative,
/// turning against the fundamental; 7, 13, 19, ...: positive), at `phase_deg` against
/// the fundamental's phase times the order. The phase voltages of a balanced set: orders
/// divisible by 3 are zero-sequence, which a three-wire motor draws no current from, and
/// are refused.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SupplyHarmonic {
    /// Harmonic order n (2..=49, not a multiple of 3).
    pub order: u32,
    /// Amplitude as a fraction of the fundamental's (0..=0.2; EN 50160 allows 6 % of the 5th).
    pub fraction: f64,
    /// Phase [deg] against the fundamental's phase times `order` (default 0).
    #[serde(default)]
    pub phase_deg: f64,
}

impl SupplyHarmonic {
    /// Whether the harmonic turns with the fundamental (order 3k + 1) or against it (3k + 2).
    pub fn positive_sequence(&self) -> bool {
        self.order % 3 == 1
    }
}

/// One supply step. Either or both of `v_scale` and `f_hz`.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SupplyStep {
    /// Time of the step [s].
    pub t_s: f64,
    /// New voltage as a multiple of the initial voltage (1.05 = +5 %), > 0.
    #[serde(default)]
    pub v_scale: Option<f64>,
    /// New frequency [Hz], > 0.
    #[serde(default)]
    pub f_hz: Option<f64>,
}

/// How the load torque depends on speed.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum LoadKind {
    /// The paper's load: T_L = Bl * omega_m [N m] (Bl on the shaft, omega_m mechanical).
    #[default]
    Viscous,
    /// A prescribed torque T_L(t) [N m], independent of speed (positive opposes motoring).
    Torque,
}

/// Load section.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct LoadSpec {
    /// `"viscous"` (default) or `"torque"`.
    #[serde(default)]
    pub kind: LoadKind,
    /// Initial load torque [N m] for `kind = "torque"` (default 0).
    #[serde(default)]
    pub torque_nm: Option<f64>,
    /// Load coefficient Bl [N m s/rad] for `kind = "viscous"` (default: the parameter file's).
    #[serde(default)]
    pub bl_nms: Option<f64>,
    /// Load steps at the first output sample at or after `t_s`.
    #[serde(default)]
    pub steps: Vec<LoadStep>,
}

/// One load step: `torque_nm` (torque load) or `bl_scale` (viscous load).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct LoadStep {
    /// Time of the step [s].
    pub t_s: f64,
    /// New load torque [N m] (torque load only).
    #[serde(default)]
    pub torque_nm: Option<f64>,
    /// New Bl as a multiple of the initial Bl (viscous load only), >= 0.
    #[serde(default)]
    pub bl_scale: Option<f64>,
}

pub(super) fn d_true() -> bool {
    true
}

impl Scenario {
    /// A healthy run of `duration_s` at `sample_rate_hz`: the parameter file's supply, the
    /// paper's viscous load, no faults or effects, ideal sensors, seed 1. Starts from
    /// standstill (direct-on-line).
    pub fn steady(duration_s: f64, sample_rate_hz: f64) -> Self {
        Scenario {
            duration_s,
            sample_rate_hz,
            seed: 1,
            max_step_s: None,
            supply: SupplySpec::default(),
            load: LoadSpec::default(),
            faults: Vec::new(),
            effects: Vec::new(),
            sensors: SensorSpec::ideal(),
            laws: UserLaws::default(),
        }
    }

    /// The reference scenario for the 2.2 kW machine: direct-on-line from
    /// standstill, 14.6 N m constant load torque from 2.5 s, 10 s at 10 kHz, ideal sensors.
    pub fn reference_2p2kw() -> Self {
        Scenario {
            load: LoadSpec {
                kind: LoadKind::Torque,
                torque_nm: Some(0.0),
                bl_nms: None,
                steps: vec![LoadStep {
                    t_s: 2.5,
                    torque_nm: Some(14.6),
                    bl_scale: None,
                }],
            },
            ..Scenario::steady(10.0, 10_000.0)
        }
    }

    /// Parses scenario TOML; `origin` names the source in messages.
    ///
    /// # Errors
    /// [`SimError::Toml`] (syntax, unknown or missing key, with the line and column) or
    /// [`SimError::Invalid`] (a value out of range, naming the key).
    pub fn from_toml_str(text: &str, origin: &str) -> Result<Self, SimError> {
        let s: Scenario = toml::from_str(text).map_err(|e| SimError::Toml {
            path: origin.to_string(),
            message: monitor_io::params::toml_error_message(text, &e),
        })?;
        s.validate()?;
        Ok(s)
    }

    /// Reads and checks a scenario file.
    ///
    /// # Errors
    /// [`SimError::Io`] if unreadable, otherwise as [`Scenario::from_toml_str`].
    pub fn load(path: &Path) -> Result<Self, SimError> {
        let text = std::fs::read_to_string(path).map_err(|source| SimError::Io {
            path: path.display().to_string(),
            source,
        })?;
        Self::from_toml_str(&text, &path.display().to_string())
    }

    /// The run's size: output rows and integrator steps (the integer number of RK4 steps
    /// per output sample is the smallest that keeps the step at or below `max_step_s`).
    /// Meaningful for a scenario that passed [`Scenario::validate`].
    pub fn workload(&self) -> Workload {
        let rows = (self.duration_s * self.sample_rate_hz).round();
        let period = 1.0 / self.sample_rate_hz;
        let hmax = self.max_step_s.unwrap_or(DEFAULT_MAX_STEP_S);
        // The 1e-12 keeps a step that divides the period exactly from rounding up.
        let steps_per_row = ((period / hmax) * (1.0 - 1e-12)).ceil().max(1.0);
        Workload {
            rows: rows as u64,
            steps_per_row: steps_per_row as u64,
            steps: rows * steps_per_row,
        }
    }

    /// Serialises to TOML.
    pub fn to_toml_string(&self) -> String {
        toml::to_string_pretty(self).unwrap_or_default()
    }

    /// Checks ranges that do not need the motor parameters (those are checked by
    /// [`crate::simulate`]).
    ///
    /// # Errors
    /// [`SimError::Invalid`] naming the key.
    pub fn validate(&self) -> Result<(), SimError> {
        positive("duration_s", self.duration_s)?;
        let (lo, hi) = SAMPLE_RATE_RANGE_HZ;
        if !(self.sample_rate_hz.is_finite() && (lo..=hi).contains(&self.sample_rate_hz)) {
            return invalid(
                "sample_rate_hz",
                format!("must be in {lo}..={hi} Hz, got {}", self.sample_rate_hz),
            );
        }
        if self.duration_s * self.sample_rate_hz > 1.0e10 {
            return invalid("duration_s", "more than 1e10 samples".into());
        }
        if let Some(h) = self.max_step_s {
            // The sample period with a little slack, so that 1/rate written out is accepted.
            let period = 1.0 / self.sample_rate_hz;
            if !(h.is_finite() && h >= MIN_STEP_S && h <= period * (1.0 + 1e-9)) {
                return invalid(
                    "max_step_s",
                    format!(
                        "must be in {MIN_STEP_S:e}..={period:e} s (the sample period), got {h:e}"
                    ),
                );
            }
        }
        self.supply.validate()?;
        self.load.validate()?;
        for f in &self.faults {
            f.validate()?;
        }
        for e in &self.effects {
            e.validate()?;
        }
        self.sensors.validate()
    }
}

impl SupplySpec {
    /// Checks the supply overrides and steps.
    ///
    /// # Errors
    /// [`SimError::Invalid`] naming the key.
    pub fn validate(&self) -> Result<(), SimError> {
        if let Some(v) = self.v_ll_rms {
            positive("supply.v_ll_rms", v)?;
        }
        if let Some(f) = self.f_hz {
            positive("supply.f_hz", f)?;
        }
        for st in &self.steps {
            not_negative("supply.steps.t_s", st.t_s)?;
            if st.v_scale.is_none() && st.f_hz.is_none() {
                return invalid("supply.steps", "a step needs v_scale or f_hz".into());
            }
            if let Some(v) = st.v_scale {
                positive("supply.steps.v_scale", v)?;
            }
            if let Some(f) = st.f_hz {
                positive("supply.steps.f_hz", f)?;
            }
        }
        for h in &self.harmonics {
            if !(2..=49).contains(&h.order) {
                return invalid(
                    "supply.harmonics.order",
                    format!("{} is not a harmonic order from 2 to 49", h.order),
                );
            }
            if h.order % 3 == 0 {
                return invalid(
                    "supply.harmonics.order",
                    format!(
                        "{} is a multiple of 3: a zero-sequence harmonic, which a three-wire motor draws no current from",
                        h.order
                    ),
                );
            }
            if !(0.0..=0.2).contains(&h.fraction) {
                return invalid(
                    "supply.harmonics.fraction",
                    format!("{} is outside 0..0.2 of the fundamental", h.fraction),
                );
            }
            if !h.phase_deg.is_finite() {
                return invalid(
                    "supply.harmonics.phase_deg",
                    "must be a finite number".into(),
                );
            }
        }
        Ok(())
    }
}

impl LoadSpec {
    /// Checks that the load's values and steps fit its kind.
    ///
    /// # Errors
    /// [`SimError::Invalid`] naming the key.
    pub fn validate(&self) -> Result<(), SimError> {
        match self.kind {
            LoadKind::Viscous => {
                if self.torque_nm.is_some() {
                    return invalid("load.torque_nm", "only for kind = \"torque\"".into());
                }
                if let Some(b) = self.bl_nms {
                    not_negative("load.bl_nms", b)?;
                }
            }
            LoadKind::Torque => {
                if self.bl_nms.is_some() {
                    return invalid("load.bl_nms", "only for kind = \"viscous\"".into());
                }
                if let Some(t) = self.torque_nm {
                    if !t.is_finite() {
                        return invalid("load.torque_nm", format!("must be finite, got {t}"));
                    }
                }
            }
        }
        for st in &self.steps {
            not_negative("load.steps.t_s", st.t_s)?;
            match (self.kind, st.torque_nm, st.bl_scale) {
                (LoadKind::Torque, Some(t), None) if t.is_finite() => {}
                (LoadKind::Viscous, None, Some(b)) => not_negative("load.steps.bl_scale", b)?,
                (LoadKind::Torque, _, _) => {
                    return invalid(
                        "load.steps",
                        "a torque load's step needs a finite torque_nm (and no bl_scale)".into(),
                    )
                }
                (LoadKind::Viscous, _, _) => {
                    return invalid(
                        "load.steps",
                        "a viscous load's step needs bl_scale (and no torque_nm)".into(),
                    )
                }
            }
        }
        Ok(())
    }
}

/// `Err(SimError::Invalid)` for `key`.
pub(super) fn invalid(key: &str, message: String) -> Result<(), SimError> {
    Err(SimError::Invalid {
        key: key.to_string(),
        message,
    })
}

/// Checks `v` is positive and finite.
pub(super) fn positive(key: &str, v: f64) -> Result<(), SimError> {
    if v.is_finite() && v > 0.0 {
        Ok(())
    } else {
        invalid(key, format!("must be a positive number, got {v}"))
    }
}

/// Checks `v` is finite and >= 0.
pub(super) fn not_negative(key: &str, v: f64) -> Result<(), SimError> {
    if v.is_finite() && v >= 0.0 {
        Ok(())
    } else {
        invalid(key, format!("must be >= 0, got {v}"))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn parse(text: &str) -> Result<Scenario, String> {
        Scenario::from_toml_str(text, "s.toml").map_err(|e| e.to_string())
    }

    #[test]
    fn sample_rate_and_step_outside_their_ranges_are_refused_with_the_range() {
        for ok in ["1.0", "1e6", "10000.0"] {
            parse(&format!("duration_s = 1.0\nsample_rate_hz = {ok}\n")).unwrap();
        }
        for bad in ["0.5", "2e6", "1e9", "inf", "nan"] {
            let e = parse(&format!("duration_s = 1.0\nsample_rate_hz = {bad}\n")).unwrap_err();
            assert!(
                e.contains("sample_rate_hz") && e.contains("1..=1000000 Hz"),
                "{e}"
            );
        }
        let with_step = |h: &str| {
            parse(&format!(
                "duration_s = 1.0\nsample_rate_hz = 1e4\nmax_step_s = {h}\n"
            ))
        };
        // The floor and the sample period itself are in range.
        for ok in ["1e-7", "1e-4", "0.0001", "3e-5"] {
            with_step(ok).unwrap();
        }
        for bad in ["1e-12", "5e-8", "2e-4", "0.0", "-1e-5"] {
            let e = with_step(bad).unwrap_err();
            assert!(
                e.contains("max_step_s") && e.contains("1e-7..=1e-4 s"),
                "{bad}: {e}"
            );
        }
    }

    #[test]
    fn workload_counts_rows_and_integrator_steps() {
        let w = |text: &str| parse(text).unwrap().workload();
        // 2 s at 10 kHz, the default 100 us step: one step a row.
        let a = w("duration_s = 2.0\nsample_rate_hz = 1e4\n");
        assert_eq!((a.rows, a.steps_per_row, a.steps), (20_000, 1, 20_000.0));
        // A 10 us step: ten a row. A 30 us step: ceil(100/30) = 4 a row (25 us).
        let b = w("duration_s = 2.0\nsample_rate_hz = 1e4\nmax_step_s = 1e-5\n");
        assert_eq!((b.rows, b.steps_per_row, b.steps), (20_000, 10, 200_000.0));
        let c = w("duration_s = 2.0\nsample_rate_hz = 1e4\nmax_step_s = 3e-5\n");
        assert_eq!(c.steps_per_row, 4);
        // 1 kHz with the default step: ten a row.
        let d = w("duration_s = 1.0\nsample_rate_hz = 1000.0\n");
        assert_eq!((d.rows, d.steps_per_row), (1000, 10));
    }

    #[test]
    fn toml_errors_give_line_and_column() {
        let e = parse("duration_s = 1.0\nsample_rate_hz = 1e4\nseed = = 2\n").unwrap_err();
        // "seed = = 2": the second '=' is the 8th character of line 3.
        assert!(e.contains("s.toml: line 3, column 8: "), "{e}");
    }
}
