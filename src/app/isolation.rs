//! The fault isolation of thread mode: the isolator for the built-in machine, the
//! isolation in the status line's words, and the [`Supervisor`]'s part that feeds the
//! monitor's statuses to the core's schedule (`monitor_core::isolation::Follower`).

use super::*;

/// The fault isolator for [`DEFAULT_MACHINE`] on its rated supply.
///
/// # Errors
/// The core's [`ConfigError`] if it rejects the machine or the supply (then nothing is
/// isolated and the blink code is the lamps' top candidate).
pub fn board_isolator() -> Result<Isolator, ConfigError> {
    let supply = DEFAULT_MACHINE.supply;
    Isolator::new(
        default_motor(),
        supply.v_phase_peak() as f32,
        supply.f_hz as f32,
    )
}

/// The isolation in the status line's words (docs/firmware.md, "The status line"): the label
/// (the fault's name `rs`..`speed_sensor`, `b/bl` for the friction class, `unknown`,
/// `none` for no deviation from the healthy baseline, `not-judged`), the named fault's
/// size (relative change, 0.48 for +48 %; for sensors the gain error; Bl's for the
/// friction class; 0 when nothing is named) and its probability (the unknown fault's for
/// `unknown`, 0 otherwise).
pub fn isolation_summary(iso: Option<&Isolation>) -> (&'static str, f32, f32) {
    let Some(iso) = iso else {
        return ("not-judged", 0.0, 0.0);
    };
    match (iso.named(), iso.state) {
        (Some(Named::Fault(c)), _) => (c.fault.name(), c.change, c.probability),
        (
            Some(Named::Friction {
                probability, bl, ..
            }),
            _,
        ) => ("b/bl", bl.change, probability),
        (None, IsolationState::NoDeviation) => ("none", 0.0, 0.0),
        (None, IsolationState::NotJudged) => ("not-judged", 0.0, 0.0),
        (None, _) => ("unknown", 0.0, iso.unknown_probability),
    }
}

impl Supervisor {
    /// Isolates against `isolator`'s machine from now on (the motor record's, read at boot;
    /// [`Supervisor::new`] starts with [`board_isolator`]'s built-in default). `None`: the
    /// machine was rejected, nothing is isolated (the blink code is the lamps' top candidate).
    pub fn set_isolator(&mut self, isolator: Option<Isolator>) {
        self.isolation = isolator.map(Follower::new);
        self.run_baseline = None;
        self.evidence = Evidence::default();
    }

    /// Puts the isolation baseline of the record loaded at boot into force (the record the
    /// core accepted), so that after a reset the isolation judges against the machine's own
    /// baseline again. Returns whether one was put into force.
    pub fn restore_isolation(&mut self, record: &CalibrationRecord) -> bool {
        match (self.isolation.as_mut(), record.isolation) {
            (Some(f), Some(b)) => f.restore_learned(b),
            _ => false,
        }
    }

    /// The latest fault isolation in force (`None` before the first steady half second, or
    /// unusable): the averaged point's, or the joint fit's over the operating points kept
    /// since the deviation began where it names a fault that the point alone does not
    /// (`monitor_core::isolation::Evidence::joint_beside`: the host's rule).
    pub fn isolation(&self) -> Option<&Isolation> {
        let single = self.isolation.as_ref().and_then(Follower::last)?;
        Some(self.evidence.in_force(single))
    }

    /// The isolation as the panel reads it ([`super::panel_input`], [`super::panel_call`]):
    /// the latest in force and whether its baseline was learned in commissioning.
    pub fn panel_isolation(&self) -> super::PanelIsolation<'_> {
        super::PanelIsolation {
            latest: self.isolation(),
            learned: self.isolation.as_ref().is_some_and(Follower::learned),
        }
    }

    /// The isolation baseline in force when it was learned in commissioning (this run or a
    /// stored one); `None` with the nominal parameters' defaults.
    pub fn isolation_baseline(&self) -> Option<Baseline> {
        self.isolation
            .as_ref()
            .filter(|f| f.learned())
            .map(|f| f.isolator().baseline())
    }

    /// Feeds a new status to the fault isolation: its operating point, `dt` from the sample
    /// counter, usable once the monitor has evaluated with no sensor fault, learning while
    /// a commissioning run learns (the core's schedule: `monitor_core::isolation::Follower`).
    /// Learning ends when the run stops learning, before its calibration is stored, so
    /// that the baseline goes into the same record. Each isolation goes to the evidence
    /// across operating points ([`Evidence::after`]: a joint fit once per 0.1 s block at
    /// most); a run that learns forgets it (a new baseline).
    pub(super) fn follow(&mut self, s: &MonitorStatus, previous_samples: u32) {
        let Some(f) = self.isolation.as_mut() else {
            return;
        };
        let dt_s = s.samples.wrapping_sub(previous_samples) as f32 / self.sample_rate_hz as f32;
        self.running |= s.evaluating;
        let usable = self.running && !s.sensor_fault.any();
        let learning = s.run.stage == monitor_core::RunStage::Learning;
        if learning {
            self.run_baseline = None;
            self.evidence = Evidence::default();
        }
        match f.observe(&s.point, dt_s, usable, learning) {
            Step::LearningEnded(ok) => self.run_baseline = ok.then(|| f.isolator().baseline()),
            Step::Isolated(result) => self.evidence.after(f, &result),
            _ => {}
        }
    }
}
