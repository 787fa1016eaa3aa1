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
//! (`crate::sim`) and the analysis's constants (`crate::analysis::simplified_model::MachineConstants`).

use monitor_core::{MotorParameters, ReferenceMachine, SupplyParameters};
use nalgebra::Complex;
use serde::{Deserialize, Serialize};
use std::f64::consts::TAU;
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

/// A closed range `lo..=hi` of plausible values.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PlausibleRange {
    /// Smallest plausible value.
    pub lo: f64,
    /// Largest plausible value.
    pub hi: f64,
}

impl PlausibleRange {
    /// The range `lo..=hi`.
    pub const fn new(lo: f64, hi: f64) -> Self {
        PlausibleRange { lo, hi }
    }

    /// True for a finite `x` in `lo..=hi`.
    pub fn contains(&self, x: f64) -> bool {
        x.is_finite() && x >= self.lo && x <= self.hi
    }
}

/// The plausible ranges of a parameter file ([`ParamFile::check_plausible`]): induction
/// machines from about 0.1 kW to 1 MW, line-fed or inverter-fed at their rated point.
///
/// The file has no rated power, so most checks are ratios that need none. Where the
/// values come from (each range is wider than every machine listed, so that a real
/// machine is never refused and a unit or typing error of 10x to 1000x is):
/// - the four machines of Krause, Wasynczuk and Sudhoff, *Analysis of Electric Machinery
///   and Drive Systems* (3 hp / 220 V, 50 hp / 460 V, 500 hp / 2300 V, 2250 hp / 2300 V,
///   all 60 Hz, 4 poles; the 3 hp one is the repository's reference motor): Lm/Ls
///   0.972..0.983, sigma 0.034..0.055, X/Rs 62..457, Lr/Rr 0.087..1.6 s, Rr/Rs 0.71..2.6,
///   H estimate 0.88..2.8 s;
/// - the repository's 2.2 kW Gamma-model reference machine (Ls = Lm): Lm/Lr 0.914, sigma
///   0.086, X/Rs 21, Lr/Rr 0.11 s, Rr/Rs 0.68, H estimate 0.089 s;
/// - textbook per-unit values for the small end (0.1 kW, 2 to 8 poles: Rs up to about
///   0.1 pu and X/Rs down to about 5, Lr/Rr down to about 20 ms, rotor inertia 1e-4 to
///   1e-3 kg m^2).
pub mod plausible {
    use super::PlausibleRange as R;

    /// Number of poles: even, 2..=24 (3000 rpm down to 250 rpm at 50 Hz; the core's own
    /// limit is 254).
    pub const POLES: core::ops::RangeInclusive<u32> = 2..=24;
    /// Supply frequency `f_hz` [Hz]: 1..400 (400 Hz: aircraft supplies and high-speed
    /// motors; high-speed spindles above that are outside this product's scope).
    pub const F_HZ: R = R::new(1.0, 400.0);
    /// Line-to-line voltage `v_ll_rms` [V]: 10..15000 (low-voltage battery drives up to
    /// 13.8 kV medium-voltage machines).
    pub const V_LL_RMS: R = R::new(10.0, 15_000.0);
    /// Lm/Ls: 0.8..=1 (1 = a Gamma-model machine with no stator leakage; below 0.8 the
    /// stator leakage would exceed a quarter of Lm).
    pub const LM_OVER_LS: R = R::new(0.8, 1.0);
    /// Lm/Lr: 0.8..=1 (1 = an inverse-Gamma-model machine with no rotor leakage).
    pub const LM_OVER_LR: R = R::new(0.8, 1.0);
    /// Leakage coefficient sigma = 1 - Lm^2/(Ls Lr): 0.01..0.25.
    pub const SIGMA: R = R::new(0.01, 0.25);
    /// Magnetising reactance over stator resistance, 2 pi f Ls / Rs, at the file's
    /// frequency: 2..1000.
    pub const X_OVER_RS: R = R::new(2.0, 1000.0);
    /// Rotor time constant Lr/Rr [s]: 0.005..5.
    pub const ROTOR_TIME_CONSTANT_S: R = R::new(0.005, 5.0);
    /// Rr/Rs: 0.1..10.
    pub const RR_OVER_RS: R = R::new(0.1, 10.0);
    /// Inertia constant estimate H = (J omega_m^2 / 2) / S0 [s], omega_m = 2 pi f / Np the
    /// synchronous mechanical speed and S0 = V_ll^2 / (2 pi f Ls) the no-load (magnetising)
    /// reactive power standing in for the rated power: 0.002..100. Real machines have H
    /// of about 0.02 s (0.1 kW, motor alone) to 2 s, and up to about 30 s with a
    /// flywheel or a large fan on the shaft (J is rotor plus load). S0 is 0.3 to 1.1 times
    /// the rated power (no-load current 25 % to 60 % of rated at power factor 0.7 to 0.9),
    /// hence the extra margin of about 4x at both ends.
    pub const INERTIA_CONSTANT_S: R = R::new(0.002, 100.0);
}

/// A parameter file value outside the range of real machines: the key, its value, the
/// quantity that is out of range and the range (one line).
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("{message}")]
pub struct Implausible {
    /// The key blamed (`motor.rs_ohm`, `supply.f_hz`, ...).
    pub key: &'static str,
    /// The whole message.
    pub message: String,
}

/// One ratio check: `quantity` = c * `key`^`exponent` must lie in `range`; blames `key`.
struct RatioCheck {
    key: &'static str,
    value: f64,
    unit: &'static str,
    /// How the quantity is formed, e.g. "lr_h / rr_ohm (rotor time constant, s)".
    what: &'static str,
    quantity: f64,
    range: PlausibleRange,
    exponent: f64,
}

impl RatioCheck {
    fn check(&self) -> Result<(), Implausible> {
        if self.range.contains(self.quantity) {
            return Ok(());
        }
        // The blamed key's own range with the other values as they are.
        let at = |q: f64| self.value * (q / self.quantity).powf(1.0 / self.exponent);
        let (a, b) = (at(self.range.lo), at(self.range.hi));
        let (lo, hi) = (a.min(b), a.max(b));
        Err(Implausible {
            key: self.key,
            message: format!(
                "{} = {} {} is implausible: {} = {}, plausible {}..{} \
                 (so {} {}..{} {} with the other values)",
                self.key,
                number(self.value),
                self.unit,
                self.what,
                number(self.quantity),
                self.range.lo,
                self.range.hi,
                self.key,
                number(lo),
                number(hi),
                self.unit,
            ),
        })
    }
}

/// `x` for a message: four significant digits, in scientific notation when very large or
/// very small.
fn number(x: f64) -> String {
    let a = x.abs();
    if a == 0.0 || !a.is_finite() || (1e-3..1e5).contains(&a) {
        let digits = if a == 0.0 || !a.is_finite() {
            0
        } else {
            (3 - a.log10().floor() as i32).max(0) as usize
        };
        let t = format!("{x:.digits$}");
        if t.contains('.') {
            t.trim_end_matches('0').trim_end_matches('.').to_string()
        } else {
            t
        }
    } else {
        format!("{x:.3e}")
    }
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

    /// Checks that every value lies in the range of real induction machines
    /// ([`plausible`](mod@plausible) lists the ranges and their sources): each value finite
    /// and positive (B and Bl >= 0), then the poles, the supply, and the ratios Lm/Ls,
    /// Lm/Lr, sigma, 2 pi f Ls/Rs, Lr/Rr, Rr/Rs and the inertia constant. Applied to a file
    /// as it is read ([`ParamFile::from_toml_str`]), not to the scaled copies that faults
    /// and refits make.
    ///
    /// # Errors
    /// The first value out of range: its key, its value, the quantity and the plausible
    /// range (for a ratio also the key's own range with the other values as they are).
    pub fn check_plausible(&self) -> Result<(), Implausible> {
        let (m, s) = (&self.motor, &self.supply);
        let fail = |key: &'static str, message: String| Err(Implausible { key, message });
        for (key, v, unit) in [
            ("motor.rs_ohm", m.rs_ohm, "ohm"),
            ("motor.rr_ohm", m.rr_ohm, "ohm"),
            ("motor.ls_h", m.ls_h, "H"),
            ("motor.lr_h", m.lr_h, "H"),
            ("motor.lm_h", m.lm_h, "H"),
            ("motor.j_kgm2", m.j_kgm2, "kg m^2"),
            ("supply.v_ll_rms", s.v_ll_rms, "V"),
            ("supply.f_hz", s.f_hz, "Hz"),
        ] {
            if !(v.is_finite() && v > 0.0) {
                return fail(
                    key,
                    format!(
                        "{key} must be positive and finite, got {} {unit}",
                        number(v)
                    ),
                );
            }
        }
        for (key, v) in [("motor.b_nms", m.b_nms), ("motor.bl_nms", m.bl_nms)] {
            if !(v.is_finite() && v >= 0.0) {
                return fail(
                    key,
                    format!("{key} must be >= 0 and finite, got {} N m s/rad", number(v)),
                );
            }
        }
        if !(plausible::POLES.contains(&m.poles) && m.poles.is_multiple_of(2)) {
            return fail(
                "motor.poles",
                format!(
                    "motor.poles = {} is implausible: plausible is an even number in {}..={}",
                    m.poles,
                    plausible::POLES.start(),
                    plausible::POLES.end()
                ),
            );
        }
        for (key, v, unit, r) in [
            ("supply.f_hz", s.f_hz, "Hz", plausible::F_HZ),
            ("supply.v_ll_rms", s.v_ll_rms, "V", plausible::V_LL_RMS),
        ] {
            if !r.contains(v) {
                return fail(
                    key,
                    format!(
                        "{key} = {} {unit} is implausible: plausible {}..{} {unit}",
                        number(v),
                        r.lo,
                        r.hi
                    ),
                );
            }
        }
        for c in self.ratio_checks() {
            c.check()?;
        }
        Ok(())
    }

    /// The ratio checks of [`ParamFile::check_plausible`], in order; each blames one key.
    fn ratio_checks(&self) -> [RatioCheck; 7] {
        let (m, s) = (&self.motor, &self.supply);
        let x_ohm = TAU * s.f_hz * m.ls_h;
        let w_mech = TAU * s.f_hz / f64::from(m.poles / 2);
        let s0_var = s.v_ll_rms * s.v_ll_rms / x_ohm;
        let check = |key, value, unit, what, quantity, range, exponent| RatioCheck {
            key,
            value,
            unit,
            what,
            quantity,
            range,
            exponent,
        };
        [
            check("motor.ls_h", m.ls_h, "H", "lm_h / ls_h", m.lm_h / m.ls_h, plausible::LM_OVER_LS, -1.0),
            check("motor.lr_h", m.lr_h, "H", "lm_h / lr_h", m.lm_h / m.lr_h, plausible::LM_OVER_LR, -1.0),
            // 1 - sigma = Lm^2 / (Ls Lr): a power law in Lm.
            check(
                "motor.lm_h",
                m.lm_h,
                "H",
                "1 - sigma = lm_h^2 / (ls_h lr_h)",
                m.lm_h * m.lm_h / (m.ls_h * m.lr_h),
                PlausibleRange {
                    lo: 1.0 - plausible::SIGMA.hi,
                    hi: 1.0 - plausible::SIGMA.lo,
                },
                2.0,
            ),
            check("motor.rs_ohm", m.rs_ohm, "ohm", "2 pi f_hz ls_h / rs_ohm", x_ohm / m.rs_ohm, plausible::X_OVER_RS, -1.0),
            check(
                "motor.rr_ohm",
                m.rr_ohm,
                "ohm",
                "lr_h / rr_ohm (rotor time constant, s)",
                m.lr_h / m.rr_ohm,
                plausible::ROTOR_TIME_CONSTANT_S,
                -1.0,
            ),
            check("motor.rr_ohm", m.rr_ohm, "ohm", "rr_ohm / rs_ohm", m.rr_ohm / m.rs_ohm, plausible::RR_OVER_RS, 1.0),
            check(
                "motor.j_kgm2",
                m.j_kgm2,
                "kg m^2",
                "inertia constant estimate H = j_kgm2 omega_sync^2 / (2 S0), S0 = v_ll_rms^2 / (2 pi f_hz ls_h), in s",
                0.5 * m.j_kgm2 * w_mech * w_mech / s0_var,
                plausible::INERTIA_CONSTANT_S,
                1.0,
            ),
        ]
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

/// The sensors' measurement ranges for a machine on a supply: the simulator's default ADC
/// ranges ([`crate::sim::SensorSpec`]), and what the plausibility limits of a log are built
/// from ([`ParamFile::log_limits`]). The one place these ranges are derived.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SensorRanges {
    /// Voltage range +/- [V]: 1.2 x the phase peak sqrt(2/3) V_ll rounded up to 50 V
    /// (400 V for the 2.2 kW reference motor, 250 V for the 3 hp one).
    pub v_range_v: f64,
    /// Current range +/- [A]: 2 x the locked-rotor peak current rounded up to 5 A (a
    /// direct-on-line start, whose first peaks exceed the steady locked-rotor peak, does
    /// not clip).
    pub i_range_a: f64,
}

impl SensorRanges {
    /// The ranges for motor `m` on a supply of `v_ll_rms` [V, line-to-line RMS] at `f_hz`
    /// [Hz] (a scenario may run the motor on another supply than the parameter file's).
    pub fn new(m: &MotorParameters, v_ll_rms: f64, f_hz: f64) -> Self {
        let vpk = v_ll_rms * (2.0f64 / 3.0).sqrt();
        let v = (1.2 * vpk / 50.0).ceil() * 50.0;
        let i_locked = locked_rotor_current_rms_a(m, v_ll_rms, f_hz);
        let i = (2.0 * 2f64.sqrt() * i_locked / 5.0).ceil() * 5.0;
        SensorRanges {
            v_range_v: v,
            i_range_a: i,
        }
    }
}

/// Stator phase current RMS [A] of the T-equivalent circuit with the rotor locked (slip
/// 1): `I = V / (Zs + Zm || Zr)` with `V = V_ll / sqrt 3`, `Zs = Rs + j we Lls`,
/// `Zm = j we Lm`, `Zr = Rr + j we Llr`, `we = 2 pi f` (the simulator's analytic steady
/// state at slip 1, `crate::sim::steady_state_at`, to the last bit; a test checks it).
pub fn locked_rotor_current_rms_a(m: &MotorParameters, v_ll_rms: f64, f_hz: f64) -> f64 {
    let we = 2.0 * std::f64::consts::PI * f_hz;
    let model = m.model::<f64>();
    let v = Complex::new(v_ll_rms / 3f64.sqrt(), 0.0);
    let zs = Complex::new(m.rs_ohm, we * model.lls_h());
    let zm = Complex::new(0.0, we * m.lm_h);
    let zr = Complex::new(m.rr_ohm, we * model.llr_h());
    let zp = zm * zr / (zm + zr);
    (v / (zs + zp)).norm()
}

/// The largest believable readings in a log of a machine: beyond them a cell is bad (the
/// data-quality stage, `crate::log::quality::CellLimits`) and the replay's monitor flags
/// the sensor (`crate::replay::monitor_config_for_log`). In the core's `f32`, as the
/// monitor's `SensorLimits`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LogLimits {
    /// Largest |phase voltage| [V]: twice the voltage range ([`SensorRanges`]), since a
    /// log does not say its ADC ranges.
    pub v_max_v: f32,
    /// Largest |phase current| [A]: twice the current range.
    pub i_max_a: f32,
    /// Largest |mechanical speed| [rad/s]: 2 x 2 pi f (at least twice the synchronous
    /// speed for any number of poles; the core's default `max_speed_rad_s`).
    pub wm_max_rad_s: f32,
}

impl ParamFile {
    /// The sensor ranges of this machine on its own supply ([`SensorRanges::new`]).
    pub fn sensor_ranges(&self) -> SensorRanges {
        SensorRanges::new(&self.motor, self.supply.v_ll_rms, self.supply.f_hz)
    }

    /// The plausibility limits of a log of this machine ([`LogLimits`]).
    pub fn log_limits(&self) -> LogLimits {
        let r = self.sensor_ranges();
        LogLimits {
            v_max_v: 2.0 * r.v_range_v as f32,
            i_max_a: 2.0 * r.i_range_a as f32,
            wm_max_rad_s: 2.0 * std::f32::consts::TAU * self.supply.f_hz as f32,
        }
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
        let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../examples/params");
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
