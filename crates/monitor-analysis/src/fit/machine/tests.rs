//! The machine fit's factors and its variance inflation.

use super::*;

#[test]
fn applying_factors_keeps_the_circuit_consistent() {
    let p = ParamFile::reference_2p2kw();
    let s = MachineScales {
        rs: 1.2,
        rr: 0.9,
        leakage: 1.5,
        lm: 0.8,
        j: 2.0,
        b_nms: 0.03,
    };
    let q = s.apply(&p);
    let (lls, llr) = (p.motor.ls_h - p.motor.lm_h, p.motor.lr_h - p.motor.lm_h);
    assert!((q.motor.rs_ohm - 1.2 * p.motor.rs_ohm).abs() < 1e-12);
    assert!((q.motor.rr_ohm - 0.9 * p.motor.rr_ohm).abs() < 1e-12);
    assert!((q.motor.lm_h - 0.8 * p.motor.lm_h).abs() < 1e-12);
    assert!((q.motor.ls_h - q.motor.lm_h - 1.5 * lls).abs() < 1e-12);
    assert!((q.motor.lr_h - q.motor.lm_h - 1.5 * llr).abs() < 1e-12);
    assert!((q.motor.j_kgm2 - 2.0 * p.motor.j_kgm2).abs() < 1e-12);
    assert!((q.motor.b_nms + q.motor.bl_nms - 0.03).abs() < 1e-12);
    // The file's own values give the file back.
    assert_eq!(MachineScales::of_file(&p).apply(&p), p);
    assert!((s.change(BaseKey::Rs, &p) - 0.2).abs() < 1e-12);
}

#[test]
fn correlated_residuals_inflate_the_variance() {
    // White: about 1. A slow sine sampled finely: large.
    // A 64-bit linear congruential generator's top bits (Knuth's MMIX constants).
    let mut x: u64 = 1;
    let white: Vec<f64> = (0..4000)
        .map(|_| {
            x = x
                .wrapping_mul(6_364_136_223_846_793_005)
                .wrapping_add(1_442_695_040_888_963_407);
            (x >> 11) as f64 / (1u64 << 53) as f64 - 0.5
        })
        .collect();
    assert!(inflation(&white, 1) < 1.2, "{}", inflation(&white, 1));
    let slow: Vec<f64> = (0..4000).map(|k| (k as f64 * 0.01).sin()).collect();
    assert!(inflation(&slow, 1) > 100.0, "{}", inflation(&slow, 1));
    // Interleaved channels are taken apart.
    let two: Vec<f64> = slow.iter().flat_map(|v| [*v, -*v]).collect();
    assert!((inflation(&two, 2) - inflation(&slow, 1)).abs() < 1e-9);
}
