//! No fault hides behind the quasi-steady gate: the stretch at the end of a log where the
//! gate held the lamps while the residuals sat far outside their bands.
//!
//! The core holds the lamps while the operating point changes (`steady_gate_per_s`) and
//! evaluates them regardless once the gate has been closed for `gate_timeout_s` (an
//! operating point that never settles is itself abnormal: a frame detuned by a speed-sensor
//! fault keeps the d-q quantities moving). A log that ends inside that time has residuals
//! nobody judged; when they sit at many times their bands, "healthy" would hide a fault,
//! so `diagnose` says it could not judge instead ([`Unsettled::withheld`]).

use crate::stage::RowFlags;
use monitor_core::MonitorOutput;

/// How far outside its band a residual must sit, in half-widths, for a held stretch to
/// withhold the verdict: 3 (a band is the learned mean +- k sigma, so 3 bands are far
/// beyond the healthy spread).
pub const WORST_BANDS: f32 = 3.0;

/// Shortest held stretch at the log's end that withholds the verdict [s]: 1 s (longer than
/// the gate's hold after a supply or load step settles, 0.5 s by default).
pub const MIN_HELD_S: f64 = 1.0;

/// The held stretch being followed.
#[derive(Debug, Clone, Copy, Default)]
pub(super) struct Unsettled {
    /// Start of the present held stretch [s] (`None`: the gate is open, or nothing judged
    /// yet).
    since_s: Option<f64>,
    /// The last time seen [s].
    last_s: f64,
    /// The largest `|r - centre| / half_width` over the stretch.
    worst: f32,
}

impl Unsettled {
    /// After each sample at time `t`: `bands` are the residuals' bands in force (centre,
    /// half-width), `judged_before` whether the lamps were ever evaluated, `trusted`
    /// whether the thresholds in force count, `flags` the output's flags.
    #[inline]
    pub(super) fn after(
        &mut self,
        t: f64,
        (out, flags): (&MonitorOutput, RowFlags),
        bands: [(f32, f32); 4],
        judged_before: bool,
        trusted: bool,
    ) {
        self.last_s = t;
        let held = !flags.quasi_steady() && judged_before && trusted && !flags.learning();
        if !held || flags.sensor_fault() {
            self.since_s = None;
            self.worst = 0.0;
            return;
        }
        self.since_s.get_or_insert(t);
        for (r, (c, h)) in out.residuals.iter().zip(bands) {
            if h > 0.0 && r.is_finite() {
                self.worst = self.worst.max((r - c).abs() / h);
            }
        }
    }

    /// A sample at `t` [s] with the output as at the last [`Unsettled::after`] (only the
    /// time moves on).
    #[inline]
    pub(super) fn tick(&mut self, t: f64) {
        self.last_s = t;
    }

    /// Why no verdict can be given when the log ended inside a held stretch of at least
    /// [`MIN_HELD_S`] with a residual at [`WORST_BANDS`] or more of its band; `None`
    /// otherwise.
    pub(super) fn withheld(&self) -> Option<HeldUnsettled> {
        let since = self.since_s?;
        let held = self.last_s - since;
        (held >= MIN_HELD_S && self.worst >= WORST_BANDS).then_some(HeldUnsettled {
            held_s: held,
            since_s: since,
            worst_bands: self.worst,
        })
    }
}

/// The log ended inside a held, unsettled stretch (the quasi-steady gate held the lamps)
/// while a residual sat far outside its band: a fault cannot be ruled out (JSON
/// `{"held_s", "since_s", "worst_bands"}`).
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct HeldUnsettled {
    /// How long the stretch lasted to the log's end [s].
    pub held_s: f64,
    /// From when [s].
    pub since_s: f64,
    /// The worst residual, in its bands.
    pub worst_bands: f32,
}
