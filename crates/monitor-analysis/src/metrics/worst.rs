//! The windows where the model fails most: each window's error, operating condition and
//! the dominant frequency of its I_qs error ([`windows`]).

use super::{dominant_frequency, measured, predicted, Weights};
use crate::prep::Prepared;
use crate::simplified_model::Prediction;
use rayon::prelude::*;
use serde::Serialize;

/// A time span where the model fails most.
#[derive(Debug, Clone, Serialize)]
pub struct WorstWindow {
    /// Start [s].
    pub t_start_s: f64,
    /// End [s].
    pub t_end_s: f64,
    /// `normalized_rms_error` in this window (channels normalised by their whole-log RMS).
    pub normalized_rms_error: f64,
    /// Operating condition in the window.
    pub condition: Condition,
    /// Dominant frequency of the I_qs error here [Hz] (0 = a steady offset).
    pub dominant_error_hz: f64,
    /// That frequency in words ("2f ripple (100 Hz = 2 x supply)", "offset", ...).
    pub error_kind: String,
    /// The transient the window lies in (start, supply step, speed change), when `compare`
    /// found one ([`crate::transients`]); null in steady operation.
    pub transient: Option<crate::transients::Transient>,
}

/// Operating condition of a window (means over the window).
#[derive(Debug, Clone, Serialize)]
pub struct Condition {
    /// Mechanical speed [rpm] (null without speed).
    pub speed_rpm: Option<f64>,
    /// Load (torque-producing) current I_qs [A].
    pub load_current_a: f64,
    /// Positive-sequence voltage amplitude [V peak, phase].
    pub voltage_v: f64,
    /// Voltage as a percentage of the parameter file's rated value.
    pub voltage_percent: f64,
    /// Supply (frame) frequency [Hz].
    pub supply_hz: f64,
    /// Time since the log's first row [s] (the motor start for a log that starts with it).
    pub time_since_start_s: f64,
}

/// Names an error frequency relative to the supply frequency.
pub fn error_kind(f: f64, fs: f64) -> String {
    if f < 1e-9 {
        return "steady offset".into();
    }
    if f < 5.0 {
        return format!("slow drift ({f:.1} Hz)");
    }
    for (m, name) in [(1.0, "1f"), (2.0, "2f ripple"), (6.0, "6f")] {
        if fs > 1.0 && (f - m * fs).abs() < 0.12 * fs {
            return format!("{name} ({f:.0} Hz = {m:.0} x supply {fs:.0} Hz)");
        }
    }
    format!("{f:.0} Hz")
}

/// Per-window errors: window start/end [s], window error, condition, plus the error
/// signal of I_qs; and the `count` worst windows (non-adjacent).
pub fn windows(
    d: &Prepared,
    p: &Prediction,
    w: &Weights,
    v_rated: f64,
    np: f64,
    n_windows: usize,
    count: usize,
) -> (Vec<WorstWindow>, Vec<WorstWindow>) {
    let len = d.len().min(p.iq.len());
    let nw = n_windows.clamp(1, len.max(1));
    let on = RatedMachine { v_rated, np };
    // Windows are independent (each with its own spectrum): computed in parallel, in order.
    let all: Vec<WorstWindow> = (0..nw)
        .into_par_iter()
        .map(|wi| {
            let a = wi * len / nw;
            let b = ((wi + 1) * len / nw).max(a + 1).min(len);
            WindowSums::over(d, p, a, b).window(d, w, a, b, on)
        })
        .collect();
    let worst = worst_apart(&all, count);
    (worst, all)
}

/// The rated voltage [V peak, phase] and pole pairs a window's condition is given with.
#[derive(Debug, Clone, Copy)]
struct RatedMachine {
    v_rated: f64,
    np: f64,
}

/// Sums over a window's samples: squared errors per channel, the measured speed, load
/// current, voltage and supply frequency, and the I_qs error signal.
struct WindowSums {
    se: [f64; 5],
    speed: f64,
    iq: f64,
    voltage: f64,
    omega_s: f64,
    err_iq: Vec<f64>,
}

impl WindowSums {
    /// The sums over samples `a..b`.
    fn over(d: &Prepared, p: &Prediction, a: usize, b: usize) -> Self {
        let mut s = WindowSums {
            se: [0.0; 5],
            speed: 0.0,
            iq: 0.0,
            voltage: 0.0,
            omega_s: 0.0,
            err_iq: Vec::with_capacity(b - a),
        };
        for k in a..b {
            let m = measured(d, k);
            let q = predicted(d, p, k);
            for c in 0..5 {
                s.se[c] += (q[c] - m[c]).powi(2);
            }
            s.err_iq.push(q[0] - m[0]);
            s.speed += d.omega_r.get(k).copied().unwrap_or(0.0);
            s.iq += d.iq[k];
            if !d.vq.is_empty() {
                s.voltage += d.vq[k].hypot(d.vd[k]);
            }
            s.omega_s += d.omega_s[k];
        }
        s
    }

    /// The window `a..b` these sums are of: its error (channels normalised by `w`), its
    /// operating condition and the dominant frequency of its I_qs error.
    fn window(
        &self,
        d: &Prepared,
        w: &Weights,
        a: usize,
        b: usize,
        on: RatedMachine,
    ) -> WorstWindow {
        let n = (b - a) as f64;
        let mut e = 0.0;
        for c in 0..5 {
            e += (self.se[c] / n).sqrt() * w.inv_rms[c];
        }
        let fsup = self.omega_s / n / (2.0 * std::f64::consts::PI);
        let f = dominant_frequency(&self.err_iq, d.dt_s);
        WorstWindow {
            t_start_s: d.t_s[a],
            t_end_s: d.t_s[b - 1],
            normalized_rms_error: e / w.n_channels().max(1) as f64,
            condition: Condition {
                speed_rpm: if d.channels.speed {
                    Some(self.speed / n / on.np * 60.0 / (2.0 * std::f64::consts::PI))
                } else {
                    None
                },
                load_current_a: self.iq / n,
                voltage_v: self.voltage / n,
                voltage_percent: 100.0 * (self.voltage / n) / on.v_rated.max(1e-9),
                supply_hz: fsup,
                time_since_start_s: d.t_s[a] - d.log_start_s,
            },
            dominant_error_hz: f,
            error_kind: error_kind(f, fsup.abs()),
            transient: None,
        }
    }
}

/// The `count` worst windows of `all`, worst first, no two adjacent.
fn worst_apart(all: &[WorstWindow], count: usize) -> Vec<WorstWindow> {
    let mut idx: Vec<usize> = (0..all.len()).collect();
    idx.sort_by(|&a, &b| {
        all[b]
            .normalized_rms_error
            .total_cmp(&all[a].normalized_rms_error)
    });
    let mut picked: Vec<usize> = Vec::new();
    for i in idx {
        if picked.len() >= count {
            break;
        }
        if picked.iter().all(|&j| (j as isize - i as isize).abs() > 1) {
            picked.push(i);
        }
    }
    picked.iter().map(|&i| all[i].clone()).collect()
}
