//! The channels' wiring ([`WiringCheck`]): what a DAQ's wiring, a current transformer
//! mounted the other way or a spreadsheet does to a log, judged before any verdict.
//!
//! - **Duplicated.** Two phase channels of one set (two currents, two voltages) that hold
//!   the same reading on more than [`DUPLICATE_SHARE`] of the rows where they alternate: one
//!   column was copied over another, or two inputs read the same sensor. A balanced
//!   three-phase set never has two phases equal for more than an instant per period.
//! - **One channel reversed.** The three currents of a star without neutral sum to zero
//!   whatever the machine does, and so do the phase voltages against the star point. A
//!   sum whose RMS exceeds a phase's ([`ZERO_SEQUENCE_SUSPECT`]) and falls by
//!   [`ZERO_SEQUENCE_FIXED`] or more with one channel's sign turned is that channel reversed
//!   (a sensor's polarity: one reversed current makes the sum twice that phase).
//! - **The phase order.** From the moments of the rows (no frequency needed): the complex
//!   power of the Clarke vectors `S = mean(V conj(I)) = P + jQ`, the vectors' mean squares
//!   and the current vector's turn from one row to the next (`alpha_k beta_{k+1} -
//!   beta_k alpha_{k+1}`, over `|I|^2 sin(w dt)`: +1 for a positive sequence, -1 for a
//!   negative one). Currents and voltages of one sequence give `|S|` about `|V| |I|`; of
//!   opposite sequences (two channels of one set exchanged) almost nothing
//!   ([`COHERENCE_MISMATCH`]). An induction machine always draws magnetising current, so
//!   `Q` has the sign of the sequence, and a motor's power-factor angle `arg S` lies
//!   between 0 and 90 degrees: currents whose angle falls a third of a turn away
//!   ([`ROTATED_OUTSIDE_DEG`]) are rotated one phase against the voltages. The shaft's
//!   direction (the speed channel's mean) says which way is forward: both sets turning
//!   against it is a phase pair exchanged in both (or a motor run backwards), both with it
//!   but the speed negative is the speed channel's sign.
//!
//! Each finding is a [`WiringFault`] with the column mapping that fixes it
//! ([`WiringFault::fix`]: the parameter file's `[columns]` entries), and withholds the
//! verdict: a log whose channels are not what their names say names no fault.

use crate::log::Row;

/// Share of the alternating rows on which two channels must be equal to be duplicates.
pub const DUPLICATE_SHARE: f64 = 0.5;
/// RMS of a set's sum over the RMS of one of its phases above which a channel may be
/// reversed (one reversed current gives 2; a healthy set a few hundredths).
pub const ZERO_SEQUENCE_SUSPECT: f64 = 1.0;
/// The factor by which one channel's sign turned must bring the sum's RMS down for that
/// channel to be named reversed (a common-mode voltage of a PWM inverter measured against
/// the DC link's midpoint makes the sum large too, but no single channel's sign removes it;
/// the real recordings of `examples/recordings/itsc` sum to 0.58 of a phase as published,
/// 1.93 with one current reversed).
pub const ZERO_SEQUENCE_FIXED: f64 = 2.5;
/// `|S| / sqrt(mean|V|^2 mean|I|^2)` below which the currents and the voltages turn
/// opposite ways (one sequence against the other: 0.01-0.05 on simulated logs); one
/// sequence gives 0.6-1 (less where a PWM voltage's harmonics fill `mean|V|^2`).
pub const COHERENCE_MISMATCH: f64 = 0.25;
/// Least `|r|`, the current vector's mean turn over `mean|I|^2 sin(w dt)` (+1 for a pure
/// positive sequence, -1 for a negative one), for its direction to be judged.
pub const DIRECTION_MIN: f64 = 0.3;
/// The power-factor angle outside of which (below minus this, above 90 + this degrees)
/// the currents are judged rotated against the voltages when a third of a turn puts them
/// inside a motor's 0..90 degrees.
pub const ROTATED_OUTSIDE_DEG: f64 = 30.0;
/// The speed channel's mean, as a fraction of the synchronous speed, beyond which it gives
/// the shaft's direction.
pub const SHAFT_MIN: f64 = 0.05;
/// Rows a finding needs before it is said.
const MIN_ROWS: u64 = 1000;

mod fault;
pub use fault::{serialize_all, ColumnFix, PhaseSet, WiringFault};

/// What the stage knows at the end that the check reads: the supply's angle per sample
/// (`w dt`, from the current's zero crossings and the sample rate) and the machine's
/// mechanical synchronous speed [rad/s].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct WiringContext {
    /// The supply's angle per sample [rad], where the currents alternate.
    pub omega_dt: Option<f64>,
    /// The mechanical synchronous speed at the file's frequency [rad/s].
    pub sync_rad_s: f64,
}

/// First and second moments of a set of rows (uncentred sums; [`Moments::cov`] centres
/// them).
#[derive(Debug, Clone, Copy, Default, PartialEq)]
struct Moments {
    n: f64,
    s: [f64; 3],
    ss: [[f64; 3]; 3],
}

impl Moments {
    #[inline(always)]
    fn push(&mut self, x: [f64; 3]) {
        self.n += 1.0;
        for k in 0..3 {
            self.s[k] += x[k];
            for j in k..3 {
                self.ss[k][j] += x[k] * x[j];
            }
        }
    }

    /// The covariance matrix.
    fn cov(&self) -> [[f64; 3]; 3] {
        let n = self.n.max(1.0);
        // Only the upper triangle is summed: (k, j) reads (min, max).
        std::array::from_fn(|k| {
            std::array::from_fn(|j| {
                let (a, b) = (k.min(j), k.max(j));
                self.ss[a][b] / n - self.s[a] / n * self.s[b] / n
            })
        })
    }
}

/// Sums of products of two 3-vectors (`x_k y_j`), with the sums of each.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
struct Cross {
    n: f64,
    sx: [f64; 3],
    sy: [f64; 3],
    sxy: [[f64; 3]; 3],
}

impl Cross {
    #[inline(always)]
    fn push(&mut self, x: [f64; 3], y: [f64; 3]) {
        self.n += 1.0;
        for k in 0..3 {
            self.sx[k] += x[k];
            self.sy[k] += y[k];
            for (j, yj) in y.iter().enumerate() {
                self.sxy[k][j] += x[k] * yj;
            }
        }
    }

    /// The cross-covariance `cov(x_k, y_j)`.
    fn cov(&self) -> [[f64; 3]; 3] {
        let n = self.n.max(1.0);
        std::array::from_fn(|k| {
            std::array::from_fn(|j| self.sxy[k][j] / n - self.sx[k] / n * self.sy[j] / n)
        })
    }
}

/// The counts and moments of the checks; see the module documentation.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct WiringCheck {
    /// Rows seen, and rows on which each pair (ab, bc, ca) of currents, then of voltages,
    /// read the same non-zero value.
    rows: u64,
    equal: [u64; 6],
    /// The currents' moments (every row), the voltages' (rows with voltages), the
    /// voltages against the currents, the currents against the next row's.
    i: Moments,
    v: Moments,
    vi: Cross,
    lag: Cross,
    /// The speed's sum and count.
    w: (f64, f64),
    /// The last row's currents, for the lag (none after a break).
    last: Option<[f64; 3]>,
}

/// Adds to `equal` the rows on which each pair (ab, bc, ca) of `x` read the same non-zero
/// value.
fn count_equal(equal: &mut [u64], x: [&[f64]; 3]) {
    let same = |p: f64, q: f64| u64::from((p == q) & (p != 0.0));
    let mut n = [0u64; 3];
    for ((&a, &b), &c) in x[0].iter().zip(x[1]).zip(x[2]) {
        n[0] += same(a, b);
        n[1] += same(b, c);
        n[2] += same(c, a);
    }
    for (e, n) in equal.iter_mut().zip(n) {
        *e += n;
    }
}

/// A set's channels mapped: channel `k` of the mapped set is `sign[k]` times channel
/// `perm[k]` of the logged one.
#[derive(Debug, Clone, Copy, PartialEq)]
struct Map {
    perm: [usize; 3],
    sign: [f64; 3],
}

const IDENTITY: Map = Map {
    perm: [0, 1, 2],
    sign: [1.0; 3],
};

impl Map {
    /// The Clarke vector's alpha and beta of the mapped set as weights on the logged
    /// channels (amplitude-invariant Clarke).
    fn clarke(&self) -> ([f64; 3], [f64; 3]) {
        const A: [f64; 3] = [2.0 / 3.0, -1.0 / 3.0, -1.0 / 3.0];
        let b = [0.0, 1.0 / 3f64.sqrt(), -1.0 / 3f64.sqrt()];
        let (mut wa, mut wb) = ([0.0; 3], [0.0; 3]);
        for k in 0..3 {
            wa[self.perm[k]] += A[k] * self.sign[k];
            wb[self.perm[k]] += b[k] * self.sign[k];
        }
        (wa, wb)
    }

    /// With channels `p.0` and `p.1` exchanged.
    fn exchanged(mut self, p: (usize, usize)) -> Map {
        self.perm.swap(p.0, p.1);
        self.sign.swap(p.0, p.1);
        self
    }

    /// Rotated by `by` phases (channel k reads channel k + by).
    fn rotated(self, by: usize) -> Map {
        let mut m = self;
        for k in 0..3 {
            m.perm[k] = self.perm[(k + by) % 3];
            m.sign[k] = self.sign[(k + by) % 3];
        }
        m
    }
}

/// `x^T c y`.
fn quad(x: &[f64; 3], c: &[[f64; 3]; 3], y: &[f64; 3]) -> f64 {
    let mut s = 0.0;
    for k in 0..3 {
        for j in 0..3 {
            s += x[k] * c[k][j] * y[j];
        }
    }
    s
}

/// The mean square of a mapped set's Clarke vector, `mean |X|^2`.
fn power(c: &[[f64; 3]; 3], m: &Map) -> f64 {
    let (a, b) = m.clarke();
    quad(&a, c, &a) + quad(&b, c, &b)
}

/// The variance of a set's sum with `sign`, over its mean phase variance.
fn zero_sequence(c: &[[f64; 3]; 3], sign: [f64; 3]) -> f64 {
    let phase = (c[0][0] + c[1][1] + c[2][2]) / 3.0;
    quad(&sign, c, &sign) / phase.max(f64::MIN_POSITIVE)
}

/// The channel of a set whose sign turned makes its sum vanish, with the sum's RMS over a
/// phase's as logged; see [`ZERO_SEQUENCE_SUSPECT`].
fn reversed_channel(c: &[[f64; 3]; 3]) -> Option<(usize, f64)> {
    let z = zero_sequence(c, [1.0; 3]);
    if z.sqrt() <= ZERO_SEQUENCE_SUSPECT {
        return None;
    }
    (0..3)
        .map(|k| {
            let mut s = [1.0; 3];
            s[k] = -1.0;
            (k, zero_sequence(c, s))
        })
        .min_by(|a, b| a.1.total_cmp(&b.1))
        .filter(|(_, zk)| zk.sqrt() * ZERO_SEQUENCE_FIXED < z.sqrt())
        .map(|(k, _)| (k, z.sqrt()))
}

/// The power-factor angle of a motor's quadrant's middle, and how far `(p, q)` lies from
/// it: `cos(arg S - 45 deg) |S|`, larger the nearer a motor's.
fn motoring(p: f64, q: f64) -> f64 {
    (p + q) / std::f64::consts::SQRT_2
}

/// The three pairs of a set.
const PAIRS: [(usize, usize); 3] = [(0, 1), (1, 2), (2, 0)];

impl WiringCheck {
    /// Follows a row's currents `i`, voltages `v` and speed `w` (all its cells good).
    #[inline(always)]
    fn accumulate(&mut self, v: Option<[f64; 3]>, i: [f64; 3], w: Option<f64>) {
        self.i.push(i);
        if let Some(p) = self.last {
            self.lag.push(p, i);
        }
        self.last = Some(i);
        if let Some(v) = v {
            self.v.push(v);
            self.vi.push(v, i);
        }
        if let Some(w) = w {
            self.w.0 += w;
            self.w.1 += 1.0;
        }
    }

    /// Follows a row whose cells are all good.
    pub fn push(&mut self, r: &Row) {
        self.rows += 1;
        let i = r.i_abc;
        let pairs = |x: [f64; 3]| [(x[0], x[1]), (x[1], x[2]), (x[2], x[0])];
        for (k, (a, b)) in pairs(i).into_iter().enumerate() {
            self.equal[k] += u64::from(a == b && a != 0.0);
        }
        if let Some(v) = r.v_abc {
            for (k, (a, b)) in pairs(v).into_iter().enumerate() {
                self.equal[3 + k] += u64::from(a == b && a != 0.0);
            }
        }
        self.accumulate(r.v_abc, i, r.wm_rad_s);
    }

    /// Follows a block of rows whose cells are all good, channel by channel (`v`: the
    /// voltages a, b, c when the rows have them; `i`: the currents, as long; `w`: the
    /// speed, when they have one): the same counts as [`WiringCheck::push`] row by row.
    pub fn push_block(&mut self, v: Option<[&[f64]; 3]>, i: [&[f64]; 3], w: Option<&[f64]>) {
        let n = i[0].len();
        self.rows += n as u64;
        count_equal(&mut self.equal[..3], i);
        if let Some(v) = v {
            count_equal(&mut self.equal[3..], v);
        }
        let at = |x: &[f64], k: usize| x.get(k).copied().unwrap_or(0.0);
        for k in 0..n {
            let row_i = [at(i[0], k), at(i[1], k), at(i[2], k)];
            let row_v = v.map(|v| [at(v[0], k), at(v[1], k), at(v[2], k)]);
            self.accumulate(row_v, row_i, w.map(|w| at(w, k)));
        }
    }

    /// A row that breaks the sequence (a bad cell, a gap): the next turn starts afresh.
    pub fn interrupt(&mut self) {
        self.last = None;
    }

    /// The duplicated channels.
    fn duplicates(&self) -> Vec<WiringFault> {
        let sets = [PhaseSet::Currents, PhaseSet::Voltages];
        let mut out = Vec::new();
        for (k, n) in self.equal.iter().enumerate() {
            let share = *n as f64 / self.rows.max(1) as f64;
            let c = sets[k / 3].columns();
            let (a, b) = PAIRS[k % 3];
            if share > DUPLICATE_SHARE {
                out.push(WiringFault::Duplicated {
                    first: c[a],
                    second: c[b],
                    share,
                });
            }
        }
        out
    }

    /// The current vector's mean turn per row over `mean|I|^2 sin(w dt)` for the
    /// currents mapped by `m`: +1 for a positive sequence, -1 for a negative one.
    fn turn(&self, m: &Map, omega_dt: f64) -> f64 {
        let (a, b) = m.clarke();
        let l = self.lag.cov();
        let t = quad(&a, &l, &b) - quad(&b, &l, &a);
        t / (power(&self.i.cov(), m) * omega_dt.sin()).max(f64::MIN_POSITIVE)
    }

    /// The complex power `(P, Q)` of the voltages mapped by `mv` against the currents
    /// mapped by `mi`, and its coherence `|S| / sqrt(mean|V|^2 mean|I|^2)`.
    fn power_of(&self, mv: &Map, mi: &Map) -> (f64, f64, f64) {
        let c = self.vi.cov();
        let ((va, vb), (ia, ib)) = (mv.clarke(), mi.clarke());
        let p = quad(&va, &c, &ia) + quad(&vb, &c, &ib);
        let q = quad(&vb, &c, &ia) - quad(&va, &c, &ib);
        let norm = (power(&self.v.cov(), mv) * power(&self.i.cov(), mi)).sqrt();
        (p, q, p.hypot(q) / norm.max(f64::MIN_POSITIVE))
    }

    /// The speed channel's mean [rad/s] where it says which way the shaft turns.
    fn shaft(&self, ctx: &WiringContext) -> Option<f64> {
        let n = self.w.1;
        let mean = self.w.0 / n.max(1.0);
        (n >= MIN_ROWS as f64 && mean.abs() > SHAFT_MIN * ctx.sync_rad_s).then_some(mean)
    }

    /// What was found ([`WiringFault`]s, the ones that decide the others' mapping first);
    /// empty when nothing.
    pub fn findings(&self, ctx: &WiringContext) -> Vec<WiringFault> {
        let mut out = self.duplicates();
        if self.rows < MIN_ROWS || !out.is_empty() {
            return out;
        }
        let (mut mi, mut mv) = (IDENTITY, IDENTITY);
        if let Some((k, z)) = reversed_channel(&self.i.cov()) {
            mi.sign[k] = -1.0;
            out.push(WiringFault::Reversed {
                channel: PhaseSet::Currents.columns()[k],
                zero_sequence: z,
            });
        }
        let voltages = self.v.n >= MIN_ROWS as f64;
        if voltages {
            if let Some((k, z)) = reversed_channel(&self.v.cov()) {
                mv.sign[k] = -1.0;
                out.push(WiringFault::Reversed {
                    channel: PhaseSet::Voltages.columns()[k],
                    zero_sequence: z,
                });
            }
        }
        let Some(omega_dt) = ctx.omega_dt.filter(|w| *w > 0.0 && *w < 3.0) else {
            return out;
        };
        let turn = self.turn(&mi, omega_dt);
        let d_i = if turn > DIRECTION_MIN {
            1.0
        } else if turn < -DIRECTION_MIN {
            -1.0
        } else {
            return out;
        };
        let shaft = self.shaft(ctx);
        if !voltages {
            if let Some(w) = shaft.filter(|w| w.signum() != d_i) {
                out.push(WiringFault::CurrentsAgainstShaft { mean_rad_s: w });
            }
            return out;
        }
        out.extend(self.order(&mv, &mi, d_i, shaft, turn));
        out
    }

    /// The pair of `set` exchanged: the one whose exchange gives a motor's power-factor
    /// angle back (the three pairs' differ by a third of a turn).
    fn exchanged_pair(
        &self,
        mv: &Map,
        mi: &Map,
        set: PhaseSet,
        coherence: f64,
    ) -> Option<WiringFault> {
        let (pair, (p, q, _)) = PAIRS
            .iter()
            .map(|pr| {
                let s = match set {
                    PhaseSet::Currents => self.power_of(mv, &mi.exchanged(*pr)),
                    PhaseSet::Voltages => self.power_of(&mv.exchanged(*pr), mi),
                };
                (*pr, s)
            })
            .max_by(|a, b| motoring(a.1 .0, a.1 .1).total_cmp(&motoring(b.1 .0, b.1 .1)))?;
        let c = set.columns();
        Some(WiringFault::Exchanged {
            set,
            first: c[pair.0],
            second: c[pair.1],
            coherence,
            angle_deg: q.atan2(p).to_degrees(),
        })
    }

    /// The phase order of the voltages (mapped by `mv`) against the currents (mapped by
    /// `mi`, turning `d_i`, `turn`) and the shaft.
    fn order(
        &self,
        mv: &Map,
        mi: &Map,
        d_i: f64,
        shaft: Option<f64>,
        turn: f64,
    ) -> Option<WiringFault> {
        let (p, q, coherence) = self.power_of(mv, mi);
        let forward = shaft.map_or(1.0, f64::signum);
        if coherence < COHERENCE_MISMATCH {
            // One set turns against the other: the one against the shaft (without a speed,
            // the currents against the voltages) has two channels exchanged.
            let set = if d_i != forward || shaft.is_none() {
                PhaseSet::Currents
            } else {
                PhaseSet::Voltages
            };
            return self.exchanged_pair(mv, mi, set, coherence);
        }
        if d_i < 0.0 {
            return Some(WiringFault::PhaseOrderReversed {
                shaft_backwards: forward < 0.0,
                turn,
            });
        }
        if let Some(w) = shaft.filter(|w| *w < 0.0) {
            return Some(WiringFault::SpeedReversed { mean_rad_s: w });
        }
        // Forward: the power-factor angle must be a motor's (or near it).
        let angle = q.atan2(p).to_degrees();
        if (-ROTATED_OUTSIDE_DEG..=90.0 + ROTATED_OUTSIDE_DEG).contains(&angle) {
            return None;
        }
        let (by, _) = [1usize, 2]
            .into_iter()
            .map(|by| {
                let (p, q, _) = self.power_of(mv, &mi.rotated(by));
                (by, motoring(p, q))
            })
            .max_by(|a, b| a.1.total_cmp(&b.1))?;
        Some(WiringFault::Rotated {
            by: by as u8,
            angle_deg: angle,
        })
    }
}

#[cfg(test)]
mod tests;
