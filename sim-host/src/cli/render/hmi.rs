//! The HMI's screen (`sim-host hmi`): a pure function of [`HmiState`] ([`render`]), laid
//! out for 80x24 and growing the strip chart on larger terminals.
//!
//! ```text
//! title (source)
//! lamps r1..r4, FAULT, state
//! residuals: value and a bar against the threshold band (learned or fixed)
//! fault candidates | operating point (speed, I_qs, i_ds, V_qs, f)
//! strip chart of r1..r4 over the last seconds
//! the source's controls; warnings and events; keys
//! ```

use monitor_studies::demo::MonitorState;
use ratatui::layout::{Constraint, Layout, Rect};
use ratatui::style::{Color, Modifier, Style};
use ratatui::symbols::Marker;
use ratatui::text::{Line, Span};
use ratatui::widgets::{Axis, Block, Borders, Chart, Dataset, GraphType, Paragraph};
use ratatui::Frame;
use sim_host::hmi::{header_text, keys, Controls, HmiState, KeyScope, Snapshot, HISTORY_S};

/// Colours of r1..r4 (lamps' labels, bars and chart).
const COLOURS: [Color; 4] = [Color::Cyan, Color::Magenta, Color::Yellow, Color::Green];

/// Draws the whole screen; in a terminal too small for it, a note that says so and what
/// size it needs ([`sim_host::hmi::size`]) instead of a panel with rows cut off.
pub fn render(frame: &mut Frame, state: &HmiState) {
    if sim_host::hmi::size::draw_if_too_small(frame) {
        return;
    }
    let rows = Layout::vertical([
        Constraint::Length(1), // title
        Constraint::Length(2), // lamps and state (the state may take a second line)
        Constraint::Length(5), // residual bars
        Constraint::Length(6), // candidates | operating point
        Constraint::Min(5),    // strip chart
        Constraint::Length(1), // controls
        Constraint::Length(2), // warnings, events
        Constraint::Length(1), // keys
    ])
    .split(frame.area());
    let title = Line::from(vec![
        Span::styled(
            " DRIVE MONITOR ",
            Style::new().add_modifier(Modifier::REVERSED),
        ),
        Span::raw(" "),
        Span::raw(state.title.as_str()),
    ]);
    frame.render_widget(Paragraph::new(title), rows[0]);
    frame.render_widget(Paragraph::new(lamps_lines(state, rows[1].width)), rows[1]);
    render_residuals(frame, rows[2], state.latest.as_ref());
    let mid =
        Layout::horizontal([Constraint::Percentage(50), Constraint::Percentage(50)]).split(rows[3]);
    render_candidates(frame, mid[0], state.latest.as_ref());
    render_operating(frame, mid[1], state.latest.as_ref());
    render_chart(frame, rows[4], state);
    frame.render_widget(Paragraph::new(controls_line(&state.controls)), rows[5]);
    frame.render_widget(Paragraph::new(notes(state)), rows[6]);
    frame.render_widget(Paragraph::new(keys_line(&state.controls)), rows[7]);
}

fn lamp(on: bool, colour: Color) -> Span<'static> {
    if on {
        Span::styled("●", Style::new().fg(colour).add_modifier(Modifier::BOLD))
    } else {
        Span::styled("○", Style::new().fg(Color::DarkGray))
    }
}

/// Lamps r1..r4, the fault lamp (red) or the amber "operating point moved" lamp, and the
/// monitor's state: on the lamps' line as far as it fits, the rest on a second line (both
/// fitted into `width` columns at word boundaries).
fn lamps_lines(state: &HmiState, width: u16) -> Vec<Line<'static>> {
    let Some(s) = &state.latest else {
        return vec![Line::from(" waiting for the first reading ...")];
    };
    let mut spans = Vec::new();
    for (k, on) in s.lamps.iter().enumerate() {
        spans.push(Span::raw(format!(" r{} ", k + 1)));
        spans.push(lamp(*on, Color::Red));
    }
    let moved = matches!(s.state, MonitorState::Moved(_));
    if moved {
        spans.push(Span::raw("   MOVED "));
        spans.push(lamp(true, Color::Yellow));
    } else {
        spans.push(Span::raw("   FAULT "));
        spans.push(lamp(s.fault_lamp, Color::Red));
    }
    let style = if s.fault_lamp {
        Style::new().fg(Color::Red).add_modifier(Modifier::BOLD)
    } else if moved {
        Style::new().fg(Color::Yellow).add_modifier(Modifier::BOLD)
    } else {
        Style::new()
    };
    spans.push(Span::raw(format!("  {:7.2} s  ", s.t_s)));
    let used: usize = spans.iter().map(|s| s.content.chars().count()).sum();
    let room = usize::from(width).saturating_sub(used);
    let text = header_text(s);
    // The first line takes whole words while they fit; the second takes the rest.
    let mut first = String::new();
    let mut rest = text.as_str();
    for w in text.split(' ') {
        let next = if first.is_empty() {
            w.chars().count()
        } else {
            first.chars().count() + 1 + w.chars().count()
        };
        if next > room {
            break;
        }
        if !first.is_empty() {
            first.push(' ');
        }
        first.push_str(w);
        rest = rest[w.len()..]
            .strip_prefix(' ')
            .unwrap_or(&rest[w.len()..]);
    }
    spans.push(Span::styled(first, style));
    let mut lines = vec![Line::from(spans)];
    if !rest.is_empty() {
        let second = fit_words(rest, usize::from(width).saturating_sub(3));
        lines.push(Line::from(Span::styled(format!("   {second}"), style)));
    }
    lines
}

/// A threshold band `centre±half-width` with the digits it has: the half-width to two
/// significant digits (at least three decimals), the centre to the same decimals, and a
/// centre that rounds to zero written `0` (not `-0.000`).
pub fn band_digits(centre: f32, half: f32) -> String {
    let decimals = if half > 0.0 && half.is_finite() {
        (1 - half.log10().floor() as i32).clamp(3, 6) as usize
    } else {
        3
    };
    let unit = 10f32.powi(-(decimals as i32));
    let c = if centre.abs() < 0.5 * unit {
        "0".to_string()
    } else {
        format!("{centre:+.decimals$}")
    };
    format!("{c}±{half:.decimals$}")
}

/// `text` in at most `width` columns: whole words, and `…` where words were left out
/// (never cut mid-word; a first word longer than the width is the one thing shortened).
pub fn fit_words(text: &str, width: usize) -> String {
    if text.chars().count() <= width {
        return text.to_string();
    }
    let mut out = String::new();
    for word in text.split(' ') {
        let next = if out.is_empty() {
            word.chars().count()
        } else {
            out.chars().count() + 1 + word.chars().count()
        };
        // Room for the word and the ellipsis after it.
        if next + 1 > width {
            break;
        }
        if !out.is_empty() {
            out.push(' ');
        }
        out.push_str(word);
    }
    if out.is_empty() {
        out = text.chars().take(width.saturating_sub(1)).collect();
    }
    let out = out
        .trim_end_matches([' ', '|', '/', ',', ':', ';'])
        .to_string();
    format!("{out}…")
}

/// A bar of `width` cells from `-scale` to `+scale`: the band as `═`, outside it `·`, the
/// zero line `┊` and the value `█` (clamped to the ends, `◀`/`▶` beyond them).
pub fn band_bar(value: f32, band: Option<(f32, f32)>, scale: f32, width: usize) -> String {
    let cell = |x: f32| -> usize {
        let u = ((x + scale) / (2.0 * scale)).clamp(0.0, 1.0);
        ((u * (width as f32 - 1.0)).round() as usize).min(width.saturating_sub(1))
    };
    let mut bar: Vec<char> = vec!['·'; width];
    if let Some((c, h)) = band {
        for ch in &mut bar[cell(c - h)..=cell(c + h)] {
            *ch = '═';
        }
    }
    bar[cell(0.0)] = '┊';
    bar[cell(value)] = if value > scale {
        '▶'
    } else if value < -scale {
        '◀'
    } else {
        '█'
    };
    bar.into_iter().collect()
}

/// The residuals against their bands, one line each.
fn render_residuals(frame: &mut Frame, area: Rect, s: Option<&Snapshot>) {
    let learned = s.is_some_and(|s| s.learned);
    let block = Block::new().borders(Borders::TOP).title(format!(
        " residuals against their threshold bands ({}) ",
        if learned { "learned" } else { "fixed" }
    ));
    let inner = block.inner(area);
    frame.render_widget(block, area);
    let Some(s) = s else { return };
    let width = usize::from(inner.width).saturating_sub(28).max(10);
    let lines: Vec<Line> = (0..4)
        .map(|k| {
            let r = s.residuals[k];
            let band = s.bands.map(|b| b[k]);
            let reach = band.map_or(0.03, |(c, h)| c.abs() + h);
            let scale = (2.0 * reach).max(0.01);
            let lit = s.lamps[k];
            let style = if lit {
                Style::new().fg(Color::Red).add_modifier(Modifier::BOLD)
            } else {
                Style::new().fg(COLOURS[k])
            };
            let band_text = band.map_or("band n/a".to_string(), |(c, h)| band_digits(c, h));
            Line::from(vec![
                Span::styled(format!(" r{} {:+8.4} ", k + 1, r), style),
                Span::styled(band_bar(r, band, scale, width), style),
                Span::raw(format!(" {band_text}")),
            ])
        })
        .collect();
    frame.render_widget(Paragraph::new(lines), inner);
}

/// The isolation's conclusion (the fault named with its size, an unknown fault with its
/// nearest candidates, or why nothing is named), the lamps' fault candidates with their
/// probability, the winding asymmetry and the sensors flagged.
fn render_candidates(frame: &mut Frame, area: Rect, s: Option<&Snapshot>) {
    let block = Block::new()
        .borders(Borders::TOP)
        .title(" fault candidates ");
    let inner = block.inner(area);
    frame.render_widget(block, area);
    let Some(s) = s else { return };
    let mut lines: Vec<Line> = Vec::new();
    // The isolation first: its name and size are the answer; the lamps' matching follows.
    let shown = if let Some(iso) = &s.isolation {
        let style = if iso.named.is_some() {
            Style::new().fg(Color::Red).add_modifier(Modifier::BOLD)
        } else {
            Style::new()
        };
        lines.push(Line::from(vec![
            Span::raw(" named: "),
            Span::styled(iso.text(), style),
        ]));
        2
    } else {
        3
    };
    lines.extend(s.candidates.iter().take(shown).map(|(f, p)| {
        let n = (p * 10.0).round() as usize;
        Line::from(format!(
            " {:<15}p {:.2} {}",
            f.name(),
            p,
            "█".repeat(n.min(10))
        ))
    }));
    if s.candidates.len() > shown {
        lines.push(Line::from(format!(
            " ... and {} more",
            s.candidates.len() - shown
        )));
    }
    if s.candidates.is_empty() {
        lines.push(Line::from(" none"));
    }
    for f in &s.sensor_faults {
        lines.push(Line::styled(
            format!(" {} flagged (impossible reading)", f.name()),
            Style::new().fg(Color::Red),
        ));
    }
    if let Some(a) = &s.asymmetry {
        let size = a.min_shorted_fraction.map_or(String::new(), |w| {
            format!(", >= {:.1} % of turns", w * 100.0)
        });
        lines.push(Line::from(format!(
            " asymmetry: phase {} (|I2/I1| {:.1} %{size})",
            a.phase.name(),
            a.ratio * 100.0
        )));
    }
    frame.render_widget(Paragraph::new(lines), inner);
}

fn quantity(name: &str, v: Option<f32>, unit: &str, decimals: usize) -> Line<'static> {
    let text = v.map_or("   n/a".to_string(), |x| format!("{x:>8.decimals$}"));
    Line::from(format!(" {name:<17}{text} {unit}"))
}

/// Speed, I_qs, i_ds, V_qs and the supply frequency.
fn render_operating(frame: &mut Frame, area: Rect, s: Option<&Snapshot>) {
    let block = Block::new()
        .borders(Borders::TOP)
        .title(" operating point ");
    let inner = block.inner(area);
    frame.render_widget(block, area);
    let Some(s) = s else { return };
    let lines = vec![
        quantity("speed", Some(s.speed_rpm), "rpm", 0),
        quantity("I_qs (torque)", s.iqs_a, "A", 2),
        quantity("i_ds (flux)", s.ids_a, "A", 2),
        quantity("V_qs", s.vqs_v, "V", 1),
        quantity("supply frequency", s.supply_hz, "Hz", 2),
    ];
    frame.render_widget(Paragraph::new(lines), inner);
}

/// r1..r4 over the last [`HISTORY_S`] seconds.
fn render_chart(frame: &mut Frame, area: Rect, state: &HmiState) {
    let now = state.history.back().map_or(0.0, |(t, _)| *t);
    let series: Vec<Vec<(f64, f64)>> = (0..4)
        .map(|k| {
            state
                .history
                .iter()
                .map(|(t, r)| (t - now, f64::from(r[k])))
                .collect()
        })
        .collect();
    // The scale of the bulk of the readings (95th percentile): the start's transient
    // does not flatten the steady residuals (a point beyond the scale is clipped).
    let mut mags: Vec<f64> = series.iter().flatten().map(|(_, y)| y.abs()).collect();
    mags.sort_by(f64::total_cmp);
    let p95 = mags
        .get((mags.len() as f64 * 0.95) as usize)
        .copied()
        .unwrap_or(0.0);
    let peak = (1.5 * p95).max(0.02);
    let datasets: Vec<Dataset> = series
        .iter()
        .enumerate()
        .map(|(k, data)| {
            Dataset::default()
                .name(format!("r{}", k + 1))
                .marker(Marker::Braille)
                .graph_type(GraphType::Line)
                .style(Style::new().fg(COLOURS[k]))
                .data(data)
        })
        .collect();
    // The legend is in the title, in the lines' colours: it fits at every size (ratatui's
    // own legend box needs more rows than an 80x24 screen gives the chart).
    let mut title = vec![Span::raw(format!(" residuals, last {HISTORY_S:.0} s: "))];
    for (k, colour) in COLOURS.iter().enumerate() {
        title.push(Span::styled(
            format!("━ r{} ", k + 1),
            Style::new().fg(*colour).add_modifier(Modifier::BOLD),
        ));
    }
    let chart = Chart::new(datasets)
        .block(Block::new().borders(Borders::TOP).title(Line::from(title)))
        .legend_position(None)
        .x_axis(
            Axis::default()
                .bounds([-HISTORY_S, 0.0])
                .labels([format!("-{HISTORY_S:.0} s"), "now".to_string()]),
        )
        .y_axis(
            Axis::default()
                .bounds([-peak, peak])
                .labels([format!("{:+.2}", -peak), format!("{:+.2}", peak)]),
        );
    frame.render_widget(chart, area);
}

/// The source's switches or playback.
fn controls_line(c: &Controls) -> Line<'static> {
    let text = match c {
        Controls::Live(l) => {
            let faults = if l.faults.is_empty() {
                "none".to_string()
            } else {
                l.faults
                    .iter()
                    .map(|(f, x)| format!("{} {:+.0}%", f.name(), x * 100.0))
                    .collect::<Vec<_>>()
                    .join(", ")
            };
            format!(
                " faults on: {faults} | next {:+.0}% | load x{:.2} | supply {:.0}% {:.1} Hz{}",
                l.change * 100.0,
                l.load_scale,
                l.voltage_scale * 100.0,
                l.supply_hz,
                if l.paused { " | PAUSED" } else { "" }
            )
        }
        Controls::Replay(p) => {
            // The verdict is the whole log's: it is shown once the playback has reached the
            // end, not beside the lamps of an earlier moment.
            let at_end = p.done && p.position_s >= p.analysed_s - 1e-9;
            format!(
                " replay {} {} | at {:.2} s of {:.2} s analysed{}{}",
                p.speed.name(),
                if at_end {
                    "ENDED"
                } else if p.paused {
                    "PAUSED"
                } else {
                    "playing"
                },
                p.position_s,
                p.analysed_s,
                if p.done { " (whole log)" } else { " ..." },
                match (&p.verdict, at_end) {
                    (Some(v), true) => format!(" | verdict: {v}"),
                    (Some(_), false) => " | verdict at the end".to_string(),
                    (None, _) => String::new(),
                }
            )
        }
        Controls::Stdin(s) => format!(
            " firmware: {} status lines of {} read | mode {}{}",
            s.status_lines,
            s.lines,
            s.mode.as_deref().unwrap_or("?"),
            if s.ended { " | input ended" } else { "" }
        ),
    };
    Line::styled(text, Style::new().add_modifier(Modifier::REVERSED))
}

/// The latest data-quality warning and the latest event.
fn notes(state: &HmiState) -> Vec<Line<'static>> {
    let warning = match state.warnings.len() {
        0 => Line::from(" data quality: no warnings"),
        1 => Line::styled(
            format!(" ! {}", state.warnings[0]),
            Style::new().fg(Color::Yellow),
        ),
        n => Line::styled(
            format!(" ! {} (+{} more)", state.warnings[0], n - 1),
            Style::new().fg(Color::Yellow),
        ),
    };
    let event = state
        .events
        .back()
        .map_or(Line::from(""), |e| Line::from(format!(" > {e}")));
    vec![warning, event]
}

/// The keys of the source, from the one list ([`keys`]).
fn keys_line(c: &Controls) -> Line<'static> {
    let scope = match c {
        Controls::Live(_) => KeyScope::Live,
        Controls::Replay(_) => KeyScope::Replay,
        Controls::Stdin(_) => KeyScope::All,
    };
    let simulated = !matches!(c, Controls::Stdin(_));
    let keys = keys();
    let items: Vec<&str> = keys
        .iter()
        .filter(|k| {
            k.scope == scope
                || k.scope == KeyScope::All
                || (k.scope == KeyScope::Simulated && simulated)
        })
        .map(|k| k.footer.as_ref())
        .collect();
    Line::styled(
        format!(" {}", items.join(" ")),
        Style::new().fg(Color::DarkGray),
    )
}

#[cfg(test)]
#[path = "hmi_tests.rs"]
mod tests;

#[cfg(test)]
#[path = "hmi_doc_tests.rs"]
mod doc_tests;
