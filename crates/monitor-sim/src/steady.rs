//! Analytic steady state of the T-equivalent circuit (per phase, RMS phasors).
//!
//! ```text
//!   V ──Rs──jX_ls──┬──jX_lr──Rr/s──┐        X = omega_e L,  Z_m = jX_m
//!                  jX_m            │        I_s = V / (Z_s + Z_m || Z_r)
//!   N ─────────────┴───────────────┘        T_e = 3 |I_r|^2 (Rr/s) / (omega_e / Np)
//! ```
//! Source: any machine text (e.g. Chapman, *Electric Machinery Fundamentals*, ch. 6;
//! Krause, *Analysis of Electric Machinery*, ch. 6). Exact for the balanced linear machine
//! of the simulator without effects (iron loss, saturation, unbalance are not included).

use super::SimError;
use monitor_core::MotorParameters;
use monitor_io::params::ParamFile;
use nalgebra::Complex;

/// Steady operating point of the T-equivalent circuit at a given slip.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct SteadyState {
    /// Slip s = (omega_e - Np omega_m) / omega_e [-].
    pub slip: f64,
    /// Mechanical speed omega_m = (1 - s) omega_e / Np [rad/s].
    pub wm_rad_s: f64,
    /// Stator phase current RMS [A].
    pub i_phase_rms_a: f64,
    /// Rotor current RMS (referred to the stator) [A].
    pub ir_rms_a: f64,
    /// Magnetising current RMS [A].
    pub im_rms_a: f64,
    /// Electromagnetic (air-gap) torque [N m].
    pub torque_nm: f64,
    /// Input power 3 Re(V I*) [W].
    pub p_in_w: f64,
    /// Copper losses 3 (Rs |Is|^2 + Rr |Ir|^2) [W].
    pub p_cu_w: f64,
    /// Mechanical (shaft, before friction) power T_e omega_m [W].
    pub p_mech_w: f64,
    /// Power factor cos(phi) [-].
    pub power_factor: f64,
}

/// A steady load: T_load = torque_nm + b_total_nms * omega_m (omega_m mechanical, rad/s).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SteadyLoad {
    /// Speed-independent load torque [N m], >= 0.
    pub torque_nm: f64,
    /// Total viscous coefficient on the shaft (machine B plus load Bl) [N m s/rad], >= 0.
    pub b_total_nms: f64,
}

impl SteadyLoad {
    /// The paper's load with the parameter file's values: b = B + Bl, no constant torque.
    pub fn viscous(params: &ParamFile) -> Self {
        SteadyLoad {
            torque_nm: 0.0,
            b_total_nms: params.motor.b_nms + params.motor.bl_nms,
        }
    }
    /// A constant load torque plus the machine's own friction B.
    pub fn torque(params: &ParamFile, torque_nm: f64) -> Self {
        SteadyLoad {
            torque_nm,
            b_total_nms: params.motor.b_nms,
        }
    }
}

/// Steady state at slip `slip` (0 < |slip|, any sign; s = 0 gives zero rotor current) with
/// the parameter file's supply.
pub fn steady_state(params: &ParamFile, slip: f64) -> SteadyState {
    steady_state_at(
        &params.motor,
        params.supply.v_ll_rms,
        params.supply.f_hz,
        slip,
    )
}

/// Steady state at slip `slip` for an explicit supply (line-to-line RMS voltage [V],
/// frequency [Hz]).
pub fn steady_state_at(m: &MotorParameters, v_ll_rms: f64, f_hz: f64, slip: f64) -> SteadyState {
    let we = 2.0 * std::f64::consts::PI * f_hz;
    let model = m.model::<f64>();
    let np = model.np();
    let v = Complex::new(v_ll_rms / 3f64.sqrt(), 0.0);
    let zs = Complex::new(m.rs_ohm, we * model.lls_h());
    let zm = Complex::new(0.0, we * m.lm_h);
    let (is, ir, im, torque) = if slip == 0.0 {
        let is = v / (zs + zm);
        (is, Complex::new(0.0, 0.0), is, 0.0)
    } else {
        let zr = Complex::new(m.rr_ohm / slip, we * model.llr_h());
        let zp = zm * zr / (zm + zr);
        let is = v / (zs + zp);
        let e = is * zp;
        let ir = e / zr;
        let im = e / zm;
        let pag = 3.0 * ir.norm_sqr() * m.rr_ohm / slip;
        (is, ir, im, pag / (we / np))
    };
    let s = v * is.conj();
    let wm = (1.0 - slip) * we / np;
    SteadyState {
        slip,
        wm_rad_s: wm,
        i_phase_rms_a: is.norm(),
        ir_rms_a: ir.norm(),
        im_rms_a: im.norm(),
        torque_nm: torque,
        p_in_w: 3.0 * s.re,
        p_cu_w: 3.0 * (m.rs_ohm * is.norm_sqr() + m.rr_ohm * ir.norm_sqr()),
        p_mech_w: torque * wm,
        power_factor: s.re / s.norm(),
    }
}

/// Solves T_e(s) = load.torque_nm + load.b_total_nms * omega_m(s) for the stable motoring
/// slip (between 0 and the pull-out slip) at the parameter file's supply.
///
/// # Errors
/// [`SimError::Invalid`] if the load is negative (generating; not supported) or exceeds
/// the pull-out torque.
pub fn solve_slip(params: &ParamFile, load: SteadyLoad) -> Result<SteadyState, SimError> {
    solve_slip_at(
        &params.motor,
        params.supply.v_ll_rms,
        params.supply.f_hz,
        load,
    )
}

/// As [`solve_slip`] for an explicit supply.
///
/// # Errors
/// As [`solve_slip`].
pub fn solve_slip_at(
    m: &MotorParameters,
    v_ll_rms: f64,
    f_hz: f64,
    load: SteadyLoad,
) -> Result<SteadyState, SimError> {
    let f = |s: f64| {
        let st = steady_state_at(m, v_ll_rms, f_hz, s);
        st.torque_nm - load.torque_nm - load.b_total_nms * st.wm_rad_s
    };
    if !(load.torque_nm >= 0.0 && load.b_total_nms >= 0.0) {
        return Err(SimError::Invalid {
            key: "load".into(),
            message: "steady state needs a motoring load (torque >= 0, b >= 0)".into(),
        });
    }
    // Pull-out slip: scan log-spaced slips for the torque maximum.
    let mut s_max = 1.0;
    let mut t_max = f64::NEG_INFINITY;
    let mut s = 1e-5;
    while s <= 1.0 {
        let t = steady_state_at(m, v_ll_rms, f_hz, s).torque_nm;
        if t > t_max {
            t_max = t;
            s_max = s;
        }
        s *= 1.05;
    }
    let (mut lo, mut hi) = (1e-12, s_max);
    if f(hi) <= 0.0 {
        return Err(SimError::Invalid {
            key: "load".into(),
            message: format!(
                "load exceeds the pull-out torque ({t_max:.2} N m at slip {s_max:.3})"
            ),
        });
    }
    if f(lo) > 0.0 {
        return Ok(steady_state_at(m, v_ll_rms, f_hz, lo));
    }
    for _ in 0..200 {
        let mid = 0.5 * (lo + hi);
        if f(mid) > 0.0 {
            hi = mid;
        } else {
            lo = mid;
        }
        if hi - lo < 1e-15 {
            break;
        }
    }
    Ok(steady_state_at(m, v_ll_rms, f_hz, 0.5 * (lo + hi)))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn power_balance_of_the_circuit() {
        for p in [ParamFile::reference_2p2kw(), ParamFile::reference_3hp()] {
            for s in [0.005, 0.03, 0.2, 1.0] {
                let st = steady_state(&p, s);
                // P_in = P_cu + P_mech (the air-gap power splits into Rr losses and P_mech).
                let err = st.p_in_w - st.p_cu_w - st.p_mech_w;
                assert!(err.abs() < 1e-9 * st.p_in_w.abs(), "s={s}: {err}");
            }
        }
    }

    #[test]
    fn solved_slip_meets_the_load() {
        let p = ParamFile::reference_2p2kw();
        let st = solve_slip(&p, SteadyLoad::torque(&p, 14.6)).unwrap();
        let tl = 14.6 + p.motor.b_nms * st.wm_rad_s;
        assert!((st.torque_nm - tl).abs() < 1e-9);
        // Rated point of a 2.2 kW 4-pole machine: slip of a few percent.
        assert!(st.slip > 0.02 && st.slip < 0.08, "{}", st.slip);
        assert!(solve_slip(&p, SteadyLoad::torque(&p, 1000.0)).is_err());
    }

    #[test]
    fn the_sensor_ranges_locked_rotor_current_is_the_circuits() {
        // params derives the sensors' current range from the same circuit at slip 1.
        for p in [ParamFile::reference_2p2kw(), ParamFile::reference_3hp()] {
            for (v, f) in [
                (p.supply.v_ll_rms, p.supply.f_hz),
                (400.0, 50.0),
                (230.0, 60.0),
            ] {
                let st = steady_state_at(&p.motor, v, f, 1.0);
                let i = monitor_io::params::locked_rotor_current_rms_a(&p.motor, v, f);
                assert_eq!(i, st.i_phase_rms_a, "{v} V {f} Hz");
            }
        }
    }
}
