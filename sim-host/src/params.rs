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
    #[error("bad parameter file {path}: {message}")]
    Range {
        /// The file.
        path: String,
        /// Which value and why.
        message: String,
    },
}

/// Nominal T-equivalent motor parameters, per phase, referred to the stator.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MotorParams {
    /// Stator resistance Rs [ohm], > 0.
    pub rs_ohm: f64,
    /// Rotor resistance Rr referred to the stator [ohm], > 0.
    pub rr_ohm: f64,
    /// Stator self inductance Ls = Lls + Lm [H], >= Lm.
    pub ls_h: f64,
    /// Rotor self inductance Lr = Llr + Lm [H], >= Lm.
    pub lr_h: f64,
    /// Magnetising inductance Lm [H], > 0, with Lm^2 < Ls Lr.
    pub lm_h: f64,
    /// Number of poles (even, >= 2). Pole pairs Np = poles / 2.
    pub poles: u32,
    /// Inertia J of rotor and load [kg m^2], > 0.
    pub j_kgm2: f64,
    /// Viscous friction B of the machine, on the shaft [N m s/rad], >= 0.
    pub b_nms: f64,
    /// Viscous load coefficient Bl, on the shaft [N m s/rad], >= 0 (the paper's load model).
    pub bl_nms: f64,
}

/// The supply the motor is connected to.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SupplyParams {
    /// Line-to-line RMS voltage [V], > 0.
    pub v_ll_rms: f64,
    /// Frequency [Hz], > 0.
    pub f_hz: f64,
}

/// A whole parameter file: `[motor]` and `[supply]`.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ParamFile {
    /// Nominal machine parameters.
    pub motor: MotorParams,
    /// Nominal supply.
    pub supply: SupplyParams,
}

impl MotorParams {
    /// Pole pairs Np = poles / 2.
    pub fn pole_pairs(&self) -> f64 {
        f64::from(self.poles / 2)
    }
    /// Leakage coefficient sigma = 1 - Lm^2 / (Ls Lr).
    pub fn sigma(&self) -> f64 {
        1.0 - self.lm_h * self.lm_h / (self.ls_h * self.lr_h)
    }
    /// Stator leakage inductance Lls = Ls - Lm [H] (zero for a Gamma-model machine).
    pub fn lls_h(&self) -> f64 {
        self.ls_h - self.lm_h
    }
    /// Rotor leakage inductance Llr = Lr - Lm [H].
    pub fn llr_h(&self) -> f64 {
        self.lr_h - self.lm_h
    }
    /// Checks physical ranges; the message names the offending key.
    pub fn check(&self) -> Result<(), String> {
        let pos = [
            ("rs_ohm", self.rs_ohm),
            ("rr_ohm", self.rr_ohm),
            ("ls_h", self.ls_h),
            ("lr_h", self.lr_h),
            ("lm_h", self.lm_h),
            ("j_kgm2", self.j_kgm2),
        ];
        for (k, v) in pos {
            if !(v.is_finite() && v > 0.0) {
                return Err(format!("motor.{k} must be a positive number, got {v}"));
            }
        }
        for (k, v) in [("b_nms", self.b_nms), ("bl_nms", self.bl_nms)] {
            if !(v.is_finite() && v >= 0.0) {
                return Err(format!("motor.{k} must be >= 0, got {v}"));
            }
        }
        if self.poles < 2 || !self.poles.is_multiple_of(2) {
            return Err(format!(
                "motor.poles must be even and >= 2, got {}",
                self.poles
            ));
        }
        if self.ls_h < self.lm_h || self.lr_h < self.lm_h {
            return Err(
                "motor.ls_h and motor.lr_h must be >= motor.lm_h (self = leakage + magnetising)"
                    .into(),
            );
        }
        if self.lm_h * self.lm_h >= self.ls_h * self.lr_h {
            return Err(
                "Lm^2 must be < Ls*Lr (sigma > 0): give at least one leakage inductance".into(),
            );
        }
        Ok(())
    }
}

impl SupplyParams {
    /// Peak phase-to-neutral voltage sqrt(2/3) * V_ll,rms [V].
    pub fn v_phase_peak(&self) -> f64 {
        self.v_ll_rms * (2.0f64 / 3.0).sqrt()
    }
    /// Angular frequency 2 pi f [rad/s].
    pub fn omega_rad_s(&self) -> f64 {
        2.0 * std::f64::consts::PI * self.f_hz
    }
}

impl ParamFile {
    /// Parses TOML text; `origin` names the source in messages.
    pub fn from_toml_str(text: &str, origin: &str) -> Result<Self, ParamError> {
        let p: ParamFile = toml::from_str(text).map_err(|e| ParamError::Toml {
            path: origin.to_string(),
            message: one_line(e.message()),
        })?;
        p.check().map_err(|message| ParamError::Range {
            path: origin.to_string(),
            message,
        })?;
        Ok(p)
    }

    /// Reads and checks a parameter file.
    pub fn load(path: &Path) -> Result<Self, ParamError> {
        let text = std::fs::read_to_string(path).map_err(|source| ParamError::Io {
            path: path.display().to_string(),
            source,
        })?;
        Self::from_toml_str(&text, &path.display().to_string())
    }

    /// Checks ranges of both sections.
    pub fn check(&self) -> Result<(), String> {
        self.motor.check()?;
        for (k, v) in [
            ("v_ll_rms", self.supply.v_ll_rms),
            ("f_hz", self.supply.f_hz),
        ] {
            if !(v.is_finite() && v > 0.0) {
                return Err(format!("supply.{k} must be a positive number, got {v}"));
            }
        }
        Ok(())
    }

    /// Serialises to TOML text.
    pub fn to_toml_string(&self) -> String {
        toml::to_string_pretty(self).unwrap_or_default()
    }

    /// DESIGN.md reference "2.2 kW" machine: 400 V, 50 Hz, 4 poles, Gamma model
    /// (no stator leakage). `bl_nms` is chosen so that Bl*omega gives the rated 14.6 N m at
    /// about 1430 rpm (149.7 rad/s): 14.6 / 149.7 = 0.0975 N m s/rad.
    pub fn reference_2p2kw() -> Self {
        ParamFile {
            motor: MotorParams {
                rs_ohm: 3.7,
                rr_ohm: 2.5,
                ls_h: 0.245,
                lr_h: 0.268,
                lm_h: 0.245,
                poles: 4,
                j_kgm2: 0.015,
                b_nms: 0.005,
                bl_nms: 0.0975,
            },
            supply: SupplyParams {
                v_ll_rms: 400.0,
                f_hz: 50.0,
            },
        }
    }

    /// DESIGN.md reference "3 hp" textbook machine: 220 V, 60 Hz, 4 poles,
    /// Xls = Xlr = 0.754 ohm and Xm = 26.13 ohm at 60 Hz, so Lls = Llr = 0.754/(2 pi 60)
    /// = 2.0 mH and Lm = 26.13/(2 pi 60) = 69.3 mH; B and Bl as in DESIGN.md's example file.
    pub fn reference_3hp() -> Self {
        let w = 2.0 * std::f64::consts::PI * 60.0;
        let lm = 26.13 / w;
        let ll = 0.754 / w;
        ParamFile {
            motor: MotorParams {
                rs_ohm: 0.435,
                rr_ohm: 0.816,
                ls_h: lm + ll,
                lr_h: lm + ll,
                lm_h: lm,
                poles: 4,
                j_kgm2: 0.089,
                b_nms: 0.002,
                bl_nms: 0.045,
            },
            supply: SupplyParams {
                v_ll_rms: 220.0,
                f_hz: 60.0,
            },
        }
    }
}

/// Folds a multi-line message onto one line.
pub fn one_line(s: &str) -> String {
    s.split_whitespace().collect::<Vec<_>>().join(" ")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn design_example_parses() {
        let text = "[motor]\nrs_ohm = 0.435\nrr_ohm = 0.816\nls_h = 0.0713\nlr_h = 0.0713\nlm_h = 0.0693\npoles = 4\nj_kgm2 = 0.089\nb_nms = 0.002\nbl_nms = 0.045\n[supply]\nv_ll_rms = 220.0\nf_hz = 60.0\n";
        let p = ParamFile::from_toml_str(text, "x").unwrap();
        assert_eq!(p.motor.poles, 4);
        assert!((p.supply.v_phase_peak() - 179.63).abs() < 0.01);
    }

    #[test]
    fn unknown_and_missing_keys_are_named() {
        let bad = "[motor]\nrs_ohm = 0.435\nrr_ohm = 0.816\nls_h = 0.0713\nlr_h = 0.0713\nlm_h = 0.0693\npoles = 4\nj_kgm2 = 0.089\nb_nms = 0.002\nbl_nms = 0.045\nrs_ohms = 1.0\n[supply]\nv_ll_rms = 220.0\nf_hz = 60.0\n";
        let e = ParamFile::from_toml_str(bad, "x").unwrap_err().to_string();
        assert!(e.contains("rs_ohms"), "{e}");
        let missing = "[motor]\nrs_ohm = 0.435\nrr_ohm = 0.816\nls_h = 0.0713\nlr_h = 0.0713\nlm_h = 0.0693\npoles = 4\nj_kgm2 = 0.089\nb_nms = 0.002\n[supply]\nv_ll_rms = 220.0\nf_hz = 60.0\n";
        let e = ParamFile::from_toml_str(missing, "x")
            .unwrap_err()
            .to_string();
        assert!(e.contains("bl_nms"), "{e}");
        assert!(!e.contains('\n'));
    }

    #[test]
    fn reference_motors_are_valid() {
        ParamFile::reference_2p2kw().check().unwrap();
        ParamFile::reference_3hp().check().unwrap();
    }
}
