//! `load_torque`: the load as a torque input.

use super::{
    plausible, About, ApartBy, Confusion, Contribution, EffectEvidence, EffectModel, EffectParam,
    EffectValuesError, FitSetup, Needs, SetupError, LOAD_STEP_MIN,
};
use crate::change_point::{Cumulative, Search};
use crate::prep::{Prepared, C64};
use crate::simplified_model::{MachineConstants, ModelTerms};
use monitor_laws::EffectId;

/// Load as a torque input.
#[derive(Debug, Clone, Copy)]
pub struct LoadTorque;

/// A constant level of the load torque the log's torque balance shows ([`load_segments`]):
/// from `from_s` on, `level_nm`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LoadSegment {
    /// Where the segment starts [s, log time]: the first segment at the first working
    /// sample, the others where their step lies, placed within its working sample.
    pub from_s: f64,
    /// The segment's mean of the torque balance's residual with the file's B + Bl [N m]
    /// (what `load_torque`'s fit starts its level from, with B + Bl at the file's value).
    pub level_nm: f64,
}

/// The torque balance per working interval `k..k+1` (length len - 1): the torque the
/// shaft's load takes, `T_L + (B + Bl) w_m` [N m], and the interval's mean speed `w_m`
/// [rad/s],
/// ```text
///   T_L + (B + Bl) w_m = Te - J dw_m/dt,   Te = (3/2) Np (Lm/Lr) Im(conj(psi_r) i_s),
/// ```
/// with the rotor flux of the current model (stationary frame, driven by the measured
/// current and speed, the file's Lm, Lr, Rr), `d psi_r/dt = (Lm/tau_r) i_s - (1/tau_r -
/// j omega_r) psi_r`, discretised exactly for the current held at its interval's mean;
/// dw_m/dt is the interval's difference quotient (its sum over a segment is the speed
/// change: the segments' means carry no differentiated noise). Unlike the torque of the
/// paper's constant-flux model (eq. 18, Te from i_f), the current model's holds in a
/// start and after a step, and nothing is low-passed: a step of the load is a step of
/// this series at its sample. (The paper: "Fault Diagnosis of Induction Motor Using D-Q
/// Simplified Model and Parity Equations", Energies 2022, 15(22), 8372.)
fn torque_balance(d: &Prepared, n: &MachineConstants) -> Vec<(f64, f64)> {
    let len = d.len().min(d.omega_r.len()).min(d.i_ab.len());
    let h = d.dt_s;
    let tau_r = n.lr_h / n.rr_ohm.max(1e-9);
    let kt = 1.5 * n.np * n.lm_h / n.lr_h;
    let mut out = Vec::with_capacity(len.saturating_sub(1));
    let (Some(&i0), Some(&wr0)) = (d.i_ab.first(), d.omega_r.first()) else {
        return out;
    };
    let slip0 = d.omega_s.first().copied().unwrap_or(0.0) - wr0;
    let mut psi = i0 * n.lm_h / C64::new(1.0, slip0 * tau_r);
    for k in 0..len.saturating_sub(1) {
        let i_mid = 0.5 * (d.i_ab[k] + d.i_ab[k + 1]);
        let wr = 0.5 * (d.omega_r[k] + d.omega_r[k + 1]);
        let a = C64::new(-1.0 / tau_r, wr);
        let e = (a * h).exp();
        let next = e * psi + (e - 1.0) / a * (n.lm_h / tau_r) * i_mid;
        let psi_mid = 0.5 * (psi + next);
        psi = next;
        let te = kt * (psi_mid.conj() * i_mid).im;
        let (w0, w1) = (d.omega_r[k] / n.np, d.omega_r[k + 1] / n.np);
        out.push((te - n.j_kgm2 * (w1 - w0) / h, 0.5 * (w0 + w1)));
    }
    out
}

/// Whether the supply frequency holds still around each split candidate: splits where it
/// moves by more than 1 % within +/- `half` samples are refused (a speed sweep changes the
/// friction torque, not the load). The supply voltage may move: the torque balance takes
/// the torque from the measured currents and speed ([`torque_balance`]), so a voltage
/// ramp or dip does not move `T_L`, and a load that steps during a variac sweep is found
/// where it stepped (refusing splits there put a textbook machine's load steps, both inside
/// voltage sweeps, at the sweeps' ends: 16x the noise floor left where 1.15x is reached).
struct SupplySteady {
    /// Cumulative sums of omega_s (length len + 1).
    cw: Vec<f64>,
    half: usize,
}

impl SupplySteady {
    fn new(d: &Prepared, half: usize) -> Self {
        let len = d.len();
        let cum_of = |x: &dyn Fn(usize) -> f64| {
            let mut c = vec![0.0; len + 1];
            for k in 0..len {
                c[k + 1] = c[k] + x(k);
            }
            c
        };
        SupplySteady {
            cw: cum_of(&|k| d.omega_s[k]),
            half,
        }
    }

    /// True when the supply holds still around sample `kk`.
    fn at(&self, kk: usize) -> bool {
        let len = self.cw.len() - 1;
        let a = kk.saturating_sub(self.half);
        let b = (kk + self.half).min(len);
        if kk <= a || b <= kk {
            return true;
        }
        let m = |c: &[f64], x: usize, y: usize| (c[y] - c[x]) / (y - x) as f64;
        let (w1, w2) = (m(&self.cw, a, kk), m(&self.cw, kk, b));
        (w1 - w2).abs() <= 0.01 * w1.abs().max(w2.abs()).max(1e-9)
    }
}

/// The viscous coefficient B + Bl [N m s/rad] the torque balance `y = T_L + B w` shows
/// within the segments `bounds` (the slope of y on w about each segment's means, pooled;
/// `fallback` where the speed hardly varies within the segments).
fn viscous_within(yw: &[(f64, f64)], bounds: &[usize], fallback: f64) -> f64 {
    let (mut sww, mut swy, mut sw2) = (0.0, 0.0, 0.0);
    for b in bounds.windows(2) {
        let seg = yw.get(b[0]..b[1]).unwrap_or(&[]);
        let m = seg.len().max(1) as f64;
        let (yb, wb) = seg
            .iter()
            .fold((0.0, 0.0), |a, (y, w)| (a.0 + y / m, a.1 + w / m));
        for (y, w) in seg {
            sww += (w - wb) * (w - wb);
            swy += (w - wb) * (y - yb);
            sw2 += w * w;
        }
    }
    // Less than 1 % of the speed's spread varies within the segments: not identified.
    if sww > 1e-4 * sw2 && sww > 0.0 {
        swy / sww
    } else {
        fallback
    }
}

/// The torque balance's residual `T_L` ([`torque_balance`], less a viscous line B w)
/// segmented into constant levels
/// ([`crate::change_point`]: least-squares binary segmentation, at most 6 splits,
/// each re-optimised between its neighbours; minimum segment 0.1 s or 10 % of the log; a
/// split must move the level by more than 3 % of the rated torque estimate, and the supply
/// must hold still around it, [`SupplySteady`]), each split placed within its sample. B is
/// the file's B + Bl first, then twice what the torque balance shows within the segments
/// found ([`viscous_within`]; a torque load replaces the paper's Bl, and a viscous line
/// left in the residual would read a start as a step). Returns the segments in time order: one segment is a log without a load step; empty
/// without a speed column or on fewer than 20 samples. The steps are what `load_torque`
/// fits levels for.
pub fn load_segments(d: &Prepared, n: &MachineConstants) -> Vec<LoadSegment> {
    let len = d.len();
    if d.omega_r.len() != len || len < 20 {
        return vec![];
    }
    let yw = torque_balance(d, n);
    let residual = |b: f64| Cumulative::new(yw.iter().map(|(y, w)| y - b * w));
    let search = Search {
        min_len: ((0.1 / d.dt_s) as usize).max(len / 10).max(2),
        min_shift: 0.03 * n.torque_scale_nm,
        max_splits: 6,
    };
    let steady = SupplySteady::new(d, (search.min_len / 2).max(1));
    let bounds_of = |c: &Cumulative| {
        let mut b = vec![0];
        b.extend(c.splits(&search, &|k| steady.at(k)));
        b.push(c.len());
        b
    };
    let mut c = residual(n.btot_nms);
    let mut bounds = bounds_of(&c);
    for _ in 0..2 {
        c = residual(viscous_within(&yw, &bounds, n.btot_nms));
        bounds = bounds_of(&c);
    }
    let file_b = residual(n.btot_nms);
    bounds
        .windows(2)
        .enumerate()
        .map(|(i, w)| {
            let within = match i {
                0 => 0.0,
                _ => c.within_sample(w[0], c.mean(bounds[i - 1], w[0]), c.mean(w[0], w[1])),
            };
            LoadSegment {
                from_s: d.t_s[w[0]] + within * d.dt_s,
                level_nm: file_b.mean(w[0], w[1]),
            }
        })
        .collect()
}

/// Load torque set up on a log: the times the segments start [s].
struct Steps {
    from_s: Vec<f64>,
}

/// The load torque's parameter: one level per segment the log's torque balance shows
/// ([`load_segments`]). The one parameter whose JSON key carries data: each segment's key
/// names it, `level_{k}_from_{T}_s` ([`level_key`]); the keys stay as they were.
const LEVEL: EffectParam = EffectParam {
    name: "level_k_from_T_s",
    unit: "N m",
    doc: "load torque in segment k, which starts at T s (one parameter per detected segment)",
    range: plausible::LOAD_RATIO,
    per: Some("the rated torque estimate"),
    basis: plausible::LOAD_BASIS,
};

/// The load torque's parameters: the per-segment level ([`LEVEL`]).
const PARAMS: [EffectParam; 1] = [LEVEL];

/// The JSON key of the level of segment `k` (from 1) that starts at `from_s` [s].
fn level_key(k: usize, from_s: f64) -> String {
    format!("level_{k}_from_{from_s:.2}_s")
}

/// The load torque's fitted values: one level per segment [N m], in time order.
#[derive(Debug, Clone, PartialEq)]
pub struct LoadLevels {
    /// The segments' levels [N m].
    pub levels_nm: Vec<f64>,
}

/// What `LoadTorque` is ([`About`]).
const ABOUT: About = About {
    kind: EffectId::LOAD_TORQUE,
    description: "The load is a torque imposed by the driven machine (possibly switched in steps), not the paper's viscous Bl*omega.",
    equations: "J dw_m/dt = Kf I_qs - (B + Bl) w_m - T_L(t), T_L piecewise constant; the step times come from change-point detection on the torque balance's residual (measured speed and current, current-model rotor flux), placed within their sample; the levels are fitted.",
    parameters: &PARAMS,
};

impl EffectModel for LoadTorque {
    fn about(&self) -> &About {
        &ABOUT
    }
    fn confused_with(&self) -> &'static [Confusion] {
        // A constant load torque is dry friction's equation at positive speed.
        &[Confusion {
            with: EffectId::COULOMB_FRICTION,
            within: 1.10,
            apart_by: ApartBy::Reversal,
        }]
    }
    fn evidence(&self, e: &EffectEvidence<'_>) -> Option<bool> {
        let hi = e.fitted.iter().fold(f64::NEG_INFINITY, |a, &b| a.max(b));
        let lo = e.fitted.iter().fold(f64::INFINITY, |a, &b| a.min(b));
        Some(hi - lo >= LOAD_STEP_MIN * e.torque_scale_nm)
    }
    fn needs(&self) -> Needs {
        Needs::VOLTAGES_AND_SPEED
    }
    /// One level: a torque of no speed (several levels are steps, no law of speed).
    fn load_torque_at(&self, values: &[f64], _w_rad_s: f64) -> Option<f64> {
        match values {
            [level] => Some(*level),
            _ => None,
        }
    }
    fn setup(&self, d: &Prepared, n: &MachineConstants) -> Result<FitSetup, SetupError> {
        if d.omega_r.is_empty() {
            return Err(SetupError::NoSpeed {
                because: "the torque observer uses the measured speed",
            });
        }
        let segments = load_segments(d, n);
        if segments.is_empty() {
            return Err(SetupError::NothingToFit(
                "the log is too short for a torque balance (fewer than 20 samples)",
            ));
        }
        let t = n.torque_scale_nm;
        let from_s = segments.iter().map(|s| s.from_s).collect();
        // Initial levels: the observer's mean torque beyond the viscous line per segment.
        let params = segments
            .iter()
            .enumerate()
            .map(|(k, seg)| {
                let init = seg.level_nm.clamp(-3.0 * t, 3.0 * t);
                LEVEL
                    .fit(init, (-3.0 * t, 3.0 * t), 0.2 * t, t)
                    .named(level_key(k + 1, seg.from_s))
            })
            .collect();
        Ok(FitSetup::new(Steps { from_s }, params)?)
    }
}

impl Contribution for Steps {
    type Values = LoadLevels;
    /// One level per segment.
    fn values(&self, v: &[f64]) -> Result<LoadLevels, EffectValuesError> {
        if v.len() != self.from_s.len() {
            return Err(EffectValuesError::Count {
                effect: EffectId::LOAD_TORQUE,
                expected: self.from_s.len(),
                got: v.len(),
            });
        }
        Ok(LoadLevels {
            levels_nm: v.to_vec(),
        })
    }
    /// The piecewise-constant load torque per working interval `k..k+1`: the mean over
    /// the interval, so a step inside an interval counts with the part of it after the
    /// step.
    fn contribute(&self, p: &LoadLevels, d: &Prepared, _n: &MachineConstants, t: &mut ModelTerms) {
        let from = &self.from_s;
        let level = |i: usize| p.levels_nm.get(i).copied().unwrap_or(0.0);
        let h = d.dt_s;
        let mut seg = 0usize;
        t.add_load_torque(d.t_s.iter().map(|&t| {
            while seg + 1 < from.len() && t >= from[seg + 1] {
                seg += 1;
            }
            match from.get(seg + 1) {
                Some(&next) if h > 0.0 && next < t + h => {
                    let after = (t + h - next) / h;
                    (1.0 - after) * level(seg) + after * level(seg + 1)
                }
                _ => level(seg),
            }
        }));
    }
    fn describe(&self, p: &LoadLevels, _d: &Prepared, _n: &MachineConstants) -> String {
        let parts: Vec<String> = self
            .from_s
            .iter()
            .zip(&p.levels_nm)
            .map(|(t, v)| format!("{v:.2} N m from {t:.4} s"))
            .collect();
        format!(
            "load behaves as a torque input (on top of the refitted viscous term): {}",
            parts.join(", ")
        )
    }
}
