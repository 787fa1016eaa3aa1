//! Following a running machine with the isolator: the steady operating point averaged,
//! the healthy baseline learned while commissioning, and an isolation every
//! [`STEP_S`]. One home for this schedule: the firmware's thread mode and the host's
//! replay (`sim_host::replay`) both run it.
//!
//! # The operating point
//! The isolation's equations hold in steady state, so the point it is given is an average
//! of the points observed (the monitor's filtered outputs on the board,
//! [`SteadyPoint::from_output`]; the replay's positive-sequence vectors on the host). The
//! points are summed in blocks of [`STEP_S`]; the point isolated is the mean of the last
//! blocks, at least [`AVERAGE_S`] (25 supply periods at 50 Hz, which also averages the frame
//! frequency's ripple) and at most [`AVERAGE_MAX_S`] of steady running. A point is steady
//! while every quantity stays within [`STEADY_FRACTION`] of that mean: the current and
//! voltage vectors by their distance relative to their magnitudes, the two speeds relative
//! to the supply's frequency. A point outside starts the average again from itself (a new
//! operating point: a load step, a supply change), and nothing is isolated until it has
//! been averaged for [`AVERAGE_S`].
//!
//! The residuals' scatter falls as the average grows: measured on simulated healthy runs
//! of the 3 hp, 2.2 kW and 11 kW machines (5 kHz, 12-bit sensors with 0.1 % noise), up to
//! 0.08 % of |V| with a 0.5 s exponential average, 0.022 % with the 2 s mean
//! ([`super::LEARNED_SPREAD_FLOOR`]). So the spreads the isolation judges by are those of
//! the baseline times `sqrt(AVERAGE_MAX_S / averaged)`: a point averaged for 0.5 s is
//! judged with twice the spread of one averaged for 2 s, and a small fault (Rs +10 %: 0.2 %
//! of |V| on the 3 hp machine) is named once the average is long enough to see it.
//! A fault newly named is reported once it has stayed the one named for [`CONFIRM_S`].
//!
//! # Settling, and the onset of a deviation
//! A point that leaves the band of the average has not settled yet: the filters that give
//! the vectors (the monitor's, the host's sequence analysis) are still moving towards the
//! new operating point. The blocks of the first [`SETTLE_S`] after such a restart are
//! dropped, so that the average holds the settled point only (measured on service logs
//! with the load stepping every 4 s: averages that began inside the filters' tail left
//! voltage residuals of 0.3 % of |V| for up to 2 s, ten times the healthy scatter, and a
//! commissioning over the load range learned spreads of 0.1-0.3 % instead of 0.04 %).
//!
//! A change smaller than [`STEADY_FRACTION`] (Ls or Lr +-50 % on the 3 hp machine) does
//! not leave the band: the first isolation that sees a deviation after a healthy one, on a
//! full average ([`AVERAGE_MAX_S`]), averages blocks from before the change with blocks
//! after it. That result is not used: the average is begun again, with the same settling,
//! and the deviation is judged on blocks after it (once per operating point: again only
//! after the point has left the band) (measured on the same service logs: the blend passed the direction of
//! Rs for half a second after an Lr +-50 % step on the 3 hp machine, and Rs was named).
//!
//! A change may also arrive while a deviation is already there (an untracked warming, a
//! fault that names nothing yet), where the onset's rule does not look. So every average of
//! at least twice [`AVERAGE_S`] is split in halves, and where the residuals of the newer
//! half differ from those of the older by more than the healthy scatter allows (less what
//! the winding can have warmed between them, 10 K/s, along the heating direction, so that a
//! winding that warms does not count),
//! the average is begun again after it with the same settling (measured on the isolation's
//! tuning sweep: a rotor-leakage step on a 37 kW motor whose untracked warming already
//! deviated was named `ls` at p 0.93 half a second after the step, from the blend).
//!
//! [`DEFAULT_SPREAD`]: super::DEFAULT_SPREAD

mod band;
mod temperature;

use super::{Isolation, Isolator, SteadyPoint};
use band::SteadyBand;

/// Shortest average of the operating point that is isolated or learned [s] (module docs).
pub const AVERAGE_S: f32 = 0.5;
/// Longest average of the operating point [s]: the mean of the last [`BLOCKS`] blocks.
pub const AVERAGE_MAX_S: f32 = BLOCKS as f32 * STEP_S;
/// Length of one block of the average, and how often the averaged point is isolated (or,
/// while commissioning, learned) [s].
pub const STEP_S: f32 = 0.1;
/// Blocks kept for the average (20 x 24 bytes of state).
pub const BLOCKS: usize = 20;
/// Relative change from the running average above which a point is not steady.
pub const STEADY_FRACTION: f32 = 0.02;
/// How long after a point left the band of the average the blocks are dropped [s] (module
/// docs): the host's 2 Hz critically damped sequence filters leave 0.4 % of a step after
/// 0.5 s, and a step that the band caught at 2 % of the current thus leaves less than 0.01 %.
pub const SETTLE_S: f32 = 0.5;
/// How long a newly named fault must stay the one named before it is reported [s]. A change
/// smaller than [`STEADY_FRACTION`] does not restart the average, which then mixes points
/// from before and after it for up to [`AVERAGE_MAX_S`]; on the way the residuals can pass
/// near another fault's direction (measured: `rr` or `speed_sensor` named for 0.15-0.4 s
/// after an Ls step on a 2-pole 11 kW machine). Withdrawing a name is immediate.
pub const CONFIRM_S: f32 = 0.5;

/// How far the residuals may move the winding's rise from a measured one [K]
/// ([`Follower::set_measured_rise_k`]): a probe's lag behind a winding that warms fast (a
/// thermocouple of 2 s, read every second, 5-10 K behind a winding warming by 3 K/s;
/// measured on the 2.2 kW motor: without the correction a 6 K lag was named a current
/// sensor's 1 % gain error for half a second).
pub const PROBE_LAG_K: f32 = 10.0;

/// Every quantity of `p` within [`STEADY_FRACTION`] of `avg`: the current and voltage
/// vectors by their distance relative to the average's magnitude, the supply and rotor
/// speeds relative to the supply's (at least 1 rad/s).
pub fn steady_against(p: &SteadyPoint, avg: &SteadyPoint) -> bool {
    SteadyBand::of(*avg).admits(p)
}

/// What one [`Follower::observe`] did.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Step {
    /// Nothing new: the point was unusable, not yet averaged long enough, or the step
    /// ([`STEP_S`]) is not due.
    Waiting,
    /// The averaged point went into the baseline being learned.
    Learned,
    /// Learning ended: `true` when the learned baseline went into force (enough points).
    LearningEnded(bool),
    /// The averaged point was isolated and the result is in force (also
    /// [`Follower::last`]).
    Isolated(Isolation),
    /// The averaged point was isolated but names a fault that has not been named for
    /// [`CONFIRM_S`] yet: [`Follower::last`] keeps the previous result.
    Unconfirmed(Isolation),
}

/// The time step `dt_s` [s] as observed: a non-finite or negative value counts as 0.
#[inline]
fn observed_dt(dt_s: f32) -> f32 {
    if dt_s.is_finite() && dt_s > 0.0 {
        dt_s
    } else {
        0.0
    }
}

/// What a result names, for the confirmation: a fault's index, the friction class, or
/// nothing.
fn name_key(iso: &Isolation) -> Option<usize> {
    match iso.named()? {
        super::Named::Fault(c) => Some(c.fault.index()),
        super::Named::Friction { .. } => Some(usize::MAX),
    }
}

/// The isolator with its schedule: averaging, learning, isolating (module docs).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Follower {
    isolator: Isolator,
    /// The block being summed: the dt-weighted sum of its points and its length [s].
    block_sum: SteadyPoint,
    block_s: f32,
    /// The means of the last blocks (a ring), how many are filled and the next slot.
    blocks: [SteadyPoint; BLOCKS],
    filled: usize,
    next: usize,
    /// The mean of the filled blocks and its limits, kept with them (every point is judged
    /// against it).
    mean: Option<SteadyBand>,
    learning: bool,
    /// Time since learning began [s] (the learned points' times).
    learning_s: f32,
    learned: bool,
    last: Option<Isolation>,
    /// The name of the latest isolation, and how long it has been named [s].
    pending: Option<usize>,
    held_s: f32,
    since_isolation_s: f32,
    /// Time left of the settling after a point left the band [s] ([`SETTLE_S`]).
    settling_s: f32,
    /// The average was begun again at the onset of a deviation since the point last left
    /// the band (module docs).
    onset_restarted: bool,
    /// The winding's measured rise since commissioning [K], when a temperature channel
    /// gives it ([`Follower::set_measured_rise_k`]).
    measured_rise_k: Option<f32>,
    /// The residuals' correction of the measured rise (the probe's lag) [K], within
    /// +-[`PROBE_LAG_K`].
    probe_lag_k: f32,
    /// Time since the winding's temperature was last judged (a point found healthy, or
    /// heating tracked) [s]: how far it can have moved since
    /// ([`Isolator::set_heating_reach_k`]).
    since_judged_s: f32,
    /// How fast the winding was last seen to warm or cool [K/s] (the tracked rise's step
    /// over the time since the heating tracked before it), at least
    /// [`super::HEATING_DRIFT_K_PER_S`] once it was seen warming; 0 before.
    warming_k_per_s: f32,
    /// Time since the heating was last tracked [s].
    since_tracked_s: f32,
    /// Where the size searches of the point's isolation, and of its check on the
    /// stator-voltage equations alone, found each fault the last time (module docs of
    /// [`crate::isolation`], "Searches started from the last result").
    hints: super::SearchHints,
    voltage_hints: super::SearchHints,
}

impl Follower {
    /// Follows with `isolator` (its baseline in force: the default, or one set with
    /// [`Isolator::set_baseline`]).
    pub fn new(isolator: Isolator) -> Self {
        Follower {
            isolator,
            block_sum: SteadyPoint::default(),
            block_s: 0.0,
            blocks: [SteadyPoint::default(); BLOCKS],
            filled: 0,
            next: 0,
            mean: None,
            learning: false,
            learning_s: 0.0,
            learned: false,
            last: None,
            pending: None,
            held_s: 0.0,
            since_isolation_s: 0.0,
            settling_s: 0.0,
            onset_restarted: false,
            measured_rise_k: None,
            probe_lag_k: 0.0,
            since_judged_s: 0.0,
            warming_k_per_s: 0.0,
            since_tracked_s: 0.0,
            hints: super::SearchHints::default(),
            voltage_hints: super::SearchHints::default(),
        }
    }

    /// The winding's rise since commissioning measured by a temperature channel [K]
    /// (`Some`), or none (`None`: the rise is tracked from the resistances again, from
    /// the factor last in force). A measured rise anchors the tracking: the isolator's Rs
    /// and Rr are `1 + alpha (rise_k + lag)` times the commissioned ones
    /// ([`Isolator::set_winding_rise_k`]), where the residuals' heating fit moves `lag`
    /// (the probe's lag behind the winding) within +-[`PROBE_LAG_K`] only: the rise
    /// itself is the channel's, not inferred from the residuals.
    /// Returns false for a rise the isolator refuses (not finite, or beyond 25 K cooler
    /// .. 160 K warmer): then no measured rise is in force, as with `None`.
    pub fn set_measured_rise_k(&mut self, rise_k: Option<f32>) -> bool {
        let ok = rise_k.is_some_and(|r| self.isolator.set_winding_rise_k(r));
        self.measured_rise_k = if ok { rise_k } else { None };
        match self.measured_rise_k {
            Some(r) if self.probe_lag_k != 0.0 => {
                // (Within the range, or the measured rise alone.)
                self.isolator.set_winding_rise_k(r + self.probe_lag_k);
            }
            Some(_) => {}
            None => self.probe_lag_k = 0.0,
        }
        ok || rise_k.is_none()
    }

    /// The residuals' correction of the measured rise in force [K] (the probe's lag,
    /// within +-[`PROBE_LAG_K`]; 0 without a measured rise).
    pub fn probe_lag_k(&self) -> f32 {
        self.probe_lag_k
    }

    /// The measured rise in force ([`Follower::set_measured_rise_k`]) [K].
    pub fn measured_rise_k(&self) -> Option<f32> {
        self.measured_rise_k
    }

    /// One observed point `p`, `dt_s` [s] after the previous observation (> 0; a
    /// non-finite or negative value counts as 0).
    ///
    /// `usable`: the point may be used (the monitor has settled and evaluates, no sensor
    /// fault); an unusable point drops the average. `learning`: commissioning is learning
    /// the healthy machine now; averaged points then go into the baseline, and its end puts
    /// the learned baseline into force ([`Isolator::finish_learning`]: at least [`super::MIN_LEARNED_POINTS`] points,
    /// half a second of steady running). A point that is not steady against the average
    /// restarts it.
    pub fn observe(&mut self, p: &SteadyPoint, dt_s: f32, usable: bool, learning: bool) -> Step {
        let dt = observed_dt(dt_s);
        // Saturate: only "long enough or not" matters.
        self.since_isolation_s = crate::math::minf(self.since_isolation_s + dt, 2.0 * CONFIRM_S);
        // (Saturates where the reach covers the whole range: 185 K at 10 K/s.)
        self.since_judged_s = crate::math::minf(self.since_judged_s + dt, 20.0);
        self.since_tracked_s = crate::math::minf(self.since_tracked_s + dt, 1000.0);
        let ended = self.follow_learning(learning, dt);
        if !usable {
            self.restart();
            return ended.map_or(Step::Waiting, Step::LearningEnded);
        }
        if !self.sum_point(p, dt) {
            return ended.map_or(Step::Waiting, Step::LearningEnded);
        }
        self.close_block();
        if let Some(ok) = ended {
            return Step::LearningEnded(ok);
        }
        self.step_averaged(learning)
    }

    /// Follows commissioning's `learning` flag over `dt` [s]: its end puts the learned
    /// baseline into force (`Some(true)` when it went into force, `Some(false)` when it did
    /// not), its start sets the learning time to 0; `None` when learning did not end.
    #[inline]
    fn follow_learning(&mut self, learning: bool, dt: f32) -> Option<bool> {
        let mut ended = None;
        if self.learning && !learning {
            let ok = self.isolator.finish_learning();
            self.learned |= ok;
            ended = Some(ok);
        }
        if learning && !self.learning {
            self.learning_s = 0.0;
        }
        if learning {
            self.learning_s += dt;
        }
        self.learning = learning;
        ended
    }

    /// Sums the usable point `p`, weighted by `dt` [s], into the block (a point outside the
    /// band restarts the average and the settling, [`SETTLE_S`]). True when the block is
    /// [`STEP_S`] long and settled, to be closed; a block that ends while settling is
    /// dropped (module docs).
    #[inline]
    fn sum_point(&mut self, p: &SteadyPoint, dt: f32) -> bool {
        if self.reference().is_some_and(|r| !r.admits(p)) {
            self.restart();
            self.settling_s = SETTLE_S;
            self.onset_restarted = false;
        } else {
            self.settling_s = crate::math::maxf(self.settling_s - dt, 0.0);
        }
        self.block_sum.add_scaled(p, dt);
        self.block_s += dt;
        // (Float sums of the time steps: a thousandth of slack.)
        if self.block_s < 0.999 * STEP_S {
            return false;
        }
        if self.settling_s > 0.0 {
            // Still settling: the block is dropped (module docs).
            self.block_sum = SteadyPoint::default();
            self.block_s = 0.0;
            return false;
        }
        true
    }

    /// After a block closed: the averaged point learned (`learning`) or isolated, once it
    /// has been averaged for [`AVERAGE_S`]; [`Step::Waiting`] before.
    fn step_averaged(&mut self, learning: bool) -> Step {
        let averaged_s = self.filled as f32 * STEP_S;
        let Some(avg) = self.mean() else {
            return Step::Waiting;
        };
        // Float sums of 0.1 s steps: half a step of slack.
        if averaged_s < AVERAGE_S - 0.5 * STEP_S {
            return Step::Waiting;
        }
        if learning {
            // (The averaged point's time: the middle of its blocks.)
            let t = crate::math::maxf(self.learning_s - 0.5 * averaged_s, 0.0);
            self.isolator.learn_at(&avg, t);
            Step::Learned
        } else {
            self.isolate_averaged(&avg, averaged_s)
        }
    }

    /// Isolates the point `avg` averaged for `averaged_s` [s], its spreads scaled by
    /// `sqrt(AVERAGE_MAX_S / averaged_s)`: heating is tracked and the point judged again;
    /// the onset of a deviation begins the average again ([`Step::Waiting`]); else the
    /// result goes to the confirmation ([`Follower::confirm`]).
    fn isolate_averaged(&mut self, avg: &SteadyPoint, averaged_s: f32) -> Step {
        if self.changed_within() {
            // A change inside the average (module docs): begun again after it.
            self.restart();
            self.settling_s = SETTLE_S;
            return Step::Waiting;
        }
        let scale = crate::math::sqrt(AVERAGE_MAX_S / averaged_s);
        // How far the winding can have moved since its temperature was last judged.
        self.isolator
            .set_heating_reach_k(self.since_judged_s, self.warming_k_per_s);
        let mut result = self
            .isolator
            .isolate_scaled_from(avg, scale, &mut self.hints);
        let onset = self.at_onset();
        let heating = self.heating_in(&result, onset);
        if self.learned && heating {
            // Heating is not a fault: the machine judged against warms with the winding,
            // and the point is judged again (module docs of `crate::isolation`).
            self.track_with_rate(result.heating.factor);
            result = self
                .isolator
                .isolate_scaled_from(avg, scale, &mut self.hints);
        }
        self.note_temperature((&result, avg, scale), self.learned && heating);
        let deviates = matches!(
            result.state,
            super::IsolationState::Isolated | super::IsolationState::Unknown
        );
        if deviates && !heating && onset {
            // The onset of a deviation: the average is begun again after it (module
            // docs).
            self.onset_restarted = true;
            self.restart();
            self.settling_s = SETTLE_S;
            return Step::Waiting;
        }
        self.confirm(result)
    }

    /// A deviation now would be an onset (module docs): the latest result in force was
    /// healthy (or none), the average is full ([`BLOCKS`]) and was not begun again at an
    /// onset since the point last left the band.
    fn at_onset(&self) -> bool {
        let was_healthy = self
            .last
            .is_none_or(|l| l.state == super::IsolationState::NoDeviation);
        // (Only a full average can hold blocks from before a change that stayed inside
        // the band; one begun after a band restart cannot.)
        let full = self.filled >= BLOCKS;
        was_healthy && full && !self.onset_restarted
    }

    /// `result` is read as heating: it explains the residuals, or continues a warming of
    /// at least [`super::WARMING_K`] in force, or begins one away from an `onset`.
    fn heating_in(&self, result: &Isolation, onset: bool) -> bool {
        let warming = self.isolator.winding_rise_k().abs() >= super::WARMING_K;
        // (A warming that begins is judged on blocks after the onset, as a fault is:
        // the blend of a step fault's onset can fit a small heating best.)
        result.heating_explains()
            || (warming && result.heating_continues())
            || (!onset && result.heating_begins())
    }

    /// Drops the average: the next point starts a new one.
    fn restart(&mut self) {
        self.block_sum = SteadyPoint::default();
        self.block_s = 0.0;
        self.filled = 0;
        self.mean = None;
    }

    /// The point the next one is judged steady against: the mean of the blocks, else the
    /// block being summed; `None` before any point.
    fn reference(&self) -> Option<SteadyBand> {
        self.mean.or_else(|| {
            (self.block_s > 0.0).then(|| {
                let mut m = self.block_sum;
                m.scale(1.0 / self.block_s);
                SteadyBand::of(m)
            })
        })
    }

    /// Ends the block being summed: its mean goes into the ring.
    fn close_block(&mut self) {
        let mut m = self.block_sum;
        m.scale(1.0 / self.block_s);
        if let Some(slot) = self.blocks.get_mut(self.next) {
            *slot = m;
        }
        self.next = (self.next + 1) % BLOCKS;
        self.filled = core::cmp::min(self.filled + 1, BLOCKS);
        self.block_sum = SteadyPoint::default();
        self.block_s = 0.0;
        self.mean = self.blocks_mean().map(SteadyBand::of);
    }

    /// The mean of the filled blocks; `None` before the first (kept by
    /// [`Follower::close_block`] and [`Follower::restart`], the only changes of the blocks).
    fn mean(&self) -> Option<SteadyPoint> {
        self.mean.map(|b| b.avg)
    }

    /// [`Follower::mean`] computed from the blocks.
    fn blocks_mean(&self) -> Option<SteadyPoint> {
        if self.filled == 0 {
            return None;
        }
        // The filled blocks are the `filled` slots before `next` (ring order).
        let mut sum = SteadyPoint::default();
        for k in 0..self.filled {
            let slot = (self.next + BLOCKS - 1 - k) % BLOCKS;
            if let Some(b) = self.blocks.get(slot) {
                sum.add_scaled(b, 1.0);
            }
        }
        sum.scale(1.0 / self.filled as f32);
        Some(sum)
    }

    /// Puts `result` into force unless it names a fault not yet named for [`CONFIRM_S`].
    fn confirm(&mut self, result: Isolation) -> Step {
        let key = name_key(&result);
        if key == self.pending {
            self.held_s = crate::math::minf(self.held_s + self.since_isolation_s, 2.0 * CONFIRM_S);
        } else {
            self.pending = key;
            self.held_s = 0.0;
        }
        self.since_isolation_s = 0.0;
        if key.is_none() || self.held_s >= CONFIRM_S {
            self.last = Some(result);
            Step::Isolated(result)
        } else {
            Step::Unconfirmed(result)
        }
    }

    /// The averaged operating point the latest isolation judged, with its spread scale
    /// `sqrt(AVERAGE_MAX_S / averaged)` (the evidence [`Isolator::isolate_points`] combines);
    /// `None` before [`AVERAGE_S`] of steady running.
    pub fn averaged(&self) -> Option<(SteadyPoint, f32)> {
        let averaged_s = self.filled as f32 * STEP_S;
        if averaged_s < AVERAGE_S - 0.5 * STEP_S {
            return None;
        }
        Some((self.mean()?, crate::math::sqrt(AVERAGE_MAX_S / averaged_s)))
    }

    /// Whether [`Follower::observe`] would find `p` steady against the mean of the blocks
    /// (and not restart the average); `None` where there is no such mean (before the
    /// first block closes, the point is judged against the block being summed, which every
    /// point moves). For a caller that hands on the means of several points at once (the
    /// host's replay) and each point alone where it is not steady.
    #[inline]
    pub fn steady(&self, p: &SteadyPoint) -> Option<bool> {
        self.mean.map(|b| b.admits(p))
    }

    /// [`Follower::steady`] in two parts: whether the current and voltage vectors of `p`
    /// are steady (this), and its speeds ([`Follower::steady_speeds`]); `steady(p)` is
    /// `Some(a && b)` of the two. For a caller whose points keep their vectors over many
    /// rows (the host's replay: the sequence analysis' vectors move once per block), which
    /// checks them again only when they or the mean changed (the mean changes only in
    /// [`Follower::observe`]).
    #[inline]
    pub fn steady_vectors(&self, p: &SteadyPoint) -> Option<bool> {
        self.mean.map(|b| b.admits_vectors(p))
    }

    /// The speeds' part of [`Follower::steady`] ([`Follower::steady_vectors`]).
    #[inline]
    pub fn steady_speeds(&self, p: &SteadyPoint) -> Option<bool> {
        self.mean.map(|b| b.admits_speeds(p))
    }

    /// Time left until the block being summed is [`STEP_S`] long and closes [s] (a caller
    /// that hands on several points at once ends its sum there, where the follower's block
    /// ends point by point).
    pub fn block_left_s(&self) -> f32 {
        0.999 * STEP_S - self.block_s
    }

    /// The latest isolation in force, if any was made.
    pub fn last(&self) -> Option<&Isolation> {
        self.last.as_ref()
    }

    /// Forgets the latest isolation (for example when the machine stops: the next one
    /// comes after [`AVERAGE_S`] of steady running).
    pub fn clear(&mut self) {
        self.last = None;
        self.pending = None;
        self.held_s = 0.0;
    }

    /// Puts a baseline learned in an earlier commissioning into force (the firmware's
    /// flash record) and counts it as learned ([`Follower::learned`]). Returns false, and
    /// changes nothing, for a baseline [`Isolator::set_baseline`] refuses.
    pub fn restore_learned(&mut self, b: super::Baseline) -> bool {
        let ok = self.isolator.set_baseline(b).is_ok();
        self.learned |= ok;
        ok
    }

    /// A baseline learned in commissioning is in force.
    pub fn learned(&self) -> bool {
        self.learned
    }

    /// The isolator (its baseline, its torque scale).
    pub fn isolator(&self) -> &Isolator {
        &self.isolator
    }
}
