//! The held-back split of the ladder, stratified by the log's events (the start, transients,
//! load moves, steady stretches): every kind of event falls in both parts.

use super::report::Stratum;
use super::rules::{EVENT_WINDOW_MAX_S, WINDOW_MAX_S, WINDOW_MIN_PERIODS};
use crate::metrics::Weights;
use crate::prep::Prepared;
use crate::simplified_model::MachineConstants;
use crate::strata::{strata, StratumKind};

/// The held-back mask of the working series `d`, stratified by its events (module doc):
/// each stratum of [`strata`] cut into alternating windows ([`alternate`]).
pub fn stratified_heldback(d: &Prepared, n: &MachineConstants) -> (Vec<bool>, Vec<Stratum>) {
    // The supply frequency: the frame's mean speed (50 Hz where it does not turn).
    let w_mean = d.omega_s.iter().map(|w| w.abs()).sum::<f64>() / d.len().max(1) as f64;
    let f_hz = if w_mean > 1.0 {
        w_mean / std::f64::consts::TAU
    } else {
        50.0
    };
    alternate(&strata(d, n), &d.t_s, d.dt_s, f_hz)
}

/// Each stratum of `strata` cut into an even number of alternating windows, each at most
/// [`WINDOW_MAX_S`] ([`EVENT_WINDOW_MAX_S`] in an event's stratum) and, where the stratum allows, at least [`WINDOW_MIN_PERIODS`] supply
/// periods (of `f_hz`) long; the strata alternate which half comes first, so that the
/// onsets of successive events fall in both parts. Returns the held-back mask and the
/// strata as reported.
fn alternate(
    strata: &[(StratumKind, usize, usize)],
    t_s: &[f64],
    dt: f64,
    f_hz: f64,
) -> (Vec<bool>, Vec<Stratum>) {
    let len = strata.last().map_or(0, |s| s.2);
    let mut held = vec![false; len];
    let mut info = Vec::new();
    let dt = dt.max(1e-9);
    let min_len = ((WINDOW_MIN_PERIODS / f_hz.max(1e-3) / dt).round() as usize).max(1);
    for (i, &(kind, a, b)) in strata.iter().enumerate() {
        let longest = if kind == StratumKind::Steady {
            WINDOW_MAX_S
        } else {
            EVENT_WINDOW_MAX_S
        };
        let max_len = ((longest / dt).round() as usize).max(min_len);
        let span = b - a;
        let mut windows = span.div_ceil(max_len).max(2);
        windows += windows % 2;
        if span / windows < min_len {
            windows = (span / min_len).max(1);
            if windows > 1 {
                windows -= windows % 2;
            }
        }
        for (j, h) in held[a..b].iter_mut().enumerate() {
            let win = j * windows / span.max(1);
            *h = (win + i) % 2 == 1;
        }
        info.push(Stratum {
            kind: kind.name(),
            t_start_s: t_s.get(a).copied().unwrap_or(0.0),
            t_end_s: t_s.get(b.saturating_sub(1)).copied().unwrap_or(0.0),
            windows,
        });
    }
    (held, info)
}

/// The held-back mask of `d`'s coarse copy `fd` (samples at the same times).
pub(crate) fn mask_on(fd: &Prepared, d: &Prepared, held: &[bool]) -> Vec<bool> {
    fd.t_s
        .iter()
        .map(|t| {
            let k = d
                .t_s
                .partition_point(|x| x < t)
                .min(d.len().saturating_sub(1));
            held.get(k).copied().unwrap_or(false)
        })
        .collect()
}

/// The weights of a fit on `d` that trains on the samples `held` does not hold back.
pub(crate) fn weights_for(d: &Prepared, held: &[bool], max_fit: usize) -> Weights {
    let mut w = Weights::new(d, 0, max_fit);
    w.train = held.iter().map(|h| !h).collect();
    w
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::strata::{load_moves, runs};

    #[test]
    fn every_event_falls_in_both_parts() {
        // 4 s at 10 kHz, load steps at 1.0 s and 3.0 s: two load moves, three steady
        // stretches; each stratum is held back in part and fitted in part.
        let dt = 1e-4;
        let t: Vec<f64> = (0..40_000).map(|k| k as f64 * dt).collect();
        let iq: Vec<f64> = t
            .iter()
            .map(|t| if (1.0..3.0).contains(t) { 8.0 } else { 4.0 })
            .collect();
        let moved = load_moves(&iq, dt);
        let strata = runs(moved.iter().map(|&m| {
            if m {
                StratumKind::LoadMove
            } else {
                StratumKind::Steady
            }
        }));
        let (held, info) = alternate(&strata, &t, dt, 50.0);
        let moves: Vec<&Stratum> = info.iter().filter(|s| s.kind == "load_move").collect();
        assert_eq!(moves.len(), 2, "{info:?}");
        // Each move covers its step.
        assert!(
            moves[0].t_start_s < 1.0 && moves[0].t_end_s > 1.0,
            "{:?}",
            moves[0]
        );
        assert!(
            moves[1].t_start_s < 3.0 && moves[1].t_end_s > 3.0,
            "{:?}",
            moves[1]
        );
        for &(_, a, b) in &strata {
            let h = held[a..b].iter().filter(|x| **x).count();
            assert!(h > 0 && h < b - a, "{a}..{b}: {h} held back");
        }
        let share = held.iter().filter(|x| **x).count() as f64 / held.len() as f64;
        assert!((0.35..0.65).contains(&share), "{share}");
    }

    #[test]
    fn a_steady_log_has_no_load_move() {
        let iq: Vec<f64> = (0..20_000).map(|k| 5.0 + 0.01 * ((k % 7) as f64)).collect();
        assert!(!load_moves(&iq, 1e-4).iter().any(|m| *m));
    }
}
