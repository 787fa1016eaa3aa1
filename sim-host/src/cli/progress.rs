//! The one progress-bar helper: bars on stderr, hidden when stderr is not a terminal (tests,
//! CI, pipes) or when the work is short.

use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};

/// A bar of `len` steps with a message; invisible unless `show` and stderr is a terminal.
/// Fractions of work go in as `len` = [`FRACTION_STEPS`] and [`set_fraction`].
pub fn bar(len: u64, msg: &str, show: bool) -> ProgressBar {
    if !(show && std::io::IsTerminal::is_terminal(&std::io::stderr())) {
        return ProgressBar::hidden();
    }
    let b = ProgressBar::with_draw_target(Some(len), ProgressDrawTarget::stderr());
    if let Ok(style) = ProgressStyle::with_template("{msg} [{bar:30}] {percent:>3}% ({elapsed})") {
        b.set_style(style.progress_chars("=> "));
    }
    b.set_message(msg.to_string());
    b
}

/// Steps of a bar that shows a fraction.
pub const FRACTION_STEPS: u64 = 1000;

/// Moves a [`FRACTION_STEPS`] bar to `fraction` (0..1).
pub fn set_fraction(b: &ProgressBar, fraction: f64) {
    b.set_position((fraction.clamp(0.0, 1.0) * FRACTION_STEPS as f64) as u64);
}
