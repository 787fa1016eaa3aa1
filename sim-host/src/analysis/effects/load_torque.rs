//! `load_torque`: the load as a torque input.

use super::{
    plausible, About, Confusion, Contribution, EffectModel, Evidence, FitParam, FitSetup, Needs,
    ParamSpec, SetupError, LOAD_STEP_MIN,
};
use crate::analysis::prep::Prepared;
use crate::analysis::simplified_model::{MachineConstants, ModelTerms};
use monitor_core::EffectKind;

/// Load as a torque input.
#[derive(Debug, Clone, Copy)]
pub struct LoadTorque;

/// A constant level of the torque observer: from `from_s` [s] on, `level_nm` [N m].
#[derive(Debug, Clone, Copy, PartialEq)]
struct Segment {
    from_s: f64,
    level_nm: f64,
}

/// The torque observer's series: Te(measured I_qs, i_f) - J dw_m/dt, low-passed at 10 Hz
/// (two first-order passes), less the best viscous line c1 w_m through the origin (the
/// paper's Bl omega; what is left is load torque the viscous model cannot describe), as
/// a cumulative sum (length len + 1) for the segments' means.
fn observer_cumsum(d: &Prepared, n: &MachineConstants) -> Vec<f64> {
    let len = d.len();
    let dt = d.dt_s;
    let lmr = n.lm_h * n.lm_h / n.lr_h;
    let mut obs = Vec::with_capacity(len);
    let a = 1.0 - (-2.0 * std::f64::consts::PI * 10.0 * dt).exp();
    let (mut s1, mut s2) = (0.0, 0.0);
    // (Few series of the log's length: this also runs on the full working series of a long
    // log, so w_m is recomputed where needed rather than stored.)
    let w_at = |k: usize| d.omega_r[k] / n.np;
    let mut wprev = w_at(0);
    for k in 0..len {
        let wm = w_at(k);
        let te = 1.5 * n.np * lmr * d.i_f[k] * d.iq_pos[k];
        let acc = (wm - wprev) / dt;
        wprev = wm;
        let x = te - n.j_kgm2 * acc;
        if k == 0 {
            s1 = x;
            s2 = x;
        }
        s1 += a * (x - s1);
        s2 += a * (s1 - s2);
        obs.push(s2);
    }
    let (sww, swx) = obs.iter().enumerate().fold((0.0, 0.0), |acc, (k, x)| {
        let w = w_at(k);
        (acc.0 + w * w, acc.1 + w * x)
    });
    let c1 = if sww > 0.0 { swx / sww } else { 0.0 };
    let mut cum = vec![0.0; len + 1];
    for k in 0..len {
        cum[k + 1] = cum[k] + (obs[k] - c1 * w_at(k));
    }
    cum
}

/// Whether the supply holds still around each split candidate: a load step is a torque
/// change while the supply holds still, so splits where the supply frequency or voltage
/// moves by more than 1 % within +/- `half` samples are refused (speed sweeps change the
/// friction torque, not the load).
struct SupplySteady {
    /// Cumulative sums of omega_s and |V| (length len + 1).
    cw: Vec<f64>,
    cv: Vec<f64>,
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
            cv: cum_of(&|k| d.vq[k].hypot(d.vd[k])),
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
        let (v1, v2) = (m(&self.cv, a, kk), m(&self.cv, kk, b));
        (w1 - w2).abs() <= 0.01 * w1.abs().max(w2.abs()).max(1e-9)
            && (v1 - v2).abs() <= 0.01 * v1.abs().max(v2.abs()).max(1e-9)
    }
}

/// Torque observer ([`observer_cumsum`]) segmented into constant levels by binary
/// segmentation (at most 6 splits; minimum segment 0.1 s or 10 % of the log; a split must
/// move the level by more than 3 % of the rated torque estimate, and the supply must hold
/// still around it, [`SupplySteady`]). Returns the segments in time order (empty without
/// a speed column or on fewer than 20 samples).
fn load_steps(d: &Prepared, n: &MachineConstants) -> Vec<Segment> {
    let len = d.len();
    if d.omega_r.len() != len || len < 20 {
        return vec![];
    }
    let cum = observer_cumsum(d, n);
    let mean = |a: usize, b: usize| (cum[b] - cum[a]) / (b - a) as f64;
    let min_len = ((0.1 / d.dt_s) as usize).max(len / 10).max(2);
    let thresh = 0.03 * n.torque_scale_nm;
    let steady = SupplySteady::new(d, (min_len / 2).max(1));
    let mut segs = vec![(0usize, len)];
    for _ in 0..6 {
        let mut best: Option<(usize, usize, f64)> = None;
        for (si, &(a0, b0)) in segs.iter().enumerate() {
            if b0 - a0 < 2 * min_len {
                continue;
            }
            let step = ((b0 - a0) / 400).max(1);
            let mut kk = a0 + min_len;
            while kk <= b0 - min_len {
                let ml = mean(a0, kk);
                let mr = mean(kk, b0);
                let gain = (ml - mr).powi(2) * ((kk - a0) * (b0 - kk)) as f64 / (b0 - a0) as f64;
                if (ml - mr).abs() > thresh
                    && best.map(|b| gain > b.2).unwrap_or(true)
                    && steady.at(kk)
                {
                    best = Some((si, kk, gain));
                }
                kk += step;
            }
        }
        let Some((si, kk, _)) = best else { break };
        let (a0, b0) = segs[si];
        segs[si] = (a0, kk);
        segs.insert(si + 1, (kk, b0));
    }
    segs.iter()
        .map(|&(a0, b0)| Segment {
            from_s: d.t_s[a0],
            level_nm: mean(a0, b0),
        })
        .collect()
}

/// Load torque set up on a log: the times the segments start [s].
struct Steps {
    from_s: Vec<f64>,
}

/// What `LoadTorque` is ([`About`]).
const ABOUT: About = About {
    kind: EffectKind::LoadTorque,
    description: "The load is a torque imposed by the driven machine (possibly switched in steps), not the paper's viscous Bl*omega.",
    equations: "J dw_m/dt = Kf I_qs - (B + Bl) w_m - T_L(t), T_L piecewise constant; the step times come from a torque observer on the measured speed and current, the levels are fitted.",
    parameters: &[ParamSpec {
        name: "level_k",
        unit: "N m",
        description: "load torque in segment k (one parameter per detected segment)",
    }],
};

impl EffectModel for LoadTorque {
    fn about(&self) -> &About {
        &ABOUT
    }
    fn confused_with(&self) -> &'static [Confusion] {
        // A constant load torque is dry friction's equation at positive speed.
        &[Confusion {
            with: EffectKind::CoulombFriction,
            within: 1.10,
        }]
    }
    fn evidence(&self, e: &Evidence<'_>) -> Option<bool> {
        let hi = e.fitted.iter().fold(f64::NEG_INFINITY, |a, &b| a.max(b));
        let lo = e.fitted.iter().fold(f64::INFINITY, |a, &b| a.min(b));
        Some(hi - lo >= LOAD_STEP_MIN * e.torque_scale_nm)
    }
    fn needs(&self) -> Needs {
        Needs::VOLTAGES_AND_SPEED
    }
    fn setup(&self, d: &Prepared, n: &MachineConstants) -> Result<FitSetup, SetupError> {
        if d.omega_r.is_empty() {
            return Err(SetupError::NoSpeed {
                because: "the torque observer uses the measured speed",
            });
        }
        let segments = load_steps(d, n);
        if segments.len() < 2 {
            return Err(SetupError::NothingToFit("no change of load torque found in the log: a constant load torque is the same equation as coulomb_friction at positive speed, so it is left to that effect"));
        }
        let t = n.torque_scale_nm;
        let r = plausible::LOAD_RATIO;
        let from_s = segments.iter().map(|s| s.from_s).collect();
        // Initial levels: the observer's mean torque beyond the viscous line per segment.
        Ok(segments
            .iter()
            .enumerate()
            .fold(FitSetup::new(Steps { from_s }), |s, (k, seg)| {
                s.param(
                    FitParam::new(
                        format!("level_{}_from_{:.2}_s", k + 1, seg.from_s),
                        "N m",
                        seg.level_nm.clamp(-3.0 * t, 3.0 * t),
                        (-3.0 * t, 3.0 * t),
                        0.2 * t,
                    )
                    .physical_scaled(r, t, plausible::LOAD_BASIS),
                )
            }))
    }
}

impl Contribution for Steps {
    /// The piecewise-constant load torque per sample.
    fn contribute(&self, p: &[f64], d: &Prepared, _n: &MachineConstants, t: &mut ModelTerms) {
        let from = &self.from_s;
        let mut seg = 0usize;
        t.add_load_torque(d.t_s.iter().map(|&t| {
            while seg + 1 < from.len() && t >= from[seg + 1] {
                seg += 1;
            }
            p.get(seg).copied().unwrap_or(0.0)
        }));
    }
    fn describe(&self, p: &[f64], _d: &Prepared, _n: &MachineConstants) -> String {
        let parts: Vec<String> = self
            .from_s
            .iter()
            .zip(p)
            .map(|(t, v)| format!("{v:.2} N m from {t:.2} s"))
            .collect();
        format!(
            "load behaves as a torque input (on top of the refitted viscous term): {}",
            parts.join(", ")
        )
    }
}
