//! The negative-sequence (unbalance / faulty-phase) analysis of `compare` and `explain`.
//! It needs only the currents, so it runs on current-only logs too.
//!
//! The current and voltage unbalance are the RMS negative- over positive-sequence parts of
//! the working series (the first 10 % left out as start-up). The phase is named by the
//! workspace's one faulty-phase method (`monitor_core::sequence::winding_asymmetry`, as
//! `diagnose` names it): the fitted `i_neg = c conj(i_pos)` and `v_neg = cv conj(i_pos)`
//! give `I2/I1 = conj(c)` and `V2/I1 = conj(cv)`; the part `V2/Z2` that the supply's own
//! unbalance drives is taken out, and the angle of what is left, minus `arg Z1` at the
//! log's operating slip, points at the winding. Below what the supply's part explains, or
//! below a healthy machine's own asymmetry ([`NAMED_WINDING_MIN`], 3 %: there is no healthy
//! reference here), no winding is suspect. The slip is
//! the measured one (`1 - omega_r/omega_s`), or, without a speed column, the one at which
//! the equivalent circuit draws the measured current (`monitor_core::sequence::slip_for_current`).

use super::prep::{Prepared, C64};
use super::simplified_model::MachineConstants;
use serde::Serialize;

/// Unbalance / faulty-phase analysis (JSON key `unbalance` of `compare` and `explain`, with
/// the sentences `summary` and `cannot_judge_because` spelled at the door beside the typed
/// `finding`).
#[derive(Debug, Clone, Serialize)]
pub struct UnbalanceAnalysis {
    /// RMS negative-sequence current / RMS positive-sequence current.
    pub negative_sequence_ratio: f64,
    /// Same for the voltages (null without voltage columns).
    pub voltage_negative_sequence_ratio: Option<f64>,
    /// Phase whose winding most likely differs ("a"/"b"/"c"), null when the winding's part
    /// is within a healthy machine's own asymmetry ([`NAMED_WINDING_MIN`]) or when the
    /// voltage unbalance explains the current unbalance.
    pub suspect_phase: Option<String>,
    /// RMS phase currents [A] a, b, c.
    pub phase_rms_a: [f64; 3],
    /// What the analysis found, with its numbers.
    pub finding: UnbalanceFinding,
}

/// What the unbalance analysis found on a log, with the numbers its sentence names.
#[derive(Debug, Clone, PartialEq, Serialize)]
#[serde(tag = "kind", rename_all = "snake_case")]
pub enum UnbalanceFinding {
    /// The log cannot carry an unbalance claim although the numbers exist.
    CannotJudge {
        /// Negative over positive sequence current.
        ratio: f64,
        /// Why not.
        why: CannotJudgeUnbalance,
    },
    /// A phase's winding differs.
    Winding {
        /// Negative over positive sequence current.
        ratio: f64,
        /// Whether the log has voltages (without them the supply is assumed balanced).
        voltages: bool,
        /// The phase.
        phase: monitor_core::Phase,
        /// The least fraction of its turns shorted (a bolted short).
        shorted_fraction: f64,
        /// Its RMS current against the phases' mean, as a fraction of the mean (signed).
        deviation: f64,
    },
    /// The supply's voltage unbalance accounts for the current's; no winding suspected.
    Supply {
        /// Negative over positive sequence current.
        ratio: f64,
        /// Negative over positive sequence voltage.
        voltage_ratio: f64,
    },
    /// A log with voltages: the winding's part is within a healthy machine's own
    /// asymmetry (`healthy`), so no winding is named.
    WithinHealthy {
        /// Negative over positive sequence current.
        ratio: f64,
        /// The winding's part (the supply's taken out).
        winding_ratio: f64,
        /// A healthy machine's own asymmetry ([`NAMED_WINDING_MIN`]).
        healthy: f64,
    },
    /// A current-only log: below a healthy machine's own asymmetry (`healthy`) a winding
    /// cannot be told from the supply's unbalance or the machine's build.
    CurrentOnly {
        /// Negative over positive sequence current.
        ratio: f64,
        /// A healthy machine's own asymmetry
        /// ([`monitor_core::sequence::INHERENT_ASYMMETRY_RATIO`]).
        healthy: f64,
    },
    /// The currents are balanced (negative sequence under 1 %).
    Balanced {
        /// Negative over positive sequence current.
        ratio: f64,
    },
}

impl UnbalanceFinding {
    /// Why no phase or unbalance is claimed although the numbers exist (`None`: judged).
    pub fn cannot_judge(&self) -> Option<&CannotJudgeUnbalance> {
        match self {
            UnbalanceFinding::CannotJudge { why, .. } => Some(why),
            _ => None,
        }
    }
}

/// Why a log cannot carry an unbalance claim.
#[derive(Debug, Clone, PartialEq, Serialize)]
#[serde(tag = "kind", rename_all = "snake_case")]
pub enum CannotJudgeUnbalance {
    /// Fewer than `needed` supply periods analysed.
    FewPeriods {
        /// Supply periods analysed.
        periods: f64,
        /// Supply periods needed ([`MIN_STEADY_PERIODS`]).
        needed: f64,
    },
    /// The positive-sequence current varies by `variation` (RMS over its mean), more than
    /// `max` ([`MAX_CURRENT_VARIATION`]): a start or a load change.
    CurrentVaries {
        /// RMS variation over the mean.
        variation: f64,
        /// The most allowed.
        max: f64,
    },
    /// The current's mean `mean_a` [A] is within `factor` x its noise `noise_a` [A].
    InNoise {
        /// Mean positive-sequence current [A].
        mean_a: f64,
        /// The currents' white noise [A].
        noise_a: f64,
        /// The factor ([`MIN_SIGNAL_OVER_NOISE`]).
        factor: f64,
    },
}

/// Supply periods the analysis needs (after the first 10 % of the series) to claim an
/// unbalance or a phase: a negative sequence of a few % needs many periods to stand
/// clear of the noise and of a transient's decaying terms.
pub const MIN_STEADY_PERIODS: f64 = 25.0;
/// Largest RMS variation of the positive-sequence current magnitude, as a fraction of its
/// mean, over the analysed part: beyond it the series is a transient (a start, a load
/// step), whose decaying terms look like a negative sequence.
pub const MAX_CURRENT_VARIATION: f64 = 0.3;
/// Smallest mean positive-sequence current, as a fraction of the RMS of the currents'
/// white noise ([`super::metrics::white_noise_sigma`]) x 10: below it the phases' ratio is
/// noise over noise.
pub const MIN_SIGNAL_OVER_NOISE: f64 = 10.0;

/// Sums over the analysed part of the series.
#[derive(Default)]
struct SequenceSums {
    /// Sums of |i_neg|^2, |i_pos|^2, i_neg i_pos, |v_neg|^2, |v_pos|^2.
    i_neg2: f64,
    i_pos2: f64,
    cross: C64,
    /// Sum of v_neg i_pos (the voltages' negative sequence against the currents' positive).
    cross_v: C64,
    v_neg2: f64,
    v_pos2: f64,
    /// Sums of the squared phase currents.
    phase2: [f64; 3],
    /// Sums of omega_s, omega_r and |i_pos|.
    omega_s: f64,
    omega_r: f64,
    i_pos: f64,
    count: f64,
}

impl SequenceSums {
    /// Sums from sample `from` on (the analyses skip the first 10 %, the start-up).
    fn new(d: &Prepared, from: usize) -> Self {
        let mut s = SequenceSums::default();
        for k in from..d.len() {
            let ineg = d.i_neg[k];
            let ipos = d.i_ab[k] - ineg;
            s.i_neg2 += ineg.norm_sqr();
            s.i_pos2 += ipos.norm_sqr();
            // LS for i_neg = c conj(i_pos): c = sum(i_neg i_pos)/sum|i_pos|^2.
            s.cross += ineg * ipos;
            s.i_pos += ipos.norm();
            let abc = super::prep::phase_values(d.i_ab[k], d.i0[k]);
            for c in 0..3 {
                s.phase2[c] += abc[c] * abc[c];
            }
            if d.channels.voltages {
                s.v_neg2 += d.v_neg[k].norm_sqr();
                s.cross_v += d.v_neg[k] * ipos;
                s.v_pos2 += d.vq[k] * d.vq[k] + d.vd[k] * d.vd[k];
            }
            s.omega_s += d.omega_s[k];
            s.omega_r += d.omega_r.get(k).copied().unwrap_or(0.0);
        }
        s.count = (d.len() - from).max(1) as f64;
        s
    }
}

/// The analysis of a working series with the machine's constants.
pub fn analyse(d: &Prepared, n: &MachineConstants) -> UnbalanceAnalysis {
    let s = SequenceSums::new(d, d.len() / 10);
    let ratio = (s.i_neg2 / s.i_pos2.max(1e-12)).sqrt();
    let vratio = d
        .channels
        .voltages
        .then(|| (s.v_neg2 / s.v_pos2.max(1e-12)).sqrt());
    let w = s.omega_s / s.count;
    let phase_rms_a = s.phase2.map(|p| (p / s.count).sqrt());
    let (asym, eps) = winding_of(d, n, &s, w);
    let cannot_judge = cannot_judge(d, &s, w);
    let suspect = asym.suspect_phase.filter(|_| cannot_judge.is_none());
    let finding = match cannot_judge {
        Some(why) => UnbalanceFinding::CannotJudge { ratio, why },
        None => Found {
            ratio,
            vratio,
            supply_explains: suspect.is_none() && f64::from(asym.supply_ratio) > 0.5 * ratio,
            winding_ratio: f64::from(asym.ratio),
            shorted_fraction: eps,
            phase_rms_a,
        }
        .finding(d, suspect),
    };
    UnbalanceAnalysis {
        negative_sequence_ratio: ratio,
        voltage_negative_sequence_ratio: vratio,
        suspect_phase: suspect.map(|p| p.name().to_string()),
        phase_rms_a,
        finding,
    }
}

/// The least winding part of the negative sequence, `|I2w/I1|`, that names a phase here: a
/// healthy machine's own asymmetry ([`monitor_core::sequence::INHERENT_ASYMMETRY_RATIO`],
/// 3 %), with or without voltages. This analysis has no healthy reference; the part below
/// it is the machine's build (winding and core tolerances), which a healthy motor carries
/// too, so the phase it points at is no fault. It is the least change `diagnose`'s winding
/// judgement asks of a log with voltages and without a baseline (`replay::winding`: twice
/// its spread, half this ratio); a current-only log cannot take the supply's part out, and
/// `diagnose` asks twice as much there, with its stretches and confidence.
pub const NAMED_WINDING_MIN: f64 = monitor_core::sequence::INHERENT_ASYMMETRY_RATIO as f64;

/// The winding asymmetry of the sums `s` by the core's one faulty-phase method (in its
/// convention I2/I1 = conj(c), V2/I1 = conj(cv)) at the mean supply frequency `w`
/// [rad/s] and the operating slip, and the least fraction of the suspect phase's turns
/// shorted (a bolted short).
fn winding_of(
    d: &Prepared,
    n: &MachineConstants,
    s: &SequenceSums,
    w: f64,
) -> (monitor_core::sequence::WindingAsymmetry, f64) {
    winding_part(d, n, s, w, s.cross / s.i_pos2.max(1e-12))
}

/// [`winding_of`] for a given `c` (`i_neg = c conj(i_pos)`, e.g. the fitted
/// `phase_asymmetry`): the supply's part (the log's `V2`, where voltages are logged) taken
/// out, named from [`NAMED_WINDING_MIN`] on.
fn winding_part(
    d: &Prepared,
    n: &MachineConstants,
    s: &SequenceSums,
    w: f64,
    c: C64,
) -> (monitor_core::sequence::WindingAsymmetry, f64) {
    let cv = s.cross_v / s.i_pos2.max(1e-12);
    let slip = operating_slip(d, n, s);
    let (we, sl) = (w.abs().max(1.0) as f32, slip as f32);
    let asym = monitor_core::sequence::winding_asymmetry(
        monitor_core::sequence::Complex32::new(c.re as f32, -c.im as f32),
        d.channels
            .voltages
            .then_some(monitor_core::sequence::Complex32::new(
                cv.re as f32,
                -cv.im as f32,
            )),
        &n.core_model,
        we,
        sl,
        NAMED_WINDING_MIN as f32,
    );
    let eps = f64::from(monitor_core::sequence::min_shorted_fraction(
        &n.core_model,
        we,
        sl,
        asym.ratio,
    ));
    (asym, eps)
}

/// What the unbalance analysis found on a series it can judge.
struct Found {
    /// Negative over positive sequence current.
    ratio: f64,
    /// Negative over positive sequence voltage (`None`: no voltages).
    vratio: Option<f64>,
    /// No phase named, and the supply's unbalance accounts for the current's.
    supply_explains: bool,
    /// The winding's part `|I2w/I1|` (the supply's part taken out where voltages are
    /// logged).
    winding_ratio: f64,
    /// The least fraction of the suspect phase's turns shorted.
    shorted_fraction: f64,
    /// Per-phase RMS currents [A].
    phase_rms_a: [f64; 3],
}

impl Found {
    /// What was found, `suspect` the phase named.
    fn finding(&self, d: &Prepared, suspect: Option<monitor_core::Phase>) -> UnbalanceFinding {
        let ratio = self.ratio;
        match (suspect, self.supply_explains) {
            (Some(phase), _) => {
                let mean_rms = self.phase_rms_a.iter().sum::<f64>() / 3.0;
                let dev = self.phase_rms_a[phase.index()] - mean_rms;
                UnbalanceFinding::Winding {
                    ratio,
                    voltages: d.channels.voltages,
                    phase,
                    shorted_fraction: self.shorted_fraction,
                    deviation: dev / mean_rms.max(1e-12),
                }
            }
            (None, true) => UnbalanceFinding::Supply {
                ratio,
                voltage_ratio: self.vratio.unwrap_or(0.0),
            },
            (None, false) if d.channels.voltages && ratio >= 0.01 => {
                UnbalanceFinding::WithinHealthy {
                    ratio,
                    winding_ratio: self.winding_ratio,
                    healthy: NAMED_WINDING_MIN,
                }
            }
            (None, false) if !d.channels.voltages && ratio >= 0.01 => {
                UnbalanceFinding::CurrentOnly {
                    ratio,
                    healthy: f64::from(monitor_core::sequence::INHERENT_ASYMMETRY_RATIO),
                }
            }
            (None, false) => UnbalanceFinding::Balanced { ratio },
        }
    }
}

/// Why the series cannot carry an unbalance claim (see
/// [`UnbalanceFinding::CannotJudge`]); `None` when it can.
fn cannot_judge(d: &Prepared, s: &SequenceSums, omega_s: f64) -> Option<CannotJudgeUnbalance> {
    let periods = s.count * d.dt_s * omega_s.abs() / std::f64::consts::TAU;
    if periods.is_nan() || periods < MIN_STEADY_PERIODS {
        return Some(CannotJudgeUnbalance::FewPeriods {
            periods,
            needed: MIN_STEADY_PERIODS,
        });
    }
    let mean = s.i_pos / s.count;
    let var = (s.i_pos2 / s.count - mean * mean).max(0.0);
    if mean.is_nan() || var.sqrt() > MAX_CURRENT_VARIATION * mean {
        return Some(CannotJudgeUnbalance::CurrentVaries {
            variation: var.sqrt() / mean.max(1e-12),
            max: MAX_CURRENT_VARIATION,
        });
    }
    let from = d.len() / 10;
    let re: Vec<f64> = d.i_ab[from..].iter().map(|z| z.re).collect();
    let noise = super::metrics::white_noise_sigma(&re);
    if noise.is_nan() || mean <= MIN_SIGNAL_OVER_NOISE * noise {
        return Some(CannotJudgeUnbalance::InNoise {
            mean_a: mean,
            noise_a: noise,
            factor: MIN_SIGNAL_OVER_NOISE,
        });
    }
    None
}

/// The winding a negative-sequence current `i_neg = c conj(i_pos)` on the log `d` names:
/// the phase and the least fraction of its turns shorted (a bolted short), by the same
/// rule as the unbalance analysis (the supply's part taken out where voltages are logged;
/// nothing below [`NAMED_WINDING_MIN`]). `None` when it names none; then
/// [`WindingPart::ratio`] says how large the winding part is.
pub fn winding_named_by(d: &Prepared, n: &MachineConstants, c: C64) -> WindingPart {
    let s = SequenceSums::new(d, d.len() / 10);
    let (asym, eps) = winding_part(d, n, &s, s.omega_s / s.count, c);
    WindingPart {
        ratio: f64::from(asym.ratio),
        named: asym.suspect_phase.map(|p| (p, eps)),
    }
}

/// What [`winding_named_by`] found.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct WindingPart {
    /// The winding's part of the negative sequence, `|I2w/I1|` (the supply's part taken
    /// out where voltages are logged).
    pub ratio: f64,
    /// The phase named and the least fraction of its turns shorted; `None` below
    /// [`NAMED_WINDING_MIN`].
    pub named: Option<(monitor_core::Phase, f64)>,
}

/// The log's mean supply angular frequency [rad/s] and slip over its last 90 % (module
/// docs), for naming the phase of a winding asymmetry.
pub fn operating_point(d: &Prepared, n: &MachineConstants) -> (f64, f64) {
    let s = SequenceSums::new(d, d.len() / 10);
    (s.omega_s / s.count, operating_slip(d, n, &s))
}

/// The mean slip of the analysed part: measured, or from the current magnitude when the
/// log has no speed (module docs).
fn operating_slip(d: &Prepared, n: &MachineConstants, s: &SequenceSums) -> f64 {
    let w = s.omega_s / s.count;
    if w.abs() <= 1.0 {
        return 0.0;
    }
    if d.channels.speed {
        return 1.0 - (s.omega_r / s.count) / w;
    }
    let v_pk = if d.channels.voltages {
        (s.v_pos2 / s.count).sqrt()
    } else {
        n.v_phase_peak
    };
    f64::from(monitor_core::sequence::slip_for_current(
        &n.core_model,
        v_pk as f32,
        w.abs() as f32,
        (s.i_pos / s.count) as f32,
    ))
}
