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

/// A bar that appears only once its work has run for `after` (so a short run shows none and
/// a long one always does), on stderr when it is a terminal. Progress goes in as a fraction
/// ([`LateBar::set`]), from any thread.
pub struct LateBar {
    bar: ProgressBar,
    start: std::time::Instant,
    after: std::time::Duration,
    shown: std::sync::atomic::AtomicBool,
    terminal: bool,
}

impl LateBar {
    /// A hidden bar with message `msg`, shown after `after` of work.
    pub fn new(msg: &str, after: std::time::Duration) -> Self {
        let bar = ProgressBar::with_draw_target(Some(FRACTION_STEPS), ProgressDrawTarget::hidden());
        if let Ok(style) =
            ProgressStyle::with_template("{msg} [{bar:30}] {percent:>3}% ({elapsed})")
        {
            bar.set_style(style.progress_chars("=> "));
        }
        bar.set_message(msg.to_string());
        LateBar {
            bar,
            start: std::time::Instant::now(),
            after,
            shown: std::sync::atomic::AtomicBool::new(false),
            terminal: std::io::IsTerminal::is_terminal(&std::io::stderr()),
        }
    }

    /// The work's `fraction` done (0..1) and, when given, what it is doing now.
    pub fn set(&self, msg: Option<String>, fraction: f64) {
        if let Some(m) = msg {
            self.bar.set_message(m);
        }
        set_fraction(&self.bar, fraction);
        if self.terminal
            && self.start.elapsed() >= self.after
            && !self.shown.swap(true, std::sync::atomic::Ordering::Relaxed)
        {
            self.bar.set_draw_target(ProgressDrawTarget::stderr());
        }
    }

    /// Clears the bar.
    pub fn finish(&self) {
        self.bar.finish_and_clear();
    }
}
