//! The squirrel cage with broken bars: the relation between adjacent broken bars, the
//! rotor phase resistance asymmetry `delta` they make, and the stator-current sidebands
//! that asymmetry drives. One home for the simulator (which integrates `delta`), the
//! `explain` analysis and `diagnose`'s rotor finding (which read it back from the
//! sidebands); the board does no spectral analysis and uses none of it.
//!
//! # Broken bars and delta
//! For an `N`-bar cage with `n` adjacent broken bars the equivalent rotor phase resistance
//! asymmetry (rotor phase a's resistance `Rr (1 + delta)`) is
//! ```text
//!   delta = 3n / (N - 3n),        n = delta N / (3 (1 + delta))
//! ```
//! (Kliman, Koegl, Stein, Endicott, Madden, "Noninvasive detection of broken rotor bars in
//! operating induction motors", IEEE Trans. Energy Convers. 3(4), 1988; Bellini,
//! Filippetti, Franceschini, Tassoni, Kliman, "Quantitative evaluation of induction motor
//! broken bars by means of electrical signature analysis", IEEE Trans. Ind. Appl. 37(5),
//! 2001). An approximation: the broken bars' current is taken as redistributed over the
//! healthy bars of one rotor pole pitch; inter-bar currents (which make real sidebands
//! smaller) and the end-ring resistance are ignored. Valid for `0 <= n < N/3`.
//!
//! # delta from the sidebands
//! The resistance mismatch's negative-sequence part, `(delta/3) Rr`, times the forward
//! rotor current drives a backward rotor current whose circuit, at small slip, is the
//! rotor resistance `Rr (1 + delta/3)`: `I_b / I_r = (delta/3) / (1 + delta/3) =
//! delta / (3 + delta)`. In the stator it is the `(1 - 2s) f` sideband; the `2 s f` speed
//! ripple moves part of it to `(1 + 2s) f`, and the sum of the two does not depend on the
//! inertia (Bellini et al. 2001). Referred to the torque-producing current `I_q` (the
//! magnetising current carries no sideband), with `r = (I_(1-2s)f + I_(1+2s)f) / I_q`:
//! ```text
//!   delta = 3 r / (1 - r),        n = r N / (1 + 2 r)
//! ```
//! Its further approximations: the backward circuit's leakage reactance and the stator's
//! impedance at `(1 - 2s) f` neglected, the coupling `Lm^2 / (Ls Lr)` taken as 1.

/// The rotor phase resistance asymmetry `delta = 3n / (N - 3n)` of a cage of `bars` bars
/// with `n` adjacent broken bars (module docs; `0 <= n < bars / 3`, infinite at
/// `n = bars / 3`).
pub fn delta_of_broken_bars(n: f64, bars: f64) -> f64 {
    3.0 * n / (bars - 3.0 * n)
}

/// The number of adjacent broken bars `n = delta N / (3 (1 + delta))` of a cage of `bars`
/// bars equivalent to the asymmetry `delta` (the inverse of [`delta_of_broken_bars`];
/// `delta >= 0`).
pub fn broken_bars_of_delta(delta: f64, bars: f64) -> f64 {
    delta * bars / (3.0 * (1.0 + delta))
}

/// The asymmetry `delta = 3 r / (1 - r)` that the sidebands say, `r` their amplitudes'
/// sum over the torque-producing current (module docs, "delta from the sidebands").
/// `None` unless `0 <= r < 1` (sidebands as large as the torque current are outside the
/// first-order relation's range).
pub fn delta_of_sideband_ratio(r: f64) -> Option<f64> {
    (r.is_finite() && (0.0..1.0).contains(&r)).then(|| 3.0 * r / (1.0 - r))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn broken_bars_and_delta_are_inverse() {
        // One broken bar of 28: 3/25 = 0.12.
        assert!((delta_of_broken_bars(1.0, 28.0) - 0.12).abs() < 1e-12);
        for (n, nb) in [(1.0, 28.0), (2.0, 40.0), (3.0, 36.0)] {
            let d = delta_of_broken_bars(n, nb);
            assert!((broken_bars_of_delta(d, nb) - n).abs() < 1e-12);
        }
    }

    #[test]
    fn the_sidebands_give_back_the_bars() {
        // n = r N / (1 + 2 r) from delta = 3r/(1-r) and n = delta N / (3 (1 + delta)).
        for r in [0.0, 0.01, 0.05, 0.2] {
            let d = delta_of_sideband_ratio(r).unwrap_or(f64::NAN);
            let n = broken_bars_of_delta(d, 28.0);
            assert!((n - r * 28.0 / (1.0 + 2.0 * r)).abs() < 1e-12, "{r}");
        }
        assert_eq!(delta_of_sideband_ratio(1.0), None);
        assert_eq!(delta_of_sideband_ratio(-0.1), None);
        assert_eq!(delta_of_sideband_ratio(f64::NAN), None);
    }
}
