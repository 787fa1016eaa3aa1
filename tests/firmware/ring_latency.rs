//! The sample path against the worst-case latency of the latency budget
//! (`drive_monitor::acquisition`, "The latency budget"), on a timing model of the board:
//! the DMA completing each half of the ring on the sample clock, thread mode logging status
//! lines back to back (each a critical section of the budget's longest frame, with a short,
//! varying stretch of interrupts enabled between two frames, so that the frames sweep every
//! phase of the sample clock), the half's interrupt taken when interrupts are enabled again,
//! then the other interrupts, the executor at their worst, the copy of the half and the work
//! on its samples (the sample task preempts thread mode, which waits for it). A half is
//! lapped when its copy ends after the DMA started writing into it again (embassy's ring
//! reports it as an overrun and the firmware recovers the acquisition).
//!
//! The model is the board's timing, not the budget's sum: it only takes the budget's terms
//! as the worst case of each event, and counts the laps over a simulated hour.

use drive_monitor::acquisition::{
    conversion_ns, lap_cycles, lap_latency_cycles, sample_period_cycles, worst_cycles,
    worst_latency_cycles, CHANNELS, COPY_INSTRUCTIONS, DMA_HANDLER_CYCLES, EXECUTOR_CYCLES,
    INTERRUPT_ENTRY_CYCLES, LAP_FRAME_CYCLES, LOG_FRAME_CYCLES, OTHER_INTERRUPTS_CYCLES,
    OVERSAMPLING, SAMPLES_PER_HALF, SAMPLE_WORK_INSTRUCTIONS,
};
use drive_monitor::clock::HCLK_HZ;

/// The firmware's sample rate [Hz].
const FS: u32 = 10_000;

/// What the model counted.
#[derive(Debug, Default)]
struct Run {
    halves: u64,
    laps: u64,
    /// The longest time from a half's completion to its samples processed [cycles].
    worst_latency: u64,
    /// The longest time from a half's completion to its copy done [cycles].
    worst_copy: u64,
    frames: u64,
}

/// A small deterministic generator for the gaps between log frames.
struct Lcg(u64);

impl Lcg {
    fn next(&mut self, below: u64) -> u64 {
        self.0 = self
            .0
            .wrapping_mul(6_364_136_223_846_793_005)
            .wrapping_add(1_442_695_040_888_963_407);
        (self.0 >> 33) % below
    }
}

/// The cycles of the board's code in the model: the budget's expected 2.1 cycles an
/// instruction, or the lap case's 2.6 (`acquisition::LAP_CYCLES_PER_INSTRUCTION_X10`).
#[derive(Clone, Copy, Debug)]
enum Cpi {
    Expected,
    LapCase,
}

impl Cpi {
    fn cycles(self, instructions: u32) -> u64 {
        u64::from(match self {
            Cpi::Expected => worst_cycles(instructions),
            Cpi::LapCase => lap_cycles(instructions),
        })
    }

    /// The longest log frame's critical section [cycles].
    fn frame(self) -> u64 {
        u64::from(match self {
            Cpi::Expected => LOG_FRAME_CYCLES,
            Cpi::LapCase => LAP_FRAME_CYCLES,
        })
    }
}

/// Runs `seconds` of sampling with `samples_per_half` samples per DMA half against a log
/// flood of `frame` cycles per frame, the board's code at `cpi`.
fn simulate(samples_per_half: u64, seconds: u64, frame: u64) -> Run {
    simulate_at(samples_per_half, seconds, frame, Cpi::Expected, 2_000)
}

/// [`simulate`] with the board's code at `cpi` and the stretches of interrupts enabled
/// between two frames up to `max_gap` cycles (uniform; the longer, the more evenly the
/// frames' starts cover the phases of the sample clock).
fn simulate_at(samples_per_half: u64, seconds: u64, frame: u64, cpi: Cpi, max_gap: u64) -> Run {
    let period = u64::from(sample_period_cycles(FS));
    let trigger = period / OVERSAMPLING as u64;
    let conversion = u64::from(conversion_ns()) * u64::from(HCLK_HZ) / 1_000_000_000;
    let wake = u64::from(
        INTERRUPT_ENTRY_CYCLES + DMA_HANDLER_CYCLES + OTHER_INTERRUPTS_CYCLES + EXECUTOR_CYCLES,
    );
    let work = cpi.cycles(SAMPLE_WORK_INSTRUCTIONS);
    // The copy of one sample's 2 x 24 words (part of the work's figure, taken first).
    let copy = cpi.cycles(COPY_INSTRUCTIONS);
    let halves = seconds * u64::from(FS) / samples_per_half;
    let mut gaps = Lcg(0x5eed);
    let mut run = Run::default();
    // The next log frame's start; the sample task is busy until `task_free`.
    let mut frame_start = 0u64;
    let mut task_free = 0u64;
    for h in 0..halves {
        // The half's last word: the last sequence's third conversion.
        let triggers = (h + 1) * samples_per_half * OVERSAMPLING as u64;
        let complete = (triggers - 1) * trigger + CHANNELS as u64 * conversion;
        // The DMA writes the half's first word again two halves later.
        let overwrite = (triggers + samples_per_half * OVERSAMPLING as u64) * trigger + conversion;
        // Thread mode's frames up to the completion.
        while frame_start + frame <= complete {
            frame_start += frame + 20 + gaps.next(max_gap);
            frame_start = frame_start.max(task_free);
            run.frames += 1;
        }
        // Interrupts are masked from `frame_start` to its end.
        let irq = if complete >= frame_start {
            frame_start + frame
        } else {
            complete
        };
        let start = (irq + wake).max(task_free);
        let copied = start + copy * samples_per_half;
        if copied > overwrite {
            run.laps += 1;
        }
        task_free = start + work * samples_per_half;
        run.worst_copy = run.worst_copy.max(copied - complete);
        run.worst_latency = run.worst_latency.max(task_free - complete);
        run.halves += 1;
        // The frame that masked the interrupt ended; the next waits for the sample task.
        if complete >= frame_start {
            frame_start += frame + 20 + gaps.next(max_gap);
            run.frames += 1;
        }
        frame_start = frame_start.max(task_free);
    }
    run
}

/// The ring the budget chose takes an hour of status lines back to back at the worst-case
/// log frame, interrupt and executor latency without a lap, and the worst latency the model
/// sees is within the budget's.
#[test]
fn the_ring_is_never_lapped_over_an_hour_at_the_worst_case_latency() {
    let k = SAMPLES_PER_HALF as u64;
    let run = simulate(k, 3_600, u64::from(LOG_FRAME_CYCLES));
    println!("{run:?}");
    assert_eq!(run.halves, 3_600 * u64::from(FS) / k);
    assert!(run.frames > 1_000_000, "{run:?}");
    assert_eq!(run.laps, 0, "{run:?}");
    assert!(
        run.worst_latency <= u64::from(worst_latency_cycles(SAMPLES_PER_HALF as u32)),
        "{run:?}"
    );
    // The frames did hit the halves' interrupts: the worst case was reached.
    assert!(run.worst_copy > u64::from(LOG_FRAME_CYCLES), "{run:?}");
}

/// The control: the former ring of one sample per half, under the same log, is lapped
/// (the 17 000 cycles of slack are less than the frame and the wake-up), and the budget's
/// ring still holds at a log frame 15 % longer than the budget's.
#[test]
fn one_sample_per_half_is_lapped_by_the_same_log() {
    let run = simulate(1, 60, u64::from(LOG_FRAME_CYCLES));
    assert!(run.laps > 1_000, "{run:?}");
    let longer = u64::from(LOG_FRAME_CYCLES) * 115 / 100;
    let run = simulate(SAMPLES_PER_HALF as u64, 60, longer);
    assert_eq!(run.laps, 0, "{run:?}");
}

/// The ring's depth tested by the laps it prevents: at the lap case (the board's code at
/// 2.6 cycles an instruction, a quarter more than the budget's assumed 2.1, with its
/// longest log frame, 31 221 cycles of interrupts masked), the ring of two samples per half
/// (the depth before the budget's) is lapped within a minute of status lines back to back;
/// the firmware's three take an hour of them without a lap, the longest copy within the
/// budget's lap latency.
#[test]
fn at_the_lap_case_two_samples_per_half_lap_and_three_do_not() {
    let frame = Cpi::LapCase.frame();
    // Gaps up to a half's period: the frames' starts cover every phase of the halves.
    let gap = 3 * u64::from(sample_period_cycles(FS));
    let two = simulate_at(2, 60, frame, Cpi::LapCase, gap);
    assert!(two.laps > 100, "{two:?}");
    let run = simulate_at(SAMPLES_PER_HALF as u64, 3_600, frame, Cpi::LapCase, gap);
    println!("{run:?}");
    assert_eq!(run.laps, 0, "{run:?}");
    assert!(run.frames > 1_000_000, "{run:?}");
    assert!(
        run.worst_copy <= u64::from(lap_latency_cycles(SAMPLES_PER_HALF as u32)),
        "{run:?}"
    );
    // The worst case was reached: a frame hit a half's request.
    assert!(run.worst_copy > frame, "{run:?}");
}

/// A flash page erase (about 22 ms, 3.74 M cycles) with interrupts masked, as embassy's
/// region API erases: no ring of up to eight samples per half survives it (the firmware's
/// deepest, 800 us). It is not a term of the budget: the firmware pauses the acquisition
/// around every erase (`app::carry_out`, `tests/sil/flash_pause.rs`) and erases with
/// interrupts enabled.
#[test]
fn a_masked_flash_erase_laps_any_ring() {
    let erase = 22 * u64::from(HCLK_HZ) / 1_000;
    for k in 1..=8 {
        let run = simulate(k, 1, erase);
        assert!(run.laps > 0, "{k} samples per half: {run:?}");
    }
}

/// The status line cannot hold interrupts off longer than the budget's frame: its bytes
/// at their worst (the line `cargo qemu-rtt` measured, 197 B, with each of its six name
/// fields at the longest name the firmware can log instead of the QEMU program's, plus
/// the timestamp's 10 bytes at most and one byte of framing for every 7 added) are within
/// `LOG_FRAME_MAX_BYTES`, on which the budget's frame is computed. A field added to the line,
/// or a longer name, fails here until the budget (and so the ring's depth) covers it.
#[test]
fn the_status_line_fits_the_log_frame_budget() {
    use drive_monitor::acquisition::{LOG_FRAME_MAX_BYTES, LOG_MEASURED_BYTES};
    use drive_monitor::panel::Mode;
    use monitor_core::verdict::Verdict;
    use monitor_core::{Fault, Phase};

    let read = |rel: &str| {
        std::fs::read_to_string(std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join(rel)).unwrap()
    };
    // The six string arguments the QEMU program logs, in the line's order.
    let qemu = read("crates/rtt-on-m4/src/main.rs");
    let call = &qemu[qemu.find("info!(").expect("the status line")..];
    let args = &call[call.find("\",").expect("the format's end") + 2..];
    let args = &args[..args.find(");").expect("the call's end")];
    let measured: Vec<&str> = args.split('"').skip(1).step_by(2).collect();
    assert_eq!(measured.len(), 6, "{measured:?}");
    // The firmware's longest in each field: call, top, 2nd, mode, iso, wind.
    let faults: Vec<&str> = Fault::ALL.iter().map(|f| f.name()).collect();
    let longest = |names: &[&str]| names.iter().map(|n| n.len()).max().unwrap_or(0);
    let calls = [
        Verdict::Fault,
        Verdict::Watching,
        Verdict::Healthy,
        Verdict::CouldNotJudge,
    ]
    .map(Verdict::name);
    let modes = [
        Mode::NotCommissioned,
        Mode::Commissioning,
        Mode::Commissioned,
        Mode::SamplingStalled,
        Mode::Failed,
    ]
    .map(Mode::name);
    let candidates: Vec<&str> = faults.iter().copied().chain(["none"]).collect();
    let isolation: Vec<&str> = faults
        .iter()
        .copied()
        .chain(["b/bl", "none", "not-judged", "unknown"])
        .collect();
    let winding: Vec<&str> = Phase::ALL
        .iter()
        .map(|p| p.name())
        .chain(["none"])
        .collect();
    let worst = [
        longest(&calls),
        longest(&candidates),
        longest(&candidates),
        longest(&modes),
        longest(&isolation),
        longest(&winding),
    ];
    let added: usize = worst
        .iter()
        .zip(&measured)
        .map(|(w, m)| w.saturating_sub(m.len()))
        .sum();
    let bound = LOG_MEASURED_BYTES as usize + added + 10 + added.div_ceil(7);
    println!("status line: at most {bound} B ({added} B of longer names)");
    assert!(added > 0);
    assert!(bound <= LOG_FRAME_MAX_BYTES as usize, "{bound} B");
}
