//! The one shape of a replay's stages ([`Stage`], [`Finish`]) and what the chain hands
//! along a row besides each stage's own output: the time ([`Clock`]) and the monitor's
//! output as flags ([`RowFlags`]).
//!
//! A stage is configured once, when it is built (its options checked there, not per row);
//! it keeps its own state; per row it takes the row with what the stages before it handed
//! on ([`Stage::update`]), and at the end it gives a typed finding ([`Finish::finish`]),
//! handed what the stages before it found. No stage reads another's fields: what it needs
//! of another comes as its input. `Replay` holds the stages in their order and passes the
//! outputs on (`replay.rs`, `Replay::push_step`).
//!
//! The shape is idsp's one processing shape lifted a floor up: configuration apart from
//! state, one call per sample, and here one call at the end.

use monitor_core::{CommissioningState, MonitorOutput};
use monitor_io::log::Row;

/// A stage's end: what the chain hands it when the rows are over, and what it found.
pub(crate) trait Finish {
    /// What the stage is handed at the end: the findings of the stages before it that it
    /// reads (`()` for none).
    type Closing<'a>;
    /// What it found: a typed value (numbers and enums; the front ends spell it).
    type Finding;

    /// Ends the stage: its finding.
    fn finish(self, closing: Self::Closing<'_>) -> Self::Finding;
}

/// A stage fed row by row: [`Stage::update`] per row, then [`Finish::finish`].
///
/// Two stages of the replay are [`Finish`] only, because their rows reach them in front of
/// the chain: the rotor's demodulator runs inside the sequence stage (on one reference
/// angle with the least-squares windows), and the data-quality stage runs before any row
/// reaches the chain (`monitor_io::log::quality`).
pub(crate) trait Stage: Finish {
    /// What the chain hands the stage with each row: the outputs of the stages before it.
    type Input<'a>;
    /// What the stage hands on for the row.
    type Output;

    /// Takes one row with what the stages before it handed on.
    fn update(&mut self, row: &Row, input: Self::Input<'_>) -> Self::Output;
}

/// The replay's time base: each row's time since the log's first row [s], and the rows
/// counted (the report's `rows`).
#[derive(Debug, Clone, Copy)]
pub(crate) struct Clock {
    /// The first row's time [s] (`None` before the first row).
    t0: Option<f64>,
    /// The sample interval the replay was configured for [s].
    dt_s: f64,
    /// Rows taken.
    rows: u64,
}

impl Clock {
    /// A clock for a log sampled at `sample_rate_hz`.
    pub(crate) fn new(sample_rate_hz: f64) -> Self {
        Clock {
            t0: None,
            dt_s: 1.0 / sample_rate_hz,
            rows: 0,
        }
    }

    /// The sample interval [s].
    pub(crate) fn dt_s(&self) -> f64 {
        self.dt_s
    }

    /// Time of `row` since the first row taken [s] (0 before any: `row` would be the
    /// first).
    pub(crate) fn time_of(&self, row: &Row) -> f64 {
        row.t_s - self.t0.unwrap_or(row.t_s)
    }
}

impl Stage for Clock {
    type Input<'a> = ();
    /// The row's time since the first row [s].
    type Output = f64;

    #[inline]
    fn update(&mut self, row: &Row, (): ()) -> f64 {
        self.rows += 1;
        row.t_s - *self.t0.get_or_insert(row.t_s)
    }
}

impl Finish for Clock {
    type Closing<'a> = ();
    /// The rows taken.
    type Finding = u64;

    fn finish(self, (): ()) -> u64 {
        self.rows
    }
}

/// The monitor's output as the isolation reads it, for one row (bits).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub(crate) struct RowFlags(u8);

impl RowFlags {
    const LEARNING: u8 = 1;
    const LEARNED_BLOCKS: u8 = 2;
    const EVALUATING: u8 = 4;
    const SENSOR_FAULT: u8 = 8;
    const COUNTS: u8 = 16;
    const FAULT_DETECTED: u8 = 32;
    const QUASI_STEADY: u8 = 64;

    /// The flags of `out`, read once per row by the replay's steps; `trusted`: the
    /// thresholds in force count ([`RowFlags::counts`]: they do, or a sensor fault is
    /// flagged).
    #[inline]
    pub(crate) fn of(out: &MonitorOutput, trusted: bool) -> Self {
        let (learning, learned_blocks) = match out.commissioning {
            CommissioningState::Learning(f) => (true, f > 0.0),
            _ => (false, false),
        };
        let bit = |b: bool, v: u8| if b { v } else { 0 };
        let sensor_fault = out.sensor_fault.any();
        RowFlags(
            bit(learning, Self::LEARNING)
                | bit(learned_blocks, Self::LEARNED_BLOCKS)
                | bit(out.evaluating, Self::EVALUATING)
                | bit(sensor_fault, Self::SENSOR_FAULT)
                | bit(sensor_fault || trusted, Self::COUNTS)
                | bit(out.fault_detected, Self::FAULT_DETECTED)
                | bit(out.quasi_steady, Self::QUASI_STEADY),
        )
    }

    /// The same flags with [`RowFlags::counts`] set to `counts` (the isolation's: the
    /// lamps count and the monitor has settled after a restart).
    #[inline]
    pub(crate) fn with_counts(self, counts: bool) -> Self {
        RowFlags(self.0 & !Self::COUNTS | if counts { Self::COUNTS } else { 0 })
    }

    fn has(self, v: u8) -> bool {
        self.0 & v != 0
    }

    /// Commissioning learns.
    pub(crate) fn learning(self) -> bool {
        self.has(Self::LEARNING)
    }

    /// Commissioning learns and has learned a block.
    pub(crate) fn learned_blocks(self) -> bool {
        self.has(Self::LEARNED_BLOCKS)
    }

    /// The monitor evaluates its lamps.
    pub(crate) fn evaluating(self) -> bool {
        self.has(Self::EVALUATING)
    }

    /// A sensor fault is flagged.
    pub(crate) fn sensor_fault(self) -> bool {
        self.has(Self::SENSOR_FAULT)
    }

    /// Lamps and detections count.
    pub(crate) fn counts(self) -> bool {
        self.has(Self::COUNTS)
    }

    /// A lamp is lit or a sensor fault flagged.
    pub(crate) fn fault_detected(self) -> bool {
        self.has(Self::FAULT_DETECTED)
    }

    /// The monitor's quasi-steady gate is open.
    pub(crate) fn quasi_steady(self) -> bool {
        self.has(Self::QUASI_STEADY)
    }
}

/// What the lamps say about a fault, as the detection reads it with the isolation's
/// (the isolation's `detected`: a lamp or the isolation detected a fault, unless heating
/// or the load explains it).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) struct LampsSeen {
    /// A counted detection happened.
    pub(crate) detected: bool,
    /// With the load an unknown input, the lamps' matching only ever named the friction
    /// class (the load term) and no sensor fault stands: a load move.
    pub(crate) only_load: bool,
}
