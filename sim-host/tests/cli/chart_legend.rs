//! Every chart draws what it names (issue 79): the checks a test runs on each SVG chart the
//! tool writes (`compare`, `explain`, `explain --ladder`, `diagnose --report`, `trend`).
//!
//! Each chart's SVG carries its legend as drawn in its `<desc>` (one line per entry:
//! `label [#1F77B4 line]: 812 points, y from -0.5 to 12`); [`check`] holds every entry to at
//! least one point drawn, two entries never to one look, a label that says "RMS" to no value
//! below zero; and, read from the drawing itself, each entry's colour to at least one
//! element drawn beside its legend mark.

#![allow(dead_code)]

/// One legend entry as the SVG's `<desc>` gives it.
#[derive(Debug, Clone, PartialEq)]
pub struct Entry {
    /// The label.
    pub label: String,
    /// Colour and stroke (`#1F77B4 dashed line`).
    pub look: String,
    /// Points drawn.
    pub points: usize,
    /// The lowest and highest value drawn.
    pub y_range: Option<(f64, f64)>,
}

fn unescape(s: &str) -> String {
    s.replace("&lt;", "<")
        .replace("&gt;", ">")
        .replace("&quot;", "\"")
        .replace("&amp;", "&")
}

/// The legend of one SVG chart (`svg` holds exactly one `<desc>legend:`), or `None`.
pub fn legend(svg: &str) -> Option<Vec<Entry>> {
    let desc = svg.split("<desc>legend:").nth(1)?.split("</desc>").next()?;
    let desc = unescape(desc);
    desc.lines()
        .filter(|l| !l.trim().is_empty())
        .map(|l| {
            let (head, drawn) = l.rsplit_once("]: ")?;
            let (label, look) = head.rsplit_once(" [")?;
            let (n, range) = match drawn.split_once(" points, y from ") {
                Some((n, r)) => (n, Some(r)),
                None => (drawn.strip_suffix(" points")?, None),
            };
            let y_range = match range {
                Some(r) => {
                    let (lo, hi) = r.split_once(" to ")?;
                    Some((lo.parse().ok()?, hi.parse().ok()?))
                }
                None => None,
            };
            Some(Entry {
                label: label.to_string(),
                look: look.to_string(),
                points: n.parse().ok()?,
                y_range,
            })
        })
        .collect()
}

/// The SVG charts of a page (each inline `<svg>...</svg>`).
pub fn svgs_of(page: &str) -> Vec<String> {
    page.split("<svg")
        .skip(1)
        .filter_map(|s| s.split("</svg>").next().map(|b| format!("<svg{b}</svg>")))
        .collect()
}

/// How many drawn elements of `svg` have the colour `hex` (`#1F77B4`): polylines, lines,
/// paths and circles stroked or filled with it (the legend's marks among them).
fn elements_of_colour(svg: &str, hex: &str) -> usize {
    ["<polyline", "<line", "<path", "<circle"]
        .iter()
        .flat_map(|tag| svg.split(tag).skip(1))
        .filter(|el| {
            let head = el.split('>').next().unwrap_or("");
            head.contains(&format!("stroke=\"{hex}\"")) || head.contains(&format!("fill=\"{hex}\""))
        })
        .count()
}

/// The rules of every chart (module docs); `what` names the chart in the message.
pub fn check(svg: &str, what: &str) -> Vec<Entry> {
    let entries = legend(svg)
        .unwrap_or_else(|| panic!("{what}: no legend record (<desc>legend:) in the SVG"));
    assert!(!entries.is_empty(), "{what}: a chart with no legend entry");
    for e in &entries {
        assert!(
            e.points > 0,
            "{what}: the legend names {:?} and nothing of it is drawn",
            e.label
        );
        if e.label.contains("RMS") {
            let (lo, _) = e.y_range.expect("a range");
            assert!(
                lo >= 0.0,
                "{what}: {:?} is labelled an RMS and draws {lo}",
                e.label
            );
        }
        // Each entry's colour is drawn beyond its legend mark: at least one element more
        // than the legend's marks of that colour.
        let hex = e.look.split_whitespace().next().unwrap_or("");
        let marks = entries.iter().filter(|f| f.look.starts_with(hex)).count();
        let drawn = elements_of_colour(svg, hex);
        assert!(
            drawn > marks,
            "{what}: {:?} ({}) has {drawn} element(s) of its colour for {marks} legend mark(s)",
            e.label,
            e.look
        );
    }
    // No two entries share a colour, but a line and its points (the ladder's whole-log
    // error, drawn as a line with a dot at each step).
    for e in &entries {
        let hex = e.look.split_whitespace().next().unwrap_or("");
        let mut same: Vec<&str> = entries
            .iter()
            .filter(|f| f.look.split_whitespace().next() == Some(hex))
            .map(|f| f.look.trim_start_matches(hex).trim())
            .collect();
        same.sort_unstable();
        assert!(
            same.len() == 1 || same == ["line", "points"],
            "{what}: legend entries share the colour {hex}: {entries:?}"
        );
    }
    entries
}
