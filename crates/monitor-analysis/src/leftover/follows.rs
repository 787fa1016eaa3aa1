//! What the leftover follows: the correlation of the error's envelope with the speed, the
//! load current and the voltage, and the error's projection on the shaft angle.

use super::series::ErrorSeries;
use super::{Equation, FOLLOWS_MIN, VARIES_MIN};
use crate::prep::Prepared;
use crate::simplified_model::MachineConstants;
use crate::strata::StratumKind;
use serde::Serialize;

/// The envelope's bins [s]: five periods of a 50 Hz supply, long enough to average a
/// pulsation at the shaft frequency out of the bins' means.
pub const BIN_S: f64 = 0.1;
/// The fewest bins a correlation is computed on.
const MIN_BINS: usize = 8;
/// The multiples of the shaft angle the error is projected on (once and twice per
/// revolution: [`shaft_angle`] takes the second's sin and cos from the first's).
const ANGLE_MULTIPLES: [u32; 2] = [1, 2];

/// A variable the error's envelope is set against.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum OperatingVariable {
    /// The measured rotor speed.
    Speed,
    /// The load (active, torque-producing) current I_qs.
    Load,
    /// The supply voltage's amplitude |V_dq|.
    Voltage,
}

/// The error's envelope set against one variable (JSON `leftover.follows[]`).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Correlate {
    /// The variable.
    pub variable: OperatingVariable,
    /// Pearson's correlation of the envelope (the error's RMS per [`BIN_S`] bin, equations
    /// normalised and summed) with the variable's mean per bin, after the start; null where
    /// the log has too few bins or the variable does not vary.
    pub r: Option<f64>,
    /// The variable's span over the bins, as a share of its largest magnitude.
    pub span: f64,
    /// Whether it varies enough to be set against ([`VARIES_MIN`]).
    pub varies: bool,
    /// Whether the error follows it (`|r|` at least [`FOLLOWS_MIN`]).
    pub follows: bool,
    /// The bins.
    pub bins: usize,
}

impl Correlate {
    /// Whether the error follows the variable.
    pub fn follows(&self) -> bool {
        self.follows
    }
}

/// The error's projection on sin and cos of `per_revolution` times the shaft angle (JSON
/// `leftover.shaft_angle[]`).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ShaftAngle {
    /// Times per revolution (1: once).
    pub per_revolution: u32,
    /// The share (0..1) of the error (mean square, equations summed, after the start) that
    /// the projection holds.
    pub share: f64,
    /// The equation it is strongest in.
    pub equation: Equation,
    /// Its amplitude there [`unit`].
    pub amplitude: f64,
    /// The unit.
    pub unit: &'static str,
}

/// The samples after the start: runs of the other strata (supply steps included: a
/// saturation's error follows the voltage they move).
fn after_start(strata: &[(StratumKind, usize, usize)], len: usize) -> Vec<(usize, usize)> {
    let mut out: Vec<(usize, usize)> = Vec::new();
    for &(_, a, b) in strata.iter().filter(|s| s.0 != StratumKind::Start) {
        let (a, b) = (a.min(len), b.min(len));
        match out.last_mut() {
            Some(last) if last.1 == a => last.1 = b,
            _ if b > a => out.push((a, b)),
            _ => {}
        }
    }
    out
}

/// Pearson's correlation of `x` and `y` (`None` for a constant series).
fn pearson(x: &[f64], y: &[f64]) -> Option<f64> {
    let n = x.len().min(y.len()) as f64;
    if n < 2.0 {
        return None;
    }
    let (mx, my) = (x.iter().sum::<f64>() / n, y.iter().sum::<f64>() / n);
    let (mut sxy, mut sxx, mut syy) = (0.0, 0.0, 0.0);
    for (a, b) in x.iter().zip(y) {
        sxy += (a - mx) * (b - my);
        sxx += (a - mx).powi(2);
        syy += (b - my).powi(2);
    }
    (sxx > 0.0 && syy > 0.0).then(|| sxy / (sxx * syy).sqrt())
}

/// What the error on `d` (its series `es`, the log's `strata`) follows: the
/// envelope's correlates and its projection on the shaft angle (measured speed only).
pub(super) fn follows(
    d: &Prepared,
    n: &MachineConstants,
    es: &ErrorSeries,
    strata: &[(StratumKind, usize, usize)],
) -> (Vec<Correlate>, Vec<ShaftAngle>) {
    let runs = after_start(strata, es.len());
    (correlates(d, es, &runs), shaft_angle(d, n, es, &runs))
}

/// The envelope per bin beside the variables' means per bin, and their correlations.
fn correlates(d: &Prepared, es: &ErrorSeries, runs: &[(usize, usize)]) -> Vec<Correlate> {
    let m = ((BIN_S / d.dt_s.max(1e-9)).round() as usize).max(1);
    let speed = d.channels.speed && d.omega_r.len() >= es.len();
    let voltage = d.vq.len() >= es.len() && d.vd.len() >= es.len();
    let mut env = Vec::new();
    let mut vars: [Vec<f64>; 3] = Default::default();
    for &(a, b) in runs {
        let mut o = a;
        while o + m <= b {
            let mean = |f: &dyn Fn(usize) -> f64| (o..o + m).map(f).sum::<f64>() / m as f64;
            env.push(mean(&|k| es.energy_at(k)).sqrt());
            vars[0].push(if speed {
                mean(&|k| d.omega_r[k].abs())
            } else {
                0.0
            });
            vars[1].push(mean(&|k| d.iq[k]));
            vars[2].push(if voltage {
                mean(&|k| d.vq[k].hypot(d.vd[k]))
            } else {
                0.0
            });
            o += m;
        }
    }
    let present = [speed, true, voltage];
    [
        OperatingVariable::Speed,
        OperatingVariable::Load,
        OperatingVariable::Voltage,
    ]
    .into_iter()
    .zip(vars)
    .zip(present)
    .filter(|(_, here)| *here)
    .map(|((variable, x), _)| {
        let lo = x.iter().copied().fold(f64::INFINITY, f64::min);
        let hi = x.iter().copied().fold(f64::NEG_INFINITY, f64::max);
        let mag = x.iter().fold(0.0f64, |a, v| a.max(v.abs()));
        let span = if mag > 0.0 && hi >= lo {
            (hi - lo) / mag
        } else {
            0.0
        };
        let varies = span >= VARIES_MIN && x.len() >= MIN_BINS;
        let r = varies.then(|| pearson(&env, &x)).flatten();
        Correlate {
            variable,
            r,
            span,
            varies,
            follows: r.is_some_and(|r| r.abs() >= FOLLOWS_MIN),
            bins: x.len(),
        }
    })
    .collect()
}

/// Sums of one channel's normalised error `x` over the samples projected: of `x`, of `x^2`,
/// and of `x cos(m theta)`, `x sin(m theta)` for each multiple `m` of [`ANGLE_MULTIPLES`].
#[derive(Default, Clone, Copy)]
struct AngleSums {
    x: f64,
    xx: f64,
    xc: [f64; 2],
    xs: [f64; 2],
}

/// The sums [`shaft_angle`] projects with, over the samples of `runs`: per channel of `es`
/// ([`AngleSums`]), of cos and sin of m theta, and the samples counted; theta the shaft
/// angle integrated (trapezoid rule) from the measured speed (`np` pole pairs) from 0 at the
/// log's first sample, sin and cos of 2 theta from those of theta.
fn angle_sums(
    d: &Prepared,
    np: f64,
    es: &ErrorSeries,
    runs: &[(usize, usize)],
) -> (Vec<AngleSums>, AngleSums, usize) {
    let mut sums = vec![AngleSums::default(); es.channels.len()];
    let mut trig = AngleSums::default();
    let (mut theta, mut count) = (0.0, 0usize);
    let mut run = runs.iter().peekable();
    for k in 0..es.len() {
        if k > 0 {
            let dt = d.t_s[k] - d.t_s[k - 1];
            theta += 0.5 * (d.omega_r[k] + d.omega_r[k - 1]) / np * dt;
        }
        while run.peek().is_some_and(|r| r.1 <= k) {
            run.next();
        }
        if run.peek().is_none_or(|r| r.0 > k) {
            continue;
        }
        let (s1, c1) = theta.sin_cos();
        let (c, s) = ([c1, c1 * c1 - s1 * s1], [s1, 2.0 * s1 * c1]);
        for m in 0..2 {
            trig.xc[m] += c[m];
            trig.xs[m] += s[m];
        }
        for (ch, acc) in es.channels.iter().zip(sums.iter_mut()) {
            let x = ch.e(k) / ch.scale;
            acc.x += x;
            acc.xx += x * x;
            for m in 0..2 {
                acc.xc[m] += x * c[m];
                acc.xs[m] += x * s[m];
            }
        }
        count += 1;
    }
    (sums, trig, count)
}

/// The error's projection on sin and cos of k theta over `runs` ([`angle_sums`]: theta the
/// shaft angle from the measured speed), each channel's mean taken out; empty without a
/// speed.
fn shaft_angle(
    d: &Prepared,
    n: &MachineConstants,
    es: &ErrorSeries,
    runs: &[(usize, usize)],
) -> Vec<ShaftAngle> {
    if !d.channels.speed || d.omega_r.len() < es.len() || runs.is_empty() {
        return Vec::new();
    }
    let (sums, trig, count) = angle_sums(d, n.np.max(1.0), es, runs);
    let count = count.max(1) as f64;
    let total: f64 = sums.iter().map(|a| a.xx).sum::<f64>() / count;
    if total <= 0.0 {
        return Vec::new();
    }
    ANGLE_MULTIPLES
        .iter()
        .enumerate()
        .map(|(m, &per_revolution)| {
            // Each channel's amplitude [its unit] and the mean square it holds.
            let parts: Vec<(f64, f64)> = es
                .channels
                .iter()
                .zip(&sums)
                .map(|(ch, acc)| {
                    let mean = acc.x / count;
                    let a = 2.0 * (acc.xc[m] - mean * trig.xc[m]) / count;
                    let b = 2.0 * (acc.xs[m] - mean * trig.xs[m]) / count;
                    let amp = a.hypot(b);
                    (amp * ch.scale, 0.5 * amp * amp)
                })
                .collect();
            let ms: f64 = parts.iter().map(|p| p.1).sum();
            let (c, amp) = parts
                .iter()
                .enumerate()
                .max_by(|a, b| a.1 .1.total_cmp(&b.1 .1))
                .map_or((0, 0.0), |(c, p)| (c, p.0));
            let eq = es.channels[c].equation;
            ShaftAngle {
                per_revolution,
                share: ms / total,
                equation: eq,
                amplitude: amp,
                unit: eq.unit(),
            }
        })
        .collect()
}
