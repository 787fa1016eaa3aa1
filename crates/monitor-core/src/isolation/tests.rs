//! Tests of the fault isolation, by topic: naming at one operating point
//! (`single_point`), heating and a measured rise (`heating`), the follower's schedule and
//! the evidence over operating points (`operating_points`). Here: the true machine's
//! steady states they share.

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
        rotor_bars: None,
        lm_at: None,
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

/// An isolator for `m` on a supply of peak `v` and `we` rad/s, with a baseline learned at
/// its healthy point (spreads at their floor, [`LEARNED_SPREAD_FLOOR`]).
fn floor_isolator(m: &MotorParameters, v: f64, we: f64) -> Isolator {
    let mut iso = Isolator::new(m.model(), v as f32, (we / core::f64::consts::TAU) as f32).unwrap(); // ok: test
    iso.set_baseline(Baseline {
        mean: ParityResiduals::default(),
        spread: LEARNED_SPREAD_FLOOR,
        at: measure(m, v, we, None, 1.0),
    })
    .unwrap(); // ok: test
    iso
}

/// An isolator for `m` commissioned over the healthy machine's steady states at `loads`
/// (multiples of its viscous load): the learned mean is zero (the parameter file is the
/// machine), the spreads at their floor, and the commissioned range spans the loads, so
/// the directions are as sure as a file that fits makes them (module docs, "How sure a
/// name is"); against the nominal values alone the file could be 20 % off.
fn commissioned_isolator(m: &MotorParameters, v: f64, we: f64, loads: &[f64]) -> Isolator {
    let mut iso = Isolator::new(m.model(), v as f32, (we / core::f64::consts::TAU) as f32).unwrap(); // ok: test
    for load in loads {
        let mut t = *m;
        t.bl_nms *= load;
        let p = measure(&t, v, we, None, 1.0);
        for _ in 0..MIN_LEARNED_POINTS {
            iso.learn(&p);
        }
    }
    assert!(iso.finish_learning());
    iso
}

/// The machine warmed by `rise_k`: Rs and Rr times 1 + alpha rise.
fn warmed(m: &MotorParameters, rise_k: f64) -> MotorParameters {
    let k = 1.0 + f64::from(COPPER_ALPHA_PER_K) * rise_k;
    MotorParameters {
        rs_ohm: m.rs_ohm * k,
        rr_ohm: m.rr_ohm * k,
        ..*m
    }
}

mod calibration;
mod heating;
mod operating_points;
mod single_point;
