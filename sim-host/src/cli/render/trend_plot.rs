//! `sim-host trend --plot`: the motors' indicators over time, one panel per indicator,
//! with the severity bands drawn (OK green, WATCH amber, FAULT red), written atomically.
//!
//! - `|I2w|/|I1|` in % of I1: FAULT from the level at which a single log's verdict names a
//!   short (the median `unbalance.least_change` of the plotted motors), WATCH from half of
//!   it, OK below.
//! - The parity residuals e_d, e_q, e_T in the motor's own scatters from its reference
//!   (its first healthy logs, or the baseline the user marks: `MotorTrend::reference`):
//!   OK within ±k reference scatters of the reference's centre, WATCH beyond (they have no
//!   FAULT level of their own: the isolation names a fault from their direction).
//! - Where a shown motor has too few logs for a reference scatter, the panel draws the
//!   stored values (in pu, without bands) and its title says so; where an indicator has no
//!   operating-point fit, its values are the stored ones, and the title says that too.
//!
//! - An indicator none of the shown motors' logs measured (the residuals and Rs beyond Rr
//!   of logs without voltages) has no panel: it is absent, not a flat line at zero.
//!
//! At most [`MAX_MOTORS`] motors are drawn: the first of the ranking (alarmed first).

use monitor_store::trend::{IndicatorTrend, MotorTrend, TrendOptions};
use plotters::coord::types::RangedCoordf64;
use plotters::prelude::*;
use std::path::Path;

use super::plot::{LegendEntry, PALETTE};

/// The most motors one plot draws.
pub const MAX_MOTORS: usize = 6;

const OK: RGBColor = RGBColor(220, 242, 220);
const WATCH: RGBColor = RGBColor(253, 238, 200);
const FAULT: RGBColor = RGBColor(250, 215, 215);

/// One panel: indicator column, title, and whether it is drawn in scatters.
pub type TrendPanel = (&'static str, &'static str, bool);

/// The panels: indicator column, title, and whether it is drawn in scatters.
const PANELS: [TrendPanel; 5] = [
    (
        "i2_over_i1",
        "|I2w|/|I1| [% of I1] (a short grows it)",
        false,
    ),
    (
        "residual_d",
        "e_d [scatters from the motor's reference]",
        true,
    ),
    (
        "residual_q",
        "e_q [scatters from the motor's reference]",
        true,
    ),
    (
        "residual_t",
        "e_T [scatters from the motor's reference]",
        true,
    ),
    (
        "stator_excess_pct",
        "Rs beyond Rr [scatters from the motor's reference] (a loosening connection raises it)",
        true,
    ),
];

/// One motor's line in a panel: its name, points (day, value) and palette index.
type PlotLine = (String, Vec<(f64, f64)>, usize);

/// One motor's points of one panel: (day, value in the panel's unit): in reference
/// scatters from the reference's centre where `in_scatters` (none without a reference
/// scatter), else the values (the normalised ones, the stored ones where there was no
/// operating-point fit) times `scale`.
pub fn points(
    t: &IndicatorTrend,
    in_scatters: bool,
    scale: f64,
    t0: f64,
) -> Option<Vec<(f64, f64)>> {
    let (centre, scatter) = if in_scatters {
        (t.reference_centre?, t.reference_scatter?)
    } else {
        (0.0, 1.0 / scale)
    };
    Some(
        t.series
            .iter()
            .map(|p| (p.t_days - t0, (p.normalised - centre) / scatter))
            .collect(),
    )
}

/// How a panel draws `column` for these motors: in reference scatters (where `in_scatters`
/// and every shown motor has a reference scatter) or in the stored unit, and its title with
/// what is drawn where it is not what the panel is for.
pub fn panel_mode(
    motors: &[&MotorTrend],
    opts: &TrendOptions,
    column: &str,
    title: &str,
    in_scatters: bool,
) -> (bool, String) {
    let shown: Vec<&IndicatorTrend> = motors
        .iter()
        .filter_map(|m| m.indicators.iter().find(|t| t.indicator == column))
        .collect();
    let unfitted = shown.iter().any(|t| !t.operating_point_fitted);
    let no_scatter: Vec<usize> = shown
        .iter()
        .filter(|t| t.reference_scatter.is_none())
        .map(|t| t.series.iter().filter(|p| p.in_reference).count())
        .collect();
    if in_scatters && !no_scatter.is_empty() {
        let few = no_scatter.iter().copied().min().unwrap_or_default();
        let label = title.split(" [").next().unwrap_or(title);
        return (
            false,
            format!(
                "{label} [pu, the stored values: too few reference logs for a scatter ({few} of {})]",
                opts.min_logs.max(3)
            ),
        );
    }
    let title = if unfitted {
        format!("{title}; stored values, no operating-point fit")
    } else {
        title.to_string()
    };
    (in_scatters, title)
}

/// The panels of the indicators some of `motors` has (an indicator no log measured is left
/// out of the motor's trend); the first panel where none has any.
pub fn panels_of(motors: &[&MotorTrend]) -> Vec<TrendPanel> {
    let has = |column: &str| {
        motors
            .iter()
            .any(|m| m.indicators.iter().any(|t| t.indicator == column))
    };
    let panels: Vec<TrendPanel> = PANELS.iter().copied().filter(|p| has(p.0)).collect();
    if panels.is_empty() {
        PANELS.iter().take(1).copied().collect()
    } else {
        panels
    }
}

/// Draws the plot into `path` (`.svg` or `.png`, by its extension).
///
/// # Errors
/// A drawing or writing error, as one line.
pub fn write(path: &Path, motors: &[MotorTrend], opts: &TrendOptions) -> Result<(), String> {
    let shown: Vec<&MotorTrend> = motors.iter().take(MAX_MOTORS).collect();
    let panels = panels_of(&shown);
    let size = (900u32, 260u32 * panels.len() as u32);
    let png = path.extension().and_then(|e| e.to_str()) == Some("png");
    if png {
        let dir = path
            .parent()
            .filter(|d| !d.as_os_str().is_empty())
            .unwrap_or(Path::new("."));
        let mut b = tempfile::Builder::new();
        b.prefix(".sim-host-").suffix(".png");
        // The mode of any new file (0o666 less the umask), as the SVG gets.
        #[cfg(unix)]
        {
            use std::os::unix::fs::PermissionsExt;
            b.permissions(std::fs::Permissions::from_mode(0o666));
        }
        let tmp = b
            .tempfile_in(dir)
            .map_err(|e| format!("{}: {e}", dir.display()))?;
        {
            let root = BitMapBackend::new(tmp.path(), size).into_drawing_area();
            draw(root, &shown, &panels, opts)?;
        }
        tmp.persist(path).map_err(|e| e.error.to_string())?;
        return Ok(());
    }
    let mut svg = String::new();
    let legend = {
        let root = SVGBackend::with_string(&mut svg, size).into_drawing_area();
        draw(root, &shown, &panels, opts)?
    };
    let svg = super::plot::described(svg, "The motors' indicators over time", &legend);
    monitor_api::files::write_atomic(path, svg.as_bytes()).map_err(|e| e.to_string())
}

/// Draws every panel into `root`; returns the legend as drawn: each motor named once, on
/// the first panel where it has a point ([`draw_lines`]).
fn draw<DB: DrawingBackend>(
    root: DrawingArea<DB, plotters::coord::Shift>,
    motors: &[&MotorTrend],
    panels: &[TrendPanel],
    opts: &TrendOptions,
) -> Result<Vec<LegendEntry>, String>
where
    DB::ErrorType: 'static,
{
    super::plot::register_font()?;
    let e = |x: DrawingAreaErrorKind<DB::ErrorType>| x.to_string();
    root.fill(&WHITE).map_err(e)?;
    let t0 = motors
        .iter()
        .flat_map(|m| m.indicators.iter())
        .filter_map(|t| t.series.first().map(|p| p.t_days.floor()))
        .fold(f64::INFINITY, f64::min);
    let t0 = if t0.is_finite() { t0 } else { 0.0 };
    let areas = root.split_evenly((panels.len(), 1));
    let mut legend = Vec::new();
    for (k, (panel, area)) in panels.iter().zip(&areas).enumerate() {
        let last = k + 1 == panels.len();
        draw_panel(area, motors, opts, panel, (k, last, t0), &mut legend)?;
    }
    root.present().map_err(e)?;
    Ok(legend)
}

/// The panel's y range and band levels: (y0, y1, WATCH level, FAULT level); with `raw`
/// (the stored values, no bands) the values' own range.
fn panel_range(
    series: &[PlotLine],
    motors: &[&MotorTrend],
    opts: &TrendOptions,
    column: &str,
    in_scatters: bool,
    raw: bool,
) -> (f64, f64, f64, Option<f64>) {
    let (mut y0, mut y1) = (f64::INFINITY, f64::NEG_INFINITY);
    for &(_, y) in series.iter().flat_map(|s| s.1.iter()) {
        if y.is_finite() {
            y0 = y0.min(y);
            y1 = y1.max(y);
        }
    }
    let (watch, fault) = if in_scatters {
        (opts.k_scatter, None)
    } else {
        let mut lv: Vec<f64> = motors
            .iter()
            .filter_map(|m| m.indicators.iter().find(|t| t.indicator == column))
            .filter_map(|t| t.fault_level)
            .collect();
        let f = monitor_store::trend::stats::median(&mut lv).map(|x| 100.0 * x);
        (f.map_or(f64::INFINITY, |f| 0.5 * f), f)
    };
    if !y0.is_finite() {
        (y0, y1) = (-1.0, 1.0);
    }
    if raw {
        let pad = 0.08 * (y1 - y0).max(1e-9 * y1.abs().max(y0.abs()).max(1e-12));
        return (y0 - pad, y1 + pad, watch, fault);
    }
    // No FAULT level (no motor shown has one): no band to make room for (an infinite
    // WATCH level would make the range infinite, and the axis's labels never end).
    let top = fault.map_or(watch, |f| 1.15 * f);
    if top.is_finite() {
        y1 = y1.max(top);
    }
    if in_scatters {
        y0 = y0.min(-1.3 * watch);
        y1 = y1.max(1.3 * watch);
    } else {
        y0 = y0.min(0.0);
    }
    let pad = 0.04 * (y1 - y0).max(1e-9);
    (y0 - pad, y1 + pad, watch, fault)
}

/// Draws panel `k` (indicator `panel`, days from `t0`) of the motors' lines with its bands,
/// naming in its legend the motors not yet in `legend` ([`draw_lines`]).
fn draw_panel<DB: DrawingBackend>(
    area: &DrawingArea<DB, plotters::coord::Shift>,
    motors: &[&MotorTrend],
    opts: &TrendOptions,
    &(column, title, in_scatters): &TrendPanel,
    (k, last, t0): (usize, bool, f64),
    legend: &mut Vec<LegendEntry>,
) -> Result<(), String>
where
    DB::ErrorType: 'static,
{
    let e = |x: DrawingAreaErrorKind<DB::ErrorType>| x.to_string();
    let (in_scatters, title) = panel_mode(motors, opts, column, title, in_scatters);
    let scale = if column == "i2_over_i1" { 100.0 } else { 1.0 };
    let series: Vec<PlotLine> = motors
        .iter()
        .enumerate()
        .filter_map(|(i, m)| {
            let t = m.indicators.iter().find(|t| t.indicator == column)?;
            Some((m.motor.clone(), points(t, in_scatters, scale, t0)?, i))
        })
        .collect();
    let x1 = series
        .iter()
        .flat_map(|s| s.1.iter().map(|p| p.0))
        .fold(1.0f64, f64::max);
    let raw = !in_scatters && column != "i2_over_i1";
    let (y0, y1, watch, fault) = panel_range(&series, motors, opts, column, in_scatters, raw);
    let caption = if k == 0 {
        format!("{title}; days from {}", monitor_store::trend::day_of(t0))
    } else {
        title.to_string()
    };
    let mut chart = ChartBuilder::on(area)
        .margin(8)
        .caption(caption, ("sans-serif", 16))
        .x_label_area_size(28)
        .y_label_area_size(60)
        .build_cartesian_2d(0.0..x1, y0..y1)
        .map_err(e)?;
    let bands = if raw {
        // The stored values without a reference scatter: no band to draw.
        Vec::new()
    } else {
        bands(x1, (y0, y1), watch, fault, in_scatters)
    };
    chart.draw_series(bands).map_err(e)?;
    chart
        .configure_mesh()
        .x_desc(if last { "day" } else { "" })
        .light_line_style(WHITE.mix(0.0))
        .draw()
        .map_err(e)?;
    draw_lines(&mut chart, series, legend)
}

/// The severity bands over `0..x1` and `y0..y1`: in scatters, OK within ±`watch` and
/// WATCH beyond; else OK below `watch`, WATCH to `fault`, FAULT above.
fn bands(
    x1: f64,
    (y0, y1): (f64, f64),
    watch: f64,
    fault: Option<f64>,
    in_scatters: bool,
) -> Vec<Rectangle<(f64, f64)>> {
    let rect = |lo: f64, hi: f64, c: RGBColor| Rectangle::new([(0.0, lo), (x1, hi)], c.filled());
    if in_scatters {
        vec![
            rect(y0, -watch, WATCH),
            rect(-watch, watch, OK),
            rect(watch, y1, WATCH),
        ]
    } else {
        let (w, f) = (watch.min(y1), fault.unwrap_or(y1).min(y1));
        vec![rect(y0, w, OK), rect(w, f, WATCH), rect(f, y1, FAULT)]
    }
}

/// Draws the motors' lines (points joined), and a legend naming each motor drawn here with
/// at least one point that `legend` (the entries of the panels above) does not name yet:
/// every motor is named once, beside a line of its own (a motor with nothing to draw on the
/// first panel is named on the next one where it has a point).
fn draw_lines<'a, DB: DrawingBackend + 'a>(
    chart: &mut ChartContext<'a, DB, Cartesian2d<RangedCoordf64, RangedCoordf64>>,
    series: Vec<PlotLine>,
    legend: &mut Vec<LegendEntry>,
) -> Result<(), String>
where
    DB::ErrorType: 'static,
{
    let e = |x: DrawingAreaErrorKind<DB::ErrorType>| x.to_string();
    let mut named_here = false;
    for (name, pts, i) in series {
        let col = PALETTE[i % PALETTE.len()];
        let ys: Vec<f64> = pts
            .iter()
            .filter(|p| p.0.is_finite() && p.1.is_finite())
            .map(|p| p.1)
            .collect();
        let name_it = !ys.is_empty() && legend.iter().all(|l| l.label != name);
        if name_it {
            legend.push(LegendEntry {
                label: name.clone(),
                look: super::plot::look(i, false, false),
                points: ys.len(),
                y_range: (!ys.is_empty()).then(|| {
                    (
                        ys.iter().copied().fold(f64::INFINITY, f64::min),
                        ys.iter().copied().fold(f64::NEG_INFINITY, f64::max),
                    )
                }),
            });
        }
        chart
            .draw_series(pts.iter().map(|&p| Circle::new(p, 2, col.filled())))
            .map_err(e)?;
        let a = chart
            .draw_series(LineSeries::new(pts, col.stroke_width(2)))
            .map_err(e)?;
        if name_it {
            named_here = true;
            a.label(name).legend(move |(x, y)| {
                PathElement::new(vec![(x, y), (x + 16, y)], col.stroke_width(2))
            });
        }
    }
    if named_here {
        chart
            .configure_series_labels()
            .position(SeriesLabelPosition::UpperLeft)
            .background_style(WHITE.mix(0.85))
            .border_style(BLACK)
            .draw()
            .map_err(e)?;
    }
    Ok(())
}
