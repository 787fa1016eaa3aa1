//! The lamps' stage of a replay ([`LampStage`]): the core's monitor fed row by row (exactly the
//! code the firmware runs), commissioning around it, and what the report keeps of its
//! outputs: the residuals' extremes, the detections, the running judged, the stretch the
//! quasi-steady gate held, the encoder count carried over a clock reset.
//!
//! Between two of the monitor's revisions ([`Monitor::revision`]) only its speed moves:
//! what depends on the rest of the output is done once per revision ([`LampStage::revise`]).
//!
//! Per row ([`Stage::update`]) it takes the row's time and hands on [`LampsRow`]: the
//! output's flags as the isolation reads them and what the monitor said after the row
//! before (the winding's windows take the learning and the speed from it). At the end
//! ([`Finish::finish`]) it gives [`LampsFinding`].

pub(crate) mod commission;
mod step;
mod unsettled;

pub use step::Detection;
pub use unsettled::HeldUnsettled;

/// Why the residuals were skipped: the column the log lacks (the report's `skipped`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "snake_case")]
pub enum SkippedAnalysis {
    /// The residuals need the voltages `va_V, vb_V, vc_V`.
    ResidualsNeedVoltages,
    /// The residuals need the speed (`wm_rad_s` or `enc_count`).
    ResidualsNeedSpeed,
}

use crate::options::{LoadModel, ReplayOptions};
use crate::sampler::{sample_of, LogSampler, CLOCK_RESET_GAP_S, COUNTS_PER_REV};
use crate::stage::{Finish, LampsSeen, RowFlags, Stage};
use commission::CommissionTracker;
use monitor_core::{AngleSource, ConfigError, Monitor, MonitorConfig, MonitorOutput};
use monitor_io::log::{Channels, Row};
pub(crate) use step::LastOutput;
use step::{
    bands_for, bands_needed, book_detection, note_residuals, BlockView, RestartHold, NO_BANDS,
};

/// The lamps' stage: the core's monitor (`None` for a log that cannot feed the residuals:
/// no voltages or no speed) and its bookkeeping.
pub(crate) struct LampStage {
    monitor: Option<Monitor>,
    sampler: LogSampler,
    commission: CommissionTracker,
    k_sigma: f32,
    /// The sample interval [s] (the running judged is counted in it).
    dt_s: f64,
    /// What is known of the load ([`LampStage::seen`]: with the load unknown, lamps that
    /// only named the load term read a load move).
    load: LoadModel,
    /// The monitor's angle source (the report's).
    angle_source: AngleSource,
    /// The analyses the log's columns cannot feed (the report's `skipped`).
    skipped: Vec<SkippedAnalysis>,
    evaluated: bool,
    /// Seconds of running on which the lamps were judged: evaluated, quasi-steady, on
    /// thresholds in force (`MIN_JUDGED_S` for a healthy verdict).
    judged_s: f64,
    /// A detection happened inside the commissioned operating range (or without one).
    detected_in_range: bool,
    first_detection: Option<f64>,
    detections: Vec<Detection>,
    /// The fault probabilities whose first fault is in `detections` already (NaN: none
    /// yet; `step::note_detection`).
    top_seen: [f32; monitor_core::FAULT_COUNT],
    max_abs: [f32; 4],
    /// What the next row needs of the monitor's output after the last row (a copy of the
    /// whole output per row is what it saves).
    last: LastOutput,
    /// What the rows up to the monitor's next revision take from its output
    /// ([`LampStage::block_row`]).
    view: BlockView,
    /// The isolation's wait after a restart of the monitor's estimators.
    restart: RestartHold,
    /// The stretch where the quasi-steady gate held the lamps, at the log's end.
    unsettled: unsettled::Unsettled,
    /// Added to every row's encoder count after a clock reset: the turn over the bridged
    /// time ([`LampStage::clock_reset`]).
    enc_offset: i64,
}

/// What the lamps hand on for one row.
#[derive(Debug, Clone, Copy, Default)]
pub(crate) struct LampsRow {
    /// What the monitor's output was after the row before (the default for a current-only
    /// log): the windows' learning and speed, and the sensor flag the isolation's report
    /// read during this row.
    pub(crate) before: LastOutput,
    /// The row fed a monitor (false for a current-only log: the stages after it that read
    /// the monitor's output skip the row).
    pub(crate) fed: bool,
    /// The output's flags with `counts` the isolation's: the lamps count and the monitor
    /// has settled after a restart of its estimators.
    pub(crate) usable: RowFlags,
    /// A lamp is lit.
    pub(crate) lamps_lit: bool,
}

/// What the lamps found over the log ([`Finish::finish`]): the monitor's last output and
/// what the report and the residual finding read.
#[derive(Debug, Clone)]
pub(crate) struct LampsFinding {
    /// The log fed a monitor (voltages and a speed).
    pub(crate) monitor: bool,
    /// The monitor's last output (the default for a current-only log).
    pub(crate) out: MonitorOutput,
    /// The lamps were evaluated at some time.
    pub(crate) evaluated: bool,
    /// Seconds of running on which the lamps were judged.
    pub(crate) judged_s: f64,
    /// A detection happened inside the commissioned operating range (or without one).
    pub(crate) detected_in_range: bool,
    /// The first detection's time [s].
    pub(crate) first_detection: Option<f64>,
    /// The faults named while a lamp was lit, each with its first time.
    pub(crate) detections: Vec<Detection>,
    /// The largest |residual| of each while evaluating.
    pub(crate) max_abs: [f32; 4],
    /// Commissioning as it ended.
    pub(crate) commission: CommissionTracker,
    /// The thresholds' spreads.
    pub(crate) k_sigma: f32,
    /// Why the log's end withholds the verdict (the quasi-steady gate held the lamps far
    /// outside their bands), where it does.
    pub(crate) withheld: Option<HeldUnsettled>,
    /// What the lamps say at the end about a fault ([`LampsSeen`]).
    pub(crate) seen: LampsSeen,
    /// With the load an unknown input, the lamps' matching only ever named the friction
    /// class (the load term).
    pub(crate) only_load_named: bool,
    /// The monitor's angle source.
    pub(crate) angle_source: AngleSource,
    /// The analyses the log's columns cannot feed, with the column they need.
    pub(crate) skipped: Vec<SkippedAnalysis>,
}

impl LampStage {
    /// The stage for a monitor configured by `cfg` from `opts` (commissioning, the load), on
    /// a log with `channels` (a monitor where they feed the
    /// residuals: voltages and a speed), rows `dt_s` apart [s].
    ///
    /// # Errors
    /// The core's check of `cfg` ([`MonitorConfig::validate`]).
    pub(crate) fn new(
        cfg: &MonitorConfig,
        opts: &ReplayOptions,
        channels: Channels,
        dt_s: f64,
    ) -> Result<Self, ConfigError> {
        let residuals = channels.voltages && (channels.speed || channels.encoder);
        let monitor = if residuals {
            Some(Monitor::new(*cfg)?)
        } else {
            cfg.validate()?;
            None
        };
        Ok(LampStage {
            monitor,
            sampler: LogSampler::default(),
            commission: CommissionTracker::new(opts.commission, cfg),
            k_sigma: cfg.thresholds.k_sigma,
            dt_s,
            load: opts.load,
            angle_source: opts.angle_source,
            skipped: skipped_analyses(channels),
            evaluated: false,
            judged_s: 0.0,
            detected_in_range: false,
            first_detection: None,
            detections: Vec::new(),
            top_seen: [f32::NAN; monitor_core::FAULT_COUNT],
            max_abs: [0.0; 4],
            last: LastOutput::default(),
            view: BlockView::default(),
            restart: RestartHold::new(f64::from(cfg.settle_s)),
            unsettled: unsettled::Unsettled::default(),
            enc_offset: 0,
        })
    }

    /// The core monitor (`None` for a current-only log).
    pub(crate) fn monitor(&self) -> Option<&Monitor> {
        self.monitor.as_ref()
    }

    /// The core monitor, to start a commissioning run by hand.
    pub(crate) fn monitor_mut(&mut self) -> Option<&mut Monitor> {
        self.monitor.as_mut()
    }

    /// Commissioning as it stands (its range, its notes).
    pub(crate) fn commission(&self) -> &CommissionTracker {
        &self.commission
    }

    /// The monitor's last output (the default for a current-only log).
    pub(crate) fn output(&self) -> MonitorOutput {
        self.monitor
            .as_ref()
            .map_or_else(MonitorOutput::default, |m| *m.output())
    }

    /// The note on the commissioned range at the monitor's last revision (the timeline's).
    pub(crate) fn range_note(&self) -> Option<&Vec<commission::RangeDeparture>> {
        self.view.range_note.as_ref()
    }

    /// What the lamps say about a fault now, `sensor_fault_seen` whether a sensor fault
    /// stood at the monitor's last revision before ([`LampsSeen`]).
    pub(crate) fn seen(&self, sensor_fault_seen: bool) -> LampsSeen {
        // With the load unknown, lamps whose matching only ever named the friction class
        // (B, Bl: the load term) read a load move, not a fault.
        let only_load = self.only_load_named() && !sensor_fault_seen;
        LampsSeen {
            detected: self.first_detection.is_some(),
            only_load,
        }
    }

    /// With the load an unknown input, the lamps' matching only ever named the friction
    /// class (the load term): a load move.
    fn only_load_named(&self) -> bool {
        self.load == LoadModel::Unknown
            && !self.detections.is_empty()
            && self
                .detections
                .iter()
                .all(|d| matches!(d.fault, monitor_core::Fault::B | monitor_core::Fault::Bl))
    }

    /// What the lamps say about a fault after the last row.
    pub(crate) fn seen_now(&self) -> LampsSeen {
        self.seen(self.last.sensor_fault)
    }

    /// Between two of the monitor's revisions ([`Monitor::revision`]) only its speed moves:
    /// what depends on the rest of the output is done on the revision's first row, in
    /// [`LampStage::block_row`] (whether this row at `t` [s] is one: the answer), every row
    /// does what depends on its time or its own values ([`LampStage::update`]).
    fn revise(&mut self, t: f64) -> bool {
        let Some(mon) = self.monitor.as_ref() else {
            return false;
        };
        let revision = mon.revision();
        if self.view.revision == Some(revision) {
            self.unsettled.tick(t);
            return false;
        }
        let out = mon.output();
        let range_note = self.commission.after(mon, t, out);
        let bands = bands_needed(mon, out);
        let out = *out;
        self.block_row(t, &out, bands, (revision, range_note));
        true
    }

    /// The part of a row that depends on the monitor's output other than its speed, done
    /// on the first row of each of its revisions ([`Monitor::revision`]; the rows after it
    /// up to the next would repeat it to the bit): the residuals' extremes, the flags, the
    /// held stretch, a counted detection, and what the rows up to the next need (`bands`: the
    /// threshold bands in force, `range_note`: the commissioned range's note now).
    fn block_row(
        &mut self,
        t: f64,
        out: &MonitorOutput,
        bands: [(f32, f32); 4],
        (revision, range_note): (u32, Option<Vec<commission::RangeDeparture>>),
    ) {
        note_residuals(&mut self.evaluated, &mut self.max_abs, out);
        // With a commissioning window asked for, lamps lit on the fixed thresholds before
        // the learned ones are in force are not detections: the window says the nominal
        // parameters are not to be trusted (a sensor fault counts at any time).
        let trusted = self.commission.thresholds_trusted(out);
        let flags = RowFlags::of(out, trusted);
        let counts = flags.counts();
        let bands = bands_for(bands, out, counts, self.detected_in_range);
        let held_bands = if out.quasi_steady { NO_BANDS } else { bands };
        let judged = self.evaluated;
        self.unsettled
            .after(t, (out, flags), held_bands, judged, trusted);
        if out.fault_detected && counts {
            let first = (&mut self.detected_in_range, &mut self.first_detection);
            let booked = (&mut self.detections, &mut self.top_seen);
            book_detection(first, booked, &self.commission, (t, out, bands));
        }
        self.view = BlockView {
            revision: Some(revision),
            flags,
            judging: out.evaluating && out.quasi_steady && trusted,
            lamps_lit: out.lamps.iter().any(|l| *l),
            range_note,
        };
    }

    /// The acquisition clock was reset before the next row (`diagnose` carries the time on
    /// by [`CLOCK_RESET_GAP_S`]): the encoder count handed on goes on by the turn
    /// over the bridged time at the monitor's speed (the count the data-quality stage hands
    /// on continues with no step).
    pub(crate) fn clock_reset(&mut self) {
        let w = self
            .monitor
            .as_ref()
            .map_or(0.0, |m| f64::from(m.output().speed_rad_s));
        let turned = w * CLOCK_RESET_GAP_S / std::f64::consts::TAU;
        self.enc_offset = self
            .enc_offset
            .wrapping_add((turned * f64::from(COUNTS_PER_REV)).round() as i64);
    }

    /// `row` with the encoder offset of the clock resets so far ([`LampStage::clock_reset`]):
    /// the row as the monitor sees it.
    pub(crate) fn with_encoder_offset(&self, row: &Row) -> Row {
        Row {
            enc_count: row.enc_count.map(|c| c.wrapping_add(self.enc_offset)),
            ..*row
        }
    }
}

impl Stage for LampStage {
    /// The row's time since the first row [s].
    type Input<'a> = f64;
    type Output = LampsRow;

    /// Feeds `row` at `t` [s] to the monitor (commissioning's start or end first); the
    /// monitor's output is then [`LampStage::monitor`]'s.
    #[inline]
    fn update(&mut self, row: &Row, t: f64) -> LampsRow {
        let before = self.last;
        let Some(mon) = self.monitor.as_mut() else {
            return LampsRow {
                before,
                ..LampsRow::default()
            };
        };
        self.commission.before(mon, t);
        mon.update(&sample_of(&mut self.sampler, self.enc_offset, row));
        let fresh = self.revise(t);
        let Some(mon) = self.monitor.as_ref() else {
            return LampsRow::default();
        };
        // (The output is read where the monitor keeps it: no copy per row.)
        let out = mon.output();
        let BlockView {
            flags,
            judging,
            lamps_lit,
            ..
        } = self.view;
        let settled = self.restart.settled(t, out);
        // The running the lamps were judged on (`MIN_JUDGED_S`).
        if judging {
            self.judged_s += self.dt_s;
        }
        if fresh {
            self.last = LastOutput::of(out, flags);
        }
        LampsRow {
            before,
            fed: true,
            usable: flags.with_counts(flags.counts() && settled),
            lamps_lit,
        }
    }
}

impl Finish for LampStage {
    type Closing<'a> = ();
    type Finding = LampsFinding;

    fn finish(self, (): ()) -> LampsFinding {
        LampsFinding {
            monitor: self.monitor.is_some(),
            out: self.output(),
            evaluated: self.evaluated,
            judged_s: self.judged_s,
            detected_in_range: self.detected_in_range,
            seen: self.seen_now(),
            only_load_named: self.only_load_named(),
            angle_source: self.angle_source,
            skipped: self.skipped,
            first_detection: self.first_detection,
            detections: self.detections,
            max_abs: self.max_abs,
            commission: self.commission,
            k_sigma: self.k_sigma,
            withheld: self.unsettled.withheld(),
        }
    }
}

/// The analyses a log with `channels` cannot feed, with the column they need (the report's
/// `skipped`).
fn skipped_analyses(channels: Channels) -> Vec<SkippedAnalysis> {
    if !channels.voltages {
        vec![SkippedAnalysis::ResidualsNeedVoltages]
    } else if !(channels.speed || channels.encoder) {
        vec![SkippedAnalysis::ResidualsNeedSpeed]
    } else {
        Vec::new()
    }
}
