//! The lamps' stage of a replay ([`LampStage`]): the core's monitor fed row by row (exactly the
//! code the firmware runs), commissioning around it, and what the report keeps of its
//! outputs: the residuals' extremes, the detections, the running judged, the stretch the
//! quasi-steady gate held, the encoder count carried over a clock reset.
//!
//! Between two of the monitor's revisions ([`Monitor::revision`]) only its speed moves:
//! what depends on the rest of the output is done once per revision ([`LampStage::revise`]).

use crate::commission::CommissionTracker;
use crate::isolation::chunk::RowFlags;
use crate::isolation::IsolationTracker;
use crate::options::LoadModel;
use crate::sampler::{sample_of, LogSampler, CLOCK_RESET_GAP_S, COUNTS_PER_REV};
use crate::step::{
    bands_for, bands_needed, book_detection, note_residuals, BlockView, Detection, LastOutput,
    RestartHold, NO_BANDS,
};
use crate::unsettled;
use crate::words::Words;
use monitor_core::{ConfigError, Monitor, MonitorConfig, MonitorOutput};
use monitor_io::log::Row;

/// The lamps' stage: the core's monitor (`None` for a log that cannot feed the residuals:
/// no voltages or no speed) and its bookkeeping.
pub(crate) struct LampStage {
    pub(crate) monitor: Option<Monitor>,
    pub(crate) sampler: LogSampler,
    pub(crate) commission: CommissionTracker,
    pub(crate) k_sigma: f32,
    pub(crate) evaluated: bool,
    /// Seconds of running on which the lamps were judged: evaluated, quasi-steady, on
    /// thresholds in force ([`MIN_JUDGED_S`] for a healthy verdict).
    pub(crate) judged_s: f64,
    /// A detection happened inside the commissioned operating range (or without one).
    pub(crate) detected_in_range: bool,
    pub(crate) first_detection: Option<f64>,
    pub(crate) detections: Vec<Detection>,
    /// The fault probabilities whose first fault is in `detections` already (NaN: none
    /// yet; [`step::note_detection`]).
    pub(crate) top_seen: [f32; monitor_core::FAULT_COUNT],
    pub(crate) max_abs: [f32; 4],
    /// What the next row needs of the monitor's output after the last row (a copy of the
    /// whole output per row is what it saves).
    pub(crate) last: LastOutput,
    /// What the rows up to the monitor's next revision take from its output
    /// ([`LampStage::block_row`]).
    pub(crate) view: BlockView,
    /// The lamps lit now first lit while the operating point had moved (or the load
    /// explained them), and have not all been dark since: their release after the load came
    /// back is still the amber state.
    pub(crate) lamps_since_moved: bool,
    /// The isolation's wait after a restart of the monitor's estimators.
    pub(crate) restart: RestartHold,
    /// The stretch where the quasi-steady gate held the lamps, at the log's end.
    pub(crate) unsettled: unsettled::Unsettled,
    /// Added to every row's encoder count after a clock reset: the turn over the bridged
    /// time ([`LampStage::clock_reset`]).
    pub(crate) enc_offset: i64,
}

impl LampStage {
    /// The stage for a monitor configured by `cfg` (`residuals`: the log can feed them),
    /// commissioning in `commission` [s] where asked for (its advice in `words`).
    ///
    /// # Errors
    /// The core's check of `cfg` ([`MonitorConfig::validate`]).
    pub(crate) fn new(
        cfg: &MonitorConfig,
        commission: Option<(f64, f64)>,
        words: Words,
        residuals: bool,
    ) -> Result<Self, ConfigError> {
        let monitor = if residuals {
            Some(Monitor::new(*cfg)?)
        } else {
            cfg.validate()?;
            None
        };
        Ok(LampStage {
            monitor,
            sampler: LogSampler::default(),
            commission: CommissionTracker::new(commission, words, cfg),
            k_sigma: cfg.thresholds.k_sigma,
            evaluated: false,
            judged_s: 0.0,
            detected_in_range: false,
            first_detection: None,
            detections: Vec::new(),
            top_seen: [f32::NAN; monitor_core::FAULT_COUNT],
            max_abs: [0.0; 4],
            last: LastOutput::default(),
            view: BlockView::default(),
            lamps_since_moved: false,
            restart: RestartHold::new(f64::from(cfg.settle_s)),
            unsettled: unsettled::Unsettled::default(),
            enc_offset: 0,
        })
    }

    /// Feeds `row` at `t` [s] to the monitor (commissioning's start or end first): whether
    /// the output is a fresh revision ([`LampStage::revise`]); `None` without a monitor.
    pub(crate) fn update(&mut self, row: &Row, t: f64) -> Option<bool> {
        let mon = self.monitor.as_mut()?;
        self.commission.before(mon, t);
        mon.update(&sample_of(&mut self.sampler, self.enc_offset, row));
        Some(self.revise(t))
    }

    /// The monitor's last output (the default for a current-only log).
    pub(crate) fn output(&self) -> MonitorOutput {
        self.monitor
            .as_ref()
            .map_or_else(MonitorOutput::default, |m| *m.output())
    }

    /// Between two of the monitor's revisions ([`Monitor::revision`]) only its speed moves:
    /// what depends on the rest of the output is done on the revision's first row, in
    /// [`LampStage::block_row`] (whether this row at `t` [s] is one: the answer), every row
    /// does what depends on its time or its own values ([`Replay::push_step`]).
    pub(crate) fn revise(&mut self, t: f64) -> bool {
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
    pub(crate) fn block_row(
        &mut self,
        t: f64,
        out: &MonitorOutput,
        bands: [(f32, f32); 4],
        (revision, range_note): (u32, Option<String>),
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

    /// Whether a fault was detected: a lamp lit or the isolation named a fault, unless the
    /// isolation ends finding that the windings' heating explains it
    /// (`monitor_core::isolation`, "Heating is not a fault"), or, with the load an unknown
    /// input, that the load moved ([`LoadModel::Unknown`]: the lamps' torque residuals see a
    /// load change as the paper's Bl fault).
    pub(crate) fn detected(&self, isolation: &IsolationTracker, load: LoadModel) -> bool {
        // With the load unknown, lamps whose matching only ever named the friction class
        // (B, Bl: the load term) read a load move, not a fault.
        let only_load = load == LoadModel::Unknown
            && !self.detections.is_empty()
            && self
                .detections
                .iter()
                .all(|d| matches!(d.fault, monitor_core::Fault::B | monitor_core::Fault::Bl))
            && !self.out_sensor_fault_seen();
        let lamps =
            self.first_detection.is_some() && !isolation.load_explains_lamps() && !only_load;
        !isolation.heating_explains_lamps() && (lamps || isolation.named_a_fault())
    }

    /// A sensor fault was flagged at the end (the lamps' detections then stand).
    pub(crate) fn out_sensor_fault_seen(&self) -> bool {
        self.last.sensor_fault
    }
}
