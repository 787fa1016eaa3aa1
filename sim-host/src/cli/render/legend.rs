//! Where a chart's legend goes ([`place`]): over no data, the y axis raised to make room
//! where every corner holds some. Pure: the chart's series and sizes in, the corner and the
//! y range out ([`super::plot`] draws).

use plotters::chart::SeriesLabelPosition;

/// The sizes [`place`] works with.
pub struct Layout {
    /// The plot's area [px]: (width, height).
    pub plot_px: (f64, f64),
    /// The legend's box as drawn [px]: (width, height).
    pub legend_px: (f64, f64),
    /// Whether the y axis is logarithmic (points not above 0 are not drawn).
    pub log_y: bool,
}

/// A legend taller than this share of the plot stays where it crosses least (no headroom
/// could clear it).
const TALLEST: f64 = 0.7;

/// A candidate place of the legend and its box as shares of the plot: (x from, x to, y
/// from, y to), y upwards.
type LegendSpot = (SeriesLabelPosition, (f64, f64, f64, f64));

/// The legend's candidate places for its size in `layout` (5 px from the plot's edges, as
/// plotters places it): the four corners and the right's middle, in the order preferred.
fn candidates(layout: &Layout) -> [LegendSpot; 5] {
    let ((pw, ph), (lw, lh)) = (layout.plot_px, layout.legend_px);
    let (bw, bh) = (((lw + 5.0) / pw).min(1.0), ((lh + 5.0) / ph).min(1.0));
    let mid = (0.5 - 0.5 * bh, 0.5 + 0.5 * bh);
    [
        (
            SeriesLabelPosition::UpperRight,
            (1.0 - bw, 1.0, 1.0 - bh, 1.0),
        ),
        (SeriesLabelPosition::UpperLeft, (0.0, bw, 1.0 - bh, 1.0)),
        (SeriesLabelPosition::LowerRight, (1.0 - bw, 1.0, 0.0, bh)),
        (SeriesLabelPosition::LowerLeft, (0.0, bw, 0.0, bh)),
        (
            SeriesLabelPosition::MiddleRight,
            (1.0 - bw, 1.0, mid.0, mid.1),
        ),
    ]
}

/// A point of a series in the plot's shares (x, y from 0 to 1), `None` for one not drawn.
type ToUnit<'a> = dyn Fn(&(f64, f64)) -> Option<(f64, f64)> + 'a;

/// How often the `series` cross each of `boxes`: their points, and for lines of fewer
/// than 400 points nine points along each segment (a point not drawn lifts the pen), each
/// point put in the plot's shares by `unit` (`None`: not drawn).
fn crossings(
    series: &[(&[(f64, f64)], bool)],
    unit: &ToUnit<'_>,
    boxes: &[LegendSpot; 5],
) -> [usize; 5] {
    let mut counts = [0usize; 5];
    let mut visit = |(x, y): (f64, f64)| {
        for (k, (_, (a, b, lo, hi))) in boxes.iter().enumerate() {
            if (*a..=*b).contains(&x) && (*lo..=*hi).contains(&y) {
                counts[k] += 1;
            }
        }
    };
    for &(points, scatter) in series {
        let along = !scatter && points.iter().filter_map(unit).count() < 400;
        let mut prev: Option<(f64, f64)> = None;
        for p in points {
            let Some(q) = unit(p) else {
                prev = None;
                continue;
            };
            visit(q);
            if let (Some(o), true) = (prev, along) {
                for j in 1..10 {
                    let f = f64::from(j) / 10.0;
                    visit((o.0 + f * (q.0 - o.0), o.1 + f * (q.1 - o.1)));
                }
            }
            prev = Some(q);
        }
    }
    counts
}

/// Where the legend goes, and the y range that leaves it room: the candidate place
/// ([`candidates`]) the `series` (points, drawn as points) cross least ([`crossings`]), in
/// the plot's own scale (the logarithm's on a logarithmic axis) within `ranges`; where
/// every place is crossed, the y range is raised until the data lie below the legend,
/// which then stands in the upper right over no data.
pub fn place(
    series: &[(&[(f64, f64)], bool)],
    layout: &Layout,
    ((x0, x1), (y0, y1)): ((f64, f64), (f64, f64)),
) -> (SeriesLabelPosition, (f64, f64)) {
    let log_y = layout.log_y;
    let ty = |y: f64| {
        if log_y {
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
    let unit = |p: &(f64, f64)| {
        let drawn = p.0.is_finite() && p.1.is_finite() && (!log_y || p.1 > 0.0);
        drawn.then(|| ((p.0 - x0) / w, (ty(p.1) - ly0) / hgt))
    };
    let boxes = candidates(layout);
    let counts = crossings(series, &unit, &boxes);
    let best = (0..boxes.len()).min_by_key(|&k| counts[k]).unwrap_or(0);
    let bh = (boxes[0].1).3 - (boxes[0].1).2;
    if counts[best] == 0 || bh >= TALLEST {
        let corner = boxes
            .into_iter()
            .nth(best)
            .map_or(SeriesLabelPosition::UpperRight, |b| b.0);
        return (corner, (y0, y1));
    }
    // Room above the data for the legend: the data's span becomes the plot's lower part.
    let grown = ly0 + hgt / (1.0 - bh - 0.02);
    let y1 = if log_y { 10f64.powf(grown) } else { grown };
    (SeriesLabelPosition::UpperRight, (y0, y1))
}
