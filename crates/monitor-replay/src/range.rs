//! What left the range learned in commissioning ([`RangeDeparture`]): the quantity, its value
//! and how far outside; below the stages, so that the lamps' commissioning, the isolation and
//! the timeline can all hand it on.

use serde::Serialize;

/// Which of the commissioned range's quantities left it.
#[derive(Debug, Clone, Copy, Serialize, PartialEq, Eq)]
#[serde(rename_all = "snake_case")]
pub enum RangeQuantity {
    /// The load: the active current [A peak].
    Load,
    /// The voltage magnitude |V| [V peak].
    Voltage,
}

/// One quantity outside the span learned in commissioning.
#[derive(Debug, Clone, Copy, Serialize, PartialEq)]
pub struct RangeDeparture {
    /// Which.
    pub quantity: RangeQuantity,
    /// Its value now.
    pub value: f32,
    /// How far outside, as a fraction of the span's edge (positive: above).
    pub fraction: f32,
    /// The span learned, `[min, max]`.
    pub span: [f32; 2],
}
