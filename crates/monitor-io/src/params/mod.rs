//! The motor parameter file (`docs/design.md`): nominal T-equivalent parameters and the supply.
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
//! An optional `[columns]` table maps the log's channels and units to the schema's
//! columns ([`ColumnsTable`], read into a mapping by the log reader,
//! `crate::log::ColumnMapping`; `docs/design.md`):
//! ```toml
//! [columns]
//! t_s = { name = "Time", unit = "ms" }
//! ia_A = { name = "Ia", unit = "mA" }
//! wm_rad_s = { name = "Speed", unit = "rpm" }
//! ```
//! Unknown keys are an error (a typo must not pass silently) and a missing key is named.
//!
//! The sections are the core's [`MotorParameters`] and [`SupplyParameters`] (one type for
//! the firmware, the simulator and the analysis); this module only reads and checks the
//! file. What each part needs is derived from them in one place:
//! [`MotorParameters::model`] (the core and the analysis), the simulator's machine
//! (`monitor_sim`) and the analysis's constants (`monitor_analysis::simplified_model::MachineConstants`).

mod plausibility;
mod sensors;

use monitor_core::{MotorParameters, ReferenceMachine, SupplyParameters};
pub use plausibility::{plausible, Implausible, PlausibleRange};
pub use sensors::{locked_rotor_current_rms_a, LogLimits, SensorRanges};
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
    /// A value is outside the range of real induction machines ([`ParamFile::check_plausible`]).
    #[error("bad parameter file {path}: {source}")]
    Implausible {
        /// The file.
        path: String,
        /// Which key, its value and the plausible range.
        source: Implausible,
    },
    /// The `[columns]` table is wrong (a key that is no schema column, a unit the column
    /// cannot have, two columns naming one channel), as the log reader finds it
    /// (`crate::log::mapping::load_params`).
    #[error("bad parameter file {path}: [columns] {message}")]
    Columns {
        /// The file.
        path: String,
        /// What is wrong, naming the key.
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

/// A one-line message for a TOML error: `line L, column C: message` (1-based, the column
/// in characters), from the error's byte span; the message alone when it has no span.
pub fn toml_error_message(text: &str, e: &toml::de::Error) -> String {
    let message = crate::one_line(e.message());
    let Some(span) = e.span() else {
        return message;
    };
    let before = text.get(..span.start.min(text.len())).unwrap_or(text);
    let line = before.matches('\n').count() + 1;
    let line_start = before.rfind('\n').map_or(0, |i| i + 1);
    let column = before.get(line_start..).map_or(0, |l| l.chars().count()) + 1;
    format!("line {line}, column {column}: {message}")
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

/// One entry of the parameter file's `[columns]` table: `ia_A = { name = "Ia", unit =
/// "mA" }` (the key a schema column, `name` the log's channel, `unit` optional), or
/// `ia_A = { column = 1 }` (the log's first field, for a file without a header row), or,
/// for the time only, `t_s = { sample_rate_hz = 1000.0 }` (no time column: the rows are
/// samples at that rate). What the keys and units may be, and the mapping built from
/// them, is the log reader's (`crate::log::ColumnMapping::from_table`, `docs/design.md`).
#[derive(Debug, Clone, PartialEq, Deserialize, Serialize, Default)]
#[serde(deny_unknown_fields)]
pub struct ColumnEntry {
    /// The channel's name in the log (its header field, Parquet column or TDMS channel).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub name: Option<String>,
    /// The channel's place in each line, counted from 1 (instead of `name`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub column: Option<u32>,
    /// Its unit; absent: the schema's SI unit.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub unit: Option<String>,
    /// `t_s` only: the log has no time column and its rows are samples at this rate [Hz]
    /// (instead of `name` or `column`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub sample_rate_hz: Option<f64>,
    /// The channel's sign is turned (a current transformer or a voltage probe mounted the
    /// other way, an encoder counting backwards): `ia_A.invert = true`, with or without a
    /// `name` (without one, the schema's name).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub invert: Option<bool>,
}

/// The `[columns]` table: schema column name to [`ColumnEntry`].
pub type ColumnsTable = std::collections::BTreeMap<String, ColumnEntry>;

/// The entries of a `[columns]` table as TOML lines (`ia_A = { name = "Ia", unit = "mA" }`,
/// one per key, without the `[columns]` header), for a file that carries a table over.
pub fn columns_entries_toml(table: &ColumnsTable) -> String {
    let quoted = |x: &str| toml::Value::String(x.to_string()).to_string();
    let mut s = String::new();
    for (key, c) in table {
        let parts: Vec<String> = [
            c.name.as_deref().map(|n| format!("name = {}", quoted(n))),
            c.column.map(|n| format!("column = {n}")),
            c.unit.as_deref().map(|u| format!("unit = {}", quoted(u))),
            c.sample_rate_hz
                .map(|r| format!("sample_rate_hz = {}", toml::Value::Float(r))),
            c.invert.map(|i| format!("invert = {i}")),
        ]
        .into_iter()
        .flatten()
        .collect();
        s.push_str(&format!("{key} = {{ {} }}\n", parts.join(", ")));
    }
    s
}

/// The `[columns]` table of the TOML file `path` (only that table is read: a parameter file,
/// or a file holding the table alone).
///
/// # Errors
/// [`ParamError::Io`] or [`ParamError::Toml`] naming the file; a file without a `[columns]`
/// table is [`ParamError::Columns`].
pub fn load_columns_table(path: &std::path::Path) -> Result<ColumnsTable, ParamError> {
    #[derive(Deserialize)]
    struct OnlyColumns {
        #[serde(default)]
        columns: Option<ColumnsTable>,
    }
    let shown = path.display().to_string();
    let text = std::fs::read_to_string(path).map_err(|source| ParamError::Io {
        path: shown.clone(),
        source,
    })?;
    let f: OnlyColumns = toml::from_str(&text).map_err(|e| ParamError::Toml {
        path: shown.clone(),
        message: toml_error_message(&text, &e),
    })?;
    f.columns.ok_or(ParamError::Columns {
        path: shown,
        message: "the file has no [columns] table".to_string(),
    })
}

/// The file as written: [`ParamFile`]'s sections and the optional `[columns]` table.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct FileSections {
    motor: MotorParameters,
    supply: SupplyParameters,
    #[serde(default)]
    columns: ColumnsTable,
}

/// The magnetising flux linkage of the rated point [Wb, peak]: the machine at no load on
/// its rated supply, the stator's resistive drop neglected, `psi_m = (V_phase,peak /
/// omega_s) Lm / Ls` (the T-equivalent circuit's magnetising branch takes `Lm / Ls` of the
/// stator flux).
pub fn rated_magnetising_flux_wb(m: &MotorParameters, s: &SupplyParameters) -> f64 {
    let ws = s.omega_rad_s().abs().max(1e-9);
    s.v_phase_peak() / ws * m.lm_h / m.ls_h.max(1e-12)
}

/// The factor from the file's `lm_h` to the unsaturated Lm0 of the saturation law
/// `Lm = Lm0 / (1 + (psi_m / psi_sat)^n)`: 1 where the file holds the unsaturated value
/// ([`monitor_core::LmPoint::Unsaturated`]); where it holds the rated point's (a no-load
/// test, the default) `1 + (psi_m,rated / psi_sat)^n`, `psi_m,rated` the rated point's
/// magnetising flux ([`rated_magnetising_flux_wb`]), so that the law gives the file's value
/// there. The simulator and the analysis take the file's Lm the same way.
pub fn lm0_over_file(m: &MotorParameters, s: &SupplyParameters, psi_sat_wb: f64, n: f64) -> f64 {
    match m.lm_point() {
        monitor_core::LmPoint::Unsaturated => 1.0,
        monitor_core::LmPoint::Rated => {
            1.0 + (rated_magnetising_flux_wb(m, s) / psi_sat_wb.max(1e-9)).powf(n)
        }
    }
}

impl ParamFile {
    /// Parses TOML text; `origin` names the source in messages. A `[columns]` table is
    /// left out ([`ParamFile::from_toml_str_with_columns`] returns it).
    ///
    /// # Errors
    /// As [`ParamFile::from_toml_str_with_columns`].
    pub fn from_toml_str(text: &str, origin: &str) -> Result<Self, ParamError> {
        Self::from_toml_str_with_columns(text, origin).map(|(p, _)| p)
    }

    /// Parses TOML text and returns its `[columns]` table too, the mapping of the schema's
    /// columns to a log's channels and units (checked and built by the log reader,
    /// `crate::log::mapping::load_params`; `docs/design.md`); `origin` names the source in
    /// messages.
    ///
    /// # Errors
    /// [`ParamError::Toml`] for malformed TOML (with its line and column) or an unknown or
    /// missing key (in a `[columns]` entry too), [`ParamError::Implausible`] for a value
    /// outside the range of real machines ([`ParamFile::check_plausible`]),
    /// [`ParamError::Range`] for a value the equations cannot take ([`ParamFile::check`]);
    /// each names the key.
    pub fn from_toml_str_with_columns(
        text: &str,
        origin: &str,
    ) -> Result<(Self, ColumnsTable), ParamError> {
        let f: FileSections = toml::from_str(text).map_err(|e| ParamError::Toml {
            path: origin.to_string(),
            message: toml_error_message(text, &e),
        })?;
        let p = ParamFile {
            motor: f.motor,
            supply: f.supply,
        };
        p.check_plausible()
            .map_err(|source| ParamError::Implausible {
                path: origin.to_string(),
                source,
            })?;
        p.check().map_err(|source| ParamError::Range {
            path: origin.to_string(),
            source,
        })?;
        Ok((p, f.columns))
    }

    /// Reads and checks a parameter file.
    ///
    /// # Errors
    /// [`ParamError::Io`] when unreadable, else as [`ParamFile::from_toml_str`].
    pub fn load(path: &Path) -> Result<Self, ParamError> {
        Self::load_with_columns(path).map(|(p, _)| p)
    }

    /// Reads and checks a parameter file and returns its `[columns]` table too
    /// ([`ParamFile::from_toml_str_with_columns`]).
    ///
    /// # Errors
    /// [`ParamError::Io`] when unreadable, else as
    /// [`ParamFile::from_toml_str_with_columns`].
    pub fn load_with_columns(path: &Path) -> Result<(Self, ColumnsTable), ParamError> {
        let text = std::fs::read_to_string(path).map_err(|source| ParamError::Io {
            path: path.display().to_string(),
            source,
        })?;
        Self::from_toml_str_with_columns(&text, &path.display().to_string())
    }

    /// Checks that the equations can take the values (finite, positive, Ls >= Lm, ...): the
    /// check every parameter set gets, including the scaled copies the simulator's faults
    /// and the analysis's refits make. A file as loaded gets [`ParamFile::check_plausible`]
    /// too.
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

    /// The "2.2 kW" reference machine ([`monitor_core::reference::MOTOR_2P2KW`]).
    pub fn reference_2p2kw() -> Self {
        Self::from_reference(&monitor_core::reference::MOTOR_2P2KW)
    }

    /// The "3 hp" reference machine, Krause's textbook machine
    /// ([`monitor_core::reference::MOTOR_3HP`]).
    pub fn reference_3hp() -> Self {
        Self::from_reference(&monitor_core::reference::MOTOR_3HP)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::f64::consts::TAU;

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
    fn the_rotor_bars_are_optional_and_checked() {
        assert_eq!(
            ParamFile::from_toml_str(DESIGN_EXAMPLE, "x")
                .unwrap()
                .motor
                .rotor_bars,
            None
        );
        let with = DESIGN_EXAMPLE.replace("poles = 4\n", "poles = 4\nrotor_bars = 28\n");
        let p = ParamFile::from_toml_str(&with, "x").unwrap();
        assert_eq!(p.motor.rotor_bars, Some(28));
        // Written back only where given.
        assert!(p.to_toml_string().contains("rotor_bars = 28"));
        assert!(!ParamFile::reference_3hp()
            .to_toml_string()
            .contains("rotor_bars"));
        // A typo stays an error; a count no cage has is refused naming the key.
        let typo = DESIGN_EXAMPLE.replace("poles = 4\n", "poles = 4\nrotor_bar = 28\n");
        let e = ParamFile::from_toml_str(&typo, "x")
            .unwrap_err()
            .to_string();
        assert!(e.contains("rotor_bar"), "{e}");
        let e = refused("poles = 4\n", "poles = 4\nrotor_bars = 3\n");
        assert!(
            e.contains("motor.rotor_bars = 3") && e.contains("8..=300"),
            "{e}"
        );
    }

    /// Krause, Wasynczuk and Sudhoff's machines (60 Hz, 4 poles; reactances at 60 Hz):
    /// (name, v_ll_rms, rs, xls = xlr, xm, rr, j).
    const KRAUSE: [(&str, f64, f64, f64, f64, f64, f64); 4] = [
        ("3 hp", 220.0, 0.435, 0.754, 26.13, 0.816, 0.089),
        ("50 hp", 460.0, 0.087, 0.302, 13.08, 0.228, 1.662),
        ("500 hp", 2300.0, 0.262, 1.206, 54.02, 0.187, 11.06),
        ("2250 hp", 2300.0, 0.029, 0.226, 13.04, 0.022, 63.87),
    ];

    fn krause(v: f64, rs: f64, xl: f64, xm: f64, rr: f64, j: f64) -> ParamFile {
        let w = TAU * 60.0;
        let mut p = ParamFile::reference_3hp();
        p.motor.rs_ohm = rs;
        p.motor.rr_ohm = rr;
        p.motor.lm_h = xm / w;
        p.motor.ls_h = (xm + xl) / w;
        p.motor.lr_h = (xm + xl) / w;
        p.motor.j_kgm2 = j;
        p.supply.v_ll_rms = v;
        p
    }

    #[test]
    fn real_machines_are_plausible() {
        for p in [ParamFile::reference_2p2kw(), ParamFile::reference_3hp()] {
            p.check_plausible().unwrap();
        }
        ParamFile::from_toml_str(DESIGN_EXAMPLE, "x").unwrap();
        for (name, v, rs, xl, xm, rr, j) in KRAUSE {
            let p = krause(v, rs, xl, xm, rr, j);
            assert_eq!(p.check_plausible(), Ok(()), "{name}");
        }
        // Every parameter file of the repository.
        let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples/params");
        let mut n = 0;
        for entry in std::fs::read_dir(&dir).unwrap() {
            let path = entry.unwrap().path();
            if path.extension().is_some_and(|e| e == "toml") {
                ParamFile::load(&path).unwrap();
                n += 1;
            }
        }
        assert!(n >= 3, "{n} files in {}", dir.display());
        // The independent motulator log's machine: the 2.2 kW one with Bl = 0.
        let mut motulator = ParamFile::reference_2p2kw();
        motulator.motor.bl_nms = 0.0;
        ParamFile::from_toml_str(&motulator.to_toml_string(), "x").unwrap();
    }

    /// The message of loading `p` with `edit` applied to the documented example.
    fn refused(from: &str, to: &str) -> String {
        let text = DESIGN_EXAMPLE.replace(from, to);
        assert_ne!(text, DESIGN_EXAMPLE, "{from} not in the example");
        let e = ParamFile::from_toml_str(&text, "motor.toml")
            .unwrap_err()
            .to_string();
        assert!(
            !e.contains('\n') && e.starts_with("bad parameter file motor.toml: "),
            "{e}"
        );
        e
    }

    #[test]
    fn values_no_machine_has_are_refused_naming_key_value_and_range() {
        // The issue's three: each names the key, the value and the plausible range.
        let e = refused("rs_ohm = 0.435", "rs_ohm = 1e9");
        assert!(
            e.contains("motor.rs_ohm = 1.000e9 ohm") && e.contains("plausible 2..1000"),
            "{e}"
        );
        let e = refused("poles = 4", "poles = 1000");
        assert!(
            e.contains("motor.poles = 1000") && e.contains("2..=24"),
            "{e}"
        );
        let e = refused("j_kgm2 = 0.089", "j_kgm2 = 1e-12");
        assert!(
            e.contains("motor.j_kgm2 = 1.000e-12") && e.contains("0.002..100"),
            "{e}"
        );
        // The blamed key's own range follows from the ratio's: X/Rs = 2 pi 60 * 0.0713 / Rs
        // in 2..1000 gives Rs in 0.02688..13.44 ohm.
        let x = TAU * 60.0 * 0.0713;
        assert!((x / 1000.0 - 0.02688).abs() < 1e-5 && (x / 2.0 - 13.44).abs() < 0.005);
        let e = refused("rs_ohm = 0.435", "rs_ohm = 1e9");
        assert!(e.contains("0.02688..13.44 ohm"), "{e}");
        // Odd poles, a unit slip in an inductance (mH typed as H), a resistance typed in
        // milliohms, the rotor time constant, a frequency or voltage out of range.
        for (from, to, key) in [
            ("poles = 4", "poles = 5", "motor.poles"),
            ("lm_h = 0.0693", "lm_h = 69.3", "motor.ls_h"),
            ("lr_h = 0.0713", "lr_h = 0.2", "motor.lr_h"),
            ("lm_h = 0.0693", "lm_h = 0.05", "motor.ls_h"),
            // Lm/Ls = Lm/Lr = 0.84 pass, but sigma = 1 - 0.84^2 = 0.29.
            ("lm_h = 0.0693", "lm_h = 0.06", "motor.lm_h"),
            ("rr_ohm = 0.816", "rr_ohm = 816", "motor.rr_ohm"),
            ("rr_ohm = 0.816", "rr_ohm = 0.0408", "motor.rr_ohm"),
            ("f_hz = 60.0", "f_hz = 6000.0", "supply.f_hz"),
            ("v_ll_rms = 220.0", "v_ll_rms = 2.2e5", "supply.v_ll_rms"),
            ("j_kgm2 = 0.089", "j_kgm2 = 89000", "motor.j_kgm2"),
            ("b_nms = 0.002", "b_nms = -0.002", "motor.b_nms"),
            ("rs_ohm = 0.435", "rs_ohm = nan", "motor.rs_ohm"),
        ] {
            let e = refused(from, to);
            assert!(e.contains(key), "{to}: {e}");
        }
    }

    #[test]
    fn toml_syntax_errors_give_line_and_column() {
        // Line 5 is "  lr_h = = 0.0713": the second '=' is the 10th character.
        let text = DESIGN_EXAMPLE.replace("lr_h = 0.0713", "  lr_h = = 0.0713");
        let e = ParamFile::from_toml_str(&text, "m.toml")
            .unwrap_err()
            .to_string();
        assert!(e.contains("m.toml: line 5, column 10: "), "{e}");
        assert!(!e.contains('\n'), "{e}");
        // Columns count characters, not bytes: "µ" is two bytes.
        let text = "[motor]\n# µ\nrs_ohm = µ\n";
        let e = ParamFile::from_toml_str(text, "m.toml")
            .unwrap_err()
            .to_string();
        assert!(e.contains("line 3, column 10: "), "{e}");
    }

    #[test]
    fn reference_motors_are_valid_and_round_trip() {
        for p in [ParamFile::reference_2p2kw(), ParamFile::reference_3hp()] {
            p.check().unwrap();
            let back = ParamFile::from_toml_str(&p.to_toml_string(), "x").unwrap();
            assert_eq!(back, p);
        }
    }

    #[test]
    fn sensor_ranges_of_the_reference_motors() {
        // The values the simulator's documentation states: 400 V for the 2.2 kW motor,
        // 250 V for the 3 hp one (1.2 x the phase peak, rounded up to 50 V).
        let r = ParamFile::reference_2p2kw().sensor_ranges();
        assert_eq!(r.v_range_v, 400.0);
        assert_eq!(ParamFile::reference_3hp().sensor_ranges().v_range_v, 250.0);
        // The current range: a multiple of 5 A between 2 and 2.5 times the locked-rotor
        // peak current (2 x peak, rounded up to 5 A).
        for p in [ParamFile::reference_2p2kw(), ParamFile::reference_3hp()] {
            let r = p.sensor_ranges();
            let i_pk = 2f64.sqrt()
                * locked_rotor_current_rms_a(&p.motor, p.supply.v_ll_rms, p.supply.f_hz);
            assert_eq!(r.i_range_a % 5.0, 0.0);
            assert!(
                r.i_range_a >= 2.0 * i_pk && r.i_range_a < 2.0 * i_pk + 5.0,
                "{r:?} {i_pk}"
            );
            // The log's limits: twice the ranges, twice the supply's angular frequency.
            let l = p.log_limits();
            assert_eq!(f64::from(l.v_max_v), 2.0 * r.v_range_v);
            assert_eq!(f64::from(l.i_max_a), 2.0 * r.i_range_a);
            assert!((f64::from(l.wm_max_rad_s) - 2.0 * TAU * p.supply.f_hz).abs() < 1e-3);
        }
    }
}
