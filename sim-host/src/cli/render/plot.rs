//! Plots: every chart is written as SVG and as PNG, both with title, axis labels, tick
//! labels and legend.
//!
//! PNG text needs a font: DejaVu Sans (`assets/fonts/DejaVuSans.ttf`, its licence beside
//! it) is embedded in the binary and registered with plotters' `ab_glyph` backend as
//! "sans-serif" before the first chart is drawn ([`FONT`]), so no system font package is
//! needed, in CI or on a user's machine. Outputs are written atomically (temporary file,
//! then rename).
//!
//! A chart draws what it names: every legend entry is a series, and the SVG carries, for
//! the reader that cannot see it (a screen reader, a test), its title and each legend
//! entry with the points drawn ([`legend`], in the SVG's `<desc>`): a test over every chart
//! the tool writes holds each entry to at least one point drawn.

use plotters::coord::ranged1d::{SegmentedCoord, ValueFormatter};
use plotters::coord::types::RangedCoordi32;
use plotters::element::DashedPathElement;
use plotters::prelude::*;
use std::path::{Path, PathBuf};

/// One curve (or point cloud) of a chart.
pub struct Series {
    /// Legend label.
    pub label: String,
    /// (x, y) points.
    pub points: Vec<(f64, f64)>,
    /// Colour index into the palette.
    pub color: usize,
    /// Draw as points instead of a line.
    pub scatter: bool,
    /// Draw the line dashed (the model before a change, drawn last so that it lies on top).
    pub dashed: bool,
}

/// A chart description.
pub struct Chart<'a> {
    /// File stem (`overlay_iqs` -> `overlay_iqs.svg`, `overlay_iqs.png`).
    pub stem: &'a str,
    /// Title.
    pub title: &'a str,
    /// X axis label.
    pub x_label: &'a str,
    /// Y axis label.
    pub y_label: &'a str,
    /// Curves.
    pub series: Vec<Series>,
    /// Logarithmic y axis.
    pub log_y: bool,
    /// Why the chart is not drawn (a sentence for the report in its place), or `None`.
    pub omitted: Option<String>,
    /// The names of the x axis' whole positions `0, 1, ..`: each gets a tick with its name
    /// (the ladder's steps); empty for a numeric axis.
    pub x_names: Vec<String>,
}

/// A legend entry and what was drawn of it ([`legend`]).
#[derive(Debug, Clone, PartialEq)]
pub struct LegendEntry {
    /// The label the legend shows.
    pub label: String,
    /// How it is drawn: its colour and stroke (`#1F77B4 line`, `#D62728 dashed line`,
    /// `#FF7F0E points`); no two entries of a chart look alike.
    pub look: String,
    /// Points drawn (finite, and above 0 on a logarithmic axis).
    pub points: usize,
    /// The lowest and the highest value drawn (y), `None` without a point.
    pub y_range: Option<(f64, f64)>,
}

/// The points of `points` a chart draws: finite, and above 0 on a logarithmic axis.
fn drawable(p: &(f64, f64), log_y: bool) -> bool {
    p.0.is_finite() && p.1.is_finite() && (!log_y || p.1 > 0.0)
}

/// How a series of palette colour `color` is drawn, as [`LegendEntry::look`] says it.
pub(crate) fn look(color: usize, dashed: bool, scatter: bool) -> String {
    let RGBColor(r, g, b) = PALETTE[color % PALETTE.len()];
    let stroke = match (scatter, dashed) {
        (true, _) => "points",
        (false, true) => "dashed line",
        (false, false) => "line",
    };
    format!("#{r:02X}{g:02X}{b:02X} {stroke}")
}

/// The legend of chart `c` as drawn: each series' label with the points drawn of it (the
/// same filter the drawing uses), in the legend's order.
pub fn legend(c: &Chart) -> Vec<LegendEntry> {
    c.series
        .iter()
        .map(|s| {
            let ys: Vec<f64> = s
                .points
                .iter()
                .filter(|p| drawable(p, c.log_y))
                .map(|p| p.1)
                .collect();
            let lo = ys.iter().copied().fold(f64::INFINITY, f64::min);
            let hi = ys.iter().copied().fold(f64::NEG_INFINITY, f64::max);
            LegendEntry {
                label: s.label.clone(),
                look: look(s.color, s.dashed, s.scatter),
                points: ys.len(),
                y_range: (!ys.is_empty()).then_some((lo, hi)),
            }
        })
        .collect()
}

/// `svg` with its `<title>` and `<desc>` (inserted as the root's first children): the
/// chart's `title`, and its legend as drawn (`entries`), one line per entry with its look,
/// its points and the range of their values (`measured [#1F77B4 line]: 812 points, y from
/// -0.5 to 12`, `model [#D62728 line]: 0 points`) after a first line `legend:`.
pub fn described(svg: String, title: &str, entries: &[LegendEntry]) -> String {
    let lines: Vec<String> = entries
        .iter()
        .map(|e| match e.y_range {
            Some((lo, hi)) => format!(
                "{} [{}]: {} points, y from {lo} to {hi}",
                e.label, e.look, e.points
            ),
            None => format!("{} [{}]: 0 points", e.label, e.look),
        })
        .collect();
    let extra = format!(
        "<title>{}</title><desc>legend:\n{}</desc>",
        xml_escape(title),
        xml_escape(&lines.join("\n"))
    );
    match svg
        .find("<svg")
        .and_then(|a| svg[a..].find('>').map(|b| a + b + 1))
    {
        Some(k) => format!("{}{extra}{}", &svg[..k], &svg[k..]),
        None => svg,
    }
}

/// Text escaped for XML.
fn xml_escape(s: &str) -> String {
    s.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
}

/// Width of every chart [px].
pub const WIDTH_PX: u32 = 900;
/// Height of every chart [px] (a named axis' upright names add theirs, [`height`]).
const HEIGHT_PX: u32 = 420;
/// Width a character of a tick label takes, about (DejaVu Sans at the mesh's 12 px) [px].
const LABEL_CHAR_PX: u32 = 6;

/// The longest name of a named axis, in label pixels ([`LABEL_CHAR_PX`]), when the names
/// stand upright (rotated a quarter turn) because one would not fit its step's width on
/// the line; 0 when they lie on one line (or the axis is numeric).
fn upright_names_px(c: &Chart) -> u32 {
    let n = c.x_names.len().max(1) as u32;
    let longest = c
        .x_names
        .iter()
        .map(|s| s.chars().count())
        .max()
        .unwrap_or(0) as u32;
    let px = longest * LABEL_CHAR_PX;
    // The plot is the chart less the y labels' area and the margins.
    if px > (WIDTH_PX - 100) / n {
        px
    } else {
        0
    }
}

/// The chart's height [px]: [`HEIGHT_PX`], and room for upright names below the plot.
fn height(c: &Chart) -> u32 {
    HEIGHT_PX + upright_names_px(c)
}

/// A tick label of a logarithmic axis: a power of ten as a number where it is short
/// (`0.001`, `100`), else as `1e-5`; any other value with two digits (`2.5e-5`). (The axis'
/// own formatting printed 1e-4 as `9.999999999e-5`.)
fn log_tick(v: &f64) -> String {
    if !(v.is_finite() && *v > 0.0) {
        return String::new();
    }
    let e = v.log10().round();
    let m = v / 10f64.powf(e);
    if (m - 1.0).abs() < 1e-6 {
        if (-3.0..=3.0).contains(&e) {
            format!("{}", 10f64.powi(e as i32))
        } else {
            format!("1e{e}")
        }
    } else {
        format!("{v:.1e}")
    }
}

/// Where the legend goes: the corner of the plot (or the right's middle) the series cross
/// least, counted on their points and, for lines, on points along their segments, in the
/// plot's own scale (`log_y`: the logarithm's) within `ranges`; and how many points cross
/// it.
fn legend_position(
    c: &Chart,
    ((x0, x1), (y0, y1)): ((f64, f64), (f64, f64)),
) -> (SeriesLabelPosition, usize) {
    let ty = |y: f64| {
        if c.log_y {
            y.max(f64::MIN_POSITIVE).log10()
        } else {
            y
        }
    };
    let (ly0, ly1) = (ty(y0), ty(y1));
    let (w, hgt) = (
        (x1 - x0).max(f64::MIN_POSITIVE),
        (ly1 - ly0).max(f64::MIN_POSITIVE),
    );
    // The candidates' boxes as shares of the plot: (x from, x to, y from, y to), y upwards.
    let boxes = [
        (SeriesLabelPosition::UpperRight, (0.6, 1.0, 0.65, 1.0)),
        (SeriesLabelPosition::UpperLeft, (0.0, 0.4, 0.65, 1.0)),
        (SeriesLabelPosition::LowerRight, (0.6, 1.0, 0.0, 0.35)),
        (SeriesLabelPosition::LowerLeft, (0.0, 0.4, 0.0, 0.35)),
        (SeriesLabelPosition::MiddleRight, (0.6, 1.0, 0.33, 0.67)),
    ];
    let mut counts = [0usize; 5];
    for s in &c.series {
        let pts: Vec<(f64, f64)> = s
            .points
            .iter()
            .filter(|p| drawable(p, c.log_y))
            .map(|&(x, y)| ((x - x0) / w, (ty(y) - ly0) / hgt))
            .collect();
        let along = !s.scatter && pts.len() < 400;
        let mut visit = |(x, y): (f64, f64)| {
            for (k, (_, (a, b, lo, hi))) in boxes.iter().enumerate() {
                if (*a..=*b).contains(&x) && (*lo..=*hi).contains(&y) {
                    counts[k] += 1;
                }
            }
        };
        for (k, &p) in pts.iter().enumerate() {
            visit(p);
            if along && k > 0 {
                let q = pts[k - 1];
                for j in 1..10 {
                    let f = f64::from(j) / 10.0;
                    visit((q.0 + f * (p.0 - q.0), q.1 + f * (p.1 - q.1)));
                }
            }
        }
    }
    let best = (0..boxes.len()).min_by_key(|&k| counts[k]).unwrap_or(0);
    (
        boxes
            .into_iter()
            .nth(best)
            .map_or(SeriesLabelPosition::UpperRight, |b| b.0),
        counts[best],
    )
}

/// Height of one legend entry [px] and the legend box's margins, as plotters draws them
/// at the legend's font (about).
const LEGEND_ROW_PX: f64 = 20.0;
/// The plot's own height within the chart [px]: the chart's less its caption, its x
/// labels and its margins (about).
const PLOT_PX: f64 = HEIGHT_PX as f64 - 110.0;

/// Where the legend goes and the y range that leaves it room: the corner the series cross
/// least ([`legend_position`]) where none crosses it; else the upper right, over headroom
/// added above the data as tall as the legend (its entries, [`LEGEND_ROW_PX`] each), so
/// that the legend never covers data (on the rotor's, the lamps' and the residuals' charts
/// it did where every corner held some). Without text, no legend: the ranges as they are;
/// a logarithmic y axis keeps its range (the corner the series cross least).
fn room_for_the_legend(
    c: &Chart,
    ((x0, x1), (y0, y1)): ((f64, f64), (f64, f64)),
    text: bool,
) -> (SeriesLabelPosition, (f64, f64)) {
    let (corner, crossing) = legend_position(c, ((x0, x1), (y0, y1)));
    let rows = legend(c).len() as f64;
    // The legend's share of the plot's height, and a little more.
    let share = ((rows * LEGEND_ROW_PX + 16.0) / PLOT_PX).min(0.8) + 0.03;
    // (A corner's box is 35 % of the plot's height: a taller legend gets the headroom.)
    // (Linear y axes only: a logarithmic one's decades are the reader's scale, not to be
    // stretched.)
    if !text || c.log_y || rows == 0.0 || (crossing == 0 && share <= 0.35) {
        return (corner, (y0, y1));
    }
    let grow = 1.0 / (1.0 - share);
    (SeriesLabelPosition::UpperRight, (y0, y0 + (y1 - y0) * grow))
}

/// DejaVu Sans 2.37 (Bitstream Vera licence: `assets/fonts/LICENSE-DejaVu.txt`), the PNG
/// charts' font.
pub const FONT: &[u8] = include_bytes!("../../../assets/fonts/DejaVuSans.ttf");

/// Registers [`FONT`] as plotters' "sans-serif" (once per process).
///
/// # Errors
/// The embedded font does not parse (not expected: a test draws with it).
pub fn register_font() -> Result<(), String> {
    static DONE: std::sync::OnceLock<Result<(), String>> = std::sync::OnceLock::new();
    DONE.get_or_init(|| {
        plotters::style::register_font("sans-serif", FontStyle::Normal, FONT)
            .map_err(|_| "the embedded chart font (DejaVu Sans) does not parse".to_string())
    })
    .clone()
}

/// The series colours of every chart (matplotlib's first five, a grey, then matplotlib's
/// brown, pink, olive and cyan), in order: ten, so that no chart's entries share a colour.
pub(crate) const PALETTE: [RGBColor; 10] = [
    RGBColor(31, 119, 180),
    RGBColor(214, 39, 40),
    RGBColor(44, 160, 44),
    RGBColor(255, 127, 14),
    RGBColor(148, 103, 189),
    RGBColor(90, 90, 90),
    RGBColor(140, 86, 75),
    RGBColor(227, 119, 194),
    RGBColor(188, 189, 34),
    RGBColor(23, 190, 207),
];

/// Keeps at most `max` points, preserving each bucket's min and max (so spikes survive).
pub fn thin(points: &[(f64, f64)], max: usize) -> Vec<(f64, f64)> {
    if points.len() <= max || max < 4 {
        return points.to_vec();
    }
    let buckets = max / 2;
    let per = points.len().div_ceil(buckets);
    let mut out = Vec::with_capacity(max + 2);
    for ch in points.chunks(per) {
        let mut lo = ch[0];
        let mut hi = ch[0];
        for &p in ch {
            if p.1 < lo.1 {
                lo = p;
            }
            if p.1 > hi.1 {
                hi = p;
            }
        }
        if lo.0 <= hi.0 {
            out.push(lo);
            out.push(hi);
        } else {
            out.push(hi);
            out.push(lo);
        }
    }
    out
}

fn ranges(c: &Chart) -> ((f64, f64), (f64, f64)) {
    let (mut x0, mut x1, mut y0, mut y1) = (
        f64::INFINITY,
        f64::NEG_INFINITY,
        f64::INFINITY,
        f64::NEG_INFINITY,
    );
    for s in &c.series {
        for &(x, y) in &s.points {
            if x.is_finite() && y.is_finite() && (!c.log_y || y > 0.0) {
                x0 = x0.min(x);
                x1 = x1.max(x);
                y0 = y0.min(y);
                y1 = y1.max(y);
            }
        }
    }
    if !c.x_names.is_empty() {
        // Whole positions 0..n, each with room beside it.
        (x0, x1) = (-0.4, c.x_names.len() as f64 - 0.6);
    }
    if !x0.is_finite() {
        return ((0.0, 1.0), (0.0, 1.0));
    }
    if x1 <= x0 {
        x1 = x0 + 1.0;
    }
    if y1 <= y0 {
        y1 = y0 + y0.abs().max(1e-9);
    }
    if c.log_y {
        ((x0, x1), (y0.max(y1 * 1e-7), y1 * 1.5))
    } else {
        let m = 0.05 * (y1 - y0);
        ((x0, x1), (y0 - m, y1 + m))
    }
}

/// Draws chart `c` into `root` (`text`: with title, axis labels, tick labels and legend).
///
/// # Errors
/// Drawing errors of the backend, or the font does not register.
fn draw<DB: DrawingBackend>(
    root: DrawingArea<DB, plotters::coord::Shift>,
    c: &Chart,
    text: bool,
) -> Result<(), String>
where
    DB::ErrorType: 'static,
{
    if text {
        register_font()?;
    }
    let e = |x: DrawingAreaErrorKind<DB::ErrorType>| x.to_string();
    root.fill(&WHITE).map_err(e)?;
    let ((x0, x1), (y0, y1)) = ranges(c);
    let (corner, (y0, y1)) = room_for_the_legend(c, ((x0, x1), (y0, y1)), text);
    let mut b = ChartBuilder::on(&root);
    b.margin(12);
    if text {
        b.caption(c.title, ("sans-serif", 20))
            .x_label_area_size(40 + upright_names_px(c))
            .y_label_area_size(70);
    }
    let ticks = if c.log_y {
        let chart = b
            .build_cartesian_2d(x0..x1, (y0..y1).log_scale())
            .map_err(e)?;
        draw_plot(chart, c, text, corner)?
    } else {
        let chart = b.build_cartesian_2d(x0..x1, y0..y1).map_err(e)?;
        draw_plot(chart, c, text, corner)?
    };
    if text {
        // A named axis: a tick at each whole position and its name below it, on one line,
        // or upright, each reading down from its tick, where one would not fit its step
        // (the mesh's own labels fall where its key points do, and it centres a label on
        // its tick, which would stand a turned name half inside the plot).
        use plotters::style::text_anchor::{HPos, Pos, VPos};
        let font = ("sans-serif", 12).into_font();
        let style = if upright_names_px(c) > 0 {
            font.transform(FontTransform::Rotate90)
                .color(&BLACK)
                .pos(Pos::new(HPos::Left, VPos::Center))
        } else {
            font.color(&BLACK).pos(Pos::new(HPos::Center, VPos::Top))
        };
        for (name, (x, y)) in c.x_names.iter().zip(ticks) {
            root.draw(&PathElement::new(vec![(x, y), (x, y + 5)], BLACK))
                .map_err(e)?;
            root.draw(&Text::new(name.as_str(), (x, y + 8), style.clone()))
                .map_err(e)?;
        }
    }
    root.present().map_err(e)?;
    Ok(())
}

/// Draws the mesh, every series of `c` and (with `text`) the axis descriptions and the
/// legend (at `corner`) into the built `chart` (linear or logarithmic y axis); returns the
/// pixels of a named axis' ticks (where each whole position meets the x axis).
///
/// # Errors
/// Drawing errors of the backend.
fn draw_plot<'a, DB, X, Y>(
    mut chart: ChartContext<'a, DB, Cartesian2d<X, Y>>,
    c: &Chart,
    text: bool,
    corner: SeriesLabelPosition,
) -> Result<Vec<(i32, i32)>, String>
where
    DB: DrawingBackend + 'a,
    DB::ErrorType: 'static,
    X: Ranged<ValueType = f64> + ValueFormatter<f64>,
    Y: Ranged<ValueType = f64> + ValueFormatter<f64>,
{
    let e = |x: DrawingAreaErrorKind<DB::ErrorType>| x.to_string();
    {
        let mut mesh = chart.configure_mesh();
        if text {
            mesh.x_desc(c.x_label).y_desc(c.y_label);
        } else {
            mesh.x_labels(0).y_labels(0);
        }
        if !c.x_names.is_empty() {
            // A named axis' ticks and names are drawn beside the mesh ([`draw`]).
            mesh.x_labels(0).disable_x_mesh();
        }
        if text && c.log_y {
            mesh.y_label_formatter(&log_tick);
        }
        mesh.draw().map_err(e)?;
    }
    for s in &c.series {
        draw_series(&mut chart, s, c.log_y, text)?;
    }
    if text {
        chart
            .configure_series_labels()
            .position(corner)
            .background_style(WHITE.mix(0.85))
            .border_style(BLACK)
            .draw()
            .map_err(e)?;
    }
    let bottom = chart.y_range().start;
    Ok((0..c.x_names.len())
        .map(|k| chart.backend_coord(&(k as f64, bottom)))
        .collect())
}

/// Draws one series (points, dashed or solid line) and, with `text`, its legend entry;
/// non-finite points (and, with `log_y`, points not above 0) are left out.
///
/// # Errors
/// Drawing errors of the backend.
fn draw_series<DB, X, Y>(
    chart: &mut ChartContext<'_, DB, Cartesian2d<X, Y>>,
    s: &Series,
    log_y: bool,
    text: bool,
) -> Result<(), String>
where
    DB: DrawingBackend,
    DB::ErrorType: 'static,
    X: Ranged<ValueType = f64>,
    Y: Ranged<ValueType = f64>,
{
    let e = |x: DrawingAreaErrorKind<DB::ErrorType>| x.to_string();
    let col = PALETTE[s.color % PALETTE.len()];
    let pts: Vec<(f64, f64)> = s
        .points
        .iter()
        .copied()
        .filter(|p| drawable(p, log_y))
        .collect();
    if s.scatter {
        let a = chart
            .draw_series(pts.iter().map(|&p| Circle::new(p, 3, col.filled())))
            .map_err(e)?;
        if text {
            a.label(s.label.clone())
                .legend(move |(x, y)| Circle::new((x + 10, y), 4, col.filled()));
        }
    } else if s.dashed {
        let style = col.stroke_width(2);
        let a = chart
            .draw_series(
                runs(&s.points, log_y)
                    .into_iter()
                    .map(move |r| DashedPathElement::new(r, 6, 4, style)),
            )
            .map_err(e)?;
        if text {
            a.label(s.label.clone())
                .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 8, y)], style));
        }
    } else {
        let style = col.stroke_width(1);
        let a = chart
            .draw_series(
                runs(&s.points, log_y)
                    .into_iter()
                    .map(move |r| PathElement::new(r, style)),
            )
            .map_err(e)?;
        if text {
            a.label(s.label.clone()).legend(move |(x, y)| {
                PathElement::new(vec![(x, y), (x + 20, y)], col.stroke_width(2))
            });
        }
    }
    Ok(())
}

/// The runs of drawable points of a line: a point that is not finite (or not positive on
/// a logarithmic axis) lifts the pen, so a series can hold several strokes (the event
/// markers of `diagnose --report`).
fn runs(points: &[(f64, f64)], log_y: bool) -> Vec<Vec<(f64, f64)>> {
    let mut out = vec![Vec::new()];
    for &p in points {
        if drawable(&p, log_y) {
            if let Some(last) = out.last_mut() {
                last.push(p);
            }
        } else if out.last().is_some_and(|r| !r.is_empty()) {
            out.push(Vec::new());
        }
    }
    out.retain(|r| !r.is_empty());
    out
}

/// Renders the chart as SVG text (with labels, and its legend as drawn in its `<desc>`).
pub fn svg_string(c: &Chart) -> Result<String, String> {
    let mut s = String::new();
    {
        let root = SVGBackend::with_string(&mut s, (WIDTH_PX, height(c))).into_drawing_area();
        draw(root, c, true)?;
    }
    Ok(described(s, c.title, &legend(c)))
}

/// Draws the chart as a PNG into `path` (`text`: with title, labels and legend).
fn png(path: &Path, c: &Chart, text: bool) -> Result<(), String> {
    let root = BitMapBackend::new(path, (WIDTH_PX, height(c))).into_drawing_area();
    draw(root, c, text)
}

/// Writes `<stem>.svg` and `<stem>.png` into `dir`; returns the SVG text (for the HTML
/// report) and the paths written.
pub fn write(dir: &Path, c: &Chart) -> Result<(String, Vec<PathBuf>), String> {
    let svg = svg_string(c)?;
    let svg_path = dir.join(format!("{}.svg", c.stem));
    monitor_api::files::write_atomic(&svg_path, svg.as_bytes())
        .map_err(|e| format!("{}: {e}", svg_path.display()))?;
    let png_path = dir.join(format!("{}.png", c.stem));
    let tmp = png_staging_file(dir).map_err(|e| format!("{}: {e}", dir.display()))?;
    png(tmp.path(), c, true)?;
    tmp.persist(&png_path)
        .map_err(|e| format!("{}: {}", png_path.display(), e.error))?;
    Ok((svg, vec![svg_path, png_path]))
}

/// The PNG's temporary file in `dir`: a random name created exclusively (it can never be an
/// existing file, so never an input), the mode of any new file (0o666 less the umask, as
/// `monitor_api::files::write_atomic` gives the SVG), deleted when drawing fails.
fn png_staging_file(dir: &Path) -> std::io::Result<tempfile::NamedTempFile> {
    let mut b = tempfile::Builder::new();
    // The image encoder picks the format from the extension.
    b.prefix(".sim-host-").suffix(".png");
    #[cfg(unix)]
    {
        use std::os::unix::fs::PermissionsExt;
        b.permissions(std::fs::Permissions::from_mode(0o666));
    }
    b.tempfile_in(dir)
}

/// The confusion matrices of `bench --isolation` as one SVG heatmap, one panel per angle
/// mode side by side: rows the true fault, columns what the isolation named, the count in
/// each cell, darker for more (the scale is each panel's largest count).
///
/// # Errors
/// Drawing errors (not expected), or no matrix.
pub fn confusion_svg(
    matrices: &[monitor_studies::bench::isolation::IsolationConfusion],
) -> Result<String, String> {
    if matrices.is_empty() {
        return Err("no confusion matrix to draw".into());
    }
    register_font()?;
    let mut s = String::new();
    {
        let width = 620 * matrices.len() as u32;
        let root = SVGBackend::with_string(&mut s, (width, 600)).into_drawing_area();
        root.fill(&WHITE).map_err(svg_err)?;
        let panels = root.split_evenly((1, matrices.len()));
        for (area, m) in panels.iter().zip(matrices) {
            confusion_panel(area, m)?;
        }
        root.present().map_err(svg_err)?;
    }
    Ok(s)
}

/// A drawing error of the SVG backend as text.
fn svg_err(x: DrawingAreaErrorKind<std::io::Error>) -> String {
    x.to_string()
}

/// One heatmap panel: columns the names the isolation gave, rows the true faults (the
/// first row at the top), both as segments `0..n`.
type Heatmap<'a, 'b> = ChartContext<
    'a,
    SVGBackend<'b>,
    Cartesian2d<SegmentedCoord<RangedCoordi32>, SegmentedCoord<RangedCoordi32>>,
>;

/// Draws the confusion matrix `m` of one angle mode into `area`: caption, labelled axes
/// and one shaded cell per count.
///
/// # Errors
/// Drawing errors (not expected).
fn confusion_panel(
    area: &DrawingArea<SVGBackend<'_>, plotters::coord::Shift>,
    m: &monitor_studies::bench::isolation::IsolationConfusion,
) -> Result<(), String> {
    let (nr, nc) = (m.rows.len() as i32, m.columns.len() as i32);
    let max = m.counts.iter().flatten().copied().max().unwrap_or(0).max(1);
    let mut chart = ChartBuilder::on(area)
        .caption(
            format!(
                "isolation bench, angle mode {}",
                monitor_api::replay::angle_source_name(m.mode)
            ),
            ("sans-serif", 18),
        )
        .margin(10)
        .x_label_area_size(110)
        .y_label_area_size(110)
        .build_cartesian_2d((0..nc).into_segmented(), (0..nr).into_segmented())
        .map_err(svg_err)?;
    let columns: Vec<String> = m.columns.iter().map(|c| c.to_string()).collect();
    let rows: Vec<String> = m.rows.iter().map(|f| f.to_string()).collect();
    let label = |names: &[String], v: &SegmentValue<i32>, flip: bool| match v {
        SegmentValue::CenterOf(i) => {
            let k = if flip { names.len() as i32 - 1 - i } else { *i };
            names.get(k as usize).cloned().unwrap_or_default()
        }
        _ => String::new(),
    };
    chart
        .configure_mesh()
        .disable_mesh()
        .x_labels(nc as usize)
        .y_labels(nr as usize)
        .x_label_formatter(&|v| label(&columns, v, false))
        .y_label_formatter(&|v| label(&rows, v, true))
        .x_label_style(
            ("sans-serif", 13)
                .into_font()
                .transform(FontTransform::Rotate90),
        )
        .y_label_style(("sans-serif", 13))
        .x_desc("named by the isolation")
        .y_desc("true fault")
        .draw()
        .map_err(svg_err)?;
    for (r, row) in m.counts.iter().enumerate() {
        for (c, n) in row.iter().enumerate() {
            confusion_cell(&mut chart, (c as i32, nr - 1 - r as i32), *n, max)?;
        }
    }
    Ok(())
}

/// Draws the heatmap cell at segment `(x, y)`: shaded by `n / max` (white for 0, the
/// palette's blue for `max`), with the count `n` centred in it unless 0.
///
/// # Errors
/// Drawing errors (not expected).
fn confusion_cell(
    chart: &mut Heatmap<'_, '_>,
    (x, y): (i32, i32),
    n: u32,
    max: u32,
) -> Result<(), String> {
    let f = f64::from(n) / f64::from(max);
    let shade = |full: f64| (255.0 - (255.0 - full) * f) as u8;
    let fill = RGBColor(shade(31.0), shade(90.0), shade(180.0));
    chart
        .draw_series(std::iter::once(Rectangle::new(
            [
                (SegmentValue::Exact(x), SegmentValue::Exact(y)),
                (SegmentValue::Exact(x + 1), SegmentValue::Exact(y + 1)),
            ],
            fill.filled(),
        )))
        .map_err(svg_err)?;
    if n > 0 {
        let colour = if f > 0.5 { WHITE } else { BLACK };
        chart
            .draw_series(std::iter::once(Text::new(
                n.to_string(),
                (SegmentValue::CenterOf(x), SegmentValue::CenterOf(y)),
                ("sans-serif", 14).into_font().color(&colour).pos(
                    plotters::style::text_anchor::Pos::new(
                        plotters::style::text_anchor::HPos::Center,
                        plotters::style::text_anchor::VPos::Center,
                    ),
                ),
            )))
            .map_err(svg_err)?;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn chart(title: &'static str) -> Chart<'static> {
        Chart {
            stem: "t",
            title,
            x_label: "time [s]",
            y_label: "current [A]",
            series: vec![Series {
                label: "measured".into(),
                points: (0..200)
                    .map(|k| (k as f64 * 0.01, (k as f64 * 0.1).sin()))
                    .collect(),
                color: 0,
                scatter: false,
                dashed: false,
            }],
            log_y: false,
            omitted: None,
            x_names: Vec::new(),
        }
    }

    /// The chart's pixels as the PNG encoder gets them (RGB, 900 x 420).
    fn pixels(c: &Chart, text: bool) -> Vec<u8> {
        let mut buf = vec![0u8; 900 * 420 * 3];
        {
            let root = BitMapBackend::with_buffer(&mut buf, (900, 420)).into_drawing_area();
            draw(root, c, text).expect("draw");
        }
        buf
    }

    /// Pixels that are not white in rows `y0..y1`.
    fn ink(rgb: &[u8], y0: usize, y1: usize) -> usize {
        rgb[y0 * 900 * 3..y1 * 900 * 3]
            .chunks_exact(3)
            .filter(|p| *p != [255, 255, 255])
            .count()
    }

    #[test]
    fn png_charts_carry_their_text() {
        let with = pixels(&chart("Phase current, measured and predicted"), true);
        let without = pixels(&chart("Phase current, measured and predicted"), false);
        // The title band (the caption above the plotting area): the title's glyphs, where
        // the chart without text has only the top of its frame.
        let title_with = ink(&with, 0, 34);
        let title_without = ink(&without, 0, 34);
        assert!(
            title_with > title_without + 300,
            "title pixels {title_with} against {title_without}"
        );
        // A longer title writes more ink: the pixels are glyphs, not a box.
        let longer = pixels(
            &chart("Phase current, measured and predicted, over the whole log"),
            true,
        );
        assert!(ink(&longer, 0, 34) > title_with + 100);
        // And the file written is a PNG of that chart.
        let dir = tempfile::tempdir().expect("tmp");
        let (_, paths) = write(dir.path(), &chart("Title")).expect("write");
        let bytes = std::fs::read(&paths[1]).expect("png");
        assert_eq!(&bytes[1..4], b"PNG");
    }

    /// The `<desc>` of an SVG: its legend lines.
    fn desc_lines(svg: &str) -> Vec<String> {
        let d = svg
            .split("<desc>legend:\n")
            .nth(1)
            .and_then(|d| d.split("</desc>").next())
            .expect("a legend record");
        d.lines().map(str::to_string).collect()
    }

    #[test]
    fn the_svg_records_each_legend_entry_with_the_points_drawn() {
        let mut c = chart("Residuals");
        // A series of holes and one of values at or below 0 on a log axis draw nothing;
        // the record says so (0 points), as the test over every chart reads it.
        c.series.push(Series {
            label: "holes".into(),
            points: vec![(0.0, f64::NAN), (f64::INFINITY, 1.0)],
            color: 1,
            scatter: false,
            dashed: true,
        });
        let svg = svg_string(&c).expect("svg");
        assert!(svg.contains("<title>Residuals</title>"), "{svg}");
        let lines = desc_lines(&svg);
        assert_eq!(lines.len(), 2, "{lines:?}");
        assert!(
            lines[0].starts_with("measured [#1F77B4 line]: 200 points, y from -"),
            "{lines:?}"
        );
        assert_eq!(lines[1], "holes [#D62728 dashed line]: 0 points");
        // On a logarithmic axis, values not above 0 are not drawn, and not counted.
        c.log_y = true;
        let e = legend(&c);
        let positive = c.series[0].points.iter().filter(|p| p.1 > 0.0).count();
        assert_eq!(e[0].points, positive);
        assert!(e[0].y_range.is_some_and(|(lo, _)| lo > 0.0), "{e:?}");
        // The record is the SVG's first child, so the picture is unchanged below it.
        let at = svg.find("<title>").expect("title");
        assert_eq!(svg[..at].matches('<').count(), 1, "{}", &svg[..at]);
    }

    #[test]
    fn a_named_axis_has_one_tick_per_whole_position_with_its_name() {
        for n in [1usize, 2, 3, 7, 12] {
            let mut c = chart("The ladder");
            c.x_names = (0..n).map(|k| format!("{k}: step")).collect();
            c.series[0].points = (0..n).map(|k| (k as f64, 1.0 / (1.0 + k as f64))).collect();
            let svg = svg_string(&c).expect("svg");
            // The SVG's texts: (y, text).
            let texts: Vec<(String, String)> = svg
                .split("<text")
                .skip(1)
                .filter_map(|t| {
                    let (head, rest) = t.split_once('>')?;
                    let y = head.split(" y=\"").nth(1)?.split('"').next()?;
                    let text = rest.split("</text>").next()?.trim();
                    (!text.is_empty()).then(|| (y.to_string(), text.to_string()))
                })
                .collect();
            for name in &c.x_names {
                let k = texts.iter().filter(|t| &t.1 == name).count();
                assert_eq!(k, 1, "{n}: {name}: {texts:?}");
            }
            // No other tick on the names' line (a fractional step's number, 0.2, 0.5).
            let line = texts.iter().find(|t| t.1.ends_with(": step")).map(|t| &t.0);
            let ticks_on_that_line = texts.iter().filter(|t| Some(&t.0) == line).count();
            assert_eq!(ticks_on_that_line, n, "{n} steps");
        }
    }
}
