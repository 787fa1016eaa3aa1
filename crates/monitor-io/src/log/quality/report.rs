//! What the data-quality stage found and did ([`DataQuality`], JSON key `data_quality`),
//! and the judgement of trust from the counts.

use super::{
    TimeUnit, JITTER_WARN, MAX_BAD_FRACTION, MAX_BRIDGED_GAP_S, MAX_DROPPED_FRACTION,
    MAX_DROP_RUNS, SUPPLY_MISMATCH,
};
use serde::Serialize;
use std::collections::BTreeMap;

/// A change of sample rate found in the log.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct RateChange {
    /// Where [s since the first row].
    pub at_s: f64,
    /// The new rate [Hz].
    pub rate_hz: f64,
}

/// A stretch of the log the command could not judge (JSON `data_quality.not_judged`).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct NotJudged {
    /// From [s of the command's time: since the first row, clock resets bridged].
    pub from_s: f64,
    /// To [s].
    pub to_s: f64,
    /// Why not.
    pub why: String,
}

/// What the data-quality stage found and what was done (JSON key `data_quality`). Times
/// are seconds since the log's first row.
#[derive(Debug, Clone, Default, PartialEq, Serialize)]
pub struct DataQuality {
    /// Rows in the log.
    pub rows_read: u64,
    /// Rows passed on (not dropped for their time).
    pub rows_passed: u64,
    /// Unit the `t_s` column was read in.
    pub time_unit: TimeUnit,
    /// Nominal sample rate [Hz] (median interval of the first rows).
    pub sample_rate_hz: f64,
    /// From the first row to the last [s].
    pub duration_s: f64,
    /// Samples missing in short gaps (bridged).
    pub dropped_samples: u64,
    /// Short gaps (one or more samples missing, at most [`MAX_BRIDGED_GAP_S`]) bridged.
    pub gaps_bridged: u64,
    /// Longest bridged gap [s].
    pub longest_bridged_gap_s: f64,
    /// Gaps longer than [`MAX_BRIDGED_GAP_S`] (each starts a segment).
    pub long_gaps: u64,
    /// The first long gaps, `[from, to]` [s].
    pub long_gap_spans: Vec<[f64; 2]>,
    /// Segments of regular time base.
    pub segments: u64,
    /// Changes of sample rate.
    pub rate_changes: Vec<RateChange>,
    /// Clock resets (time went back for good).
    pub clock_resets: u64,
    /// Rows dropped because their time repeats or goes back.
    pub repeated_or_backward_rows: u64,
    /// Rows dropped because their time is not a number.
    pub non_finite_times: u64,
    /// Single timestamps off the grid, corrected.
    pub timestamp_glitches: u64,
    /// Intervals that are no whole number of periods (kept with their real time).
    pub irregular_intervals: u64,
    /// RMS distance of the timestamps from the smoothed sample clock [s].
    pub timestamp_jitter_rms_s: f64,
    /// Bad cells per column (not finite or beyond the limits).
    pub bad_cells: BTreeMap<String, u64>,
    /// Rows with at least one bad cell.
    pub bad_rows: u64,
    /// Cells of stuck or dead phase channels per column ([`super::stuck`]; counted in
    /// `bad_cells` too).
    pub stuck_cells: BTreeMap<String, u64>,
    /// The channels' wiring faults ([`super::wiring`]: duplicated, reversed or exchanged
    /// channels, a phase order against the shaft), each with the `[columns]` mapping that
    /// fixes it (JSON: each with its `fix` and `sentence`).
    #[serde(serialize_with = "super::wiring::serialize_all")]
    pub wiring: Vec<super::wiring::WiringFault>,
    /// Wraps of the encoder counter (16, 24, 32 or 64 bits) undone
    /// ([`super::encoder`]).
    pub encoder_wraps: u64,
    /// Re-zeroed encoder counters followed ([`super::encoder`]).
    pub encoder_resets: u64,
    /// Runs of consecutive rows with bad cells.
    pub glitch_bursts: u64,
    /// Longest such run [s].
    pub longest_burst_s: f64,
    /// Rows in bursts up to [`MAX_BRIDGED_GAP_S`] long (glitches; a longer burst is a
    /// sensor that failed, a finding of its own).
    pub rows_in_short_bursts: u64,
    /// Stretches of consecutive rows dropped for their time (a stalled clock is one).
    pub time_drop_runs: u64,
    /// Blank lines of a CSV, skipped (JSON: present when not zero).
    #[serde(skip_serializing_if = "is_zero")]
    pub blank_lines: u64,
    /// Frequency of the phase-a current (median zero-crossing period) [Hz], if it
    /// alternates.
    pub current_frequency_hz: Option<f64>,
    /// The speed channel is no running motor's: the likely unit (`super::speed_unit`);
    /// null when it is plausible or absent. Not trusted.
    pub speed_unit: Option<String>,
    /// What the command did about what was found.
    pub actions: Vec<String>,
    /// Stretches the command could not judge (a verdict of "healthy" is withheld when
    /// they exceed [`super::MAX_NOT_JUDGED_FRACTION`] of the log).
    pub not_judged: Vec<NotJudged>,
    /// What the user should know (also printed on stderr).
    pub warnings: Vec<String>,
    /// Voltage and current channels that clip ([`crate::log::clipping`]): not trusted.
    pub clipped: Vec<ClippedChannel>,
    /// False when the command's verdict would rest on data the stage rejected.
    pub trusted: bool,
    /// Why not trusted.
    pub not_trusted_because: Vec<String>,
    /// Trusted, or not trusted only because the currents alternate at another frequency
    /// than the file's supply: the monitor's residuals run at the file's frequency and its
    /// verdict is withheld, but an analysis that models the log's own voltages (explain, the
    /// ladder) goes on (a V/f drive below base speed). Not in the JSON (`trusted` is).
    #[serde(skip)]
    pub trusted_but_for_the_supply: bool,
}

fn is_zero(n: &u64) -> bool {
    *n == 0
}

/// What the assessment found: warnings, and reasons not to trust the log.
#[derive(Debug, Default)]
struct QualityFindings {
    warn: Vec<String>,
    distrust: Vec<String>,
    /// Whether one of `distrust` is the supply's frequency against the file's.
    supply_differs: bool,
}

/// A channel whose readings clip ([`crate::log::clipping`]).
#[derive(Debug, Clone, Serialize, PartialEq)]
pub struct ClippedChannel {
    /// Column name (`va_V` ... `ic_A`).
    pub column: String,
    /// Share of its samples at the flat top, (0, 1].
    pub share: f64,
    /// The flat top's value [V or A].
    pub value: f64,
}

impl DataQuality {
    /// Fills `warnings`, `trusted` and `not_trusted_because` from the counts.
    pub(super) fn assess(&mut self, supply_hz: f64) {
        let mut found = QualityFindings::default();
        self.assess_time(&mut found);
        self.assess_cells(supply_hz, &mut found);
        self.trusted = found.distrust.is_empty();
        self.trusted_but_for_the_supply = found.distrust.len() == usize::from(found.supply_differs);
        self.warnings = found.warn;
        self.not_trusted_because = found.distrust;
    }

    /// What the timestamps say: their unit, rows dropped, gaps, segments, jitter.
    fn assess_time(&self, found: &mut QualityFindings) {
        self.assess_dropped_time(found);
        self.assess_gaps(found);
        self.assess_clock(found);
    }

    /// The time's unit and the rows dropped for their time (repeated, backward, not a
    /// number): many scattered ones leave no stretch of the log to trust.
    fn assess_dropped_time(&self, found: &mut QualityFindings) {
        let QualityFindings { warn, distrust, .. } = found;
        let rows = self.rows_read.max(1) as f64;
        if self.time_unit != TimeUnit::S {
            warn.push(format!(
                "t_s is in {} (the currents alternate at the supply frequency only so): read as {}",
                self.time_unit.name(),
                self.time_unit.name()
            ));
        }
        let dropped_time = self.repeated_or_backward_rows + self.non_finite_times;
        if dropped_time > 0 {
            warn.push(format!(
                "{} rows dropped: time repeats or goes back ({}) or is not a number ({})",
                dropped_time, self.repeated_or_backward_rows, self.non_finite_times
            ));
        }
        // A few long stretches of unusable time are gaps (the estimators restart after
        // them); many scattered ones leave no stretch of the log to trust.
        if dropped_time as f64 / rows > MAX_BAD_FRACTION && self.time_drop_runs > MAX_DROP_RUNS {
            distrust.push(format!(
                "{:.1} % of the rows have an unusable time",
                100.0 * dropped_time as f64 / rows
            ));
        }
    }

    /// The gaps in the time: bridged ones, the share of samples missing, the segments the
    /// log falls into.
    fn assess_gaps(&self, found: &mut QualityFindings) {
        let QualityFindings { warn, distrust, .. } = found;
        if self.gaps_bridged > 0 {
            warn.push(format!(
                "{} samples missing in {} gaps (longest {:.4} s), bridged with the real elapsed time",
                self.dropped_samples, self.gaps_bridged, self.longest_bridged_gap_s
            ));
        }
        let expected = self.rows_passed as f64 + self.dropped_samples as f64;
        if self.dropped_samples as f64 / expected.max(1.0) > MAX_DROPPED_FRACTION {
            distrust.push(format!(
                "{:.1} % of the samples are missing",
                100.0 * self.dropped_samples as f64 / expected.max(1.0)
            ));
        }
        if self.long_gaps > 0 || self.clock_resets > 0 || !self.rate_changes.is_empty() {
            warn.push(format!(
                "the log falls into {} segments ({} gaps over {} s, {} rate changes, {} clock resets)",
                self.segments,
                self.long_gaps,
                MAX_BRIDGED_GAP_S,
                self.rate_changes.len(),
                self.clock_resets
            ));
        }
    }

    /// The sample clock: timestamps corrected onto it, their jitter, irregular intervals.
    fn assess_clock(&self, found: &mut QualityFindings) {
        let QualityFindings { warn, distrust, .. } = found;
        let rows = self.rows_read.max(1) as f64;
        if self.timestamp_glitches > 0 {
            warn.push(format!(
                "{} timestamps off the sample grid corrected",
                self.timestamp_glitches
            ));
        }
        if self.timestamp_jitter_rms_s * self.sample_rate_hz > JITTER_WARN {
            warn.push(format!(
                "the timestamps jitter by {:.1} us RMS ({:.0} % of a period): smoothed onto the sample clock",
                1e6 * self.timestamp_jitter_rms_s,
                100.0 * self.timestamp_jitter_rms_s * self.sample_rate_hz
            ));
        }
        if self.irregular_intervals > 0 {
            warn.push(format!(
                "{} intervals are no whole number of sample periods",
                self.irregular_intervals
            ));
        }
        if self.irregular_intervals as f64 / rows > MAX_BAD_FRACTION {
            distrust.push(format!(
                "the timestamps are irregular on {:.1} % of the intervals",
                100.0 * self.irregular_intervals as f64 / rows
            ));
        }
    }

    /// What the cells say: bad cells and their bursts, the currents' frequency, clipping.
    fn assess_cells(&self, supply_hz: f64, found: &mut QualityFindings) {
        self.assess_bad_cells(found);
        self.assess_channels(found);
        self.assess_signals(supply_hz, found);
    }

    /// Blank lines skipped and rows held out for bad cells.
    fn assess_bad_cells(&self, found: &mut QualityFindings) {
        let warn = &mut found.warn;
        if self.blank_lines > 0 {
            warn.push(format!("{} blank lines skipped", self.blank_lines));
        }
        if self.bad_rows > 0 {
            let cells: Vec<String> = self
                .bad_cells
                .iter()
                .map(|(c, n)| format!("{c} {n}"))
                .collect();
            warn.push(format!(
                "{} rows with cells not finite or out of range ({}) in {} bursts (longest {:.4} s), held out",
                self.bad_rows,
                cells.join(", "),
                self.glitch_bursts,
                self.longest_burst_s
            ));
        }
    }

    /// The channels: wiring faults, stuck channels, bad cells in short glitches all through
    /// the log.
    fn assess_channels(&self, found: &mut QualityFindings) {
        let QualityFindings { warn, distrust, .. } = found;
        let rows = self.rows_read.max(1) as f64;
        for w in &self.wiring {
            distrust.push(w.sentence());
        }
        for (c, n) in &self.stuck_cells {
            let share = *n as f64 / rows;
            let what = format!(
                "{c} is stuck on {:.1} % of the rows (identical readings for over {} of a supply period while the other channels alternate: a frozen sensor, a held DAQ channel, a dead input)",
                100.0 * share,
                super::stuck::STUCK_PERIODS
            );
            if share > MAX_BAD_FRACTION {
                distrust.push(what);
            } else {
                warn.push(what);
            }
        }
        if self.rows_in_short_bursts as f64 / rows > MAX_BAD_FRACTION {
            distrust.push(format!(
                "{:.1} % of the rows have bad cells, in short glitches all through the log",
                100.0 * self.rows_in_short_bursts as f64 / rows
            ));
        }
    }

    /// The signals: the currents' frequency against the supply's [Hz], the speed's unit,
    /// clipping channels.
    fn assess_signals(&self, supply_hz: f64, found: &mut QualityFindings) {
        let QualityFindings {
            distrust,
            supply_differs,
            ..
        } = found;
        if let Some(f) = self.current_frequency_hz {
            if (f / supply_hz - 1.0).abs() > SUPPLY_MISMATCH {
                *supply_differs = true;
                // The monitor's model runs at the file's frequency: judged against another,
                // every residual moves as a fault's would (a 60 Hz file on a 50 Hz log read
                // rr +44 %). Not trusted, the verdict withheld.
                distrust.push(format!(
                    "the currents alternate at {f:.1} Hz but the parameter file's supply is {supply_hz} Hz: set f_hz to the log's (a V/f drive below base speed shows this too)"
                ));
            }
        }
        if let Some(s) = &self.speed_unit {
            distrust.push(s.clone());
        }
        for c in &self.clipped {
            distrust.push(format!(
                "{} clips: {:.1} % of its samples sit at {} (a sensor or ADC past its full scale: the readings' amplitude, and every size and residual from it, is not the signal's)",
                c.column,
                100.0 * c.share,
                c.value
            ));
        }
    }

    /// One line for the text output: "clean" or what was found.
    pub fn summary(&self) -> String {
        if self.warnings.is_empty() && !self.not_trusted_because.is_empty() {
            return format!(
                "{} rows at {:.0} Hz, time in {}: not trusted (below)",
                self.rows_read,
                self.sample_rate_hz,
                self.time_unit.name()
            );
        }
        if self.warnings.is_empty() {
            return format!(
                "clean ({} rows at {:.0} Hz, time in {})",
                self.rows_read,
                self.sample_rate_hz,
                self.time_unit.name()
            );
        }
        format!(
            "{} rows at {:.0} Hz: {}",
            self.rows_read,
            self.sample_rate_hz,
            self.warnings.join("; ")
        )
    }
}
