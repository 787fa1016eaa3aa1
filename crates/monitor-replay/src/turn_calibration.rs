//! A calibration of a shorted turn's level learned from labelled runs of the same motor
//! ([`TurnCalibration`]): one of the options the winding stage reads (`ReplayOptions::
//! turn_level`, `winding::level`).

use monitor_core::Phase;
use serde::{Deserialize, Serialize};

/// Most levels a calibration keeps per phase.
pub const MAX_CALIBRATION_LEVELS: usize = 8;

/// A calibration of the loop ratio `|r|` against the shorted fraction, learned from
/// labelled runs of one motor: per phase, the mean `|r|` of each labelled level; a reading
/// is mapped by straight lines through `(0, 0)` and those points (beyond the last, on the
/// last segment's slope). A file (`diagnose --turn-calibration FILE`) holds it as JSON.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct TurnCalibration {
    /// Per phase (a, b, c), up to [`MAX_CALIBRATION_LEVELS`] points `[loop_ratio,
    /// fraction]`, sorted by fraction; unused points are `[0, 0]`.
    pub points: [[[f32; 2]; MAX_CALIBRATION_LEVELS]; 3],
    /// How many points each phase holds.
    pub counts: [u8; 3],
    /// The RMS scatter of one run's `|r|` about its level's mean (the interval's width).
    pub scatter: f32,
    /// How many labelled runs it was learned from.
    pub runs: u32,
}

/// One labelled run for [`TurnCalibration::learn`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LabelledRun {
    /// The shorted phase.
    pub phase: Phase,
    /// The shorted fraction of its turns (the label).
    pub fraction: f32,
    /// The run's measured loop ratio ([`ShortedTurns::loop_ratio`]).
    pub loop_ratio: f32,
}

impl TurnCalibration {
    /// Learns the calibration from labelled fault runs (healthy runs carry no level and are
    /// not given); `None` without any.
    pub fn learn(runs: &[LabelledRun]) -> Option<Self> {
        if runs.is_empty() {
            return None;
        }
        let mut cal = TurnCalibration {
            points: [[[0.0; 2]; MAX_CALIBRATION_LEVELS]; 3],
            counts: [0; 3],
            scatter: 0.0,
            runs: runs.len() as u32,
        };
        let (mut ss, mut n) = (0.0f32, 0u32);
        for p in Phase::ALL {
            let mut levels: Vec<f32> = runs
                .iter()
                .filter(|r| r.phase == p)
                .map(|r| r.fraction)
                .collect();
            levels.sort_by(f32::total_cmp);
            levels.dedup_by(|a, b| (*a - *b).abs() < 1e-4);
            for (i, lv) in levels.iter().take(MAX_CALIBRATION_LEVELS).enumerate() {
                let at: Vec<f32> = runs
                    .iter()
                    .filter(|r| r.phase == p && (r.fraction - lv).abs() < 1e-4)
                    .map(|r| r.loop_ratio)
                    .collect();
                let m = at.iter().sum::<f32>() / at.len() as f32;
                ss += at.iter().map(|x| (x - m).powi(2)).sum::<f32>();
                n += at.len().saturating_sub(1) as u32;
                cal.points[p.index()][i] = [m, *lv];
                cal.counts[p.index()] = (i + 1) as u8;
            }
        }
        // One run at each level gives no scatter: a tenth of the smallest level's ratio.
        let smallest = runs.iter().map(|r| r.loop_ratio).fold(f32::MAX, f32::min);
        cal.scatter = if n > 0 {
            (ss / n as f32).sqrt()
        } else {
            0.1 * smallest
        };
        Some(cal)
    }

    /// The fraction at loop ratio `x` for `phase` (the other phases' points where it has
    /// none); `None` when the calibration holds no point.
    pub fn fraction(&self, phase: Phase, x: f32) -> Option<f32> {
        let of = |k: usize| {
            let n = usize::from(self.counts[k]).min(MAX_CALIBRATION_LEVELS);
            self.points[k][..n].to_vec()
        };
        let mut pts = of(phase.index());
        if pts.is_empty() {
            pts = (0..3).flat_map(of).collect();
            pts.sort_by(|a, b| a[1].total_cmp(&b[1]));
        }
        let mut prev = [0.0f32, 0.0f32];
        let last = *pts.last()?;
        for p in &pts {
            if x <= p[0] {
                return Some(interp(prev, *p, x));
            }
            prev = *p;
        }
        // Beyond the last point: on the last segment's slope.
        let before = pts.len().checked_sub(2).and_then(|i| pts.get(i).copied());
        Some(interp(before.unwrap_or([0.0, 0.0]), last, x))
    }
}

/// The straight line through `a` and `b` (`[x, y]`) at `x` (`a`'s `y` where they share `x`).
fn interp(a: [f32; 2], b: [f32; 2], x: f32) -> f32 {
    let dx = b[0] - a[0];
    if dx.abs() <= f32::EPSILON {
        return a[1];
    }
    a[1] + (b[1] - a[1]) * (x - a[0]) / dx
}
