//! `cargo fw bring-up`: flash the firmware with probe-rs, let it boot, read back over the
//! probe every register the boot's self-check reads (the firmware's own table,
//! `src/self_check/registers.rs`, included here as it is) and print each against its
//! expected value; then the part's identity (DBGMCU_IDCODE: DEV_ID and REV_ID, for the
//! errata sheet ES0430). Exits non-zero on a mismatch.
//!
//! It shells out to `probe-rs` (`cargo install probe-rs-tools --locked`, the user's):
//! `probe-rs download`, `probe-rs reset`, then `probe-rs read b32 ADDRESS 1` for each
//! register, whose output is the word in hexadecimal. The parsing and the comparison are
//! plain functions with host tests; the probe itself is not run here (no board).

#[path = "../../../src/self_check/registers.rs"]
#[allow(dead_code)]
mod registers;

use registers::{CheckId, Expectation};
use std::path::Path;
use std::process::Command;
use std::time::Duration;

/// probe-rs's name of the part.
pub const CHIP: &str = "STM32G474RETx";
/// `DBGMCU_IDCODE` (RM0440, "MCU device ID code"): `DEV_ID` bits 11:0, `REV_ID` bits 31:16.
pub const DBGMCU_IDCODE: u32 = 0xE004_2000;
/// The G474's `DEV_ID` (the category 3 devices, STM32G471/473/474/483/484).
pub const DEV_ID_G47X: u32 = 0x469;
/// How long the firmware gets to boot before the reads [s] (the crystal's bound, the
/// self-check, the ADCs' set-up: well under a second).
const BOOT_WAIT_S: u64 = 3;

/// One register read over the probe against its check.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Row {
    /// What it checks.
    pub id: CheckId,
    /// The register's address.
    pub address: u32,
    /// The value read.
    pub read: u32,
    /// The bits compared.
    pub mask: u32,
    /// Their expected value.
    pub expected: u32,
}

impl Row {
    /// Whether the register holds the expected bits.
    pub fn holds(&self) -> bool {
        self.read & self.mask == self.expected
    }

    /// The row as printed: `ok` or `MISMATCH`, the name, the address, the bits read and
    /// expected under the mask.
    pub fn line(&self) -> String {
        format!(
            "{:<8} {:<44} {:#010x}  read {:#010x}  mask {:#010x}  got {:#010x}  want {:#010x}",
            if self.holds() { "ok" } else { "MISMATCH" },
            self.id.name(),
            self.address,
            self.read,
            self.mask,
            self.read & self.mask,
            self.expected
        )
    }
}

/// The word in `probe-rs read b32`'s output (hexadecimal words separated by spaces; the
/// first one), or why not.
pub fn parse_word(output: &str) -> Result<u32, String> {
    let word = output
        .split_whitespace()
        .next()
        .ok_or_else(|| format!("probe-rs read printed nothing: {output:?}"))?;
    let digits = word.trim_start_matches("0x");
    if digits.is_empty() || digits.len() > 8 {
        return Err(format!("probe-rs read printed {word:?}, not a 32-bit word"));
    }
    u32::from_str_radix(digits, 16).map_err(|_| format!("probe-rs read printed {word:?}"))
}

/// The rows of every check, each register read by `read` (over the probe, or a test's
/// table) against [`Expectation::BRING_UP`] (the crystal, the encoder's record not known:
/// its filter and direction left out).
pub fn compare(mut read: impl FnMut(u32) -> Result<u32, String>) -> Result<Vec<Row>, String> {
    let e = Expectation::BRING_UP;
    CheckId::ALL
        .iter()
        .map(|&id| {
            let c = e.check(id);
            Ok(Row {
                id,
                address: c.address,
                read: read(c.address)?,
                mask: c.mask,
                expected: c.expected,
            })
        })
        .collect()
}

/// The part's identity line from `DBGMCU_IDCODE`'s value, and whether it is a G47x.
pub fn identity(idcode: u32) -> (String, bool) {
    let dev = idcode & 0xFFF;
    let rev = idcode >> 16;
    let ok = dev == DEV_ID_G47X;
    let line = format!(
        "{:<8} DBGMCU_IDCODE {:#010x}: DEV_ID {:#05x} ({}), REV_ID {:#06x} (look it up in ES0430's device identification table: which errata apply)",
        if ok { "ok" } else { "MISMATCH" },
        idcode,
        dev,
        if ok { "STM32G47x/48x" } else { "not an STM32G47x" },
        rev
    );
    (line, ok)
}

/// `probe-rs` with `args` and the chip; its standard output.
fn probe_rs(args: &[&str]) -> Result<String, String> {
    let out = Command::new("probe-rs")
        .args(args)
        .args(["--chip", CHIP])
        .output()
        .map_err(|e| {
            format!("cannot start probe-rs ({e}): cargo install probe-rs-tools --locked")
        })?;
    if !out.status.success() {
        return Err(format!(
            "probe-rs {} failed: {}",
            args.join(" "),
            String::from_utf8_lossy(&out.stderr).trim()
        ));
    }
    Ok(String::from_utf8_lossy(&out.stdout).into_owned())
}

/// One word at `address` over the probe.
fn read_over_probe(address: u32) -> Result<u32, String> {
    parse_word(&probe_rs(&[
        "read",
        "b32",
        &format!("{address:#010x}"),
        "1",
    ])?)
}

/// `cargo fw bring-up` (module docs): flashes `elf` (unless `no_flash`), resets the board,
/// waits for the boot and prints the rows. `Ok(false)`: a register did not hold what it
/// should.
pub fn run(elf: &Path, no_flash: bool) -> Result<bool, String> {
    let elf = elf.to_string_lossy();
    if !no_flash {
        println!("probe-rs download --chip {CHIP} {elf}");
        probe_rs(&["download", &elf])?;
    }
    println!("probe-rs reset --chip {CHIP}; {BOOT_WAIT_S} s for the boot");
    probe_rs(&["reset"])?;
    std::thread::sleep(Duration::from_secs(BOOT_WAIT_S));
    let (line, mut all) = identity(read_over_probe(DBGMCU_IDCODE)?);
    println!("{line}");
    for row in compare(read_over_probe)? {
        println!("{}", row.line());
        all &= row.holds();
    }
    println!(
        "{}",
        if all {
            "bring-up: every register holds what the firmware wrote"
        } else {
            "bring-up: a register does not hold what the firmware wrote (docs/firmware.md, \"Bring-up checklist\")"
        }
    );
    Ok(all)
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::collections::HashMap;

    /// A board after a good boot, register by register (RM0440's fields written out).
    fn good_board() -> HashMap<u32, u32> {
        HashMap::from([
            (0xE004_2008, 1 << 12),
            (0xE004_2010, 1 << 11 | 1 << 16),
            (0x4002_1000, 0x0303_0500 | 1 << 19),
            (0x4002_2020, 0xFFEF_F8AA | 4 << 8),
            (0x4000_0808, 0b0011),
            (0x4000_0818, 0x0101 | 6 << 4 | 6 << 12),
            (0x4000_081C, 0b11),
            (0x4000_0820, 0x111),
            (0x4000_080C, 1 << 11),
            (0x5000_0308, 0b0010 << 18 | 1 << 22),
        ])
    }

    #[test]
    fn probe_rs_words_are_parsed() {
        assert_eq!(parse_word("00001000\n"), Ok(0x1000));
        assert_eq!(parse_word("ffefffaa 00000000"), Ok(0xFFEF_FFAA));
        assert_eq!(parse_word("0x0808"), Ok(0x808));
        assert!(parse_word("").is_err());
        assert!(parse_word("Error: no probe").is_err());
        assert!(parse_word("123456789").is_err());
    }

    #[test]
    fn a_good_board_passes_and_each_wrong_register_is_named() {
        let board = good_board();
        let rows = compare(|a| Ok(board[&a])).unwrap();
        assert_eq!(rows.len(), CheckId::ALL.len());
        assert!(rows.iter().all(Row::holds), "{rows:?}");
        // The brown-out level at the factory's 0 and CSSON off: two rows, by name.
        let mut wrong = good_board();
        wrong.insert(0x4002_2020, 0xFFEF_F8AA);
        wrong.insert(0x4002_1000, 0x0303_0500);
        let rows = compare(|a| Ok(wrong[&a])).unwrap();
        let bad: Vec<&str> = rows
            .iter()
            .filter(|r| !r.holds())
            .map(|r| r.id.name())
            .collect();
        assert_eq!(bad, ["RCC_CR.CSSON", "FLASH_OPTR.BOR_LEV"]);
        let line = rows
            .iter()
            .find(|r| r.id == CheckId::BrownOutLevel)
            .unwrap()
            .line();
        assert!(line.starts_with("MISMATCH FLASH_OPTR.BOR_LEV"), "{line}");
        assert!(line.contains("got 0x00000000  want 0x00000400"), "{line}");
        // A read that fails stops the comparison with its reason.
        assert!(compare(|_| Err("no probe".into())).is_err());
    }

    #[test]
    fn the_part_is_identified() {
        let (line, ok) = identity(0x1000_6469);
        assert!(ok);
        assert!(
            line.contains("DEV_ID 0x469") && line.contains("REV_ID 0x1000"),
            "{line}"
        );
        assert!(!identity(0x1000_6468).1);
    }
}
