//! The motor parameter file (DESIGN.md §3): nominal T-equivalent parameters and the supply.
//!
//! ```toml
//! [motor]
//! rs_ohm = 0.435   # stator resistance per phase [ohm]
//! rr_ohm = 0.816   # rotor resistance referred to the stator [ohm]
//! ls_h = 0.0713    # stator self inductance, leakage + magnetising [H]
//! lr_h = 0.0713    # rotor self inductance [H]
//! lm_h = 0.0693    # magnetising inductance [H]
//! poles = 4        # number of poles (pole pairs = poles / 2)
//! j_kgm2 = 0.089   # rotor + load inertia [kg m^2]
//! b_nms = 0.002    # friction coefficient on the shaft [N m s/rad]
//! bl_nms = 0.045   # load friction coefficient on the shaft [N m s/rad]
//! [supply]
//! v_ll_rms = 220.0 # line-to-line RMS voltage [V]
//! f_hz = 60.0      # supply frequency [Hz]
//! ```
//! Unknown keys are an error (a typo must not pass silently) and a missing key is named.
//!
//! The sections are the core's [`MotorParameters`] and [`SupplyParameters`] (one type for
//! the firmware, the simulator and the analysis); this module only reads and checks the
//! file. What each part needs is derived from them in one place:
//! [`MotorParameters::model`] (the core and the analysis), the simulator's machine
//! (`crate::sim`) and the analysis's constants (`crate::analysis::simplified_model::MachineConstants`).

use monitor_core::{MotorParameters, ReferenceMachine, SupplyParameters};
use serde::{Deserialize, Serialize};
use std::path::Path;

/// Errors from reading or checking a parameter file.
#[derive(Debug, thiserror::Error)]
pub enum ParamError {
    /// The file could not be read.
    #[error("cannot read parameter file {path}: {source}")]
    Io {
        /// The file.
        path: String,
        /// The I/O error.
        source: std::io::Error,
    },
    /// The TOML is malformed, has an unknown key or lacks a key.
    #[error("bad parameter file {path}: {message}")]
    Toml {
        /// The file.
        path: String,
        /// The parser's message, folded onto one line.
        message: String,
    },
    /// A value is outside its physical range.
    #[error("bad parameter file {path}: {source}")]
    Range {
        /// The file.
        path: String,
        /// Which key and what it must satisfy.
        source: monitor_core::ConfigError,
    },
}

/// A whole parameter file: `[motor]` and `[supply]`.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ParamFile {
    /// Nominal machine parameters.
    pub motor: MotorParameters,
    /// Nominal supply.
    pub supply: SupplyParameters,
}

impl ParamFile {
    /// Parses TOML text; `origin` names the source in messages.
    ///
    /// # Errors
    /// [`ParamError::Toml`] for malformed TOML or an unknown or missing key,
    /// [`ParamError::Range`] for a value out of range; both name the key.
    pub fn from_toml_str(text: &str, origin: &str) -> Result<Self, ParamError> {
        let p: ParamFile = toml::from_str(text).map_err(|e| ParamError::Toml {
            path: origin.to_string(),
            message: crate::one_line(e.message()),
        })?;
        p.check().map_err(|source| ParamError::Range {
            path: origin.to_string(),
            source,
        })?;
        Ok(p)
    }

    /// Reads and checks a parameter file.
    ///
    /// # Errors
    /// [`ParamError::Io`] when unreadable, else as [`ParamFile::from_toml_str`].
    pub fn load(path: &Path) -> Result<Self, ParamError> {
        let text = std::fs::read_to_string(path).map_err(|source| ParamError::Io {
            path: path.display().to_string(),
            source,
        })?;
        Self::from_toml_str(&text, &path.display().to_string())
    }

    /// Checks ranges of both sections.
    ///
    /// # Errors
    /// The first value out of range, naming its key (`motor.rs_ohm`, `supply.f_hz`, ...).
    pub fn check(&self) -> Result<(), monitor_core::ConfigError> {
        self.motor.validate()?;
        self.supply.validate()
    }

    /// Serialises to TOML text (the file format above).
    pub fn to_toml_string(&self) -> String {
        toml::to_string_pretty(self).unwrap_or_default()
    }

    /// The parameter file of a reference machine ([`monitor_core::reference`]).
    pub fn from_reference(m: &ReferenceMachine) -> Self {
        ParamFile {
            motor: m.motor,
            supply: m.supply,
        }
    }

    /// DESIGN.md's "2.2 kW" machine ([`monitor_core::reference::MOTOR_2P2KW`]).
    pub fn reference_2p2kw() -> Self {
        Self::from_reference(&monitor_core::reference::MOTOR_2P2KW)
    }

    /// DESIGN.md's "3 hp" textbook machine ([`monitor_core::reference::MOTOR_3HP`]).
    pub fn reference_3hp() -> Self {
        Self::from_reference(&monitor_core::reference::MOTOR_3HP)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const DESIGN_EXAMPLE: &str = "[motor]\nrs_ohm = 0.435\nrr_ohm = 0.816\nls_h = 0.0713\nlr_h = 0.0713\nlm_h = 0.0693\npoles = 4\nj_kgm2 = 0.089\nb_nms = 0.002\nbl_nms = 0.045\n[supply]\nv_ll_rms = 220.0\nf_hz = 60.0\n";

    #[test]
    fn design_example_parses() {
        let p = ParamFile::from_toml_str(DESIGN_EXAMPLE, "x").unwrap();
        assert_eq!(p.motor.poles, 4);
        assert!((p.supply.v_phase_peak() - 179.63).abs() < 0.01);
    }

    #[test]
    fn unknown_missing_and_bad_keys_are_named() {
        let bad = DESIGN_EXAMPLE.replace("bl_nms = 0.045\n", "bl_nms = 0.045\nrs_ohms = 1.0\n");
        let e = ParamFile::from_toml_str(&bad, "x").unwrap_err().to_string();
        assert!(e.contains("rs_ohms"), "{e}");
        let missing = DESIGN_EXAMPLE.replace("bl_nms = 0.045\n", "");
        let e = ParamFile::from_toml_str(&missing, "x")
            .unwrap_err()
            .to_string();
        assert!(e.contains("bl_nms"), "{e}");
        assert!(!e.contains('\n'));
        let negative = DESIGN_EXAMPLE.replace("rr_ohm = 0.816", "rr_ohm = -0.816");
        let e = ParamFile::from_toml_str(&negative, "x")
            .unwrap_err()
            .to_string();
        assert!(e.contains("motor.rr_ohm must be positive"), "{e}");
    }

    #[test]
    fn reference_motors_are_valid_and_round_trip() {
        for p in [ParamFile::reference_2p2kw(), ParamFile::reference_3hp()] {
            p.check().unwrap();
            let back = ParamFile::from_toml_str(&p.to_toml_string(), "x").unwrap();
            assert_eq!(back, p);
        }
    }
}
