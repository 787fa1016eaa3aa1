//! The RUN lamp's patterns as `src/panel.rs`'s module docs give them, read back at every
//! millisecond (the firmware renders every 50 ms; a pattern's edge one millisecond off is
//! another pattern), and the modes' names as the status line's `mode=` spells them
//! (docs/firmware.md, "The status line").

use drive_monitor::panel::{render, Mode, PanelInput};

/// A panel with nothing but `mode` set (no fault, no mark).
fn input(mode: Mode) -> PanelInput {
    PanelInput {
        mode,
        residual_lamps: [false; 4],
        fault_detected: false,
        input_invalid: false,
        fault_code: 0,
        commissioning_failed: false,
        default_motor: false,
        clock_fallback: false,
        bor_below_goal: false,
        moved: false,
        clip_range: false,
    }
}

/// The RUN lamp over 0..4 s and 10 s later (an offset of whole periods), millisecond by
/// millisecond, against `lit(t)` within the pattern's period; the first disagreement.
fn first_wrong(input: &PanelInput, lit: impl Fn(u32) -> bool) -> Option<(u32, bool)> {
    (0..4_000u32)
        .chain(10_000..14_000)
        .map(|t| (t, render(input, t).run))
        .find(|&(t, run)| run != lit(t))
}

/// A pattern: whether the lamp is lit at a time in milliseconds.
type Pattern = fn(u32) -> bool;

/// The module docs' table: commissioned, a 1 Hz blink (500 ms on / 500 ms off);
/// commissioning, 5 Hz (100 on / 100 off); not commissioned, the double flash (100 on, 100
/// off, 100 on, 1 700 off); the "operating point moved" triple flash (100 on, 100 off, 100
/// on, 100 off, 100 on, 1 500 off); sampling stalled, 2 Hz (250 on / 250 off); failed, off.
#[test]
fn the_run_lamps_patterns_are_the_documented_ones_at_the_millisecond() {
    let cases: [(PanelInput, Pattern, &str); 6] = [
        (input(Mode::Commissioned), |t| t % 1_000 < 500, "1 Hz"),
        (input(Mode::Commissioning), |t| t % 200 < 100, "5 Hz"),
        (
            input(Mode::NotCommissioned),
            |t| matches!(t % 2_000, 0..=99 | 200..=299),
            "double flash",
        ),
        (
            PanelInput {
                moved: true,
                ..input(Mode::Commissioned)
            },
            |t| matches!(t % 2_000, 0..=99 | 200..=299 | 400..=499),
            "triple flash",
        ),
        (input(Mode::SamplingStalled), |t| t % 500 < 250, "2 Hz"),
        (input(Mode::Failed), |_| false, "off"),
    ];
    for (given, lit, pattern) in cases {
        assert_eq!(first_wrong(&given, lit), None, "{pattern}: {given:?}");
    }
}

/// The modes' names, each the status line's `mode=` value as docs/firmware.md lists it.
#[test]
fn each_mode_has_the_status_lines_name() {
    let names = [
        (Mode::NotCommissioned, "not-commissioned"),
        (Mode::Commissioning, "commissioning"),
        (Mode::Commissioned, "commissioned"),
        (Mode::SamplingStalled, "sampling-stalled"),
        (Mode::Failed, "failed"),
    ];
    let docs = std::fs::read_to_string(concat!(env!("CARGO_MANIFEST_DIR"), "/docs/firmware.md"))
        .expect("docs/firmware.md");
    let row = docs
        .lines()
        .find(|l| l.starts_with("| `mode=` |"))
        .expect("the status line's `mode=` row");
    for (mode, name) in names {
        assert_eq!(mode.name(), name);
        assert!(row.contains(&format!("`{name}`")), "{row}");
    }
}
