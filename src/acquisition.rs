//! The acquisition's geometry, written once for the firmware and the host's model of the
//! ADC and DMA (`tests/sil/recovery.rs`): channels per ADC, oversampling, the DMA ring's
//! length, the sampling time and the conversion time it gives; the averaging of the
//! oversampled sequences into one sample ([`average_half`]); and one sample's frame from its
//! conversions ([`SampleBuilder`]).
//!
//! **Oversampling against the inverter's PWM.** An inverter switches at 2-16 kHz; its
//! line-to-neutral voltage is a pulse train whose switching components (around multiples
//! of the carrier, `m f_c +- n f_1`) are hundreds of volts. Sampled at the monitor's
//! 10 kHz behind the front end's single-pole 16 kHz RC, a component at `f` folds to
//! `|f - k f_s|`: 4 kHz switching puts its fifth group (20 kHz +- 50 Hz) onto the
//! fundamental, 8 kHz its fifth (40 kHz), 16 kHz its fifth (80 kHz), attenuated by the RC
//! only to 0.62, 0.37 and 0.20. So TIM1 triggers both ADCs [`OVERSAMPLING`] times per
//! sample (80 kHz) and the sample is the mean of the [`OVERSAMPLING`] sequences spread
//! evenly over the sample period: a moving average over one whole period, whose gain is
//! zero at every multiple of the sample rate, where the folding to the fundamental comes
//! from (`|sin(pi f N / f_t) / (N sin(pi f / f_t))|`, `f_t` the trigger rate). What
//! still folds is what lies near multiples of the trigger rate (80 kHz: the RC's 0.20
//! times the PWM's small high-order groups there); docs/firmware.md gives the front end's
//! anti-alias requirement and the figures.
//!
//! **The in-band ripple.** A carrier below half the sample rate (4 kHz at 10 kHz), or one
//! whose groups fold to a few kHz (8 kHz: its second group at 16 kHz lands on 4 kHz, its
//! first on 2 kHz), is not an alias of the fundamental but ripple in band: tens of volts
//! at kHz on every reading. It does not move the fundamental, but it moves the monitor's
//! fast quantities (measured: a 4 kHz inverter lit r1 and r4 on a healthy machine, and the
//! host's isolation found no steady operating point). [`PwmFilter`] takes it out: two
//! one-pole low-passes on the six channels alike, the fundamental's gain restored, the
//! encoder held back by the filters' delay.
//!
//! **The latency budget.** The sample task copies each DMA half out of the ring after the
//! half-transfer (or transfer-complete) interrupt, through the DMA interrupt and the
//! interrupt executor; the DMA writes into that half again [`SAMPLES_PER_HALF`] sample
//! periods after it completed it. Everything that can delay the copy is a term of
//! [`worst_latency_cycles`], each at its worst, in CPU cycles of [`clock::HCLK_HZ`]: a log
//! frame that masked interrupts just before the request ([`LOG_FRAME_CYCLES`], defmt-rtt
//! holds a critical section for a whole frame, the status line being the longest), the
//! interrupt's entry, the DMA handler, the other interrupts, the executor and the work on
//! the half's samples. The ring's depth is the smallest that covers it at the lap case
//! ([`samples_per_half_for`], [`LAP_CYCLES_PER_INSTRUCTION_X10`]): at 10 kHz and 170 MHz
//! one sample per half (a copy 36 917 cycles after the request against 18 831 of slack) and
//! two (37 177 against 35 831) are lapped, three (37 437 against 52 831) are not. The
//! host's model (`tests/firmware/ring_latency.rs`) runs the sample path against that worst case for
//! a simulated hour and counts no lap.
//!
//! **Per sample** ([`SampleBuilder`], what the sample task runs and `cargo qemu-core`
//! counts): the oversampled sums with every conversion checked against its channel's
//! linear range ([`sum_clipped`]), the clip held ([`ClipHold`]), the latched encoder counts
//! checked and averaged ([`EncoderCheck::sample`]), [`PwmFilter`]; the check and the
//! filter's stages are Thumb-2 kernels on the Cortex-M4 (`acquisition/thumb.rs`).

use crate::clock;

/// Channels per ADC: ADC1 va, vb, vc; ADC2 ia, ib, ic (the regular sequence's length,
/// [`crate::adc_rules::CHANNELS`], kept there so that the recovery below this module
/// re-arms the encoder latch with it too).
pub use crate::adc_rules::CHANNELS;
// The checks of a sample's conversions (clipping) and of the latched encoder counts (steps
// beyond the maximum speed): a file of their own, compiled with this one wherever it is
// (the firmware's library, the QEMU program).
#[path = "acquisition/checks.rs"]
mod checks;
// The sample path's three kernels in Thumb-2 assembly (the per-conversion clip check with the
// oversampled sums, the filter's stages, the encoder check's steps): on the Cortex-M4 only;
// the host runs their Rust.
#[cfg(target_arch = "arm")]
#[path = "acquisition/thumb.rs"]
mod thumb;
// The channels' linear ranges and one ADC's clip check precomputed from them, which the
// checks and the kernels both read: below either.
#[path = "acquisition/limits.rs"]
mod limits;
// The in-band ripple's filter (module docs, "The in-band ripple").
#[path = "acquisition/filter.rs"]
mod filter;
// The QEMU program uses a part of them.
#[allow(unused_imports)]
pub use checks::{
    max_step_per_trigger, steps_ored, steps_ored_portable, sum_clipped, sum_clipped_portable,
    ClipHold, EncoderCheck, CLIP_HOLD_SAMPLES, FAST_MAX_STEP,
};
#[allow(unused_imports)]
pub use filter::{PwmFilter, ENCODER_DELAY_SAMPLES};
#[allow(unused_imports)]
pub use limits::{ClipLimits, LinearRange, LinearRanges};

/// Sequences (triggers) averaged into one sample (module docs).
pub const OVERSAMPLING: usize = 8;
/// 16-bit words of one sample's sequences ([`OVERSAMPLING`] x [`CHANNELS`], 24): the unit
/// [`sum_half`] and [`average_half`] take. (The name is older than the deeper ring: a DMA
/// half now holds [`SAMPLES_PER_HALF`] of them, [`DMA_HALF_LEN`] words.)
pub const HALF_LEN: usize = OVERSAMPLING * CHANNELS;
/// Samples per DMA half buffer, chosen from the latency budget
/// ([`samples_per_half_for`] at [`BUDGET_SAMPLE_RATE_HZ`]; module docs, "The latency
/// budget"): 3 at 10 kHz and 170 MHz.
pub const SAMPLES_PER_HALF: usize = samples_per_half_for(BUDGET_SAMPLE_RATE_HZ);
/// 16-bit words in one DMA half buffer ([`SAMPLES_PER_HALF`] samples' sequences).
pub const DMA_HALF_LEN: usize = SAMPLES_PER_HALF * HALF_LEN;
/// The DMA ring's length per ADC in 16-bit words (two halves), which is also the
/// channel's `CNDTR` at the start of a turn.
pub const RING_LEN: usize = 2 * DMA_HALF_LEN;

/// The encoder latch's ring length in counts: TIM1's trigger makes the encoder timer
/// capture its count (TIM4 channel 3 on `TRC`, the trigger's `TRGO`) and the capture's DMA
/// request copies it into a ring of its own, one count per sequence, the same two halves
/// as the ADCs' rings (48).
pub const LATCH_LEN: usize = RING_LEN / CHANNELS;
/// Counts in one half of the latch's ring (24).
pub const LATCH_HALF_LEN: usize = LATCH_LEN / 2;

/// One sample's encoder count from the counts latched at its [`OVERSAMPLING`] triggers
/// (`latched`, oldest first): their mean, the shortest way round the 16-bit counter from
/// the first, rounded; the instant of the readings' mean, as the oversampled sum is. An
/// empty slice gives 0.
#[inline]
pub fn sample_count(latched: &[u16]) -> u16 {
    let Some(&first) = latched.first() else {
        return 0;
    };
    let n = latched.len() as i32;
    let sum: i32 = latched
        .iter()
        .map(|&c| i32::from(c.wrapping_sub(first) as i16))
        .sum();
    let mean = (2 * sum + n).div_euclid(2 * n);
    first.wrapping_add(mean as u16)
}

/// The sample rate the ring is sized for [Hz] (the firmware's `SETTINGS`, checked there at
/// compile time with [`ring_fits`]).
pub const BUDGET_SAMPLE_RATE_HZ: u32 = 10_000;
/// The status line's bytes as `cargo qemu-rtt` measured them (2 005 B for ten lines, 200.5 B
/// a line, rounded up; with issue 74's `clip=`, `enc_rej=`, `stack=` and `clip_range=`:
/// 197 B before them, the bool packed with the line's others), with the names the QEMU
/// program logs.
pub const LOG_MEASURED_BYTES: u32 = 201;
/// The instructions that line took with interrupts masked under QEMU
/// (`flood_max_late_instructions=9440`: defmt-rtt holds a critical section for a whole
/// frame, encoding and copying it byte by byte; 8 960 before issue 74's fields, 9 400
/// before `clip_range=`).
pub const LOG_MEASURED_INSTRUCTIONS: u32 = 9_440;
/// The longest frame the firmware logs [bytes]: the status line with the longest name in
/// each of its six name fields, the frame's timestamp and the framing's overhead
/// (`tests/firmware/ring_latency.rs` computes the bound from the names and fails when the line
/// outgrows it).
pub const LOG_FRAME_MAX_BYTES: u32 = 268;
/// The longest frame's instructions, with interrupts masked: the measured line's cost per
/// byte times [`LOG_FRAME_MAX_BYTES`], rounded up (12 587).
pub const LOG_FRAME_INSTRUCTIONS: u32 =
    (LOG_MEASURED_INSTRUCTIONS * LOG_FRAME_MAX_BYTES).div_ceil(LOG_MEASURED_BYTES);
/// CPU cycles per instruction on the worst path, x 10 (an assumption, not measured: the
/// G474 at 170 MHz runs the flash with 4 wait states behind the ART cache; loads, taken
/// branches and cache misses put a frame of 9 000 instructions at 60-110 us): 2.1.
pub const WORST_CYCLES_PER_INSTRUCTION_X10: u32 = 21;
/// The Cortex-M4F's interrupt entry with the FPU's lazy stacking and flash wait states
/// [cycles] (12 cycles from the architecture, more than doubled).
pub const INTERRUPT_ENTRY_CYCLES: u32 = 30;
/// One DMA channel's half/full-transfer interrupt: the firmware's check of `TEIF`, then
/// embassy's handler waking the ring's reader [cycles] (about 150 instructions, x 2.1,
/// rounded up).
pub const DMA_HANDLER_CYCLES: u32 = 400;
/// Other interrupts that may run first at the same or a higher priority: the other ADC's
/// DMA channel, embassy-time's alarm (TIM15) and the button's EXTI [cycles].
pub const OTHER_INTERRUPTS_CYCLES: u32 = 1_500;
/// The interrupt executor from the pended `UART4` to the sample task's code after its
/// awaits: the poll, the `with_timeout` future and its timer queue entry [cycles].
pub const EXECUTOR_CYCLES: u32 = 2_000;
/// One sample's work at its worst [instructions] (`cargo qemu-core`: the sampling path's
/// 639 when the sample's latched counts go through the encoder check count by count, a
/// glitch or the first sample after a restart (318 otherwise: the oversampled sums with
/// the per-conversion clip check, the encoder counts' check and their mean, the filter;
/// `sampling_path_encoder_rejects` and `sampling_path`); the core's fast path 213 and, on
/// every 25th sample, its slow path's 785), plus copying its 2 x 24 words out of the rings
/// ([`COPY_INSTRUCTIONS`]).
pub const SAMPLE_WORK_INSTRUCTIONS: u32 = 639 + 213 + 785 + COPY_INSTRUCTIONS;

/// `instructions` at [`WORST_CYCLES_PER_INSTRUCTION_X10`] [cycles], rounded up.
pub const fn worst_cycles(instructions: u32) -> u32 {
    (instructions * WORST_CYCLES_PER_INSTRUCTION_X10).div_ceil(10)
}

/// The longest critical section a log frame may hold [CPU cycles]: 26 433 (155 us at
/// 170 MHz).
pub const LOG_FRAME_CYCLES: u32 = worst_cycles(LOG_FRAME_INSTRUCTIONS);

/// The worst-case sample-path latency [CPU cycles] with `samples_per_half` samples per DMA
/// half: from the half-transfer interrupt's request to the half copied out and its samples
/// processed, the worst case of every term at once (a log frame that masked interrupts
/// just before the request, the interrupt, the other interrupts, the executor, the work).
pub const fn worst_latency_cycles(samples_per_half: u32) -> u32 {
    LOG_FRAME_CYCLES
        + INTERRUPT_ENTRY_CYCLES
        + DMA_HANDLER_CYCLES
        + OTHER_INTERRUPTS_CYCLES
        + EXECUTOR_CYCLES
        + samples_per_half * worst_cycles(SAMPLE_WORK_INSTRUCTIONS)
}

/// One sample period [CPU cycles] at `sample_rate_hz` (17 000 at 10 kHz; 0 for 0 Hz).
pub const fn sample_period_cycles(sample_rate_hz: u32) -> u32 {
    match clock::HCLK_HZ.checked_div(sample_rate_hz) {
        Some(c) => c,
        None => 0,
    }
}

/// Cycles per instruction of the **lap case**, x 10: the expected
/// [`WORST_CYCLES_PER_INSTRUCTION_X10`] (2.1, an assumption no board has measured) plus a
/// quarter, 2.6. The ring is sized so that it holds even where the assumption is a quarter
/// too low: at 2.1 a ring of two samples per half would hold (its copy 30 783 cycles after
/// the request, the DMA back 35 831 after it), at 2.6 it is lapped (37 177), and three
/// hold (37 437 against 52 831; up to 3.7 cycles an instruction). `tests/firmware/ring_latency.rs`
/// runs the board's events at this case.
pub const LAP_CYCLES_PER_INSTRUCTION_X10: u32 = 26;
/// Instructions to copy one sample's 2 x 24 words out of the rings (part of
/// [`SAMPLE_WORK_INSTRUCTIONS`], done first).
pub const COPY_INSTRUCTIONS: u32 = 100;

/// `instructions` at [`LAP_CYCLES_PER_INSTRUCTION_X10`] [cycles], rounded up.
pub const fn lap_cycles(instructions: u32) -> u32 {
    (instructions * LAP_CYCLES_PER_INSTRUCTION_X10).div_ceil(10)
}

/// The longest log frame at the lap case's cycles per instruction [CPU cycles]: 32 727
/// (193 us at 170 MHz).
pub const LAP_FRAME_CYCLES: u32 = lap_cycles(LOG_FRAME_INSTRUCTIONS);

/// The lap latency [CPU cycles] with `samples_per_half` samples per DMA half: from the
/// half's interrupt request to the half copied out of the ring (what the DMA must not
/// overwrite first), every term at its worst at once and the instructions at the lap
/// case's cycles per instruction: a log frame that masked interrupts just before the
/// request, the entry, the DMA handler, the other interrupts, the executor, the copy.
pub const fn lap_latency_cycles(samples_per_half: u32) -> u32 {
    LAP_FRAME_CYCLES
        + INTERRUPT_ENTRY_CYCLES
        + DMA_HANDLER_CYCLES
        + OTHER_INTERRUPTS_CYCLES
        + EXECUTOR_CYCLES
        + samples_per_half * lap_cycles(COPY_INSTRUCTIONS)
}

/// One conversion [CPU cycles], rounded down (147 at 170 MHz).
pub const fn conversion_cycles() -> u32 {
    (conversion_ns() as u64 * clock::HCLK_HZ as u64 / 1_000_000_000) as u32
}

/// The time a half's copy has [CPU cycles]: from the half's completion (its last
/// sequence's last conversion) to the DMA writing its first word again, two halves later:
/// `(OVERSAMPLING x samples_per_half + 1)` trigger periods less two conversions (18 831,
/// 35 831 and 52 831 cycles with 1, 2, 3 samples per half at 10 kHz).
pub const fn lap_slack_cycles(sample_rate_hz: u32, samples_per_half: u32) -> u32 {
    let trigger = sample_period_cycles(sample_rate_hz) / OVERSAMPLING as u32;
    ((OVERSAMPLING as u32 * samples_per_half + 1) * trigger)
        .saturating_sub((CHANNELS as u32 - 1) * conversion_cycles())
}

/// Whether a ring of two halves of `samples_per_half` samples holds at `sample_rate_hz`:
/// a half must be copied out before the DMA writes into it again ([`lap_latency_cycles`]
/// within [`lap_slack_cycles`], at the lap case), and the task must keep up (a half's work,
/// at the lap case, within a half's periods).
pub const fn ring_fits(sample_rate_hz: u32, samples_per_half: u32) -> bool {
    samples_per_half > 0
        && lap_latency_cycles(samples_per_half)
            <= lap_slack_cycles(sample_rate_hz, samples_per_half)
        && samples_per_half * lap_cycles(SAMPLE_WORK_INSTRUCTIONS)
            < samples_per_half * sample_period_cycles(sample_rate_hz)
}

/// The smallest number of samples per DMA half (1..=8) that tolerates the worst-case
/// latency at `sample_rate_hz` ([`ring_fits`]); 8 when none does (the firmware's
/// compile-time check then fails).
pub const fn samples_per_half_for(sample_rate_hz: u32) -> usize {
    let mut k = 1;
    while k < 8 {
        if ring_fits(sample_rate_hz, k) {
            return k as usize;
        }
        k += 1;
    }
    8
}

/// The regular channels' sampling time in ADC clock cycles, times 2 (`SMPx` = 24.5
/// cycles; halves are how RM0440 counts them): the front end drives each pin through
/// 1 kohm and 10 nF, far below the datasheet's source-resistance bound for 24.5 cycles
/// (about 11 kohm).
pub const SAMPLE_TIME_HALF_CYCLES: u32 = 49;
/// A 12-bit conversion's successive approximation in ADC cycles, times 2 (12.5 cycles).
pub const CONVERSION_HALF_CYCLES: u32 = 25;
/// One conversion [ADC clock cycles x 2]: sampling plus approximation (37 cycles).
pub const CONVERSION_TOTAL_HALF_CYCLES: u32 = SAMPLE_TIME_HALF_CYCLES + CONVERSION_HALF_CYCLES;

/// One conversion [ns] at [`clock::ADC_CLOCK_HZ`] (870 ns).
pub const fn conversion_ns() -> u32 {
    (CONVERSION_TOTAL_HALF_CYCLES as u64 * 1_000_000_000 / (2 * clock::ADC_CLOCK_HZ as u64)) as u32
}

/// One sequence of [`CHANNELS`] conversions [ns] (2.6 us).
pub const fn sequence_ns() -> u32 {
    conversion_ns() * CHANNELS as u32
}

/// The trigger rate [Hz] for `sample_rate_hz`: [`OVERSAMPLING`] sequences per sample.
pub const fn trigger_rate_hz(sample_rate_hz: u32) -> u32 {
    sample_rate_hz.saturating_mul(OVERSAMPLING as u32)
}

/// The longest the injected VREFINT conversion holds a regular sequence up [ns]: 247.5 +
/// 12.5 cycles (`supply::REFERENCE_SAMPLE_CYCLES`), once a second.
pub const fn reference_conversion_ns() -> u32 {
    (260 * 1_000_000_000_u64 / clock::ADC_CLOCK_HZ as u64) as u32
}

/// Whether the acquisition fits `sample_rate_hz` (the firmware checks its rate at compile
/// time): a sequence, even one held up by the reference's injected conversion, ends before
/// the next trigger (no overrun by design), and the timers' clock divides the trigger rate
/// exactly.
pub const fn fits(sample_rate_hz: u32) -> bool {
    let trigger = trigger_rate_hz(sample_rate_hz);
    trigger > 0
        && sequence_ns() + reference_conversion_ns() < 1_000_000_000 / trigger
        && clock::timer_divider(trigger).is_some()
}

/// The mean of each channel over the [`OVERSAMPLING`] sequences of one half buffer
/// `half` (`[a, b, c, a, b, c, ...]`, [`HALF_LEN`] words), rounded to the nearest code.
/// A shorter `half` averages the whole sequences it holds; an empty one gives zeros.
#[inline]
pub fn average_half(half: &[u16]) -> [u16; CHANNELS] {
    let mut sum = [0u32; CHANNELS];
    let mut n = 0u32;
    for seq in half.chunks_exact(CHANNELS) {
        for (s, &code) in sum.iter_mut().zip(seq) {
            *s += u32::from(code);
        }
        n += 1;
    }
    let n = n.max(1);
    sum.map(|s| ((s + n / 2) / n) as u16)
}

/// The sum of each channel over the sequences of one half buffer `half` (`[a, b, c, a,
/// b, c, ...]`) and how many sequences it held: what [`PwmFilter::step`] takes.
#[inline]
pub fn sum_half(half: &[u16]) -> ([u32; CHANNELS], u32) {
    let (sequences, _) = half.as_chunks::<CHANNELS>();
    let [mut a, mut b, mut c] = [0u32; CHANNELS];
    for &[x, y, z] in sequences {
        a += u32::from(x);
        b += u32::from(y);
        c += u32::from(z);
    }
    ([a, b, c], sequences.len() as u32)
}

/// What [`SampleBuilder::build`] makes of one sample.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct BuiltSample {
    /// The filtered voltage codes a, b, c.
    pub v: [u16; CHANNELS],
    /// The filtered current codes a, b, c.
    pub i: [u16; CHANNELS],
    /// The encoder count, held back with the filter's delay.
    pub count: u16,
    /// `[voltage, current]`: a conversion of the sample, or of the [`CLIP_HOLD_SAMPLES`]
    /// before it, was clipped ([`sum_clipped`], [`ClipHold`]).
    pub clipped: [bool; 2],
    /// The sample's latched counts rejected as a step beyond the maximum speed (0..=8).
    pub encoder_rejects: u8,
}

/// One sample's conversions and latched encoder counts -> its filtered codes and count,
/// with the checks: each ADC's oversampled sequences summed with every conversion checked
/// against its channel's linear range ([`sum_clipped`], the limits precomputed here; a clip
/// held through the filter's memory, [`ClipHold`]), the latched counts checked against the
/// maximum speed and averaged ([`EncoderCheck::sample`]), the inverter's ripple filtered out
/// ([`PwmFilter`]). What the sample task runs per sample (`app::FrameBuilder`) and what
/// `cargo qemu-core` counts (`sampling_path`). No allocation, no panics.
#[derive(Clone, Copy, Debug)]
pub struct SampleBuilder {
    filter: PwmFilter,
    hold: ClipHold,
    encoder: EncoderCheck,
    voltage: ClipLimits,
    current: ClipLimits,
}

impl SampleBuilder {
    /// A builder at `sample_rate_hz` whose filter restores the gain at `supply_hz`, with
    /// the channels' linear `ranges` (`motor_source::linear_ranges`) and the encoder's
    /// largest step between two triggers `max_step` (`motor_source::EncoderSetup`).
    pub fn new(sample_rate_hz: u32, supply_hz: f32, ranges: &LinearRanges, max_step: u16) -> Self {
        Self {
            filter: PwmFilter::new(sample_rate_hz, supply_hz),
            hold: ClipHold::default(),
            encoder: EncoderCheck::new(max_step),
            voltage: ClipLimits::new(&ranges.voltage),
            current: ClipLimits::new(&ranges.current),
        }
    }

    /// After a gap in the triggers (a recovery, a paused acquisition): the next latched
    /// count starts the encoder check afresh.
    pub fn restart(&mut self) {
        self.encoder.restart();
    }

    /// A sample that is dropped (`adc_rules::IdleDiscard`): its latched counts still go
    /// through the encoder check, so the next sample's first step is one trigger long.
    pub fn skip(&mut self, latched: &[u16; OVERSAMPLING]) {
        self.encoder.sample(latched);
    }

    /// One sample: `v` and `i` its sequences of ADC1 and ADC2 (`[a, b, c, a, b, c, ...]`),
    /// `latched` the encoder counts latched at its triggers (oldest first).
    #[inline(always)]
    pub fn build(
        &mut self,
        v: &[u16; HALF_LEN],
        i: &[u16; HALF_LEN],
        latched: &[u16; OVERSAMPLING],
    ) -> BuiltSample {
        // The counts first: the sums go to the filter as soon as they are made.
        let (count, encoder_rejects) = self.encoder.sample(latched);
        let (vs, v_clip) = sum_clipped(v, &self.voltage);
        let (is, i_clip) = sum_clipped(i, &self.current);
        let (v, i, count) = self.filter.step(vs, is, count);
        let clipped = self.hold.step([v_clip, i_clip]);
        BuiltSample {
            v,
            i,
            count,
            clipped,
            encoder_rejects,
        }
    }
}

#[cfg(test)]
#[path = "acquisition/tests.rs"]
mod tests;
