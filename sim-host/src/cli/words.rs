//! The command line's words for the library's: a field is named by its flag
//! (`commission` -> `--commission 4:2`), and the library's typed values are parsed by the
//! library's one parser, their refusals shown as clap shows a bad value.

use monitor_api::replay::{CommissionWindow, ParallelPaths, ReplayError, TimelineStep};
use monitor_api::words::Spelling;
use monitor_api::ApiError;
pub use sim_host::flags::CliWords;

/// One error of a chain in the command line's words: a library error that names fields
/// names their flags; any other as it displays.
pub fn error_text(e: &(dyn std::error::Error + 'static)) -> String {
    if let Some(e) = e.downcast_ref::<ApiError>() {
        e.spelled(&CliWords)
    } else if let Some(e) = e.downcast_ref::<ReplayError>() {
        monitor_api::words::replay_error(e, &CliWords)
    } else if let Some(e) = e.downcast_ref::<monitor_api::replay::OptionError>() {
        monitor_api::words::option_error(e, &CliWords)
    } else if let Some(e) = e.downcast_ref::<monitor_api::files::LogError>() {
        e.spelled(&|name| CliWords.key(name))
    } else if let Some(monitor_store::HistoryError::Missing(p)) =
        e.downcast_ref::<monitor_store::HistoryError>()
    {
        format!("no store at {p} (write one with `sim-host fleet ... --store {p}`)")
    } else {
        e.to_string()
    }
}

/// `--commission START:END`, by the library's one parser of a window.
pub fn parse_window(s: &str) -> Result<CommissionWindow, String> {
    s.parse()
        .map_err(|e: monitor_api::replay::OptionError| e.why)
}

/// `--timeline-step SECONDS`, by the library's one parser of a step (> 0, finite).
pub fn parse_timeline_step(s: &str) -> Result<TimelineStep, String> {
    s.parse()
        .map_err(|e: monitor_api::replay::OptionError| e.why)
}

/// `--parallel-paths N`: a whole number in the library's range (1..=8).
pub fn parse_parallel_paths(s: &str) -> Result<ParallelPaths, String> {
    let n = s
        .trim()
        .parse::<i64>()
        .map_err(|_| format!("'{s}' is not a whole number of paths (1..=8)"))?;
    ParallelPaths::new(n).map_err(|e| e.why)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fields_are_named_by_their_flags() {
        use monitor_api::replay::OptionField;
        let e = monitor_api::replay::CommissionWindow::new(4.0, 2.0).unwrap_err();
        assert_eq!(
            monitor_api::words::option_error(&e, &CliWords),
            "--commission 4:2: the window must be START:END with 0 <= START < END, both finite (seconds)"
        );
        assert_eq!(CliWords.option(OptionField::From, ""), "--from");
        assert_eq!(
            CliWords.option(OptionField::TimelineStep, "0"),
            "--timeline-step 0"
        );
        assert!(parse_timeline_step("0").is_err() && parse_parallel_paths("9").is_err());
        let e = ApiError::Identify {
            what: "cannot identify from",
            log: "a.csv".into(),
            why: monitor_api::IdentifyWhy::Failed(
                monitor_api::analysis::identify::IdentifyError::Irregular {
                    at_s: 1.0,
                    interval_s: 2e-3,
                    dt_s: 1e-3,
                },
            ),
        };
        assert!(e.spelled(&CliWords).ends_with("(--from/--to)"), "{e}");
        let e = ApiError::WindowOrder {
            from_s: 2.0,
            to_s: 1.0,
        };
        assert_eq!(e.spelled(&CliWords), "--to (1) must be after --from (2)");
    }
}
