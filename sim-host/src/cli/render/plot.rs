//! Plots: every chart is written as SVG and as PNG, both with title, axis labels, tick
//! labels and legend.
//!
//! PNG text needs a font: DejaVu Sans (`assets/fonts/DejaVuSans.ttf`, its licence beside
//! it) is embedded in the binary and registered with plotters' `ab_glyph` backend as
//! "sans-serif" before the first chart is drawn ([`FONT`]), so no system font package is
//! needed, in CI or on a user's machine. Outputs are written atomically (temporary file,
//! then rename).

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
}

/// Width of every chart [px].
pub const WIDTH_PX: u32 = 900;
/// Height of every chart [px].
const HEIGHT_PX: u32 = 420;

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

/// The series colours of every chart (matplotlib's first five and a grey), in order.
pub(crate) const PALETTE: [RGBColor; 6] = [
    RGBColor(31, 119, 180),
    RGBColor(214, 39, 40),
    RGBColor(44, 160, 44),
    RGBColor(255, 127, 14),
    RGBColor(148, 103, 189),
    RGBColor(90, 90, 90),
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
    let mut b = ChartBuilder::on(&root);
    b.margin(12);
    if text {
        b.caption(c.title, ("sans-serif", 20))
            .x_label_area_size(40)
            .y_label_area_size(70);
    }
    if c.log_y {
        let chart = b
            .build_cartesian_2d(x0..x1, (y0..y1).log_scale())
            .map_err(e)?;
        draw_plot(chart, c, text)?;
    } else {
        draw_plot(b.build_cartesian_2d(x0..x1, y0..y1).map_err(e)?, c, text)?;
    }
    root.present().map_err(e)?;
    Ok(())
}

/// Draws the mesh, every series of `c` and (with `text`) the axis descriptions and the
/// legend into the built `chart` (linear or logarithmic y axis).
///
/// # Errors
/// Drawing errors of the backend.
fn draw_plot<'a, DB, X, Y>(
    mut chart: ChartContext<'a, DB, Cartesian2d<X, Y>>,
    c: &Chart,
    text: bool,
) -> Result<(), String>
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
        mesh.draw().map_err(e)?;
    }
    for s in &c.series {
        draw_series(&mut chart, s, c.log_y, text)?;
    }
    if text {
        chart
            .configure_series_labels()
            .background_style(WHITE.mix(0.85))
            .border_style(BLACK)
            .draw()
            .map_err(e)?;
    }
    Ok(())
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
        .filter(|p| p.0.is_finite() && p.1.is_finite() && (!log_y || p.1 > 0.0))
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
        if p.0.is_finite() && p.1.is_finite() && (!log_y || p.1 > 0.0) {
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

/// Renders the chart as SVG text (with labels).
pub fn svg_string(c: &Chart) -> Result<String, String> {
    let mut s = String::new();
    {
        let root = SVGBackend::with_string(&mut s, (WIDTH_PX, HEIGHT_PX)).into_drawing_area();
        draw(root, c, true)?;
    }
    Ok(s)
}

/// Draws the chart as a PNG into `path` (`text`: with title, labels and legend).
fn png(path: &Path, c: &Chart, text: bool) -> Result<(), String> {
    let root = BitMapBackend::new(path, (WIDTH_PX, HEIGHT_PX)).into_drawing_area();
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
}
