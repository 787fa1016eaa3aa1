//! What a replay is asked to do ([`ReplayOptions`], [`LoadModel`]), the typed values a
//! front end parses its words into ([`CommissionWindow`], [`TimelineStep`]), the one check
//! of them all ([`ReplayOptions::validate`]) and its error ([`OptionError`], naming the
//! field, never a front end's spelling of it), and the monitor configuration a replay runs
//! with ([`monitor_config_for_log`]).

use super::option_values::{check_parallel_paths, CommissionWindow, OptionError, TimelineStep};
use super::{HealthyReference, TICK_HZ};
use monitor_core::{AngleSource, MonitorConfig, ResidualForm};
use monitor_io::params::ParamFile;

/// Replay options.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ReplayOptions {
    /// Frame angle source.
    pub angle_source: AngleSource,
    /// Residual form for the lamps.
    pub residual_form: ResidualForm,
    /// Commissioning window [start, end) in log seconds; None = fixed thresholds. Checked
    /// by [`ReplayOptions::validate`] as [`CommissionWindow::new`] checks it.
    pub commission: Option<(f64, f64)>,
    /// Report a commissioning window that was not learned instead of refusing.
    pub allow_incomplete: bool,
    /// Timeline resolution (one point per interval; default 0.5 s, the one default of
    /// the command line, the API and Python).
    pub timeline_step: TimelineStep,
    /// The healthy machine's negative sequence to judge the winding against (the field
    /// `baseline` of a request: healthy logs); without it, the one learned in the
    /// commissioning window, else none ([`super::UnbalanceBaseline`]).
    pub unbalance_baseline: Option<HealthyReference>,
    /// What is known of the load ([`LoadModel`]; the field `load`).
    pub load: LoadModel,
    /// How the shorted-turn level is sized (the fields `parallel_paths`, 1..=8 as
    /// [`super::PARALLEL_PATHS`] says, and `turn_calibration`; [`super::winding::level`]).
    pub turn_level: super::TurnLevelOptions,
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
            turn_level: super::TurnLevelOptions::default(),
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
    /// The one check of the options every front end calls (the command line, Python, the
    /// HMI, the fleet; [`super::Replay::new`] too): the commissioning window as
    /// [`CommissionWindow::new`] checks it, `parallel_paths` in [`super::PARALLEL_PATHS`] (the
    /// time step is positive by construction, [`TimelineStep`]).
    ///
    /// # Errors
    /// [`OptionError`] naming the field (`commission`, `parallel_paths`).
    pub fn validate(&self) -> Result<(), OptionError> {
        if let Some((a, b)) = self.commission {
            CommissionWindow::new(a, b)?;
        }
        check_parallel_paths(i64::from(self.turn_level.parallel_paths))?;
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use monitor_io::log::quality::CellLimits;

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
}
