//! The 0.37 kW machine the tests use beside the two reference motors (the one of
//! `crates/monitor-io/tests/io/nameplate.rs`: made for the tests from per-unit values typical of its size, not a
//! published circuit), and the three motors as a list.

use monitor_core::{MotorParameters, SupplyParameters};
use monitor_io::params::ParamFile;
use std::f64::consts::TAU;

/// The 0.37 kW, 400 V, 50 Hz, 4-pole machine (Rs 30, Rr 24, Xls = Xlr 16, Xm 260 ohm at
/// 50 Hz), J of a 71-frame motor, the paper's viscous load at its rated torque (2.57 N m
/// at 1375 rpm).
pub fn small_0p37kw() -> ParamFile {
    let w = TAU * 50.0;
    let (lm, ll) = (260.0 / w, 16.0 / w);
    let w_rated = TAU * 1375.0 / 60.0;
    let bl = 370.0 / (w_rated * w_rated);
    ParamFile {
        motor: MotorParameters {
            rs_ohm: 30.0,
            rr_ohm: 24.0,
            ls_h: lm + ll,
            lr_h: lm + ll,
            lm_h: lm,
            poles: 4,
            j_kgm2: 0.0009,
            b_nms: 0.005 * bl,
            bl_nms: bl,
            rotor_bars: None,
            lm_at: None,
        },
        supply: SupplyParameters {
            v_ll_rms: 400.0,
            f_hz: 50.0,
        },
    }
}

/// The 3 hp and 2.2 kW reference motors and the 0.37 kW machine, with their names.
pub fn three_motors() -> Vec<(&'static str, ParamFile)> {
    vec![
        ("3 hp", ParamFile::reference_3hp()),
        ("2.2 kW", ParamFile::reference_2p2kw()),
        ("0.37 kW", small_0p37kw()),
    ]
}

/// Krause, Wasynczuk and Sudhoff's 50 hp, 460 V, 60 Hz, 4-pole machine (Analysis of
/// Electric Machinery and Drive Systems: Rs 0.087, Rr 0.228, Xls = Xlr 0.302, Xm 13.08
/// ohm at 60 Hz, J 1.662 kg m^2), in the paper's simplified-model structure (Ls = Lls + Lm,
/// Lr = Llr + Lm, the viscous load): Bl 0.9 N m s/rad, 160 N m (0.8 of its rated 198 N m)
/// at 1705 rpm, B a hundredth of it.
pub fn krause_50hp() -> ParamFile {
    let w = TAU * 60.0;
    let (xm, xl) = (13.08, 0.302);
    let mut p = ParamFile::reference_3hp();
    p.motor.rs_ohm = 0.087;
    p.motor.rr_ohm = 0.228;
    p.motor.lm_h = xm / w;
    p.motor.ls_h = (xm + xl) / w;
    p.motor.lr_h = (xm + xl) / w;
    p.motor.j_kgm2 = 1.662;
    p.motor.bl_nms = 0.9;
    p.motor.b_nms = 0.009;
    p.supply.v_ll_rms = 460.0;
    p
}
