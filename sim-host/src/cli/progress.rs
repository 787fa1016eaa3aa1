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
    /// The furthest position shown.
    furthest: std::sync::atomic::AtomicU64,
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
            furthest: std::sync::atomic::AtomicU64::new(0),
        }
    }

    /// The work's `fraction` done (0..1) and, when given, what it is doing now. The bar
    /// only goes forward: a fraction below one already shown (a thread's report arriving
    /// after a later one's) leaves it where it is.
    pub fn set(&self, msg: Option<String>, fraction: f64) {
        if let Some(m) = msg {
            self.bar.set_message(m);
        }
        let at = (fraction.clamp(0.0, 1.0) * FRACTION_STEPS as f64) as u64;
        let before = self
            .furthest
            .fetch_max(at, std::sync::atomic::Ordering::Relaxed);
        self.bar.set_position(before.max(at));
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

/// The share of the ladder's bar its rounds fill: the chosen model's refit on the whole log
/// fills the rest.
const LADDER_ROUNDS_SHARE: f64 = 0.9;

/// Where the ladder's bar stands at `p`, and what it says. The number of rounds is not
/// known ahead (a round that keeps no step is the last), so round `r` fills
/// [(r - 1) / (r + 1), r / (r + 2)] of [`LADDER_ROUNDS_SHARE`] (a third for the first, a
/// sixth for the second, still a hundredth for the twelfth): the bar only goes forward
/// however many rounds run; the refit of the chosen model goes from where a round after
/// the last kept step ends to the end. The words count the steps
/// kept, never a step that is only being tried.
pub fn ladder_position(p: monitor_api::analysis::LadderProgress) -> (String, f64) {
    use monitor_api::analysis::LadderProgress;
    let steps = |k: usize| match k {
        0 => "no step kept yet".to_string(),
        1 => "1 step kept".to_string(),
        k => format!("{k} steps kept"),
    };
    let rounds_done = |r: usize| LADDER_ROUNDS_SHARE * r as f64 / (r as f64 + 2.0);
    match p {
        LadderProgress::Round {
            round,
            kept,
            fraction,
        } => {
            let (a, b) = (rounds_done(round.saturating_sub(1)), rounds_done(round));
            (
                format!("ladder round {round} ({}): fitting candidates", steps(kept)),
                a + (b - a) * fraction.clamp(0.0, 1.0),
            )
        }
        LadderProgress::FinalFit { kept, fraction } => {
            let a = rounds_done(kept + 1);
            (
                format!(
                    "ladder: {}; refitting the chosen model on the whole log",
                    steps(kept)
                ),
                a + (1.0 - a) * fraction.clamp(0.0, 1.0),
            )
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use monitor_api::analysis::LadderProgress;

    /// The reports of a ladder that kept `kept` steps: each round's fits (the threads'
    /// reports a little out of order), the last round keeping none, then the refit.
    fn walk(kept: usize) -> Vec<LadderProgress> {
        let mut v = Vec::new();
        for r in 1..=kept + 1 {
            for f in [0.0, 0.1, 0.3, 0.2, 0.7, 1.0] {
                v.push(LadderProgress::Round {
                    round: r,
                    kept: r - 1,
                    fraction: f,
                });
            }
        }
        for f in [0.0, 1.0] {
            v.push(LadderProgress::FinalFit { kept, fraction: f });
        }
        v
    }

    /// A two-step ladder (three rounds), none and a twelve-step one: the bar never goes
    /// back (the bar's own guard takes the threads' jitter within a round), each round
    /// moves it on, it ends full, and every message counts the steps kept so far, never a
    /// step only being tried ("step 3" in a two-step ladder).
    #[test]
    fn the_ladder_bar_only_goes_forward_and_counts_the_steps_kept() {
        let kept_words = |k: usize| match k {
            0 => "no step kept yet".to_string(),
            1 => "1 step kept".to_string(),
            k => format!("{k} steps kept"),
        };
        for kept in [0usize, 2, 12] {
            let bar = LateBar::new("ladder", std::time::Duration::from_secs(3600));
            let mut last = 0u64;
            let mut round_start = 0u64;
            for p in walk(kept) {
                let (msg, at) = ladder_position(p);
                bar.set(Some(msg.clone()), at);
                let pos = bar.bar.position();
                assert!(
                    pos >= last,
                    "{kept} kept: {p:?} moved the bar back {last} -> {pos}"
                );
                last = pos;
                let so_far = match p {
                    LadderProgress::Round {
                        kept: k, fraction, ..
                    } => {
                        if fraction == 0.0 {
                            round_start = pos;
                        } else if fraction == 1.0 {
                            assert!(pos > round_start, "{p:?} did not move the bar");
                        }
                        k
                    }
                    LadderProgress::FinalFit { kept: k, .. } => k,
                };
                assert!(msg.contains(&kept_words(so_far)), "{p:?}: {msg}");
                for k in so_far + 1..so_far + 3 {
                    let tried = [format!("step {k}"), format!("{k} step")];
                    assert!(!tried.iter().any(|t| msg.contains(t)), "{p:?}: {msg}");
                }
            }
            assert_eq!(last, FRACTION_STEPS, "{kept} kept");
        }
    }
}
