//! The replay of a log row by row ([`Replay`]): the ordered chain of the replay's stages
//! (`stage.rs`), each fed one row at a time with what the stages before it handed on.
//!
//! ```text
//! row -> clock -> sequences -> lamps -> winding -> isolation -> timeline
//!          t        step        LampsRow   (windows)   (chunks)    (points)
//! end:  sequences -> lamps -> winding -> rotor -> isolation -> timeline -> findings
//! ```
//!
//! Per row ([`Replay::push`]): the clock gives the row's time; the sequence stage its step
//! (the steady point's vectors, the windows it closed); the lamps feed the core's monitor
//! and hand on its flags and what it said after the row before; the winding books the
//! windows with that; the isolation takes the steady point with the monitor's speed; the
//! timeline takes a point where one is due, with what the panel shows. At the end
//! ([`Replay::finish`]) each stage gives its typed finding, handed what the ones before it
//! found; the report's findings are drawn from them and the verdict is decided once.

use crate::error::ReplayError;
use crate::isolation::{
    FaultCandidate, IsolationClosing, IsolationInput, IsolationName, IsolationReport,
    IsolationTracker, NameGiven,
};
use crate::lamps::LampStage;
use crate::options::{monitor_config_for_log, ReplayOptions};
use crate::report::{signature_candidates, DiagnoseReport};
use crate::rotor::{RotorClosing, RotorStage};
use crate::sequences::{SequenceFront, SequenceStage, SequenceStep};
use crate::stage::{Clock, Finish, LampsSeen, Stage};
use crate::timeline::MovedWhy;
use crate::timeline::{MonitorState, Panel, TimelineInput, TimelineStage};
use crate::verdict::{glance, Verdict};
use crate::winding::{WindingClosing, WindingStage};
use crate::windows::SequenceWindow;
use monitor_core::{Isolator, Monitor, MonitorOutput};
use monitor_io::log::{Channels, Row};
use monitor_io::params::ParamFile;

/// Watches a replay row by row (`diagnose_file_observed`): the live HMI's log source.
pub trait ReplayObserver {
    /// The monitor's output after `row` (as the data-quality stage passed it on, glitches
    /// filled in); `replay` for its time base and thresholds ([`Replay::time_of`],
    /// [`Replay::threshold_bands`]).
    fn output(&mut self, row: &Row, out: &MonitorOutput, replay: &Replay);
    /// The replay starts again from the log's first row (the reader's fast path handed
    /// over to the exact reader): forget every output so far.
    fn restart(&mut self);
}

/// Streaming replay: feed rows, then [`Replay::finish`]. It holds the chain of stages in
/// the order a row passes them, and nothing else.
pub struct Replay {
    clock: Clock,
    sequences: SequenceStage,
    lamps: LampStage,
    winding: WindingStage,
    isolation: IsolationTracker,
    timeline: TimelineStage,
    /// The rotor's rows reach it inside the sequence stage; it only ends.
    rotor: RotorStage,
}

impl Replay {
    /// Prepares a replay of a log with the given channels and sample rate: each stage
    /// configured once, from the options checked here.
    ///
    /// # Errors
    /// [`ReplayError::Config`] when the core rejects the configuration (e.g. a sample rate
    /// below 8x the supply frequency). (The options are valid by construction.)
    pub fn new(
        params: &ParamFile,
        channels: Channels,
        sample_rate_hz: f64,
        opts: ReplayOptions,
    ) -> Result<Self, ReplayError> {
        let cfg = monitor_config_for_log(params, sample_rate_hz, &opts);
        let config_error = |source| ReplayError::Config {
            source,
            sample_rate_hz,
        };
        let clock = Clock::new(sample_rate_hz);
        let lamps = LampStage::new(&cfg, &opts, channels, clock.dt_s()).map_err(config_error)?;
        let front = SequenceFront::new(
            params,
            channels.voltages,
            sample_rate_hz,
            f64::from(cfg.limits.i_max),
            f64::from(cfg.limits.v_max),
        )
        .map_err(config_error)?;
        let isolator = Isolator::new(
            params.motor.model(),
            params.supply.v_phase_peak() as f32,
            params.supply.f_hz as f32,
        );
        Ok(Replay {
            winding: WindingStage::new(params, lamps.monitor().is_some(), &opts),
            isolation: IsolationTracker::new(
                isolator.ok(),
                channels.temperature,
                &opts,
                (clock.dt_s(), u32::from(cfg.decimation)),
            ),
            timeline: TimelineStage::new(clock.dt_s(), &opts),
            rotor: RotorStage::new(params),
            sequences: SequenceStage::new(front),
            lamps,
            clock,
        })
    }

    /// Feeds one row; returns the monitor's output (default output for current-only logs).
    pub fn push(&mut self, row: &Row) -> MonitorOutput {
        if self.sequences.present() {
            let t = self.clock.update(row, ());
            let step = self.sequences.update(row, t);
            self.winding.queue(self.sequences.closed());
            self.after_sequences(row, t, &step);
        }
        self.lamps.output()
    }

    /// [`Replay::push`] with the sequence stage's step for the row already taken (by the
    /// sequence stage lent to another thread, whose closed windows were queued first:
    /// [`Replay::queue_window`]).
    pub(crate) fn push_step(&mut self, row: &Row, step: &SequenceStep) {
        let t = self.clock.update(row, ());
        self.after_sequences(row, t, step);
    }

    /// The chain after the sequence stage, for the row at `t` [s] with its `step`.
    #[inline]
    fn after_sequences(&mut self, row: &Row, t: f64, step: &SequenceStep) {
        let lamps = self.lamps.update(row, t);
        let wr = self.lamps.monitor().map(|_| lamps.before.wr_rad_s);
        let windows = step.window_row(lamps.before.learning, wr);
        self.winding.update(row, windows);
        if !lamps.fed {
            return;
        }
        let Some(out) = self.lamps.monitor().map(Monitor::output) else {
            return;
        };
        let point = step.point(out.operating.wr_rad_s);
        let usable = lamps.usable;
        self.isolation.update(
            row,
            IsolationInput {
                t,
                usable,
                point: &point,
            },
        );
        // (The panel reads the lamps' sensor flag as it stood before this row's revision.)
        let seen = self.lamps.seen(lamps.before.sensor_fault);
        let (stages_lamps, isolation) = (&self.lamps, &self.isolation);
        let panel = |since_moved| panel_of(stages_lamps, isolation, (seen, since_moved), out);
        let moved = || {
            isolation.load_explains_lamps() || stages_lamps.commission().outside_learned_range(out)
        };
        let input = TimelineInput {
            t,
            out,
            lamps_lit: lamps.lamps_lit,
            range_note: stages_lamps.range_note(),
            moved: &moved,
            panel: &panel,
        };
        self.timeline.update(row, input);
    }

    /// Queues a window the sequence stage closed on another thread, before the step of the
    /// row it closed at ([`Replay::push_step`]).
    pub(crate) fn queue_window(&mut self, w: Option<SequenceWindow>) {
        self.winding.queue(std::iter::once(w));
    }

    /// Takes over the sequence stage's front that ran on another thread, once every row was
    /// pushed: its last window is the replay's to close ([`Replay::finish`]).
    pub(crate) fn set_sequence_front(&mut self, front: SequenceFront) {
        self.sequences.give_back(front);
    }

    /// Lends the sequence stage's front to the thread that reads the log, which runs it
    /// beside this replay and gives it back at the end ([`Replay::set_sequence_front`]): the
    /// one front built with the replay, on the replay's configuration.
    pub(crate) fn lend_sequence_front(&mut self) -> Option<SequenceFront> {
        self.sequences.lend()
    }

    /// The acquisition clock was reset before the next row: the lamps carry the encoder
    /// count on over the bridged time.
    pub(crate) fn clock_reset(&mut self) {
        self.lamps.clock_reset();
    }

    /// `row` as the monitor sees it (the encoder offset of the clock resets so far).
    pub(crate) fn as_monitor_sees(&self, row: &Row) -> Row {
        self.lamps.with_encoder_offset(row)
    }

    /// The learned calibration (mean and spread of r1..r4), once commissioning is done.
    pub fn calibration(&self) -> Option<monitor_core::Calibration> {
        self.lamps.monitor().and_then(Monitor::calibration)
    }

    /// The threshold bands of r1..r4 in force, (centre, half-width)
    /// ([`Monitor::threshold_bands`]); `None` for a current-only log.
    pub fn threshold_bands(&self) -> Option<[(f32, f32); 4]> {
        self.lamps.monitor().map(Monitor::threshold_bands)
    }

    /// Time of `row` since the replay's first row [s] (the timeline's time).
    pub fn time_of(&self, row: &Row) -> f64 {
        self.clock.time_of(row)
    }

    /// What the isolation concludes now, as [`Replay::finish`] would report it (the report
    /// and the candidates listed), for a screen that follows the replay.
    pub fn isolation_now(&self) -> (IsolationReport, Vec<FaultCandidate>) {
        self.isolation.now(self.lamps.seen_now())
    }

    /// Every name the isolation gave so far (a fault or the friction class `b/bl`), each
    /// with the first time it was given [s] (the replay's time), in that order: a name
    /// given and later withdrawn stays here.
    pub fn isolation_names(&self) -> &[NameGiven] {
        self.isolation.names()
    }

    /// Where the load or the voltage of `out` has left the range learned in
    /// commissioning: the note ("load (active current) 9.52 is 47 % above the commissioned
    /// 6.47..6.48"); `None` inside it or without a learned window. The HMI shows this as
    /// the amber "operating point moved" state: to the paper's model a load change is a Bl
    /// change, so lamps lit there are not a fault unless the isolation names one.
    pub fn operating_point_moved(
        &self,
        out: &MonitorOutput,
    ) -> Option<Vec<crate::lamps::commission::RangeDeparture>> {
        self.lamps.commission().moved_note(out)
    }

    /// The core monitor (`None` for a current-only log).
    pub fn monitor(&self) -> Option<&Monitor> {
        self.lamps.monitor()
    }

    /// The core monitor, to start a commissioning run by hand (the live HMI's key); `None`
    /// for a current-only log.
    pub fn monitor_mut(&mut self) -> Option<&mut Monitor> {
        self.lamps.monitor_mut()
    }

    /// True when a commissioning window was asked for and not learned.
    pub fn commissioning_incomplete(&self) -> bool {
        self.lamps.monitor().is_some() && self.lamps.commission().incomplete()
    }

    /// The commissioning window asked for and why it was not learned, where it was not.
    pub(crate) fn commissioning_not_learned(&self) -> Option<crate::lamps::commission::NotLearned> {
        self.lamps.commission().not_learned()
    }

    /// The monitor's state at the replay's output `out` as the panel shows it, the one rule
    /// of the HMI, the demo and `diagnose`'s timeline: [`MonitorState::of`], except that
    /// where the load or the voltage has left the commissioned range
    /// ([`Replay::operating_point_moved`]) and neither the isolation nor a sensor check
    /// names a fault, an evaluated output (healthy or lamps lit) is the amber
    /// [`MonitorState::Moved`] with the note: to the paper's model a load change is a Bl
    /// change, so lamps lit there are not a fault (the friction class `b/bl` is not named
    /// as one).
    pub fn state(&self, out: &MonitorOutput) -> MonitorState {
        let now = (self.lamps.seen_now(), self.timeline.since_moved());
        state_given(
            &self.lamps,
            &self.isolation,
            now,
            out,
            MonitorState::of(out),
            None,
        )
    }

    /// What the panel shows at the replay's output `out`: the state ([`Replay::state`]),
    /// the FAULT lamp (off in the amber state) and, where the lamps are evaluated, the
    /// isolation's conclusion (asked for once).
    pub fn panel(&self, out: &MonitorOutput) -> Panel {
        let now = (self.lamps.seen_now(), self.timeline.since_moved());
        panel_of(&self.lamps, &self.isolation, now, out)
    }

    /// Ends the replay and builds the report, its verdict decided
    /// ([`DiagnoseReport::conclude`]; `data_quality` left at its default for the caller to
    /// fill).
    pub fn finish(self) -> DiagnoseReport {
        let mut report = self.end();
        report.conclude();
        report
    }

    /// Ends every stage in the chain's order, each handed what the ones before it found:
    /// the report with its findings, the verdict not decided yet (`diagnose` adds the
    /// data-quality stage's finding first).
    pub(crate) fn end(self) -> DiagnoseReport {
        let bands = self.threshold_bands().map(|b| b.map(|(c, w)| [c, w]));
        let rows = self.clock.finish(());
        let sequences = self.sequences.finish(());
        let lamps = self.lamps.finish(());
        let wr = lamps.monitor.then_some(lamps.out.operating.wr_rad_s);
        let unbalance = self.winding.finish(WindingClosing {
            closed: sequences.closed,
            closed_last: sequences.closed_last.then_some(wr),
        });
        let measured: Vec<_> = unbalance
            .segments
            .iter()
            .filter_map(|g| g.measured_point())
            .collect();
        let rotor = self.rotor.finish(RotorClosing {
            front: sequences.front.as_ref().map(SequenceFront::rotor),
            measured: &measured,
        });
        let signature = signature_candidates(&lamps.out);
        let moved_note = lamps.commission.moved_note(&lamps.out);
        let isolation = self.isolation.finish(IsolationClosing {
            seen: lamps.seen,
            out: &lamps.out,
            moved_note: moved_note.as_deref(),
            current_sensor: unbalance.current_sensor_phase.as_ref(),
            voltage_sensor: unbalance.voltage_sensor_phase.as_ref(),
            signature: &signature,
        });
        let timeline = self.timeline.finish(());
        let mut report = DiagnoseReport::undecided(
            rows,
            (lamps, isolation),
            (unbalance, rotor),
            signature,
            timeline,
        );
        report.threshold_bands = bands;
        report
    }
}

/// [`Replay::state`] from the output's own state `state` ([`MonitorState::of`]) and, when
/// the caller has it, the isolation's report now (else asked for only where the operating
/// point has moved); `(seen, since_moved)`: what the lamps saw, and the timeline's amber
/// memory.
fn state_given(
    lamps: &LampStage,
    isolation: &IsolationTracker,
    (seen, since_moved): (LampsSeen, bool),
    out: &MonitorOutput,
    state: MonitorState,
    report: Option<&IsolationReport>,
) -> MonitorState {
    let evaluated = matches!(state, MonitorState::Healthy | MonitorState::Fault(_));
    if !evaluated || out.sensor_fault.any() {
        return state;
    }
    let note = match lamps.commission().moved_note(out) {
        Some(departures) => MovedWhy::OutsideRange { departures },
        // With the load an unknown input, lamps lit for a load that moved inside the
        // commissioned range are the amber state too (`LoadModel::Unknown`).
        None if matches!(state, MonitorState::Fault(_)) && isolation.load_explains_lamps() => {
            MovedWhy::LoadMovedInside
        }
        // Lamps that lit while the load had moved are still releasing (they go out
        // after a second inside their bands): amber until they do, unless the isolation
        // names a fault meanwhile.
        None if matches!(state, MonitorState::Fault(_)) && since_moved => MovedWhy::LoadCameBack,
        None => return state,
    };
    let named = match report {
        Some(r) => r.named,
        None => isolation.now(seen).0.named,
    };
    if matches!(named, Some(IsolationName::Fault(_))) {
        state
    } else {
        MonitorState::Moved(note)
    }
}

/// What the panel shows at `out` ([`Replay::panel`]), from the lamps' and the isolation's
/// stages with what the lamps saw and the timeline's amber memory (`now`).
fn panel_of(
    lamps: &LampStage,
    isolation: &IsolationTracker,
    now: (LampsSeen, bool),
    out: &MonitorOutput,
) -> Panel {
    let (seen, since_moved) = now;
    let own = MonitorState::of(out);
    let evaluated = matches!(own, MonitorState::Healthy | MonitorState::Fault(_));
    let asked_once = evaluated.then(|| isolation.now(seen));
    let state = state_given(
        lamps,
        isolation,
        now,
        out,
        own,
        asked_once.as_ref().map(|(r, _)| r),
    );
    // Outside the evaluated points (a transient: the lamps hold) the isolation is
    // asked once here where the rule or the load's note needs it.
    let asked =
        (asked_once.is_none() && (out.fault_detected || since_moved)).then(|| isolation.now(seen));
    let report = asked_once.as_ref().or(asked.as_ref());
    // Lamps held through the transient after a load move are the load's, not a fault,
    // unless the isolation names one.
    let held_for_load = since_moved
        && !matches!(
            report.and_then(|(r, _)| r.named),
            Some(IsolationName::Fault(_))
        );
    // The decision table (`monitor_core::verdict`), as the verdict and the board's
    // lamp read it: the FAULT lamp is lit for a named fault at even odds or better only.
    let moved = matches!(state, MonitorState::Moved(_)) || held_for_load;
    let call = glance(out, report, moved).decide().verdict;
    Panel {
        fault_lamp: call == Verdict::Fault && !moved,
        call,
        isolation: asked_once,
        state,
    }
}
