//! The end of the read ([`QualityStage::finish`]): the rows still held settled, the
//! report's last figures, and the verdict on a channel that leaves nothing to analyse.

use super::{CleanSink, ClippedChannel, DataQuality, QualityStage, UNUSABLE_FRACTION};
use crate::log::{Column, LogError};

impl<S: CleanSink> QualityStage<'_, S> {
    /// The error for a log none of whose rows can be analysed because of one channel (at
    /// least [`UNUSABLE_FRACTION`] of the rows have a bad cell): names the channel with the
    /// most bad cells and what they are (not finite: "channel ia_A holds no finite value";
    /// beyond the limits: a unit the parameter file's `[columns]` does not give).
    fn channel_without_values(&self) -> Option<LogError> {
        let rows = self.q.rows_passed;
        if rows == 0 || (self.q.bad_rows as f64) < UNUSABLE_FRACTION * rows as f64 {
            return None;
        }
        // The channel with the most cells missing or out of range; a log made unusable by
        // other bad cells (stuck channels...) is left to the command's own judgement.
        let (c, [non_finite, beyond]) = Column::ALL
            .into_iter()
            .map(|c| (c, self.cells_out[c as usize]))
            .max_by_key(|(_, n)| n[0] + n[1])?;
        let why = if non_finite == rows {
            "holds no finite value (every cell is empty, NA, null, NaN or inf)".to_string()
        } else if 2 * (non_finite + beyond) < rows {
            return None;
        } else if non_finite >= beyond {
            format!("has {non_finite} of its {rows} cells empty, NA, null, NaN or inf: nothing is left to analyse")
        } else {
            let (limit, unit, other) = match c {
                Column::Va | Column::Vb | Column::Vc => (self.limits.v_max, "V", "mV"),
                Column::Ia | Column::Ib | Column::Ic => (self.limits.i_max, "A", "mA"),
                _ => (self.limits.wm_max, "rad/s", "rpm"),
            };
            format!(
                "has {beyond} of its {rows} values beyond +/-{limit:.0} {unit} (twice this motor's sensor range): if it is recorded in another unit, give it in the parameter file's [columns] table, e.g. {} = {{ name = \"...\", unit = \"{other}\" }} (docs/design.md)",
                c.name()
            )
        };
        Some(LogError::NoValue {
            path: self.shown.clone(),
            channel: c.name().to_string(),
            why,
        })
    }

    /// Ends the read (settles the rows still held) and returns the report.
    ///
    /// # Errors
    /// [`LogError::Empty`] for a log without rows; the time-base errors of the first rows
    /// ([`LogError::NoTimeBase`], [`LogError::RateTooLow`]); [`LogError::NoValue`] when
    /// a channel leaves nothing to analyse (all missing or not finite: "channel ia_A holds
    /// no finite value"; beyond the limits: its unit is not the schema's).
    pub fn finish(mut self) -> Result<DataQuality, LogError> {
        if let Some(e) = self.error.take() {
            return Err(e);
        }
        if self.base.is_none() && !self.stopped {
            if self.head.is_empty() {
                return Err(LogError::Empty { path: self.shown });
            }
            self.start();
            if let Some(e) = self.error.take() {
                return Err(e);
            }
        }
        if let Some(p) = self.pending.take() {
            if !self.stopped {
                self.settle(p);
            }
        }
        self.end_burst();
        if let Some(e) = self.channel_without_values() {
            return Err(e);
        }
        if let Some(b) = self.base {
            self.q.duration_s = (self.last_t - b.t0_s).max(0.0);
        }
        let (clips, crossings, speed, wiring) = self.signals.done();
        self.q.current_frequency_hz = crossings.median_period().map(|p| 1.0 / p);
        // Running: the currents alternate (at whatever frequency a drive gives them); the
        // synchronous speed scales with that frequency.
        let f_cur = self.q.current_frequency_hz.filter(|f| *f > 1.0);
        let scale = f_cur.map_or(1.0, |f| f / self.limits.supply_hz);
        self.q.speed_unit = speed.finding(f_cur.is_some(), scale, self.limits.pole_pairs);
        self.q.timestamp_jitter_rms_s = (self.jitter.0 / self.jitter.1.max(1) as f64).sqrt();
        self.q.wiring = wiring.findings(&super::wiring::WiringContext {
            omega_dt: f_cur.map(|f| std::f64::consts::TAU * f / self.q.sample_rate_hz.max(1.0)),
            sync_rad_s: self.limits.sync_rad_s,
        });
        self.q.encoder_wraps = self.encoder.wraps;
        self.q.encoder_resets = self.encoder.resets;
        self.q.clipped = clips
            .clipped()
            .into_iter()
            .map(|(column, share, value)| ClippedChannel {
                column,
                share,
                value,
            })
            .collect();
        self.q.assess(self.limits.supply_hz);
        Ok(self.q)
    }
}
