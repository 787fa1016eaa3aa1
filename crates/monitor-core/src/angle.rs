//! The synchronous angle: where the d-q frame points.
//!
//! Three sources, chosen in [`crate::MonitorConfig::angle_source`] (why the frame's
//! orientation matters: `docs/design.md`):
//! - [`ZeroCrossing`]: the paper's method (section 4.2, item 3): the phase-a voltage's rising
//!   zero crossing with a frequency estimate from the crossing period. Voltage orientation.
//! - [`SrfPll`]: a synchronous-reference-frame PLL on the voltage vector. Voltage
//!   orientation, smoother than zero crossings and immune to a single noisy crossing.
//! - [`RotorFluxCurrentModel`]: the rotor-flux angle from the current model (measured
//!   currents, encoder speed, nominal Rr, Lr, Lm). Rotor-flux orientation, in which the
//!   paper's steady-state model (eqs. 21-23) is exact, so healthy residuals are zero at
//!   every load. With voltage orientation the healthy r1 grows with slip (about
//!   0.1 % of Vqs at 1 % slip, 10 % at 5 % slip), which the paper absorbed in heuristic
//!   thresholds.
//!
//! Voltage orientation puts the voltage vector on +q (`V_ds = 0`, `V_qs = |V|`): the
//! rising zero crossing of `va = V cos(theta_v)` is at `theta_v = -pi/2`, so the Park angle
//! there is `theta = theta_v - pi/2 = -pi`.

#[cfg(test)]
use crate::frames::park;
use crate::frames::{wrap_angle, AlphaBeta, Dq, SinCos};
use core::f32::consts::{FRAC_PI_2, PI, TAU};

/// Which angle the residuals are computed in.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum AngleSource {
    /// Phase-a voltage zero crossing + frequency estimate (the paper's hardware).
    ZeroCrossing,
    /// SRF-PLL on the measured voltages.
    Pll,
    /// Rotor-flux angle from the current model ([`RotorFluxCurrentModel`]: measured
    /// currents, encoder speed, nominal Rr, Lr, Lm). The host's model-vs-measurement
    /// analysis uses a different rotor-flux estimator, the voltage model, which needs no
    /// speed and no rotor parameters; the two are named apart everywhere.
    #[default]
    RotorFluxCurrentModel,
}

/// Phase-a rising zero-crossing detector with frequency estimate (the paper's method).
///
/// Between crossings the angle advances at the estimated frequency; at each crossing it is
/// snapped to the interpolated crossing instant. A crossing is armed only after `va` has
/// been below `-hysteresis_v`, so noise around zero gives one crossing, not many. Crossing
/// periods outside `[1/f_max, 1/f_min]` are ignored (a lost or doubled crossing does not
/// corrupt the frequency).
#[derive(Debug, Clone, Copy)]
pub struct ZeroCrossing {
    dt: f32,
    hysteresis_v: f32,
    armed: bool,
    prev_va: f32,
    since_crossing_s: f32,
    period_min_s: f32,
    period_max_s: f32,
    omega: f32,
    theta: f32,
    locked: bool,
}

impl ZeroCrossing {
    /// New detector at sample period `dt_s`, starting at `f0_hz`, accepting `f_min..f_max`.
    pub fn new(dt_s: f32, f0_hz: f32, f_min_hz: f32, f_max_hz: f32, hysteresis_v: f32) -> Self {
        ZeroCrossing {
            dt: dt_s,
            hysteresis_v,
            armed: false,
            prev_va: 0.0,
            since_crossing_s: 0.0,
            period_min_s: 1.0 / f_max_hz,
            period_max_s: 1.0 / f_min_hz,
            omega: TAU * f0_hz,
            theta: 0.0,
            locked: false,
        }
    }

    /// Feeds the phase-a voltage; returns the Park angle (voltage on +q) [rad].
    pub fn update(&mut self, va: f32) -> f32 {
        self.since_crossing_s += self.dt;
        self.theta = wrap_angle(self.theta + self.omega * self.dt);
        if va < -self.hysteresis_v {
            self.armed = true;
        }
        if self.armed && self.prev_va < 0.0 && va >= 0.0 {
            self.armed = false;
            // Linear interpolation of the crossing inside this sample interval.
            let frac = va / (va - self.prev_va); // 0..1: fraction of dt since the crossing
            let after = frac * self.dt;
            let period = self.since_crossing_s - after;
            if period > self.period_min_s && period < self.period_max_s {
                self.omega = TAU / period;
                self.locked = true;
            }
            self.since_crossing_s = after;
            self.theta = wrap_angle(-PI + self.omega * after);
        }
        self.prev_va = va;
        self.theta
    }

    /// Estimated supply angular frequency [rad/s].
    pub fn omega_rad_s(&self) -> f32 {
        self.omega
    }

    /// True once one valid period has been measured.
    pub fn locked(&self) -> bool {
        self.locked
    }

    /// Advances the angle over `elapsed_s` without a measurement (samples missing from the
    /// stream) at the present frequency estimate; the next crossing is still measured from
    /// the last one. Non-finite or negative values are ignored.
    pub fn skip(&mut self, elapsed_s: f32) {
        if elapsed_s > 0.0 && elapsed_s.is_finite() {
            self.since_crossing_s += elapsed_s;
            self.theta = wrap_angle(self.theta + self.omega * elapsed_s);
        }
    }
}

/// Synchronous-reference-frame PLL. The internal angle `theta_pll` tracks the voltage
/// vector (its d axis on the voltage); the output angle is `theta_pll - pi/2` (voltage on
/// +q, as [`ZeroCrossing`]). The phase detector is `e = V_q,pll / V_nominal` (normalised
/// by the nominal peak voltage, so the loop gain is that of the design at nominal voltage
/// and proportional to it otherwise), the loop filter a PI with `kp = 2 zeta wn`,
/// `ki = wn^2`, `zeta = 0.707`, and the frequency is limited to `[0, 2 w0]`.
#[derive(Debug, Clone, Copy)]
pub struct SrfPll {
    dt: f32,
    kp: f32,
    ki: f32,
    w0: f32,
    inv_v: f32,
    integ: f32,
    omega: f32,
    theta_pll: f32,
}

impl SrfPll {
    /// New PLL at sample period `dt_s`, nominal `f0_hz`, bandwidth `bw_hz` (wn = 2 pi bw),
    /// nominal peak voltage `v_nominal` (> 0).
    pub fn new(dt_s: f32, f0_hz: f32, bw_hz: f32, v_nominal: f32) -> Self {
        let wn = TAU * bw_hz;
        SrfPll {
            dt: dt_s,
            kp: 2.0 * 0.707 * wn,
            ki: wn * wn,
            w0: TAU * f0_hz,
            inv_v: if v_nominal > 0.0 {
                1.0 / v_nominal
            } else {
                0.0
            },
            integ: 0.0,
            omega: TAU * f0_hz,
            theta_pll: 0.0,
        }
    }

    /// Feeds the voltage vector with the sin/cos of the current PLL angle (from
    /// [`SrfPll::theta_pll`]); advances the angle and returns the new frequency estimate
    /// [rad/s].
    pub fn update(&mut self, v: AlphaBeta, sc_pll: SinCos) -> f32 {
        // q component only: V_q = -alpha sin + beta cos.
        let e = (-v.alpha * sc_pll.sin + v.beta * sc_pll.cos) * self.inv_v;
        // max/min rather than clamp: no panic path, NaN-safe (NaN input leaves the bound).
        self.integ = crate::math::minf(
            crate::math::maxf(self.integ + self.ki * e * self.dt, -self.w0),
            self.w0,
        );
        self.omega = crate::math::minf(
            crate::math::maxf(self.w0 + self.integ + self.kp * e, 0.0),
            2.0 * self.w0,
        );
        self.theta_pll = wrap_angle(self.theta_pll + self.omega * self.dt);
        self.omega
    }

    /// Advances the angle over `elapsed_s` at the present frequency, without a measurement
    /// (samples missing from the stream). Non-finite or negative values are ignored.
    pub fn skip(&mut self, elapsed_s: f32) {
        if elapsed_s > 0.0 && elapsed_s.is_finite() {
            self.theta_pll = wrap_angle(self.theta_pll + self.omega * elapsed_s);
        }
    }

    /// Sets the PLL's own angle to `theta_pll_rad` (the vector's angle, on +d), e.g. the
    /// first sample's `atan2(beta, alpha)`, so that the loop starts locked instead of
    /// pulling in from zero. A non-finite angle is ignored.
    pub fn align(&mut self, theta_pll_rad: f32) {
        if theta_pll_rad.is_finite() {
            self.theta_pll = wrap_angle(theta_pll_rad);
        }
    }

    /// The PLL's own angle (voltage on +d) [rad].
    pub fn theta_pll(&self) -> f32 {
        self.theta_pll
    }

    /// Park angle with the voltage on +q [rad].
    pub fn theta(&self) -> f32 {
        wrap_angle(self.theta_pll - FRAC_PI_2)
    }

    /// Estimated supply angular frequency [rad/s].
    pub fn omega_rad_s(&self) -> f32 {
        self.omega
    }
}

/// Rotor-flux angle from the current model (indirect field orientation):
///
/// `T_r d(i_mr)/dt = i_ds - i_mr`,   `omega_slip = i_qs / (T_r i_mr)`,
/// `d(theta)/dt = wr + omega_slip`
///
/// with `T_r = L_r/R_r`, `i_mr = psi_r / L_m` the magnetising current, `wr` the
/// electrical rotor speed (pole pairs x encoder speed) and `i_ds, i_qs` the stator currents
/// in the estimated frame. In steady state `i_mr = i_ds` and the slip is
/// `R_r i_qs /(L_r i_ds)`, the paper's eq. (22). The division is guarded: below
/// `imr_min` the slip term is dropped (the flux has not built up yet).
#[derive(Debug, Clone, Copy)]
pub struct RotorFluxCurrentModel {
    dt: f32,
    inv_tr: f32,
    imr_min: f32,
    imr: f32,
    theta: f32,
    omega: f32,
}

impl RotorFluxCurrentModel {
    /// New estimator: sample period, nominal `Rr` [ohm], `Lr` [H], smallest magnetising
    /// current for which the slip is computed [A].
    pub fn new(dt_s: f32, rr_ohm: f32, lr_h: f32, imr_min_a: f32) -> Self {
        RotorFluxCurrentModel {
            dt: dt_s,
            inv_tr: rr_ohm / lr_h,
            imr_min: imr_min_a,
            imr: 0.0,
            theta: 0.0,
            omega: 0.0,
        }
    }

    /// Advances the model with the stator currents in the present estimated frame and the
    /// electrical rotor speed `wr_rad_s` (Np x mechanical) [rad/s]. Returns the new angle [rad].
    pub fn update(&mut self, i_dq: Dq, wr_rad_s: f32) -> f32 {
        self.imr += self.dt * self.inv_tr * (i_dq.d - self.imr);
        let slip = if self.imr > self.imr_min {
            i_dq.q * self.inv_tr / self.imr
        } else {
            0.0
        };
        self.omega = wr_rad_s + slip;
        self.theta = wrap_angle(self.theta + self.omega * self.dt);
        self.theta
    }

    /// Advances the model over `elapsed_s` without new currents (samples missing from the
    /// stream): the magnetising current and the frame frequency are held and the angle
    /// advances at that frequency, the best guess over a short gap. Non-finite or negative
    /// values are ignored.
    pub fn skip(&mut self, elapsed_s: f32) {
        if elapsed_s > 0.0 && elapsed_s.is_finite() {
            self.theta = wrap_angle(self.theta + self.omega * elapsed_s);
        }
    }

    /// Present angle [rad].
    pub fn theta(&self) -> f32 {
        self.theta
    }

    /// Frame angular frequency wr + omega_slip [rad/s].
    pub fn omega_rad_s(&self) -> f32 {
        self.omega
    }

    /// Estimated magnetising current i_mr = psi_r / Lm [A].
    pub fn imr(&self) -> f32 {
        self.imr
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::frames::clarke;
    use crate::frames::Abc;

    fn supply(t: f32, f: f32, v: f32, phase: f32) -> Abc {
        let w = TAU * f * t + phase;
        Abc {
            a: v * w.cos(),
            b: v * (w - TAU / 3.0).cos(),
            c: v * (w + TAU / 3.0).cos(),
        }
    }

    #[test]
    fn zero_crossing_and_pll_put_the_voltage_on_q() {
        let dt = 1e-4;
        for f in [50.0f32, 60.0, 37.0] {
            let mut zc = ZeroCrossing::new(dt, 50.0, 5.0, 200.0, 5.0);
            let mut pll = SrfPll::new(dt, 50.0, 20.0, 325.0);
            let (mut dq_zc, mut dq_pll) = (Dq::default(), Dq::default());
            for k in 0..20000 {
                let t = k as f32 * dt;
                let v = supply(t, f, 325.0, 0.4);
                let th = zc.update(v.a);
                let ab = clarke(v);
                dq_zc = park(ab, SinCos::from_angle(th));
                // The angle belongs to this sample until update() advances it.
                let sc = SinCos::from_angle(pll.theta_pll());
                dq_pll = park(ab, sc.minus_quarter_turn());
                pll.update(ab, sc);
            }
            assert!((zc.omega_rad_s() - TAU * f).abs() < 0.01 * TAU * f);
            assert!((pll.omega_rad_s() - TAU * f).abs() < 0.002 * TAU * f);
            for dq in [dq_zc, dq_pll] {
                assert!((dq.q - 325.0).abs() < 3.0, "{dq:?}");
                assert!(dq.d.abs() < 0.03 * 325.0, "{dq:?}");
            }
        }
    }
}
