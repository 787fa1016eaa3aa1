//! The chart sets of `compare` and `explain` (drawn and written by [`super::plot`]).

use super::plot::{self, Chart, Series};
use sim_host::analysis::compare::CompareOutput;
use sim_host::analysis::metrics::{self, WorstWindow};
use sim_host::analysis::prep::Prepared;
use sim_host::analysis::simplified_model::Prediction;

/// The charts `compare` writes (file stems; each as `.svg` and `.png`).
pub const COMPARE: [&str; 9] = [
    "overlay_iqs",
    "overlay_omega_r",
    "overlay_ia",
    "error_time",
    "error_vs_speed",
    "error_vs_load",
    "error_vs_voltage",
    "error_vs_time_since_start",
    "error_spectrum",
];

/// The charts `explain` writes.
pub const EXPLAIN: [&str; 3] = [
    "before_after_iqs",
    "before_after_omega_r",
    "before_after_error",
];

/// Every file a chart set can write (for the output guard).
pub fn file_names(stems: &[&str]) -> Vec<String> {
    stems
        .iter()
        .flat_map(|s| [format!("{s}.svg"), format!("{s}.png")])
        .collect()
}

const MAX_POINTS: usize = 4000;

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
    }
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

/// Builds the `compare` charts: overlays, error vs time, error vs operating variables,
/// error spectrum.
pub fn compare_charts(d: &Prepared, out: &CompareOutput) -> Vec<Chart<'static>> {
    let p = &out.prediction;
    let mut v = Vec::new();
    if p.iq.is_empty() {
        return v;
    }
    let t = &d.t_s;
    v.push(over_time(
        "overlay_iqs",
        "I_qs: measured vs model",
        "I_qs [A]",
        vec![
            line("measured", t, d.iq.iter().copied(), 0),
            line("model", t, p.iq.iter().copied(), 1),
        ],
    ));
    if d.channels.speed {
        v.push(over_time(
            "overlay_omega_r",
            "omega_r (electrical rotor speed): measured vs model",
            "omega_r [rad/s]",
            vec![
                line("measured", t, d.omega_r.iter().copied(), 0),
                line("model", t, p.omega_r.iter().copied(), 1),
            ],
        ));
    }
    let (a, b) = zoom(d, &out.report.worst_windows);
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
                "model",
                &t[a..b],
                (a..b).map(|k| metrics::predicted(d, p, k)[2]),
                1,
            ),
        ],
    ));
    let eiq: Vec<f64> = p.iq.iter().zip(&d.iq).map(|(a, b)| a - b).collect();
    let mut err_series = vec![line("I_qs error [A]", t, eiq.iter().copied(), 1)];
    if d.channels.speed {
        let e = p.omega_r.iter().zip(&d.omega_r).map(|(a, b)| a - b);
        err_series.push(line("omega_r error [rad/s]", t, e, 2));
    }
    v.push(over_time(
        "error_time",
        "Model error vs time (model - measured)",
        "error",
        err_series,
    ));
    v.extend(condition_charts(d, &out.all_windows));
    v.push(Chart {
        stem: "error_spectrum",
        title: "Spectrum of the I_qs error",
        x_label: "frequency [Hz]",
        y_label: "amplitude [A]",
        series: vec![Series {
            label: "I_qs error".into(),
            points: metrics::spectrum(&eiq, d.dt_s),
            color: 4,
            scatter: false,
        }],
        log_y: true,
    });
    v
}

/// Window error against the operating condition: speed, load current, voltage, time since
/// start (one point per window).
fn condition_charts(d: &Prepared, all: &[WorstWindow]) -> Vec<Chart<'static>> {
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
            series: vec![Series {
                label: "window".into(),
                points,
                color: 3,
                scatter: true,
            }],
            log_y: false,
        })
        .collect()
}

/// Before/after charts of `explain`: I_qs and omega_r overlays of measured, the configured
/// model, and the model with the top-ranked effect.
pub fn explain_charts(
    d: &Prepared,
    before: &Prediction,
    after: Option<&(monitor_core::EffectKind, Prediction)>,
) -> Vec<Chart<'static>> {
    let mut v = Vec::new();
    if before.iq.is_empty() {
        return v;
    }
    let t = &d.t_s;
    // Measured, the model before, and (when an effect was found) the model with it.
    let overlay = |measured: &[f64], pick: &dyn Fn(&Prediction) -> &[f64]| {
        let mut s = vec![
            line("measured", t, measured.iter().copied(), 0),
            line("model before", t, pick(before).iter().copied(), 1),
        ];
        if let Some((name, p)) = after {
            s.push(line(
                format!("model + {name}"),
                t,
                pick(p).iter().copied(),
                2,
            ));
        }
        s
    };
    v.push(over_time(
        "before_after_iqs",
        "I_qs: measured, model before and after adding the top effect",
        "I_qs [A]",
        overlay(&d.iq, &|p| &p.iq),
    ));
    if d.channels.speed {
        v.push(over_time(
            "before_after_omega_r",
            "omega_r: measured, model before and after adding the top effect",
            "omega_r [rad/s]",
            overlay(&d.omega_r, &|p| &p.omega_r),
        ));
    }
    let error = |p: &Prediction| {
        p.iq.iter()
            .zip(&d.iq)
            .map(|(a, b)| a - b)
            .collect::<Vec<_>>()
    };
    let mut s = vec![line("error before", t, error(before).into_iter(), 1)];
    if let Some((name, p)) = after {
        s.push(line(
            format!("error with {name}"),
            t,
            error(p).into_iter(),
            2,
        ));
    }
    v.push(over_time(
        "before_after_error",
        "I_qs error before and after",
        "error [A]",
        s,
    ));
    v
}
