//! One renderer per output format, as a CLI tool keeps its exporters: [`text`] (the human
//! tables; [`bench_text`] the benchmarks'), [`json`] (one document on stdout), [`html`] (the report page and the chart
//! files), with the chart sets in [`charts`] drawn by [`plot`]; [`hmi`] draws the live
//! HMI's screen.

pub mod bench_text;
pub mod charts;
pub mod hmi;
pub mod html;
pub mod json;
pub mod mcsa;
pub mod plot;
pub mod text;
pub mod trend_plot;
