//! Plots: every chart is written as SVG (with title, axis labels and legend) and as PNG.
//!
//! PNG text needs a font, and this crate builds plotters without a font backend (so no
//! system font or font crate is needed at build time). PNGs therefore carry the curves,
//! the grid and the legend colours but no text; the same chart's SVG and the HTML report
//! carry the labels. Outputs are written atomically (temporary file, then rename).

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
}

const PALETTE: [RGBColor; 6] = [
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

fn draw<DB: DrawingBackend>(
    root: DrawingArea<DB, plotters::coord::Shift>,
    c: &Chart,
    text: bool,
) -> Result<(), String>
where
    DB::ErrorType: 'static,
{
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
    macro_rules! body {
        ($chart:expr) => {{
            let mut chart = $chart;
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
                let col = PALETTE[s.color % PALETTE.len()];
                let pts: Vec<(f64, f64)> = s
                    .points
                    .iter()
                    .copied()
                    .filter(|p| p.0.is_finite() && p.1.is_finite() && (!c.log_y || p.1 > 0.0))
                    .collect();
                if s.scatter {
                    let a = chart
                        .draw_series(pts.iter().map(|&p| Circle::new(p, 3, col.filled())))
                        .map_err(e)?;
                    if text {
                        a.label(s.label.clone())
                            .legend(move |(x, y)| Circle::new((x + 10, y), 4, col.filled()));
                    }
                } else {
                    let a = chart
                        .draw_series(LineSeries::new(pts, col.stroke_width(1)))
                        .map_err(e)?;
                    if text {
                        a.label(s.label.clone()).legend(move |(x, y)| {
                            PathElement::new(vec![(x, y), (x + 20, y)], col.stroke_width(2))
                        });
                    }
                }
            }
            if text {
                chart
                    .configure_series_labels()
                    .background_style(WHITE.mix(0.85))
                    .border_style(BLACK)
                    .draw()
                    .map_err(e)?;
            }
        }};
    }
    if c.log_y {
        body!(b
            .build_cartesian_2d(x0..x1, (y0..y1).log_scale())
            .map_err(e)?);
    } else {
        body!(b.build_cartesian_2d(x0..x1, y0..y1).map_err(e)?);
    }
    root.present().map_err(e)?;
    Ok(())
}

/// Renders the chart as SVG text (with labels).
pub fn svg_string(c: &Chart) -> Result<String, String> {
    let mut s = String::new();
    {
        let root = SVGBackend::with_string(&mut s, (900, 420)).into_drawing_area();
        draw(root, c, true)?;
    }
    Ok(s)
}

/// Writes `<stem>.svg` and `<stem>.png` into `dir`; returns the SVG text (for the HTML
/// report) and the paths written.
pub fn write(dir: &Path, c: &Chart) -> Result<(String, Vec<PathBuf>), String> {
    let svg = svg_string(c)?;
    let svg_path = dir.join(format!("{}.svg", c.stem));
    sim_host::log::write_atomic(&svg_path, svg.as_bytes())
        .map_err(|e| format!("{}: {e}", svg_path.display()))?;
    let png_path = dir.join(format!("{}.png", c.stem));
    let tmp = png_staging_file(dir).map_err(|e| format!("{}: {e}", dir.display()))?;
    {
        let root = BitMapBackend::new(tmp.path(), (900, 420)).into_drawing_area();
        draw(root, c, false)?;
    }
    tmp.persist(&png_path)
        .map_err(|e| format!("{}: {}", png_path.display(), e.error))?;
    Ok((svg, vec![svg_path, png_path]))
}

/// The PNG's temporary file in `dir`: a random name created exclusively (it can never be an
/// existing file, so never an input), the mode of any new file (0o666 less the umask, as
/// `sim_host::log::write_atomic` gives the SVG), deleted when drawing fails.
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
