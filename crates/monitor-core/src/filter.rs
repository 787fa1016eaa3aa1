//! Filters for the d-q quantities.
//!
//! The steady-state residuals of eq. (37) are evaluated on low-pass-filtered d-q
//! quantities, and the full residuals of eq. (36) need first and second derivatives. Both
//! come from one critically damped second-order state-variable filter per signal:
//!
//! `y'' = wc^2 (x - y) - 2 wc y'`
//!
//! whose states give the filtered value `y`, a consistent filtered first derivative `y'` and
//! second derivative `y''` (the transfer functions are `wc^2/(s+wc)^2` times 1, s and s^2).
//! Discretised with semi-implicit Euler, stable for `wc * dt < 0.5`; the configuration
//! check enforces `wc * dt <= 0.2` so the discretisation error stays below 10 %.
//!
//! Each filter is an immutable, validated configuration ([`LowPass`], [`Svf`], built with
//! a `Result`) and a separate state ([`LowPassState`], [`SvfState`]) that
//! `update(&self, &mut state, x)` advances, as idsp does: one configuration serves many
//! signals, and a configuration the filter cannot run with is rejected when it is built
//! ([`ConfigError`]), never turned into a pass-through.

use crate::error::{ConfigCheck, ConfigError};

/// `x` finite and > 0.
fn positive(x: f32) -> bool {
    x.is_finite() && x > 0.0
}

/// The checks both filters make of `fc_hz` and `dt_s`.
fn check_corner(fc_hz: f32, dt_s: f32) -> Result<(), ConfigError> {
    if !positive(fc_hz) {
        return Err(ConfigError::new(ConfigCheck::FilterCornerHz));
    }
    if !positive(dt_s) {
        return Err(ConfigError::new(ConfigCheck::FilterSamplePeriod));
    }
    Ok(())
}

/// First-order low-pass `y += a (x - y)`, `a = dt/(tau + dt)`, `tau = 1/(2 pi fc)`
/// (backward Euler of `tau y' = x - y`): it cannot overshoot for any `dt > 0`. The
/// configuration; the output lives in a [`LowPassState`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LowPass {
    a: f32,
}

/// The output of a [`LowPass`] (zero at the start).
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct LowPassState {
    y: f32,
}

impl LowPassState {
    /// The current output.
    #[inline]
    pub fn y(&self) -> f32 {
        self.y
    }

    /// Forgets the state (output back to zero).
    pub fn reset(&mut self) {
        self.y = 0.0;
    }
}

impl LowPass {
    /// A low-pass with cutoff `fc_hz` [Hz] at sample period `dt_s` [s].
    ///
    /// # Errors
    /// [`ConfigCheck::FilterCornerHz`] unless `fc_hz` is finite and > 0,
    /// [`ConfigCheck::FilterSamplePeriod`] unless `dt_s` is finite and > 0.
    pub fn new(fc_hz: f32, dt_s: f32) -> Result<Self, ConfigError> {
        check_corner(fc_hz, dt_s)?;
        let tau = 1.0 / (core::f32::consts::TAU * fc_hz);
        Ok(LowPass {
            a: dt_s / (tau + dt_s),
        })
    }

    /// Feeds one sample `x` into `state` and returns the new output.
    #[inline]
    pub fn update(&self, state: &mut LowPassState, x: f32) -> f32 {
        state.y += self.a * (x - state.y);
        state.y
    }
}

/// Critically damped second-order state-variable filter with derivative outputs (module
/// docs): the configuration; value and derivative live in an [`SvfState`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Svf {
    wc2_dt: f32,
    two_wc_dt: f32,
    wc2: f32,
    two_wc: f32,
    dt: f32,
}

/// The state of an [`Svf`]: the filtered value and its first derivative (zero at the
/// start).
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct SvfState {
    y: f32,
    dy: f32,
}

impl SvfState {
    /// A state at rest at `y` (derivative zero): a filter started on a known value.
    pub fn at(y: f32) -> Self {
        SvfState { y, dy: 0.0 }
    }

    /// The filtered value y.
    #[inline]
    pub fn y(&self) -> f32 {
        self.y
    }

    /// The filtered first derivative y' [unit/s].
    #[inline]
    pub fn dy(&self) -> f32 {
        self.dy
    }

    /// Moves the value to `y`, keeping the derivative (a filter whose first input
    /// defines its level).
    pub fn set_y(&mut self, y: f32) {
        self.y = y;
    }

    /// Forgets the state (value and derivative back to zero).
    pub fn reset(&mut self) {
        *self = SvfState::default();
    }
}

/// Largest `wc dt` an [`Svf`] accepts: the semi-implicit Euler step of the critically
/// damped filter is stable for `wc dt < 0.5` (module docs); the monitor's own check keeps
/// its block filters at `wc dt <= 0.2`.
pub const SVF_MAX_WC_DT: f32 = 0.5;

impl Svf {
    /// A filter with corner `fc_hz` [Hz] at sample period `dt_s` [s].
    ///
    /// # Errors
    /// [`ConfigCheck::FilterCornerHz`] unless `fc_hz` is finite and > 0,
    /// [`ConfigCheck::FilterSamplePeriod`] unless `dt_s` is finite and > 0,
    /// [`ConfigCheck::FilterStability`] unless `2 pi fc_hz dt_s <` [`SVF_MAX_WC_DT`].
    pub fn new(fc_hz: f32, dt_s: f32) -> Result<Self, ConfigError> {
        check_corner(fc_hz, dt_s)?;
        let wc = core::f32::consts::TAU * fc_hz;
        if !(wc * dt_s < SVF_MAX_WC_DT) {
            return Err(ConfigError::new(ConfigCheck::FilterStability));
        }
        Ok(Svf {
            wc2_dt: wc * wc * dt_s,
            two_wc_dt: 2.0 * wc * dt_s,
            wc2: wc * wc,
            two_wc: 2.0 * wc,
            dt: dt_s,
        })
    }

    /// Feeds one sample `x` into `state` and returns the new filtered value y (the
    /// derivative is [`SvfState::dy`], the second derivative [`Svf::ddy`]).
    #[inline]
    pub fn update(&self, state: &mut SvfState, x: f32) -> f32 {
        state.dy += self.wc2_dt * (x - state.y) - self.two_wc_dt * state.dy;
        state.y += self.dt * state.dy;
        state.y
    }

    /// Filtered second derivative y'' of `state` for the last input `x` [unit/s^2].
    #[inline]
    pub fn ddy(&self, state: &SvfState, x: f32) -> f32 {
        self.wc2 * (x - state.y) - self.two_wc * state.dy
    }
}

#[cfg(test)]
#[allow(clippy::unwrap_used)]
mod tests {
    use super::*;

    #[test]
    fn svf_tracks_a_ramp_and_its_slope() {
        // Input x = 3 t: after settling, y' -> 3 and y'' -> 0, y lags by 2/wc * 3.
        let dt = 1e-4;
        let f = Svf::new(10.0, dt).unwrap();
        let mut s = SvfState::default();
        let mut x = 0.0;
        for k in 0..20000 {
            x = 3.0 * k as f32 * dt;
            f.update(&mut s, x);
        }
        assert!((s.dy() - 3.0).abs() < 0.01, "{}", s.dy());
        // Semi-implicit Euler: discretisation error ~ wc dt relative to the 2 wc x' terms.
        assert!(
            f.ddy(&s, x).abs() < 0.02 * 2.0 * core::f32::consts::TAU * 10.0 * 3.0,
            "{}",
            f.ddy(&s, x)
        );
        let lag = 2.0 / (core::f32::consts::TAU * 10.0) * 3.0;
        assert!((x - s.y() - lag).abs() < 0.01);
    }

    #[test]
    fn svf_attenuates_twice_line_frequency() {
        // |H(j 2 pi 100)| for fc = 10 Hz is 1/(1+100) ~ 0.0099.
        let dt = 1e-4;
        let f = Svf::new(10.0, dt).unwrap();
        let mut s = SvfState::default();
        let mut peak: f32 = 0.0;
        for k in 0..40000 {
            let t = k as f32 * dt;
            f.update(&mut s, (core::f32::consts::TAU * 100.0 * t).sin());
            if k > 20000 {
                peak = peak.max(s.y().abs());
            }
        }
        assert!(peak < 0.012 && peak > 0.008, "{peak}");
    }

    #[test]
    fn lowpass_step_reaches_63_percent_at_tau() {
        let dt = 1e-4;
        let f = LowPass::new(10.0, dt).unwrap();
        let mut s = LowPassState::default();
        let tau = 1.0 / (core::f32::consts::TAU * 10.0);
        let n = (tau / dt) as usize;
        for _ in 0..n {
            f.update(&mut s, 1.0);
        }
        assert!((s.y() - 0.632).abs() < 0.01, "{}", s.y());
        s.reset();
        assert_eq!(s.y(), 0.0);
    }

    #[test]
    fn bad_configuration_is_rejected_when_built() {
        let check = |r: Result<(), ConfigError>| r.err().map(|e| e.check);
        for (fc, dt, want) in [
            (0.0, 1e-4, ConfigCheck::FilterCornerHz),
            (-1.0, 1e-4, ConfigCheck::FilterCornerHz),
            (f32::NAN, 1e-4, ConfigCheck::FilterCornerHz),
            (10.0, 0.0, ConfigCheck::FilterSamplePeriod),
            (10.0, f32::INFINITY, ConfigCheck::FilterSamplePeriod),
        ] {
            assert_eq!(
                check(LowPass::new(fc, dt).map(|_| ())),
                Some(want),
                "{fc} {dt}"
            );
            assert_eq!(check(Svf::new(fc, dt).map(|_| ())), Some(want), "{fc} {dt}");
        }
        // 2 pi 100 Hz x 1 ms = 0.63: the Euler step is unstable; the low-pass is fine.
        assert_eq!(
            check(Svf::new(100.0, 1e-3).map(|_| ())),
            Some(ConfigCheck::FilterStability)
        );
        assert!(LowPass::new(100.0, 1e-3).is_ok() && Svf::new(50.0, 1e-3).is_ok());
    }

    #[test]
    fn one_configuration_serves_many_states() {
        let f = Svf::new(5.0, 1e-3).unwrap();
        let (mut a, mut b) = (SvfState::default(), SvfState::at(2.0));
        for _ in 0..3000 {
            f.update(&mut a, 1.0);
            f.update(&mut b, 1.0);
        }
        assert!((a.y() - 1.0).abs() < 1e-3 && (b.y() - 1.0).abs() < 1e-3);
    }
}
