//! The timeline stage ([`TimelineStage`]): one point per `timeline_step` with what the panel
//! shows there ([`Panel`]), a point of its own where commissioning has learned, and whether
//! the lamps lit now first lit while the load had moved (the amber state's release).
//!
//! Per row it is handed the monitor's output and what the panel needs of the stages before
//! it ([`TimelineInput`]); at the end it gives its points.

use crate::isolation::{FaultCandidate, IsolationReport};
use crate::lamps::commission::RangeDeparture;
use crate::options::ReplayOptions;
use crate::stage::{Finish, Stage};
use monitor_core::{CommissioningState, Fault, MonitorOutput};
use monitor_io::log::Row;
use serde::Serialize;

use monitor_core::verdict::Verdict;

/// What the monitor is doing at a timeline point, as the panel would show it.
#[derive(Debug, Clone, PartialEq)]
pub enum MonitorState {
    /// Learning the healthy residuals; the fraction done.
    Commissioning(f32),
    /// The operating point is changing: the lamps hold.
    Transient,
    /// Settling after start (lamps not yet evaluated).
    Starting,
    /// Evaluating, no lamp lit.
    Healthy,
    /// Lamps lit: the candidates with their probabilities.
    Fault(Vec<(Fault, f32)>),
    /// The load or the voltage has left the commissioned range and no fault is named (the
    /// amber state): lamps may light, the FAULT lamp stays off; why the operating point
    /// counts as moved ([`crate::Replay::operating_point_moved`]).
    Moved(MovedWhy),
}

impl MonitorState {
    /// The state of a monitor output.
    pub fn of(o: &MonitorOutput) -> Self {
        match o.commissioning {
            CommissioningState::Learning(x) => MonitorState::Commissioning(x),
            _ if !o.quasi_steady => MonitorState::Transient,
            _ if !o.evaluating => MonitorState::Starting,
            _ if o.top().is_none() => MonitorState::Healthy,
            _ => MonitorState::Fault(MonitorState::signature(o)),
        }
    }

    /// The signature matching's candidates of `o` (probability above zero), most probable
    /// first.
    pub fn signature(o: &MonitorOutput) -> Vec<(Fault, f32)> {
        let mut c: Vec<(Fault, f32)> = Fault::ALL
            .iter()
            .zip(o.diagnosis.probabilities)
            .filter(|(_, p)| *p > 0.0)
            .map(|(f, p)| (*f, p))
            .collect();
        c.sort_by(|a, b| b.1.total_cmp(&a.1));
        c
    }
}

/// Why the operating point counts as moved (the amber state).
#[derive(Debug, Clone, PartialEq, Serialize)]
#[serde(tag = "kind", rename_all = "snake_case")]
pub enum MovedWhy {
    /// The load or the voltage has left the commissioned range.
    OutsideRange {
        /// What left it.
        departures: Vec<RangeDeparture>,
    },
    /// The lamps lit for a load that moved inside the commissioned range, with the load an
    /// unknown input (`LoadModel::Unknown`): the stator-voltage equations fit.
    LoadMovedInside,
    /// The load came back into the commissioned range; the lamps that lit while it had
    /// moved are going out.
    LoadCameBack,
    /// The board's status line says the load or the voltage left the commissioned range
    /// (it does not say which, nor by how much).
    BoardSays,
}

/// One point of the diagnosis timeline.
#[derive(Debug, Clone, Serialize)]
pub struct TimelinePoint {
    /// Time [s].
    pub t_s: f64,
    /// Normalised residuals r1..r4.
    pub residuals: [f32; 4],
    /// Lamps r1..r4.
    pub lamps: [bool; 4],
    /// Most probable fault, if any (JSON: its name).
    pub top: Option<Fault>,
    /// Its probability.
    pub top_probability: f32,
    /// Mechanical speed [rad/s].
    pub speed_rad_s: f32,
    /// Lamps are being evaluated (running, settled, commissioned or fixed).
    pub evaluating: bool,
    /// Learning healthy statistics.
    pub commissioning: bool,
    /// The operating point is quasi-steady (the steady-state residuals apply).
    pub quasi_steady: bool,
    /// |I2|/|I1|.
    pub negative_sequence_ratio: f32,
    /// Beside a lit r2..r4 lamp: the operating point has left the commissioned range, and
    /// how (JSON `range_departures`; the door spells it as `range_note`).
    #[serde(rename = "range_departures", skip_serializing_if = "Option::is_none")]
    pub range_note: Option<Vec<RangeDeparture>>,
    /// What the panel shows ([`crate::Replay::panel`]; not in the JSON, whose keys above carry
    /// it).
    #[serde(skip)]
    pub panel: Panel,
}

/// What the panel shows at an output ([`crate::Replay::panel`]): the HMI, the demo's and
/// `diagnose`'s timelines.
#[derive(Debug, Clone, PartialEq)]
pub struct Panel {
    /// The state ([`crate::Replay::state`]).
    pub state: MonitorState,
    /// The FAULT lamp: the decision table's FAULT ([`Panel::call`]), off in the amber
    /// state.
    pub fault_lamp: bool,
    /// The decision table's verdict at this output (`monitor_core::verdict::Glance`, the
    /// board's rule).
    pub call: Verdict,
    /// What the isolation concluded where the lamps are evaluated (the report and the
    /// candidates listed, [`crate::Replay::isolation_now`]), else `None`.
    pub isolation: Option<(IsolationReport, Vec<FaultCandidate>)>,
}

/// The timeline stage: its points, the next point's time, and the amber state's memory.
#[derive(Debug, Clone)]
pub(crate) struct TimelineStage {
    points: Vec<TimelinePoint>,
    /// The next point's time [s].
    next_point: f64,
    /// Commissioning was learning at the last row (its end gets a point of its own).
    was_learning: bool,
    /// The sample interval [s] and the step between points [s].
    dt_s: f64,
    step_s: f64,
    /// The lamps lit now first lit while the operating point had moved (or the load
    /// explained them), and have not all been dark since: their release after the load came
    /// back is still the amber state.
    since_moved: bool,
}

/// What the chain hands the timeline with a row the monitor was fed.
pub(crate) struct TimelineInput<'a> {
    /// The row's time since the first row [s].
    pub(crate) t: f64,
    /// The monitor's output after the row.
    pub(crate) out: &'a MonitorOutput,
    /// A lamp is lit.
    pub(crate) lamps_lit: bool,
    /// The commissioned range's note at the monitor's last revision.
    pub(crate) range_note: Option<&'a Vec<RangeDeparture>>,
    /// Whether the operating point has moved now: the load explains the lamps, or the
    /// point is outside the commissioned range (asked only while a lamp is lit and the
    /// amber memory is off).
    pub(crate) moved: &'a dyn Fn() -> bool,
    /// What the panel shows at `out`, given the amber memory ([`TimelineStage::since_moved`]).
    pub(crate) panel: &'a dyn Fn(bool) -> Panel,
}

impl TimelineStage {
    /// A timeline of a log sampled every `dt_s` [s], as `opts` ask (one point every
    /// `timeline_step`).
    pub(crate) fn new(dt_s: f64, opts: &ReplayOptions) -> Self {
        TimelineStage {
            points: Vec::new(),
            next_point: 0.0,
            was_learning: false,
            dt_s,
            step_s: opts.timeline_step.seconds(),
            since_moved: false,
        }
    }

    /// The lamps lit now first lit while the load had moved (the amber state's memory).
    pub(crate) fn since_moved(&self) -> bool {
        self.since_moved
    }
}

/// The timeline point of an output at `t` with what the panel shows there.
fn point(
    t: f64,
    out: &MonitorOutput,
    range_note: Option<Vec<RangeDeparture>>,
    panel: Panel,
) -> TimelinePoint {
    let top = out.top();
    TimelinePoint {
        t_s: t,
        residuals: out.residuals,
        lamps: out.lamps,
        top: top.map(|(f, _)| f),
        top_probability: top.map(|(_, p)| p).unwrap_or(0.0),
        speed_rad_s: out.speed_rad_s,
        evaluating: out.evaluating,
        commissioning: matches!(out.commissioning, CommissioningState::Learning(_)),
        quasi_steady: out.quasi_steady,
        negative_sequence_ratio: out.unbalance.negative_sequence_ratio,
        range_note,
        panel,
    }
}

impl Stage for TimelineStage {
    type Input<'a> = TimelineInput<'a>;
    type Output = ();

    #[inline]
    fn update(&mut self, _row: &Row, inp: TimelineInput<'_>) {
        let (t, out) = (inp.t, inp.out);
        // The moment commissioning has learned gets a point of its own ("commissioning
        // 100 %"): between two steps it would otherwise jump from a part done to healthy.
        let learning = matches!(out.commissioning, CommissioningState::Learning(_));
        if self.was_learning && matches!(out.commissioning, CommissioningState::Commissioned) {
            let mut done = point(t, out, None, (inp.panel)(self.since_moved));
            done.panel.state = MonitorState::Commissioning(1.0);
            done.commissioning = true;
            self.points.push(done);
        }
        self.was_learning = learning;
        // The sample nearest each timeline step (half a sample early counts: the data-quality
        // stage's sample clock may put the sample at the step a hair before it).
        if timeline_step_due(&mut self.next_point, t, self.dt_s, self.step_s) {
            let p = point(
                t,
                out,
                inp.range_note.cloned(),
                (inp.panel)(self.since_moved),
            );
            self.points.push(p);
        }
        // (Once true it stays true while a lamp is lit: the load's checks are made only
        // while it is false.)
        self.since_moved = inp.lamps_lit && (self.since_moved || (inp.moved)());
    }
}

impl Finish for TimelineStage {
    type Closing<'a> = ();
    type Finding = Vec<TimelinePoint>;

    fn finish(self, (): ()) -> Vec<TimelinePoint> {
        self.points
    }
}

/// Whether the sample at `t` [s] (interval `dt_s`) is the one nearest the timeline step
/// `next` (half a sample early counts); if so, `next` moves on by `step_s`, past `t` after a
/// gap (one point for the gap, not one per step missed).
#[inline]
fn timeline_step_due(next: &mut f64, t: f64, dt_s: f64, step_s: f64) -> bool {
    if t + 0.5 * dt_s < *next {
        return false;
    }
    *next += step_s;
    if *next <= t {
        *next += (((t - *next) / step_s).floor() + 1.0) * step_s;
    }
    true
}
