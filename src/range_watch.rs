//! The commissioned operating range in thread mode, and the panel's "operating point moved"
//! state.
//!
//! The learned healthy means of the residuals hold only near the operating point of the
//! commissioning run that learned them (to the paper's model a load change is a Bl change).
//! While a run learns, [`RangeWatch::observe`] widens the span of the load (active current)
//! and of the voltage magnitude, measured without the d-q frame's angle, from each
//! quasi-steady status the sample task hands over (block rate, nothing in the per-sample
//! path); when the run ends stored and in force ([`RangeWatch::commit`]) that span is the
//! commissioned range. Afterwards [`RangeWatch::moved`] says when the load or the voltage is
//! more than 20 % of the span's largest magnitude outside it: the rule and the margin are
//! the core's (`monitor_core::operating_range`), the same as the host's `diagnose`, HMI
//! and demo.
//!
//! The range lives in RAM only: after a reset without a new commissioning run the board
//! does not judge "moved" (the flash record holds the thresholds and the isolation
//! baseline, not the range).

use monitor_core::{OperatingPoint, OperatingRange, RunStage};

/// What the watch reads of one status the sample task hands over (the app builds it,
/// `MonitorStatus::range_moment`; this module knows nothing of the app).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RangeMoment {
    /// The status's operating point ([`OperatingPoint::from_dq`] of its `V_ds`, `V_qs`,
    /// `i_ds`, `I_qs`).
    pub point: OperatingPoint,
    /// The commissioning run's stage.
    pub stage: RunStage,
    /// The commissioning run's id.
    pub run: u16,
    /// The quasi-steady gate is open.
    pub quasi_steady: bool,
    /// Thresholds learned by commissioning are in force.
    pub commissioned: bool,
    /// The lamps are evaluated (past the warm-up).
    pub evaluating: bool,
}

/// The commissioned range and the one being learned (module docs).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct RangeWatch {
    /// The range of the run in force (since boot); empty before one.
    commissioned: OperatingRange,
    /// The range the latest run learned (or is learning), and its run id.
    learning: Option<(u16, OperatingRange)>,
}

impl RangeWatch {
    /// Nothing learned.
    pub const fn new() -> Self {
        Self {
            commissioned: OperatingRange::EMPTY,
            learning: None,
        }
    }

    /// Feeds a status: while its run learns and the quasi-steady gate is open, widens that
    /// run's range (a new run starts from nothing).
    pub fn observe(&mut self, s: &RangeMoment) {
        if s.stage != RunStage::Learning || !s.quasi_steady {
            return;
        }
        let id = s.run;
        if !matches!(self.learning, Some((run, _)) if run == id) {
            self.learning = Some((id, OperatingRange::EMPTY));
        }
        if let Some((_, range)) = &mut self.learning {
            range.learn(s.point);
        }
    }

    /// The run `run` ended stored and in force: its range is the commissioned one (a run
    /// that learned no point leaves nothing to judge against).
    pub fn commit(&mut self, run: u16) {
        self.commissioned = match self.learning {
            Some((id, range)) if id == run => range,
            _ => OperatingRange::EMPTY,
        };
    }

    /// The commissioned range in force (empty before a run since boot).
    pub fn commissioned(&self) -> &OperatingRange {
        &self.commissioned
    }

    /// The status's operating point has left the commissioned range (beyond the core's
    /// margin) while the learned thresholds are in force and the lamps are evaluated.
    pub fn moved(&self, s: &RangeMoment) -> bool {
        s.commissioned && s.evaluating && !s.stage.is_active() && self.commissioned.moved(s.point)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn moment(load_a: f32, stage: RunStage, quasi_steady: bool) -> RangeMoment {
        RangeMoment {
            point: OperatingPoint {
                load_a,
                voltage_v: 325.0,
            },
            stage,
            run: 1,
            quasi_steady,
            commissioned: false,
            evaluating: true,
        }
    }

    /// The commissioned range is what the run learned at steady operating points: a status
    /// with the quasi-steady gate closed (a load step's transient) or one past the learning
    /// (the run's end, its storage) widens nothing.
    #[test]
    fn only_quasi_steady_points_of_a_learning_run_widen_the_range() {
        let mut w = RangeWatch::new();
        w.observe(&moment(10.0, RunStage::Learning, true));
        w.observe(&moment(12.0, RunStage::Learning, true));
        w.observe(&moment(30.0, RunStage::Learning, false));
        w.observe(&moment(50.0, RunStage::Done, true));
        w.commit(1);
        assert_eq!(w.commissioned().load_a, Some([10.0, 12.0]));
        assert_eq!(w.commissioned().voltage_v, Some([325.0, 325.0]));
    }

    /// A run that ends stored without a steady point learned (its statuses all with the
    /// gate closed) leaves no range to judge against, not the range an earlier run learned.
    #[test]
    fn a_run_that_learned_no_point_commits_an_empty_range() {
        let mut w = RangeWatch::new();
        w.observe(&moment(10.0, RunStage::Learning, true));
        w.commit(1);
        assert!(w.commissioned().is_learned());
        let mut second = moment(20.0, RunStage::Learning, false);
        second.run = 2;
        w.observe(&second);
        w.commit(2);
        assert_eq!(*w.commissioned(), OperatingRange::EMPTY);
    }
}
