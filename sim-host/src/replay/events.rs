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

use super::isolation::IsolationName;
use monitor_core::SteadyPoint;
use serde::Serialize;

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
        /// When [s] (the replay's time of the steady point that showed it).
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

    /// One line for the text report, e.g. `  601.70 s  load moved: active current 6.21 ->
    /// 4.36 A (-30 %)` or `3000.50 s  named rr +20 % (p 0.99)`.
    pub fn line(&self) -> String {
        match self {
            IsolationEvent::Named {
                t_s,
                name,
                change,
                probability,
            } => {
                // A size under 10 % to a tenth of a per cent: "+0 %" says nothing.
                let digits = usize::from(change.abs() < 0.095);
                format!(
                    "{t_s:9.2} s  named {name} {:+.digits$} % (p {probability:.2})",
                    100.0 * change
                )
            }
            IsolationEvent::LoadMoved { t_s, from_a, to_a } => format!(
                "{t_s:9.2} s  load moved: active current {from_a:.2} -> {to_a:.2} A ({:+.0} %), an operating-point change",
                100.0 * (to_a / from_a - 1.0)
            ),
        }
    }
}

/// The events of a replay, in time order.
#[derive(Debug, Clone, Default)]
pub(super) struct EventLog {
    events: Vec<IsolationEvent>,
    /// The active current of the last steady point recorded [A].
    load_a: Option<f32>,
    dropped: usize,
}

impl EventLog {
    /// After a steady operating point `p` judged at `t`: a load move if its active current
    /// moved by [`LOAD_MOVE_FRACTION`] or more from the last point recorded.
    pub(super) fn point(&mut self, t: f64, p: &SteadyPoint) {
        let a = active_current(p);
        if !a.is_finite() {
            return;
        }
        match self.load_a {
            Some(a0) if (a - a0).abs() >= LOAD_MOVE_FRACTION * a0.abs() => {
                self.push(IsolationEvent::LoadMoved {
                    t_s: t,
                    from_a: a0,
                    to_a: a,
                });
                self.load_a = Some(a);
            }
            Some(_) => {}
            None => self.load_a = Some(a),
        }
    }

    /// The commissioned operating point, where no steady point was recorded yet: the load
    /// the first move is measured from.
    pub(super) fn seed(&mut self, p: &SteadyPoint) {
        let a = active_current(p);
        if self.load_a.is_none() && a.is_finite() {
            self.load_a = Some(a);
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

    fn push(&mut self, e: IsolationEvent) {
        if self.events.len() < MAX_EVENTS {
            self.events.push(e);
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
        assert!(moves[0].line().contains("(-30 %)"), "{}", moves[0].line());
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
