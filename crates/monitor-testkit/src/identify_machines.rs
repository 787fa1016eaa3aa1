//! The six machines the `identify` tests identify (`crates/monitor-analysis/tests/analysis/identify.rs`,
//! the library; `sim-host/tests/cli/identify.rs`, the command), each with its published circuit,
//! its nameplate (computed from that circuit) and the start file `params from-nameplate`
//! estimates from it.

use monitor_core::{MotorParameters, SupplyParameters};
use monitor_io::nameplate::{estimate, Connection, Nameplate, NemaDesign};
use monitor_io::params::ParamFile;
use monitor_sim::steady_state_at;
use std::f64::consts::TAU;

/// A machine: name, rated kW, V_ll, Hz, [Rs, Rr, Lls, Llr, Lm] (ohm, H), J [kg m^2].
pub struct Machine {
    /// The name the tests print.
    pub name: &'static str,
    /// Rated shaft power [kW].
    pub p_kw: f64,
    /// Rated line-to-line voltage [V rms].
    pub v_ll: f64,
    /// Rated frequency [Hz].
    pub f_hz: f64,
    /// The T-circuit [Rs, Rr, Lls, Llr, Lm] (ohm, H).
    pub t: [f64; 5],
    /// Rotor inertia [kg m^2].
    pub j: f64,
}

/// The six machines (4-pole): a 0.37 kW machine of per-unit values typical of its size
/// (made for these tests, see `crates/monitor-io/tests/io/nameplate.rs`); motulator's
/// 2.2 kW (published in inverse-Gamma form: its leakage all on the stator side);
/// Krause, Wasynczuk and Sudhoff's 3 hp and 50 hp (Analysis of Electric Machinery and
/// Drive Systems, 60 Hz, Xls = Xlr, with their J); MATLAB/Simscape's 4 kW and 15 kW
/// presets as transcribed by the Modelica Buildings library (Ls = Lr, J of the presets).
pub fn machines() -> Vec<Machine> {
    let w60 = TAU * 60.0;
    let krause = |name, hp: f64, v, rs, xl: f64, xm: f64, rr, j| Machine {
        name,
        p_kw: hp * 0.7457,
        v_ll: v,
        f_hz: 60.0,
        t: [rs, rr, xl / w60, xl / w60, xm / w60],
        j,
    };
    let simscape = |name, p_kw, rs, rr, ls: f64, lm: f64, j| Machine {
        name,
        p_kw,
        v_ll: 400.0,
        f_hz: 50.0,
        t: [rs, rr, ls - lm, ls - lm, lm],
        j,
    };
    let w50 = TAU * 50.0;
    vec![
        Machine {
            name: "small 0.37 kW",
            p_kw: 0.37,
            v_ll: 400.0,
            f_hz: 50.0,
            t: [30.0, 24.0, 16.0 / w50, 16.0 / w50, 260.0 / w50],
            j: 0.0009,
        },
        Machine {
            name: "motulator 2.2 kW",
            p_kw: 2.2,
            v_ll: 400.0,
            f_hz: 50.0,
            t: [3.7, 2.1, 0.021, 0.0, 0.224],
            j: 0.015,
        },
        krause("Krause 3 hp", 3.0, 220.0, 0.435, 0.754, 26.13, 0.816, 0.089),
        simscape("Simscape 4 kW", 4.0, 1.405, 1.395, 0.178039, 0.1722, 0.0131),
        simscape(
            "Simscape 15 kW",
            15.0,
            0.2147,
            0.2205,
            0.065181,
            0.06419,
            0.102,
        ),
        krause(
            "Krause 50 hp",
            50.0,
            460.0,
            0.087,
            0.302,
            13.08,
            0.228,
            1.662,
        ),
    ]
}

impl Machine {
    /// The true parameter file: the circuit, J, the paper's viscous load at rated torque.
    pub fn truth(&self) -> ParamFile {
        let [rs, rr, lls, llr, lm] = self.t;
        let w_rated = TAU * self.f_hz / 2.0 * 0.97;
        ParamFile {
            motor: MotorParameters {
                rs_ohm: rs,
                rr_ohm: rr,
                ls_h: lm + lls,
                lr_h: lm + llr,
                lm_h: lm,
                poles: 4,
                j_kgm2: self.j,
                b_nms: 0.005 * 1000.0 * self.p_kw / (w_rated * w_rated),
                bl_nms: 1000.0 * self.p_kw / (w_rated * w_rated),
                rotor_bars: None,
                lm_at: None,
            },
            supply: SupplyParameters {
                v_ll_rms: self.v_ll,
                f_hz: self.f_hz,
            },
        }
    }

    /// The nameplate at rated shaft power (slip by bisection on the analytic steady
    /// state), rounded as a nameplate prints it.
    pub fn nameplate(&self) -> Nameplate {
        let m = self.truth().motor;
        let at = |s: f64| steady_state_at(&m, self.v_ll, self.f_hz, s);
        let (mut lo, mut hi) = (1e-5, 0.3);
        for _ in 0..200 {
            let mid = 0.5 * (lo + hi);
            if at(mid).p_mech_w < 1000.0 * self.p_kw {
                lo = mid;
            } else {
                hi = mid;
            }
        }
        let st = at(0.5 * (lo + hi));
        let sig3 = |x: f64| {
            let k = 10f64.powi(2 - x.log10().floor() as i32);
            (x * k).round() / k
        };
        Nameplate {
            power_kw: self.p_kw,
            voltage_v: self.v_ll,
            current_a: sig3(st.i_phase_rms_a),
            frequency_hz: self.f_hz,
            speed_rpm: (st.wm_rad_s * 60.0 / TAU).round(),
            power_factor: (100.0 * st.power_factor).round() / 100.0,
            efficiency: (1000.0 * 1000.0 * self.p_kw / st.p_in_w).round() / 1000.0,
            poles: None,
            connection: Connection::Star,
            locked_rotor_ratio: None,
            design: NemaDesign::B,
        }
    }

    /// The start file: `params from-nameplate`'s estimate.
    pub fn start(&self) -> ParamFile {
        estimate(&self.nameplate())
            .unwrap_or_else(|e| panic!("{}: {e}", self.name))
            .params
    }
}
