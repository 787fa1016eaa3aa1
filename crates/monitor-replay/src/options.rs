//! What a replay is asked to do ([`ReplayOptions`], [`LoadModel`]), the typed values a
//! front end parses its words into, each checked once, where it is made, and valid from
//! then on ([`CommissionWindow`], `START:END` seconds; [`TimelineStep`], positive;
//! [`ParallelPaths`], in [`PARALLEL_PATHS`]), their error ([`OptionError`], naming the
//! field, [`OptionField`], never a front end's spelling
//! of it: the door, `monitor_words`, says it in the command line's flags or Python's
//! keywords), and the monitor configuration a replay runs with ([`monitor_config_for_log`]).
//! No option carries words.

use super::baseline::HealthyReference;
pub use super::fields::{OptionError, OptionField, OptionValue};
use super::sampler::TICK_HZ;
use crate::turn_calibration::TurnCalibration;
use monitor_core::{AngleSource, MonitorConfig, ResidualForm};
use monitor_io::params::ParamFile;
use serde::Serialize;
use std::fmt;
use std::ops::RangeInclusive;
use std::str::FromStr;

/// Serialises an angle source by its command-line name ([`angle_source_name`]), for
/// `#[serde(serialize_with = "serialize_angle_source")]` on a report's field.
pub fn serialize_angle_source<S: serde::Serializer>(
    a: &AngleSource,
    s: S,
) -> Result<S::Ok, S::Error> {
    s.serialize_str(angle_source_name(*a))
}

/// Name of an angle source as used on the command line.
pub fn angle_source_name(a: AngleSource) -> &'static str {
    match a {
        AngleSource::ZeroCrossing => "zero-crossing",
        AngleSource::Pll => "pll",
        AngleSource::RotorFluxCurrentModel => "rotor-flux",
    }
}

/// Replay options.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ReplayOptions {
    /// Frame angle source.
    pub angle_source: AngleSource,
    /// Residual form for the lamps.
    pub residual_form: ResidualForm,
    /// Commissioning window [start, end) in log seconds, valid by construction
    /// ([`CommissionWindow::new`], the one check); None = fixed thresholds.
    pub commission: Option<CommissionWindow>,
    /// Report a commissioning window that was not learned instead of refusing.
    pub allow_incomplete: bool,
    /// Timeline resolution (one point per interval; default 0.5 s, the one default of
    /// the command line, the API and Python).
    pub timeline_step: TimelineStep,
    /// The healthy machine's negative sequence to judge the winding against (the field
    /// `baseline` of a request: healthy logs); without it, the one learned in the
    /// commissioning window, else none ([`super::baseline::UnbalanceBaseline`]).
    pub unbalance_baseline: Option<HealthyReference>,
    /// What is known of the load ([`LoadModel`]; the field `load`).
    pub load: LoadModel,
    /// How the shorted-turn level is sized (the fields `parallel_paths`, 1..=8 as
    /// [`PARALLEL_PATHS`] says, and `turn_calibration`; `winding::level`).
    pub turn_level: TurnLevelOptions,
}

/// What the replay knows of the load torque.
///
/// The paper's model has a fixed viscous load `Bl wr` (eq. 4), so to it any change of the
/// load is a change of Bl, and the friction class B/Bl is one of its faults (Table 1). In
/// service the load moves all day and nothing tells a change of the load from a change of
/// the friction: with the load as an unknown input B and Bl cannot be judged, and a reading
/// of them is an operating-point change.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum LoadModel {
    /// The load is an unknown input (real service; the default): the friction class is
    /// never named, its reading is reported as a load move (an event and the verdict
    /// sentence); electrical faults are named from the stator-voltage equations and, at a
    /// load measured just before a deviation, the torque against it.
    #[default]
    Unknown,
    /// The paper's fixed viscous load (Table 1, the demo): a B/Bl change is a fault, named
    /// as the friction class `b/bl`.
    Viscous,
}

/// What the level is computed with (`ReplayOptions::turn_level`; `diagnose
/// --parallel-paths`, `--turn-calibration`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TurnLevelOptions {
    /// Parallel paths of each phase (1 for a series star or delta, 2 for a double star;
    /// 1..=8, [`PARALLEL_PATHS`], by construction).
    pub parallel_paths: ParallelPaths,
    /// A calibration learned from labelled runs of the same motor, used instead of the
    /// model where given (the model's estimate is still reported).
    pub calibration: Option<TurnCalibration>,
}

/// One path, no calibration (the model's level).
impl Default for TurnLevelOptions {
    fn default() -> Self {
        TurnLevelOptions {
            parallel_paths: ParallelPaths::ONE,
            calibration: None,
        }
    }
}

/// The one home of `diagnose`'s defaults: the command line, the API
/// (`monitor_api::DiagnoseRequest`), the fleet run and the Python package take theirs from
/// here.
impl Default for ReplayOptions {
    fn default() -> Self {
        ReplayOptions {
            angle_source: AngleSource::RotorFluxCurrentModel,
            residual_form: ResidualForm::Steady,
            commission: None,
            allow_incomplete: false,
            timeline_step: TimelineStep::DEFAULT,
            unbalance_baseline: None,
            load: LoadModel::Unknown,
            turn_level: TurnLevelOptions::default(),
        }
    }
}

/// The monitor configuration for replaying a log: the parameter file's machine and supply
/// at the log's sample rate, 1 MHz timestamps. The sensor limits are the log's
/// ([`ParamFile::log_limits`]: twice the sensor ranges, because a log does not say its ADC
/// ranges), the same the data-quality stage judges cells by. (The firmware's configuration is `drive_monitor::app`'s
/// `board_monitor_config`.)
pub fn monitor_config_for_log(
    p: &ParamFile,
    sample_rate_hz: f64,
    opts: &ReplayOptions,
) -> MonitorConfig {
    let mut cfg = MonitorConfig::new(
        p.motor.model(),
        p.supply.f_hz as f32,
        p.supply.v_ll_rms as f32,
        sample_rate_hz as f32,
    );
    cfg.angle_source = opts.angle_source;
    cfg.residual_form = opts.residual_form;
    cfg.tick_hz = TICK_HZ as f32;
    let limits = p.log_limits();
    cfg.limits.v_max = limits.v_max_v;
    cfg.limits.i_max = limits.i_max_a;
    cfg.limits.max_speed_rad_s = limits.wm_max_rad_s;
    cfg
}

impl ReplayOptions {
    /// Sets the option `field` from `value` as a front end hands it by name
    /// ([`crate::DIAGNOSE_OPTIONS`]), each value checked by its type's one constructor.
    ///
    /// # Errors
    /// [`OptionError`] naming the field, for a value it does not take (or a field that is
    /// no option of `diagnose`).
    pub fn set(&mut self, field: OptionField, value: OptionValue) -> Result<(), OptionError> {
        let bad = |why: &str| OptionError::new(field, value.shown(), why);
        match (field, &value) {
            (OptionField::Commission, OptionValue::Text(s)) => self.commission = Some(s.parse()?),
            (OptionField::Commission, OptionValue::Pair(a, b)) => {
                self.commission = Some(CommissionWindow::new(*a, *b)?);
            }
            (OptionField::AllowIncomplete, OptionValue::Flag(b)) => self.allow_incomplete = *b,
            (OptionField::Load, OptionValue::Text(s)) => {
                self.load = match s.as_str() {
                    "unknown" => LoadModel::Unknown,
                    "viscous" => LoadModel::Viscous,
                    _ => return Err(bad("give 'unknown' or 'viscous'")),
                };
            }
            (OptionField::Angle, OptionValue::Text(s)) => {
                self.angle_source = [
                    AngleSource::RotorFluxCurrentModel,
                    AngleSource::Pll,
                    AngleSource::ZeroCrossing,
                ]
                .into_iter()
                .find(|a| angle_source_name(*a) == s)
                .ok_or_else(|| bad("give 'rotor-flux', 'pll' or 'zero-crossing'"))?;
            }
            (OptionField::Residuals, OptionValue::Text(s)) => {
                self.residual_form = match s.as_str() {
                    "steady" => ResidualForm::Steady,
                    "full" => ResidualForm::Full,
                    _ => return Err(bad("give 'steady' or 'full'")),
                };
            }
            (OptionField::TimelineStep, OptionValue::Number(x)) => {
                self.timeline_step = TimelineStep::new(*x)?;
            }
            (OptionField::ParallelPaths, OptionValue::Whole(n)) => {
                self.turn_level.parallel_paths = ParallelPaths::new(*n)?;
            }
            (OptionField::TurnCalibration, OptionValue::Text(json)) => {
                let cal = serde_json::from_str::<TurnCalibration>(json)
                    .map_err(|e| OptionError::new(field, "", format!("not a calibration: {e}")))?;
                self.turn_level.calibration = Some(cal);
            }
            _ => return Err(bad("not a value this option takes")),
        }
        Ok(())
    }
}

/// The parallel paths per phase a winding may have (the field `parallel_paths`): 1 for a
/// series star or delta, 2 for a double star, at most 8.
pub const PARALLEL_PATHS: RangeInclusive<u8> = 1..=8;

/// The winding's parallel paths per phase (the field `parallel_paths`): in
/// [`PARALLEL_PATHS`] by construction.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
pub struct ParallelPaths(u8);

impl ParallelPaths {
    /// One path (a series star or delta): the default.
    pub const ONE: ParallelPaths = ParallelPaths(1);

    /// The paths `n`, given as any whole number.
    ///
    /// # Errors
    /// [`OptionError`] naming `parallel_paths` for a count outside [`PARALLEL_PATHS`].
    pub fn new(n: i64) -> Result<Self, OptionError> {
        match u8::try_from(n) {
            Ok(p) if PARALLEL_PATHS.contains(&p) => Ok(ParallelPaths(p)),
            _ => Err(OptionError::new(
                OptionField::ParallelPaths,
                n.to_string(),
                "give the parallel paths of each phase, 1..=8 (1 for a series star or delta, 2 for a double star)",
            )),
        }
    }

    /// Paths known valid where they are written (a constant).
    ///
    /// # Panics
    /// Outside [`PARALLEL_PATHS`].
    pub const fn of(n: u8) -> Self {
        assert!(n >= 1 && n <= 8, "parallel paths 1..=8");
        ParallelPaths(n)
    }

    /// The paths (1..=8).
    pub fn get(self) -> u8 {
        self.0
    }
}

impl fmt::Display for ParallelPaths {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}", self.0)
    }
}

/// A commissioning window `[start, end)` in log seconds: `0 <= start < end`, both finite,
/// by construction. Written and parsed as `START:END` (`"2:4"`); serialized as
/// `[start, end]`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CommissionWindow {
    start_s: f64,
    end_s: f64,
}

impl CommissionWindow {
    /// The window `[start_s, end_s)` [s].
    ///
    /// # Errors
    /// [`OptionError`] naming `commission` unless `0 <= start_s < end_s`, both finite.
    pub fn new(start_s: f64, end_s: f64) -> Result<Self, OptionError> {
        if end_s > start_s && start_s >= 0.0 && end_s.is_finite() {
            Ok(CommissionWindow { start_s, end_s })
        } else {
            Err(OptionError::new(
                OptionField::Commission,
                format!("{start_s}:{end_s}"),
                "the window must be START:END with 0 <= START < END, both finite (seconds)",
            ))
        }
    }

    /// A window known valid where it is written (a constant: use it in a `const` so that a
    /// bad one fails the build).
    ///
    /// # Panics
    /// Unless `0 <= start_s < end_s`, both finite.
    pub const fn of(start_s: f64, end_s: f64) -> Self {
        assert!(
            end_s > start_s && start_s >= 0.0 && end_s.is_finite(),
            "a commissioning window 0 <= START < END, both finite"
        );
        CommissionWindow { start_s, end_s }
    }

    /// The start [s].
    pub fn start_s(self) -> f64 {
        self.start_s
    }

    /// The end [s].
    pub fn end_s(self) -> f64 {
        self.end_s
    }

    /// `(start, end)` [s].
    pub fn seconds(self) -> (f64, f64) {
        (self.start_s, self.end_s)
    }
}

impl fmt::Display for CommissionWindow {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}:{}", self.start_s, self.end_s)
    }
}

impl Serialize for CommissionWindow {
    fn serialize<S: serde::Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        [self.start_s, self.end_s].serialize(s)
    }
}

/// A window from `[start, end]` (a fleet table's `commission = [2.0, 4.0]`), checked as it is
/// read ([`CommissionWindow::new`]).
impl<'de> serde::Deserialize<'de> for CommissionWindow {
    fn deserialize<D: serde::Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        let [a, b] = <[f64; 2]>::deserialize(d)?;
        CommissionWindow::new(a, b).map_err(serde::de::Error::custom)
    }
}

/// The one parser of a commissioning window: `START:END` in seconds (`"2:4"`, `"1.5:2.4"`).
impl FromStr for CommissionWindow {
    type Err = OptionError;

    fn from_str(s: &str) -> Result<Self, OptionError> {
        let bad = |why: String| OptionError::new(OptionField::Commission, s, why);
        let (a, b) = s
            .split_once(':')
            .ok_or_else(|| bad("not START:END (seconds), e.g. 2:4".into()))?;
        let number = |x: &str| {
            x.trim()
                .parse::<f64>()
                .map_err(|_| bad(format!("'{}' is not a number of seconds", x.trim())))
        };
        CommissionWindow::new(number(a)?, number(b)?)
    }
}

/// The timeline's step [s]: one point per step of the log; finite and > 0 by construction
/// (but [`TimelineStep::NONE`]).
#[derive(Debug, Clone, Copy, PartialEq, PartialOrd)]
pub struct TimelineStep(f64);

impl TimelineStep {
    /// The one default, 0.5 s (the command line's, the API's, Python's).
    pub const DEFAULT: TimelineStep = TimelineStep(0.5);
    /// No timeline (a step no log reaches: the HMI's live view keeps none).
    pub const NONE: TimelineStep = TimelineStep(f64::INFINITY);

    /// A step of `seconds`.
    ///
    /// # Errors
    /// [`OptionError`] naming `timeline_step` unless finite and > 0.
    pub fn new(seconds: f64) -> Result<Self, OptionError> {
        if seconds.is_finite() && seconds > 0.0 {
            Ok(TimelineStep(seconds))
        } else {
            Err(OptionError::new(
                OptionField::TimelineStep,
                seconds.to_string(),
                "give a finite number of seconds > 0",
            ))
        }
    }

    /// A step of `seconds` known valid where it is written (a constant: use it in a
    /// `const` so that a bad one fails the build).
    ///
    /// # Panics
    /// Unless `seconds` is finite and > 0.
    pub const fn of(seconds: f64) -> Self {
        assert!(
            seconds.is_finite() && seconds > 0.0,
            "a timeline step > 0 s"
        );
        TimelineStep(seconds)
    }

    /// The step [s] (> 0; infinite for [`TimelineStep::NONE`]).
    pub fn seconds(self) -> f64 {
        self.0
    }
}

impl fmt::Display for TimelineStep {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}", self.0)
    }
}

impl Default for TimelineStep {
    fn default() -> Self {
        TimelineStep::DEFAULT
    }
}

/// The one parser of a time step: a number of seconds > 0 (`"0.5"`).
impl FromStr for TimelineStep {
    type Err = OptionError;

    fn from_str(s: &str) -> Result<Self, OptionError> {
        let x = s.trim().parse::<f64>().map_err(|_| {
            OptionError::new(
                OptionField::TimelineStep,
                s,
                format!("'{}' is not a number of seconds", s.trim()),
            )
        })?;
        TimelineStep::new(x)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::fields::{Takes, DIAGNOSE_OPTIONS};
    use monitor_io::log::quality::CellLimits;

    /// A value of the kind `takes` that is no option's default.
    fn sample(takes: Takes) -> OptionValue {
        match takes {
            Takes::Window => OptionValue::Text("1:2".into()),
            Takes::Choice(names) => OptionValue::Text(names.last().copied().unwrap_or("").into()),
            Takes::Seconds => OptionValue::Number(0.25),
            Takes::Count => OptionValue::Whole(2),
            Takes::Flag => OptionValue::Flag(true),
            Takes::JsonFile => {
                let run = crate::turn_calibration::LabelledRun {
                    phase: monitor_core::Phase::A,
                    fraction: 0.05,
                    loop_ratio: 0.02,
                };
                let cal = TurnCalibration::learn(&[run]).expect("one run"); // ok: test
                OptionValue::Text(serde_json::to_string(&cal).expect("JSON")) // ok: test
            }
        }
    }

    #[test]
    fn every_described_option_is_set_by_its_name() {
        for spec in DIAGNOSE_OPTIONS {
            let mut opts = ReplayOptions::default();
            opts.set(spec.field, sample(spec.takes))
                .unwrap_or_else(|e| panic!("{}: {e}", spec.field)); // ok: test
            assert_ne!(opts, ReplayOptions::default(), "{} set nothing", spec.field);
        }
        // A value of another kind, or a field that is no option, is refused by name.
        let mut opts = ReplayOptions::default();
        let e = opts.set(OptionField::TimelineStep, OptionValue::Text("x".into()));
        assert_eq!(e.map_err(|e| e.field), Err(OptionField::TimelineStep));
        assert!(opts
            .set(OptionField::Params, OptionValue::Flag(true))
            .is_err());
        let e = opts.set(OptionField::Load, OptionValue::Text("heavy".into()));
        assert_eq!(
            e.map_err(|e| e.to_string()),
            Err("load = heavy: give 'unknown' or 'viscous'".to_string())
        );
    }

    #[test]
    fn the_monitor_and_the_quality_stage_judge_a_log_by_the_same_limits() {
        for p in [ParamFile::reference_2p2kw(), ParamFile::reference_3hp()] {
            let cfg = monitor_config_for_log(&p, 10_000.0, &ReplayOptions::default());
            let cells = CellLimits::for_params(&p);
            assert_eq!(f64::from(cfg.limits.v_max), cells.v_max);
            assert_eq!(f64::from(cfg.limits.i_max), cells.i_max);
            assert_eq!(f64::from(cfg.limits.max_speed_rad_s), cells.wm_max);
            // The speed limit is the core's own default for the supply.
            let core = MonitorConfig::new(
                p.motor.model(),
                p.supply.f_hz as f32,
                p.supply.v_ll_rms as f32,
                10_000.0,
            );
            assert_eq!(cfg.limits.max_speed_rad_s, core.limits.max_speed_rad_s);
            // Twice the sensor ranges.
            let r = p.sensor_ranges();
            assert_eq!(cells.v_max, 2.0 * r.v_range_v);
            assert_eq!(cells.i_max, 2.0 * r.i_range_a);
        }
    }

    #[test]
    fn a_window_is_parsed_and_checked_in_one_place() {
        let w: CommissionWindow = "1.5:2.4".parse().unwrap();
        assert_eq!(w.seconds(), (1.5, 2.4));
        assert_eq!(w.to_string(), "1.5:2.4");
        for bad in ["4:2", "2", "a:3", "-1:2", "1:inf", "2:2"] {
            let e = bad.parse::<CommissionWindow>().unwrap_err();
            assert_eq!(e.field, OptionField::Commission, "{bad}");
            assert!(e.to_string().starts_with("commission = "), "{e}");
        }
    }

    #[test]
    fn a_step_is_positive_and_finite() {
        assert_eq!(TimelineStep::default().seconds(), 0.5);
        assert_eq!("0.25".parse::<TimelineStep>().unwrap().seconds(), 0.25);
        for bad in [0.0, -1.0, f64::NAN, f64::INFINITY] {
            let e = TimelineStep::new(bad).unwrap_err();
            assert_eq!(e.field, OptionField::TimelineStep);
        }
        assert!("x".parse::<TimelineStep>().is_err());
        assert!(ParallelPaths::new(0).is_err() && ParallelPaths::new(9).is_err());
        assert_eq!(ParallelPaths::new(8).map(ParallelPaths::get), Ok(8));
    }
}
