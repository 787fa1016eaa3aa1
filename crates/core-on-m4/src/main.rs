//! monitor-core on the Cortex-M4F instruction set (QEMU `mps2-an386`, semihosting).
//!
//! 1. Replays the embedded log (`data/replay.bin`, generated on the host by
//!    `cargo run --manifest-path tools/fwtool/Cargo.toml -- gen-replay`) through
//!    `Monitor::update` and compares the outputs at every checkpoint with the host's
//!    (`data/expected.bin`). Tolerance: 6e-4 absolute + 1e-4 relative. Both sides run the
//!    same f32 code with micromath's trigonometry, so differences come only from
//!    instruction selection (no fused multiply-add on either side by default) and stay
//!    far below micromath's own 6e-4 error; the bound allows for that error once.
//!    Lamps and the fault flag must match exactly.
//! 2. Counts instructions per sample for angle+Park, the speed estimate, the residuals
//!    and the whole pipeline. QEMU runs with `-icount shift=0` (virtual time advances one
//!    step per executed instruction); SysTick is read around each loop and calibrated
//!    against a loop of a known instruction count, and the cost of the loop itself
//!    (decoding the sample) is subtracted.
//! 3. Counts the instructions of the fault isolation's work per 0.1 s block in thread
//!    mode (not per sample): one isolation of the averaged point and one joint fit over
//!    [`MAX_POINTS`] operating points with an anchor (the evidence across operating
//!    points, `monitor_core::isolation::Evidence`).
//! 4. Counts the instructions per sample of the firmware's sampling path ahead of the core
//!    (`drive_monitor::acquisition`, the same source files: `SampleBuilder::build`, the
//!    eight oversampled sequences of each ADC summed with every conversion checked against
//!    its channel's linear range, the clip held, the latched encoder counts checked and
//!    averaged, `PwmFilter::step`), and checks the sampling path's three Thumb-2 kernels
//!    (`src/acquisition/thumb.rs`) against their Rust on the replay and on pseudo-random
//!    samples (the encoder check's also against its count by count path).
//! 5. Prints `name=value` lines and exits 0, or non-zero on any mismatch, a kernel that does
//!    not agree with its Rust, or a budget missed ([`WHOLE_PIPELINE_BUDGET`],
//!    [`SAMPLING_PATH_BUDGET`]).
#![no_std]
#![no_main]

// The firmware library's acquisition, its ADC rules and clock, compiled here from their own
// files (the firmware's library pulls embassy on this target; these need nothing but `core`).
#[path = "../../../src/acquisition.rs"]
#[allow(dead_code)]
mod acquisition;
#[path = "../../../src/adc_rules.rs"]
#[allow(dead_code)]
mod adc_rules;
#[path = "../../../src/clock.rs"]
#[allow(dead_code)]
mod clock;
mod encoder;
mod scenario;

use core::hint::black_box;

use cortex_m::peripheral::syst::SystClkSource;
use cortex_m_rt::entry;
use monitor_core::angle::RotorFluxCurrentModel;
use monitor_core::encoder::MtSpeed;
use monitor_core::frames::{clarke, park, SinCos};
use monitor_core::isolation::{Isolator, SteadyPoint, MAX_POINTS};
use monitor_core::residuals::{residuals, Operating};
use monitor_core::{Monitor, MonitorConfig};
use scenario::Check;

static REPLAY: &[u8] = include_bytes!("../data/replay.bin");
static EXPECTED: &[u8] = include_bytes!("../data/expected.bin");

/// The core's instructions per sample at most (issue 74: the sample path within 250).
const WHOLE_PIPELINE_BUDGET: f32 = 250.0;
/// The sampling path's instructions per sample at most: 318 measured with the
/// per-conversion clip check (317 since the encoder check's steps are taken half by half) (issue 74 asked 250; the check of 48 conversions against
/// their ranges is about 100 of them, docs/firmware.md, "Clipping per conversion").
const SAMPLING_PATH_BUDGET: f32 = 325.0;

/// Absolute tolerance: one micromath sin/cos error (6e-4) on a quantity of order one.
const ATOL: f32 = 6e-4;
/// Relative tolerance for large quantities (speeds in rad/s).
const RTOL: f32 = 1e-4;

use qemu_semihosting as semihosting;
use qemu_semihosting::println;

/// SysTick as a 24-bit down counter; elapsed ticks between two readings.
fn elapsed(start: u32, end: u32) -> u32 {
    start.wrapping_sub(end) & 0x00FF_FFFF
}

fn now() -> u32 {
    cortex_m::peripheral::SYST::get_current()
}

/// Run `f` and return the SysTick ticks it took (must stay below 2^24 ticks).
fn measure(mut f: impl FnMut()) -> u32 {
    let t0 = now();
    f();
    elapsed(t0, now())
}

/// A loop of exactly `2 * n` instructions (`subs`, `bne`) plus a few around it.
fn known_loop(n: u32) {
    // SAFETY: pure register arithmetic.
    unsafe {
        core::arch::asm!("1:", "subs {0}, #1", "bne 1b", inout(reg) n => _, options(nomem, nostack));
    }
}

#[entry]
fn main() -> ! {
    let Some(mut cp) = cortex_m::Peripherals::take() else {
        semihosting::exit(false)
    };
    cp.SYST.set_clock_source(SystClkSource::Core);
    cp.SYST.set_reload(0x00FF_FFFF);
    cp.SYST.clear_current();
    cp.SYST.enable_counter();

    let n = scenario::u32_at(REPLAY, 4) as usize;
    let checks = scenario::u32_at(EXPECTED, 4) as usize;
    let spacing = scenario::u32_at(EXPECTED, 8) as usize;
    if n == 0 || spacing == 0 || checks * spacing > n || REPLAY.get(0..4) != Some(b"RPL1") {
        println!("error=bad embedded data");
        semihosting::exit(false);
    }
    println!("samples={}", n);

    let ticks_per_instr = calibrate();
    let cfg = scenario::config();
    let ok = replay_matches_host(&cfg, n, checks, spacing);
    let whole = count_instructions(&cfg, n, ticks_per_instr);
    count_isolation(&cfg, n, ticks_per_instr);
    let sampling = count_sampling_path(n, ticks_per_instr);
    let ok = check_kernels(n) && ok;
    let within = |name: &str, value: f32, budget: f32| {
        let fits = value <= budget;
        println!(
            "budget_{}={} (at most {:.0})",
            name,
            if fits { "pass" } else { "FAIL" },
            budget
        );
        fits
    };
    let ok = within("whole_pipeline", whole, WHOLE_PIPELINE_BUDGET)
        & within("sampling_path", sampling, SAMPLING_PATH_BUDGET)
        & ok;
    println!("result={}", if ok { "pass" } else { "FAIL" });
    semihosting::exit(ok)
}

/// SysTick ticks per instruction, from a loop of known length.
fn calibrate() -> f32 {
    const CAL_N: u32 = 200_000;
    let t_cal = measure(|| known_loop(black_box(CAL_N))) as f32;
    let t_cal0 = measure(|| known_loop(black_box(1))) as f32;
    let ticks_per_instr = (t_cal - t_cal0) / (2.0 * (CAL_N - 1) as f32);
    if !(ticks_per_instr > 0.0) {
        println!("error=SysTick does not advance (run QEMU with -icount shift=0)");
        semihosting::exit(false);
    }
    ticks_per_instr
}

/// Replays the embedded samples through `Monitor` and compares the checkpoints with the
/// host's results; prints the mismatches and the largest deviation.
fn replay_matches_host(cfg: &MonitorConfig, n: usize, checks: usize, spacing: usize) -> bool {
    let Ok(mut monitor) = Monitor::new(*cfg) else {
        println!("error=config rejected");
        semihosting::exit(false);
    };
    let mut ok = true;
    let mut max_abs = 0.0f32;
    let mut j = 0usize;
    for k in 0..n {
        let out = monitor.update(&scenario::sample(REPLAY, k));
        if j < checks && k + 1 == (j + 1) * spacing {
            let got = Check::of(&out);
            let want = Check::read(EXPECTED, j);
            for (g, w) in got.values.iter().zip(want.values) {
                let d = (g - w).abs();
                max_abs = max_abs.max(if w.abs() > 1.0 { d / w.abs() } else { d });
                if !(d <= ATOL + RTOL * w.abs()) {
                    ok = false;
                    println!("mismatch checkpoint={} got={} want={}", j, g, w);
                }
            }
            if got.lamps != want.lamps || got.fault != want.fault {
                ok = false;
                println!(
                    "mismatch checkpoint={} lamps got={:04b} want={:04b}",
                    j, got.lamps, want.lamps
                );
            }
            j += 1;
        }
    }
    println!("checkpoints={}", j);
    println!("max_deviation={:e}", max_abs);
    ok
}

/// Ticks of `n` samples through angle + Park as `Monitor::update` does it with the
/// rotor-flux model: the frame's sin/cos advanced by a small rotation per sample
/// (`SinCos::rotated`), resynchronised by one sin/cos per block.
#[inline(always)]
fn measure_angle_park(cfg: &MonitorConfig, n: usize) -> u32 {
    let m = &cfg.motor;
    let dt = 1.0 / cfg.sample_rate_hz;
    let imr_min = 0.05 * cfg.v_phase_peak / (core::f32::consts::TAU * cfg.supply_hz * m.ls_h);
    let mut rfo = RotorFluxCurrentModel::new(dt, m.rr_ohm, m.lr_h, imr_min);
    let wr = black_box(150.0f32);
    let dec = cfg.decimation as usize;
    let mut sc = SinCos::from_angle(rfo.theta());
    measure(|| {
        for k in 0..n {
            let s = scenario::sample(REPLAY, k);
            let v = clarke(s.v_abc);
            let i = clarke(s.i_abc);
            if k % dec == 0 {
                sc = SinCos::from_angle(rfo.theta());
            }
            let i_dq = park(i, sc);
            rfo.update(i_dq, wr);
            let v_dq = park(v, sc);
            // The negative-sequence rotation shares the same sin/cos.
            let n_dq = park(i, sc.negated());
            sc = sc.rotated(rfo.omega_rad_s() * dt);
            black_box((v_dq, i_dq, n_dq));
        }
    })
}

/// Ticks of `n` samples through the M/T speed estimate.
#[inline(always)]
fn measure_speed(cfg: &MonitorConfig, n: usize) -> u32 {
    let dt = 1.0 / cfg.sample_rate_hz;
    let mut mt = MtSpeed::new(&cfg.encoder, cfg.tick_hz, cfg.limits.max_speed_rad_s, dt);
    measure(|| {
        for k in 0..n {
            let s = scenario::sample(REPLAY, k);
            black_box(mt.update(s.encoder_count, s.timestamp_ticks));
        }
    })
}

/// Ticks of `n` evaluations of the steady-state residuals (eq. 37).
#[inline(always)]
fn measure_residuals(cfg: &MonitorConfig, n: usize) -> u32 {
    let m = &cfg.motor;
    measure(|| {
        for k in 0..n {
            let s = scenario::sample(REPLAY, k);
            let op = Operating {
                iqs: s.i_abc.a,
                i_f: 3.0 + s.i_abc.b,
                vqs: s.v_abc.a,
                wr_rad_s: 300.0 + s.i_abc.c,
            };
            black_box(residuals(m, op, None));
        }
    })
}

/// Ticks of `n` samples through a fresh `Monitor` of `cfg`.
#[inline(always)]
fn measure_monitor(cfg: MonitorConfig, n: usize) -> u32 {
    let Ok(mut monitor) = Monitor::new(cfg) else {
        semihosting::exit(false);
    };
    measure(|| {
        for k in 0..n {
            black_box(monitor.update(&scenario::sample(REPLAY, k)));
        }
    })
}

/// Counts the instructions per sample of the pipeline's parts and of the whole
/// `Monitor::update`, and prints them; returns the whole pipeline's.
fn count_instructions(cfg: &MonitorConfig, n: usize, ticks_per_instr: f32) -> f32 {
    let cfg = *cfg;
    let per_sample = |ticks: u32, base: u32, count: usize| -> f32 {
        (ticks as f32 - base as f32) / ticks_per_instr / count as f32
    };
    let base = measure(|| {
        for k in 0..n {
            black_box(scenario::sample(REPLAY, k));
        }
    });
    let t_park = measure_angle_park(&cfg, n);
    let t_speed = measure_speed(&cfg, n);
    let t_res = measure_residuals(&cfg, n);
    let t_all = measure_monitor(cfg, n);
    // Split fast and slow path: total(d) = fast + slow / d, measured at d and d/2.
    let mut cfg_half = cfg;
    cfg_half.decimation = (cfg.decimation / 2).max(1);
    let t_half = measure_monitor(cfg_half, n);
    let d = f32::from(cfg.decimation);
    let dh = f32::from(cfg_half.decimation);
    let (all, half) = (per_sample(t_all, base, n), per_sample(t_half, base, n));
    let slow = if d > dh {
        (half - all) / (1.0 / dh - 1.0 / d)
    } else {
        0.0
    };
    let fast = all - slow / d;

    println!("ticks_per_instruction={}", ticks_per_instr);
    println!("angle_park={:.0}", per_sample(t_park, base, n));
    println!("speed_estimate={:.0}", per_sample(t_speed, base, n));
    println!("residuals_per_call={:.0}", per_sample(t_res, base, n));
    println!(
        "residuals_per_sample={:.0}",
        per_sample(t_res, base, n) / f32::from(cfg.decimation)
    );
    println!(
        "monitor_output_bytes={}",
        core::mem::size_of::<monitor_core::MonitorOutput>()
    );
    println!("fast_path={:.0}", fast);
    println!("slow_path_per_call={:.0}", slow);
    let whole = per_sample(t_all, base, n);
    println!("whole_pipeline={:.0}", whole);
    whole
}

/// Counts the instructions per sample of the firmware's sampling path (module docs, 4):
/// each replay sample's six codes as [`acquisition::OVERSAMPLING`] sequences per ADC and its
/// count as the eight latched counts, through `acquisition::SampleBuilder::build`, what
/// `app::FrameBuilder::frame` runs (every conversion checked against its channel's linear
/// range while summed, the clip held, the latched counts checked against the maximum speed
/// and averaged, `PwmFilter`). Prints `sampling_path` and returns it; the loop that writes
/// the samples into memory is measured alone and subtracted.
fn count_sampling_path(n: usize, ticks_per_instr: f32) -> f32 {
    use acquisition::{LinearRange, LinearRanges, SampleBuilder, CHANNELS, HALF_LEN, OVERSAMPLING};
    let mut buf = ([0u16; HALF_LEN], [0u16; HALF_LEN], [0u16; OVERSAMPLING]);
    let base = measure(|| {
        for k in 0..n {
            fill(black_box(k), &mut buf);
            black_box(&mut buf);
        }
    });
    // The built-in front end's ranges (motor_source::linear_ranges: 62..=4033) and the
    // built-in encoder's largest step (4 counts a trigger).
    let range = [LinearRange {
        low: 62,
        high: 4033,
    }; CHANNELS];
    let ranges = LinearRanges {
        voltage: range,
        current: range,
    };
    let mut builder = SampleBuilder::new(10_000, 50.0, &ranges, 4);
    let t = measure(|| {
        for k in 0..n {
            fill(black_box(k), &mut buf);
            let (v, i, latched) = black_box(&mut buf);
            black_box(builder.build(v, i, latched));
        }
    });
    let per_sample = (t as f32 - base as f32) / ticks_per_instr / n as f32;
    println!("sampling_path={:.0}", per_sample);
    // At its worst: every sample's first step a glitch (the eight counts the sample's
    // own, about 10 counts from the last: rejected), so every sample's counts go through
    // the encoder check's count-by-count path.
    let mut builder = SampleBuilder::new(10_000, 50.0, &ranges, 4);
    let t = measure(|| {
        for k in 0..n {
            fill(black_box(k), &mut buf);
            let (v, i, latched) = black_box(&mut buf);
            let [.., own] = *latched;
            *latched = [own; OVERSAMPLING];
            black_box(builder.build(v, i, latched));
        }
    });
    let glitch = (t as f32 - base as f32) / ticks_per_instr / n as f32;
    println!("sampling_path_encoder_rejects={:.0}", glitch);
    per_sample
}

/// The sample path's Thumb-2 kernels (`src/acquisition/thumb.rs`) against their Rust
/// (module docs, 4): `sum_clipped` against `sum_clipped_portable` and `PwmFilter::step`
/// against `PwmFilter::step_portable`, on the replay's samples and on 20 000 pseudo-random
/// samples (codes anywhere in 0..=4095, a tenth of them on a range's edges), with the
/// built-in ranges, the rails alone, channels of different ranges and a narrow range that
/// clips most conversions; the encoder check's ([`encoder::check_encoder_kernel`]). Prints
/// `kernels=pass` or the mismatches; `false` on any, or when no sample of the encoder's
/// went through the counter's wrap.
fn check_kernels(n: usize) -> bool {
    use acquisition::{sum_clipped, sum_clipped_portable, PwmFilter, HALF_LEN};
    let limits = KERNEL_RANGES.map(|r| acquisition::ClipLimits::new(&r));
    let mut seed = 0x2545_F491u32;
    let mut buf = (
        [0u16; HALF_LEN],
        [0u16; HALF_LEN],
        [0u16; acquisition::OVERSAMPLING],
    );
    let (mut filter, mut reference) = (PwmFilter::new(10_000, 50.0), PwmFilter::new(10_000, 50.0));
    let (mut checked, mut clipped, mut mismatches) = (0u32, 0u32, 0u32);
    for k in 0..n + 20_000 {
        if k < n {
            fill(k, &mut buf);
        } else {
            for code in buf.0.iter_mut().chain(buf.1.iter_mut()) {
                *code = random_code(&mut seed);
            }
        }
        for lim in &limits {
            for half in [&buf.0, &buf.1] {
                let (got, want) = (sum_clipped(half, lim), sum_clipped_portable(half, lim));
                checked += 1;
                clipped += u32::from(want.1);
                if got != want {
                    mismatches += 1;
                    if mismatches <= 5 {
                        println!(
                            "mismatch kernel=sum_clipped sample={} got={:?} want={:?}",
                            k, got, want
                        );
                    }
                }
            }
        }
        let (v, i) = (
            sum_clipped_portable(&buf.0, &limits[0]).0,
            sum_clipped_portable(&buf.1, &limits[0]).0,
        );
        let count = k as u16;
        let (got, want) = (
            filter.step(v, i, count),
            reference.step_portable(v, i, count),
        );
        if got != want {
            mismatches += 1;
            if mismatches <= 5 {
                println!(
                    "mismatch kernel=filter sample={} got={:?} want={:?}",
                    k, got, want
                );
            }
        }
    }
    let (encoder_mismatches, wrapped) = encoder::check_encoder_kernel(n, &mut seed);
    kernel_verdict(checked, clipped, mismatches + encoder_mismatches) && wrapped
}

/// [`check_kernels`]' ranges: the built-in ones, the rails alone, channels of different
/// ranges, and a narrow range that clips most conversions.
const KERNEL_RANGES: [[acquisition::LinearRange; 3]; 4] = {
    use acquisition::LinearRange;
    const fn r(low: u16, high: u16) -> LinearRange {
        LinearRange { low, high }
    }
    [
        [r(62, 4033); 3],
        [LinearRange::RAILS; 3],
        [r(115, 4033), r(62, 4033), r(62, 3976)],
        [r(1500, 2600), r(0, 2048), r(2047, 4095)],
    ]
};

/// [`check_kernels`]' next pseudo-random code from `seed` (xorshift32): anywhere in
/// 0..=4095, a tenth of them on a range's edges.
fn random_code(seed: &mut u32) -> u16 {
    const EDGES: [u16; 12] = [0, 1, 61, 62, 63, 114, 115, 116, 3976, 4032, 4033, 4095];
    *seed ^= *seed << 13;
    *seed ^= *seed >> 17;
    *seed ^= *seed << 5;
    let x = *seed;
    if x % 10 == 0 {
        EDGES[(x / 10) as usize % EDGES.len()]
    } else {
        (x >> 8) as u16 & 0x0FFF
    }
}

/// Prints [`check_kernels`]' counts and `kernels=pass` or `FAIL`: whether the kernels
/// passed (no mismatch, and some of the `checked` clip checks `clipped` but not all).
fn kernel_verdict(checked: u32, clipped: u32, mismatches: u32) -> bool {
    println!(
        "kernel_checks={} kernel_checks_clipped={}",
        checked, clipped
    );
    println!("kernels={}", if mismatches == 0 { "pass" } else { "FAIL" });
    mismatches == 0 && clipped > 0 && clipped < checked
}

/// Sample `k`'s conversions and latched counts written into `buf` as the DMA writes its
/// rings: its six codes as the [`acquisition::OVERSAMPLING`] sequences of each ADC; the
/// counts latched at its eight triggers advancing evenly from the previous sample's count to
/// its own (the replay's shaft turns about 10 counts a sample: 1.25 a trigger, within the
/// encoder check's 4). Out of line: the base loop and the measured one of
/// [`count_sampling_path`] run the same code.
#[inline(never)]
pub(crate) fn fill(
    k: usize,
    buf: &mut (
        [u16; acquisition::HALF_LEN],
        [u16; acquisition::HALF_LEN],
        [u16; acquisition::OVERSAMPLING],
    ),
) {
    use acquisition::{CHANNELS, OVERSAMPLING};
    let (v, i, latched) = buf;
    let at = scenario::REPLAY_HEADER + k * scenario::SAMPLE_BYTES;
    let c = |x: usize| scenario::u16_at(REPLAY, at + 2 * x);
    for (j, (v, i)) in v.iter_mut().zip(i.iter_mut()).enumerate() {
        *v = c(j % CHANNELS);
        *i = c(CHANNELS + j % CHANNELS);
    }
    let count = c(6);
    let previous = match k.checked_sub(1) {
        Some(p) => scenario::u16_at(
            REPLAY,
            scenario::REPLAY_HEADER + p * scenario::SAMPLE_BYTES + 12,
        ),
        None => count,
    };
    let step = i32::from(count.wrapping_sub(previous) as i16);
    for (t, l) in (1i32..).zip(latched.iter_mut()) {
        *l = previous.wrapping_add((step * t / OVERSAMPLING as i32) as u16);
    }
}

/// Counts the instructions of the isolation's thread-mode work per 0.1 s block (module
/// docs, 3) and prints them: `isolate_single` (`Isolator::isolate_scaled`, the averaged
/// point) and `isolate_joint` (`Isolator::isolate_points_anchored` over [`MAX_POINTS`]
/// points and an anchor). The points are the monitor's steady points
/// (`SteadyPoint::from_output`) over the last quarter of the replay with the voltage read
/// 5 % high, a deviation, so that every hypothesis is fitted (a point without deviation
/// returns early); the anchor is the last point as read. The isolator is the replay's
/// machine on its supply (400 V, 50 Hz).
fn count_isolation(cfg: &MonitorConfig, n: usize, ticks_per_instr: f32) {
    let Ok(mut monitor) = Monitor::new(*cfg) else {
        semihosting::exit(false);
    };
    let Ok(isolator) = Isolator::new(scenario::motor(), 400.0 * 0.816_496_6, 50.0) else {
        semihosting::exit(false);
    };
    let mut points = [(SteadyPoint::default(), 1.0f32); MAX_POINTS];
    let mut anchor = SteadyPoint::default();
    let spacing = n / (4 * MAX_POINTS);
    for k in 0..n {
        let out = monitor.update(&scenario::sample(REPLAY, k));
        let from_end = n - 1 - k;
        if spacing > 0 && from_end.is_multiple_of(spacing) && from_end / spacing < MAX_POINTS {
            let mut p = SteadyPoint::from_output(out);
            if from_end == 0 {
                anchor = p;
            }
            p.v.d *= 1.05;
            p.v.q *= 1.05;
            points[from_end / spacing] = (p, 1.0);
        }
    }
    let mut single = None;
    let t_single = measure(|| {
        single = Some(black_box(isolator.isolate_scaled(&points[0].0, 1.0)));
    });
    let mut joint = None;
    let t_joint = measure(|| {
        joint = Some(black_box(
            isolator.isolate_points_anchored(&points, Some(&anchor)),
        ));
    });
    let instr = |t: u32| t as f32 / ticks_per_instr;
    let state = |i: Option<monitor_core::Isolation>| i.map(|i| (i.state, i.deviation));
    println!("isolate_single_state={:?}", state(single));
    println!("isolate_joint_state={:?}", state(joint));
    println!("isolate_single={:.0}", instr(t_single));
    println!("isolate_joint_{}_points={:.0}", MAX_POINTS, instr(t_joint));
}

#[panic_handler]
fn panic(_: &core::panic::PanicInfo) -> ! {
    semihosting::write0(b"panic\n\0");
    semihosting::exit(false)
}
