//! The fault isolation of a replay: the core's [`Isolator`] fed from the monitor's
//! outputs, its baseline learned over the commissioning window, and what `diagnose`
//! reports about it (JSON `isolation`, the candidates' `change`).
//!
//! The isolator works on a steady operating point: the positive-sequence voltage and current
//! vectors of the replay's sequence analysis (one angle from a PLL on the voltages, so the
//! point does not depend on the monitor's frame, which a speed-sensor or rotor-parameter
//! fault detunes), the PLL's frequency and the monitor's electrical speed (encoder),
//! averaged once the monitor has settled, with no sensor fault, and isolated (or, while
//! commissioning learns, added to the baseline) on the core's schedule
//! ([`monitor_core::isolation::Follower`]: the same code the firmware runs; the firmware
//! feeds it the monitor's own outputs, [`SteadyPoint::from_output`]).

mod chunk;
mod report;
mod resistances;
pub mod said;
mod stage;

pub use resistances::ResistanceReading;
pub(crate) use stage::{IsolationClosing, IsolationFinding, IsolationInput};

pub use crate::isolation_name::{IsolationName, NameGiven};
use crate::stage::RowFlags;
use monitor_core::isolation::{Follower, Named, Step, DEFAULT_SPREAD};
use monitor_core::{Fault, Isolation, IsolationState, Isolator, SteadyPoint};
use report::refine_single_phase;
use report::{baseline_name, groups, REPORTED_RISE_K};
pub use report::{
    state_name, DetectionLimit, FaultCandidate, GroupWhy, IsolationBaseline, IsolationGroup,
    IsolationReport,
};
use serde::Serializer;

/// No vectors checked yet ([`IsolationTracker::steady`]).
const NO_VECTORS: ([f32; 4], bool) = ([f32::NAN; 4], false);

/// A reported isolation older than this at the log's end says so [s].
pub const STALE_S: f64 = 1.0;

/// A candidate is listed from this probability on.
pub const LIST_FROM: f32 = 0.01;

/// Serialises an [`IsolationState`] by its report name ([`state_name`]), for
/// `#[serde(serialize_with = "serialize_state")]` on a report's field (the studies' rows).
pub fn serialize_state<S: Serializer>(state: &IsolationState, s: S) -> Result<S::Ok, S::Error> {
    s.serialize_str(state_name(*state))
}

/// Follows the monitor's outputs and isolates (the core's [`Follower`] schedule).
pub(super) struct IsolationTracker {
    follower: Option<Follower>,
    first_named: Option<NameGiven>,
    /// Every name given, with the first time it was given [s].
    names: Vec<NameGiven>,
    /// The monitor has evaluated once (settled, voltage present).
    running: bool,
    /// Time of the last isolation and of the last sample [s].
    last_t: f64,
    end_t: f64,
    /// The operating point of the last isolation.
    last_point: SteadyPoint,
    /// The sample interval [s].
    dt_s: f64,
    /// Rs and Rr read apart at each isolation's point ([`resistances`]).
    resistances: resistances::ResistanceSums,
    /// A lamp lit while lamps counted.
    lamps_lit: bool,
    /// The operating points kept since a deviation, and their joint isolation.
    evidence: monitor_core::isolation::Evidence,
    /// What is known of the load ([`super::options::LoadModel`]).
    load: super::options::LoadModel,
    /// Names and load moves, with times.
    events: super::events::EventLog,
    /// The log's temperature channel (`t_winding_c`), when it has one.
    temperature: super::temperature::TemperatureChannel,
    /// The rows not yet handed to the follower and the events ([`chunk`]), and the most
    /// rows of a chunk (the core's block).
    chunk: chunk::RowChunk,
    chunk_rows: u32,
    /// The time left in the follower's block after the last chunk [s]: a chunk ends where
    /// the block does.
    block_left_s: f64,
    /// [`IsolationTracker::load_explains_lamps`], as of the last chunk (its inputs change
    /// only there).
    load_explains: bool,
    /// The last point's current and voltage vectors `(i_d, i_q, v_d, v_q)` checked, and
    /// whether the follower found them steady ([`IsolationTracker::steady`]); NaN: none
    /// (forgotten at each flush: the follower's mean moves only there).
    vectors_seen: ([f32; 4], bool),
}

/// With the load an unknown input, B and Bl are not candidates (their change is the load's
/// move): their probabilities are set to zero and they go last, so that no list, group or
/// sentence offers them (the others keep their probabilities). Applied after the name is
/// decided ([`IsolationTracker::report`]).
fn without_friction(iso: &mut Isolation) {
    for c in iso.candidates.iter_mut() {
        if matches!(c.fault, Fault::B | Fault::Bl) {
            c.probability = 0.0;
        }
    }
    iso.candidates
        .sort_by(|a, b| b.probability.total_cmp(&a.probability));
}

/// The candidates `diagnose` lists for `iso` when `shown` (a lamp lit or a name given, or
/// a deviation from a learned baseline; most probable first, those from [`LIST_FROM`] on;
/// an unknown fault's three nearest only; none without a deviation).
fn listed_candidates(iso: &Isolation, shown: bool) -> Vec<FaultCandidate> {
    if !shown || iso.state == IsolationState::NoDeviation {
        return Vec::new();
    }
    let listed = if iso.state == IsolationState::Unknown {
        3
    } else {
        iso.candidates.len()
    };
    iso.candidates
        .iter()
        .take(listed)
        .filter(|c| c.probability >= LIST_FROM)
        .map(FaultCandidate::from)
        .collect()
}

/// `n` is the friction class while the load is an unknown input: a load move, not a name
/// ([`super::options::LoadModel::Unknown`]).
fn load_reading(load: super::options::LoadModel, n: &Named) -> bool {
    load == super::options::LoadModel::Unknown && matches!(n, Named::Friction { .. })
}

/// What the report concludes from ([`IsolationTracker::concluded`]).
struct Concluded {
    /// The isolation judged (joint or single, the load's move read as no deviation).
    iso: Isolation,
    /// The joint fit and its number of points, where it is the one judged.
    joint: Option<(Isolation, usize)>,
    /// The friction class was read as the load's move.
    load_moved: bool,
}

/// How far a parameter file's values may be off the machine's (nameplate estimates are
/// 10-30 % off): against the nominal parameters (no commissioning), a change this small or
/// smaller, with every lamp dark, is the file's own error as much as a fault, and is not
/// named; with lamps lit it is no FAULT (the one verdict's table, `monitor_core::verdict`).
/// The core's constant, re-exported.
pub use monitor_core::isolation::NOMINAL_UNCERTAINTY;

impl IsolationTracker {
    /// A tracker for the nominal machine (`None`: a machine the isolator rejects, then
    /// nothing is isolated and the report says so), of a log with a temperature column
    /// (`temperature_column`) or without, as `opts` ask (what is known of the load).
    /// `chunk_rows`: the most rows whose points are handed on together (the core's block of
    /// `decimation` samples, [`chunk`]; at least 1).
    pub(crate) fn new(
        isolator: Option<Isolator>,
        temperature_column: bool,
        opts: &super::options::ReplayOptions,
        (dt_s, chunk_rows): (f64, u32),
    ) -> Self {
        let load = opts.load;
        let isolator = isolator.map(|mut i| {
            i.set_load_unknown(load == super::options::LoadModel::Unknown);
            i
        });
        IsolationTracker {
            follower: isolator.map(Follower::new),
            first_named: None,
            names: Vec::new(),
            running: false,
            last_t: 0.0,
            end_t: 0.0,
            last_point: SteadyPoint::default(),
            dt_s,
            resistances: resistances::ResistanceSums::default(),
            lamps_lit: false,
            evidence: monitor_core::isolation::Evidence::default(),
            load,
            events: super::events::EventLog::default(),
            temperature: super::temperature::TemperatureChannel::new(temperature_column),
            chunk: chunk::RowChunk::default(),
            chunk_rows: chunk_rows.max(1),
            block_left_s: 0.0,
            load_explains: false,
            vectors_seen: NO_VECTORS,
        }
    }

    /// After the monitor's output for the sample at `t` (`dt_s` after the previous one);
    /// `flags`: the output's flags ([`RowFlags`]), their `counts` whether the lamps and
    /// detections count now (the learned thresholds are in force, or none were asked for)
    /// and the monitor has settled after a restart; `point`: the steady-state vectors at
    /// this sample (module docs); `temperature_c`: the log's temperature reading, if it has the column. The point goes
    /// into the chunk of rows handed on together ([`chunk`]; [`IsolationTracker::flush`]).
    #[inline]
    fn after(&mut self, t: f64, flags: RowFlags, point: &SteadyPoint, temperature_c: Option<f64>) {
        self.end_t = t;
        if self.follower.is_none() {
            return;
        }
        if self.chunk.ends_before(flags) {
            self.flush();
        }
        if let Some(follower) = self
            .follower
            .as_mut()
            .filter(|_| self.temperature.present())
        {
            self.temperature
                .put_in_force(follower, t, temperature_c, flags.learning());
        }
        // A point the follower judges against a moving reference, or would not find steady,
        // goes alone, after the rows before it: its average restarts where it would row by
        // row ([`chunk`]).
        let alone = self.usable_with(flags) && self.steady(point) != Some(true);
        if alone {
            self.flush();
        }
        let rows = self.chunk.add(t, self.dt_s, point, flags);
        if rows >= self.chunk_rows || alone || self.chunk.span_s() >= self.block_left_s {
            self.flush();
        }
    }

    /// The follower's [`Follower::steady`] of `point`: its speeds checked on every row, its
    /// vectors only where they differ from the last row's to the bit (the sequence
    /// analysis' vectors move once per block; the follower's mean only at a flush, which
    /// forgets the last check): the same answer.
    #[inline]
    fn steady(&mut self, point: &SteadyPoint) -> Option<bool> {
        let f = self.follower.as_ref()?;
        if !f.steady_speeds(point)? {
            return Some(false);
        }
        let (i, v) = (point.i, point.v);
        let ([id, iq, vd, vq], ok) = self.vectors_seen;
        // (Equal floats give the same answer: the check squares differences, so the signs
        // of zeros do not matter; a NaN never equals, and is checked again.)
        if id == i.d && iq == i.q && vd == v.d && vq == v.q {
            return Some(ok);
        }
        let ok = f.steady_vectors(point)?;
        self.vectors_seen = ([i.d, i.q, v.d, v.q], ok);
        Some(ok)
    }

    /// Whether a point with `flags` is usable by the follower: the monitor runs (now or
    /// before), no sensor fault, and commissioning learns or the lamps count.
    #[inline]
    fn usable_with(&self, flags: RowFlags) -> bool {
        let running = self.running || flags.evaluating() || flags.learned_blocks();
        running && !flags.sensor_fault() && (flags.learning() || flags.counts())
    }

    /// Hands the rows of the chunk to the events' history and the follower (their mean
    /// point, the chunk's length; [`chunk`]), and books what the follower isolated; at the
    /// end of the log, what is left.
    pub(crate) fn flush(&mut self) {
        let Some(c) = self.chunk.close() else {
            return;
        };
        self.vectors_seen = NO_VECTORS;
        let usable = self.usable_with(c.flags);
        let Some(follower) = self.follower.as_mut() else {
            return;
        };
        let (t, flags, point) = (c.last_t, c.flags, &c.point);
        self.events.sample(c.first_t, c.span_s, point);
        let learning = flags.learning();
        // Running: the monitor evaluates its lamps, or its commissioning has learned a
        // block (it learns on running, quasi-steady blocks only, and does not evaluate
        // meanwhile: a window that opens before the first evaluation would otherwise teach
        // the isolation nothing).
        self.running |= flags.evaluating() || flags.learned_blocks();
        let counts = flags.counts();
        self.lamps_lit |= counts && flags.fault_detected();
        let learned = follower.learned();
        if learned {
            // Load moves are measured from the commissioned point, and recorded at every
            // quasi-steady output (the isolation does not run outside the learned range).
            self.events.seed(&follower.isolator().baseline().at);
            if usable && flags.quasi_steady() {
                self.events.point(t, point);
            }
        }
        // Quasi-steady by the vectors themselves (the monitor's gate follows its own frame,
        // which a sensor fault can detune).
        if let Step::Isolated(result) = follower.observe(point, c.span_s as f32, usable, learning) {
            let lag = follower.measured_rise_k().map(|_| follower.probe_lag_k());
            self.temperature.after_isolation(t, &result, lag);
            self.evidence.after(follower, &result);
            let averaged = follower.averaged().map(|(p, _)| p);
            if let Some(p) = averaged {
                self.events.point(t, &p);
            }
            let motor = *follower.isolator().motor();
            self.resistances.add(&motor, &averaged.unwrap_or(*point));
            if let Some(n) = self.name_of(&result, learned) {
                self.give_name(t, n);
            }
            self.last_t = t;
            self.last_point = *point;
        }
        self.block_left_s = self
            .follower
            .as_ref()
            .map_or(0.0, |f| f64::from(f.block_left_s()));
        self.load_explains = self.load_explains_now();
    }

    /// The name the isolation gives after `result` (`learned`: a learned baseline is in
    /// force): a fault one point cannot name may be named from several (evidence across
    /// operating points). The joint fit's fault goes before the friction class of the last
    /// point (a load that moved is, to the paper's model, a Bl change); against the nominal
    /// parameters with every lamp dark a change within their uncertainty is not named, nor,
    /// with the load unknown, the friction class.
    fn name_of(&self, result: &Isolation, learned: bool) -> Option<Named> {
        let joint = self
            .evidence
            .joint_beside(result)
            .and_then(|(j, _)| j.named());
        joint
            .or(result.named())
            .filter(|n| learned || !within_nominal_uncertainty(n))
            .filter(|n| !load_reading(self.load, n))
    }

    /// Books the name `n` given at `t` [s]: the first name, and each name the first time it
    /// is given (with its event).
    fn give_name(&mut self, t: f64, n: Named) {
        let given = NameGiven {
            name: IsolationName::of(&n),
            t_s: t,
        };
        self.first_named.get_or_insert(given);
        if !self.names.iter().any(|g| g.name == given.name) {
            self.names.push(given);
            let (change, p) = match n {
                Named::Fault(c) => (c.change, c.probability),
                Named::Friction {
                    probability, bl, ..
                } => (bl.change, probability),
            };
            self.events.named(t, given.name, change, p);
        }
    }

    /// Every name the isolation gave so far (a fault or the friction class), each with the
    /// first time it was given [s], in that order.
    pub(crate) fn names(&self) -> &[NameGiven] {
        &self.names
    }

    /// The isolation named a fault other than the friction class at some point (a load
    /// change is, to the paper's model, a Bl change: that is left to the lamps and the
    /// commissioned range).
    pub(crate) fn named_a_fault(&self) -> bool {
        self.first_named
            .is_some_and(|g| g.name != IsolationName::Friction)
    }

    /// How far the current of the last isolation is from the one the learned baseline was
    /// learned at: `|I| / |I_learned| - 1` (0.3: 30 % more current); `None` without a
    /// learned baseline or its point.
    /// The tracked winding temperature rise [K] when a learned baseline is in force and it
    /// is at least [`report::REPORTED_RISE_K`] either way.
    pub(crate) fn winding_rise_k(&self) -> Option<f32> {
        let f = self.follower.as_ref().filter(|f| f.learned())?;
        let rise = f.isolator().winding_rise_k();
        (rise.abs() >= REPORTED_RISE_K).then_some(rise)
    }

    /// The winding's heating explains the deviation ([`IsolationReport::heating_explains`]):
    /// against commissioning, [`IsolationTracker::heating_explains_lamps`]; against the
    /// parameter file, the last isolation's heating hypothesis (Rs and Rr together) is more
    /// probable than every fault and the unknown fault, within the healthy scatter, with
    /// the rise above the file's temperature it needs [K].
    fn heating_explains(&self, learned: bool, iso: &Isolation) -> Option<f32> {
        if learned {
            return self
                .heating_explains_lamps()
                .then(|| self.winding_rise_k())
                .flatten();
        }
        let rise = (iso.heating.factor - 1.0) / monitor_core::isolation::COPPER_ALPHA_PER_K;
        (iso.heating_continues() && rise.abs() >= REPORTED_RISE_K).then_some(rise)
    }

    /// The lamps' detections, and any name given on the way, are explained by the
    /// winding's heating: the last isolation found no deviation from the machine at its
    /// tracked (warmer) temperature, which has risen by at least [`report::REPORTED_RISE_K`] (a
    /// name given while the tracking lagged a fast warming was withdrawn since).
    pub(crate) fn heating_explains_lamps(&self) -> bool {
        self.winding_rise_k().is_some_and(|r| r > 0.0)
            && self
                .concluded()
                .is_some_and(|c| c.iso.state == IsolationState::NoDeviation)
    }

    /// The isolation the report concludes from: the joint fit over the operating points
    /// kept where it names a fault the last point alone does not, else the last point;
    /// with the load an unknown input, a reading of the friction class is the load's move
    /// (state [`IsolationState::NoDeviation`]). `None` before any point was isolated.
    fn concluded(&self) -> Option<Concluded> {
        let single = self.follower.as_ref().and_then(|f| f.last().copied())?;
        let joint = self.evidence.joint_beside(&single).map(|(j, n)| (*j, n));
        let mut iso = joint.map_or(single, |(j, _)| j);
        let load_moved = iso.named().is_some_and(|n| load_reading(self.load, &n));
        if load_moved {
            iso.state = IsolationState::NoDeviation;
        }
        if self.load == super::options::LoadModel::Unknown {
            without_friction(&mut iso);
        }
        Some(Concluded {
            iso,
            joint,
            load_moved,
        })
    }

    /// With the load an unknown input ([`super::options::LoadModel::Unknown`]), the lamps' detections
    /// are the load's move: the last isolation reads the friction class (the load), the
    /// operating points since name no fault, and no fault was ever named.
    pub(crate) fn load_explains_lamps(&self) -> bool {
        self.load_explains
    }

    /// [`IsolationTracker::load_explains_lamps`] from the follower's last result, the
    /// evidence and the names given.
    fn load_explains_now(&self) -> bool {
        let friction = self
            .follower
            .as_ref()
            .and_then(|f| f.last())
            .and_then(Isolation::named)
            .is_some_and(|n| load_reading(self.load, &n));
        friction && self.evidence.named().is_none() && !self.named_a_fault()
    }

    fn moved_from_learned(&self) -> Option<f32> {
        let f = self.follower.as_ref().filter(|f| f.learned())?;
        let at = f.isolator().baseline().at;
        let (i0, i1) = (
            at.i.d.hypot(at.i.q),
            self.last_point.i.d.hypot(self.last_point.i.q),
        );
        let r = i1 / i0 - 1.0;
        (i0 > 0.0 && r.is_finite()).then_some(r)
    }

    /// The report, and the candidates for `diagnose` (most probable first, those from
    /// [`LIST_FROM`] on) when `detected` (a lamp lit or a sensor fault was seen) or the
    /// isolation deviates from a learned baseline.
    pub(crate) fn report(&self, detected: bool) -> (IsolationReport, Vec<FaultCandidate>) {
        let learned = self.follower.as_ref().is_some_and(Follower::learned);
        let Some(concluded) = self.concluded() else {
            let why = if self.follower.is_none() {
                said::NotIsolatedWhy::MachineUnusable
            } else {
                said::NotIsolatedWhy::NoSteadyPoint
            };
            return (IsolationReport::not_judged(why, learned), Vec::new());
        };
        let iso = concluded.iso;
        // (A deviation from a learned baseline that names no fault alone is still a finding:
        // its candidates are listed, with their probabilities.)
        let candidates = listed_candidates(&iso, detected || learned);
        let moved = self.moved_from_learned();
        let in_file_error = iso
            .named()
            .filter(|n| !learned && within_nominal_uncertainty(n));
        let named = iso.named().filter(|_| in_file_error.is_none());
        let heating = self.heating_explains(learned, &iso);
        let report = IsolationReport {
            state: iso.state,
            named: named.map(|n| IsolationName::of(&n)),
            named_change: named.map(|n| n.change()),
            named_probability: named.map(|n| n.probability()),
            said: self.said(&concluded, in_file_error, detected, moved),
            moved_from_learned: moved,
            winding_rise_k: if learned {
                self.winding_rise_k()
            } else {
                heating
            },
            heating_explains: heating.is_some(),
            temperature: self.temperature.report(),
            judged_at_s: self.last_t,
            groups: groups(&iso),
            deviation_sigma: iso.deviation,
            unknown_probability: iso.unknown_probability,
            separation_deg: iso.separation_deg,
            residuals: iso.residuals.to_array(),
            spread: self
                .follower
                .as_ref()
                .map_or(DEFAULT_SPREAD, |f| f.isolator().baseline().spread)
                .to_array(),
            baseline: baseline_name(learned),
            first_named: self.first_named,
            events: self.events.events().to_vec(),
            events_dropped: self.events.dropped(),
            resistances: self.resistances.reading(),
            detection_limits: if learned && iso.state == IsolationState::NoDeviation {
                self.detection_limits()
            } else {
                Vec::new()
            },
        };
        (report, candidates)
    }
}

/// A named fault (not the friction class, which a load change moves) whose size is within
/// [`NOMINAL_UNCERTAINTY`] (`monitor_core::isolation::within_nominal_uncertainty`).
fn within_nominal_uncertainty(n: &Named) -> bool {
    matches!(n, Named::Fault(c) if monitor_core::isolation::within_nominal_uncertainty(c.change))
}
