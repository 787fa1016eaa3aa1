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

/// First-order low-pass `y += a (x - y)`, `a = dt/(tau + dt)` (backward Euler of
/// `tau y' = x - y`), so it cannot overshoot for any `dt > 0`.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct LowPass {
    a: f32,
    /// Current output.
    pub y: f32,
}

impl LowPass {
    /// A low-pass with cutoff `fc_hz` at sample period `dt_s` (both > 0; a non-positive
    /// value gives a pass-through filter).
    pub fn new(fc_hz: f32, dt_s: f32) -> Self {
        let tau = 1.0 / (core::f32::consts::TAU * fc_hz);
        let a = if fc_hz > 0.0 && dt_s > 0.0 {
            dt_s / (tau + dt_s)
        } else {
            1.0
        };
        LowPass { a, y: 0.0 }
    }

    /// Feeds one sample and returns the new output.
    #[inline]
    pub fn update(&mut self, x: f32) -> f32 {
        self.y += self.a * (x - self.y);
        self.y
    }

    /// Forgets the state (output back to zero), keeping the cutoff.
    pub fn reset(&mut self) {
        self.y = 0.0;
    }
}

/// Critically damped second-order state-variable filter with derivative outputs.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct Svf {
    wc2_dt: f32,
    two_wc_dt: f32,
    wc2: f32,
    two_wc: f32,
    dt: f32,
    /// Filtered value y.
    pub y: f32,
    /// Filtered first derivative y' [unit/s].
    pub dy: f32,
}

impl Svf {
    /// A filter with corner `fc_hz` at sample period `dt_s`.
    pub fn new(fc_hz: f32, dt_s: f32) -> Self {
        let wc = core::f32::consts::TAU * fc_hz;
        Svf {
            wc2_dt: wc * wc * dt_s,
            two_wc_dt: 2.0 * wc * dt_s,
            wc2: wc * wc,
            two_wc: 2.0 * wc,
            dt: dt_s,
            y: 0.0,
            dy: 0.0,
        }
    }

    /// Forgets the state (value and derivative back to zero), keeping the corner.
    pub fn reset(&mut self) {
        self.y = 0.0;
        self.dy = 0.0;
    }

    /// Feeds one sample and returns the new filtered value y (the derivative is in
    /// [`Svf::dy`], the second derivative from [`Svf::ddy`]).
    #[inline]
    pub fn update(&mut self, x: f32) -> f32 {
        self.dy += self.wc2_dt * (x - self.y) - self.two_wc_dt * self.dy;
        self.y += self.dt * self.dy;
        self.y
    }

    /// Filtered second derivative y'' for the last input `x` [unit/s^2].
    #[inline]
    pub fn ddy(&self, x: f32) -> f32 {
        self.wc2 * (x - self.y) - self.two_wc * self.dy
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn svf_tracks_a_ramp_and_its_slope() {
        // Input x = 3 t: after settling, y' -> 3 and y'' -> 0, y lags by 2/wc * 3.
        let dt = 1e-4;
        let mut f = Svf::new(10.0, dt);
        let mut x = 0.0;
        for k in 0..20000 {
            x = 3.0 * k as f32 * dt;
            f.update(x);
        }
        assert!((f.dy - 3.0).abs() < 0.01, "{}", f.dy);
        // Semi-implicit Euler: discretisation error ~ wc dt relative to the 2 wc x' terms.
        assert!(
            f.ddy(x).abs() < 0.02 * 2.0 * core::f32::consts::TAU * 10.0 * 3.0,
            "{}",
            f.ddy(x)
        );
        let lag = 2.0 / (core::f32::consts::TAU * 10.0) * 3.0;
        assert!((x - f.y - lag).abs() < 0.01);
    }

    #[test]
    fn svf_attenuates_twice_line_frequency() {
        // |H(j 2 pi 100)| for fc = 10 Hz is 1/(1+100) ~ 0.0099.
        let dt = 1e-4;
        let mut f = Svf::new(10.0, dt);
        let mut peak: f32 = 0.0;
        for k in 0..40000 {
            let t = k as f32 * dt;
            f.update((core::f32::consts::TAU * 100.0 * t).sin());
            if k > 20000 {
                peak = peak.max(f.y.abs());
            }
        }
        assert!(peak < 0.012 && peak > 0.008, "{peak}");
    }

    #[test]
    fn lowpass_step_reaches_63_percent_at_tau() {
        let dt = 1e-4;
        let mut f = LowPass::new(10.0, dt);
        let tau = 1.0 / (core::f32::consts::TAU * 10.0);
        let n = (tau / dt) as usize;
        for _ in 0..n {
            f.update(1.0);
        }
        assert!((f.y - 0.632).abs() < 0.01, "{}", f.y);
    }
}
