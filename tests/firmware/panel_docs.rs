//! The lamp table in `board.rs` (`Lamp::pin`, `Lamp::label`) is the one definition of the
//! panel's pins: the pin maps in the docs (`board.rs`'s module docs, docs/firmware.md's
//! "Pin map and wiring") must list each lamp on its pin, and the code and docs that used
//! to repeat the pins (the panel module, the firmware's panic handler) must not name them.

use drive_monitor::board::Lamp;
use std::path::PathBuf;

fn read(path: &str) -> String {
    let full = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join(path);
    std::fs::read_to_string(&full).unwrap_or_else(|e| panic!("{}: {e}", full.display()))
}

/// The table row of `lamp` in a pin map: `| <label> lamp | <pin> |` (in `board.rs` after
/// `//! `).
fn row(lamp: Lamp) -> String {
    format!("| {} lamp | {} |", lamp.label(), lamp.pin())
}

#[test]
fn the_pin_maps_in_the_docs_are_the_lamp_tables() {
    let board = read("src/board.rs");
    let readme = read("docs/firmware.md");
    for lamp in Lamp::ALL {
        assert!(
            board.contains(&format!("//! {}", row(lamp))),
            "board.rs docs lack `{}`",
            row(lamp)
        );
        assert!(
            readme.contains(&row(lamp)),
            "docs/firmware.md lacks `{}`",
            row(lamp)
        );
        // And nothing else in docs/firmware.md names that pin (it was written in five places).
        let pin = lamp.pin().to_string();
        let mentions = readme
            .split(|c: char| !c.is_ascii_alphanumeric())
            .filter(|w| *w == pin)
            .count();
        assert_eq!(mentions, 1, "docs/firmware.md names {pin} {mentions} times");
    }
}

#[test]
fn the_panel_and_the_panic_handler_do_not_repeat_the_pins() {
    // The panic handlers live in src/firmware/failure.rs.
    let files = [
        "src/panel.rs",
        "src/panel/blink.rs",
        "src/firmware.rs",
        "src/firmware/failure.rs",
    ];
    for file in files {
        let text = read(file);
        for lamp in Lamp::ALL {
            let pin = lamp.pin().to_string();
            assert!(!text.contains(&pin), "{file} names {pin}");
        }
    }
}

#[test]
fn the_panel_is_a_leaf_that_imports_nothing_from_the_application() {
    // `app` builds the panel's input (`app::panel_input`); the panel must not need `app`
    // (they imported each other once). Code lines only: the docs may name `app`.
    // (The blink codes, src/panel/blink.rs, are the panel's too.)
    for file in ["src/panel.rs", "src/panel/blink.rs"] {
        let panel = read(file);
        let uses: Vec<&str> = panel
            .lines()
            .map(str::trim_start)
            .filter(|l| !l.starts_with("//"))
            .filter(|l| {
                l.contains("crate::") || l.contains("super::") || l.contains("drive_monitor::")
            })
            .filter(|l| !l.starts_with("use super::*;"))
            .collect();
        for l in &uses {
            assert!(
                l.contains("crate::board::"),
                "{file} uses more than the lamp table: `{l}`"
            );
        }
    }
}
