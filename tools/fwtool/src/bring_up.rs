//! `cargo fw bring-up`: flash the firmware with probe-rs, let it boot, read back over the
//! probe every register the boot's self-check reads (the firmware's own table,
//! `src/self_check/registers.rs`, included here as it is) and print each against its
//! expected value as a table; then the part's identity (DBGMCU_IDCODE: DEV_ID and REV_ID,
//! for the errata sheet ES0430). Exits non-zero on a mismatch. `--dry-run` prints what it
//! would run and read, without a probe.
//!
//! It shells out to `probe-rs` (`cargo install probe-rs-tools --locked`, the user's):
//! `probe-rs download`, `probe-rs reset`, then `probe-rs read --chip .. b32 ADDRESS 1` for
//! each register. What `read` prints depends on the version (probe-rs-tools'
//! `src/bin/probe-rs/cmd/read.rs`, read at commit 67993c4b6f3fcbabfc811d1df334acfe66cef150,
//! v0.32.0-71):
//! - since v0.32.0 (commit 654c4e1c, "Print read memory as a table of values by default")
//!   `--format` defaults to `hex-table`: the address, a colon, then the words
//!   (`e0042000: 10006469`); `--format simple-hex` prints the words alone (`10006469`);
//!   `ihex` and `binary` print Intel HEX records and the raw bytes;
//! - up to v0.31 the console output was the words, each followed by a space
//!   (`10006469 `), and `--format` (`hex`, `binary`) applied only to `--output` files.
//!
//! So the tool passes no `--format` (the one command every version takes) and
//! [`parse_word`] reads the table, checking that its address is the one asked for, and the
//! plain words; anything else (Intel HEX, raw bytes, another width) is refused with what
//! was printed. The parsing and the comparison are plain functions with host tests on those
//! exact lines; the probe itself is not run here (no board).

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

/// The table's column heads ([`Row::line`] lines them up).
pub const HEADER: &str =
    "verdict  register.field                               address     read        got (mask)   want";

impl Row {
    /// Whether the register holds the expected bits.
    pub fn holds(&self) -> bool {
        self.read & self.mask == self.expected
    }

    /// The row as printed under [`HEADER`]: `ok` or `MISMATCH`, the name, the address, the
    /// word read, the bits read under the mask and the bits expected (for a field of
    /// contiguous bits its value too, as RM0440 writes it: `BOR_LEV 0, want 4`); a mismatch
    /// says what to do.
    pub fn line(&self) -> String {
        let verdict = if self.holds() { "ok" } else { "MISMATCH" };
        let mut line = format!(
            "{:<8} {:<44} {:#010x}  {:#010x}  {:#010x}   {:#010x}",
            verdict,
            self.id.name(),
            self.address,
            self.read,
            self.read & self.mask,
            self.expected
        );
        if let Some(shift) = field_shift(self.mask) {
            line.push_str(&format!(
                "  (field {} want {})",
                (self.read & self.mask) >> shift,
                self.expected >> shift
            ));
        }
        if !self.holds() {
            line.push_str("\n         -> ");
            line.push_str(remedy(self.id));
        }
        line
    }
}

/// The shift of a mask of more than one contiguous bit (a field with a value), else `None`.
fn field_shift(mask: u32) -> Option<u32> {
    let shift = mask.trailing_zeros();
    let bits = mask.checked_shr(shift)?;
    (bits > 1 && (bits & (bits + 1)) == 0).then_some(shift)
}

/// What a person at the bench does about a check that does not hold (docs/firmware.md,
/// "Bring-up checklist", step 8).
pub fn remedy(id: CheckId) -> &'static str {
    match id {
        CheckId::FreezeWatchdog | CheckId::FreezeTimers => {
            "the firmware's debug freeze did not take: was DBGMCU written by the debugger after the boot? (step 5)"
        }
        CheckId::ClockSecurity => {
            "the crystal did not start (the boot report says so): check X3 and its solder bridges (step 4)"
        }
        CheckId::BrownOutLevel | CheckId::BootPinIgnored => {
            "run `cargo fw bor` once for this board (step 6: BOR_LEV = 4, nSWBOOT0 = 0)"
        }
        CheckId::CcmSramKept
        | CheckId::SramParityOff
        | CheckId::BootFromFlash
        | CheckId::WatchdogBySoftware
        | CheckId::BootBank1
        | CheckId::DualBank => {
            "set this option bit back to its factory value with STM32CubeProgrammer's option-byte page (step 8)"
        }
        CheckId::EncoderMode
        | CheckId::EncoderInputs
        | CheckId::EncoderLatch
        | CheckId::EncoderEnables
        | CheckId::LatchDma
        | CheckId::AdcCommon => {
            "the acquisition's set-up did not take (a change of the HAL: drive_monitor::under_the_hal), or the firmware is not sampling yet"
        }
    }
}

/// Why `probe-rs read`'s output is not one 32-bit word at the address asked for.
fn refuse(what: &str, output: &str) -> String {
    let shown: String = output.chars().take(60).collect();
    format!("probe-rs read printed {what}: {shown:?}")
}

/// The word at `address` in `probe-rs read b32 ADDRESS 1`'s output (module docs: the table
/// of v0.32 and later, `e0042000: 10006469`, whose address must be `address`; the plain
/// words of `--format simple-hex` and of v0.31 and earlier, `10006469`), or why not.
pub fn parse_word(output: &str, address: u32) -> Result<u32, String> {
    let Some(line) = output.lines().map(str::trim).find(|l| !l.is_empty()) else {
        return Err(refuse("nothing", output));
    };
    if line.starts_with(':') {
        return Err(refuse(
            "Intel HEX (--format ihex), not the table or the words",
            output,
        ));
    }
    let mut tokens = line.split_whitespace();
    let mut word = tokens.next().unwrap_or("");
    if let Some(at) = word.strip_suffix(':') {
        let shown = u32::from_str_radix(at, 16)
            .map_err(|_| refuse("a table line whose address is not hexadecimal", output))?;
        if shown != address {
            return Err(format!(
                "probe-rs read answered for {shown:#010x}, not {address:#010x}: {line:?}"
            ));
        }
        word = tokens
            .next()
            .ok_or_else(|| refuse("a table line without a word", output))?;
    }
    if word.len() != 8 || !word.bytes().all(|b| b.is_ascii_hexdigit()) {
        return Err(refuse(
            "no 32-bit word (b32 prints eight hexadecimal digits)",
            output,
        ));
    }
    u32::from_str_radix(word, 16).map_err(|_| refuse("no 32-bit word", output))
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

/// The arguments of one `probe-rs read` of the word at `address` (no `--format`: module
/// docs).
pub fn read_args(address: u32) -> Vec<String> {
    [
        "read".to_string(),
        "--chip".to_string(),
        CHIP.to_string(),
        "b32".to_string(),
        format!("{address:#010x}"),
        "1".to_string(),
    ]
    .into()
}

/// The probe-rs commands of a bring-up, each with what it is for: the download (unless
/// `no_flash`), the reset, then the reads, each with the register and the bits it should
/// hold. What `--dry-run` prints.
pub fn plan(elf: &str, no_flash: bool) -> Vec<String> {
    let mut lines = Vec::new();
    if !no_flash {
        lines.push(format!(
            "probe-rs download --chip {CHIP} {elf}    # flash the firmware"
        ));
    }
    lines.push(format!(
        "probe-rs reset --chip {CHIP}    # boot it, then wait {BOOT_WAIT_S} s"
    ));
    lines.push(format!(
        "probe-rs {}    # DBGMCU_IDCODE: DEV_ID 0x469 (STM32G47x/48x), REV_ID for ES0430",
        read_args(DBGMCU_IDCODE).join(" ")
    ));
    let e = Expectation::BRING_UP;
    for id in CheckId::ALL {
        let c = e.check(id);
        lines.push(format!(
            "probe-rs {}    # {}: bits {:#010x} should read {:#010x}",
            read_args(c.address).join(" "),
            id.name(),
            c.mask,
            c.expected
        ));
    }
    lines
}

/// `probe-rs` with `args`; its standard output.
fn probe_rs(args: &[String]) -> Result<String, String> {
    let out = Command::new("probe-rs").args(args).output().map_err(|e| {
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

/// The reads of a bring-up over `probe` (`probe-rs`'s output for the arguments, or a
/// test's transcript): the identity line, then [`HEADER`] and every row; whether all hold.
pub fn read_back(
    mut probe: impl FnMut(&[String]) -> Result<String, String>,
) -> Result<(Vec<String>, bool), String> {
    let mut read = |address: u32| parse_word(&probe(&read_args(address))?, address);
    let (identity_line, mut all) = identity(read(DBGMCU_IDCODE)?);
    let mut lines = vec![identity_line, HEADER.to_string()];
    for row in compare(&mut read)? {
        lines.push(row.line());
        all &= row.holds();
    }
    lines.push(
        if all {
            "bring-up: every register holds what the firmware wrote"
        } else {
            "bring-up: a register does not hold what the firmware wrote (docs/firmware.md, \"Bring-up checklist\")"
        }
        .to_string(),
    );
    Ok((lines, all))
}

/// `cargo fw bring-up` (module docs): flashes `elf` (unless `no_flash`), resets the board,
/// waits for the boot and prints the table. `Ok(false)`: a register did not hold what it
/// should.
pub fn run(elf: &Path, no_flash: bool) -> Result<bool, String> {
    let elf = elf.to_string_lossy().into_owned();
    let args = |first: &str, rest: &[&str]| -> Vec<String> {
        [first, "--chip", CHIP]
            .iter()
            .chain(rest)
            .map(|a| a.to_string())
            .collect()
    };
    if !no_flash {
        println!("probe-rs download --chip {CHIP} {elf}");
        probe_rs(&args("download", &[&elf]))?;
    }
    println!("probe-rs reset --chip {CHIP}; {BOOT_WAIT_S} s for the boot");
    probe_rs(&args("reset", &[]))?;
    std::thread::sleep(Duration::from_secs(BOOT_WAIT_S));
    let (lines, all) = read_back(probe_rs)?;
    for l in lines {
        println!("{l}");
    }
    Ok(all)
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::collections::HashMap;

    /// A board after a good boot, register by register (RM0440's fields written out).
    fn good_board() -> HashMap<u32, u32> {
        HashMap::from([
            (0xE004_2000, 0x1000_6469),
            (0xE004_2008, 1 << 12),
            (0xE004_2010, 1 << 11 | 1 << 16),
            (0x4002_1000, 0x0303_0500 | 1 << 19),
            (0x4002_2020, (0xFFEF_F8AA | 4 << 8) & !(1 << 26)),
            (0x4000_0808, 0b0011),
            (0x4000_0818, 0x0101 | 6 << 4 | 6 << 12),
            (0x4000_081C, 0b11),
            (0x4000_0820, 0x111),
            (0x4000_080C, 1 << 11),
            (0x5000_0308, 0b0010 << 18 | 1 << 22),
        ])
    }

    /// What probe-rs v0.32 prints for `read b32 ADDRESS 1` by default (`hex-table`:
    /// `write_hex_table`, `"{address:08x}: "` then `write_simple_hex`'s words and a
    /// newline).
    fn hex_table(address: u32, word: u32) -> String {
        format!("{address:08x}: {word:08x}\n")
    }

    /// The lines of probe-rs-tools' `read` (module docs), word for word.
    #[test]
    fn every_format_probe_rs_prints_is_read_or_refused_by_name() {
        let a = DBGMCU_IDCODE;
        // v0.32 and later, the default `--format hex-table`.
        assert_eq!(parse_word("e0042000: 10006469\n", a), Ok(0x1000_6469));
        assert_eq!(hex_table(a, 0x1000_6469), "e0042000: 10006469\n");
        // `--format simple-hex` (v0.32 and later).
        assert_eq!(parse_word("10006469\n", a), Ok(0x1000_6469));
        // v0.31 and earlier: every word followed by a space, then a newline.
        assert_eq!(parse_word("10006469 \n", a), Ok(0x1000_6469));
        // A table for another address is not this register's value.
        let e = parse_word("e0042004: 10006469\n", a).unwrap_err();
        assert!(e.contains("answered for 0xe0042004, not 0xe0042000"), "{e}");
        // `--format ihex`: the extended linear address record first.
        let e = parse_word(":02000004E00416\n:0420000069640010FF\n:00000001FF\n", a).unwrap_err();
        assert!(e.contains("Intel HEX"), "{e}");
        // `--format binary`: the four bytes as they are.
        let raw = String::from_utf8_lossy(&0x1000_6469u32.to_le_bytes()).into_owned();
        assert!(parse_word(&raw, a).is_err());
        // Another width (b16 prints four digits), nothing, an error on stdout.
        assert!(parse_word("6469\n", a).is_err());
        assert!(parse_word("", a).is_err());
        assert!(parse_word("Error: no probe was found", a).is_err());
        assert!(parse_word("123456789", a).is_err());
    }

    #[test]
    fn the_read_asks_for_no_format_and_one_word() {
        assert_eq!(
            read_args(0x4002_2020).join(" "),
            "read --chip STM32G474RETx b32 0x40022020 1"
        );
    }

    /// RM0440's addresses (the peripheral's base, the register's offset), written out here:
    /// the table the firmware and the tool share reads these.
    #[test]
    fn the_table_reads_rm0440s_addresses() {
        let rm0440 = [
            (CheckId::FreezeWatchdog, 0xE004_2000 + 0x08),
            (CheckId::FreezeTimers, 0xE004_2000 + 0x10),
            (CheckId::ClockSecurity, 0x4002_1000),
            (CheckId::CcmSramKept, 0x4002_2000 + 0x20),
            (CheckId::SramParityOff, 0x4002_2000 + 0x20),
            (CheckId::BootFromFlash, 0x4002_2000 + 0x20),
            (CheckId::WatchdogBySoftware, 0x4002_2000 + 0x20),
            (CheckId::BootBank1, 0x4002_2000 + 0x20),
            (CheckId::DualBank, 0x4002_2000 + 0x20),
            (CheckId::BrownOutLevel, 0x4002_2000 + 0x20),
            (CheckId::EncoderMode, 0x4000_0800 + 0x08),
            (CheckId::EncoderInputs, 0x4000_0800 + 0x18),
            (CheckId::EncoderLatch, 0x4000_0800 + 0x1C),
            (CheckId::EncoderEnables, 0x4000_0800 + 0x20),
            (CheckId::LatchDma, 0x4000_0800 + 0x0C),
            (CheckId::AdcCommon, 0x5000_0300 + 0x08),
            (CheckId::BootPinIgnored, 0x4002_2000 + 0x20),
        ];
        assert_eq!(rm0440.len(), CheckId::ALL.len());
        for (id, address) in rm0440 {
            assert_eq!(Expectation::BRING_UP.check(id).address, address, "{id:?}");
        }
    }

    /// A recorded transcript: a good board answering every read as probe-rs v0.32 prints
    /// it; then the same board with the factory's brown-out level and the crystal not
    /// started.
    #[test]
    fn a_transcript_of_a_good_board_reads_ok_and_each_wrong_register_is_named() {
        let answer = |board: &HashMap<u32, u32>, args: &[String]| {
            let address = u32::from_str_radix(args[4].trim_start_matches("0x"), 16).unwrap();
            Ok(hex_table(address, board[&address]))
        };
        let board = good_board();
        let (lines, all) = read_back(|args| answer(&board, args)).unwrap();
        assert!(all, "{lines:#?}");
        assert!(
            lines[0].starts_with("ok       DBGMCU_IDCODE 0x10006469"),
            "{}",
            lines[0]
        );
        assert_eq!(lines[1], HEADER);
        assert_eq!(lines.len(), 2 + CheckId::ALL.len() + 1);
        assert!(lines.last().unwrap().contains("every register holds"));

        // The factory's option bytes (the brown-out level 0, nSWBOOT0 1) and the crystal
        // not started.
        let mut wrong = good_board();
        wrong.insert(0x4002_2020, 0xFFEF_F8AA);
        wrong.insert(0x4002_1000, 0x0303_0500);
        let (lines, all) = read_back(|args| answer(&wrong, args)).unwrap();
        assert!(!all);
        let bad: Vec<&String> = lines.iter().filter(|l| l.starts_with("MISMATCH")).collect();
        assert_eq!(bad.len(), 3, "{lines:#?}");
        assert!(
            bad[2].starts_with("MISMATCH FLASH_OPTR.nSWBOOT0"),
            "{}",
            bad[2]
        );
        assert!(bad[2].contains("0x04000000   0x00000000"), "{}", bad[2]);
        assert!(bad[0].starts_with("MISMATCH RCC_CR.CSSON"), "{}", bad[0]);
        assert!(bad[0].contains("check X3"), "{}", bad[0]);
        assert!(
            bad[1].starts_with("MISMATCH FLASH_OPTR.BOR_LEV"),
            "{}",
            bad[1]
        );
        assert!(
            bad[1].contains("0x00000000   0x00000400  (field 0 want 4)"),
            "{}",
            bad[1]
        );
        assert!(bad[1].contains("cargo fw bor"), "{}", bad[1]);
        // A read that fails stops the bring-up with its reason.
        assert!(read_back(|_| Err("no probe".into())).is_err());
        // A probe-rs that printed Intel HEX: refused by name.
        let e = read_back(|_| Ok(":02000004E00416\n".into())).unwrap_err();
        assert!(e.contains("Intel HEX"), "{e}");
    }

    #[test]
    fn the_dry_run_names_every_command_and_register() {
        let lines = plan("drive-monitor.elf", false);
        assert_eq!(lines.len(), 3 + CheckId::ALL.len());
        assert!(lines[0].starts_with("probe-rs download --chip STM32G474RETx drive-monitor.elf"));
        assert!(lines[1].starts_with("probe-rs reset --chip STM32G474RETx"));
        assert!(lines[2].starts_with("probe-rs read --chip STM32G474RETx b32 0xe0042000 1"));
        assert!(lines.iter().any(|l| l.contains("b32 0x40022020 1")
            && l.contains("FLASH_OPTR.BOR_LEV: bits 0x00000700 should read 0x00000400")));
        assert_eq!(plan("x", true).len(), 2 + CheckId::ALL.len());
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
