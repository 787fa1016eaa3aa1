//! The acquisition's geometry, written once for the firmware and the host's model of the
//! ADC and DMA (`tests/sil/recovery.rs`): channels per ADC, oversampling, the DMA ring's
//! length, the sampling time and the conversion time it gives; and the averaging of the
//! oversampled sequences into one sample ([`average_half`]).
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
//! the half's samples. The ring's depth is the smallest that covers it
//! ([`samples_per_half_for`]): at 10 kHz and 170 MHz one sample per half (17 000 cycles of
//! slack) does not, nor do two (34 000 against 34 889), three (51 000) do, with 37 760
//! cycles worst-case (222 us). The host's model
//! (`tests/ring_latency.rs`) runs the sample path against that worst case for a simulated
//! hour and counts no lap.

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
// The QEMU program uses a part of them.
#[allow(unused_imports)]
pub use checks::{
    max_step_per_trigger, sum_half_clipped, ClipHold, EncoderCheck, LinearRange, LinearRanges,
    CLIP_HOLD_SAMPLES,
};

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
/// a line, rounded up; with issue 74's `clip=`, `enc_rej=` and `stack=`: 197 B before),
/// with the names the QEMU program logs.
pub const LOG_MEASURED_BYTES: u32 = 201;
/// The instructions that line took with interrupts masked under QEMU
/// (`flood_max_late_instructions=9400`: defmt-rtt holds a critical section for a whole
/// frame, encoding and copying it byte by byte; 8 960 before issue 74's fields).
pub const LOG_MEASURED_INSTRUCTIONS: u32 = 9_400;
/// The longest frame the firmware logs [bytes]: the status line with the longest name in
/// each of its six name fields, the frame's timestamp and the framing's overhead
/// (`tests/ring_latency.rs` computes the bound from the names and fails when the line
/// outgrows it).
pub const LOG_FRAME_MAX_BYTES: u32 = 268;
/// The longest frame's instructions, with interrupts masked: the measured line's cost per
/// byte times [`LOG_FRAME_MAX_BYTES`], rounded up (12 008).
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
/// 918, with the per-conversion clip check, the encoder counts' check and their mean; the
/// core's fast path 211 and, on every 25th sample, its slow path's 784), plus copying its
/// 2 x 24 words out of the rings ([`COPY_INSTRUCTIONS`]).
pub const SAMPLE_WORK_INSTRUCTIONS: u32 = 918 + 211 + 784 + COPY_INSTRUCTIONS;

/// `instructions` at [`WORST_CYCLES_PER_INSTRUCTION_X10`] [cycles], rounded up.
pub const fn worst_cycles(instructions: u32) -> u32 {
    (instructions * WORST_CYCLES_PER_INSTRUCTION_X10).div_ceil(10)
}

/// The longest critical section a log frame may hold [CPU cycles]: 26 322 (155 us at
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
/// too low: at 2.1 a ring of two samples per half would hold (its copy 30 672 cycles after
/// the request, the DMA back 35 831 after it), at 2.6 it is lapped (37 039), and three
/// hold (37 299 against 52 831; up to 3.8 cycles an instruction). `tests/ring_latency.rs`
/// runs the board's events at this case.
pub const LAP_CYCLES_PER_INSTRUCTION_X10: u32 = 26;
/// Instructions to copy one sample's 2 x 24 words out of the rings (part of
/// [`SAMPLE_WORK_INSTRUCTIONS`], done first).
pub const COPY_INSTRUCTIONS: u32 = 100;

/// `instructions` at [`LAP_CYCLES_PER_INSTRUCTION_X10`] [cycles], rounded up.
pub const fn lap_cycles(instructions: u32) -> u32 {
    (instructions * LAP_CYCLES_PER_INSTRUCTION_X10).div_ceil(10)
}

/// The longest log frame at the lap case's cycles per instruction [CPU cycles]: 32 589
/// (192 us at 170 MHz).
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

/// Fractional bits of [`PwmFilter`]'s states.
const FILTER_FRAC_BITS: u32 = 12;
/// The first stage's coefficient `a = 2^-2` (a one-pole low-pass `y += a (x - y)` at 10 kHz:
/// -3 dB at 458 Hz).
const STAGE1_SHIFT: u32 = 2;
/// The second stage's coefficient `a = 2^-1` (-3 dB at 1.1 kHz at 10 kHz).
const STAGE2_SHIFT: u32 = 1;
/// Samples the encoder count is held back, the filters' delay at the fundamental
/// (`(1 - a) / a`: 3 and 1 samples) so that the shaft angle goes with the readings.
pub const ENCODER_DELAY_SAMPLES: usize = 4;

/// The in-band part of an inverter's ripple taken out of the six channels (module docs):
/// two one-pole low-passes in integer arithmetic on the oversampled sums ([`sum_half`]),
/// `a = 1/4` then `a = 1/2` at the sample rate (at 10 kHz: -3 dB at 458 Hz and 1.1 kHz;
/// gain 0.052 at 4 kHz, 0.12 at 2 kHz, where an 8 kHz carrier's second group lands), and
/// the fundamental's gain restored (`gain_q15`, from [`PwmFilter::new`]'s supply frequency:
/// at 50 Hz the two stages pass 0.993). All six channels are filtered alike, so the
/// machine's equations between the voltages and currents hold through it (a linear filter
/// commutes with a linear machine's equations in steady state); the encoder count is held
/// back [`ENCODER_DELAY_SAMPLES`] samples to go with them. No allocation, no panics.
#[derive(Clone, Copy, Debug)]
pub struct PwmFilter {
    /// Each channel's two stages (voltages a, b, c, then currents), in sums x 2^12.
    stages: [[i32; 2]; 2 * CHANNELS],
    /// The encoder counts of the last samples, a ring; `at` the oldest.
    counts: [u16; ENCODER_DELAY_SAMPLES],
    at: usize,
    /// The inverse of the stages' gain at the supply frequency, x 2^15.
    gain_q15: i32,
    primed: bool,
}

impl PwmFilter {
    /// A filter at `sample_rate_hz` whose gain at `supply_hz` is restored to 1 (invalid
    /// rates: no restoring).
    pub fn new(sample_rate_hz: u32, supply_hz: f32) -> Self {
        let w = core::f32::consts::TAU * supply_hz / sample_rate_hz as f32;
        // |a / (1 - b e^{-jw})|^2 of each stage.
        let gain2 = |shift: u32| {
            let a = 1.0 / (1u32 << shift) as f32;
            let b = 1.0 - a;
            let (re, im) = (1.0 - b * micro_cos(w), b * micro_sin(w));
            a * a / (re * re + im * im)
        };
        let g2 = gain2(STAGE1_SHIFT) * gain2(STAGE2_SHIFT);
        let gain_q15 = if g2.is_finite() && g2 > 0.25 && g2 <= 1.0 {
            (32768.0 * sqrt_near_one(1.0 / g2)) as i32
        } else {
            32768
        };
        Self {
            stages: [[0; 2]; 2 * CHANNELS],
            counts: [0; ENCODER_DELAY_SAMPLES],
            at: 0,
            gain_q15,
            primed: false,
        }
    }

    /// One sample: the voltages' and currents' sums over `n` sequences (from [`sum_half`])
    /// and the encoder count read after them; the filtered codes (rounded, within
    /// 0..=4095) and the encoder count of [`ENCODER_DELAY_SAMPLES`] samples ago. The first
    /// sample starts the stages at its own value (no run-up from zero).
    #[inline]
    pub fn step(
        &mut self,
        v: [u32; CHANNELS],
        i: [u32; CHANNELS],
        n: u32,
        count: u16,
    ) -> ([u16; CHANNELS], [u16; CHANNELS], u16) {
        let n = n.max(1) as i32;
        let (primed, gain) = (self.primed, self.gain_q15);
        let [va, vb, vc] = v;
        let [ia, ib, ic] = i;
        let [s0, s1, s2, s3, s4, s5] = &mut self.stages;
        let v = [
            filter_channel(s0, va, n, primed, gain),
            filter_channel(s1, vb, n, primed, gain),
            filter_channel(s2, vc, n, primed, gain),
        ];
        let i = [
            filter_channel(s3, ia, n, primed, gain),
            filter_channel(s4, ib, n, primed, gain),
            filter_channel(s5, ic, n, primed, gain),
        ];
        self.primed = true;
        if !primed {
            self.counts = [count; ENCODER_DELAY_SAMPLES];
        }
        let slot = self.counts.get_mut(self.at % ENCODER_DELAY_SAMPLES);
        let delayed = slot.map_or(count, |c| core::mem::replace(c, count));
        self.at = (self.at + 1) % ENCODER_DELAY_SAMPLES;
        (v, i, delayed)
    }
}

/// One channel of [`PwmFilter::step`]: the mean of `sum` over `n` sequences in codes x
/// 2^12 (n <= 8: 4095 x 2^12 < 2^24) through the two stages `st` (started at it when not
/// `primed`), the gain restored around mid-scale (the swing, not the offset), rounded to
/// a code within 0..=4095.
#[inline(always)]
fn filter_channel(st: &mut [i32; 2], sum: u32, n: i32, primed: bool, gain_q15: i32) -> u16 {
    let x = ((sum as i32) << FILTER_FRAC_BITS) / n;
    if !primed {
        *st = [x, x];
    }
    let [a, b] = st;
    *a += (x - *a) >> STAGE1_SHIFT;
    *b += (*a - *b) >> STAGE2_SHIFT;
    let mid = 2048 << FILTER_FRAC_BITS;
    let y = mid + ((i64::from(*b - mid) * i64::from(gain_q15)) >> 15) as i32;
    let code = (y + (1 << (FILTER_FRAC_BITS - 1))) >> FILTER_FRAC_BITS;
    code.clamp(0, 4095) as u16
}

/// `sqrt(x)` for `x` in 1..=4 (the inverse gain squared) by Newton's iteration from `x`:
/// six steps reach f32's precision there (no `std` on the board).
fn sqrt_near_one(x: f32) -> f32 {
    let mut y = x;
    for _ in 0..6 {
        y = 0.5 * (y + x / y);
    }
    y
}

/// cos for the filter's set-up (host and board alike: `micromath`-free Taylor series,
/// accurate to 1e-6 for |x| < 0.5, the supply's angle per sample).
fn micro_cos(x: f32) -> f32 {
    let x2 = x * x;
    1.0 - x2 / 2.0 + x2 * x2 / 24.0 - x2 * x2 * x2 / 720.0
}

/// sin, as [`micro_cos`].
fn micro_sin(x: f32) -> f32 {
    let x2 = x * x;
    x * (1.0 - x2 / 6.0 + x2 * x2 / 120.0 - x2 * x2 * x2 / 5040.0)
}

#[cfg(test)]
#[path = "acquisition/tests.rs"]
mod tests;
