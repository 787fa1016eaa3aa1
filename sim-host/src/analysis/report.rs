//! Plot sets and the one-page HTML report of `compare` and `explain`.
//!
//! The report embeds the SVG charts inline, so `report.html` is one self-contained file;
//! the PNG copies sit beside it for slides and tickets.

use super::metrics::{self, WorstWindow};
use super::model::Prediction;
use super::plot::{self, Chart, Series};
use super::prep::Prepared;
use super::{CompareOutput, ExplainOutput};
use std::fmt::Write as _;
use std::path::Path;

const MAX_POINTS: usize = 4000;

/// (file stem, title, x label, points) of an error-vs-condition chart.
type ScatterSpec = (&'static str, &'static str, &'static str, Vec<(f64, f64)>);

fn pts(t: &[f64], y: impl Iterator<Item = f64>) -> Vec<(f64, f64)> {
    plot::thin(&t.iter().copied().zip(y).collect::<Vec<_>>(), MAX_POINTS)
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
    v.push(Chart {
        stem: "overlay_iqs",
        title: "I_qs: measured vs model",
        x_label: "time [s]",
        y_label: "I_qs [A]",
        series: vec![
            Series {
                label: "measured".into(),
                points: pts(&d.t_s, d.iq.iter().copied()),
                color: 0,
                scatter: false,
            },
            Series {
                label: "model".into(),
                points: pts(&d.t_s, p.iq.iter().copied()),
                color: 1,
                scatter: false,
            },
        ],
        log_y: false,
    });
    if d.channels.speed {
        v.push(Chart {
            stem: "overlay_omega_r",
            title: "omega_r (electrical rotor speed): measured vs model",
            x_label: "time [s]",
            y_label: "omega_r [rad/s]",
            series: vec![
                Series {
                    label: "measured".into(),
                    points: pts(&d.t_s, d.omega_r.iter().copied()),
                    color: 0,
                    scatter: false,
                },
                Series {
                    label: "model".into(),
                    points: pts(&d.t_s, p.omega_r.iter().copied()),
                    color: 1,
                    scatter: false,
                },
            ],
            log_y: false,
        });
    }
    let (a, b) = zoom(d, &out.report.worst_windows);
    let ia_m: Vec<f64> = (a..b).map(|k| metrics::measured(d, k)[2]).collect();
    let ia_p: Vec<f64> = (a..b).map(|k| metrics::predicted(d, p, k)[2]).collect();
    v.push(Chart {
        stem: "overlay_ia",
        title: "Phase current i_a around the worst window: measured vs model",
        x_label: "time [s]",
        y_label: "i_a [A]",
        series: vec![
            Series {
                label: "measured".into(),
                points: pts(&d.t_s[a..b], ia_m.into_iter()),
                color: 0,
                scatter: false,
            },
            Series {
                label: "model".into(),
                points: pts(&d.t_s[a..b], ia_p.into_iter()),
                color: 1,
                scatter: false,
            },
        ],
        log_y: false,
    });
    let eiq: Vec<f64> = p.iq.iter().zip(&d.iq).map(|(a, b)| a - b).collect();
    let mut err_series = vec![Series {
        label: "I_qs error [A]".into(),
        points: pts(&d.t_s, eiq.iter().copied()),
        color: 1,
        scatter: false,
    }];
    if d.channels.speed {
        err_series.push(Series {
            label: "omega_r error [rad/s]".into(),
            points: pts(&d.t_s, p.omega_r.iter().zip(&d.omega_r).map(|(a, b)| a - b)),
            color: 2,
            scatter: false,
        });
    }
    v.push(Chart {
        stem: "error_time",
        title: "Model error vs time (model - measured)",
        x_label: "time [s]",
        y_label: "error",
        series: err_series,
        log_y: false,
    });
    let all = &out.all_windows;
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
    for (stem, title, xl, points) in vs {
        v.push(Chart {
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
        });
    }
    let sp = metrics::spectrum(&eiq, d.dt_s);
    v.push(Chart {
        stem: "error_spectrum",
        title: "Spectrum of the I_qs error",
        x_label: "frequency [Hz]",
        y_label: "amplitude [A]",
        series: vec![Series {
            label: "I_qs error".into(),
            points: sp,
            color: 4,
            scatter: false,
        }],
        log_y: true,
    });
    v
}

/// Before/after charts of `explain`: I_qs and omega_r overlays of measured, the configured
/// model, and the model with the top-ranked effect.
pub fn explain_charts(
    d: &Prepared,
    before: &Prediction,
    after: Option<&(String, Prediction)>,
) -> Vec<Chart<'static>> {
    let mut v = Vec::new();
    if before.iq.is_empty() {
        return v;
    }
    let mut s = vec![
        Series {
            label: "measured".into(),
            points: pts(&d.t_s, d.iq.iter().copied()),
            color: 0,
            scatter: false,
        },
        Series {
            label: "model before".into(),
            points: pts(&d.t_s, before.iq.iter().copied()),
            color: 1,
            scatter: false,
        },
    ];
    if let Some((name, p)) = after {
        s.push(Series {
            label: format!("model + {name}"),
            points: pts(&d.t_s, p.iq.iter().copied()),
            color: 2,
            scatter: false,
        });
    }
    v.push(Chart {
        stem: "before_after_iqs",
        title: "I_qs: measured, model before and after adding the top effect",
        x_label: "time [s]",
        y_label: "I_qs [A]",
        series: s,
        log_y: false,
    });
    if d.channels.speed {
        let mut s = vec![
            Series {
                label: "measured".into(),
                points: pts(&d.t_s, d.omega_r.iter().copied()),
                color: 0,
                scatter: false,
            },
            Series {
                label: "model before".into(),
                points: pts(&d.t_s, before.omega_r.iter().copied()),
                color: 1,
                scatter: false,
            },
        ];
        if let Some((name, p)) = after {
            s.push(Series {
                label: format!("model + {name}"),
                points: pts(&d.t_s, p.omega_r.iter().copied()),
                color: 2,
                scatter: false,
            });
        }
        v.push(Chart {
            stem: "before_after_omega_r",
            title: "omega_r: measured, model before and after adding the top effect",
            x_label: "time [s]",
            y_label: "omega_r [rad/s]",
            series: s,
            log_y: false,
        });
    }
    let mut s = vec![Series {
        label: "error before".into(),
        points: pts(&d.t_s, before.iq.iter().zip(&d.iq).map(|(a, b)| a - b)),
        color: 1,
        scatter: false,
    }];
    if let Some((name, p)) = after {
        s.push(Series {
            label: format!("error with {name}"),
            points: pts(&d.t_s, p.iq.iter().zip(&d.iq).map(|(a, b)| a - b)),
            color: 2,
            scatter: false,
        });
    }
    v.push(Chart {
        stem: "before_after_error",
        title: "I_qs error before and after",
        x_label: "time [s]",
        y_label: "error [A]",
        series: s,
        log_y: false,
    });
    v
}

/// Writes the charts into `dir` (created if needed); returns (stem, svg) pairs.
pub fn write_charts(dir: &Path, charts: &[Chart]) -> Result<Vec<(String, String)>, String> {
    std::fs::create_dir_all(dir).map_err(|e| format!("{}: {e}", dir.display()))?;
    let mut v = Vec::new();
    for c in charts {
        let (svg, _) = plot::write(dir, c)?;
        v.push((c.stem.to_string(), svg));
    }
    Ok(v)
}

fn esc(s: &str) -> String {
    s.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
}

const STYLE: &str = "body{font-family:sans-serif;max-width:1000px;margin:2em auto;color:#222}table{border-collapse:collapse;margin:1em 0}td,th{border:1px solid #bbb;padding:4px 8px;text-align:right}th{background:#eee}td.l,th.l{text-align:left}.v{font-size:1.2em;background:#f4f4dc;padding:.6em;border-left:4px solid #cc4}";

/// The `compare` report page.
pub fn compare_html(log: &str, out: &CompareOutput, charts: &[(String, String)]) -> String {
    let r = &out.report;
    let mut h = String::new();
    let _ = write!(h, "<!doctype html><html><head><meta charset=utf-8><title>compare: {}</title><style>{STYLE}</style></head><body>", esc(log));
    let _ = write!(h, "<h1>Model vs measurement</h1><p>Log <code>{}</code>: {} rows at {:.0} Hz ({:.2} s), analysed at {:.0} Hz in the {}.</p>", esc(log), r.data.rows, r.data.log_rate_hz, r.data.duration_s, r.data.working_rate_hz, esc(&r.data.frame));
    let eff = if r.effects.is_empty() {
        "none (the paper's model, eqs. 28-29)".to_string()
    } else {
        r.effects.join(", ")
    };
    let _ = write!(h, "<p class=v>Effects in the model: <b>{}</b>. Normalized RMS error <b>{:.4}</b> (noise floor {:.4}: a perfect model would score about this).</p>", esc(&eff), r.normalized_rms_error, r.noise_floor);
    for s in &r.skipped {
        let _ = write!(h, "<p><i>{}</i></p>", esc(s));
    }
    h.push_str("<h2>Error per channel</h2><table><tr><th class=l>channel</th><th>RMS error</th><th>RMS measured</th><th>normalized</th></tr>");
    for c in &r.channels {
        let _ = write!(
            h,
            "<tr><td class=l>{}</td><td>{:.4}</td><td>{:.4}</td><td>{:.4}</td></tr>",
            c.channel, c.rms_error, c.rms_measured, c.normalized
        );
    }
    h.push_str("</table><h2>Where the model fails most</h2><table><tr><th>from [s]</th><th>to [s]</th><th>error</th><th>speed [rpm]</th><th>load I_qs [A]</th><th>voltage [%]</th><th>supply [Hz]</th><th>since start [s]</th><th class=l>error is mostly</th></tr>");
    for w in &r.worst_windows {
        let _ = write!(h, "<tr><td>{:.2}</td><td>{:.2}</td><td>{:.4}</td><td>{}</td><td>{:.2}</td><td>{:.1}</td><td>{:.1}</td><td>{:.2}</td><td class=l>{}</td></tr>", w.t_start_s, w.t_end_s, w.normalized_rms_error, w.condition.speed_rpm.map(|s| format!("{s:.0}")).unwrap_or("-".into()), w.condition.load_current_a, w.condition.voltage_percent, w.condition.supply_hz, w.condition.time_since_start_s, esc(&w.error_kind));
    }
    h.push_str("</table><h2>Fitted parameters</h2><p>Nominal values are never exact; the parameters the data identify are refitted.</p><table><tr><th class=l>parameter</th><th>fitted</th><th>nominal</th><th class=l>unit</th></tr>");
    for (k, v) in &r.base_parameters {
        let _ = write!(
            h,
            "<tr><td class=l>{}</td><td>{:.5}</td><td>{:.5}</td><td class=l>{}</td></tr>",
            k,
            v.value,
            v.nominal.unwrap_or(f64::NAN),
            esc(&v.unit)
        );
    }
    h.push_str("</table>");
    for e in &r.fitted_effects {
        let _ = write!(h, "<p><b>{}</b>: {}</p>", e.effect, esc(&e.summary));
    }
    let _ = write!(h, "<h2>Unbalance</h2><p>{}</p>", esc(&r.unbalance.summary));
    for (stem, svg) in charts {
        let _ = write!(h, "<h3>{stem}</h3>{svg}");
    }
    h.push_str("<p>Next step: <code>sim-host explain</code> ranks the physical effects that could remove this error.</p></body></html>");
    h
}

/// The `explain` report page.
pub fn explain_html(log: &str, out: &ExplainOutput, charts: &[(String, String)]) -> String {
    let r = &out.report;
    let mut h = String::new();
    let _ = write!(h, "<!doctype html><html><head><meta charset=utf-8><title>explain: {}</title><style>{STYLE}</style></head><body>", esc(log));
    let _ = write!(h, "<h1>Which physical effect is missing?</h1><p>Log <code>{}</code>. Effects already in the model: {}.</p>", esc(log), if r.effects.is_empty() { "none".into() } else { r.effects.join(", ") });
    let _ = write!(h, "<p class=v>{}</p>", esc(&r.verdict));
    let _ = write!(h, "<p>Error of the model as configured: {:.4} (whole log), {:.4} on the held-back windows the fits never saw; noise floor {:.4}. Each candidate below was added to the model and fitted together with the base parameters; ranking is by the held-back error, so an effect that only fits noise does not win.</p>", r.baseline_normalized_rms_error, r.baseline_validation_normalized_rms_error, r.noise_floor);
    h.push_str("<table><tr><th>rank</th><th class=l>effect</th><th>error</th><th>held-back error</th><th>explained</th><th>params</th><th class=l>fitted, in words</th></tr>");
    for (i, c) in r.ranking.iter().enumerate() {
        let _ = write!(h, "<tr><td>{}</td><td class=l>{}</td><td>{:.4}</td><td>{:.4}</td><td>{:.0} %</td><td>{}</td><td class=l>{}</td></tr>", i + 1, c.effect, c.normalized_rms_error, c.validation_normalized_rms_error, 100.0 * c.explained_fraction, c.n_parameters, esc(&c.summary));
    }
    h.push_str("</table>");
    if let Some(c) = r.ranking.first() {
        let _ = write!(h, "<h2>Before / after</h2><table><tr><th class=l>model</th><th>normalized RMS error</th></tr><tr><td class=l>as configured</td><td>{:.4}</td></tr><tr><td class=l>+ {}</td><td>{:.4}</td></tr></table>", r.baseline_normalized_rms_error, c.effect, c.normalized_rms_error);
    }
    for s in &r.skipped {
        let _ = write!(h, "<p><i>skipped: {}</i></p>", esc(s));
    }
    let _ = write!(h, "<h2>Unbalance</h2><p>{}</p>", esc(&r.unbalance.summary));
    for (stem, svg) in charts {
        let _ = write!(h, "<h3>{stem}</h3>{svg}");
    }
    h.push_str("</body></html>");
    h
}
