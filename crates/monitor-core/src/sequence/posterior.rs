//! The probability that a change of the negative sequence is shorted turns, and in which
//! phase: a posterior over "no short" and "a short in phase a, b or c", so that a phase's
//! confidence is a probability a verdict can be built on.
//!
//! A reading `M = I2/I1` (the winding's part: the supply's `V2/Z2` taken out where the
//! voltages are known) is judged against a healthy reference `R` whose readings scatter
//! with a standard deviation `sigma` in each component (the reference's spread and the
//! reading's own). Two kinds of hypothesis:
//!
//! - **No short**: `M = R + n`, `n ~ N(0, sigma^2)` in each component.
//! - **A short in phase k** (Tallam's loop, the parent module's docs): the loop adds
//!   `r I1_h a^k` to the healthy machine's `I2` and `r I1_h` to its `I1`, so
//!   `M = (R + r a^k)/(1 + r) + n`. `r = (mu/3) Z1/Z_f` has the angle
//!   `arg Z1 - arg Z_f`: the healthy machine's `arg Z1` with a Gaussian uncertainty
//!   ([`ShortModel::angle_sd_rad`]: the reference's own and the loop's angle `arg Z_f`).
//!   Two forms, by where the reference angle comes from:
//!   - the healthy machine's `arg Z1` (the model at a measured speed, or a range of
//!     loads): the reading is mapped to the loop, `r a^k = (M - R)/(1 - M a^-k)`, whose
//!     angle is the reference's; `|r|` is uniform in `ln |r|` over [`SHORT_RATIO_MIN`]..
//!     [`SHORT_RATIO_MAX`] (no size favoured over another ten times larger);
//!   - an angle taken on the faulty machine's own current (`arg(V1/I1)`, or the model
//!     at the slip where it draws the measured `|I1|`, which the loop's mostly resistive
//!     current turns alike): that angle is `arg Z1 - arg(1 + r)`, and
//!     `(M - R)/(1 - R a^-k) = (r/(1 + r)) a^k` has it; `|r/(1 + r)|` is uniform in its
//!     logarithm over [`SHORT_RATIO_MIN`]..1.
//!
//! The likelihood of a short is the noise's density convolved with that prior, integrated
//! numerically over `ln |r|` and `arg r` on a grid that covers the noise's support around
//! the reading (six spreads): [`ln_short`]. With the priors [`NO_SHORT_PRIOR`] for no short
//! and a third of the rest for each phase, [`phase_posterior`] gives the probabilities;
//! the probability of the most probable phase is the phase's confidence. How it is
//! calibrated on real recordings and on simulation: `docs/isolation.md` ("The phase's
//! probability").
//!
//! Limits: the healthy spread is Gaussian; a reference whose real scatter is wider than
//! `sigma` (a supply whose unbalance changed, a baseline at another load without the
//! widening for it) makes the probabilities too sure of a short.

use super::Complex32;
use crate::frames::{wrap_angle, Phase};
use micromath::F32Ext;

/// Smallest size `|r|` of the shorted loop (`|I2/I1|` it draws, about) the prior allows:
/// below the noise of any current sensor.
pub const SHORT_RATIO_MIN: f32 = 0.003;
/// Largest `|r|` the prior allows: ten times the healthy machine's current (a bolted
/// short of a tenth of the turns draws that; the 40 %-turns shorts of the real
/// recordings, through the bench's switch, `|r|` up to 0.45).
pub const SHORT_RATIO_MAX: f32 = 10.0;
/// Prior probability of no short (each phase has a third of the rest): as likely as not
/// before the reading is looked at.
pub const NO_SHORT_PRIOR: f32 = 0.5;
/// Standard deviation [deg] of the angle of `r` about the reference angle that the
/// shorted loop and the sensors add to the reference's own uncertainty: `arg Z_f` of a
/// real shorted loop (its leakage and the switch's wiring) and the current sensors' phase
/// errors. On the real recordings (`docs/isolation.md`) the loop's angle moves by about
/// 30 deg between 10 % and 40 % of the turns.
pub const LOOP_ANGLE_SD_DEG: f32 = 15.0;
/// Grid points over `ln |r|` and over `arg r`.
const GRID: usize = 40;
/// Half-width of the grid about the reading, in spreads.
const GRID_SPREADS: f32 = 6.0;

/// The short's model a reading is judged with.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ShortModel {
    /// The reference angle `theta = arg Z1` [rad] (`super::asymmetry_correction_rad`, or
    /// measured as `arg(V1/I1)`).
    pub reference_rad: f32,
    /// Standard deviation of `arg r` about it [rad], > 0: the reference's uncertainty and
    /// [`LOOP_ANGLE_SD_DEG`] combined.
    pub angle_sd_rad: f32,
    /// The reference angle was taken on the faulty machine's own current (module docs:
    /// the second form).
    pub on_faulty_current: bool,
}

impl ShortModel {
    /// The model with the healthy machine's reference angle `reference_rad` [rad] known
    /// to `reference_sd_rad` [rad] (>= 0), [`LOOP_ANGLE_SD_DEG`] added in quadrature.
    pub fn new(reference_rad: f32, reference_sd_rad: f32) -> Self {
        let loop_sd = LOOP_ANGLE_SD_DEG.to_radians();
        ShortModel {
            reference_rad,
            angle_sd_rad: crate::math::fast_hypot(
                crate::math::maxf(0.0, reference_sd_rad),
                loop_sd,
            ),
            on_faulty_current: false,
        }
    }

    /// The same with the reference angle taken on the faulty machine's own current.
    pub fn on_faulty_current(reference_rad: f32, reference_sd_rad: f32) -> Self {
        ShortModel {
            on_faulty_current: true,
            ..Self::new(reference_rad, reference_sd_rad)
        }
    }

    /// The largest size the prior allows in this form.
    fn max_size(&self) -> f32 {
        if self.on_faulty_current {
            1.0
        } else {
            SHORT_RATIO_MAX
        }
    }

    /// The reading `M` of a short of size `x` on its phase-a sector centre on a healthy
    /// reference of zero.
    fn reading_of(&self, x: f32) -> Complex32 {
        let r = unit(self.reference_rad) * x;
        if self.on_faulty_current {
            r
        } else {
            cdiv(r, Complex32::new(1.0 + r.re, r.im))
        }
    }
}

/// Probabilities of no short and of a short in each phase (they sum to 1).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct PhasePosterior {
    /// No short.
    pub no_short: f32,
    /// A short in phase a, b, c.
    pub phases: [f32; 3],
}

impl PhasePosterior {
    /// The posterior from ln-likelihoods (priors not yet in: [`NO_SHORT_PRIOR`] and a third
    /// of the rest each are added here). Non-finite input gives "no short" certain.
    pub fn from_ln(ln_no_short: f32, ln_phases: [f32; 3]) -> Self {
        let p_short = (1.0 - NO_SHORT_PRIOR) / 3.0;
        let ln0 = ln_no_short + NO_SHORT_PRIOR.ln();
        let lk = ln_phases.map(|l| l + p_short.ln());
        Self::normalised(ln0, lk)
    }

    /// The posterior from ln-probabilities that already hold their priors (normalised
    /// here).
    pub fn normalised(ln_no_short: f32, ln_phases: [f32; 3]) -> Self {
        let max = ln_phases
            .iter()
            .fold(ln_no_short, |m, &l| crate::math::maxf(m, l));
        if !max.is_finite() || ln_phases.iter().any(|l| l.is_nan()) || ln_no_short.is_nan() {
            return PhasePosterior {
                no_short: 1.0,
                phases: [0.0; 3],
            };
        }
        let e = |l: f32| exp_neg(l - max);
        let p0 = e(ln_no_short);
        let pk = ln_phases.map(e);
        let sum = p0 + pk.iter().sum::<f32>();
        PhasePosterior {
            no_short: p0 / sum,
            phases: pk.map(|p| p / sum),
        }
    }

    /// The most probable phase and its probability.
    pub fn most_probable(&self) -> (Phase, f32) {
        Phase::ALL
            .into_iter()
            .zip(self.phases)
            .fold(
                (Phase::A, f32::MIN),
                |best, (p, x)| {
                    if x > best.1 {
                        (p, x)
                    } else {
                        best
                    }
                },
            )
    }

    /// The phase a report names: the most probable, when it is more probable than no
    /// short; `None` otherwise.
    pub fn named(&self) -> Option<(Phase, f32)> {
        let (p, x) = self.most_probable();
        (x > self.no_short).then_some((p, x))
    }

    /// The probability of a short in any phase.
    pub fn short(&self) -> f32 {
        self.phases.iter().sum()
    }
}

/// `e^x` for `x <= 0` (0 below -80, where f32 underflows).
fn exp_neg(x: f32) -> f32 {
    if x < -80.0 {
        0.0
    } else {
        F32Ext::exp(crate::math::minf(x, 0.0))
    }
}

/// `ln` of the density of a two-component Gaussian with standard deviation `s` in each
/// component at `d`.
fn ln_gauss2(d: Complex32, s: f32) -> f32 {
    let s2 = s * s;
    -d.norm_sqr() / (2.0 * s2) - (core::f32::consts::TAU * s2).ln()
}

/// `a / b`, NaN for `b = 0`.
fn cdiv(a: Complex32, b: Complex32) -> Complex32 {
    if !(b.norm_sqr() > 0.0) {
        return Complex32::new(f32::NAN, f32::NAN);
    }
    a / b
}

/// `e^{j angle}`.
fn unit(angle: f32) -> Complex32 {
    let (s, c) = F32Ext::sin_cos(angle);
    Complex32::new(c, s)
}

/// `ln` of the density of the reading `m = I2/I1` about the healthy reference `r` when
/// nothing is shorted: each component of `m - r` Gaussian with standard deviation `sigma`
/// (> 0; fraction of `|I1|`). Non-finite for a non-positive `sigma`.
pub fn ln_no_short(m: Complex32, r: Complex32, sigma: f32) -> f32 {
    ln_gauss2(m - r, sigma)
}

/// `ln` of the density of the reading `m = I2/I1` about the healthy reference `r` when a
/// short in `phase` is added (module docs): the reading mapped to the loop's
/// `c = r a^k = (m - r)/(1 - m a^-k)` (or, on the faulty current,
/// `c = (m - r)/(1 - r a^-k)`), its spread `sigma` (> 0) carried through the map's
/// derivative `J` (`(1 - r a^-k)/(1 - m a^-k)^2`, or `1/(1 - r a^-k)`), and the density
/// of `c` under the short's prior ([`ShortModel`]) times `|J|^2`. A reading that is no
/// number gives `-inf`.
pub fn ln_short(m: Complex32, r: Complex32, phase: Phase, model: &ShortModel, sigma: f32) -> f32 {
    let third = core::f32::consts::TAU / 3.0;
    let turn = phase.index() as f32 * third;
    let a_minus_k = unit(-turn);
    let one_less = |x: Complex32| {
        let y = x * a_minus_k;
        Complex32::new(1.0 - y.re, -y.im)
    };
    let (den_m, den_r) = (one_less(m), one_less(r));
    let d = m - r;
    let (c, jac) = if model.on_faulty_current {
        (
            cdiv(d, den_r),
            1.0 / crate::math::fast_hypot(den_r.re, den_r.im),
        )
    } else {
        (
            cdiv(d, den_m),
            crate::math::fast_hypot(den_r.re, den_r.im) / den_m.norm_sqr(),
        )
    };
    let ok = c.re.is_finite() && c.im.is_finite() && jac.is_finite() && jac > 0.0;
    if !(ok && sigma > 0.0 && model.angle_sd_rad > 0.0) {
        return f32::NEG_INFINITY;
    }
    let centre = model.reference_rad + turn;
    let sd = model.angle_sd_rad;
    short_density(c, centre, sd, sigma * jac, model.max_size()) + 2.0 * jac.ln()
}

/// `ln` of `int p(|w|) g(arg w) N(c - w; s) d^2w`: the prior of the loop's `w = r a^k`
/// (uniform in `ln |w|`, a wrapped Gaussian of standard deviation `sd` about `centre` in
/// angle) convolved with the noise (module docs), on a grid over the noise's support.
/// (`max`: the prior's largest size).
fn short_density(c: Complex32, centre: f32, sd: f32, s: f32, max: f32) -> f32 {
    let span = (max / SHORT_RATIO_MIN).ln();
    let mag = crate::math::fast_hypot(c.re, c.im);
    let clamp = |x: f32| crate::math::minf(max, crate::math::maxf(SHORT_RATIO_MIN, x));
    let (mut lo, mut hi) = (clamp(mag - GRID_SPREADS * s), clamp(mag + GRID_SPREADS * s));
    if hi <= lo * 1.0001 {
        // The noise's support lies beyond one end of the prior: its last stretch.
        if lo >= max {
            lo = max / 1.5;
        } else {
            hi = SHORT_RATIO_MIN * 1.5;
        }
    }
    let (u0, u1) = (lo.ln(), hi.ln());
    let du = (u1 - u0) / GRID as f32;
    let half = if mag > GRID_SPREADS * s {
        F32Ext::asin(GRID_SPREADS * s / mag)
    } else {
        core::f32::consts::PI
    };
    let dphi = 2.0 * half / GRID as f32;
    let phi0 = F32Ext::atan2(c.im, c.re) - half;
    let ln_cell = (du * dphi).ln() - span.ln();
    // The grid's sizes, and its angles' prior and unit vectors, once per row and column;
    // each term once (the same operations in the same order as term by term).
    let rho: [f32; GRID] = core::array::from_fn(|i| F32Ext::exp(u0 + (i as f32 + 0.5) * du));
    let angles: [(f32, Complex32); GRID] = core::array::from_fn(|j| {
        let phi = phi0 + (j as f32 + 0.5) * dphi;
        (ln_wrapped_gauss(phi - centre, sd), unit(phi))
    });
    let gauss = Gauss2::new(s);
    let mut terms = [[0.0f32; GRID]; GRID];
    // Two passes: the largest term, then the sum below it (log-sum-exp).
    let mut max = f32::NEG_INFINITY;
    for (row, rho) in terms.iter_mut().zip(rho) {
        for (t, (ln_angle, u)) in row.iter_mut().zip(&angles) {
            *t = ln_angle + gauss.ln_at(c - *u * rho);
            max = crate::math::maxf(max, *t);
        }
    }
    if !max.is_finite() {
        return f32::NEG_INFINITY;
    }
    let mut sum = 0.0f32;
    for t in terms.iter().flatten() {
        sum += exp_neg(t - max);
    }
    max + sum.ln() + ln_cell
}

/// [`ln_gauss2`] for one `s`, its normalisation's logarithm taken once: `ln_at(d)` is
/// `ln_gauss2(d, s)` to the bit.
struct Gauss2 {
    two_s2: f32,
    ln_norm: f32,
}

impl Gauss2 {
    fn new(s: f32) -> Self {
        let s2 = s * s;
        Gauss2 {
            two_s2: 2.0 * s2,
            ln_norm: (core::f32::consts::TAU * s2).ln(),
        }
    }

    fn ln_at(&self, d: Complex32) -> f32 {
        -d.norm_sqr() / self.two_s2 - self.ln_norm
    }
}

/// `ln` of a wrapped Gaussian's density (standard deviation `sd` [rad], > 0) at the
/// angle `x` [rad] (three turns summed: enough for `sd` up to about 60 deg).
fn ln_wrapped_gauss(x: f32, sd: f32) -> f32 {
    let x = wrap_angle(x);
    let tau = core::f32::consts::TAU;
    let q = |d: f32| -(d * d) / (2.0 * sd * sd);
    let (a, b, c) = (q(x), q(x - tau), q(x + tau));
    let m = crate::math::maxf(a, crate::math::maxf(b, c));
    m + (exp_neg(a - m) + exp_neg(b - m) + exp_neg(c - m)).ln() - (tau.sqrt() * sd).ln()
}

/// The posterior of a reading `m = I2/I1` against one healthy reference `r` with the
/// spread `sigma` (> 0, each component) under `model`: [`ln_no_short`] and [`ln_short`]
/// for each phase, with the priors ([`PhasePosterior::from_ln`]).
pub fn phase_posterior(
    m: Complex32,
    r: Complex32,
    sigma: f32,
    model: &ShortModel,
) -> PhasePosterior {
    PhasePosterior::from_ln(
        ln_no_short(m, r, sigma),
        Phase::ALL.map(|p| ln_short(m, r, p, model, sigma)),
    )
}

/// The least change: the size of a short that reads on its phase's sector centre on the
/// reference `R = 0` (`|r|`, or `|r/(1 + r)|` on the faulty current) at which its phase
/// reaches the probability `target` (0..1) with the spread `sigma` (> 0); bisection on
/// the prior's sizes to 0.1 %. `None` when not even the largest reaches it (an angle too
/// uncertain, or a spread too wide, to name a phase).
pub fn least_change(sigma: f32, model: &ShortModel, target: f32) -> Option<f32> {
    let p_at = |x: f32| {
        phase_posterior(model.reading_of(x), Complex32::new(0.0, 0.0), sigma, model).phases[0]
    };
    let max = model.max_size();
    if !(p_at(max) >= target) {
        return None;
    }
    let (mut lo, mut hi) = (SHORT_RATIO_MIN, max);
    if p_at(lo) >= target {
        return Some(lo);
    }
    while hi - lo > 1e-3 * hi {
        let mid = (lo * hi).sqrt();
        if p_at(mid) >= target {
            hi = mid;
        } else {
            lo = mid;
        }
    }
    Some(hi)
}

#[cfg(test)]
mod tests {
    use super::*;

    const D: f32 = core::f32::consts::PI / 180.0;

    /// A plain Monte-Carlo-free check of the grid: with a tiny spread the convolved
    /// density is the prior's own density at the reading, `g(arg c) / (|c|^2 ln(max/min))`.
    #[test]
    fn the_grid_integral_is_the_prior_density_for_a_sharp_reading() {
        let c = Complex32::new(0.1 * (70.0 * D).cos(), 0.1 * (70.0 * D).sin());
        let sd = 20.0 * D;
        let got = short_density(c, 60.0 * D, sd, 1e-4, SHORT_RATIO_MAX);
        let g = (-(10.0f32 * D).powi(2) / (2.0 * sd * sd)).exp()
            / ((core::f32::consts::TAU).sqrt() * sd);
        let want = (g / (0.01 * (SHORT_RATIO_MAX / SHORT_RATIO_MIN).ln())).ln();
        assert!((got - want).abs() < 0.02, "{got} {want}");
    }

    #[test]
    fn a_large_change_on_a_sector_centre_names_its_phase_and_a_small_one_none() {
        let model = ShortModel::new(60.0 * D, 10.0 * D);
        // Phase b's centre: 60 + 120 deg.
        let at = |x: f32, deg: f32| Complex32::new(x * (deg * D).cos(), x * (deg * D).sin());
        let p = phase_posterior(at(0.10, 180.0), Complex32::new(0.0, 0.0), 0.01, &model);
        assert_eq!(p.named().map(|n| n.0), Some(Phase::B), "{p:?}");
        assert!(p.phases[1] > 0.99, "{p:?}");
        // A change of one spread: no short is the more probable.
        let p = phase_posterior(at(0.01, 180.0), Complex32::new(0.0, 0.0), 0.01, &model);
        assert!(p.no_short > 0.5 && p.named().is_none(), "{p:?}");
        // On the border of a and b (120 deg): the two share it (a small reading, where
        // the loop's own share of I1 barely turns the border).
        let p = phase_posterior(at(0.02, 120.0), Complex32::new(0.0, 0.0), 0.002, &model);
        assert!((p.phases[0] - p.phases[1]).abs() < 0.2, "{p:?}");
        assert!(p.phases[0] < 0.6 && p.phases[1] < 0.6, "{p:?}");
        let sum = p.no_short + p.phases.iter().sum::<f32>();
        assert!((sum - 1.0).abs() < 1e-4);
        // No number, no short.
        let p = phase_posterior(
            Complex32::new(f32::NAN, 0.0),
            Complex32::new(0.0, 0.0),
            0.01,
            &model,
        );
        assert_eq!(p.no_short, 1.0);
    }

    #[test]
    fn the_least_change_grows_with_the_spread() {
        let model = ShortModel::new(60.0 * D, 10.0 * D);
        let a = least_change(0.005, &model, 0.5).unwrap_or(1.0);
        let b = least_change(0.01, &model, 0.5).unwrap_or(1.0);
        // About two to three spreads (the prior's Occam factor).
        assert!(a > 0.01 && a < 0.02, "{a}");
        assert!((b / a - 2.0).abs() < 0.3, "{a} {b}");
    }
}
