//! Fault isolation beyond Table 1: which fault, how large, from the full steady-state
//! equations of the T-equivalent machine (parity space, directional residual matching).
//!
//! # Why the lamps cannot name the fault
//! In steady state the paper's r3 and r4 are combinations of r1 and r2 (see
//! [`crate::residuals`]), so four lamps carry two equations' worth of information; the
//! current-model angle itself depends on Rr, Lr and the encoder. The lamps stay as the
//! paper has them (the panel, the paper's comparison); this module adds, beside them, the
//! equations the paper drops.
//!
//! # The parity equations used here
//! In any frame turning at the supply frequency `we` (rotor-flux or voltage orientation
//! alike: only the vectors' relative angle counts) the steady state of the T-equivalent
//! machine with slip frequency `ws = we - wr` is (paper eqs. 13-23 with `d/dt = 0`):
//!
//! - stator, d and q axes together: `V = Z(ws) I`, with
//!   `Z = Rs + j we Ls + we ws Lm^2 / (Rr + j ws Lr)`; the q-axis part is the paper's r1
//!   (eq. 37), the d-axis part (eq. 16 in steady state) is the r5 the paper drops: Rs
//!   enters it through `Rs i_ds`, Rr does not;
//! - torque balance with the paper's viscous load: `Te = (B + Bl) wr / Np`, with
//!   `Te = 3/2 Np Im(conj(Lm Ir) I)` and the rotor current `Ir = -j ws Lm I / (Rr + j ws Lr)`;
//!   this is r2 (eq. 37) with the rotor flux taken from the circuit rather than from
//!   `Lm i_ds`.
//!
//! The three parity residuals ([`Residual3`]) are `e_d + j e_q = (V - Z I)/|V|` and
//! `e_T = (Te - (B+Bl) wr/Np) / T_base` (dimensionless; `T_base` is the torque at
//! `I_qs = i_mag`, about rated torque: [`Isolator::torque_base_nm`]). The speed implied by
//! the electrical equations against the encoder's, and a voltage-model flux angle against
//! the current model's, carry no information beyond these three: both follow from
//! `V`, `I`, `we` and `wr` through the same circuit, so they are the speed-sensor and
//! rotor-parameter directions of the same residual vector.
//!
//! # Directional matching
//! Each fault hypothesis `(f, k)` (parameter `f` scaled by `k = 1 + change`, or a sensor
//! reading `k` times the truth) predicts the residual vector the monitor would see:
//! the measurements are first corrected for the hypothesised sensor gain, then checked
//! against the machine with the hypothesised parameter. The fit over `k` in
//! [`K_MIN`]..[`K_MAX`] minimises the weighted misfit `chi2(f, k) = sum ((e_i - b_i)/s_i)^2`
//! (`b`: the healthy baseline, learned by [`Isolator::learn`]; `s`: the residuals' spread);
//! the best `k` is the fault's **size**. This is the linearised direction test of parity
//! space carried to large faults: near `k = 1`, `e(f, k) ~ e(f, 1) + (k - 1) de/dk`, and
//! the fit is the projection of the measured change on the fault's direction.
//!
//! Candidates are ranked by their misfit; the probabilities are
//! `p_f ~ exp(-(chi2_f - chi2_min) / (2 T))` with the temperature `T = max(1, chi2_min/2)`
//! (the 2 degrees of freedom left after the size is fitted): a poor best fit spreads the
//! probability instead of naming one fault with confidence. An *unknown fault* takes part
//! with the misfit [`UNKNOWN_CHI2`] (or a tenth of the deviation's chi-square, when larger): a change
//! that fits no fault's direction goes to it, so the monitor does not name a wrong fault
//! with probability 0.5 or more.
//!
//! # Away from the learned point
//! A learned baseline cancels the nameplate's error at the operating point where it was
//! learned ([`Baseline::at`]), not elsewhere: after a load change the residuals move by
//! `J(p) delta - J(p0) delta` (`delta`: the parameters' error), which no single fault's
//! direction is meant to absorb (found on a simulated 11 kW log with parameters 15-20 % off:
//! a load step to 0.7, then Rr +50 %, was named `current_sensor -27 %` at p = 0.95). The
//! misfit therefore uses the covariance `S = diag(spread^2) + sum_j d_j d_j^T`, with `d_j`
//! the difference, between the present point and the learned one, of what an error of
//! `u` [`NAMEPLATE_UNCERTAINTY`] in parameter `j` (Rs, Rr, both leakages, Lm) does to the
//! residuals. `u` follows the evidence: the learned mean of the voltage residuals against
//! what a full [`NAMEPLATE_UNCERTAINTY`] error of each parameter leaves at the learned
//! point, between [`NAMEPLATE_FLOOR`] and 1. One `S`, at the measured point with the
//! nominal circuit, serves every hypothesis so that their misfits compare. At the learned
//! point `d_j = 0` and nothing changes; a fault that itself moves the point (a sensor gain,
//! a large Rr change) is judged with the widening its move brings, which is what a
//! nameplate that is off deserves.
//!
//! Faults that cannot be separated:
//! - **B and Bl**: both scale the same load term `(B + Bl) wr`; the directions coincide at
//!   every operating point (one friction class; the size is given for each as if it alone
//!   changed);
//! - **current and voltage sensor at no load**: both scale `Z` (the measured `V/I`); only
//!   the torque balance separates them, and at no load the torque is small;
//! - **Rr, the speed sensor and (near rated load) Ls**: `Z` and `Te` depend on the slip
//!   frequency and Rr only through `ws / Rr`, so a speed reading a few tenths of a percent
//!   off moves the voltage equations like a 10 % Rr change; the torque balance tells them
//!   apart only through the load term `(B + Bl) wr` and, at a given current, through the
//!   torque's slope in `ws / Rr`, which is zero at `ws Lr / Rr = 1` (`I_qs = i_ds`, about
//!   rated load on small machines). There a stator-leakage change of 10 % also looks like
//!   Rr +-1 % (measured on the 3 hp machine at rated load: rr, ls and speed_sensor at about
//!   a third each; the isolation bench lists these cases);
//! - others depend on the operating point (the angle between directions,
//!   [`Isolation::separation_deg`]).
//!
//! Cost: about 300 circuit evaluations of some 60 flops each per call (280 for the fits,
//! 12 for the weight); run it from a
//! low-priority task (the firmware: thread mode, from the status hand-over, every
//! [`STEP_S`] at most), never from the per-sample path. [`Follower`] runs the schedule
//! (averaging the operating point, learning the baseline, isolating) for the firmware and
//! the host alike.

mod follower;
pub use follower::{
    steady_against, Follower, Step, AVERAGE_MAX_S, AVERAGE_S, BLOCKS, CONFIRM_S, STEADY_FRACTION,
    STEP_S,
};

use crate::frames::Dq;
use crate::machine::MotorModel;
use crate::signature::{Fault, FAULT_COUNT};
use micromath::F32Ext;

/// Smallest factor `k = 1 + change` fitted (a parameter at a quarter of nominal).
pub const K_MIN: f32 = 0.25;
/// Largest factor fitted (four times nominal).
pub const K_MAX: f32 = 4.0;
/// Grid points between [`K_MIN`] and [`K_MAX`] before the golden-section refinement
/// (geometric, 12.2 % apart).
const GRID: usize = 25;
/// Golden-section steps: bracket of two grid steps shrunk by 0.618^16 (better than 1e-3
/// of the factor).
const GOLDEN_STEPS: usize = 16;
/// Misfit given to the unknown-fault hypothesis: 5 spreads on the 2 residual dimensions
/// left after fitting a size.
pub const UNKNOWN_CHI2: f32 = 25.0;
/// Fewest averaged points a learned baseline needs: half a second of steady running after
/// the first [`AVERAGE_S`] average, one point per [`STEP_S`] block.
pub const MIN_LEARNED_POINTS: u32 = 5;
/// A deviation below this misfit is no evidence of a fault: the 99.9 % point of chi-square
/// with 3 degrees of freedom (16.3), for spreads of one standard deviation.
pub const DETECT_CHI2: f32 = 16.0;
/// How much more probable than the runner-up a fault must be to be named alone: two
/// faults whose directions coincide share the probability about evenly (0.50 / 0.50 up to
/// rounding), and neither is named.
pub const NAME_MARGIN: f32 = 0.1;
/// Relative uncertainty of the nameplate's circuit parameters (Rs, Rr, both leakages and
/// Lm): parameters from a nameplate or a datasheet are commonly 10-30 % off the machine
/// (equivalent-circuit parameters from IEEE 112 / IEC 60034-28 tests of the same motor
/// differ by 10-20 %). A learned baseline cancels their effect at the point where it was
/// learned, not elsewhere (module docs, "Away from the learned point"). It is the most
/// that is allowed for; how much is allowed for follows the evidence, see
/// [`NAMEPLATE_FLOOR`].
pub const NAMEPLATE_UNCERTAINTY: f32 = 0.2;
/// The least nameplate error allowed for away from the learned point, as a fraction of
/// [`NAMEPLATE_UNCERTAINTY`] (0.25: 5 %). Between it and 1 the fraction is the learned
/// mean of the voltage residuals against what a [`NAMEPLATE_UNCERTAINTY`] error of each
/// parameter would leave at the learned point (root sum of squares): a nameplate that fits
/// the machine where it was learned is probably close elsewhere too. Errors that cancel
/// at the learned point are what the floor is for. With the floor at 1 (20 % always) the
/// isolation bench named 391 of 432 cases right and 8 wrongly (rotor resistance +-50 % at
/// 0.6 load taken for a speed-sensor error); at 0.25, 409 and 1 (as without widening).
pub const NAMEPLATE_FLOOR: f32 = 0.25;

/// The steady-state operating point the isolation works on: the stator voltage and current
/// vectors in one frame turning at the supply frequency, and the two speeds.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct SteadyPoint {
    /// Stator current vector (i_ds, i_qs) [A, peak phase].
    pub i: Dq,
    /// Stator voltage vector (v_ds, v_qs) [V, peak phase].
    pub v: Dq,
    /// Supply (frame) angular frequency [rad/s], > 0.
    pub we_rad_s: f32,
    /// Electrical rotor speed from the encoder, Np x mechanical [rad/s].
    pub wr_rad_s: f32,
}

impl SteadyPoint {
    /// The point the monitor's filtered outputs describe: `(i_ds, I_qs)`, `(V_ds, V_qs)`,
    /// the frame's angular frequency and the electrical rotor speed (all filtered at the
    /// monitor's `filter_hz`, except the frame frequency: average it over a few supply
    /// periods before use, as the host's replay does).
    pub fn from_output(o: &crate::MonitorOutput) -> Self {
        SteadyPoint {
            i: Dq {
                d: o.operating.i_f,
                q: o.operating.iqs,
            },
            v: Dq {
                d: o.vds,
                q: o.operating.vqs,
            },
            we_rad_s: o.frame_omega_rad_s,
            wr_rad_s: o.operating.wr,
        }
    }

    /// Adds `w` times `p` to this point (a weighted sum's step).
    pub fn add_scaled(&mut self, p: &SteadyPoint, w: f32) {
        self.i.d += w * p.i.d;
        self.i.q += w * p.i.q;
        self.v.d += w * p.v.d;
        self.v.q += w * p.v.q;
        self.we_rad_s += w * p.we_rad_s;
        self.wr_rad_s += w * p.wr_rad_s;
    }

    /// Multiplies every quantity by `k` (a weighted sum into a mean).
    pub fn scale(&mut self, k: f32) {
        let p = *self;
        *self = SteadyPoint::default();
        self.add_scaled(&p, k);
    }

    /// Moves this point towards `p` by the fraction `a` (an exponential average's step).
    pub fn approach(&mut self, p: &SteadyPoint, a: f32) {
        self.i.d += a * (p.i.d - self.i.d);
        self.i.q += a * (p.i.q - self.i.q);
        self.v.d += a * (p.v.d - self.v.d);
        self.v.q += a * (p.v.q - self.v.q);
        self.we_rad_s += a * (p.we_rad_s - self.we_rad_s);
        self.wr_rad_s += a * (p.wr_rad_s - self.wr_rad_s);
    }
}

/// The three parity residuals `[e_d, e_q, e_T]` (module docs), dimensionless.
pub type Residual3 = [f32; 3];

/// The healthy reference of the residuals: mean and spread (one standard deviation), from
/// [`Isolator::learn`] or the defaults (zero mean; spreads 0.5 % of |V| on the voltage
/// equations and 0.4 % of `T_base` on the torque balance: three times the scatter left by the
/// monitor's 5 Hz filters and the host's 0.5 s average, measured on simulated healthy runs
/// of both reference motors with the simulator's default 12-bit, 0.1 %-noise sensors:
/// 0.05 %, 0.05 % and 0.1 %).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Baseline {
    /// Mean residual of the healthy machine.
    pub mean: Residual3,
    /// Spread of each residual, > 0.
    pub spread: Residual3,
    /// The mean operating point the baseline was learned at; [`SteadyPoint::default`]
    /// (not a usable point) for the defaults and for baselines stored without it. Away
    /// from it the nameplate's error no longer cancels and the misfit is widened
    /// accordingly (module docs, "Away from the learned point").
    pub at: SteadyPoint,
}

impl Default for Baseline {
    fn default() -> Self {
        Baseline {
            mean: [0.0; 3],
            spread: DEFAULT_SPREAD,
            at: SteadyPoint::default(),
        }
    }
}

/// The spreads used without a learned baseline (the nominal parameters' own error at other
/// operating points is in them).
pub const DEFAULT_SPREAD: Residual3 = [0.0015, 0.0015, 0.004];

/// The floor of learned spreads, for points averaged [`AVERAGE_MAX_S`]: the largest scatter
/// of such points measured on simulated healthy runs of the 3 hp, 2.2 kW and 11 kW machines
/// (5 kHz, 12-bit sensors, 0.1 % noise; 24 runs, 4 seeds per machine and load) was 0.022 %
/// of |V| on the voltage equations and 0.055 % of `T_base` on the torque balance, against
/// 0.08 % and 0.44 % with the former 0.5 s exponential average; the floor is about twice
/// that (a commissioning window's scatter understates what a longer run meets).
pub const LEARNED_SPREAD_FLOOR: Residual3 = [0.0004, 0.0004, 0.001];

/// One fault's fit.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Candidate {
    /// The fault.
    pub fault: Fault,
    /// Probability, [0, 1]; with [`Isolation::unknown_probability`] they sum to 1.
    pub probability: f32,
    /// Estimated relative change: parameter `k - 1` (0.48 for +48 %), sensor gain error
    /// (the reading is `1 + change` times the truth).
    pub change: f32,
    /// Misfit left after the fit, in standard deviations (`sqrt(chi2)`).
    pub misfit: f32,
    /// The fit's factor is at the end of the range searched (the change may be larger).
    pub at_limit: bool,
}

/// What the isolation concluded.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum IsolationState {
    /// No valid operating point (no voltage, no current, not turning at a frequency).
    #[default]
    NotJudged,
    /// The residuals are within the healthy spread: nothing to isolate.
    NoDeviation,
    /// A fault's direction fits the change.
    Isolated,
    /// No fault's direction fits: an unknown fault (or a model that does not fit the
    /// motor); the nearest candidates are listed with their misfit.
    Unknown,
}

/// The isolation's result.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Isolation {
    /// The conclusion.
    pub state: IsolationState,
    /// Every fault's fit, most probable first.
    pub candidates: [Candidate; FAULT_COUNT],
    /// Probability that the change fits none of the faults.
    pub unknown_probability: f32,
    /// The measured change from the baseline, in standard deviations (`sqrt(chi2)` of the
    /// healthy hypothesis).
    pub deviation: f32,
    /// The residuals minus the baseline mean, `[e_d, e_q, e_T]`.
    pub residuals: Residual3,
    /// Angle between the top two candidates' directions (the change each fitted size makes
    /// to the residuals, weighted by the spreads) [deg], 0..180; small: they cannot be
    /// separated at this operating point.
    pub separation_deg: f32,
}

impl Default for Isolation {
    fn default() -> Self {
        Isolation {
            state: IsolationState::NotJudged,
            candidates: Fault::ALL.map(|fault| Candidate {
                fault,
                probability: 0.0,
                change: 0.0,
                misfit: 0.0,
                at_limit: false,
            }),
            unknown_probability: 0.0,
            deviation: 0.0,
            residuals: [0.0; 3],
            separation_deg: 0.0,
        }
    }
}

/// What the isolation names.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Named {
    /// One fault, with probability at least 0.5.
    Fault(Candidate),
    /// The friction class B/Bl (they cannot be separated): their summed probability is at
    /// least 0.5; the sizes are each one's own.
    Friction {
        /// Probability of the class.
        probability: f32,
        /// B's fit.
        b: Candidate,
        /// Bl's fit.
        bl: Candidate,
    },
}

impl Isolation {
    /// The fault (or the friction class) named: state [`IsolationState::Isolated`] and
    /// probability at least 0.5; `None` otherwise.
    pub fn named(&self) -> Option<Named> {
        if self.state != IsolationState::Isolated {
            return None;
        }
        let top = *self.candidates.first()?;
        if !matches!(top.fault, Fault::B | Fault::Bl) {
            let second = self.candidates.get(1).map_or(0.0, |c| c.probability);
            let alone = top.probability >= 0.5 && top.probability - second >= NAME_MARGIN;
            return alone.then_some(Named::Fault(top));
        }
        let find = |f: Fault| self.candidates.iter().find(|c| c.fault == f).copied();
        let (b, bl) = (find(Fault::B)?, find(Fault::Bl)?);
        let probability = b.probability + bl.probability;
        (probability >= 0.5).then_some(Named::Friction { probability, b, bl })
    }

    /// The single fault named, if one is ([`Isolation::named`] without the friction class).
    pub fn named_fault(&self) -> Option<Candidate> {
        match self.named()? {
            Named::Fault(c) => Some(c),
            Named::Friction { .. } => None,
        }
    }
}

/// Running mean and spread of the healthy residuals (Welford).
#[derive(Debug, Clone, Copy, Default, PartialEq)]
struct Learning {
    n: u32,
    mean: Residual3,
    m2: Residual3,
    at: SteadyPoint,
}

/// The fault isolator: the nominal machine, the healthy baseline, and the fits.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Isolator {
    motor: MotorModel,
    torque_base_nm: f32,
    baseline: Baseline,
    learning: Learning,
}

/// The machine's circuit parameters under a hypothesis.
#[derive(Debug, Clone, Copy)]
struct Circuit {
    rs: f32,
    rr: f32,
    ls: f32,
    lr: f32,
    lm: f32,
    np: f32,
    b_total: f32,
}

impl Isolator {
    /// An isolator for the nominal `motor` on a supply of peak phase voltage
    /// `v_phase_peak` [V] and `supply_hz` [Hz]; `None` when the motor fails
    /// [`MotorModel::validate`] or the supply is not positive and finite.
    pub fn new(motor: MotorModel, v_phase_peak: f32, supply_hz: f32) -> Option<Self> {
        motor.validate().ok()?;
        if !(v_phase_peak > 0.0 && supply_hz > 0.0 && v_phase_peak.is_finite()) {
            return None;
        }
        let i_mag = v_phase_peak / (core::f32::consts::TAU * supply_hz * motor.ls_h);
        let torque_base_nm = motor.kf_per_if() * i_mag * i_mag;
        if !(torque_base_nm.is_finite() && torque_base_nm > 0.0) {
            return None;
        }
        Some(Isolator {
            motor,
            torque_base_nm,
            baseline: Baseline::default(),
            learning: Learning::default(),
        })
    }

    /// The torque scale of `e_T`: `3/2 Np Lm^2/Lr i_mag^2` with the magnetising current
    /// `i_mag = V_peak / (we Ls)` [N m] (the torque at `I_qs = i_ds`, near rated torque for
    /// common motors).
    pub fn torque_base_nm(&self) -> f32 {
        self.torque_base_nm
    }

    /// The baseline in use.
    pub fn baseline(&self) -> Baseline {
        self.baseline
    }

    /// Puts a baseline into force (for example one stored after commissioning). Spreads
    /// below [`DEFAULT_SPREAD`]'s fifth are raised to it; non-finite values are ignored
    /// (returns false and keeps the baseline in force).
    pub fn set_baseline(&mut self, b: Baseline) -> bool {
        if !b.mean.iter().chain(b.spread.iter()).all(|x| x.is_finite()) {
            return false;
        }
        let mut b = b;
        if self.residuals(&b.at, None).is_none() {
            b.at = SteadyPoint::default();
        }
        for (s, d) in b.spread.iter_mut().zip(DEFAULT_SPREAD) {
            *s = crate::maxf(*s, 0.2 * d);
        }
        self.baseline = b;
        true
    }

    /// Adds a healthy operating point to the baseline being learned (commissioning).
    /// Points that give no residuals are skipped.
    pub fn learn(&mut self, p: &SteadyPoint) {
        let Some(e) = self.residuals(p, None) else {
            return;
        };
        let l = &mut self.learning;
        l.n = l.n.saturating_add(1);
        let n = l.n as f32;
        l.at.approach(p, 1.0 / n);
        for ((m, m2), x) in l.mean.iter_mut().zip(l.m2.iter_mut()).zip(e) {
            let d = x - *m;
            *m += d / n;
            *m2 += d * (x - *m);
        }
    }

    /// Ends learning: the learned mean and twice the learned standard deviation (at least
    /// [`LEARNED_SPREAD_FLOOR`]: a short window's scatter understates what a longer run meets) go into force. Returns false, and keeps the baseline in force,
    /// with fewer than [`MIN_LEARNED_POINTS`] points learned.
    pub fn finish_learning(&mut self) -> bool {
        let l = self.learning;
        self.learning = Learning::default();
        if l.n < MIN_LEARNED_POINTS {
            return false;
        }
        let n = l.n as f32;
        let mut spread = [0.0; 3];
        for ((s, m2), d) in spread.iter_mut().zip(l.m2).zip(LEARNED_SPREAD_FLOOR) {
            *s = crate::maxf(2.0 * crate::sqrt(m2 / (n - 1.0)), d);
        }
        self.set_baseline(Baseline {
            mean: l.mean,
            spread,
            at: l.at,
        })
    }

    /// The parity residuals at `p` under hypothesis `h` (`None`: the nominal machine and
    /// sensors); `None` when the point is not usable (no voltage or current, frequency
    /// not positive, non-finite values).
    pub fn residuals(&self, p: &SteadyPoint, h: Option<(Fault, f32)>) -> Option<Residual3> {
        let (c, q) = self.hypothesis(p, h);
        self.eval(&c, &q)
    }

    /// The circuit and the readings corrected for hypothesis `h`.
    #[inline(never)]
    fn hypothesis(&self, p: &SteadyPoint, h: Option<(Fault, f32)>) -> (Circuit, SteadyPoint) {
        let (mut i, mut v, mut wr) = (p.i, p.v, p.wr_rad_s);
        let mut c = self.circuit();
        if let Some((f, k)) = h {
            match f {
                Fault::CurrentSensor => {
                    i = Dq {
                        d: i.d / k,
                        q: i.q / k,
                    }
                }
                Fault::VoltageSensor => {
                    v = Dq {
                        d: v.d / k,
                        q: v.q / k,
                    }
                }
                Fault::SpeedSensor => wr /= k,
                _ => c = c.with(f, k, &self.motor),
            }
        }
        let q = SteadyPoint {
            i,
            v,
            we_rad_s: p.we_rad_s,
            wr_rad_s: wr,
        };
        (c, q)
    }

    /// The weight (inverse covariance) of the residuals at the measured point `q`: the
    /// inverse of `S = D + sum_j d_j d_j^T`, `D = diag(spread^2)`, with `d_j` how
    /// much more the residuals move at `q` than at the learned point when circuit
    /// parameter `j` (Rs, Rr, the leakages, Lm) is [`NAMEPLATE_UNCERTAINTY`] off (module
    /// docs, "Away from the learned point"). Without a learned point, or where a point is
    /// not usable: `D^-1`.
    #[inline(never)]
    fn weight(&self, q: &SteadyPoint) -> Sym3 {
        let s = self.baseline.spread;
        let diag = Sym3::diagonal_weight(&s);
        let (at, c0) = (self.baseline.at, self.circuit());
        let (Some(e_here), Some(e_at)) = (self.eval(&c0, q), self.eval(&c0, &at)) else {
            return diag;
        };
        let [a, b, z] = s;
        let mut cov = Sym3 {
            xx: a * a,
            yy: b * b,
            zz: z * z,
            ..Sym3::default()
        };
        // d_j for a NAMEPLATE_UNCERTAINTY error, and what that error leaves at the learned
        // point in the voltage residuals (the evidence for how far off the nameplate is).
        let mut d = [[0.0f32; 3]; 5];
        let mut expected = 0.0f32;
        for (j, dj) in d.iter_mut().enumerate() {
            let (Some(h), Some(t)) = (
                self.eval(&c0.nameplate_off(j), q),
                self.eval(&c0.nameplate_off(j), &at),
            ) else {
                return diag;
            };
            let g = sub3(&t, &e_at);
            let [gd, gq, _] = g;
            expected += gd * gd + gq * gq;
            *dj = sub3(&sub3(&h, &e_here), &g);
        }
        let [md, mq, _] = self.baseline.mean;
        let seen = crate::sqrt((md * md + mq * mq) / expected);
        let u = if seen.is_finite() {
            crate::minf(crate::maxf(seen, NAMEPLATE_FLOOR), 1.0)
        } else {
            1.0
        };
        for dj in d {
            cov.add_outer(&dj.map(|x| u * x));
        }
        cov.inverse().unwrap_or(diag)
    }

    /// The parity residuals of circuit `c` at the (corrected) readings `q` (see
    /// [`Isolator::residuals`]).
    #[inline(never)]
    fn eval(&self, c: &Circuit, q: &SteadyPoint) -> Option<Residual3> {
        let (i, v, we, wr) = (q.i, q.v, q.we_rad_s, q.wr_rad_s);
        let vmag = crate::fast_hypot(v.d, v.q);
        let imag = crate::fast_hypot(i.d, i.q);
        if !(we > 0.0 && vmag > 0.0 && imag > 0.0 && wr.is_finite()) {
            return None;
        }
        let ws = we - wr;
        // 1 / (Rr + j ws Lr) = (Rr - j ws Lr) / den
        let den = c.rr * c.rr + ws * ws * c.lr * c.lr;
        let (yr, yi) = (c.rr / den, -ws * c.lr / den);
        let g = we * ws * c.lm * c.lm;
        let z_re = c.rs + g * yr;
        let z_im = we * c.ls + g * yi;
        let vp_d = z_re * i.d - z_im * i.q;
        let vp_q = z_re * i.q + z_im * i.d;
        // Ir = -j ws Lm I / (Rr + j ws Lr): (-j ws Lm) * (yr + j yi) * I
        let (a_re, a_im) = (ws * c.lm * yi, -ws * c.lm * yr);
        let ir_d = a_re * i.d - a_im * i.q;
        let ir_q = a_re * i.q + a_im * i.d;
        // Te = 3/2 Np Im(conj(Lm Ir) I) = 3/2 Np Lm (ir_d i_q - ir_q i_d)
        let te = 1.5 * c.np * c.lm * (ir_d * i.q - ir_q * i.d);
        let tl = c.b_total * wr / c.np;
        let e = [
            (v.d - vp_d) / vmag,
            (v.q - vp_q) / vmag,
            (te - tl) / self.torque_base_nm,
        ];
        e.iter().all(|x| x.is_finite()).then_some(e)
    }

    /// [`Isolator::isolate`] with the baseline's spreads multiplied by `spread_scale`
    /// (>= 1; values below 1 or not finite count as 1): a point averaged for a shorter time
    /// scatters more ([`Follower`]: `sqrt(AVERAGE_MAX_S / averaged)`).
    pub fn isolate_scaled(&self, p: &SteadyPoint, spread_scale: f32) -> Isolation {
        let k = if spread_scale.is_finite() {
            crate::maxf(spread_scale, 1.0)
        } else {
            1.0
        };
        let mut scaled = *self;
        for s in scaled.baseline.spread.iter_mut() {
            *s *= k;
        }
        scaled.isolate(p)
    }

    /// Isolates the fault at the steady operating point `p` (module docs). Never panics;
    /// an unusable point gives [`IsolationState::NotJudged`].
    pub fn isolate(&self, p: &SteadyPoint) -> Isolation {
        let mut out = Isolation::default();
        let Some(e0) = self.residuals(p, None) else {
            return out;
        };
        let b = self.baseline;
        for ((r, e), m) in out.residuals.iter_mut().zip(e0).zip(b.mean) {
            *r = e - m;
        }
        let w = self.weight(p);
        let chi0 = self.chi2_at(p, None, &w);
        out.deviation = crate::sqrt(chi0);
        if chi0 < DETECT_CHI2 {
            out.state = IsolationState::NoDeviation;
            return out;
        }
        let mut fits = [(0.0f32, 1.0f32); FAULT_COUNT];
        for (fit, f) in fits.iter_mut().zip(Fault::ALL) {
            *fit = self.fit(p, f, &w);
        }
        // B and Bl scale the same load term: one friction class with one misfit (each
        // keeps the size it needs on its own).
        let friction = [Fault::B.index(), Fault::Bl.index()];
        let chi_friction = friction
            .iter()
            .filter_map(|k| fits.get(*k))
            .fold(f32::INFINITY, |a, (c, _)| crate::minf(a, *c));
        for k in friction {
            if let Some((c, _)) = fits.get_mut(k) {
                *c = chi_friction;
            }
        }
        let chi_min = fits
            .iter()
            .fold(f32::INFINITY, |a, (c, _)| crate::minf(a, *c));
        let chi_unknown = crate::maxf(UNKNOWN_CHI2, 0.1 * chi0);
        let t = crate::maxf(1.0, 0.5 * chi_min);
        let w = |c: f32| F32Ext::exp(-(c - chi_min) / (2.0 * t));
        let mut total = w(chi_unknown);
        for (c, _) in fits {
            total += w(c);
        }
        for ((cand, (c, k)), f) in out.candidates.iter_mut().zip(fits).zip(Fault::ALL) {
            *cand = Candidate {
                fault: f,
                probability: w(c) / total,
                change: k - 1.0,
                misfit: crate::sqrt(c),
                at_limit: k <= K_MIN * 1.001 || k >= K_MAX * 0.999,
            };
        }
        out.unknown_probability = w(chi_unknown) / total;
        sort_by_probability(&mut out.candidates);
        out.state =
            if out.unknown_probability >= out.candidates.first().map_or(0.0, |c| c.probability) {
                IsolationState::Unknown
            } else {
                IsolationState::Isolated
            };
        out.separation_deg = self.separation(p, &e0, &out.candidates);
        out
    }

    /// The misfit of hypothesis `h` (fault `f` of factor `k`; `None`: the healthy machine)
    /// against the baseline under the weight `w` ([`Isolator::weight`] at the measured
    /// point, one for every hypothesis so that their misfits compare); unusable points
    /// count as infinitely bad.
    #[inline(never)]
    fn chi2_at(&self, p: &SteadyPoint, h: Option<(Fault, f32)>, w: &Sym3) -> f32 {
        let (c, q) = self.hypothesis(p, h);
        match self.eval(&c, &q) {
            Some(e) => w.quadratic(&sub3(&e, &self.baseline.mean)),
            None => f32::INFINITY,
        }
    }

    /// Best factor `k` for fault `f`: geometric grid, then golden section around the best
    /// grid point. Returns `(chi2, k)`. Not inlined: one copy for the nine faults keeps
    /// the firmware's flash small (it runs in thread mode, where a call costs nothing).
    #[inline(never)]
    fn fit(&self, p: &SteadyPoint, f: Fault, w: &Sym3) -> (f32, f32) {
        let step = F32Ext::powf(K_MAX / K_MIN, 1.0 / (GRID - 1) as f32);
        let (mut best_k, mut best_c) = (1.0f32, self.chi2_at(p, Some((f, 1.0)), w));
        let mut k = K_MIN;
        for _ in 0..GRID {
            let c = self.chi2_at(p, Some((f, k)), w);
            if c < best_c {
                (best_k, best_c) = (k, c);
            }
            k *= step;
        }
        let (mut lo, mut hi) = (
            crate::maxf(best_k / step, K_MIN),
            crate::minf(best_k * step, K_MAX),
        );
        const G: f32 = 0.618_034;
        let mut x1 = hi - G * (hi - lo);
        let mut x2 = lo + G * (hi - lo);
        let (mut c1, mut c2) = (
            self.chi2_at(p, Some((f, x1)), w),
            self.chi2_at(p, Some((f, x2)), w),
        );
        for _ in 0..GOLDEN_STEPS {
            if c1 < c2 {
                hi = x2;
                (x2, c2) = (x1, c1);
                x1 = hi - G * (hi - lo);
                c1 = self.chi2_at(p, Some((f, x1)), w);
            } else {
                lo = x1;
                (x1, c1) = (x2, c2);
                x2 = lo + G * (hi - lo);
                c2 = self.chi2_at(p, Some((f, x2)), w);
            }
        }
        for (c, x) in [(c1, x1), (c2, x2)] {
            if c < best_c {
                (best_k, best_c) = (x, c);
            }
        }
        (best_c, best_k)
    }

    /// Angle between the top two candidates' weighted directions `e(f, k*) - e(nominal)`
    /// [deg]; 180 when either direction is empty.
    fn separation(&self, p: &SteadyPoint, e0: &Residual3, c: &[Candidate; FAULT_COUNT]) -> f32 {
        let dir = |cand: Option<&Candidate>| -> Option<Residual3> {
            let cand = cand?;
            let e = self.residuals(p, Some((cand.fault, 1.0 + cand.change)))?;
            let mut d = [0.0; 3];
            for (((o, x), x0), s) in d.iter_mut().zip(e).zip(e0).zip(self.baseline.spread) {
                *o = (x - x0) / s;
            }
            Some(d)
        };
        let (Some(a), Some(b)) = (dir(c.first()), dir(c.get(1))) else {
            return 180.0;
        };
        let dot: f32 = a.iter().zip(b).map(|(x, y)| x * y).sum();
        let na = crate::sqrt(a.iter().map(|x| x * x).sum());
        let nb = crate::sqrt(b.iter().map(|x| x * x).sum());
        if !(na > 0.0 && nb > 0.0) {
            return 180.0;
        }
        let cos = crate::minf(crate::maxf(dot / (na * nb), -1.0), 1.0);
        F32Ext::acos(cos).to_degrees()
    }

    /// The nominal circuit.
    fn circuit(&self) -> Circuit {
        let m = &self.motor;
        Circuit {
            rs: m.rs_ohm,
            rr: m.rr_ohm,
            ls: m.ls_h,
            lr: m.lr_h,
            lm: m.lm_h,
            np: m.np(),
            b_total: m.b_nms + m.bl_nms,
        }
    }
}

/// A symmetric 3 x 3 matrix (covariance or weight of [`Residual3`]).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
struct Sym3 {
    xx: f32,
    xy: f32,
    xz: f32,
    yy: f32,
    yz: f32,
    zz: f32,
}

impl Sym3 {
    /// `diag(1/s^2)`: the weight of independent spreads `s`.
    fn diagonal_weight(s: &Residual3) -> Self {
        let [a, b, c] = *s;
        Sym3 {
            xx: 1.0 / (a * a),
            yy: 1.0 / (b * b),
            zz: 1.0 / (c * c),
            ..Sym3::default()
        }
    }

    /// Adds the outer product `d d^T`.
    fn add_outer(&mut self, d: &Residual3) {
        let [x, y, z] = *d;
        self.xx += x * x;
        self.xy += x * y;
        self.xz += x * z;
        self.yy += y * y;
        self.yz += y * z;
        self.zz += z * z;
    }

    /// The inverse (adjugate over determinant); `None` when the determinant is not
    /// positive or anything is not finite.
    fn inverse(&self) -> Option<Self> {
        let m = self;
        let c_xx = m.yy * m.zz - m.yz * m.yz;
        let c_xy = m.xz * m.yz - m.xy * m.zz;
        let c_xz = m.xy * m.yz - m.xz * m.yy;
        let det = m.xx * c_xx + m.xy * c_xy + m.xz * c_xz;
        if !(det > 0.0 && det.is_finite()) {
            return None;
        }
        let inv = Sym3 {
            xx: c_xx / det,
            xy: c_xy / det,
            xz: c_xz / det,
            yy: (m.xx * m.zz - m.xz * m.xz) / det,
            yz: (m.xy * m.xz - m.xx * m.yz) / det,
            zz: (m.xx * m.yy - m.xy * m.xy) / det,
        };
        let all = [inv.xx, inv.xy, inv.xz, inv.yy, inv.yz, inv.zz];
        all.iter().all(|v| v.is_finite()).then_some(inv)
    }

    /// `d^T M d`.
    fn quadratic(&self, d: &Residual3) -> f32 {
        let [x, y, z] = *d;
        self.xx * x * x
            + self.yy * y * y
            + self.zz * z * z
            + 2.0 * (self.xy * x * y + self.xz * x * z + self.yz * y * z)
    }
}

/// `a - b`, element by element.
fn sub3(a: &Residual3, b: &Residual3) -> Residual3 {
    let ([a0, a1, a2], [b0, b1, b2]) = (*a, *b);
    [a0 - b0, a1 - b1, a2 - b2]
}

impl Circuit {
    /// This circuit with parameter `j` (0 Rs, 1 Rr, 2 the stator leakage, 3 the rotor
    /// leakage, 4 Lm with the leakages kept) [`NAMEPLATE_UNCERTAINTY`] larger.
    fn nameplate_off(mut self, j: usize) -> Self {
        let mut f = [1.0f32; 5];
        if let Some(x) = f.get_mut(j) {
            *x += NAMEPLATE_UNCERTAINTY;
        }
        let [rs, rr, lls, llr, lm] = f;
        let (l_s, l_r) = (self.ls - self.lm, self.lr - self.lm);
        self.rs *= rs;
        self.rr *= rr;
        self.lm *= lm;
        self.ls = l_s * lls + self.lm;
        self.lr = l_r * llr + self.lm;
        self
    }

    /// The circuit with parameter fault `f` of factor `k`. The `ls` and `lr` faults scale
    /// the leakage inductances (DESIGN.md §2: PSIM's Ls and Lr are the leakages); on a side
    /// without leakage (a Gamma-model machine) they scale Lm, as the simulator does.
    fn with(mut self, f: Fault, k: f32, m: &MotorModel) -> Self {
        let (lls, llr) = (m.lls_h(), m.llr_h());
        let tiny = 1e-9 * m.lm_h;
        match f {
            Fault::Rs => self.rs *= k,
            Fault::Rr => self.rr *= k,
            Fault::Ls | Fault::Lr => {
                let (l_side, side_is_s) = if f == Fault::Ls {
                    (lls, true)
                } else {
                    (llr, false)
                };
                if l_side <= tiny {
                    self.lm = m.lm_h * k;
                    self.ls = lls + self.lm;
                    self.lr = llr + self.lm;
                } else if side_is_s {
                    self.ls = lls * k + m.lm_h;
                } else {
                    self.lr = llr * k + m.lm_h;
                }
            }
            Fault::B => self.b_total = m.b_nms * k + m.bl_nms,
            Fault::Bl => self.b_total = m.b_nms + m.bl_nms * k,
            Fault::CurrentSensor | Fault::VoltageSensor | Fault::SpeedSensor => {}
        }
        self
    }
}

/// Sorts candidates by probability, most probable first (insertion sort: nine entries,
/// no allocation, stable so Table 1's order breaks ties).
fn sort_by_probability(c: &mut [Candidate; FAULT_COUNT]) {
    for n in 1..c.len() {
        let mut j = n;
        while j > 0 {
            let swap = match (c.get(j - 1), c.get(j)) {
                (Some(a), Some(b)) => b.probability > a.probability,
                _ => false,
            };
            if !swap {
                break;
            }
            c.swap(j - 1, j);
            j -= 1;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::reference::{MOTOR_2P2KW, MOTOR_3HP};
    use crate::MotorParameters;

    type C = (f64, f64);
    fn mul(a: C, b: C) -> C {
        (a.0 * b.0 - a.1 * b.1, a.0 * b.1 + a.1 * b.0)
    }
    fn div(a: C, b: C) -> C {
        let d = b.0 * b.0 + b.1 * b.1;
        ((a.0 * b.0 + a.1 * b.1) / d, (a.1 * b.0 - a.0 * b.1) / d)
    }
    fn add(a: C, b: C) -> C {
        (a.0 + b.0, a.1 + b.1)
    }

    /// The true machine: parameters in f64 with a fault applied the way the simulator
    /// applies it (leakages scaled; Lm on a side without leakage).
    fn faulty(p: &MotorParameters, f: Option<Fault>, k: f64) -> MotorParameters {
        let mut m = *p;
        let (lls, llr) = (p.ls_h - p.lm_h, p.lr_h - p.lm_h);
        match f {
            Some(Fault::Rs) => m.rs_ohm *= k,
            Some(Fault::Rr) => m.rr_ohm *= k,
            Some(Fault::Ls) if lls <= 1e-9 => {
                m.lm_h *= k;
                m.ls_h = m.lm_h;
                m.lr_h = llr + m.lm_h;
            }
            Some(Fault::Ls) => m.ls_h = lls * k + p.lm_h,
            Some(Fault::Lr) => m.lr_h = llr * k + p.lm_h,
            Some(Fault::B) => m.b_nms *= k,
            Some(Fault::Bl) => m.bl_nms *= k,
            _ => {}
        }
        m
    }

    /// Steady state of the true machine `m` on `v_peak` at `we` with its viscous load,
    /// solved from the equivalent circuit (magnetising branch in parallel with the rotor
    /// branch) and the air-gap power `Te = 3/2 Np |Ir|^2 Rr / ws` by bisection on the
    /// slip; the sensors read `k` times the truth under a sensor fault.
    fn measure(m: &MotorParameters, v_peak: f64, we: f64, f: Option<Fault>, k: f64) -> SteadyPoint {
        let np = (m.poles / 2) as f64;
        let (lls, llr) = (m.ls_h - m.lm_h, m.lr_h - m.lm_h);
        let solve = |s: f64| {
            let zm = (0.0, we * m.lm_h);
            let zr = (m.rr_ohm / s, we * llr);
            let z = add((m.rs_ohm, we * lls), div(mul(zm, zr), add(zm, zr)));
            let i = div((0.0, v_peak), z);
            let ir = div(mul(i, zm), add(zm, zr));
            let te = 1.5 * np * (ir.0 * ir.0 + ir.1 * ir.1) * m.rr_ohm / (s * we);
            let wr = we * (1.0 - s);
            (te - (m.b_nms + m.bl_nms) * wr / np, i, wr)
        };
        let (mut lo, mut hi) = (1e-7, 0.5);
        for _ in 0..100 {
            let mid = 0.5 * (lo + hi);
            if solve(mid).0 > 0.0 {
                hi = mid;
            } else {
                lo = mid;
            }
        }
        let (_, i, wr) = solve(0.5 * (lo + hi));
        let g = |x: Fault| if f == Some(x) { k } else { 1.0 };
        let (gi, gv, gw) = (
            g(Fault::CurrentSensor),
            g(Fault::VoltageSensor),
            g(Fault::SpeedSensor),
        );
        SteadyPoint {
            i: Dq {
                d: (i.0 * gi) as f32,
                q: (i.1 * gi) as f32,
            },
            v: Dq {
                d: 0.0,
                q: (v_peak * gv) as f32,
            },
            we_rad_s: we as f32,
            wr_rad_s: (wr * gw) as f32,
        }
    }

    /// A third machine with other per-unit values: an 11 kW, 400 V, 50 Hz, 2-pole motor
    /// (low Rr, high Lm: slip about 1 %), not one the code was developed on.
    fn motor_11kw() -> MotorParameters {
        MotorParameters {
            rs_ohm: 0.42,
            rr_ohm: 0.36,
            ls_h: 0.108,
            lr_h: 0.109,
            lm_h: 0.104,
            poles: 2,
            j_kgm2: 0.04,
            b_nms: 0.003,
            bl_nms: 0.11,
        }
    }

    fn machines() -> [(&'static str, MotorParameters, f64, f64); 3] {
        let v = |ll: f64| ll * (2.0f64 / 3.0).sqrt();
        [
            ("2.2 kW", MOTOR_2P2KW.motor, v(400.0), 314.159),
            ("3 hp", MOTOR_3HP.motor, v(220.0), 376.99),
            ("11 kW", motor_11kw(), v(400.0), 314.159),
        ]
    }

    #[test]
    fn the_healthy_machine_has_zero_residuals_at_its_steady_state() {
        for (name, m, v, we) in machines() {
            let iso =
                Isolator::new(m.model(), v as f32, (we / core::f64::consts::TAU) as f32).unwrap(); // ok: test
            let p = measure(&m, v, we, None, 1.0);
            let e = iso.residuals(&p, None).unwrap(); // ok: test
            assert!(e.iter().all(|x| x.abs() < 1e-4), "{name}: {e:?}");
            assert_eq!(iso.isolate(&p).state, IsolationState::NoDeviation, "{name}");
        }
    }

    /// Cases that cannot be named alone, and why (asserted: not named wrongly instead).
    fn not_separable(name: &str, f: Fault, change: f64) -> bool {
        // The 3 hp machine: Rs, Ls and Lr at 10 % move |V - Z I| by under 0.2 % of |V|,
        // about one spread (below detection); its leakage change of 50 % points where a
        // 3 % Rr change does (0.1-2 deg apart). Rr at 10 %: a 0.3 % speed-sensor error
        // fits too (the rotor circuit depends on Rr/slip; only the torque balance helps).
        (name == "3 hp" && change.abs() < 0.2 && matches!(f, Fault::Rs | Fault::Ls | Fault::Lr))
            || (name == "3 hp" && f == Fault::Ls)
            || (name == "3 hp" && f == Fault::Rr && change.abs() < 0.2)
            || (name == "11 kW" && f == Fault::Rs && change.abs() < 0.2)
    }

    #[test]
    fn every_fault_is_named_alone_with_its_size_or_not_named_at_all() {
        let mut named = 0;
        for (name, m, v, we) in machines() {
            let iso =
                Isolator::new(m.model(), v as f32, (we / core::f64::consts::TAU) as f32).unwrap(); // ok: test
            for f in Fault::ALL {
                for change in [-0.5f64, 0.5, -0.1, 0.1] {
                    let k = 1.0 + change;
                    let p = measure(&faulty(&m, Some(f), k), v, we, Some(f), k);
                    let out = iso.isolate(&p);
                    // Never a wrong fault at probability 0.5 or more.
                    for c in &out.candidates {
                        let friction = matches!(f, Fault::B | Fault::Bl)
                            && matches!(c.fault, Fault::B | Fault::Bl);
                        assert!(
                            c.fault == f || friction || c.probability < 0.5,
                            "{name} {f} {change}: {} named at {}",
                            c.fault,
                            c.probability
                        );
                    }
                    let expected = !matches!(f, Fault::B | Fault::Bl)
                        && !not_separable(name, f, change)
                        && (change.abs() > 0.2
                            || matches!(
                                f,
                                Fault::Rs
                                    | Fault::Rr
                                    | Fault::CurrentSensor
                                    | Fault::VoltageSensor
                                    | Fault::SpeedSensor
                            )
                            || name == "2.2 kW"
                            || name == "11 kW");
                    if !expected {
                        continue;
                    }
                    let top = out
                        .named_fault()
                        .unwrap_or_else(|| panic!("{name} {f} {change}: not named: {out:?}")); // ok: test
                    assert_eq!(top.fault, f, "{name} {f} {change}: {out:?}");
                    assert!(
                        (f64::from(top.change) - change).abs() < 0.2 * change.abs(),
                        "{name} {f} {change}: size {}",
                        top.change
                    );
                    named += 1;
                }
            }
        }
        // 3 machines x 7 faults x 4 sizes, minus the documented exceptions.
        assert!(named >= 70, "{named} named");
    }

    #[test]
    fn b_and_bl_are_one_friction_class() {
        let (_, m, v, we) = machines()[1];
        let iso = Isolator::new(m.model(), v as f32, 60.0).unwrap(); // ok: test
        let p = measure(&faulty(&m, Some(Fault::Bl), 1.5), v, we, None, 1.0);
        let out = iso.isolate(&p);
        let top2: Vec<Fault> = out.candidates[..2].iter().map(|c| c.fault).collect();
        assert!(
            top2.contains(&Fault::B) && top2.contains(&Fault::Bl),
            "{out:?}"
        );
        assert!(out.separation_deg < 1.0, "{}", out.separation_deg);
        let bl = out
            .candidates
            .iter()
            .find(|c| c.fault == Fault::Bl)
            .unwrap(); // ok: test
        assert!((bl.change - 0.5).abs() < 0.1, "{}", bl.change);
        assert!(
            out.named_fault().is_none(),
            "neither is named alone: {out:?}"
        );
        assert!(
            matches!(out.named(), Some(Named::Friction { .. })),
            "{out:?}"
        );
    }

    #[test]
    fn a_change_no_fault_explains_is_unknown_not_a_wrong_name() {
        // Rs and Lr both changed: no single fault's direction fits.
        let (_, m, v, we) = machines()[1];
        let iso = Isolator::new(m.model(), v as f32, 60.0).unwrap(); // ok: test
        let mut t = faulty(&m, Some(Fault::Rs), 1.6);
        t.lr_h = (m.lr_h - m.lm_h) * 0.4 + m.lm_h;
        t.bl_nms *= 0.6;
        let out = iso.isolate(&measure(&t, v, we, None, 1.0));
        assert!(out.deviation > 10.0);
        assert!(
            out.candidates.iter().all(|c| c.probability < 0.5),
            "{out:?}"
        );
    }

    #[test]
    fn a_learned_baseline_absorbs_a_nameplate_that_is_off() {
        // Nominal parameters 20 % off; learning on the healthy machine at two loads, then
        // an Rr fault is named from the change.
        let (_, m, v, we) = machines()[0];
        let mut off = m;
        off.rs_ohm *= 1.2;
        off.lm_h *= 0.8;
        off.ls_h = off.lm_h;
        off.lr_h = m.lr_h - m.lm_h + off.lm_h;
        let mut iso = Isolator::new(off.model(), v as f32, 50.0).unwrap(); // ok: test
        assert_ne!(
            iso.isolate(&measure(&m, v, we, None, 1.0)).state,
            IsolationState::NoDeviation
        );
        for n in 0..20 {
            let mut load = m;
            load.bl_nms *= 0.95 + 0.005 * n as f64;
            iso.learn(&measure(&load, v, we, None, 1.0));
        }
        assert!(iso.finish_learning());
        let healthy = iso.isolate(&measure(&m, v, we, None, 1.0));
        assert_eq!(healthy.state, IsolationState::NoDeviation, "{healthy:?}");
        let out = iso.isolate(&measure(
            &faulty(&m, Some(Fault::Rr), 1.5),
            v,
            we,
            None,
            1.0,
        ));
        // Learned over a 10 % load range and widened for the nameplate's error away from
        // the learned point, the torque balance no longer tells Rr from a speed-sensor
        // error (directions 0.2 deg apart): they share the probability, neither is named
        // alone, and Rr's size is right.
        let rr = out.candidates.iter().find(|c| c.fault == Fault::Rr);
        let rr = rr.unwrap(); // ok: test
        assert!(rr.probability >= 0.4, "{out:?}");
        assert!((rr.change - 0.5).abs() < 0.05, "{out:?}");
        assert!(
            matches!(out.named_fault().map(|c| c.fault), None | Some(Fault::Rr)),
            "{out:?}"
        );
    }

    #[test]
    fn unusable_points_are_not_judged() {
        let (_, m, v, _) = machines()[1];
        let iso = Isolator::new(m.model(), v as f32, 60.0).unwrap(); // ok: test
        for p in [
            SteadyPoint::default(),
            SteadyPoint {
                i: Dq {
                    d: f32::NAN,
                    q: 1.0,
                },
                v: Dq { d: 0.0, q: 100.0 },
                we_rad_s: 377.0,
                wr_rad_s: 370.0,
            },
        ] {
            assert_eq!(iso.isolate(&p).state, IsolationState::NotJudged);
        }
        assert!(Isolator::new(m.model(), f32::NAN, 60.0).is_none());
    }

    /// The follower's schedule: nothing before half a second of steady running; a load or
    /// supply step restarts the average; the baseline learned while commissioning learns
    /// goes into force when it ends; an Rr +40 % change is then named with its size, and
    /// reported once it has been named for `CONFIRM_S`.
    #[test]
    fn the_follower_averages_learns_and_isolates_on_schedule() {
        let (_, m, v, we) = machines()[0];
        let iso = Isolator::new(m.model(), v as f32, (we / core::f64::consts::TAU) as f32);
        let mut f = Follower::new(iso.unwrap()); // ok: test
        let healthy = measure(&m, v, we, None, 1.0);
        let dt = 0.01;
        // 0.49 s of steady running: waiting.
        for _ in 0..49 {
            assert_eq!(f.observe(&healthy, dt, true, false), Step::Waiting);
        }
        assert!(f.last().is_none());
        // Learning for 2 s: points go into the baseline, none is isolated.
        let mut learned = 0;
        for _ in 0..200 {
            match f.observe(&healthy, dt, true, true) {
                Step::Learned => learned += 1,
                Step::Waiting => {}
                other => panic!("while learning: {other:?}"), // ok: test
            }
        }
        // One point per STEP_S block once AVERAGE_S is averaged: 0.5..2.49 s.
        assert!((19..=21).contains(&learned), "{learned} points learned");
        assert_eq!(
            f.observe(&healthy, dt, true, false),
            Step::LearningEnded(true)
        );
        assert!(f.learned());
        // A 5 % voltage step: not steady, the average restarts (0.5 s before a result).
        let mut stepped = measure(&m, 1.05 * v, we, None, 1.0);
        let mut steps = 0;
        for k in 0..100 {
            if let Step::Isolated(r) = f.observe(&stepped, dt, true, false) {
                assert!(k >= 49, "isolated {k} steps after the step");
                assert_eq!(r.state, IsolationState::NoDeviation, "{r:?}");
                steps += 1;
            }
        }
        assert!(steps >= 5, "{steps} isolations in 1 s");
        // An unusable point (a sensor fault) drops the average.
        assert_eq!(f.observe(&stepped, dt, false, false), Step::Waiting);
        let rr = faulty(&m, Some(Fault::Rr), 1.4);
        stepped = measure(&rr, 1.05 * v, we, Some(Fault::Rr), 1.4);
        // Named after 0.5 s of averaging, reported after CONFIRM_S more.
        let (mut named, mut unconfirmed) = (None, 0);
        for k in 0..150 {
            match f.observe(&stepped, dt, true, false) {
                Step::Isolated(r) => {
                    assert!(k >= 99, "in force {k} steps after the change");
                    named = r.named_fault();
                }
                Step::Unconfirmed(r) => {
                    assert_eq!(r.named_fault().map(|c| c.fault), Some(Fault::Rr));
                    unconfirmed += 1;
                }
                _ => {}
            }
        }
        // One per STEP_S block for CONFIRM_S.
        assert!(unconfirmed >= 4, "{unconfirmed} unconfirmed isolations");
        let c = named.unwrap_or_else(|| panic!("Rr +40 % not named: {:?}", f.last())); // ok: test
        assert_eq!(c.fault, Fault::Rr);
        assert!((c.change - 0.4).abs() < 0.04, "size {}", c.change);
        // Bad time steps count as no time.
        for dt in [f32::NAN, -1.0, f32::INFINITY] {
            assert_eq!(f.observe(&stepped, dt, true, false), Step::Waiting);
        }
    }
    /// The nominal parameters 15-20 % off (Rs +20 %, Rr -19 %, leakages -13 %, Lm -15 %),
    /// learned at the machine's own load; then the load moves to 0.5-1.1 of it, with or
    /// without a fault. Before the weight was widened away from the learned point this
    /// named wrong faults with confidence (a 10 % load rise with Rr +50 % on the 2.2 kW
    /// machine: speed sensor at 0.74; found by hand on a simulated 11 kW log: current
    /// sensor at 0.95 for Rr +50 % after a load step to 0.7).
    #[test]
    fn a_load_change_with_a_fault_and_a_nameplate_that_is_off() {
        let (mut right, mut cases) = (0, 0);
        let mut wrong = Vec::new();
        for (name, m, v, we) in machines() {
            let mut off = m;
            let (lls, llr) = (m.ls_h - m.lm_h, m.lr_h - m.lm_h);
            off.rs_ohm *= 1.2;
            off.rr_ohm *= 0.81;
            off.lm_h *= 0.85;
            off.ls_h = lls * 0.87 + off.lm_h;
            off.lr_h = llr * 0.87 + off.lm_h;
            let hz = (we / core::f64::consts::TAU) as f32;
            let mut iso = Isolator::new(off.model(), v as f32, hz).unwrap(); // ok: test
            for _ in 0..20 {
                iso.learn(&measure(&m, v, we, None, 1.0));
            }
            assert!(iso.finish_learning());
            for load in [0.5, 0.7, 0.9, 1.1] {
                let mut t = m;
                t.bl_nms *= load;
                let healthy = iso.isolate(&measure(&t, v, we, None, 1.0));
                if let Some(Named::Fault(c)) = healthy.named() {
                    wrong.push(format!("{name} load {load} healthy: {c:?}"));
                }
                for (f, k) in [
                    (Fault::Rr, 1.5),
                    (Fault::Rs, 1.5),
                    (Fault::CurrentSensor, 0.7),
                    (Fault::SpeedSensor, 1.01),
                    (Fault::Lr, 0.5),
                ] {
                    let out = iso.isolate(&measure(&faulty(&t, Some(f), k), v, we, Some(f), k));
                    cases += 1;
                    let top = out.candidates[0];
                    eprintln!(
                        "{name} load {load} {f} {k}: top {} {:.2} ({:+.2}), second {} {:.2}, unknown {:.2}",
                        top.fault, top.probability, top.change, out.candidates[1].fault,
                        out.candidates[1].probability, out.unknown_probability
                    );
                    match out.named() {
                        Some(Named::Fault(c)) if c.fault == f => right += 1,
                        Some(Named::Fault(c)) => {
                            wrong.push(format!("{name} load {load} {f} {k}: {c:?}"))
                        }
                        _ => {}
                    }
                }
            }
        }
        eprintln!("named right {right} of {cases}");
        assert!(wrong.is_empty(), "{wrong:#?}");
    }
}
