//! Stage 2 of [`super`]: the voltage-model rotor-flux frame and the d-q signals.

use super::sequence::{supply_steps, SequenceSeparator};
use super::{
    hann, zero_phase_lpf, zero_phase_lpf_in_place, Decimated, Prepared, C64, FLUX_LEAK_RAD_S,
    I_F_SMOOTH_HZ, THETA_SMOOTH_HZ,
};
use monitor_io::params::ParamFile;

/// Builds the voltage-model rotor-flux frame and the d-q signals from the working series.
///
/// `p` gives the parameters of the flux estimator (Rs, sigma Ls, Lr/Lm) and, for
/// current-only logs, the supply frequency of the frame. Pole pairs convert the measured
/// mechanical speed to electrical omega_r.
pub fn voltage_model_flux_frame(d: &Decimated, p: &ParamFile) -> Prepared {
    let n = d.t_s.len();
    let dt = if n > 1 {
        (d.t_s[n - 1] - d.t_s[0]) / (n - 1) as f64
    } else {
        1e-3
    };
    let to_c64 = |x: &[f32; 2]| C64::new(x[0] as f64, x[1] as f64);
    let i_ab: Vec<C64> = d.i_ab.iter().map(to_c64).collect();
    let v_ab: Vec<C64> = d.v_ab.iter().map(to_c64).collect();
    let w = Working {
        d,
        v_ab: &v_ab,
        i_ab: &i_ab,
        dt,
    };
    // The frame's angle and the sequence separation's own (the supply voltage's) are
    // independent: built on both cores. (A current-only log separates in the frame: built
    // first, then used.)
    let (f, (i_neg, v_neg)) = if d.channels.voltages {
        rayon::join(|| w.frame(p), || w.sequences(None))
    } else {
        let f = w.frame(p);
        let s = w.sequences(Some(&f));
        (f, s)
    };
    let rot = &f.rot;
    // Park transforms in complex form: x_dq = x_alphabeta e^{-j theta}; voltages and
    // currents (with the flux current's smoothing) on both cores.
    let ((vd, vq), (id, iq, iq_pos, i_f)) = rayon::join(
        || w.park_voltages(&v_neg, rot),
        || w.park_currents(&i_neg, rot),
    );
    let np = p.motor.model::<f64>().np();
    Prepared {
        i_f,
        t_s: d.t_s.clone(),
        dt_s: dt,
        theta: f.theta,
        omega_s: f.omega_s,
        vd,
        vq,
        id,
        iq,
        iq_pos,
        i_ab,
        i0: d.i0.iter().map(|&x| x as f64).collect(),
        v_neg,
        i_neg,
        omega_r: d.wm.iter().map(|&w| w as f64 * np).collect(),
        channels: d.channels,
        rows: d.rows,
        log_rate_hz: d.log_rate_hz,
        block_rows: d.factor,
        log_start_s: d.log_start_s,
    }
}

/// The working series as complex vectors, with its sample period [s].
struct Working<'a> {
    d: &'a Decimated,
    v_ab: &'a [C64],
    i_ab: &'a [C64],
    dt: f64,
}

/// The analysis frame: its Park angle [rad] (unwrapped), speed [rad/s] and rotation
/// e^{j theta}.
struct FluxFrame {
    theta: Vec<f64>,
    omega_s: Vec<f64>,
    rot: Vec<C64>,
}

impl Working<'_> {
    /// The frame: the voltage-model rotor-flux angle, smoothed (the nominal supply angle
    /// for a current-only log).
    fn frame(&self, p: &ParamFile) -> FluxFrame {
        let (d, dt) = (self.d, self.dt);
        let theta = if d.channels.voltages {
            let raw = flux_angle(self.v_ab, self.i_ab, dt, p);
            smooth_angle(raw, dt)
        } else {
            let w0 = p.supply.omega_rad_s();
            d.t_s.iter().map(|t| w0 * t).collect()
        };
        let omega_s = frame_speed(&theta, &d.t_s, dt);
        let rot: Vec<C64> = theta
            .iter()
            .map(|&th| C64::new(th.cos(), th.sin()))
            .collect();
        FluxFrame {
            theta,
            omega_s,
            rot,
        }
    }

    /// The negative sequences of the current and the voltage (zeros without voltages).
    /// They are separated in the supply voltage's own (smoothed) frame when the log has
    /// voltages: any frame turning with the positive sequence separates them alike in
    /// steady state, but through a start the rotor-flux frame is still forming (it may turn
    /// a whole revolution against the supply in the first 0.1 s), and the demodulated
    /// signal then leaks volts into the negative sequence for the low-pass's memory
    /// (0.2 s): 4 V on an 11 kW start, which the model takes as its input. A current-only
    /// log separates in the analysis frame `frame`.
    fn sequences(&self, frame: Option<&FluxFrame>) -> (Vec<C64>, Vec<C64>) {
        let (d, dt) = (self.d, self.dt);
        let voltages = d.channels.voltages;
        let (sep_theta, sep_omega) = match frame {
            Some(f) if !voltages => (f.theta.clone(), f.omega_s.clone()),
            _ => {
                let th = smooth_angle(unwrapped_angle(self.v_ab), dt);
                let w = frame_speed(&th, &d.t_s, dt);
                (th, w)
            }
        };
        let sep_rot: Vec<C64> = sep_theta
            .iter()
            .map(|&th| C64::new(th.cos(), th.sin()))
            .collect();
        let mut sep = SequenceSeparator::new(&sep_theta, &sep_omega, dt);
        if voltages {
            sep.steps = supply_steps(self.v_ab, &sep_rot);
        }
        rayon::join(
            || sep.negative(self.i_ab, &sep_rot),
            || {
                if voltages {
                    sep.negative(self.v_ab, &sep_rot)
                } else {
                    vec![C64::new(0.0, 0.0); d.t_s.len()]
                }
            },
        )
    }

    /// The positive-sequence V_ds and V_qs (empty without voltages).
    fn park_voltages(&self, v_neg: &[C64], rot: &[C64]) -> (Vec<f64>, Vec<f64>) {
        let n = self.d.t_s.len();
        let mut vd = Vec::new();
        let mut vq = Vec::new();
        if self.d.channels.voltages {
            vd.reserve(n);
            vq.reserve(n);
            for k in 0..n {
                let v = (self.v_ab[k] - v_neg[k]) * rot[k].conj();
                vd.push(v.re);
                vq.push(v.im);
            }
        }
        (vd, vq)
    }

    /// The positive-sequence I_ds, the whole I_qs, the positive-sequence I_qs and i_f.
    #[allow(clippy::type_complexity)]
    fn park_currents(
        &self,
        i_neg: &[C64],
        rot: &[C64],
    ) -> (Vec<f64>, Vec<f64>, Vec<f64>, Vec<f64>) {
        let n = self.d.t_s.len();
        let i_ab = self.i_ab;
        let mut id = Vec::with_capacity(n);
        let mut iq = Vec::with_capacity(n);
        let mut iq_pos = Vec::with_capacity(n);
        for k in 0..n {
            let ip = (i_ab[k] - i_neg[k]) * rot[k].conj();
            let it = i_ab[k] * rot[k].conj();
            id.push(ip.re);
            iq_pos.push(ip.im);
            iq.push(it.im);
        }
        let i_f = zero_phase_lpf(&id, self.dt, I_F_SMOOTH_HZ);
        (id, iq, iq_pos, i_f)
    }
}

/// Frame speed [rad/s]: central difference of the unwrapped angle, low-passed (20 Hz)
/// without phase shift (a causal filter would lag a V/f ramp by its group delay).
fn frame_speed(theta: &[f64], t_s: &[f64], dt: f64) -> Vec<f64> {
    let n = theta.len();
    let mut omega = vec![0.0; n];
    for k in 0..n {
        let (a, b) = (k.saturating_sub(1), (k + 1).min(n.saturating_sub(1)));
        if b > a {
            omega[k] = (theta[b] - theta[a]) / (t_s[b] - t_s[a]);
        }
    }
    zero_phase_lpf_in_place(&mut omega, dt, 20.0);
    omega
}

/// The unwrapped angle of a vector series (a zero vector keeps the previous angle).
fn unwrapped_angle(x: &[C64]) -> Vec<f64> {
    let mut out = Vec::with_capacity(x.len());
    let mut acc = 0.0f64;
    // (Each vector's magnitude computed once: `prev` keeps it.)
    let mut prev: Option<(C64, f64)> = None;
    for &v in x {
        let nv = v.norm();
        match prev {
            None => acc = if nv > 0.0 { v.arg() } else { 0.0 },
            Some((p, np)) if nv * np > 0.0 => acc += (v * p.conj()).arg(),
            Some(_) => {}
        }
        if nv > 0.0 {
            prev = Some((v, nv));
        }
        out.push(acc);
    }
    out
}

/// Initial stator flux of the voltage model: zero when the log starts de-energised (a
/// start from standstill), otherwise the value that makes the flux zero-mean over the first
/// eight nominal supply periods (a log that starts mid-run), Hann-weighted: a plain mean
/// over a period count that the sample grid cuts short leaves a flux offset of about
/// (missing fraction) x |psi|, which the leak then takes a second to remove and which shows
/// as a supply-frequency ripple on I_qs meanwhile.
fn initial_stator_flux(v_ab: &[C64], i_ab: &[C64], dt: f64, rs: f64, w0: f64) -> C64 {
    let n = i_ab.len();
    let n_per = ((8.0 * 2.0 * std::f64::consts::PI / w0) / dt)
        .round()
        .max(1.0) as usize;
    let n_per = n_per.min(n);
    let i_rms_all = (i_ab.iter().map(|x| x.norm_sqr()).sum::<f64>() / n as f64).sqrt();
    let n_head = ((0.002 / dt).ceil() as usize).clamp(1, n);
    let i_rms_head =
        (i_ab[..n_head].iter().map(|x| x.norm_sqr()).sum::<f64>() / n_head as f64).sqrt();
    if i_rms_head <= 0.02 * i_rms_all {
        return C64::new(0.0, 0.0);
    }
    let mut acc = C64::new(0.0, 0.0);
    let mut sum = C64::new(0.0, 0.0);
    let mut wsum = 0.0;
    for k in 0..n_per {
        if k > 0 {
            acc += (v_ab[k] - i_ab[k] * rs + v_ab[k - 1] - i_ab[k - 1] * rs) * (0.5 * dt);
        }
        let w = hann(k, n_per);
        sum += acc * w;
        wsum += w;
    }
    -sum / wsum.max(1e-12)
}

/// The unwrapped angle of the voltage-model rotor flux: stator flux by a leaky
/// (trapezoidal) integrator of `v - Rs i`, the leak's quasi-steady phase lead undone,
/// `psi_r = (Lr/Lm) (psi_s - sigma Ls i)`.
fn flux_angle(v_ab: &[C64], i_ab: &[C64], dt: f64, p: &ParamFile) -> Vec<f64> {
    let n = i_ab.len();
    let m = p.motor.model::<f64>();
    let sls = m.la_h();
    let kr = m.lr_h / m.lm_h;
    let decay = (-FLUX_LEAK_RAD_S * dt).exp();
    let w0 = p.supply.omega_rad_s();
    let mut psi_s = initial_stator_flux(v_ab, i_ab, dt, m.rs_ohm, w0);
    let mut theta = Vec::with_capacity(n);
    let mut prev_e = v_ab[0] - i_ab[0] * m.rs_ohm;
    let mut unwrapped = 0.0f64;
    let mut prev_ang: Option<f64> = None;
    // Stator-flux frequency (causal, 20 Hz) for the leak compensation.
    let mut w_flux = w0;
    let a_w = 1.0 - (-2.0 * std::f64::consts::PI * THETA_SMOOTH_HZ * dt).exp();
    let mut prev_psi = psi_s;
    for k in 0..n {
        let e = v_ab[k] - i_ab[k] * m.rs_ohm;
        if k > 0 {
            psi_s = psi_s * decay + (e + prev_e) * (0.5 * dt);
            let turn = psi_s * prev_psi.conj();
            // (Squared magnitudes against squared thresholds: no square root per sample.)
            if turn.norm_sqr() > 1e-24 {
                w_flux += a_w * (turn.im.atan2(turn.re) / dt - w_flux);
            }
        }
        prev_e = e;
        prev_psi = psi_s;
        // The leak turns a flux rotating at w by atan(leak / w) (0.6 degrees at 15 Hz)
        // and a frame error tilts I_qs by about (Ls w / Ra) x I_ds x the angle; so the
        // quasi-steady leak response jw/(jw + leak) is undone: psi = psi_leaky (1 - j leak/w).
        let psi_c = if w_flux.abs() > 5.0 * FLUX_LEAK_RAD_S {
            psi_s * C64::new(1.0, -FLUX_LEAK_RAD_S / w_flux)
        } else {
            psi_s
        };
        let psi_r = (psi_c - i_ab[k] * sls) * kr;
        let ang = if psi_r.norm_sqr() > 1e-12 {
            psi_r.im.atan2(psi_r.re)
        } else {
            // No flux yet: follow the nominal supply.
            prev_ang.map(|a| a + w0 * dt).unwrap_or(0.0)
        };
        match prev_ang {
            None => unwrapped = ang,
            Some(pa) => {
                let mut da = ang - pa;
                da = (da + std::f64::consts::PI).rem_euclid(2.0 * std::f64::consts::PI)
                    - std::f64::consts::PI;
                unwrapped += da;
            }
        }
        prev_ang = Some(ang);
        theta.push(unwrapped);
    }
    theta
}

/// The frame angle: the voltage-model angle carries a 2f wobble when the machine or the
/// supply is unbalanced; the frame follows its zero-phase smoothed version (20 Hz), which
/// keeps start-up and step transients and makes the sequence separation clean.
/// (Smoothing the angle's increments and summing them back avoids the end effects a
/// filter has on a ramp.)
fn smooth_angle(mut theta: Vec<f64>, dt: f64) -> Vec<f64> {
    let n = theta.len();
    if n <= 2 {
        return theta;
    }
    let mut inc: Vec<f64> = theta.windows(2).map(|w| w[1] - w[0]).collect();
    zero_phase_lpf_in_place(&mut inc, dt, THETA_SMOOTH_HZ);
    let mut th = theta[0];
    let mut smooth = Vec::with_capacity(n);
    smooth.push(th);
    for v in inc {
        th += v;
        smooth.push(th);
    }
    // A zero-phase filter moves the running sum of a ramp's increments at every kink
    // (by the slope change times half the kernel's variance: 0.02 rad for a V/f ramp
    // of 150 rad/s^2 at 20 Hz, enough to tilt I_qs by 13 % of I_ds x 0.02 in a sweep). The
    // summed angle is therefore only the reference: the raw angle's deviation from it,
    // itself smoothed, is added back, so the frame follows the flux at every kink.
    // (The deviation takes the raw angle's buffer.)
    for (a, b) in theta.iter_mut().zip(&smooth) {
        *a -= b;
    }
    zero_phase_lpf_in_place(&mut theta, dt, THETA_SMOOTH_HZ);
    for (v, e) in smooth.iter_mut().zip(&theta) {
        *v += e;
    }
    smooth
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A balanced supply that steps from 100 % at 50 Hz to 60 % at 30 Hz (a V/f step)
    /// has no negative sequence; the separation must not make one. Before it ran in the
    /// supply's frame and both ways around steps: 0.3 % of the voltage for 0.2 s.
    #[test]
    fn a_supply_step_makes_no_negative_sequence() {
        let p = ParamFile::reference_2p2kw();
        let dt = 0.5e-3;
        let vpk = p.supply.v_phase_peak();
        let mut d = Decimated {
            channels: monitor_io::log::Channels {
                voltages: true,
                speed: false,
                encoder: false,
                temperature: false,
            },
            factor: 1,
            log_rate_hz: 1.0 / dt,
            ..Default::default()
        };
        let mut phase = 0.0f64;
        for k in 0..6000 {
            let t = k as f64 * dt;
            let (scale, f) = if t < 1.5 { (1.0, 50.0) } else { (0.6, 30.0) };
            let v = C64::from_polar(vpk * scale, phase);
            // A current lagging the voltage by 30 degrees.
            let i = C64::from_polar(5.0 * scale, phase - 0.5);
            d.t_s.push(t);
            d.v_ab.push([v.re as f32, v.im as f32]);
            d.i_ab.push([i.re as f32, i.im as f32]);
            d.i0.push(0.0);
            phase += 2.0 * std::f64::consts::PI * f * dt;
        }
        let prep = voltage_model_flux_frame(&d, &p);
        let worst = prep.v_neg.iter().map(|x| x.norm()).fold(0.0, f64::max);
        assert!(
            worst < 1e-3 * vpk,
            "|v_neg| up to {worst:.3} V of {vpk:.0} V"
        );
    }
}
