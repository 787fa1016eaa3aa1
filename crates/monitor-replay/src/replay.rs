//! The replay of a log row by row ([`Replay`]): the core's monitor, the sequence analysis,
//! the isolation and the bookkeeping of the report, fed one row at a time.

use crate::error::ReplayError;
use crate::isolation::{self, FaultCandidate, IsolationReport, IsolationTracker, NameGiven};
use crate::lamps::LampStage;
use crate::options::{monitor_config_for_log, LoadModel, ReplayOptions};
use crate::report::{
    final_lamps, note_moved_point, signature_candidates, skipped_analyses, DiagnoseReport,
    MonitorState, Panel, TimelinePoint, LOAD_BACK_NOTE, LOAD_MOVED_NOTE,
};
use crate::rotor::{rotor_report, RotorReport};
use crate::sequences::{self, SequenceWindow};
use crate::step::{lamps_since_moved, timeline_step_due, BlockView, LastOutput};
use crate::verdict::{findings, glance, Rule, Verdict};
use crate::winding::{unbalance_report, UnbalanceReport};
use crate::words::Words;
use monitor_core::{CommissioningState, Isolator, Monitor, MonitorOutput};
use monitor_io::log::quality::DataQuality;
use monitor_io::log::{Channels, Row};
use monitor_io::params::ParamFile;

/// The isolation's tracker for a replay of a log with `channels` under `params` (no
/// isolator for a machine it rejects), `load` what is known of the load, `decimation` the
/// core's block (the rows the tracker hands on together).
fn isolation_tracker(
    params: &ParamFile,
    channels: Channels,
    load: LoadModel,
    words: Words,
    decimation: u16,
) -> IsolationTracker {
    let isolator = Isolator::new(
        params.motor.model(),
        params.supply.v_phase_peak() as f32,
        params.supply.f_hz as f32,
    );
    IsolationTracker::new(
        isolator.ok(),
        channels.temperature,
        load,
        words,
        u32::from(decimation),
    )
}

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

/// Streaming replay: feed rows, then [`Replay::finish`].
pub struct Replay {
    pub(crate) opts: ReplayOptions,
    pub(crate) params: ParamFile,
    pub(crate) channels: Channels,
    pub(crate) rows: u64,
    pub(crate) timeline: Vec<TimelinePoint>,
    pub(crate) next_point: f64,
    /// Commissioning was learning at the last output (its end gets a timeline point).
    pub(crate) was_learning: bool,
    pub(crate) dt_s: f64,
    pub(crate) t0: Option<f64>,
    pub(crate) isolation: IsolationTracker,
    /// The symmetrical components, sample by sample ([`sequences::SequenceFront`]; on the
    /// reading thread in `diagnose`, whose steps come with the rows: [`Replay::push_step`]).
    pub(crate) seq_front: Option<sequences::SequenceFront>,
    /// The least-squares windows with the monitor's learning and speed.
    pub(crate) book: sequences::WindowBook,
    /// The lamps: the core's monitor and what the report keeps of its outputs.
    pub(crate) lamps: LampStage,
}

impl Replay {
    /// Prepares a replay of a log with the given channels and sample rate.
    ///
    /// # Errors
    /// [`ReplayError::Config`] when the core rejects the configuration (e.g. a sample rate
    /// below 8x the supply frequency); [`ReplayError::Option`] for options
    /// [`ReplayOptions::validate`] refuses.
    pub fn new(
        params: &ParamFile,
        channels: Channels,
        sample_rate_hz: f64,
        opts: ReplayOptions,
    ) -> Result<Self, ReplayError> {
        opts.validate()?;
        let cfg = monitor_config_for_log(params, sample_rate_hz, &opts);
        let config_error = |source| ReplayError::Config {
            source,
            sample_rate_hz,
        };
        let residuals = channels.voltages && (channels.speed || channels.encoder);
        Ok(Replay {
            lamps: LampStage::new(&cfg, opts.commission, opts.words, residuals)
                .map_err(config_error)?,
            opts,
            params: *params,
            channels,
            rows: 0,
            timeline: Vec::new(),
            next_point: 0.0,
            was_learning: false,
            dt_s: 1.0 / sample_rate_hz,
            t0: None,
            isolation: isolation_tracker(params, channels, opts.load, opts.words, cfg.decimation),
            seq_front: Some(
                sequences::SequenceFront::new(
                    params,
                    channels.voltages,
                    sample_rate_hz,
                    f64::from(cfg.limits.i_max),
                    f64::from(cfg.limits.v_max),
                )
                .map_err(config_error)?,
            ),
            book: sequences::WindowBook::new(),
        })
    }

    /// Feeds one row; returns the monitor's output (default output for current-only logs).
    pub fn push(&mut self, row: &Row) -> MonitorOutput {
        let t = row.t_s - *self.t0.get_or_insert(row.t_s);
        if let Some(front) = self.seq_front.as_mut() {
            let step = front.track(row, t);
            self.book.take(front);
            self.push_step(row, &step);
        }
        self.lamps.output()
    }

    /// [`Replay::push`] with the sequence analysis' step for the row already taken (by a
    /// [`sequences::SequenceFront`] of its own on another thread, whose closed windows were
    /// queued first: [`Replay::queue_window`]).
    pub(crate) fn push_step(&mut self, row: &Row, step: &sequences::SequenceStep) {
        self.rows += 1;
        let t0 = *self.t0.get_or_insert(row.t_s);
        let t = row.t_s - t0;
        let wr = self
            .lamps
            .monitor
            .as_ref()
            .map(|_| self.lamps.last.wr_rad_s);
        self.book.row(step, self.lamps.last.learning, wr);
        let Some(fresh) = self.lamps.update(row, t) else {
            return;
        };
        let Some(mon) = self.lamps.monitor.as_ref() else {
            return;
        };
        // (The output is read where the monitor keeps it: no copy per row.)
        let out = mon.output();
        let BlockView {
            flags,
            judging,
            lamps_lit,
            ..
        } = self.lamps.view;
        let point = step.point(out.operating.wr_rad_s);
        let settled = self.lamps.restart.settled(t, out);
        let usable = flags.with_counts(flags.counts() && settled);
        let (dt_s, tc) = (self.dt_s, row.t_winding_c);
        self.isolation.after(t, dt_s, usable, &point, tc);
        // The sample nearest each timeline step (half a sample early counts: the data-quality
        // stage's sample clock may put the sample at the step a hair before it).
        // The moment commissioning has learned gets a point of its own ("commissioning
        // 100 %"): between two steps it would otherwise jump from a part done to healthy.
        let learning = matches!(out.commissioning, CommissioningState::Learning(_));
        if self.was_learning && matches!(out.commissioning, CommissioningState::Commissioned) {
            let mut done = timeline_point(self, t, out, None);
            done.panel.state = MonitorState::Commissioning(1.0);
            done.commissioning = true;
            self.timeline.push(done);
        }
        self.was_learning = learning;
        let (dt_s, step_s) = (self.dt_s, self.opts.timeline_step.seconds());
        if timeline_step_due(&mut self.next_point, t, dt_s, step_s) {
            let point = timeline_point(self, t, out, self.lamps.view.range_note.clone());
            self.timeline.push(point);
        }
        // The running the lamps were judged on ([`MIN_JUDGED_S`]).
        if judging {
            self.lamps.judged_s += self.dt_s;
        }
        self.lamps.lamps_since_moved = lamps_since_moved(
            (self.lamps.lamps_since_moved, lamps_lit),
            out,
            &self.lamps.commission,
            &self.isolation,
        );
        if fresh {
            self.lamps.last = LastOutput::of(out, flags);
        }
    }

    /// Queues a window the sequence analysis closed on another thread, before the step of
    /// the row it closed at ([`Replay::push_step`]).
    pub(crate) fn queue_window(&mut self, w: Option<SequenceWindow>) {
        self.book.queue(w);
    }

    /// Takes over the sequence analysis that ran on another thread, once every row was
    /// pushed: its last window is the replay's to close ([`Replay::finish`]).
    pub(crate) fn set_sequence_front(&mut self, front: sequences::SequenceFront) {
        self.seq_front = Some(front);
    }

    /// Lends the sequence analysis to the thread that reads the log, which runs it beside
    /// this replay and gives it back at the end ([`Replay::set_sequence_front`]): the one
    /// front built with the replay, on the replay's configuration.
    pub(crate) fn lend_sequence_front(&mut self) -> Option<sequences::SequenceFront> {
        self.seq_front.take()
    }

    /// The learned calibration (mean and spread of r1..r4), once commissioning is done.
    pub fn calibration(&self) -> Option<monitor_core::Calibration> {
        self.lamps.monitor.as_ref().and_then(|m| m.calibration())
    }

    /// The threshold bands of r1..r4 in force, (centre, half-width)
    /// ([`Monitor::threshold_bands`]); `None` for a current-only log.
    pub fn threshold_bands(&self) -> Option<[(f32, f32); 4]> {
        self.lamps.monitor.as_ref().map(Monitor::threshold_bands)
    }

    /// Time of `row` since the replay's first row [s] (the timeline's time).
    pub fn time_of(&self, row: &Row) -> f64 {
        row.t_s - self.t0.unwrap_or(row.t_s)
    }

    /// What the isolation concludes now, as [`Replay::finish`] would report it (the report
    /// and the candidates listed), for a screen that follows the replay.
    pub fn isolation_now(&self) -> (IsolationReport, Vec<FaultCandidate>) {
        let detected = self.lamps.detected(&self.isolation, self.opts.load);
        self.isolation.report(detected)
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
    pub fn operating_point_moved(&self, out: &MonitorOutput) -> Option<String> {
        self.lamps.commission.moved_note(out)
    }

    /// The core monitor (`None` for a current-only log).
    pub fn monitor(&self) -> Option<&Monitor> {
        self.lamps.monitor.as_ref()
    }

    /// The core monitor, to start a commissioning run by hand (the live HMI's key); `None`
    /// for a current-only log.
    pub fn monitor_mut(&mut self) -> Option<&mut Monitor> {
        self.lamps.monitor.as_mut()
    }

    /// True when a commissioning window was asked for and not learned.
    pub fn commissioning_incomplete(&self) -> bool {
        self.lamps.monitor.is_some() && self.lamps.commission.incomplete()
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
        self.state_given(out, MonitorState::of(out), None)
    }

    /// [`Replay::state`] from the output's own state `state` ([`MonitorState::of`]) and,
    /// when the caller has it, the isolation's report now (else asked for only where the
    /// operating point has moved).
    fn state_given(
        &self,
        out: &MonitorOutput,
        state: MonitorState,
        isolation: Option<&IsolationReport>,
    ) -> MonitorState {
        let evaluated = matches!(state, MonitorState::Healthy | MonitorState::Fault(_));
        if !evaluated || out.sensor_fault.any() {
            return state;
        }
        let note = match self.operating_point_moved(out) {
            Some(note) => note,
            // With the load an unknown input, lamps lit for a load that moved inside the
            // commissioned range are the amber state too (`LoadModel::Unknown`).
            None if matches!(state, MonitorState::Fault(_))
                && self.isolation.load_explains_lamps() =>
            {
                LOAD_MOVED_NOTE.to_string()
            }
            // Lamps that lit while the load had moved are still releasing (they go out
            // after a second inside their bands): amber until they do, unless the isolation
            // names a fault meanwhile.
            None if matches!(state, MonitorState::Fault(_)) && self.lamps.lamps_since_moved => {
                LOAD_BACK_NOTE.to_string()
            }
            None => return state,
        };
        let named = match isolation {
            Some(r) => r.named,
            None => self.isolation_now().0.named,
        };
        if matches!(named, Some(isolation::IsolationName::Fault(_))) {
            state
        } else {
            MonitorState::Moved(note)
        }
    }

    /// What the panel shows at the replay's output `out`: the state ([`Replay::state`]),
    /// the FAULT lamp (off in the amber state) and, where the lamps are evaluated, the
    /// isolation's conclusion (asked for once).
    pub fn panel(&self, out: &MonitorOutput) -> Panel {
        let own = MonitorState::of(out);
        let evaluated = matches!(own, MonitorState::Healthy | MonitorState::Fault(_));
        let isolation = evaluated.then(|| self.isolation_now());
        let state = self.state_given(out, own, isolation.as_ref().map(|(r, _)| r));
        // Outside the evaluated points (a transient: the lamps hold) the isolation is
        // asked once here where the rule or the load's note needs it.
        let asked = (isolation.is_none() && (out.fault_detected || self.lamps.lamps_since_moved))
            .then(|| self.isolation_now());
        let report = isolation.as_ref().or(asked.as_ref());
        // Lamps held through the transient after a load move are the load's, not a fault,
        // unless the isolation names one.
        let held_for_load = self.lamps.lamps_since_moved
            && !matches!(
                report.and_then(|(r, _)| r.named),
                Some(isolation::IsolationName::Fault(_))
            );
        // The decision table (`monitor_core::verdict`), as the verdict and the board's
        // lamp read it: the FAULT lamp is lit for a named fault at even odds or better only.
        let moved = matches!(state, MonitorState::Moved(_)) || held_for_load;
        let call = glance(out, report, moved).decide().verdict;
        Panel {
            fault_lamp: call == Verdict::Fault && !moved,
            call,
            isolation,
            state,
        }
    }
    /// The isolation's report at the end, with the candidates the report lists (the lamps'
    /// own for a sensor's impossible reading): the moved point's sentence, one phase's
    /// sensor from the zero sequence.
    fn final_isolation(
        &self,
        out: &MonitorOutput,
        unbalance: &UnbalanceReport,
        detected: bool,
        signature_candidates: &[FaultCandidate],
    ) -> (IsolationReport, Vec<FaultCandidate>) {
        let (mut isolation, mut isolated) = self.isolation.report(detected);
        if let Some(note) = self.lamps.commission.moved_note(out) {
            note_moved_point(&mut isolation, &note);
        }
        isolation::refine_single_phase(
            &mut isolation,
            &mut isolated,
            unbalance.current_sensor_phase.as_ref(),
            unbalance.voltage_sensor_phase.as_ref(),
        );
        if out.sensor_fault.any() {
            (isolation, signature_candidates.to_vec())
        } else {
            (isolation, isolated)
        }
    }

    /// The reports of the sequence analysis' windows and record at the end: the winding's
    /// negative sequence and the rotor's sidebands.
    fn sequence_reports(&self) -> (UnbalanceReport, RotorReport) {
        let unbalance = unbalance_report(
            self.book.windows(),
            &self.params,
            self.lamps.monitor.is_some(),
            self.opts.unbalance_baseline,
            self.opts.turn_level,
            self.opts.words,
        );
        let rotor = match &self.seq_front {
            Some(front) => {
                let measured: Vec<_> = unbalance
                    .segments
                    .iter()
                    .filter_map(|g| g.measured_point())
                    .collect();
                rotor_report(front.rotor(), &self.params, &measured)
            }
            // (Lent and never given back: a read that ended before its end.)
            None => RotorReport::default(),
        };
        (unbalance, rotor)
    }

    /// Ends the replay and builds the report (`data_quality` left at its default for the
    /// caller to fill).
    pub fn finish(mut self) -> DiagnoseReport {
        self.isolation.flush();
        let out = self.lamps.output();
        self.close_sequences(&out);
        let skipped = skipped_analyses(self.channels);
        let (unbalance, rotor) = self.sequence_reports();
        let signature_candidates = signature_candidates(&out);
        let detected = self.lamps.detected(&self.isolation, self.opts.load);
        let (isolation, candidates) =
            self.final_isolation(&out, &unbalance, detected, &signature_candidates);
        let lamps = final_lamps(&out);
        let judged = findings::Stages {
            lamps: &self.lamps,
            isolation: &self.isolation,
            opts: &self.opts,
        };
        let found = judged.findings(
            &findings::ResidualInputs {
                out: &out,
                isolation: &isolation,
                candidates: &candidates,
                detected,
                skipped: &skipped,
            },
            &unbalance,
            &rotor,
        );
        let mut report = DiagnoseReport {
            verdict: Verdict::CouldNotJudge,
            verdict_line: String::new(),
            verdict_rule: Rule::NothingJudged,
            verdict_finding: None,
            findings: found,
            judged: Vec::new(),
            not_judged: Vec::new(),
            verdict_withheld_because: Vec::new(),
            lamps,
            candidates,
            isolation,
            signature_candidates,
            first_detection_s: self.lamps.first_detection,
            unbalance,
            rotor,
            detections: self.lamps.detections,
            skipped,
            angle_source: self.opts.angle_source,
            commission: self.opts.commission,
            commissioning: self.lamps.commission.report(self.lamps.k_sigma),
            data_quality: DataQuality::default(),
            rows: self.rows,
            max_abs_residual: self.lamps.max_abs,
            timeline: self.timeline,
        };
        report.conclude();
        report
    }

    /// Closes the sequence analysis' last window (the front's, then the book's, with the
    /// monitor's speed in `out`).
    fn close_sequences(&mut self, out: &MonitorOutput) {
        let Some(front) = self.seq_front.as_mut() else {
            return;
        };
        if front.finish() {
            self.book.take(front);
            self.book
                .close(self.lamps.monitor.as_ref().map(|_| out.operating.wr_rad_s));
        }
    }
}

/// The timeline point of an output at `t` of `replay`, with what the panel shows
/// ([`Replay::panel`]).
pub(super) fn timeline_point(
    replay: &Replay,
    t: f64,
    out: &MonitorOutput,
    range_note: Option<String>,
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
        panel: replay.panel(out),
    }
}
