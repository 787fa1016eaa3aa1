//! The machine's sequence impedances (T-equivalent circuit), for the unbalance effects.

use crate::prep::C64;
use crate::simplified_model::MachineConstants;

/// Negative-sequence impedance of the machine at supply angular frequency `w` (rotor at
/// about synchronous speed, so the rotor branch sees slip 2): positive-frequency form
/// `Rs + j w Lls + (j w Lm) || (Rr/2 + j w Llr)`; the negative-sequence current is
/// `v_neg / conj(Z2)`.
pub fn z2_neg(n: &MachineConstants, w: f64) -> C64 {
    z2_neg_at(n, w, 2.0)
}

/// [`z2_neg`] at the negative-sequence slip `s2 = 2 - s = 1 + omega_r/omega_s` of the
/// present speed: the rotor branch is `Rr/s2 + j w Llr`, so at standstill (a start, `s2`
/// = 1) the rotor resistance counts twice what it does near synchronous speed (the
/// reduced model's `supply_unbalance`; the full-order model gets this from the machine
/// itself). `s2` is held at 0.05 or more (a rotor driven backwards near the supply speed).
pub fn z2_neg_at(n: &MachineConstants, w: f64, s2: f64) -> C64 {
    let w = w.abs().max(1.0);
    let s2 = if s2.is_finite() { s2.max(0.05) } else { 2.0 };
    let zm = C64::new(0.0, w * n.lm_h);
    let zr = C64::new(n.rr_ohm / s2, w * n.llr_h);
    C64::new(n.rs_ohm, w * n.lls_h) + zm * zr / (zm + zr)
}

/// Positive-sequence impedance of the machine at supply angular frequency `w` and slip `s`
/// (T-equivalent circuit, `Rs + j w Lls + (j w Lm) || (Rr/s + j w Llr)`; the rotor branch
/// as an admittance, so that s = 0 is the open rotor).
pub fn z1_pos(n: &MachineConstants, w: f64, s: f64) -> C64 {
    let w = w.abs().max(1.0);
    let y_r = C64::new(s, 0.0) / C64::new(n.rr_ohm, s * w * n.llr_h);
    let y_m = C64::new(0.0, -1.0 / (w * n.lm_h));
    C64::new(n.rs_ohm, w * n.lls_h) + (y_m + y_r).inv()
}
