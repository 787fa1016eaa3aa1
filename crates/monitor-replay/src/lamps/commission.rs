//! What `diagnose` did about its thresholds (JSON key `commissioning`): whether a
//! `--commission START:END` window was learned, over which part of the log, how many
//! seconds of it the core could evaluate, and which operating range it covered; without
//! a window, how far each residual sat from zero against the fixed thresholds.
//!
//! The core learns over *evaluated* running (`monitor_core::commissioning`: blocks with
//! the quasi-steady gate closed do not count), so a window of `END - START` seconds may
//! need a little longer in log time. The replay starts the run at `START` and lets it
//! finish up to [`grace_s`] after `END`; a run still learning then, or at the end of the
//! log, is *incomplete*: it is cancelled (the fixed thresholds stay in force) and
//! `diagnose` refuses to give a verdict unless `--allow-incomplete`.
//!
//! The learned healthy means hold only near the operating point they were learned at
//! (to the paper's model a load change is a Bl change, a voltage change moves
//! the residuals' means). While an r2/r3/r4 lamp is lit the tracker compares the load
//! and the voltage with their span during learning and says when they have left it
//! ([`RangeNote`]). Both are measured without the model's d-q frame, whose angle comes
//! from the speed reading and the parameter file (a speed-sensor fault turns it, and with
//! it `Iqs` and `Vqs`, without the machine's operating point moving at all):
//! ```text
//!   |V| = sqrt(V_ds^2 + V_qs^2),   I_active = (V_ds i_ds + V_qs i_qs) / |V|
//! ```
//! (amplitude-invariant d-q: `|V|` is the phase voltage's peak, `I_active` the peak of
//! the current's part in phase with the voltage, `P = 1.5 |V| I_active`), both unchanged
//! by any rotation of the frame ([`operating_point`]). The rule (the arithmetic, the span
//! and the 20 % margin, `monitor_core::operating_range::RANGE_MARGIN`) is the core's
//! `monitor_core::operating_range`, which the firmware's panel uses too.

use crate::options::CommissionWindow;
pub use crate::range::{RangeDeparture, RangeQuantity};
use monitor_core::operating_range::{outside, widen};
use monitor_core::{
    CommissioningState, Monitor, MonitorConfig, MonitorOutput, OperatingPoint, RunStage,
};
use serde::Serialize;

/// How long after the window's end a run may still finish [s]: half the window, at least
/// one second.
pub fn grace_s(start_s: f64, end_s: f64) -> f64 {
    (0.5 * (end_s - start_s)).max(1.0)
}

/// The least evaluated running a window must hold to be learned [s]: 1 s (400 blocks at
/// the usual 2.5 ms; the isolation's baseline needs half a second of it), or the whole
/// window when it is shorter. A window over real running, with supply or load steps
/// inside it, is learned from its quasi-steady blocks when they add up to this much.
pub fn min_learned_s(start_s: f64, end_s: f64) -> f64 {
    MIN_LEARNED_S.min(end_s - start_s)
}

/// See [`min_learned_s`].
pub const MIN_LEARNED_S: f64 = 1.0;

/// What became of the commissioning asked for (JSON `learned`, `incomplete`, `none`).
#[derive(Debug, Clone, Copy, Serialize, PartialEq, Eq)]
#[serde(rename_all = "snake_case")]
pub enum CommissioningOutcome {
    /// The window was learned: the thresholds and the isolation's baseline are the
    /// learned ones.
    Learned,
    /// A window was asked for and not learned (the report says why).
    Incomplete,
    /// No window was asked for: the thresholds are fixed.
    None,
}

/// The commissioning part of `diagnose`'s report.
#[derive(Debug, Clone, Serialize, PartialEq)]
pub struct CommissioningReport {
    /// `learned`, `incomplete` or `none`.
    pub state: CommissioningOutcome,
    /// The window asked for, `[START, END]` [s], if any.
    pub requested: Option<CommissionWindow>,
    /// The part of the log the run actually spanned, from its start to its end (or to
    /// where it was cancelled, or to the end of the log) [s]; null if it never started.
    pub window: Option<[f64; 2]>,
    /// Seconds of evaluated running learned.
    pub seconds_evaluated: f64,
    /// Seconds of evaluated running the window asked for.
    pub seconds_needed: f64,
    /// Span of the load (the active current, in phase with the voltage: module docs)
    /// while learning, `[min, max]` [A peak].
    pub load_current_a: Option<[f32; 2]>,
    /// Span of the voltage magnitude |V| while learning, `[min, max]` [V peak, phase].
    pub voltage_v: Option<[f32; 2]>,
    /// Which thresholds the lamps used (JSON `thresholds_in_force`; the door spells it as
    /// `thresholds`).
    #[serde(rename = "thresholds_in_force")]
    pub thresholds: Thresholds,
    /// Without commissioning: the first quasi-steady point and the residuals there.
    pub first_quasi_steady: Option<QuasiSteadyPoint>,
    /// Times a lit r2/r3/r4 lamp met an operating point outside the learned range.
    pub outside_range: Vec<RangeNote>,
    /// What the user should do, if anything (JSON `advice_given`; the door spells it as
    /// `advice`): given only where the residuals ran.
    #[serde(rename = "advice_given")]
    pub advice: Option<CommissionAdvice>,
}

/// The thresholds the lamps acted on (JSON `{"kind": ..}`).
#[derive(Debug, Clone, Copy, Serialize, PartialEq)]
#[serde(tag = "kind", rename_all = "snake_case")]
pub enum Thresholds {
    /// The fixed thresholds against the nominal parameters: `|r| > fixed` (a fraction).
    Fixed {
        /// The fixed threshold on `|r|` (0.03: 3 %).
        fixed: f32,
    },
    /// Learned over `[from_s, to_s]`: the healthy mean +/- `k_sigma` spreads.
    Learned {
        /// Where learning began [s].
        from_s: f64,
        /// Where it ended [s].
        to_s: f64,
        /// How many spreads a lamp's band is wide.
        k_sigma: f32,
    },
    /// A window was asked for and not learned: the fixed thresholds stayed in force.
    FixedIncomplete {
        /// The fixed threshold on `|r|`.
        fixed: f32,
    },
    /// No residual ran (the log lacks the voltages or the speed): no threshold was used.
    NotUsed,
}

/// What the user should do about commissioning (JSON `{"kind": ..}`).
#[derive(Debug, Clone, Copy, Serialize, PartialEq)]
#[serde(tag = "kind", rename_all = "snake_case")]
pub enum CommissionAdvice {
    /// The thresholds are fixed against the file's nominal values: commission over healthy
    /// running that covers the whole load and voltage range.
    CommissionOverRange,
    /// The window asked for was not learned, and why.
    NotLearned(NotLearned),
}

/// A commissioning window that was not learned, and why.
#[derive(Debug, Clone, Copy, Serialize, PartialEq)]
pub struct NotLearned {
    /// The window asked for.
    pub window: CommissionWindow,
    /// Why it was not learned.
    pub why: NotLearnedWhy,
}

/// Why a commissioning window was not learned (JSON `{"kind": ..}`).
#[derive(Debug, Clone, Copy, Serialize, PartialEq)]
#[serde(tag = "kind", rename_all = "snake_case")]
pub enum NotLearnedWhy {
    /// The log ends at `end_s`, before the window starts.
    EndsBeforeWindow {
        /// The log's last time [s].
        end_s: f64,
    },
    /// Too little evaluated running was learned.
    TooLittle {
        /// Seconds of evaluated running learned.
        learned_s: f64,
        /// By when [s].
        by_s: f64,
        /// Seconds needed at least ([`min_learned_s`]).
        needed_s: f64,
        /// The run was given up (the window held too little quasi-steady running with
        /// usable data); else the log ended first.
        cancelled: bool,
    },
}

/// The residuals at one time.
#[derive(Debug, Clone, Copy, Serialize, PartialEq)]
pub struct QuasiSteadyPoint {
    /// Time since the log's start [s].
    pub t_s: f64,
    /// Normalised residuals r1..r4 (the fixed thresholds act on |r|).
    pub residuals: [f32; 4],
}

/// An operating point outside the commissioned range while a lamp was lit.
#[derive(Debug, Clone, Serialize, PartialEq)]
pub struct RangeNote {
    /// First time [s].
    pub t_s: f64,
    /// What left the range, by how much (the door spells it as `note`).
    pub departures: Vec<RangeDeparture>,
}

/// Why the first quasi-steady point already passes a fixed threshold without commissioning.
#[derive(Debug, Clone, Copy, Serialize, PartialEq)]
pub struct FirstPointMisfit {
    /// The first quasi-steady point [s].
    pub t_s: f64,
    /// Which residual (0 for r1).
    pub residual: usize,
    /// Its value.
    pub value: f32,
    /// Its fixed threshold.
    pub threshold: f32,
}

/// Follows a replay's commissioning (see the module documentation).
#[derive(Debug, Clone)]
pub(crate) struct CommissionTracker {
    requested: Option<CommissionWindow>,
    run_id: Option<u16>,
    started_at: Option<f64>,
    ended_at: Option<f64>,
    cancelled: bool,
    slow_hz: f64,
    fixed: [f32; 4],
    iqs: Option<[f32; 2]>,
    vqs: Option<[f32; 2]>,
    first_steady: Option<QuasiSteadyPoint>,
    notes: Vec<RangeNote>,
    noted: u8,
    last_t: f64,
    learned: (u32, u32),
}

/// The load and the voltage of `out`, independent of the d-q frame's angle: the active
/// current `I_active = (V_ds i_ds + V_qs i_qs) / |V|` [A] and the voltage magnitude
/// `|V| = sqrt(V_ds^2 + V_qs^2)` [V] (module docs; the rule is the core's
/// [`OperatingPoint`], `|V|` by the standard library's `hypot`); `I_active` is NaN without
/// voltage.
pub(crate) fn operating_point(out: &MonitorOutput) -> (f32, f32) {
    let o = &out.operating;
    let p = OperatingPoint::with_magnitude(out.vds, o.vqs, o.i_f, o.iqs, out.vds.hypot(o.vqs));
    (p.load_a, p.voltage_v)
}

impl CommissionTracker {
    pub(crate) fn new(requested: Option<CommissionWindow>, cfg: &MonitorConfig) -> Self {
        CommissionTracker {
            requested,
            run_id: None,
            started_at: None,
            ended_at: None,
            cancelled: false,
            slow_hz: f64::from(cfg.sample_rate_hz) / f64::from(cfg.decimation.max(1)),
            fixed: cfg.thresholds.fixed,
            iqs: None,
            vqs: None,
            first_steady: None,
            notes: Vec::new(),
            noted: 0,
            last_t: 0.0,
            learned: (0, 0),
        }
    }

    /// Before the sample at `t` [s since the log's start]: starts the run at the window's
    /// start, cancels it when it is still learning past the grace time.
    pub(crate) fn before(&mut self, mon: &mut Monitor, t: f64) {
        self.last_t = t;
        let Some((a, b)) = self.requested.map(CommissionWindow::seconds) else {
            return;
        };
        if self.started_at.is_none() && t >= a {
            self.started_at = Some(t);
            self.run_id = mon.start_commissioning((b - a) as f32).ok();
        }
        if let Some(id) = self.run_id {
            // At the window's end the run ends with the evaluated running it learned inside
            // the window (supply and load steps close the quasi-steady gate for a while),
            // if that is at least the stated minimum; else it may go on for the grace time.
            if self.ended_at.is_none()
                && t >= b
                && mon.commissioning().stage == RunStage::Learning
                && mon.finish_commissioning(id, min_learned_s(a, b) as f32)
            {
                self.ended_at = Some(t);
            }
            if self.ended_at.is_none()
                && t > b + grace_s(a, b)
                && mon.commissioning().stage == RunStage::Learning
                && mon.cancel_commissioning(id)
            {
                self.ended_at = Some(t);
                self.cancelled = true;
            }
        }
    }

    /// After the sample: records the learning range, the run's end, the first
    /// quasi-steady point; returns a note when a lit r2..r4 lamp meets an operating point
    /// outside the learned range.
    pub(crate) fn after(
        &mut self,
        mon: &Monitor,
        t: f64,
        out: &MonitorOutput,
    ) -> Option<Vec<RangeDeparture>> {
        // (The run is read only where this replay started one.)
        if let Some(id) = self.run_id {
            let run = mon.commissioning();
            if run.id == id {
                self.learned = (run.blocks_learned, run.blocks_needed);
                if run.stage == RunStage::Done && self.ended_at.is_none() {
                    self.ended_at = Some(t);
                }
            }
        }
        if matches!(out.commissioning, CommissioningState::Learning(_)) && out.quasi_steady {
            let (i_active, v) = operating_point(out);
            widen(&mut self.iqs, i_active);
            widen(&mut self.vqs, v);
        }
        if self.requested.is_none() && self.first_steady.is_none() && out.evaluating {
            self.first_steady = Some(QuasiSteadyPoint {
                t_s: t,
                residuals: out.residuals,
            });
        }
        let learned = out.commissioning == CommissioningState::Commissioned;
        if !(learned && out.lamps.iter().skip(1).any(|l| *l)) {
            return None;
        }
        self.range_note(t, out)
    }

    fn range_note(&mut self, t: f64, out: &MonitorOutput) -> Option<Vec<RangeDeparture>> {
        let said = self.departures(out);
        for d in &said {
            let k = match d.quantity {
                RangeQuantity::Load => 0,
                RangeQuantity::Voltage => 1,
            };
            let bit = 1u8 << (2 * k + usize::from(d.fraction > 0.0));
            if self.noted & bit == 0 {
                self.noted |= bit;
                self.notes.push(RangeNote {
                    t_s: t,
                    departures: vec![*d],
                });
            }
        }
        (!said.is_empty()).then_some(said)
    }

    /// The quantities of `out` outside the span learned while commissioning (beyond the
    /// reporting margin), whether or not the learned thresholds are in force.
    fn departures(&self, out: &MonitorOutput) -> Vec<RangeDeparture> {
        let (i_active, v) = operating_point(out);
        [
            (self.iqs, i_active, RangeQuantity::Load),
            (self.vqs, v, RangeQuantity::Voltage),
        ]
        .into_iter()
        .filter_map(|(span, value, quantity)| {
            let span = span?;
            outside(span, value).map(|fraction| RangeDeparture {
                quantity,
                value,
                fraction,
                span,
            })
        })
        .collect()
    }

    /// Where the learned thresholds are in force and the load current or the voltage has
    /// left the span seen while learning (beyond the reporting margin): what left it, as
    /// the timeline's `range_note` has it, whether or not a lamp is lit. `None` inside the
    /// range or without a learned window.
    pub(crate) fn moved_note(&self, out: &MonitorOutput) -> Option<Vec<RangeDeparture>> {
        if out.commissioning != CommissioningState::Commissioned {
            return None;
        }
        let said = self.departures(out);
        (!said.is_empty()).then_some(said)
    }

    /// True when the learned thresholds are in force and the load current or the voltage
    /// is outside the span seen while learning (beyond the reporting margin).
    /// (The same test as [`CommissionTracker::moved_note`]'s, without its words.)
    #[inline]
    pub(crate) fn outside_learned_range(&self, out: &MonitorOutput) -> bool {
        out.commissioning == CommissioningState::Commissioned && self.outside_span(out)
    }

    /// [`CommissionTracker::outside_learned_range`] with the learned thresholds in force
    /// (out of line: the replay asks on every row with a lamp lit).
    #[inline(never)]
    fn outside_span(&self, out: &MonitorOutput) -> bool {
        let (i_active, v) = operating_point(out);
        self.iqs.and_then(|s| outside(s, i_active)).is_some()
            || self.vqs.and_then(|s| outside(s, v)).is_some()
    }

    /// Whether lamps on the thresholds now in force count as detections: always without a
    /// window (the fixed thresholds are what the user chose), with one once the learned
    /// thresholds are in force, or once an incomplete run was given up (then the fixed
    /// thresholds are what `--allow-incomplete` reports with); never before.
    pub(crate) fn thresholds_trusted(&self, out: &MonitorOutput) -> bool {
        self.requested.is_none()
            || self.cancelled
            || out.commissioning == CommissioningState::Commissioned
    }

    /// Without commissioning: why no verdict can rest on the fixed thresholds, when the
    /// residuals already pass them at the first quasi-steady point. Wrong nominal
    /// parameters (a nameplate 10-30 % off) and a fault present from the start then look
    /// the same; only commissioning on healthy running tells them apart.
    pub(crate) fn nominal_misfit(&self) -> Option<FirstPointMisfit> {
        let p = self.first_steady.filter(|_| self.requested.is_none())?;
        let (k, r) = p
            .residuals
            .iter()
            .zip(self.fixed)
            .enumerate()
            .filter(|(_, (r, f))| r.abs() > *f)
            .map(|(k, (r, _))| (k, *r))
            .max_by(|a, b| a.1.abs().total_cmp(&b.1.abs()))?;
        Some(FirstPointMisfit {
            t_s: p.t_s,
            residual: k,
            value: r,
            threshold: self.fixed.get(k).copied().unwrap_or(0.0),
        })
    }

    /// True when a window was asked for and not learned.
    pub(crate) fn incomplete(&self) -> bool {
        self.requested.is_some() && !self.learned_ok()
    }

    /// A window was asked for and learned: the lamps' thresholds are the motor's own.
    pub(crate) fn learned(&self) -> bool {
        self.requested.is_some() && self.learned_ok()
    }

    fn learned_ok(&self) -> bool {
        !self.cancelled && self.ended_at.is_some() && self.learned.0 >= self.learned.1
    }

    /// The window asked for and why it was not learned, where it was not.
    pub(crate) fn not_learned(&self) -> Option<NotLearned> {
        let window = self.requested?;
        let (a, b) = window.seconds();
        if self.learned_ok() {
            return None;
        }
        let end = self.last_t;
        let why = match self.started_at {
            None => NotLearnedWhy::EndsBeforeWindow { end_s: end },
            Some(_) => NotLearnedWhy::TooLittle {
                learned_s: self.seconds(self.learned.0),
                by_s: self.ended_at.unwrap_or(end),
                needed_s: min_learned_s(a, b),
                cancelled: self.cancelled,
            },
        };
        Some(NotLearned { window, why })
    }

    fn seconds(&self, blocks: u32) -> f64 {
        f64::from(blocks) / self.slow_hz.max(1e-9)
    }

    /// The commissioning window asked for [s], if any.
    pub(crate) fn requested(&self) -> Option<CommissionWindow> {
        self.requested
    }

    /// The report at the end of the replay (`monitor`: the residuals ran; without them no
    /// threshold was used and no advice is given).
    pub(crate) fn report(&self, k_sigma: f32, monitor: bool) -> CommissioningReport {
        let fixed = self.fixed[0];
        let (state, thresholds, advice) = match self.requested.map(CommissionWindow::seconds) {
            None if !monitor => (CommissioningOutcome::None, Thresholds::NotUsed, None),
            None => (
                CommissioningOutcome::None,
                Thresholds::Fixed { fixed },
                Some(CommissionAdvice::CommissionOverRange),
            ),
            Some((a, _)) if self.learned_ok() => (
                CommissioningOutcome::Learned,
                Thresholds::Learned {
                    from_s: a,
                    to_s: self.ended_at.unwrap_or(self.last_t),
                    k_sigma,
                },
                None,
            ),
            Some(_) if !monitor => (CommissioningOutcome::Incomplete, Thresholds::NotUsed, None),
            Some(_) => (
                CommissioningOutcome::Incomplete,
                Thresholds::FixedIncomplete { fixed },
                self.not_learned().map(CommissionAdvice::NotLearned),
            ),
        };
        CommissioningReport {
            state,
            requested: self.requested,
            window: self
                .started_at
                .map(|s| [s, self.ended_at.unwrap_or(self.last_t)]),
            seconds_evaluated: self.seconds(self.learned.0),
            seconds_needed: self.requested.map_or(0.0, |w| w.end_s() - w.start_s()),
            load_current_a: self.iqs,
            voltage_v: self.vqs,
            thresholds,
            first_quasi_steady: self.first_steady,
            outside_range: self.notes.clone(),
            advice,
        }
    }
}
