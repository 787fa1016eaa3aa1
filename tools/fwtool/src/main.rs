//! `fwtool`: the host helper behind the cargo aliases (see `.cargo/config.toml`).
//!
//! - `fw [--check]`: build the firmware ELF (the workspace's `firmware` profile: fat LTO,
//!   one codegen unit, debug info) for `thumbv7em-none-eabihf`, then
//!   read its section table and print flash and static RAM use against the budget of the
//!   part (`budget`: `memory.x`'s bank 1, 256 KiB; a warning above 192 KiB, a failure above
//!   224 KiB; 32 KiB of static RAM), whether every allocated section lies in bank 1 (bank 2,
//!   from 0x0804_0000, is the records' and the reset log's) and whether the stack lies below
//!   the statics (flip-link). `--check` exits 1 when any of these is missed.
//! - `fw bring-up [--no-flash] [--dry-run]`: flash the firmware with probe-rs, reset, and
//!   read back over the probe every register the boot's self-check reads, each against its
//!   expected value, as a table (`bring_up`; the user installs probe-rs). Exits 1 on a
//!   mismatch. `--dry-run` prints the commands and what each read should find.
//! - `qemu-core`: build `crates/core-on-m4` for `thumbv7em-none-eabihf`, check that its
//!   vector table is at 0x0 (the mps2-an386 layout, not the G474's), and run it on
//!   `qemu-system-arm -M mps2-an386 -cpu cortex-m4 -icount shift=0` with semihosting.
//!   Exits with QEMU's status (non-zero on any mismatch) and after 300 s at the latest.
//! - `qemu-rtt [--blocking | --drop-on-contention]`: the same for `crates/rtt-on-m4`, the
//!   firmware's defmt-rtt logger with a stalled reader against a 10 kHz sample loop (no
//!   sample may be lost); `--blocking` builds the control with defmt-rtt's blocking mode (the
//!   samples must stop), `--drop-on-contention` defmt-rtt's other mode, for comparison.
//!
//! - `fw bor [--dry-run]`: program the brown-out reset level 4 (about 2.8 V) and the boot
//!   memory chosen by the option bit, not the BOOT0 pin (`nSWBOOT0` = 0, `nBOOT0` = 1), into
//!   the option bytes of the board on the ST-LINK, once per board, with ST's
//!   `STM32_Programmer_CLI` (which runs RM0440's option-byte sequence: unlock, write
//!   `FLASH_OPTR`, `OPTSTRT`, `OBL_LAUNCH`), then read the option bytes back. The firmware
//!   only reads the level and warns at every boot while it is below 4; writing option bytes
//!   from the firmware would risk them on every boot. `--dry-run` prints the commands.
//!
//! The QEMU program's data (`crates/core-on-m4/data/{replay,expected}.bin`) is a log from
//! the sim-host simulator and the host build's answers to it; the root test
//! `tests/firmware/qemu_replay_data.rs` checks it is current and regenerates it with
//! `REGENERATE_QEMU_DATA=1 cargo test --test firmware -- qemu_replay_data::`.
//!
//! Cargo runs this tool with the workspace root as the directory of the alias call; the
//! tool locates the root from its own manifest directory, so it works from anywhere.

mod bring_up;
mod budget;

use std::path::{Path, PathBuf};
use std::process::{Command, ExitCode, Stdio};
use std::time::{Duration, Instant};

use budget::{Budget, Verdict, BANK2_START};

const TARGET: &str = "thumbv7em-none-eabihf";
/// Static RAM goal (the stack not included): a quarter of the G474's 128 KiB, the rest the
/// stack's room.
const RAM_GOAL: u64 = 32 * 1024;

fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..")
}

fn cargo() -> Command {
    Command::new(std::env::var_os("CARGO").unwrap_or_else(|| "cargo".into()))
}

fn target_dir(default: &Path) -> PathBuf {
    std::env::var_os("CARGO_TARGET_DIR")
        .map(PathBuf::from)
        .unwrap_or_else(|| default.join("target"))
}

fn run(cmd: &mut Command) -> Result<(), String> {
    let status = cmd
        .status()
        .map_err(|e| format!("cannot start {cmd:?}: {e}"))?;
    if status.success() {
        Ok(())
    } else {
        Err(format!("{cmd:?} failed with {status}"))
    }
}

/// One section header of an ELF32 file.
struct Section {
    name: String,
    /// `sh_type` (`SHT_NOBITS`: no bytes in the file, as `.bss`).
    ty: u32,
    /// `sh_flags` (`SHF_ALLOC`: occupies memory at run time).
    flags: u32,
    addr: u32,
    size: u32,
}

/// The section headers of an ELF32 little-endian file.
fn sections(elf: &[u8]) -> Result<Vec<Section>, String> {
    let u16_at = |o: usize| elf.get(o..o + 2).map(|b| u16::from_le_bytes([b[0], b[1]]));
    let u32_at = |o: usize| {
        elf.get(o..o + 4)
            .map(|b| u32::from_le_bytes([b[0], b[1], b[2], b[3]]))
    };
    if elf.get(0..6) != Some(&[0x7f, b'E', b'L', b'F', 1, 1]) {
        return Err("not a 32-bit little-endian ELF".into());
    }
    let bad = || "truncated ELF".to_string();
    let shoff = u32_at(0x20).ok_or_else(bad)? as usize;
    let shentsize = u16_at(0x2E).ok_or_else(bad)? as usize;
    let shnum = u16_at(0x30).ok_or_else(bad)? as usize;
    let shstrndx = u16_at(0x32).ok_or_else(bad)? as usize;
    let sh = |i: usize, f: usize| u32_at(shoff + i * shentsize + f).ok_or_else(bad);
    let strtab = sh(shstrndx, 0x10)? as usize;
    let mut out = Vec::new();
    for i in 0..shnum {
        let name_off = strtab + sh(i, 0)? as usize;
        let name: String = elf
            .get(name_off..)
            .ok_or_else(bad)?
            .iter()
            .take_while(|b| **b != 0)
            .map(|b| *b as char)
            .collect();
        out.push(Section {
            name,
            ty: sh(i, 4)?,
            flags: sh(i, 8)?,
            addr: sh(i, 0x0C)?,
            size: sh(i, 0x14)?,
        });
    }
    Ok(out)
}

const SHF_ALLOC: u32 = 2;
const SHT_NOBITS: u32 = 8;

/// What the firmware's ELF takes of the chip ([`usage`]).
struct Usage {
    /// Flash [bytes]: the allocated sections outside RAM and the initial values of `.data`.
    flash: u64,
    /// Static RAM [bytes] (the stack not included).
    ram: u64,
    /// The lowest address of a static in RAM (`u64::MAX` without one).
    first_static: u64,
    /// The highest address an allocated section outside RAM reaches (one past its end).
    flash_end: u64,
}

/// Prints the ELF's allocated sections (name, bytes, address) and adds up what they take
/// of the flash and the RAM.
fn usage(elf: &[u8]) -> Result<Usage, String> {
    let (mut flash, mut ram) = (0u64, 0u64);
    // The lowest address of a static in RAM: with flip-link the stack lies below the
    // statics, from the start of RAM (docs/firmware.md, "The stack").
    let mut first_static = u64::MAX;
    let mut flash_end = 0u64;
    println!("{:<16} {:>8} {:>10}", "section", "bytes", "address");
    for Section {
        name,
        ty,
        flags,
        addr,
        size,
    } in sections(elf)?
    {
        if flags & SHF_ALLOC == 0 || size == 0 {
            continue;
        }
        println!("{name:<16} {size:>8} {addr:#010x}");
        let in_ram = (0x2000_0000..0x2002_0000).contains(&addr);
        if in_ram {
            ram += u64::from(size);
            first_static = first_static.min(u64::from(addr));
            if ty != SHT_NOBITS {
                flash += u64::from(size); // .data: initial values are stored in flash
            }
        } else {
            flash += u64::from(size);
            flash_end = flash_end.max(u64::from(addr) + u64::from(size));
        }
    }
    Ok(Usage {
        flash,
        ram,
        first_static,
        flash_end,
    })
}

/// Builds the firmware ELF (the `firmware` profile) and returns its path.
fn build_firmware() -> Result<PathBuf, String> {
    let root = root();
    run(cargo().current_dir(&root).args([
        "build",
        "--profile",
        "firmware",
        "--target",
        TARGET,
        "-p",
        "drive-monitor",
    ]))?;
    Ok(target_dir(&root)
        .join(TARGET)
        .join("firmware/drive-monitor"))
}

fn fw(check: bool) -> Result<(), String> {
    let elf_path = build_firmware()?;
    let elf = std::fs::read(&elf_path).map_err(|e| format!("{}: {e}", elf_path.display()))?;
    let memory_x = root().join("memory.x");
    let memory_x =
        std::fs::read_to_string(&memory_x).map_err(|e| format!("{}: {e}", memory_x.display()))?;
    let budget = Budget::of_bank(budget::flash_length(&memory_x)?);
    let Usage {
        flash,
        ram,
        first_static,
        flash_end,
    } = usage(&elf)?;
    println!("ELF: {}", elf_path.display());
    let verdict = budget.verdict(flash);
    let in_bank1 = flash_end <= BANK2_START;
    let stack_below = first_static != u64::MAX && first_static > 0x2000_0000;
    print_usage(&budget, verdict, (flash, ram), (flash_end, first_static));
    if check && (verdict == Verdict::Over || ram > RAM_GOAL) {
        return Err("size budget missed".into());
    }
    if check && !in_bank1 {
        return Err("a section lies in bank 2, the records' pages (memory.x)".into());
    }
    if check && !stack_below {
        return Err("the statics start at the bottom of RAM: the firmware was not linked with flip-link (.cargo/config.toml)".into());
    }
    Ok(())
}

/// Prints the flash use against the `budget` (its `verdict`), the static RAM against its
/// goal, where the code ends (`flash_end`: bank 1 or not) and where the stack lies (below
/// the first static, `first_static`: flip-link).
fn print_usage(
    budget: &Budget,
    verdict: Verdict,
    (flash, ram): (u64, u64),
    (flash_end, first_static): (u64, u64),
) {
    println!(
        "flash={flash} bytes ({:.1} KiB of bank 1's {} KiB in memory.x: {}; warn above {} KiB, fail above {} KiB)",
        flash as f64 / 1024.0,
        budget.bank / 1024,
        match verdict {
            Verdict::Ok => "ok",
            Verdict::Warn => "WARNING: above three quarters of the bank",
            Verdict::Over => "OVER BUDGET",
        },
        budget.warn_above / 1024,
        budget.fail_above / 1024
    );
    println!(
        "ram={ram} bytes static ({:.1} KiB, goal {} KiB: {}; stack not included)",
        ram as f64 / 1024.0,
        RAM_GOAL / 1024,
        if ram <= RAM_GOAL { "ok" } else { "OVER GOAL" }
    );
    println!(
        "code and constants end at {flash_end:#010x}: {}",
        if flash_end <= BANK2_START {
            "bank 1 (bank 2, from 0x08040000, is the records')"
        } else {
            "IN BANK 2"
        }
    );
    let stack_below = first_static != u64::MAX && first_static > 0x2000_0000;
    println!(
        "stack={} ({:#010x}..{:#010x} below the statics: {})",
        if stack_below {
            "at the bottom of RAM"
        } else {
            "above the statics"
        },
        0x2000_0000u32,
        first_static.min(0x2000_0000 + 128 * 1024),
        if stack_below {
            "flip-link: ok"
        } else {
            "NOT flip-link"
        }
    );
}

/// `fw bring-up` (`bring_up`): the firmware built, flashed (unless `--no-flash`) and its
/// registers read back over the probe; with `dry_run` only the commands and what each read
/// should find, printed (nothing built, no probe).
fn fw_bring_up(no_flash: bool, dry_run: bool) -> Result<ExitCode, String> {
    if dry_run {
        let root = root().canonicalize().unwrap_or_else(|_| root());
        let elf = target_dir(&root)
            .join(TARGET)
            .join("firmware/drive-monitor");
        println!("cargo build --profile firmware --target {TARGET} -p drive-monitor");
        for line in bring_up::plan(&elf.to_string_lossy(), no_flash) {
            println!("{line}");
        }
        return Ok(ExitCode::SUCCESS);
    }
    let elf = build_firmware()?;
    Ok(if bring_up::run(&elf, no_flash)? {
        ExitCode::SUCCESS
    } else {
        ExitCode::FAILURE
    })
}

/// ST's command-line programmer, which writes option bytes (probe-rs writes memory, not
/// option bytes).
const ST_PROGRAMMER: &str = "STM32_Programmer_CLI";
/// The brown-out level the firmware wants (`drive_monitor::supply::BOR_GOAL`).
const BOR_LEVEL: u8 = 4;

/// `fw bor`: programs `BOR_LEV` = [`BOR_LEVEL`], `nSWBOOT0` = 0 and `nBOOT0` = 1 over SWD
/// and reads the option bytes back;
/// with `dry_run` only prints the commands.
fn bor(dry_run: bool) -> Result<(), String> {
    let program = [
        "-c".to_string(),
        "port=SWD".into(),
        "-ob".into(),
        format!("BOR_LEV={BOR_LEVEL}"),
        // The boot memory from the option bit nBOOT0 (1: the main flash), not from the
        // BOOT0 pin (PB8): the factory's nSWBOOT0 = 1 lets a pin high at reset start ST's
        // bootloader (the self-check's `FLASH_OPTR.nSWBOOT0`).
        "nSWBOOT0=0".into(),
        "nBOOT0=1".into(),
    ];
    let display = ["-c", "port=SWD", "-ob", "displ"];
    println!("{ST_PROGRAMMER} {}", program.join(" "));
    println!("{ST_PROGRAMMER} {}", display.join(" "));
    if dry_run {
        println!("(dry run: nothing written; the next boot's log shows `brown-out reset level 4` and no self-check finding for FLASH_OPTR.nSWBOOT0)");
        return Ok(());
    }
    run(Command::new(ST_PROGRAMMER).args(&program)).map_err(|e| {
        format!("{e}\n(install STM32CubeProgrammer and put {ST_PROGRAMMER} on PATH, or set BOR_LEV = 4 in its option-byte page)")
    })?;
    run(Command::new(ST_PROGRAMMER).args(display))
}

/// Builds the QEMU program in `crates/<name>` (release, `thumbv7em-none-eabihf`, with
/// `features`: cargo's feature arguments), checks that its vector table is at 0x0 (the
/// mps2-an386 layout, not the G474's) and returns the ELF's path.
fn build_qemu_program(name: &str, features: &[&str]) -> Result<PathBuf, String> {
    let dir = root().join("crates").join(name);
    run(cargo()
        .current_dir(&dir)
        .args([
            "build",
            "--release",
            "--target",
            TARGET,
            "--manifest-path",
            "Cargo.toml",
        ])
        .args(features))?;
    let elf_path = target_dir(&dir).join(TARGET).join("release").join(name);
    let elf = std::fs::read(&elf_path).map_err(|e| format!("{}: {e}", elf_path.display()))?;
    let vt = sections(&elf)?
        .into_iter()
        .find(|s| s.name == ".vector_table")
        .ok_or("no .vector_table")?;
    if vt.addr != 0 {
        return Err(format!(
            "vector table at {:#x}, not 0x0: the G474 memory.x was linked instead of the mps2-an386 one",
            vt.addr
        ));
    }
    Ok(elf_path)
}

/// Runs `elf` on `qemu-system-arm -M mps2-an386 -cpu cortex-m4 -icount shift=0` with
/// semihosting; its exit status, or an error after 300 s.
fn run_qemu(elf_path: &Path) -> Result<ExitCode, String> {
    let mut child = Command::new("qemu-system-arm")
        .args([
            "-M",
            "mps2-an386",
            "-cpu",
            "cortex-m4",
            "-nographic",
            "-monitor",
            "none",
        ])
        .args([
            "-serial",
            "none",
            "-semihosting-config",
            "enable=on,target=native",
        ])
        .args(["-icount", "shift=0", "-kernel"])
        .arg(elf_path)
        .stdin(Stdio::null())
        .spawn()
        .map_err(|e| {
            format!("cannot start qemu-system-arm (apt-get install qemu-system-arm): {e}")
        })?;
    let start = Instant::now();
    loop {
        if let Some(status) = child.try_wait().map_err(|e| e.to_string())? {
            return Ok(if status.success() {
                ExitCode::SUCCESS
            } else {
                ExitCode::FAILURE
            });
        }
        if start.elapsed() > Duration::from_secs(300) {
            let _ = child.kill();
            return Err("QEMU timed out after 300 s".into());
        }
        std::thread::sleep(Duration::from_millis(50));
    }
}

fn qemu_core() -> Result<ExitCode, String> {
    run_qemu(&build_qemu_program("core-on-m4", &[])?)
}

/// `qemu-rtt`: the stalled log reader against the 10 kHz sample loop (`crates/rtt-on-m4`)
/// with the firmware's logger; `--blocking` the control (defmt-rtt's default blocking
/// mode: the samples must stop), `--drop-on-contention` defmt-rtt's other mode.
fn qemu_rtt(args: &[String]) -> Result<ExitCode, String> {
    let features: &[&str] = match args.first().map(String::as_str) {
        None => &[],
        Some("--blocking") => &["--no-default-features"],
        Some("--drop-on-contention") => &["--features", "contention"],
        Some(other) => return Err(format!("qemu-rtt: unknown option {other}")),
    };
    run_qemu(&build_qemu_program("rtt-on-m4", features)?)
}

fn main() -> ExitCode {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let result = match args.first().map(String::as_str) {
        Some("fw") if args.get(1).map(String::as_str) == Some("bor") => {
            bor(args.iter().any(|a| a == "--dry-run")).map(|()| ExitCode::SUCCESS)
        }
        Some("fw") if args.get(1).map(String::as_str) == Some("bring-up") => {
            fw_bring_up(
                args.iter().any(|a| a == "--no-flash"),
                args.iter().any(|a| a == "--dry-run"),
            )
        }
        Some("fw") => fw(args.iter().any(|a| a == "--check")).map(|()| ExitCode::SUCCESS),
        Some("qemu-core") => qemu_core(),
        Some("qemu-rtt") => qemu_rtt(&args[1..]),
        _ => Err(
            "usage: fwtool fw [--check] | fw bor [--dry-run] | fw bring-up [--no-flash] [--dry-run] | qemu-core | qemu-rtt [--blocking | --drop-on-contention]"
                .into(),
        ),
    };
    match result {
        Ok(code) => code,
        Err(e) => {
            eprintln!("fwtool: {e}");
            ExitCode::FAILURE
        }
    }
}
