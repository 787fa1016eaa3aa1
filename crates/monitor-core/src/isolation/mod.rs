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
//! The three parity residuals ([`ParityResiduals`]) are `e_d + j e_q = (V - Z I)/|V|` and
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
//! # Over a commissioned range
//! A commissioning that saw the load move learns the residuals over a span of operating
//! points, not at one: its learned spread holds whatever the nameplate's error does across
//! that span. Within the span (the active current between the smallest and the largest
//! learned, the span at least [`WIDE_SPAN`] of its largest value, the voltage within the
//! commissioned range's margin: [`crate::operating_range`]) the misfit is therefore not
//! widened; outside it, it is widened as above. (Measured on service logs whose load
//! moved +-30 % every 4 s, commissioned over the range: the widening for a 5 % nameplate
//! error between 0.7 and 1.3 of the load hid an Rs +50 % fault on a 37 kW machine, 2 spreads
//! of deviation for 15 on the voltage equations.)
//!
//! # The load before the deviation
//! The torque balance needs the load, which in service moves. The last steady point judged
//! healthy before a deviation began (the *anchor*) tells the load there: the torque the
//! nominal machine gave. Where the active current (the input power's measure) has not
//! moved by more than [`ANCHOR_LOAD_BAND`] since, the load is taken as the same viscous
//! load, carried to the point's speed ([`LOAD_LAW_SPREAD`] allowed for its law), and
//! [`Isolator::isolate_points_anchored`] compares each hypothesis' torque with it. A
//! sensor gain step, which moves neither the machine nor its load, is then judged with the
//! torque balance (a current sensor's error scales the torque, a voltage sensor's does not:
//! the two scale `Z = V / I` alike and only the torque tells them apart), and an Rr change
//! parts from a speed-sensor error at one load level. A load step leaves the voltage
//! equations to decide.
//!
//! # Heating is not a fault
//! A winding that warms raises Rs and Rr together, by the same factor
//! `k = 1 + alpha dT` (copper: [`COPPER_ALPHA_PER_K`] = 0.393 %/K; an aluminium cage's
//! 0.403 %/K is within the fit's resolution). Beside the faults the isolation fits this
//! *heating* hypothesis (Rs and Rr both times `k`, `k` from [`HEATING_K_MIN`] to
//! [`HEATING_K_MAX`] of the winding's commissioned temperature: 25 K cooler to 160 K warmer,
//! beyond an insulation class H winding's 125 K rise) and ranks it with them
//! ([`Isolation::heating`]). When it is the most probable explanation the [`Follower`]
//! tracks it: the isolator's machine takes the warmer resistances
//! ([`Isolator::heating_factor`]) and the point is isolated again against it, so the
//! rise is reported, not a fault, and a later fault is judged against the warm machine.
//! A change that moves Rs or Rr alone, or both but apart from their common ratio, fits a
//! fault better and is named as before. Where heating fits best but not alone (on a machine
//! whose Rs is a small part of its impedance, heating, Rr and the speed sensor's gain point
//! almost the same way), a first step of at most [`HEATING_ONSET_K`] is still taken as the
//! winding beginning to warm ([`Isolation::heating_begins`]): a deviation that grew from
//! nothing is a warming, a step fault appears at its full size.
//!
//! # The temperature unknown
//! Against the parameter file's nominal values (no learned baseline, so no measured rise
//! either) the winding's temperature is not known: a motor in service runs 20-100 K above
//! the file's, and Rs and Rr follow it. A fault is then fitted on a winding at any
//! temperature of the heating range (its size and the heating factor together,
//! `Isolator::fit_at_any_temperature`), and takes part in the ranking only for what it
//! explains beyond the heating: where it lowers the heating hypothesis' misfit by at least
//! [`DETECT_CHI2`] (a change beyond the heated machine detected, as any deviation is). The
//! others explain nothing the heating does not, and their probability is 0. Where Rs is
//! large against the reactances (a small motor) and the load light, the heating and a
//! stator-leakage change move the residuals almost alike, and a fault fitted at the file's
//! temperature named the leakage for a loosening connection on a warm winding (issue 79:
//! `ls +35 %` at p 0.90 for Rs +10 % on a winding 20 K warm at 42 % of the rated torque).
//! Fitted at any temperature, one point's
//! two stator-voltage equations no longer tell a fault from another (two unknowns, two
//! equations): nothing is named from one point with the load unknown; over two load levels
//! or more (the joint fit, [`Evidence`]) or with the torque balance, a fault on a warm
//! winding parts from another. Rs beyond Rr stays what it is: an Rs rise, or an Rr fall on
//! a winding warmer still, which no log without a temperature tells apart.
//!
//! # Heating during commissioning
//! A motor commissioned soon after its start warms while the baseline is learned. Its
//! residuals then drift along the heating direction `h = de/dk` over the window, and a
//! plain mean and spread would take the drift for scatter (measured: the 3 hp motor
//! warming 20 K over a 6 s window learned spreads 15 times the healthy ones, and a later
//! warming was named as an Ls fault). So learning fits `e(t) = m + r h t` (`t` since the
//! window began; the three residuals weighted by [`DEFAULT_SPREAD`]): when the load stayed
//! within [`WIDE_SPAN`], the trend is a rise (or fall) of at least [`WARMING_K`] over the
//! window and it explains at least [`WARMING_EXPLAINS`] of the scatter, the baseline's mean is `m` (the machine at the window's start), its spread that
//! about the trend, and the tracked heating factor at the window's end `1 - r t_end` (the
//! rise since the window began). Otherwise mean and spread are the plain ones.
//!
//! # How sure a name is
//! The probabilities are meant as calibrated ones: of the faults named at probability p,
//! about p are right (measured on simulated logs the rules were not tuned on: the host's
//! `crates/monitor-studies/tests/studies/isolation_calibration.rs`, docs/isolation.md "How often a name is right"). What
//! keeps them so:
//!
//! - **The directions' own uncertainty.** Each fault's direction is computed on the
//!   parameter file's machine; a file that is off moves it by about as much. The ranking's
//!   temperature is `T = max(1 + eps^2 chi2_0 / n, chi2_min / 2)` (`n` the equations):
//!   a model error of `eps` times the deviation, spread over the equations. `eps` is
//!   [`DIRECTION_UNCERTAINTY`] times [`NAMEPLATE_UNCERTAINTY`] times the evidenced fraction
//!   of it ([`NAMEPLATE_FLOOR`]..1, module docs "Away from the learned point"), and
//!   [`NAMEPLATE_UNCERTAINTY`] itself against the file's nominal values.
//! - **A name stands apart.** A fault is named at [`NAME_PROBABILITY`] or more,
//!   [`NAME_MARGIN`] ahead of the runner-up: another fault, heating or the unknown fault;
//!   and with a size inside [`K_MIN`]..[`K_MAX`] (at the end of the range the change may be
//!   larger, and a file far off fits there too). Below it the fault is a leading candidate.
//! - **Heating as fast as a winding can warm.** Heating is bounded by how far the winding
//!   can have warmed since its temperature was last judged ([`HEATING_ONSET_K`] plus
//!   [`HEATING_RATE_K_PER_S`] per second, [`Isolator::set_heating_reach_k`]): a step larger
//!   than that is a fault, not heating. Every fault is fitted with the tracked
//!   temperature's lag allowed for, one standard deviation [`HEATING_LAG_SIGMA_K`] on a
//!   warm machine plus the warming rate last seen (at least [`HEATING_DRIFT_K_PER_S`] once
//!   it was seen warming) times the time since; the joint fit over operating points allows
//!   for it in its weights.
//! - **The load is unknown.** Against the file's nominal values with the load an unknown
//!   input ([`Isolator::set_load_unknown`]) the torque balance is left out.
//!
//! Faults that cannot be separated:
//! - **B and Bl**: both scale the same load term `(B + Bl) wr`; the directions coincide at
//!   every operating point (one friction class; the size is given for each as if it alone
//!   changed);
//! - **current and voltage sensor at no load**: both scale `Z` (the measured `V/I`); only
//!   the torque balance separates them, and at no load the torque is small;
//! - **Rr, the speed sensor and (near rated load) the stator leakage `ls`**: `Z` and `Te` depend on the slip
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
//! # Searches started from the last result
//! Each fault's size is searched on a grid of [`K_MIN`]..[`K_MAX`] and refined by golden
//! section. A search repeated on a point that moves little (the [`Follower`]'s isolation
//! every [`STEP_S`], the [`Evidence`]'s joint fit) starts from the grid point that was best
//! the last time ([`SearchHints`]): where it is still below its two grid neighbours and
//! `k = 1`, the rest of the grid is not searched (for a misfit with one minimum over the
//! grid, the same point and so the same result); the whole grid is searched where the last
//! whole grid had more than one minimum, where the deviation moved by more than half a
//! spread or 1 % since the last isolation, where the number of points changed, and every
//! tenth isolation.
//!
//! Cost: about 300 circuit evaluations of some 60 flops each per call (280 for the fits,
//! 12 for the weight; about half the fits' from the last result); run it from a
//! low-priority task (the firmware: thread mode, from the status hand-over, every
//! [`STEP_S`] at most), never from the per-sample path. [`Follower`] runs the schedule
//! (averaging the operating point, learning the baseline, isolating) for the firmware and
//! the host alike.
//!
//! # What a name is called
//! What a named fault of a given size is called (a FAULT, watched, or no judgement before
//! commissioning) is the decision table of [`crate::verdict`], shared by the host's verdict
//! and panel and the board's FAULT lamp; the sizes it reads, [`MIN_FAULT_CHANGE`] and
//! [`NOMINAL_UNCERTAINTY`], with their reasons, are here.

mod follower;
pub use follower::{
    steady_against, Follower, Step, AVERAGE_MAX_S, AVERAGE_S, BLOCKS, CONFIRM_S, PROBE_LAG_K,
    SETTLE_S, STEADY_FRACTION, STEP_S,
};
mod circuit;
mod evidence;
pub use evidence::{Evidence, LEVEL_APART};
mod isolator;
pub use isolator::{
    SearchHints, ANCHOR_LOAD_BAND, ANCHOR_TORQUE_SPREAD, HEATING_LAG_SIGMA_K, LOAD_LAW_SPREAD,
    MAX_POINTS,
};
mod outcome;
pub use outcome::{
    Candidate, Heating, Isolation, IsolationState, Named, HEATING_MAX_MISFIT, HEATING_ONSET_K,
    WARMING_EXPLAINS, WARMING_K,
};
mod resistances;
pub use resistances::{resistance_split, ResistanceSplit, MIN_SPLIT_SLIP, SPLIT_FACTOR_RANGE};
mod rule;
pub use rule::{within_nominal_uncertainty, MIN_FAULT_CHANGE, NOMINAL_UNCERTAINTY};

use circuit::{Circuit, Sym3};

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
/// The fastest a winding warms [K/s]: a copper winding's adiabatic rate at a locked
/// rotor's current density (about 10 K/s; module docs, "Heating is not a fault"). A heating
/// step larger than this rate allows since the temperature was last judged, plus
/// [`HEATING_ONSET_K`], is no heating ([`Isolator::set_heating_reach_k`]).
pub const HEATING_RATE_K_PER_S: f32 = 10.0;
/// The least warming rate the tracked temperature's uncertainty grows by while it is not
/// judged, once the winding was seen warming [K/s] ([`Isolator::set_heating_reach_k`]; the
/// [`Follower`] uses the rate it last saw, at least this; a winding never seen warming has
/// none): a motor at its working temperature drifts by a fraction of a kelvin a second as
/// its load moves.
pub const HEATING_DRIFT_K_PER_S: f32 = 0.1;
/// Temperature coefficient of copper's resistance near 20 °C [1/K] (IEC 60228; IEEE Std 112
/// corrects resistances with 234.5 + T, the same 0.393 %/K at 20 °C).
pub const COPPER_ALPHA_PER_K: f32 = 0.00393;
/// Smallest resistance factor of the heating hypothesis, relative to the commissioned
/// winding: 25 K cooler (a motor commissioned warm, then cooled).
pub const HEATING_K_MIN: f32 = 1.0 - 25.0 * COPPER_ALPHA_PER_K;
/// Largest resistance factor of the heating hypothesis: 160 K warmer than commissioned (a
/// cold start at 20 °C to 180 °C, the class H limit; beyond it a change is not heating).
pub const HEATING_K_MAX: f32 = 1.0 + 160.0 * COPPER_ALPHA_PER_K;

/// Smallest width of the learned load span, as a fraction of its largest magnitude, that
/// counts as a commissioned range rather than one operating point (module docs, "Over a
/// commissioned range"): 10 %.
pub const WIDE_SPAN: f32 = 0.1;

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
/// The least probability of a fault named alone (module docs, "How sure a name is").
pub const NAME_PROBABILITY: f32 = 0.9;
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

/// The relative uncertainty of a fault's direction in the residual space against a learned
/// baseline, per unit of the parameter file's evidenced error (module docs, "How sure a
/// name is").
pub const DIRECTION_UNCERTAINTY: f32 = 0.1;

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
    /// The point's load and voltage ([`crate::OperatingPoint`]): its active current (the
    /// current's part in phase with the voltage, `(vd id + vq iq) / |v|` [A]; NaN without
    /// voltage) and `|v|` [V].
    pub fn operating_point(&self) -> crate::OperatingPoint {
        crate::OperatingPoint::from_dq(self.v.d, self.v.q, self.i.d, self.i.q)
    }

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
            wr_rad_s: o.operating.wr_rad_s,
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

/// The three parity residuals of the isolation (module docs), dimensionless: the d and q
/// components `e_d + j e_q = (V - Z I)/|V|` of the stator-voltage equation's misfit
/// (`Z`: the machine's steady-state impedance at the slip frequency), and the torque
/// balance's misfit `e_T = (Te - (B + Bl) wr / Np) / T_base`
/// ([`Isolator::torque_base_nm`]). Also used for their means and spreads ([`Baseline`]).
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct ParityResiduals {
    /// `e_d`: the d component of the stator-voltage misfit `(V - Z I)/|V|`.
    pub voltage_d: f32,
    /// `e_q`: the q component of the stator-voltage misfit `(V - Z I)/|V|`.
    pub voltage_q: f32,
    /// `e_T`: the torque-balance misfit `(Te - (B + Bl) wr / Np) / T_base`.
    pub torque: f32,
}

impl ParityResiduals {
    /// The residuals from `[e_d, e_q, e_T]` (the order of the flash record and the host's
    /// reports).
    pub const fn from_array([voltage_d, voltage_q, torque]: [f32; 3]) -> Self {
        ParityResiduals {
            voltage_d,
            voltage_q,
            torque,
        }
    }

    /// `[e_d, e_q, e_T]`.
    pub const fn to_array(self) -> [f32; 3] {
        [self.voltage_d, self.voltage_q, self.torque]
    }

    /// `f` applied to each residual.
    pub fn map(self, f: impl Fn(f32) -> f32) -> Self {
        Self::from_array(self.to_array().map(f))
    }

    /// `f` applied to each residual and its counterpart in `other`.
    pub fn zip_map(self, other: Self, f: impl Fn(f32, f32) -> f32) -> Self {
        ParityResiduals {
            voltage_d: f(self.voltage_d, other.voltage_d),
            voltage_q: f(self.voltage_q, other.voltage_q),
            torque: f(self.torque, other.torque),
        }
    }

    /// Every residual finite.
    pub fn is_finite(&self) -> bool {
        self.to_array().iter().all(|x| x.is_finite())
    }
}

impl core::ops::Sub for ParityResiduals {
    type Output = Self;
    /// Element by element.
    fn sub(self, rhs: Self) -> Self {
        self.zip_map(rhs, |a, b| a - b)
    }
}

/// The healthy reference of the residuals: mean and spread (one standard deviation), from
/// [`Isolator::learn`] or the defaults (zero mean; spreads 0.5 % of |V| on the voltage
/// equations and 0.4 % of `T_base` on the torque balance: three times the scatter left by the
/// monitor's 5 Hz filters and the host's 0.5 s average, measured on simulated healthy runs
/// of both reference motors with the simulator's default 12-bit, 0.1 %-noise sensors:
/// 0.05 %, 0.05 % and 0.1 %).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Baseline {
    /// Mean residual of the healthy machine.
    pub mean: ParityResiduals,
    /// Spread of each residual, > 0.
    pub spread: ParityResiduals,
    /// The mean operating point the baseline was learned at; [`SteadyPoint::default`]
    /// (not a usable point) for the defaults and for baselines stored without it. Away
    /// from it the nameplate's error no longer cancels and the misfit is widened
    /// accordingly (module docs, "Away from the learned point").
    pub at: SteadyPoint,
}

impl Default for Baseline {
    fn default() -> Self {
        Baseline {
            mean: ParityResiduals::default(),
            spread: DEFAULT_SPREAD,
            at: SteadyPoint::default(),
        }
    }
}

/// The spreads used without a learned baseline (the nominal parameters' own error at other
/// operating points is in them).
pub const DEFAULT_SPREAD: ParityResiduals = ParityResiduals::from_array([0.0015, 0.0015, 0.004]);

/// The floor of learned spreads, for points averaged [`AVERAGE_MAX_S`]: the largest scatter
/// of such points measured on simulated healthy runs of the 3 hp, 2.2 kW and 11 kW machines
/// (5 kHz, 12-bit sensors, 0.1 % noise; 24 runs, 4 seeds per machine and load) was 0.022 %
/// of |V| on the voltage equations and 0.055 % of `T_base` on the torque balance, against
/// 0.08 % and 0.44 % with the former 0.5 s exponential average; the floor is about twice
/// that (a commissioning window's scatter understates what a longer run meets).
pub const LEARNED_SPREAD_FLOOR: ParityResiduals =
    ParityResiduals::from_array([0.0004, 0.0004, 0.001]);

/// Step of the heating factor for the heating direction `de/dk` while learning.
const LEARN_DK: f32 = 0.01;
/// Step of a fault's factor for its direction `de/dk` in [`Isolator::detection_limit`].
pub const LIMIT_DK: f32 = 0.01;

/// Sums of the healthy residuals learned while commissioning, for their mean and spread
/// with a warming of the winding taken out (module docs, "Heating during commissioning"):
/// per residual, [`TrendSums`] of `x` (the residual less the first point's) and `u = h t`
/// (the heating direction `h = de/dk` at the point times the point's time `t` [s] since
/// learning began).
#[derive(Debug, Clone, Copy, Default, PartialEq)]
struct Learning {
    n: u32,
    /// The first point's residuals (the sums are of the residuals less these).
    shift: [f32; 3],
    /// `[e_d, e_q, e_T]`'s sums.
    sums: [TrendSums; 3],
    /// The latest point's time since learning began [s].
    t_last: f32,
    at: SteadyPoint,
    /// The span of the load and the voltage of the points learned.
    range: crate::OperatingRange,
}

/// One residual's sums for the fit `x = m + r u` ([`Learning`]).
#[derive(Debug, Clone, Copy, Default, PartialEq)]
struct TrendSums {
    x: f32,
    u: f32,
    xx: f32,
    xu: f32,
    uu: f32,
}

impl TrendSums {
    fn add(&mut self, x: f32, u: f32) {
        self.x += x;
        self.u += u;
        self.xx += x * x;
        self.xu += x * u;
        self.uu += u * u;
    }

    /// The centred sums `(Sxx, Sxu, Suu)` of `n` points (`Sxx`, `Suu` at least 0).
    fn centred(&self, n: f32) -> (f32, f32, f32) {
        (
            crate::math::maxf(self.xx - self.x * self.x / n, 0.0),
            self.xu - self.x * self.u / n,
            crate::math::maxf(self.uu - self.u * self.u / n, 0.0),
        )
    }
}

/// The fault isolator: the nominal machine, the healthy baseline, and the fits.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Isolator {
    motor: MotorModel,
    torque_base_nm: f32,
    baseline: Baseline,
    learning: Learning,
    /// Rs and Rr factor of the winding's tracked temperature, relative to the
    /// commissioned one (module docs, "Heating is not a fault").
    heating_factor: f32,
    /// The span of the load and the voltage over which the baseline in force was learned
    /// (module docs, "Over a commissioned range"); empty for a baseline put into force by
    /// [`Isolator::set_baseline`].
    learned_range: crate::OperatingRange,
    /// How far the winding can have warmed or cooled since its temperature was last
    /// judged [K] ([`Isolator::set_heating_reach_k`]); infinite: the whole range.
    heating_reach_k: f32,
    /// One standard deviation of the tracked temperature's lag behind the winding's [K]
    /// ([`Isolator::set_heating_reach_k`]).
    lag_sigma_k: f32,
    /// The load is an unknown input ([`Isolator::set_load_unknown`]).
    torque_unknown: bool,
}

#[cfg(test)]
mod tests;
