//! The isolation as a stage of the chain: per row the monitor's flags and the steady point
//! ([`IsolationInput`]), at the end its report with what the lamps saw
//! ([`IsolationClosing`], [`IsolationFinding`]).

use super::{refine_single_phase, FaultCandidate, IsolationReport, IsolationTracker};
use crate::range::RangeDeparture;
use crate::stage::{Finish, LampsSeen, RowFlags, Stage};
use crate::windows::SensorPhaseReport;
use monitor_core::{MonitorOutput, SteadyPoint};
use monitor_io::log::Row;

/// What the chain hands the isolation with a row the monitor was fed.
#[derive(Debug, Clone, Copy)]
pub(crate) struct IsolationInput<'a> {
    /// The row's time since the first row [s].
    pub(crate) t: f64,
    /// The monitor's flags, `counts` whether the lamps count and the monitor has settled
    /// after a restart.
    pub(crate) usable: RowFlags,
    /// The steady-state vectors at the row (the sequence stage's, the monitor's speed).
    pub(crate) point: &'a SteadyPoint,
}

/// What the chain hands the isolation at the end.
#[derive(Debug, Clone, Copy)]
pub(crate) struct IsolationClosing<'a> {
    /// What the lamps saw ([`LampsSeen`]).
    pub(crate) seen: LampsSeen,
    /// The monitor's last output.
    pub(crate) out: &'a MonitorOutput,
    /// Where the operating point was outside the commissioned range at the end: what left
    /// it.
    pub(crate) moved_note: Option<&'a [RangeDeparture]>,
    /// One phase's current and voltage sensor read from the zero sequence (the winding's).
    pub(crate) current_sensor: Option<&'a SensorPhaseReport>,
    /// See `current_sensor`.
    pub(crate) voltage_sensor: Option<&'a SensorPhaseReport>,
    /// The lamps' own candidates (a sensor's impossible reading names its sensor).
    pub(crate) signature: &'a [FaultCandidate],
}

/// What the isolation found.
#[derive(Debug, Clone)]
pub(crate) struct IsolationFinding {
    /// The report.
    pub(crate) report: IsolationReport,
    /// The candidates the report lists (the lamps' own for a sensor's impossible reading).
    pub(crate) candidates: Vec<FaultCandidate>,
    /// A fault was detected: a lamp or the isolation, unless heating or the load explains
    /// it ([`IsolationTracker::detected`]).
    pub(crate) detected: bool,
    /// The windings' heating explains the lamps.
    pub(crate) heating_explains_lamps: bool,
    /// The load's move explains the lamps (the load an unknown input).
    pub(crate) load_explains_lamps: bool,
}

impl IsolationTracker {
    /// Whether a fault was detected: a lamp lit (`seen`) or the isolation named a fault,
    /// unless the isolation ends finding that the windings' heating explains it
    /// (`monitor_core::isolation`, "Heating is not a fault"), or, with the load an unknown
    /// input, that the load moved (`LoadModel::Unknown`: the lamps' torque residuals see a
    /// load change as the paper's Bl fault).
    pub(crate) fn detected(&self, seen: LampsSeen) -> bool {
        let lamps = seen.detected && !self.load_explains_lamps() && !seen.only_load;
        !self.heating_explains_lamps() && (lamps || self.named_a_fault())
    }

    /// What the isolation concludes now with what the lamps saw (`seen`), as its finish
    /// would report it (the report and the candidates listed).
    pub(crate) fn now(&self, seen: LampsSeen) -> (IsolationReport, Vec<FaultCandidate>) {
        self.report(self.detected(seen))
    }
}

impl Stage for IsolationTracker {
    type Input<'a> = IsolationInput<'a>;
    type Output = ();

    #[inline]
    fn update(&mut self, row: &Row, inp: IsolationInput<'_>) {
        self.after(inp.t, inp.usable, inp.point, row.t_winding_c);
    }
}

impl Finish for IsolationTracker {
    type Closing<'a> = IsolationClosing<'a>;
    type Finding = IsolationFinding;

    /// The report at the end, with the candidates it lists: the moved point's sentence,
    /// one phase's sensor from the zero sequence.
    fn finish(mut self, c: IsolationClosing<'_>) -> IsolationFinding {
        self.flush();
        let detected = self.detected(c.seen);
        let (mut report, mut isolated) = self.report(detected);
        if let Some(note) = c.moved_note {
            note_moved_point(&mut report, note);
        }
        refine_single_phase(
            &mut report,
            &mut isolated,
            c.current_sensor,
            c.voltage_sensor,
        );
        let candidates = if c.out.sensor_fault.any() {
            c.signature.to_vec()
        } else {
            isolated
        };
        IsolationFinding {
            report,
            candidates,
            detected,
            heating_explains_lamps: self.heating_explains_lamps(),
            load_explains_lamps: self.load_explains_lamps(),
        }
    }
}

/// Outside the commissioned range at the end (`note`: where the point moved), a deviation no
/// single fault explains is the new operating point's, said calmly (the verdict withholds a
/// judgement).
fn note_moved_point(isolation: &mut IsolationReport, note: &[RangeDeparture]) {
    if isolation.state == monitor_core::IsolationState::Unknown {
        isolation.said = super::said::IsolationSaid::OutsideRange {
            departures: note.to_vec(),
            deviation: isolation.deviation_sigma,
        };
    }
}
