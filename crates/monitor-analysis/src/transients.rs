//! Transients in a log: the direct-on-line start and the steps of the supply voltage,
//! the supply frequency or the speed, found from the measured signals. `compare` uses them
//! to say when its worst windows are a transient, which dynamics effects cover it, and
//! from where (`--from`) the log is past the start; `explain` and `compare` decide by one
//! rule ([`not_proposed`]) whether a dynamics effect is proposed on a log, so that
//! `compare`'s advice and `explain`'s `skipped` give the same reasons.

use super::effects::{library, EffectModel};
use super::metrics::WorstWindow;
use super::prep::Prepared;
use super::simplified_model::MachineConstants;
use monitor_laws::EffectId;
use serde::Serialize;

/// A relative change of the supply voltage amplitude or frequency larger than this within a
/// window (or the settling time before it) makes the window a step.
pub const STEP_MIN: f64 = 0.03;
/// A speed change larger than this fraction of the synchronous speed within a window makes
/// it a speed transient.
pub const SPEED_CHANGE_MIN: f64 = 0.03;

/// What kind of transient a window lies in (JSON `start`, `supply_step`, `speed_change`).
#[derive(Debug, Clone, Copy, Serialize, PartialEq, Eq)]
#[serde(rename_all = "snake_case")]
pub enum TransientKind {
    /// A direct-on-line start from standstill.
    Start,
    /// A voltage or frequency step of the supply.
    SupplyStep,
    /// The speed moves (after a load step, for example).
    SpeedChange,
}

impl TransientKind {
    /// The kind's name (as in the JSON).
    pub fn name(self) -> &'static str {
        match self {
            TransientKind::Start => "start",
            TransientKind::SupplyStep => "supply_step",
            TransientKind::SpeedChange => "speed_change",
        }
    }
}

impl std::fmt::Display for TransientKind {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

/// The transient a window lies in.
#[derive(Debug, Clone, Serialize, PartialEq)]
pub struct Transient {
    /// `start` (direct-on-line start from standstill), `supply_step` (voltage or frequency
    /// step) or `speed_change` (the speed moves, e.g. after a load step).
    pub kind: TransientKind,
    /// What was seen, in words.
    pub description: String,
}

/// The end of a start from standstill [s, log time]: the first time the speed reaches
/// 90 % of its median over the rest of the log (the current envelope falls to 1.5x its
/// median without a speed column); `None` when the log does not begin at standstill.
pub fn start_end_s(d: &Prepared) -> Option<f64> {
    let n = d.len();
    if n < 10 {
        return None;
    }
    let head = ((0.01 / d.dt_s).ceil() as usize).clamp(1, n);
    // The value a sort puts in the middle, by selection (no sort of a long log).
    let median = |x: &mut Vec<f64>| {
        let mid = x.len() / 2;
        if x.is_empty() {
            0.0
        } else {
            *x.select_nth_unstable_by(mid, f64::total_cmp).1
        }
    };
    if d.channels.speed && d.omega_r.len() == n {
        let w0 = d.omega_r[..head].iter().sum::<f64>() / head as f64;
        let mut rest: Vec<f64> = d.omega_r[n / 2..].iter().map(|w| w.abs()).collect();
        let wm = median(&mut rest);
        if wm <= 0.0 || w0.abs() > 0.1 * wm {
            return None;
        }
        let k = d.omega_r.iter().position(|w| w.abs() >= 0.9 * wm)?;
        return Some(d.t_s[k]);
    }
    let mag: Vec<f64> = d.i_ab.iter().map(|i| i.norm()).collect();
    let mut all = mag.clone();
    let im = median(&mut all);
    let first = mag.iter().take(head).sum::<f64>() / head as f64;
    let peak = mag.iter().take(n / 4).fold(0.0f64, |a, &v| a.max(v));
    if first > 0.1 * im || peak < 3.0 * im {
        return None;
    }
    let kp = mag.iter().position(|&v| v >= peak)?;
    let k = mag[kp..].iter().position(|&v| v < 1.5 * im)? + kp;
    Some(d.t_s[k])
}

fn span(x: impl Iterator<Item = f64>) -> (f64, f64, f64) {
    let (mut lo, mut hi, mut s, mut c) = (f64::INFINITY, f64::NEG_INFINITY, 0.0, 0.0);
    for v in x {
        lo = lo.min(v);
        hi = hi.max(v);
        s += v;
        c += 1.0;
    }
    (lo, hi, s / f64::max(c, 1.0))
}

/// The transient window `w` lies in (or that ended within `lookback_s` before it), if any.
///
/// A window up to the start's end `start_end` (90 % of the running speed) is the start;
/// one within `lookback_s` after it (the start's settling tail) too, unless the supply
/// voltage stepped after the start's end: then that step names it (on a machine with a
/// long rotor time constant the tail covers the first steps of a V/f run, and a window
/// just after such a step was called "the start"). Only the voltage's magnitude decides
/// there: the frame's frequency and the speed still settle from the start. Later windows:
/// a supply step or a speed change within `lookback_s` before them.
pub fn classify(
    d: &Prepared,
    n: &MachineConstants,
    w: &WorstWindow,
    start_end: Option<f64>,
    lookback_s: f64,
) -> Option<Transient> {
    let within = |from: f64| -> Vec<usize> {
        (0..d.len())
            .filter(|&k| d.t_s[k] >= from && d.t_s[k] <= w.t_end_s)
            .collect()
    };
    match start_end {
        Some(te) if w.t_start_s <= te + lookback_s => {
            let idx = within((w.t_start_s - lookback_s).max(te));
            if w.t_start_s > te && voltage_step(d, &idx).is_some() {
                return classify_events(d, n, &idx);
            }
            Some(Transient {
                kind: TransientKind::Start,
                description: format!(
                    "the direct-on-line start (the motor reaches 90 % of its running speed at {te:.2} s)"
                ),
            })
        }
        _ => classify_events(d, n, &within(w.t_start_s - lookback_s)),
    }
}

/// The relative change of the supply voltage's magnitude over the samples `idx`, when it
/// is more than [`STEP_MIN`] (a voltage-less log: none).
fn voltage_step(d: &Prepared, idx: &[usize]) -> Option<f64> {
    if d.vq.len() != d.len() || idx.len() < 2 {
        return None;
    }
    let (lo, hi, m) = span(idx.iter().map(|&k| d.vq[k].hypot(d.vd[k])));
    (m > 0.0 && (hi - lo) / m > STEP_MIN).then_some((hi - lo) / m)
}

/// A supply step or a speed change among the samples `idx`, if any.
fn classify_events(d: &Prepared, n: &MachineConstants, idx: &[usize]) -> Option<Transient> {
    if idx.len() < 2 {
        return None;
    }
    let mut steps = Vec::new();
    if let Some(r) = voltage_step(d, idx) {
        steps.push(format!("the supply voltage moves by {:.0} %", 100.0 * r));
    }
    let (lo, hi, m) = span(idx.iter().map(|&k| d.omega_s[k].abs()));
    if m > 0.0 && (hi - lo) / m > STEP_MIN {
        steps.push(format!(
            "the supply frequency moves from {:.1} to {:.1} Hz",
            lo / std::f64::consts::TAU,
            hi / std::f64::consts::TAU
        ));
    }
    if !steps.is_empty() {
        return Some(Transient {
            kind: TransientKind::SupplyStep,
            description: steps.join(" and "),
        });
    }
    if d.omega_r.len() == d.len() {
        let (lo, hi, _) = span(idx.iter().map(|&k| d.omega_r[k]));
        let ws = super::effects::sync_speed_mech(d, n) * n.np;
        if (hi - lo) / ws > SPEED_CHANGE_MIN {
            return Some(Transient {
                kind: TransientKind::SpeedChange,
                description: format!(
                    "the speed changes by {:.0} % of synchronous speed",
                    100.0 * (hi - lo) / ws
                ),
            });
        }
    }
    None
}

/// Settling time after a transient: five rotor time constants (the slowest electrical
/// dynamics; the flux has settled to 0.7 %).
pub fn settling_s(n: &MachineConstants) -> f64 {
    5.0 * n.lr_h / n.rr_ohm
}

/// Why a library effect is not proposed on a log (`explain`'s `skipped`, and `compare`'s
/// advice on the dynamics effects): the one rule both commands print
/// ([`not_proposed`]); the words are spelled at the door (`monitor-words`).
#[derive(Debug, Clone, PartialEq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum NotProposed {
    /// Effects it needs in the model first ([`EffectModel::requires`]).
    Requires(Vec<EffectId>),
    /// Its time constant `tau_s` [s] is shorter than 3 samples of the fit series (period
    /// `dt_s` [s]): a shorter window of the log would resolve it.
    Unresolved {
        /// Sample period of the fit series [s].
        dt_s: f64,
        /// The effect's time constant [s].
        tau_s: f64,
    },
    /// A dynamics effect (time constant `tau_s` [s]) on a log without a start, a supply
    /// step (voltage and frequency within [`STEP_MIN`]) or a fast speed change (within
    /// [`SPEED_CHANGE_MIN`] of the synchronous speed over [`settling_s`],
    /// [`speed_transient`]).
    NoTransient {
        /// The effect's time constant [s].
        tau_s: f64,
        /// The window a speed change is judged over ([`settling_s`]) [s].
        settling_s: f64,
    },
}

/// What the analysed span offers an effect with a time constant: the sample period of the
/// series the fits run on (a long log's coarse copy), whether that series holds a
/// transient of the model's inputs ([`input_transients`]) and whether its speed moves
/// faster than the rotor's flux settles ([`speed_transient`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Span {
    /// Sample period of the fit series [s].
    pub dt_s: f64,
    /// Whether it holds a start or a supply step.
    pub input_transient: bool,
    /// Whether its speed moves by more than [`SPEED_CHANGE_MIN`] of the synchronous speed
    /// within [`settling_s`] (a load step on a machine whose shaft is light against its
    /// rotor time constant).
    pub speed_change: bool,
}

impl Span {
    /// The span of the fit series `fit_series` of machine `n`.
    pub fn of(fit_series: &Prepared, n: &MachineConstants) -> Self {
        Span {
            dt_s: fit_series.dt_s,
            input_transient: input_transients(fit_series, n).iter().any(|&t| t),
            speed_change: speed_transient(fit_series, n),
        }
    }
}

/// Whether the measured speed of `d` moves by more than [`SPEED_CHANGE_MIN`] of the
/// synchronous speed within any [`settling_s`] of the log (false without a speed column).
/// Such a move is a transient the electrical dynamics act on: the rotor's flux and the
/// currents settle over the rotor time constant `Lr / Rr`, and a load step moves a light
/// shaft faster than that (motulator's 2.2 kW machine takes its rated torque from no load
/// in about 10 ms, against a rotor time constant of 107 ms: the full-order machine then
/// removes 98 % of the error a load torque leaves). A move spread over more than the
/// settling time stays quasi-static and is not counted.
pub fn speed_transient(d: &Prepared, n: &MachineConstants) -> bool {
    let len = d.len();
    if !d.channels.speed || d.omega_r.len() != len || len < 2 {
        return false;
    }
    let look = ((settling_s(n) / d.dt_s.max(1e-9)).ceil() as usize).max(1);
    let ws = super::effects::sync_speed_mech(d, n) * n.np;
    sliding_span(&d.omega_r, look)
        .into_iter()
        .any(|(lo, hi, _)| (hi - lo) / ws > SPEED_CHANGE_MIN)
}

/// The one rule for whether effect `e` is proposed on a span (`None`: it is), with the
/// model holding `in_model`: for a dynamics effect (one that declares a time constant,
/// [`EffectModel::time_constant_s`]), its time constant is shorter than 3 samples of the
/// (coarse) fit series of a long log, or the span holds no transient for its dynamics to
/// act on (said first: then no rung of the dynamics ladder is proposed): no start, no
/// supply step, no speed change faster than the rotor's flux settles
/// ([`speed_transient`]); else an effect it needs first ([`EffectModel::requires`]) is
/// missing. Without any of these the electrical states follow the inputs quasi-statically,
/// the full-order machine's steady state is the paper's model, and what a dynamics
/// effect's extra states gain there they gain by absorbing another effect
/// (docs/model-vs-measurement.md, "How it works"). `explain` skips such an effect with
/// this reason; `compare`'s advice prints the same ([`dynamics_plan`]).
pub fn not_proposed(
    e: &dyn EffectModel,
    span: Span,
    n: &MachineConstants,
    in_model: &[EffectId],
) -> Option<NotProposed> {
    if let Some(tau_s) = e.time_constant_s(n) {
        if span.dt_s > tau_s / 3.0 {
            return Some(NotProposed::Unresolved {
                dt_s: span.dt_s,
                tau_s,
            });
        }
        if !span.input_transient && !span.speed_change {
            return Some(NotProposed::NoTransient {
                tau_s,
                settling_s: settling_s(n),
            });
        }
    }
    let missing: Vec<EffectId> = e
        .requires()
        .iter()
        .copied()
        .filter(|k| !in_model.contains(k))
        .collect();
    (!missing.is_empty()).then_some(NotProposed::Requires(missing))
}

/// Every dynamics effect of the library not in the model (`in_model`), in the library's
/// order, with why it is not proposed on the span ([`not_proposed`]; `None`: proposed).
/// What an effect needs first counts as there when the same plan proposes it: the advice
/// adds them together (`cross_coupling_dynamics` with `d_axis_dynamics`: the full-order
/// machine, as the ladder's candidate of all the missing dynamics effects at once). Judged
/// against the model alone, the advice had dropped `cross_coupling_dynamics` ("needs
/// d_axis_dynamics in the model first") and nothing proposed it later: a hidden supply
/// unbalance then fell 0.1078 -> 0.0636 where all four dynamics effects took it to 0.0046
/// (issue 62).
pub fn dynamics_plan(
    span: Span,
    n: &MachineConstants,
    in_model: &[EffectId],
) -> Vec<(EffectId, Option<NotProposed>)> {
    let missing: Vec<Box<dyn EffectModel>> = library()
        .into_iter()
        .filter(|m| m.kind().is_dynamics() && !in_model.contains(&m.kind()))
        .collect();
    // First without what they need: those the span itself allows.
    let allowed: Vec<EffectId> = missing
        .iter()
        .filter(|model| {
            let all: Vec<EffectId> = in_model.iter().chain(model.requires()).copied().collect();
            not_proposed(model.as_ref(), span, n, &all).is_none()
        })
        .map(|m| m.kind())
        .collect();
    let with: Vec<EffectId> = in_model.iter().chain(&allowed).copied().collect();
    missing
        .into_iter()
        .map(|m| (m.kind(), not_proposed(m.as_ref(), span, n, &with)))
        .collect()
}

/// What `compare` advises when its worst windows are transients (JSON `advice_values[]`,
/// beside the sentences `advice`).
#[derive(Debug, Clone, PartialEq, Serialize)]
#[serde(tag = "kind", rename_all = "snake_case")]
pub enum Advice {
    /// The worst windows that are transients, and what the model's dynamics effects do for
    /// them.
    Transients {
        /// Each such window: its span [s] and its transient.
        windows: Vec<TransientWindow>,
        /// What the dynamics effects of the plan cover.
        cover: Cover,
    },
    /// A dynamics effect the plan does not propose, with the reason `explain` gives for
    /// skipping it (the same words).
    NotProposed {
        /// The effect.
        effect: EffectId,
        /// Why not.
        why: NotProposed,
    },
    /// After a start: analyse from `from_s` [s] (the start ends at about `start_end_s`,
    /// plus five rotor time constants, rounded up to 0.1 s).
    LeaveStartOut {
        /// Where the analysed window may begin [s].
        from_s: f64,
        /// The start's end [s] ([`start_end_s`]).
        start_end_s: f64,
    },
}

/// A worst window of `compare` that is a transient.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct TransientWindow {
    /// Its start [s].
    pub t_start_s: f64,
    /// Its end [s].
    pub t_end_s: f64,
    /// The transient.
    pub transient: Transient,
}

/// What the dynamics effects of a plan ([`dynamics_plan`]) do for transients.
#[derive(Debug, Clone, PartialEq, Serialize)]
#[serde(tag = "kind", rename_all = "snake_case")]
pub enum Cover {
    /// Every dynamics effect is already in the model: what remains there is another effect
    /// or a parameter error.
    AllInModel,
    /// None is proposed on this span (why: [`Advice::NotProposed`]).
    NoneProposed,
    /// Add `proposed` (the model's `effects` with them).
    Add {
        /// The dynamics effects proposed.
        proposed: Vec<EffectId>,
        /// The effects of the model with them (what `--effects` takes).
        effects: Vec<EffectId>,
    },
}

/// The advice `compare` gives when its worst windows are transients: the dynamics effects
/// not in the model that [`dynamics_plan`] proposes on this span (with the effects that add
/// them), each one it does not propose with the reason `explain` gives for skipping it,
/// and, after a start, the window past it. The windows' transients first (`None` for a
/// window in none).
pub fn advice(
    d: &Prepared,
    n: &MachineConstants,
    worst: &[WorstWindow],
    in_model: &[EffectId],
    plan: &[(EffectId, Option<NotProposed>)],
) -> (Vec<Option<Transient>>, Vec<Advice>) {
    let start = start_end_s(d);
    let look = settling_s(n);
    let tags: Vec<Option<Transient>> = worst
        .iter()
        .map(|w| classify(d, n, w, start, look))
        .collect();
    let mut out = Vec::new();
    if tags.iter().all(Option::is_none) {
        return (tags, out);
    }
    let windows: Vec<TransientWindow> = worst
        .iter()
        .zip(&tags)
        .filter_map(|(w, t)| {
            t.as_ref().map(|t| TransientWindow {
                t_start_s: w.t_start_s,
                t_end_s: w.t_end_s,
                transient: t.clone(),
            })
        })
        .collect();
    out.push(Advice::Transients {
        windows,
        cover: cover(plan, in_model),
    });
    out.extend(plan.iter().filter_map(|(k, why)| {
        why.as_ref().map(|w| Advice::NotProposed {
            effect: *k,
            why: w.clone(),
        })
    }));
    if let Some(te) = start {
        out.push(Advice::LeaveStartOut {
            from_s: ((te + look) * 10.0).ceil() / 10.0,
            start_end_s: te,
        });
    }
    (tags, out)
}

/// What the dynamics effects of `plan` do for the transients: those proposed, with the
/// effects of `in_model` and them, or why none is.
fn cover(plan: &[(EffectId, Option<NotProposed>)], in_model: &[EffectId]) -> Cover {
    let proposed: Vec<EffectId> = plan
        .iter()
        .filter(|(_, why)| why.is_none())
        .map(|(k, _)| *k)
        .collect();
    if plan.is_empty() {
        return Cover::AllInModel;
    }
    if proposed.is_empty() {
        return Cover::NoneProposed;
    }
    let effects = in_model.iter().chain(&proposed).copied().collect();
    Cover::Add { proposed, effects }
}

/// The samples of `d` that lie in a transient of the model's inputs: within the
/// [`settling_s`] after the direct-on-line start ends ([`start_end_s`]), or where the
/// supply voltage amplitude or the supply frequency spans more than [`STEP_MIN`] of its
/// mean over the [`settling_s`] before the sample (the same test as a `supply_step` window
/// of [`classify`]). A load step is not an input transient (the model's inputs are the
/// supply); where it moves the speed fast, [`speed_transient`] says so.
pub fn input_transients(d: &Prepared, n: &MachineConstants) -> Vec<bool> {
    let len = d.len();
    let look = ((settling_s(n) / d.dt_s.max(1e-9)).ceil() as usize).max(1);
    let mut out = vec![false; len];
    if let Some(te) = start_end_s(d) {
        let until = te + settling_s(n);
        for (o, t) in out.iter_mut().zip(&d.t_s) {
            *o |= *t <= until;
        }
    }
    let amp: Vec<f64> = if d.vq.len() == len {
        (0..len).map(|k| d.vq[k].hypot(d.vd[k])).collect()
    } else {
        Vec::new()
    };
    let freq: Vec<f64> = d.omega_s.iter().map(|w| w.abs()).collect();
    for x in [&amp, &freq] {
        if x.len() != len {
            continue;
        }
        for (k, (lo, hi, mean)) in sliding_span(x, look).into_iter().enumerate() {
            out[k] |= mean > 0.0 && (hi - lo) / mean > STEP_MIN;
        }
    }
    out
}

/// Minimum, maximum and mean of `x` over the trailing window `[k + 1 - w, k]` for every
/// `k` (monotonic queues: O(n)).
fn sliding_span(x: &[f64], w: usize) -> Vec<(f64, f64, f64)> {
    use std::collections::VecDeque;
    let mut lo: VecDeque<usize> = VecDeque::new();
    let mut hi: VecDeque<usize> = VecDeque::new();
    let mut sum = 0.0;
    let mut out = Vec::with_capacity(x.len());
    for k in 0..x.len() {
        while lo.back().is_some_and(|&j| x[j] >= x[k]) {
            lo.pop_back();
        }
        lo.push_back(k);
        while hi.back().is_some_and(|&j| x[j] <= x[k]) {
            hi.pop_back();
        }
        hi.push_back(k);
        sum += x[k];
        if k >= w {
            sum -= x[k - w];
        }
        let first = (k + 1).saturating_sub(w);
        while lo.front().is_some_and(|&j| j < first) {
            lo.pop_front();
        }
        while hi.front().is_some_and(|&j| j < first) {
            hi.pop_front();
        }
        let count = (k + 1 - first) as f64;
        out.push((x[lo[0]], x[hi[0]], sum / count));
    }
    out
}

#[cfg(test)]
mod tests;
