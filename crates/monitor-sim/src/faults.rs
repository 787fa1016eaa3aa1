//! A fault of the scenario (`[[faults]]`): parametric or sensor, when it starts, what it
//! changes.

use super::scenario::{invalid, not_negative};
use super::SimError;
use monitor_core::{Fault, FaultTarget, Phase, SensorChannel};
use serde::{Deserialize, Serialize};

/// What a sensor fault does to the reading x.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum SensorFaultMode {
    /// Reads (1 + change) * x.
    Gain,
    /// Reads x + offset (offset in the channel's unit: V, A or rad/s).
    Offset,
    /// Reads 0 (the encoder stops counting).
    Disconnected,
    /// Holds the last reading before the fault (the encoder stops counting).
    Stuck,
}

/// One fault, switched on at the first output sample at or after `at_s` and kept on.
///
/// Parametric faults (`rs, rr, ls, lr, b, bl`) need `change` (relative, > -1; +0.5 = +50 %):
/// `rs`, `rr`, `b`: the value x (1 + change). `ls`, `lr`: the LEAKAGE inductance x (1 +
/// change), the self inductance follows (PSIM's convention, `docs/design.md`); for a machine
/// without that leakage (the Gamma-model 2.2 kW reference has Lls = 0) Lm itself is scaled
/// (the other leakage kept, so both self inductances follow). `bl`: Bl x (1 + change), or
/// the load torque for a torque load. The speed sensor fault acts on `wm_rad_s` and on the
/// encoder count.
/// Sensor faults need `mode`; `gain` needs `change`, `offset` needs `offset`; `phase`
/// (voltage and current sensors only) restricts the fault to one phase (default: all three).
/// Several faults of the same kind compose multiplicatively.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct FaultSpec {
    /// Which fault (JSON and TOML: its name, [`Fault::name`]).
    pub kind: Fault,
    /// Switch-on time [s], >= 0.
    pub at_s: f64,
    /// Relative change (parametric faults, sensor gain).
    #[serde(default)]
    pub change: Option<f64>,
    /// Sensor fault mode.
    #[serde(default)]
    pub mode: Option<SensorFaultMode>,
    /// Sensor offset in the channel's unit [V, A or rad/s].
    #[serde(default)]
    pub offset: Option<f64>,
    /// Restrict a voltage/current sensor fault to one phase.
    #[serde(default)]
    pub phase: Option<Phase>,
}

impl FaultSpec {
    /// A parametric fault (`rs, rr, ls, lr, b, bl`) with relative `change` at `at_s`.
    pub fn parametric(kind: Fault, at_s: f64, change: f64) -> Self {
        FaultSpec {
            kind,
            at_s,
            change: Some(change),
            mode: None,
            offset: None,
            phase: None,
        }
    }
    /// Table 1's kind of fault of relative size `change` at `at_s`: a parametric change,
    /// or for a sensor a gain error on all its channels (the reading is (1 + change)
    /// times the true value).
    pub fn at_change(kind: Fault, at_s: f64, change: f64) -> Self {
        if kind.is_sensor() {
            Self::sensor_gain(kind, at_s, change)
        } else {
            Self::parametric(kind, at_s, change)
        }
    }

    /// A sensor gain fault: the reading is (1 + change) times the true value.
    pub fn sensor_gain(kind: Fault, at_s: f64, change: f64) -> Self {
        FaultSpec {
            mode: Some(SensorFaultMode::Gain),
            ..Self::parametric(kind, at_s, change)
        }
    }
}

impl FaultSpec {
    /// Checks that the fault has what its kind needs.
    ///
    /// # Errors
    /// [`SimError::Invalid`] naming the key.
    pub fn validate(&self) -> Result<(), SimError> {
        not_negative("faults.at_s", self.at_s)?;
        if !self.kind.is_sensor() {
            if self.mode.is_some() || self.offset.is_some() || self.phase.is_some() {
                return invalid(
                    "faults.mode",
                    "mode/offset/phase are for sensor faults only".into(),
                );
            }
            return match self.change {
                Some(c) if c.is_finite() && c > -1.0 => Ok(()),
                Some(c) => invalid("faults.change", format!("must be > -1, got {c}")),
                None => invalid("faults.change", "a parametric fault needs change".into()),
            };
        }
        let Some(mode) = self.mode else {
            return invalid(
                "faults.mode",
                "a sensor fault needs mode = gain|offset|disconnected|stuck".into(),
            );
        };
        match mode {
            SensorFaultMode::Gain if !self.change.is_some_and(f64::is_finite) => {
                return invalid("faults.change", "mode = \"gain\" needs change".into())
            }
            SensorFaultMode::Offset if !self.offset.is_some_and(f64::is_finite) => {
                return invalid("faults.offset", "mode = \"offset\" needs offset".into())
            }
            _ => {}
        }
        if self.phase.is_some() && self.kind.target() == FaultTarget::Sensor(SensorChannel::Speed) {
            return invalid("faults.phase", "the speed sensor has no phases".into());
        }
        Ok(())
    }
}
