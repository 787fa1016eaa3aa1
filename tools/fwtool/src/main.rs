//! `fwtool`: the host helper behind the cargo aliases (see `.cargo/config.toml`).
//!
//! - `fw [--check]`: build the release firmware ELF for `thumbv7em-none-eabihf`, then
//!   read its section table and print flash and static RAM use against the goals
//!   (64 KiB flash, 16 KiB RAM). `--check` exits 1 when a goal is missed.
//! - `qemu-core`: build `crates/core-on-m4` for `thumbv7em-none-eabihf`, check that its
//!   vector table is at 0x0 (the mps2-an386 layout, not the G474's), and run it on
//!   `qemu-system-arm -M mps2-an386 -cpu cortex-m4 -icount shift=0` with semihosting.
//!   Exits with QEMU's status (non-zero on any mismatch) and after 300 s at the latest.
//! - `gen-replay`: regenerate `crates/core-on-m4/data/{replay,expected}.bin` from a
//!   synthetic steady-state log of the 2.2 kW reference motor run through the host build
//!   of monitor-core.
//!
//! Cargo runs this tool with the workspace root as the directory of the alias call; the
//! tool locates the root from its own manifest directory, so it works from anywhere.

use std::path::{Path, PathBuf};
use std::process::{Command, ExitCode, Stdio};
use std::time::{Duration, Instant};

#[path = "../../../crates/core-on-m4/src/scenario.rs"]
#[allow(dead_code)]
mod scenario;

const TARGET: &str = "thumbv7em-none-eabihf";
const FLASH_GOAL: u64 = 64 * 1024;
const RAM_GOAL: u64 = 16 * 1024;

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

/// Allocated sections of an ELF32 little-endian file: (name, type, flags, addr, size).
fn sections(elf: &[u8]) -> Result<Vec<(String, u32, u32, u32, u32)>, String> {
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
        out.push((name, sh(i, 4)?, sh(i, 8)?, sh(i, 0x0C)?, sh(i, 0x14)?));
    }
    Ok(out)
}

const SHF_ALLOC: u32 = 2;
const SHT_NOBITS: u32 = 8;

fn fw(check: bool) -> Result<(), String> {
    let root = root();
    run(cargo().current_dir(&root).args([
        "build",
        "--release",
        "--target",
        TARGET,
        "-p",
        "drive-monitor",
    ]))?;
    let elf_path = target_dir(&root).join(TARGET).join("release/drive-monitor");
    let elf = std::fs::read(&elf_path).map_err(|e| format!("{}: {e}", elf_path.display()))?;
    let (mut flash, mut ram) = (0u64, 0u64);
    println!("{:<16} {:>8} {:>10}", "section", "bytes", "address");
    for (name, ty, flags, addr, size) in sections(&elf)? {
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
        "flash={flash} bytes ({:.1} KiB, goal 64 KiB: {})",
        flash as f64 / 1024.0,
        verdict(flash, FLASH_GOAL)
    );
    println!(
        "ram={ram} bytes static ({:.1} KiB, goal 16 KiB: {}; stack not included)",
        ram as f64 / 1024.0,
        verdict(ram, RAM_GOAL)
    );
    if check && (flash > FLASH_GOAL || ram > RAM_GOAL) {
        return Err("size goal missed".into());
    }
    Ok(())
}

fn qemu_core() -> Result<ExitCode, String> {
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
        .find(|s| s.0 == ".vector_table")
        .ok_or("no .vector_table")?;
    if vt.3 != 0 {
        return Err(format!(
            "vector table at {:#x}, not 0x0: the G474 memory.x was linked instead of the mps2-an386 one",
            vt.3
        ));
    }
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
        .arg(&elf_path)
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

/// Synthetic steady state of the 2.2 kW motor: 400 V / 50 Hz supply, 5 A peak current
/// lagging 35 degrees, 4 % slip (150.8 rad/s mechanical), quantized by the board's front
/// end, the encoder counting 4096 per revolution into a 16-bit counter. From sample
/// 2500 on, the current amplitude rises by 30 % (the lamps then have something to do).
fn gen_replay() -> Result<(), String> {
    use std::f64::consts::TAU;
    const N: usize = 4000;
    const SPACING: usize = 100;
    let fs = f64::from(scenario::SAMPLE_RATE_HZ);
    let vp = 400.0 * (2.0f64 / 3.0).sqrt();
    let wm = TAU * 50.0 / 2.0 * 0.96;
    let code = |x: f64, per_lsb: f32| -> u16 {
        (x / f64::from(per_lsb) + f64::from(scenario::MID) + 0.5).clamp(0.0, 4095.0) as u16
    };
    let mut replay = Vec::with_capacity(scenario::REPLAY_HEADER + N * scenario::SAMPLE_BYTES);
    replay.extend_from_slice(b"RPL1");
    replay.extend_from_slice(&(N as u32).to_le_bytes());
    for k in 0..N {
        let t = k as f64 / fs;
        let th = TAU * 50.0 * t;
        let ip = if k >= 2500 { 6.5 } else { 5.0 };
        let phi = 35f64.to_radians();
        let ph = [0.0, -TAU / 3.0, TAU / 3.0];
        let mut words = [0u16; 7];
        for (n, p) in ph.iter().enumerate() {
            words[n] = code(vp * (th + p).cos(), scenario::VOLT_PER_LSB);
            words[3 + n] = code(ip * (th + p - phi).cos(), scenario::AMP_PER_LSB);
        }
        words[6] = ((wm * t / TAU * 4096.0).floor() as u64 & 0xFFFF) as u16;
        for w in words {
            replay.extend_from_slice(&w.to_le_bytes());
        }
    }
    let mut monitor =
        monitor_core::Monitor::new(scenario::config()).map_err(|e| format!("config: {e}"))?;
    let mut expected = Vec::new();
    expected.extend_from_slice(b"EXP1");
    expected.extend_from_slice(&((N / SPACING) as u32).to_le_bytes());
    expected.extend_from_slice(&(SPACING as u32).to_le_bytes());
    let mut lamp_changes = 0;
    let mut last_lamps = 0;
    for k in 0..N {
        let out = monitor.update(&scenario::sample(&replay, k));
        if (k + 1) % SPACING == 0 {
            let c = scenario::Check::of(&out);
            if c.lamps != last_lamps {
                lamp_changes += 1;
                last_lamps = c.lamps;
            }
            expected.extend_from_slice(&c.bytes());
        }
    }
    let dir = root().join("crates/core-on-m4/data");
    std::fs::create_dir_all(&dir).map_err(|e| e.to_string())?;
    std::fs::write(dir.join("replay.bin"), &replay).map_err(|e| e.to_string())?;
    std::fs::write(dir.join("expected.bin"), &expected).map_err(|e| e.to_string())?;
    println!(
        "wrote {} samples ({} bytes) and {} checkpoints ({} bytes); lamp changes: {lamp_changes}",
        N,
        replay.len(),
        N / SPACING,
        expected.len()
    );
    Ok(())
}

fn main() -> ExitCode {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let result = match args.first().map(String::as_str) {
        Some("fw") => fw(args.iter().any(|a| a == "--check")).map(|()| ExitCode::SUCCESS),
        Some("qemu-core") => qemu_core(),
        Some("gen-replay") => gen_replay().map(|()| ExitCode::SUCCESS),
        _ => Err("usage: fwtool fw [--check] | qemu-core | gen-replay".into()),
    };
    match result {
        Ok(code) => code,
        Err(e) => {
            eprintln!("fwtool: {e}");
            ExitCode::FAILURE
        }
    }
}
