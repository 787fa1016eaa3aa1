//! One renderer per output format, as a CLI tool keeps its exporters: [`text`] (the human
//! tables; [`bench_text`] the benchmarks'), [`json`] (one document), [`html`] (the report
//! page and the chart files; [`diagnose_html`] `diagnose`'s page), with the chart sets in [`charts`]
//! (the ladder's in [`ladder_charts`]) drawn by [`plot`] (the legend placed by [`legend`]); [`hmi`]
//! draws the live HMI's screen. The text and JSON renderers write to the writer they are
//! given (the commands pass [`crate::cli::out::stdout`]; a test can pass a `Vec<u8>`).

pub mod bench_text;
pub mod charts;
pub mod diagnose_html;
pub mod hmi;
pub mod html;
pub mod json;
pub mod ladder_charts;
pub mod legend;
pub mod mcsa;
pub mod plot;
pub mod text;
pub mod trend_plot;

/// A multiple of the noise floor as the ladder's tables print it (`12.3x`); beyond 999x (a
/// noise-free log's floor is next to nothing) `>999x`, the ratio saying no more there; `-`
/// where no error was measured (the model could not run). The text and the HTML report
/// print it alike.
pub(super) fn times_floor(r: f64) -> String {
    if !r.is_finite() {
        "-".into()
    } else if r < 999.5 {
        format!("{r:.1}x")
    } else {
        ">999x".into()
    }
}

/// The base parameters of the ladder's end (`f`, the chosen model refitted on the whole
/// log) in a table cell: the changes named, or "base parameters as the file's".
pub fn end_base(f: &monitor_api::analysis::FinalFit) -> String {
    let changed: Vec<String> = f
        .base
        .iter()
        .filter(|c| c.changed)
        .map(monitor_api::words::ladder::base_change)
        .collect();
    if changed.is_empty() {
        "base parameters as the file's".to_string()
    } else {
        format!("base: {}", changed.join(", "))
    }
}
