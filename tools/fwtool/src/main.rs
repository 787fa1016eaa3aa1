//! `fwtool`: the host helper behind the cargo aliases (see `.cargo/config.toml`).
//!
//! - `fw [--check]`: build the firmware ELF (the workspace's `firmware` profile: fat LTO,
//!   one codegen unit, debug info) for `thumbv7em-none-eabihf`, then
//!   read its section table and print flash and static RAM use against the goals
//!   (128 KiB flash, 32 KiB RAM: the smallest STM32G4 part with the same peripherals).
//!   `--check` exits 1 when a goal is missed.
//! - `qemu-core`: build `crates/core-on-m4` for `thumbv7em-none-eabihf`, check that its
//!   vector table is at 0x0 (the mps2-an386 layout, not the G474's), and run it on
//!   `qemu-system-arm -M mps2-an386 -cpu cortex-m4 -icount shift=0` with semihosting.
//!   Exits with QEMU's status (non-zero on any mismatch) and after 300 s at the latest.
//!
//! The QEMU program's data (`crates/core-on-m4/data/{replay,expected}.bin`) is a log from
//! the sim-host simulator and the host build's answers to it; the root test
//! `tests/qemu_replay_data.rs` checks it is current and regenerates it with
//! `REGENERATE_QEMU_DATA=1 cargo test --test qemu_replay_data`.
//!
//! Cargo runs this tool with the workspace root as the directory of the alias call; the
//! tool locates the root from its own manifest directory, so it works from anywhere.

use std::path::{Path, PathBuf};
use std::process::{Command, ExitCode, Stdio};
use std::time::{Duration, Instant};

const TARGET: &str = "thumbv7em-none-eabihf";
/// Flash goal: the smallest STM32G4 part with the G474's peripherals used here (ADC1/2,
/// TIM1, TIM4, DMA, IWDG) has 128 KiB of flash and 32 KiB of RAM.
const FLASH_GOAL: u64 = 128 * 1024;
/// Static RAM goal (the stack not included), see [`FLASH_GOAL`].
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

fn fw(check: bool) -> Result<(), String> {
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
    let elf_path = target_dir(&root)
        .join(TARGET)
        .join("firmware/drive-monitor");
    let elf = std::fs::read(&elf_path).map_err(|e| format!("{}: {e}", elf_path.display()))?;
    let (mut flash, mut ram) = (0u64, 0u64);
    println!("{:<16} {:>8} {:>10}", "section", "bytes", "address");
    for Section {
        name,
        ty,
        flags,
        addr,
        size,
    } in sections(&elf)?
    {
        if flags & SHF_ALLOC == 0 || size == 0 {
            continue;
        }
        println!("{name:<16} {size:>8} {addr:#010x}");
        let in_ram = (0x2000_0000..0x2002_0000).contains(&addr);
        if in_ram {
            ram += u64::from(size);
            if ty != SHT_NOBITS {
                flash += u64::from(size); // .data: initial values are stored in flash
            }
        } else {
            flash += u64::from(size);
        }
    }
    println!("ELF: {}", elf_path.display());
    let verdict = |used: u64, goal: u64| if used <= goal { "ok" } else { "OVER GOAL" };
    println!(
        "flash={flash} bytes ({:.1} KiB, goal {} KiB: {})",
        flash as f64 / 1024.0,
        FLASH_GOAL / 1024,
        verdict(flash, FLASH_GOAL)
    );
    println!(
        "ram={ram} bytes static ({:.1} KiB, goal {} KiB: {}; stack not included)",
        ram as f64 / 1024.0,
        RAM_GOAL / 1024,
        verdict(ram, RAM_GOAL)
    );
    if check && (flash > FLASH_GOAL || ram > RAM_GOAL) {
        return Err("size goal missed".into());
    }
    Ok(())
}

fn qemu_core() -> Result<ExitCode, String> {
    let elf_path = build_core_for_qemu()?;
    run_in_qemu(&elf_path)
}

/// Builds `crates/core-on-m4` for the QEMU board and checks that its vector table is at
/// 0x0 (the mps2-an386 memory layout, not the G474's); the ELF's path.
fn build_core_for_qemu() -> Result<PathBuf, String> {
    let dir = root().join("crates/core-on-m4");
    run(cargo().current_dir(&dir).args([
        "build",
        "--release",
        "--target",
        TARGET,
        "--manifest-path",
        "Cargo.toml",
    ]))?;
    let elf_path = target_dir(&dir).join(TARGET).join("release/core-on-m4");
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

/// Runs the ELF `elf_path` on QEMU's mps2-an386 (a Cortex-M4) with semihosting, at most
/// 300 s; its exit status.
fn run_in_qemu(elf_path: &Path) -> Result<ExitCode, String> {
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

fn main() -> ExitCode {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let result = match args.first().map(String::as_str) {
        Some("fw") => fw(args.iter().any(|a| a == "--check")).map(|()| ExitCode::SUCCESS),
        Some("qemu-core") => qemu_core(),
        _ => Err("usage: fwtool fw [--check] | qemu-core".into()),
    };
    match result {
        Ok(code) => code,
        Err(e) => {
            eprintln!("fwtool: {e}");
            ExitCode::FAILURE
        }
    }
}
