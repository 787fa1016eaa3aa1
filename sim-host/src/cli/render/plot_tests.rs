//! The axis and the legend of a chart as drawn (the SVG): a logarithmic axis labelled down
//! to its lowest value, a legend over no data.

use super::*;

/// A line chart over time with one series.
fn chart(title: &'static str) -> Chart<'static> {
    Chart {
        stem: "t",
        title,
        x_label: "time [s]",
        y_label: "error",
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

/// The SVG's texts as (x, y, text).
fn svg_texts(svg: &str) -> Vec<(f64, f64, String)> {
    svg.split("<text")
        .skip(1)
        .filter_map(|t| {
            let (head, rest) = t.split_once('>')?;
            let attr = |name: &str| -> Option<f64> {
                head.split(&format!(" {name}=\""))
                    .nth(1)?
                    .split('"')
                    .next()?
                    .parse()
                    .ok()
            };
            let text = rest.split("</text>").next()?.trim().to_string();
            Some((attr("x")?, attr("y")?, text))
        })
        .collect()
}

/// A ladder's errors from 0.6 down to a floor at 0.004 on a logarithmic axis: a
/// labelled tick at or below the floor (the axis drew none below 0.01).
#[test]
fn a_log_axis_is_labelled_down_to_its_lowest_value() {
    let mut c = chart("The ladder");
    c.log_y = true;
    c.series[0].points = vec![(0.0, 0.6), (1.0, 0.05), (2.0, 0.0045)];
    c.series.push(Series {
        label: "noise floor".into(),
        points: vec![(0.0, 0.004), (2.0, 0.004)],
        color: 2,
        scatter: false,
        dashed: true,
    });
    let svg = svg_string(&c).expect("svg");
    let ticks: Vec<f64> = svg_texts(&svg)
        .iter()
        .filter(|t| t.0 < f64::from(MARGIN_PX + Y_LABELS_PX))
        .filter_map(|t| t.2.parse::<f64>().ok())
        .collect();
    assert!(ticks.iter().any(|&v| v <= 0.004), "{ticks:?}");
}

/// Eight lines that cross every corner of the plot: the legend (its white box as
/// drawn) stands over none of their vertices, the y range raised to make room for it.
#[test]
fn a_legend_never_covers_the_data() {
    for log_y in [false, true] {
        let mut c = chart("Crowded");
        c.log_y = log_y;
        c.series = (0..8)
            .map(|k| Series {
                label: format!("step {k}: a label of some length"),
                points: (0..300)
                    .map(|j| {
                        let x = j as f64 / 299.0;
                        let y = 1.5 + (std::f64::consts::TAU * (x * 2.0 + k as f64 / 8.0)).sin();
                        (x, y)
                    })
                    .collect(),
                color: k,
                scatter: false,
                dashed: false,
            })
            .collect();
        let svg = svg_string(&c).expect("svg");
        // The legend's box: the rect filled white at 0.85 opacity; the data are drawn
        // before it (its own marks after).
        let at = svg.find("opacity=\"0.85\"").expect("a legend box");
        let start = svg[..at].rfind("<rect").expect("its rect");
        let (data, rect) = (&svg[..start], &svg[start..]);
        let attr = |name: &str| -> f64 {
            rect.split(&format!(" {name}=\""))
                .nth(1)
                .and_then(|v| v.split('"').next())
                .and_then(|v| v.parse().ok())
                .expect(name)
        };
        let (x, y, w, h) = (attr("x"), attr("y"), attr("width"), attr("height"));
        let inside = data
            .split("<polyline")
            .skip(1)
            .filter_map(|p| p.split("points=\"").nth(1)?.split('"').next())
            .flat_map(|pts| pts.split(' ').map(str::to_string).collect::<Vec<_>>())
            .filter_map(|p| {
                let (a, b) = p.split_once(',')?;
                Some((a.parse::<f64>().ok()?, b.parse::<f64>().ok()?))
            })
            .filter(|&(px, py)| px > x && px < x + w && py > y && py < y + h)
            .count();
        assert_eq!(
            inside, 0,
            "log_y {log_y}: {inside} vertices under the legend"
        );
    }
}
