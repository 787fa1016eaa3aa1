//! J and B + Bl from the torque balance of the paper's mechanics (Energies 2022, 15(22),
//! 8372, eq. 27 with the load `Bl omega_m`): `T_e = J domega_m/dt + (B + Bl) omega_m`,
//! integrated over windows of [`WINDOW_S`] so the measured speed is not differentiated:
//! ```text
//!   int T_e dt = J (omega(t_b) - omega(t_a)) + (B + Bl) int omega dt   (trapezoid sums)
//! ```
//! `T_e` is the identified electrical model's torque with the measured speed imposed;
//! linear least squares gives both, and `s^2 (A^T A)^-1` their variances. A constant
//! load torque (not in the model) is taken as friction: B + Bl is then the mean torque
//! over the mean speed of the windows, not a viscous coefficient.

use super::model::{simulate, IdentifiedCircuit};
use super::Samples;
use nalgebra::DMatrix;

/// Window of the integrated torque balance [s].
pub const WINDOW_S: f64 = 0.02;

/// The judged result of a parameter: `(value, lo, hi)` or why it was not identified.
pub type MechanicsJudged = Result<(f64, f64, f64), NotIdentified>;

/// Why a parameter was not identified (its `Display` is the report's sentence,
/// `not_identified_because`).
#[derive(Debug, Clone, Copy, PartialEq, thiserror::Error)]
pub enum NotIdentified {
    /// A flat direction of the fit.
    #[error(
        "the log leaves it undetermined (a flat direction of the fit: the log does not excite it)"
    )]
    Flat,
    /// A 95 % interval wider than the value.
    #[error("the log does not determine it: its 95 % interval {lo:.3e}..{hi:.3e} is wider than the value {value:.3e}")]
    TooWide {
        /// The value.
        value: f64,
        /// The interval's ends.
        lo: f64,
        /// The interval's ends.
        hi: f64,
    },
    /// A value that is not positive.
    #[error("the fit gives {value:.3e}, not a physical value (95 % interval {lo:.3e}..{hi:.3e})")]
    NotPhysical {
        /// The value.
        value: f64,
        /// The interval's ends.
        lo: f64,
        /// The interval's ends.
        hi: f64,
    },
    /// The identified circuit cannot be simulated.
    #[error("the identified circuit cannot be simulated")]
    CircuitFails,
    /// Too few samples for the torque balance's windows.
    #[error("the log is too short for the torque balance")]
    TooShort,
    /// The parameter was not among those fitted.
    #[error("not fitted")]
    NotFitted,
}

/// J and B + Bl.
#[derive(Debug, Clone)]
pub struct Mechanics {
    /// J [kg m^2].
    pub j: MechanicsJudged,
    /// B + Bl [N m s/rad].
    pub b_total: MechanicsJudged,
}

/// A log-space estimate: `value` and the standard deviation of `ln(value)`.
#[derive(Debug, Clone, Copy)]
pub struct LogEstimate {
    /// The value.
    pub value: f64,
    /// Standard deviation of its logarithm.
    pub sigma: f64,
}

impl LogEstimate {
    /// The 95 % interval `value exp(+-1.96 sigma)`; not identified when it is wider than
    /// the value or sigma is not finite.
    pub fn judged(&self) -> MechanicsJudged {
        let (v, sg) = (self.value, self.sigma);
        if !sg.is_finite() {
            return Err(NotIdentified::Flat);
        }
        let (lo, hi) = (v * (-1.96 * sg).exp(), v * (1.96 * sg).exp());
        if hi - lo > v {
            return Err(NotIdentified::TooWide { value: v, lo, hi });
        }
        Ok((v, lo, hi))
    }
}

/// A linear estimate's judgement: `value +- 1.96 sigma`, not identified when that is wider
/// than the value or the value is not positive.
fn judged_linear(v: f64, sg: f64) -> MechanicsJudged {
    if !sg.is_finite() {
        return Err(NotIdentified::Flat);
    }
    let (lo, hi) = (v - 1.96 * sg, v + 1.96 * sg);
    if v.is_nan() || v <= 0.0 {
        return Err(NotIdentified::NotPhysical { value: v, lo, hi });
    }
    if hi - lo > v {
        return Err(NotIdentified::TooWide { value: v, lo, hi });
    }
    Ok((v, lo, hi))
}

/// J and B + Bl of the log `s` with the identified circuit `c` (the speed imposed).
pub fn fit(c: &IdentifiedCircuit, s: &Samples) -> Mechanics {
    let fail = |why: NotIdentified| Mechanics {
        j: Err(why),
        b_total: Err(why),
    };
    let (Some(t), Some(w)) = (simulate(c, s), s.wm_rad_s.as_ref()) else {
        return fail(NotIdentified::CircuitFails);
    };
    let step = ((WINDOW_S / s.dt_s).round() as usize).max(1);
    let (mut rows, mut y) = (Vec::new(), Vec::new());
    let n = w.len();
    let mut a = 0;
    while a + step < n {
        let b = a + step;
        let trap = |x: &[f64]| -> f64 {
            x[a..=b]
                .windows(2)
                .map(|p| 0.5 * (p[0] + p[1]))
                .sum::<f64>()
                * s.dt_s
        };
        rows.push([w[b] - w[a], trap(w)]);
        y.push(trap(&t.torque_nm));
        a = b;
    }
    if rows.len() < 3 {
        return fail(NotIdentified::TooShort);
    }
    linear_fit(&rows, &y)
}

/// Least squares of `y = A [J, B]` with column scaling, and the judged results.
fn linear_fit(rows: &[[f64; 2]], y: &[f64]) -> Mechanics {
    let norm = |k: usize| rows.iter().map(|r| r[k] * r[k]).sum::<f64>().sqrt();
    let sc = [norm(0).max(1e-300), norm(1).max(1e-300)];
    let mut ata = DMatrix::<f64>::zeros(2, 2);
    let mut aty = [0.0; 2];
    for (r, yk) in rows.iter().zip(y) {
        let u = [r[0] / sc[0], r[1] / sc[1]];
        for i in 0..2 {
            aty[i] += u[i] * yk;
            for j in 0..2 {
                ata[(i, j)] += u[i] * u[j];
            }
        }
    }
    // The pseudo-inverse solution: a direction the data leave flat gets 0 (and an
    // infinite sigma below).
    let top = ata.iter().fold(0.0f64, |t, v| t.max(v.abs()));
    let rhs = nalgebra::DVector::from_column_slice(&aty);
    let p = match ata.clone().svd(true, true).solve(&rhs, 1e-12 * top) {
        Ok(p) => [p[0], p[1]],
        Err(_) => [0.0, 0.0],
    };
    let sse: f64 = rows
        .iter()
        .zip(y)
        .map(|(r, yk)| {
            let e = yk - p[0] * r[0] / sc[0] - p[1] * r[1] / sc[1];
            e * e
        })
        .sum();
    let s2 = sse / (rows.len() - 2) as f64;
    let sig = super::covariance_sigmas(&ata, s2, 1e-12);
    Mechanics {
        j: judged_linear(p[0] / sc[0], sig[0] / sc[0]),
        b_total: judged_linear(p[1] / sc[1], sig[1] / sc[1]),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_linear_fit_recovers_j_and_b_and_says_when_j_is_not_excited() {
        // omega ramps: J = 0.02, B = 0.01, exact data.
        let rows: Vec<[f64; 2]> = (0..20)
            .map(|k| [1.0 + 0.1 * k as f64, 2.0 + (k % 3) as f64])
            .collect();
        let y: Vec<f64> = rows.iter().map(|r| 0.02 * r[0] + 0.01 * r[1]).collect();
        let m = linear_fit(&rows, &y);
        let (j, ..) = m.j.expect("J");
        let (b, ..) = m.b_total.expect("B");
        assert!((j / 0.02 - 1.0).abs() < 1e-9 && (b / 0.01 - 1.0).abs() < 1e-9);
        // Constant speed: no change of speed in any window, J flat.
        let rows: Vec<[f64; 2]> = (0..20).map(|k| [0.0, 3.0 + 1e-3 * k as f64]).collect();
        let y: Vec<f64> = rows
            .iter()
            .map(|r| 0.01 * r[1] + 1e-6 * (r[1] * 7.0).sin())
            .collect();
        let m = linear_fit(&rows, &y);
        assert!(m.j.is_err(), "{:?}", m.j);
        assert!(m.b_total.is_ok(), "{:?}", m.b_total);
    }
}
