//! The chart sets of `compare` and `explain` (drawn and written by [`super::plot`]).

use super::plot::{self, Chart, Series};
use monitor_api::analysis::CompareOutput;
use monitor_api::analysis::EffectId;
use monitor_api::analysis::Prediction;
use monitor_api::analysis::Prepared;
use monitor_api::analysis::{metrics, WorstWindow};

/// The charts `compare` writes (file stems; each as `.svg` and `.png`; the zoomed panels
/// only for a log long enough to be drawn as envelopes, a scatter only where the log spans
/// operating points).
pub const COMPARE: [&str; 12] = [
    "overlay_iqs",
    "overlay_omega_r",
    "zoom_iqs_1",
    "zoom_iqs_2",
    "overlay_ia",
    "error_time",
    "error_time_omega_r",
    "error_vs_speed",
    "error_vs_load",
    "error_vs_voltage",
    "error_vs_time_since_start",
    "error_spectrum",
];

/// The charts `explain` writes.
pub const EXPLAIN: [&str; 5] = [
    "before_after_iqs",
    "before_after_omega_r",
    "zoom_before_after_iqs_1",
    "zoom_before_after_iqs_2",
    "before_after_error",
];

/// Every file a chart set can write (for the output guard).
pub fn file_names(stems: &[&str]) -> Vec<String> {
    stems
        .iter()
        .flat_map(|s| [format!("{s}.svg"), format!("{s}.png")])
        .collect()
}

/// Points a line over a short span keeps (min/max pairs): under one per pixel column of a
/// [`plot::WIDTH_PX`] chart.
const MAX_POINTS: usize = 800;
/// A line over more supply periods than this is drawn per supply period ([`Per`]): sample
/// by sample it would be a solid band.
const ENVELOPE_FROM_PERIODS: usize = 40;
/// Supply periods a zoomed panel shows.
const ZOOM_PERIODS: usize = 4;

/// (file stem, title, x label, points) of an error-vs-condition chart.
type ScatterSpec = (&'static str, &'static str, &'static str, Vec<(f64, f64)>);

fn pts(t: &[f64], y: impl Iterator<Item = f64>) -> Vec<(f64, f64)> {
    plot::thin(&t.iter().copied().zip(y).collect::<Vec<_>>(), MAX_POINTS)
}

/// A line of `y` over the times `t`, thinned for plotting.
fn line(label: impl Into<String>, t: &[f64], y: impl Iterator<Item = f64>, color: usize) -> Series {
    Series {
        label: label.into(),
        points: pts(t, y),
        color,
        scatter: false,
        dashed: false,
    }
}

/// Samples in one supply period (from the mean frame speed; 50 Hz without one).
fn period_samples(d: &Prepared) -> usize {
    let n = d.omega_s.len().max(1) as f64;
    let w = d.omega_s.iter().map(|w| w.abs()).sum::<f64>() / n;
    let f_hz = if w > 1.0 {
        w / std::f64::consts::TAU
    } else {
        50.0
    };
    ((1.0 / (f_hz * d.dt_s)).round() as usize).max(1)
}

/// What a long line draws per supply period ([`envelope`]).
#[derive(Debug, Clone, Copy, PartialEq)]
enum Per {
    /// The period's mean, signed: a quantity of the rotating frame (I_qs, the speed), whose
    /// value is its mean and whose sign matters (motoring or braking).
    Mean,
    /// The period's RMS, never negative: the size of an error.
    Rms,
}

impl Per {
    /// How the legend names it.
    fn label(self) -> &'static str {
        match self {
            Per::Mean => "mean per supply period",
            Per::Rms => "RMS per supply period",
        }
    }
}

/// The envelope of `y`: per supply period of `per` samples, (mid time, the period's mean or
/// RMS as `what` says).
fn envelope(t: &[f64], y: &[f64], per: usize, what: Per) -> Vec<(f64, f64)> {
    t.chunks(per)
        .zip(y.chunks(per))
        .filter_map(|(tc, yc)| {
            let (first, last) = (tc.first()?, tc.last()?);
            let n = yc.len().max(1) as f64;
            let v = match what {
                Per::Mean => yc.iter().sum::<f64>() / n,
                Per::Rms => (yc.iter().map(|v| v * v).sum::<f64>() / n).sqrt(),
            };
            Some((0.5 * (first + last), v))
        })
        .collect()
}

/// A line of `y` over `t`: sample by sample over a short span, its envelope
/// ([`envelope`], `what` per period, the label says which) over more than
/// [`ENVELOPE_FROM_PERIODS`] periods.
fn trace(label: &str, t: &[f64], y: &[f64], per: usize, color: usize, what: Per) -> Series {
    if t.len() > ENVELOPE_FROM_PERIODS * per {
        Series {
            label: format!("{label} ({})", what.label()),
            points: envelope(t, y, per, what),
            color,
            scatter: false,
            dashed: false,
        }
    } else {
        line(label, t, y.iter().copied(), color)
    }
}

/// The dashed "before" line, drawn last so that it lies on top.
fn before(mut s: Series) -> Series {
    s.dashed = true;
    s
}

/// The sample spans of the zoomed panels: [`ZOOM_PERIODS`] supply periods around the two
/// periods where `error` is largest (apart by more than a panel), when the log is long
/// enough to be drawn as envelopes; else none.
fn worst_spans(error: &[f64], per: usize) -> Vec<(usize, usize)> {
    let n = error.len();
    if n <= ENVELOPE_FROM_PERIODS * per {
        return Vec::new();
    }
    let mut periods: Vec<(usize, f64)> = error
        .chunks(per)
        .map(|c| c.iter().map(|v| v * v).sum::<f64>())
        .enumerate()
        .collect();
    periods.sort_by(|a, b| b.1.total_cmp(&a.1));
    let mut picked: Vec<usize> = Vec::new();
    for (k, _) in periods {
        if picked.iter().all(|p| p.abs_diff(k) > 2 * ZOOM_PERIODS) {
            picked.push(k);
        }
        if picked.len() == 2 {
            break;
        }
    }
    picked
        .into_iter()
        .map(|k| {
            let a = (k * per).saturating_sub(ZOOM_PERIODS * per / 2);
            (a, (a + ZOOM_PERIODS * per).min(n))
        })
        .collect()
}

/// The zoomed panels of `series` (label, values, colour, dashed) over `spans`.
fn zooms(
    t: &[f64],
    spans: &[(usize, usize)],
    stems: [&'static str; 2],
    titles: [&'static str; 2],
    series: &[(&str, &[f64], usize, bool)],
) -> Vec<Chart<'static>> {
    spans
        .iter()
        .zip(stems.into_iter().zip(titles))
        .map(|(&(a, b), (stem, title))| {
            let s = series
                .iter()
                .map(|&(label, y, color, dashed)| {
                    let mut s = line(label, &t[a..b], y[a..b].iter().copied(), color);
                    s.dashed = dashed;
                    s
                })
                .collect();
            over_time(stem, title, "I_qs [A]", s)
        })
        .collect()
}

/// A chart over time.
fn over_time(
    stem: &'static str,
    title: &'static str,
    y_label: &'static str,
    series: Vec<Series>,
) -> Chart<'static> {
    Chart {
        stem,
        title,
        x_label: "time [s]",
        y_label,
        series,
        log_y: false,
        omitted: None,
        x_names: Vec::new(),
    }
}

/// A zoom window for phase-current overlays: the worst window if any, else the last 0.1 s.
fn zoom(d: &Prepared, worst: &[WorstWindow]) -> (usize, usize) {
    let n = d.len();
    let per = (0.1 / d.dt_s).ceil() as usize;
    let centre = worst
        .first()
        .map(|w| {
            d.t_s
                .partition_point(|&t| t < 0.5 * (w.t_start_s + w.t_end_s))
        })
        .unwrap_or(n.saturating_sub(per / 2));
    let a = centre.saturating_sub(per / 2);
    (a, (a + per).min(n))
}

/// The model `compare` ran, as its charts' legends name it: the paper's, with the
/// configured effects.
fn model_label(effects: &[EffectId]) -> String {
    if effects.is_empty() {
        "the paper's model".into()
    } else {
        let names: Vec<&str> = effects.iter().map(|e| e.name()).collect();
        format!("the paper's model + {}", names.join(" + "))
    }
}

/// Builds the `compare` charts of the model it was asked for (its effects named in every
/// legend): overlays (envelopes over a long log, with zoomed panels at the worst periods),
/// error vs time (one unit per chart), error vs operating variables, error spectrum.
pub fn compare_charts(d: &Prepared, out: &CompareOutput) -> Vec<Chart<'static>> {
    let p = &out.prediction;
    if p.iq.is_empty() {
        return Vec::new();
    }
    let model = model_label(&out.report.effects);
    let eiq: Vec<f64> = p.iq.iter().zip(&d.iq).map(|(a, b)| a - b).collect();
    let mut v = overlays(d, p, &eiq, &out.report.worst_windows, &model);
    v.extend(errors_over_time(d, p, &eiq, &model));
    v.extend(condition_charts(d, &out.all_windows, &model));
    v.push(Chart {
        stem: "error_spectrum",
        title: "Spectrum of the q-axis current's error",
        x_label: "frequency [Hz]",
        y_label: "amplitude [A]",
        series: vec![Series {
            label: format!("I_qs error of {model}"),
            points: plot::thin(&metrics::spectrum(&eiq, d.dt_s), MAX_POINTS),
            color: 4,
            scatter: false,
            dashed: false,
        }],
        log_y: true,
        omitted: None,
        x_names: Vec::new(),
    });
    v
}

/// The measured and predicted I_qs and speed over the log, I_qs zoomed where its error
/// `eiq` is worst, and the phase current around the worst window of `worst` (`model`: the
/// model's name in the legends).
fn overlays(
    d: &Prepared,
    p: &Prediction,
    eiq: &[f64],
    worst: &[WorstWindow],
    model: &str,
) -> Vec<Chart<'static>> {
    let (t, per) = (&d.t_s, period_samples(d));
    let mut v = vec![over_time(
        "overlay_iqs",
        "q-axis current I_qs: measured vs model",
        "I_qs [A]",
        vec![
            trace("measured", t, &d.iq, per, 0, Per::Mean),
            trace(model, t, &p.iq, per, 1, Per::Mean),
        ],
    )];
    if d.channels.speed {
        v.push(over_time(
            "overlay_omega_r",
            "Rotor speed omega_r (electrical): measured vs model",
            "omega_r [rad/s]",
            vec![
                trace("measured", t, &d.omega_r, per, 0, Per::Mean),
                trace(model, t, &p.omega_r, per, 1, Per::Mean),
            ],
        ));
    }
    v.extend(zooms(
        t,
        &worst_spans(eiq, per),
        ["zoom_iqs_1", "zoom_iqs_2"],
        [
            "q-axis current, a few supply periods where the model is worst: measured vs model",
            "q-axis current, a few supply periods where the model is second worst: measured vs model",
        ],
        &[("measured", &d.iq, 0, false), (model, &p.iq, 1, false)],
    ));
    let (a, b) = zoom(d, worst);
    v.push(over_time(
        "overlay_ia",
        "Phase current i_a around the worst window: measured vs model",
        "i_a [A]",
        vec![
            line(
                "measured",
                &t[a..b],
                (a..b).map(|k| metrics::measured(d, k)[2]),
                0,
            ),
            line(
                model,
                &t[a..b],
                (a..b).map(|k| metrics::predicted(d, p, k)[2]),
                1,
            ),
        ],
    ));
    v
}

/// The model's errors over time: I_qs (`eiq`) and, with a speed column, the speed
/// (`model`: its name in the legends).
fn errors_over_time(d: &Prepared, p: &Prediction, eiq: &[f64], model: &str) -> Vec<Chart<'static>> {
    let t = &d.t_s;
    let per = period_samples(d);
    let mut v = vec![over_time(
        "error_time",
        "Error of the q-axis current vs time (model - measured)",
        "I_qs error [A]",
        vec![trace(
            &format!("I_qs error of {model}"),
            t,
            eiq,
            per,
            1,
            Per::Rms,
        )],
    )];
    if d.channels.speed {
        let e: Vec<f64> = p
            .omega_r
            .iter()
            .zip(&d.omega_r)
            .map(|(a, b)| a - b)
            .collect();
        v.push(over_time(
            "error_time_omega_r",
            "Error of the rotor speed vs time (model - measured)",
            "omega_r error [rad/s]",
            vec![trace(
                &format!("omega_r error of {model}"),
                t,
                &e,
                per,
                2,
                Per::Rms,
            )],
        ));
    }
    v
}

/// Why an error-vs-condition chart is not drawn: fewer than three windows, or every
/// window's condition within 5 % of one value (the log holds one operating point).
fn one_operating_point(x_label: &str, points: &[(f64, f64)]) -> Option<String> {
    let lo = points.iter().map(|p| p.0).fold(f64::INFINITY, f64::min);
    let hi = points.iter().map(|p| p.0).fold(f64::NEG_INFINITY, f64::max);
    if points.len() < 3 {
        return Some(format!(
            "Not drawn: {} window(s), too few to set the error against {x_label}.",
            points.len()
        ));
    }
    (hi - lo <= 0.05 * lo.abs().max(hi.abs())).then(|| {
        format!(
            "Not drawn: every window's {x_label} lies within {lo:.2}..{hi:.2}; the log holds one operating point, so the error cannot be set against it."
        )
    })
}

/// Window error against the operating condition: speed, load current, voltage, time since
/// start (one point per window of `model`'s prediction).
fn condition_charts(d: &Prepared, all: &[WorstWindow], model: &str) -> Vec<Chart<'static>> {
    let wpts = |f: &dyn Fn(&WorstWindow) -> Option<f64>| -> Vec<(f64, f64)> {
        all.iter()
            .filter_map(|w| f(w).map(|x| (x, w.normalized_rms_error)))
            .collect()
    };
    let mut vs: Vec<ScatterSpec> = vec![
        (
            "error_vs_load",
            "Window error vs load current",
            "mean I_qs [A]",
            wpts(&|w| Some(w.condition.load_current_a)),
        ),
        (
            "error_vs_voltage",
            "Window error vs voltage level",
            "voltage [% of rated]",
            wpts(&|w| Some(w.condition.voltage_percent)),
        ),
        (
            "error_vs_time_since_start",
            "Window error vs time since start",
            "time since start [s]",
            wpts(&|w| Some(w.condition.time_since_start_s)),
        ),
    ];
    if d.channels.speed {
        vs.insert(
            0,
            (
                "error_vs_speed",
                "Window error vs speed",
                "speed [rpm]",
                wpts(&|w| w.condition.speed_rpm),
            ),
        );
    }
    vs.into_iter()
        .map(|(stem, title, xl, points)| Chart {
            stem,
            title,
            x_label: xl,
            y_label: "normalized RMS error",
            omitted: one_operating_point(xl, &points),
            x_names: Vec::new(),
            series: vec![Series {
                label: format!("window of {model}"),
                points,
                color: 3,
                scatter: true,
                dashed: false,
            }],
            log_y: false,
        })
        .collect()
}

/// Before/after charts of `explain`: I_qs and omega_r overlays of measured, the model with
/// the top-ranked effect, and the configured model ("before", dashed and on top), as
/// envelopes over a long log with zoomed panels at the periods the model before is worst.
pub fn explain_charts(
    d: &Prepared,
    before_p: &Prediction,
    after: Option<&(EffectId, Prediction)>,
) -> Vec<Chart<'static>> {
    let mut v = Vec::new();
    if before_p.iq.is_empty() {
        return v;
    }
    let t = &d.t_s;
    let per = period_samples(d);
    let overlay = |measured: &[f64], pick: &dyn Fn(&Prediction) -> &[f64]| {
        let mut s = vec![trace("measured", t, measured, per, 0, Per::Mean)];
        if let Some((name, p)) = after {
            s.push(trace(
                &format!("model + {name}"),
                t,
                pick(p),
                per,
                2,
                Per::Mean,
            ));
        }
        s.push(before(trace(
            "model before",
            t,
            pick(before_p),
            per,
            1,
            Per::Mean,
        )));
        s
    };
    v.push(over_time(
        "before_after_iqs",
        "q-axis current I_qs: measured, model before (dashed) and with the top effect",
        "I_qs [A]",
        overlay(&d.iq, &|p| &p.iq),
    ));
    if d.channels.speed {
        v.push(over_time(
            "before_after_omega_r",
            "Rotor speed omega_r: measured, model before (dashed) and with the top effect",
            "omega_r [rad/s]",
            overlay(&d.omega_r, &|p| &p.omega_r),
        ));
    }
    v.extend(before_after_errors(d, before_p, after));
    v
}

/// `explain`'s I_qs zoomed where the model before is worst, and its error before and
/// after adding the top effect.
fn before_after_errors(
    d: &Prepared,
    before_p: &Prediction,
    after: Option<&(EffectId, Prediction)>,
) -> Vec<Chart<'static>> {
    let t = &d.t_s;
    let per = period_samples(d);
    let error = |p: &Prediction| {
        p.iq.iter()
            .zip(&d.iq)
            .map(|(a, b)| a - b)
            .collect::<Vec<_>>()
    };
    let e_before = error(before_p);
    let named = after.map(|(name, p)| (format!("model + {name}"), p));
    let mut zs: Vec<(&str, &[f64], usize, bool)> = vec![("measured", &d.iq, 0, false)];
    if let Some((label, p)) = &named {
        zs.push((label, &p.iq, 2, false));
    }
    zs.push(("model before", &before_p.iq, 1, true));
    let mut v = zooms(
        t,
        &worst_spans(&e_before, per),
        ["zoom_before_after_iqs_1", "zoom_before_after_iqs_2"],
        [
            "q-axis current, a few supply periods where the model before is worst",
            "q-axis current, a few supply periods where the model before is second worst",
        ],
        &zs,
    );
    let mut s = Vec::new();
    if let Some((name, p)) = after {
        s.push(trace(
            &format!("error with {name}"),
            t,
            &error(p),
            per,
            2,
            Per::Rms,
        ));
    }
    s.push(before(trace(
        "error before",
        t,
        &e_before,
        per,
        1,
        Per::Rms,
    )));
    v.push(over_time(
        "before_after_error",
        "Error of the q-axis current before (dashed) and after adding the top effect",
        "I_qs error [A]",
        s,
    ));
    v
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A supply current's q-axis part over 50 periods of 20 samples: `offset` plus a ripple
    /// of amplitude `a` at the supply frequency.
    fn rippled(offset: f64, a: f64) -> (Vec<f64>, Vec<f64>) {
        let n = 50 * 20;
        let t: Vec<f64> = (0..n).map(|k| k as f64 * 0.001).collect();
        let y = (0..n)
            .map(|k| offset + a * (std::f64::consts::TAU * k as f64 / 20.0).sin())
            .collect();
        (t, y)
    }

    #[test]
    fn an_error_is_drawn_as_its_rms_a_quantity_as_its_mean_each_named_so() {
        // An error of -3 A with a 2 A ripple: its RMS per period is sqrt(9 + 2) A, never
        // negative; the signed envelope drew -3.3 A under the label "RMS".
        let (t, y) = rippled(-3.0, 2.0);
        let e = trace("I_qs error", &t, &y, 20, 1, Per::Rms);
        assert_eq!(e.label, "I_qs error (RMS per supply period)");
        assert_eq!(e.points.len(), 50);
        for &(_, v) in &e.points {
            assert!((v - 11f64.sqrt()).abs() < 1e-9, "{v}");
        }
        // A current is drawn as the period's mean: its sign (braking) kept, the ripple out.
        let m = trace("measured", &t, &y, 20, 0, Per::Mean);
        assert_eq!(m.label, "measured (mean per supply period)");
        for &(_, v) in &m.points {
            assert!((v + 3.0).abs() < 1e-9, "{v}");
        }
        // A short span is drawn sample by sample, and named plainly.
        let short = trace("I_qs error", &t[..200], &y[..200], 20, 1, Per::Rms);
        assert_eq!(short.label, "I_qs error");
        assert!(short.points.iter().any(|p| p.1 < 0.0));
    }
}
