//! Evidence across operating points: once the isolation sees a deviation, the steady
//! operating points the motor visits are kept (one per load level) and every hypothesis is
//! fitted over all of them together ([`Isolator::isolate_points`](super::Isolator::isolate_points),
//! the stator-voltage equations only: the load at each point is an unknown input). Faults
//! that coincide at one point (on the 3 hp motor at rated load Ls, Rr and the speed sensor)
//! part over two load levels 20 % apart or more.
//!
//! The last point judged healthy before the deviation is kept as the *anchor*: where the
//! load (the active current) has not moved since, the load is the torque the machine gave
//! there, and the joint fit compares each hypothesis' torque at the first point of the
//! deviation with it (`Isolator::isolate_points_anchored`; that point is kept while the
//! deviation lasts). A sensor gain step, which moves neither the
//! machine nor its load, is judged with it from the first point after the step: a current
//! sensor's error scales the torque computed from the currents, a voltage sensor's does
//! not (the stator-voltage equations alone see the two alike).
//!
//! No allocation: the points are kept in an array of [`MAX_POINTS`]; the host's replay and
//! the firmware's thread mode run this same code.

use super::{Follower, Isolation, IsolationState, Named, SearchHints, SteadyPoint, MAX_POINTS};

/// Smallest relative difference of the load (the active current) between two kept points:
/// 15 %, so that two points are two operating points and not one seen twice.
pub const LEVEL_APART: f32 = 0.15;

/// Largest relative difference of the active current at which a later point replaces the
/// first one (the same operating point averaged again): 2 %, the follower's steadiness
/// band (`monitor_core::isolation::STEADY_FRACTION`).
const SAME_POINT: f32 = super::STEADY_FRACTION;

/// Largest deviation of the stator-voltage equations alone [standard deviations] at which
/// a point the single isolation reads as the friction class counts as a load that moved:
/// 2, half the detection threshold (a fault that moves the voltage equations a little, Ls
/// on the 3 hp machine at one load level, stays evidence).
const LOAD_MOVED_SIGMA: f32 = 2.0;

/// The active current of a steady point [A] ([`SteadyPoint::operating_point`]).
fn active_current(p: &SteadyPoint) -> f32 {
    p.operating_point().load_a
}

/// The kept points and the joint isolation over them.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct Evidence {
    /// The points kept (the first `len`), each with its spread scale.
    points: [(SteadyPoint, f32); MAX_POINTS],
    len: usize,
    joint: Option<Isolation>,
    /// The last averaged point judged healthy (no deviation) before the points kept.
    anchor: Option<SteadyPoint>,
    /// Where the size searches of the joint fit, and of the load's check on one point,
    /// found each fault the last time (module docs of [`crate::isolation`], "Searches
    /// started from the last result").
    hints: SearchHints,
    moved_hints: SearchHints,
}

impl Evidence {
    /// After an isolation `result` of the follower: a deviation keeps the averaged point
    /// (replacing the one at its load level, else added, the oldest dropped beyond
    /// [`MAX_POINTS`], except the first with an anchor) and refits jointly; no deviation, or
    /// one the stator-voltage equations do not see (the load moved), forgets the evidence
    /// and makes the averaged point the anchor.
    pub fn after(&mut self, follower: &Follower, result: &Isolation) {
        if !matches!(
            result.state,
            IsolationState::Isolated | IsolationState::Unknown
        ) || result.heating_explains()
        {
            self.forget();
            if result.state == IsolationState::NoDeviation {
                self.anchor = follower.averaged().map(|(p, _)| p);
            }
            return;
        }
        let Some((p, scale)) = follower.averaged() else {
            return;
        };
        if self.load_moved(follower, result, &(p, scale)) {
            self.forget();
            self.anchor = Some(p);
            return;
        }
        let a = active_current(&p);
        if !a.is_finite() {
            return;
        }
        self.keep(p, scale, a);
        let enough = self.len >= 2 || self.anchor.is_some();
        let kept = self.points.get(..self.len).unwrap_or(&[]);
        self.joint = enough.then(|| {
            follower.isolator().isolate_points_anchored_from(
                kept,
                self.anchor.as_ref(),
                &mut self.hints,
            )
        });
    }

    /// Forgets the points kept and the joint isolation (the anchor stays).
    fn forget(&mut self) {
        self.len = 0;
        self.joint = None;
    }

    /// The deviation `result` of the averaged `point` (with its spread scale) is a load
    /// that moved, not a fault: the single point reads it as the friction class, no
    /// evidence is kept yet, and the stator-voltage equations alone deviate by less than
    /// [`LOAD_MOVED_SIGMA`].
    fn load_moved(
        &mut self,
        follower: &Follower,
        result: &Isolation,
        point: &(SteadyPoint, f32),
    ) -> bool {
        // A deviation the single point reads as the friction class that the stator-voltage
        // equations do not see (within LOAD_MOVED_SIGMA: the load moved) is an
        // operating-point change, not a fault: before any evidence of a fault it is the new
        // anchor. After such evidence it is one more operating point of the joint fit (an
        // Ls change on the 3 hp machine at half load moves the voltage equations by less
        // than LOAD_MOVED_SIGMA; the points before the load move still tell it).
        let iso = follower.isolator();
        let friction = matches!(result.named(), Some(Named::Friction { .. }));
        friction
            && self.len == 0
            && iso
                .isolate_points_anchored_from(
                    core::slice::from_ref(point),
                    None,
                    &mut self.moved_hints,
                )
                .deviation
                < LOAD_MOVED_SIGMA
    }

    /// Keeps the point `p` (spread scale `scale`, active current `a` [A]): it replaces the
    /// kept point at its load level (within [`LEVEL_APART`]), except a first point compared
    /// with the anchor, else it is added ([`Evidence::push`]).
    fn keep(&mut self, p: SteadyPoint, scale: f32, a: f32) {
        let same_level = self.kept().iter().position(|(q, _)| {
            let b = active_current(q);
            (a - b).abs() < LEVEL_APART * b.abs().max(a.abs())
        });
        match same_level {
            // The first point, compared with the anchor's load, gives way only to a later
            // average of the same operating point before the load has moved (the first may
            // have begun inside the change).
            Some(0) if self.anchor.is_some() && (self.len > 1 || !self.same_point_as_first(a)) => {}
            Some(k) => {
                if let Some(slot) = self.kept_mut().get_mut(k) {
                    *slot = (p, scale);
                }
            }
            None => self.push(p, scale),
        }
    }

    /// Adds the point `p` (spread scale `scale`) after the kept ones; beyond
    /// [`MAX_POINTS`] the oldest is dropped (the oldest after the first with an anchor).
    fn push(&mut self, p: SteadyPoint, scale: f32) {
        if self.len >= MAX_POINTS {
            // The first point, at the anchor's load, is the one the torque
            // comparison holds for: the oldest after it goes.
            let oldest = usize::from(self.anchor.is_some() && self.len > 1);
            if let Some(tail) = self.kept_mut().get_mut(oldest..) {
                tail.rotate_left(1);
            }
            self.len -= 1;
        }
        if let Some(slot) = self.points.get_mut(self.len) {
            *slot = (p, scale);
            self.len += 1;
        }
    }

    /// The points kept, oldest first.
    fn kept(&self) -> &[(SteadyPoint, f32)] {
        self.points.get(..self.len).unwrap_or(&[])
    }

    /// The points kept, oldest first, to change in place.
    fn kept_mut(&mut self) -> &mut [(SteadyPoint, f32)] {
        self.points.get_mut(..self.len).unwrap_or(&mut [])
    }

    /// The active current `a` is within [`SAME_POINT`] of the first point's.
    fn same_point_as_first(&self, a: f32) -> bool {
        self.kept().first().is_some_and(|(q, _)| {
            let b = active_current(q);
            (a - b).abs() <= SAME_POINT * b.abs()
        })
    }

    /// The joint isolation compares the first point's torque with the load at an anchor
    /// (the last point judged healthy before the deviation).
    pub fn anchored(&self) -> bool {
        self.anchor.is_some()
    }

    /// The joint isolation in force beside the single point's latest result `single`, with
    /// the number of points (the one rule the host's replay and the firmware share): the
    /// joint fit's when it names a fault ([`Evidence::named`]) while `single` deviates and
    /// names none. The friction class of `single` does not count as a name: to the paper's
    /// model a load that moved is a Bl change, and the joint fit, which treats the load as
    /// an unknown input, may name the electrical fault behind it.
    pub fn joint_beside(&self, single: &Isolation) -> Option<(&Isolation, usize)> {
        let (_, n) = self.named()?;
        let joint = self.joint.as_ref()?;
        let names_a_fault = matches!(single.named(), Some(Named::Fault(_)));
        (!names_a_fault && single.state != IsolationState::NoDeviation).then_some((joint, n))
    }

    /// The isolation in force: [`Evidence::joint_beside`]'s, else `single`.
    pub fn in_force<'a>(&'a self, single: &'a Isolation) -> &'a Isolation {
        self.joint_beside(single).map_or(single, |(j, _)| j)
    }

    /// The joint isolation when it names a fault (not the friction class, which the
    /// voltage equations cannot judge) that explains every point within the healthy
    /// scatter (its misfit within `sqrt(16 n)` for n points), and the number of points.
    pub fn named(&self) -> Option<(Isolation, usize)> {
        let j = self.joint?;
        let n = self.len;
        match j.named()? {
            Named::Fault(c) if c.misfit * c.misfit <= super::DETECT_CHI2 * n as f32 => Some((j, n)),
            _ => None,
        }
    }
}
