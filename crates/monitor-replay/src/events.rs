//! What happened during a replay, with times: the isolation's names (each fault the first
//! time it was named, with its size) and the load's moves (operating-point changes), for
//! logs of hours where a timeline is too long to read (`diagnose --json` key
//! `isolation.events`, and the `events:` lines of the text report).
//!
//! A load move is an operating-point change, not a fault: the active current (the current's
//! part in phase with the voltage, which follows the input power) of a steady operating
//! point differs from the one of the last point recorded by [`LOAD_MOVE_FRACTION`] or more.
//! The faults of the list move it by their losses only, a few per cent (Rr +50 %: about 3 %),
//! so a load move is a change of the load (or of the machine's friction B, which no log
//! without a load model tells apart from it).
//!
//! # When a load move began
//! A move is found after the fact: at the first steady point after it, once the monitor's
//! quasi-steady gate has opened again or the isolation has averaged the new point (0.8-1.4 s
//! after the step on the demo and the motulator log). It is dated where it began: the log
//! keeps the active current's means over [`HISTORY_BLOCK_S`] blocks for the last
//! [`HISTORY_S`] ([`LoadHistory`]), and a move is dated back from the newest block where the
//! active current crossed the middle between the old and the new level to the end of the
//! last block before it that was still on the old level's side and no longer moving
//! towards the new one (by less than [`STILL_FRACTION`] of the move). The sequence analysis'
//! 2 Hz critically damped filters start a step with zero slope and move 2.6 % of it in the
//! first 20 ms block, so the date is within about one block of the step plus the machine's
//! own mechanical response (tens of milliseconds on the reference motors).

use super::isolation_name::IsolationName;
use monitor_core::SteadyPoint;
use serde::Serialize;
use std::collections::VecDeque;

/// Smallest relative change of the active current between two steady operating points
/// that is reported as a load move: 10 % (the faults of the list move it by a few per cent
/// at a constant load; module docs).
pub const LOAD_MOVE_FRACTION: f32 = 0.1;

/// Most events kept; later ones are counted ([`EventLog::dropped`]). An hour of a load
/// that moves every few seconds gives about a thousand moves.
pub const MAX_EVENTS: usize = 200;

/// One event of a replay (JSON: an object with `t_s` and `event`, then the event's keys).
#[derive(Debug, Clone, PartialEq, Serialize)]
#[serde(tag = "event", rename_all = "snake_case")]
pub enum IsolationEvent {
    /// The isolation named a fault (or, with the paper's viscous load, the friction class)
    /// for the first time.
    Named {
        /// When [s] (the replay's time).
        t_s: f64,
        /// What was named (JSON: its name).
        name: IsolationName,
        /// Its estimated relative change (0.2: +20 %).
        change: f32,
        /// Its probability, [0, 1].
        probability: f32,
    },
    /// The load moved: a steady operating point whose active current differs from the last
    /// one recorded by at least [`LOAD_MOVE_FRACTION`].
    LoadMoved {
        /// When the move began [s] (the replay's time; module docs, "When a load move
        /// began"; where the history does not reach back to it, the time of the steady
        /// point that showed it).
        t_s: f64,
        /// The active current before [A, peak].
        from_a: f32,
        /// The active current now [A, peak].
        to_a: f32,
    },
}

impl IsolationEvent {
    /// When the event happened [s].
    pub fn t_s(&self) -> f64 {
        match self {
            IsolationEvent::Named { t_s, .. } | IsolationEvent::LoadMoved { t_s, .. } => *t_s,
        }
    }
}

/// The events of a replay, in time order.
#[derive(Debug, Clone, Default)]
pub(super) struct EventLog {
    events: Vec<IsolationEvent>,
    /// The active current of the last steady point recorded [A], and when it was recorded
    /// [s].
    load_a: Option<(f32, f64)>,
    dropped: usize,
    /// The active current's recent block means, to date a move back to its onset.
    history: LoadHistory,
}

impl EventLog {
    /// Every sample's operating point `p` at `t` [s], `dt_s` [s] after the previous one
    /// (steady or not): its active current goes into the history moves are dated from.
    pub(super) fn sample(&mut self, t: f64, dt_s: f64, p: &SteadyPoint) {
        self.history.add(t, dt_s, p);
    }

    /// After a steady operating point `p` judged at `t`: a load move if its active current
    /// moved by [`LOAD_MOVE_FRACTION`] or more from the last point recorded, dated where it
    /// began (module docs).
    pub(super) fn point(&mut self, t: f64, p: &SteadyPoint) {
        let a = active_current(p);
        if !a.is_finite() {
            return;
        }
        match self.load_a {
            Some((a0, t0)) if (a - a0).abs() >= LOAD_MOVE_FRACTION * a0.abs() => {
                let began = self.history.onset(a0, a, t0).unwrap_or(t);
                self.push(IsolationEvent::LoadMoved {
                    t_s: began,
                    from_a: a0,
                    to_a: a,
                });
                self.load_a = Some((a, t));
            }
            Some(_) => {}
            None => self.load_a = Some((a, t)),
        }
    }

    /// The commissioned operating point, where no steady point was recorded yet: the load
    /// the first move is measured from.
    pub(super) fn seed(&mut self, p: &SteadyPoint) {
        let a = active_current(p);
        if self.load_a.is_none() && a.is_finite() {
            self.load_a = Some((a, f64::NEG_INFINITY));
        }
    }

    /// A name given for the first time.
    pub(super) fn named(&mut self, t: f64, name: IsolationName, change: f32, probability: f32) {
        self.push(IsolationEvent::Named {
            t_s: t,
            name,
            change,
            probability,
        });
    }

    /// Keeps `e` in time order (a move dated back can precede a name given since it began).
    fn push(&mut self, e: IsolationEvent) {
        if self.events.len() < MAX_EVENTS {
            let at = self
                .events
                .iter()
                .rposition(|x| x.t_s() <= e.t_s())
                .map_or(0, |k| k + 1);
            self.events.insert(at, e);
        } else {
            self.dropped += 1;
        }
    }

    /// The events kept, in time order.
    pub(super) fn events(&self) -> &[IsolationEvent] {
        &self.events
    }

    /// How many events came after [`MAX_EVENTS`] and were not kept.
    pub(super) fn dropped(&self) -> usize {
        self.dropped
    }
}

/// The active current of a steady point [A, peak] ([`SteadyPoint::operating_point`]).
fn active_current(p: &SteadyPoint) -> f32 {
    p.operating_point().load_a
}

/// Length of one block of the active current's history [s]: 20 ms, a supply period at
/// 50 Hz (module docs, "When a load move began").
pub const HISTORY_BLOCK_S: f64 = 0.02;

/// How far back the history reaches [s]: longer than a move takes to be seen as a steady
/// point (the quasi-steady gate and the isolation's average: 1-2 s) with room for a motor
/// that settles slowly.
pub const HISTORY_S: f64 = 10.0;

/// How little the active current may move between two blocks, as a fraction of the move,
/// for the older block to count as the old level (module docs, "When a load move began"):
/// 1 %, below the 2.6 % the sequence analysis' filters move in the first block after a step.
pub const STILL_FRACTION: f32 = 0.01;

/// The active current's means over [`HISTORY_BLOCK_S`] blocks for the last [`HISTORY_S`]
/// (module docs, "When a load move began"). A block's mean is the active current of the
/// block's mean operating point (the vectors averaged, then `V.I/|V|` once per block rather
/// than per sample): over 20 ms the sequence analysis' 2 Hz filtered vectors hardly turn, and
/// the two differ by the vectors' variance within the block, below 1e-5 of the current.
#[derive(Debug, Clone, Default)]
struct LoadHistory {
    /// Closed blocks: start time [s] and mean active current [A], oldest first.
    blocks: VecDeque<(f64, f32)>,
    /// The open block: its start [s], summed time [s] and the dt-weighted sum of its points
    /// [s times the point's units].
    open: Option<(f64, f64, SteadyPoint)>,
}

/// Least voltage magnitude of a point the history takes [V] (the active current needs a
/// voltage to be in phase with; the operating point's own floor).
const HISTORY_MIN_VOLTAGE_V: f32 = 1e-3;

impl LoadHistory {
    /// Adds the operating point `p` of the sample at `t` [s], `dt_s` after the previous
    /// one; a point whose vectors are not finite or that has no voltage closes nothing and
    /// is left out (the speeds do not enter the active current).
    fn add(&mut self, t: f64, dt_s: f64, p: &SteadyPoint) {
        let v2 = p.v.d * p.v.d + p.v.q * p.v.q;
        let finite = [p.i.d, p.i.q, p.v.d, p.v.q].iter().all(|x| x.is_finite());
        if !(finite
            && v2 > HISTORY_MIN_VOLTAGE_V * HISTORY_MIN_VOLTAGE_V
            && dt_s.is_finite()
            && dt_s > 0.0)
        {
            return;
        }
        let (start, span, sum) = self.open.get_or_insert((t, 0.0, SteadyPoint::default()));
        *span += dt_s;
        sum.add_scaled(p, dt_s as f32);
        if *span >= HISTORY_BLOCK_S * (1.0 - 1e-6) {
            let mut mean = SteadyPoint::default();
            mean.add_scaled(sum, (1.0 / *span) as f32);
            let block = (*start, active_current(&mean));
            self.open = None;
            if !block.1.is_finite() {
                return;
            }
            self.blocks.push_back(block);
            while self
                .blocks
                .front()
                .is_some_and(|(t0, _)| t - t0 > HISTORY_S)
            {
                self.blocks.pop_front();
            }
        }
    }

    /// When the move from `from_a` to `to_a` [A] began [s]: the end of the last block, at
    /// or after `not_before` [s], that was still on the old level (module docs); `None`
    /// where the history holds no crossing of the middle of the two levels after
    /// `not_before`.
    fn onset(&self, from_a: f32, to_a: f32, not_before: f64) -> Option<f64> {
        let mid = 0.5 * (from_a + to_a);
        let sign = (to_a - from_a).signum();
        let still = STILL_FRACTION * (to_a - from_a).abs();
        let new_side = |a: f32| (a - mid) * sign >= 0.0;
        let kept: Vec<&(f64, f32)> = self
            .blocks
            .iter()
            .filter(|(t0, _)| *t0 >= not_before)
            .collect();
        // The newest crossing of the middle: a block on the new side after one on the old.
        let cross = kept
            .windows(2)
            .rposition(|w| matches!(w, [a, b] if !new_side(a.1) && new_side(b.1)))?;
        // Back from it while the older block is further towards the old level by more
        // than `still`.
        let mut k = cross;
        while k > 0 {
            let (Some(older), Some(newer)) = (kept.get(k - 1), kept.get(k)) else {
                break;
            };
            if (newer.1 - older.1) * sign <= still {
                break;
            }
            k -= 1;
        }
        // The onset is the end of block k, the start of the block after it.
        kept.get(k + 1).map(|b| b.0)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use monitor_core::Dq;

    fn point(active_a: f32) -> SteadyPoint {
        // Voltage on d: the active current is i_d.
        SteadyPoint {
            v: Dq { d: 100.0, q: 0.0 },
            i: Dq {
                d: active_a,
                q: -3.0,
            },
            ..SteadyPoint::default()
        }
    }

    #[test]
    fn a_load_move_is_recorded_once_from_the_last_point() {
        let mut log = EventLog::default();
        log.point(1.0, &point(6.0));
        log.point(2.0, &point(6.3)); // +5 %: not a move
        log.point(3.0, &point(4.2)); // -30 %: a move
        log.point(4.0, &point(4.3)); // +2 % from the last recorded: not a move
        let moves: Vec<_> = log.events().to_vec();
        assert_eq!(moves.len(), 1, "{moves:?}");
        match &moves[0] {
            IsolationEvent::LoadMoved { t_s, from_a, to_a } => {
                assert_eq!(*t_s, 3.0);
                assert!((from_a - 6.0).abs() < 1e-6 && (to_a - 4.2).abs() < 1e-6);
            }
            other => panic!("{other:?}"),
        }
    }

    /// A step of the active current from 6 A to `to` A at `step_s` seen through a 2 Hz
    /// critically damped filter (`1 - (1 + w t) e^(-w t)`, written here), sampled at 5 kHz
    /// from 0 to `end_s`, each sample offered to the log and the steady point recorded at
    /// `end_s`.
    fn filtered_step(to: f32, step_s: f64, end_s: f64) -> EventLog {
        let mut log = EventLog::default();
        let w = std::f64::consts::TAU * 2.0;
        let dt = 2e-4;
        log.point(0.5, &point(6.0));
        for k in 0..((end_s / dt) as usize) {
            let t = k as f64 * dt;
            let x = (w * (t - step_s)).max(0.0);
            let a = 6.0 + (to - 6.0) * (1.0 - (1.0 + x) * (-x).exp()) as f32;
            log.sample(t, dt, &point(a));
        }
        log.point(end_s, &point(to));
        log
    }

    #[test]
    fn a_move_is_dated_where_it_began_not_where_it_was_seen() {
        for (to, step_s) in [(8.4, 5.0), (4.2, 3.337), (6.7, 7.21)] {
            let log = filtered_step(to, step_s, step_s + 1.4);
            let began: Vec<f64> = log.events().iter().map(IsolationEvent::t_s).collect();
            assert_eq!(began.len(), 1, "{began:?}");
            // Within one 20 ms block after the step.
            assert!(
                began[0] >= step_s - 1e-9 && began[0] <= step_s + HISTORY_BLOCK_S + 1e-9,
                "step at {step_s} s to {to} A dated {began:?}"
            );
        }
        // A move seen beyond the history's reach keeps the time it was seen.
        let log = filtered_step(8.4, 1.0, 1.0 + HISTORY_S + 2.0);
        assert_eq!(log.events().first().map(IsolationEvent::t_s), Some(13.0));
    }

    #[test]
    fn events_beyond_the_cap_are_counted_not_kept() {
        let mut log = EventLog::default();
        for k in 0..(MAX_EVENTS + 5) {
            // Alternating 5 A and 8 A: every point a move after the first.
            log.point(k as f64, &point(if k % 2 == 0 { 5.0 } else { 8.0 }));
        }
        assert_eq!(log.events().len(), MAX_EVENTS);
        assert_eq!(log.dropped(), 4);
        let json = serde_json::to_value(&log.events()[0]).unwrap_or_default();
        assert_eq!(json["event"], "load_moved");
    }
}
