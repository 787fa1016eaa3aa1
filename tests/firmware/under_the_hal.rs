//! The firmware's register writes under embassy-stm32 are listed, with the HAL version they
//! were checked against (`drive_monitor::under_the_hal`): a new embassy-stm32 in
//! `Cargo.lock`, or a file of the register layer (`src/regs*`, the one place that names
//! registers) that reaches them without an entry, fails here.

use drive_monitor::under_the_hal::EMBASSY_STM32_CHECKED;
use std::path::Path;

fn read(rel: &str) -> String {
    std::fs::read_to_string(Path::new(env!("CARGO_MANIFEST_DIR")).join(rel)).unwrap()
}

/// The version of `name` in `Cargo.lock`.
fn locked(name: &str) -> String {
    let lock = read("Cargo.lock");
    let entry = &lock[lock
        .find(&format!("name = \"{name}\"\n"))
        .unwrap_or_else(|| panic!("{name} in Cargo.lock"))..];
    let version = entry.lines().nth(1).expect("its version line");
    version
        .strip_prefix("version = \"")
        .and_then(|v| v.strip_suffix('"'))
        .unwrap_or_else(|| panic!("a version line: {version}"))
        .to_string()
}

#[test]
fn the_locked_embassy_stm32_is_the_version_checked() {
    assert_eq!(
        locked("embassy-stm32"),
        EMBASSY_STM32_CHECKED,
        "embassy-stm32 changed: read its source again for every entry of src/under_the_hal.rs, then change EMBASSY_STM32_CHECKED"
    );
}

#[test]
fn every_file_of_the_layer_that_reaches_the_registers_has_an_entry() {
    let list = read("src/under_the_hal.rs");
    let mut files = vec!["src/regs.rs".to_string()];
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("src/regs");
    for e in std::fs::read_dir(dir).unwrap() {
        let name = e.unwrap().file_name().into_string().unwrap();
        files.push(format!("src/regs/{name}"));
    }
    let mut missing = Vec::new();
    for f in &files {
        let reaches = read(f).lines().any(|l| {
            let code = l.split("//").next().unwrap_or("");
            code.contains("pac::")
        });
        if reaches && !list.contains(&format!("| `{f}`")) {
            missing.push(f.clone());
        }
    }
    assert!(files.len() >= 6, "{files:?}");
    assert!(
        missing.is_empty(),
        "no entry in src/under_the_hal.rs: {missing:?}"
    );
}
