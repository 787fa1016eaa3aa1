//! LED panel: what the lamps show, and the blink codes.
//!
//! A pure function of the panel's inputs and the time ([`render`]), so the exact patterns
//! are tested on the host. The firmware calls it every 50 ms and copies the result to the
//! pins. Which pin drives which lamp, and what a lit lamp means, is defined once in
//! `board.rs` ([`Lamp`]: [`Lamp::pin`], [`Lamp::meaning`]).
//!
//! # RUN lamp patterns (period 2 s)
//!
//! | pattern | meaning |
//! |---|---|
//! | 1 Hz blink (500 ms on / 500 ms off) | monitoring, commissioned (learned thresholds in force) |
//! | double flash (100 on, 100 off, 100 on, 1700 off) | monitoring, NOT commissioned (no valid record: default thresholds) |
//! | triple flash (100 on, 100 off, 100 on, 100 off, 100 on, 1500 off) | OPERATING POINT MOVED (the "amber" state): commissioned, but the load or the voltage is more than 20 % outside the range the commissioning run saw, and the isolation names no fault; residual lamps may be lit, the FAULT lamp stays off for them (below) |
//! | 5 Hz blink (100 on / 100 off) | commissioning (learning healthy thresholds, then storing them) |
//! | all six lamps flash together at 2 Hz (250 ms on / 250 ms off) | SAMPLING STALLED: no samples arrive; the lamps show no monitoring result; the firmware restarts sampling, the watchdog resets the MCU if that fails |
//! | off, all five other lamps steady on | MONITOR FAILED (a panic or a watchdog reset; for 5 s after the reset, see the defmt log) |
//!
//! **Built-in default motor.** When no valid motor record was found in flash (or the
//! option bytes are single-bank and the flash is not used), the firmware monitors the
//! built-in default machine: then, in the three monitoring/commissioning patterns above,
//! the RUN lamp is lit **steadily for the first 2 s of every 10 s**, dark for 0.5 s, then
//! shows its pattern as above for 7.5 s. **Clock on the internal oscillator**: when the
//! board's 24 MHz crystal did not start and the clock fell back to the HSI (+-1 %), the RUN
//! lamp is lit steadily from 5 s to 7 s of every 10 s, then dark for 0.5 s (both marks
//! show together when both apply). **Brown-out level below the goal**: while the option
//! bytes' brown-out reset level is below level 4 (the factory's level 0, bring-up step
//! `cargo fw bor` not done), the flash records are refused and every commissioning ends
//! "not stored" (the FAULT lamp's flicker): the RUN lamp is dark from 2 s, lit steadily
//! from 2.5 s to 4.5 s of every 10 s, then dark for 0.5 s, so the panel says why. **Front end's
//! range too small** (the range state: clipping persists in steady running,
//! `crate::clip_watch`; the verdict could not judge, the FAULT lamp dark, no sensor named):
//! the RUN lamp is dark from 7 s, lit steadily from 7.5 s to 9.5 s of every 10 s, then dark
//! for 0.5 s. No other state lights the RUN lamp for more than 500 ms at a time.
//!
//! The RUN lamp is never off for more than 1.7 s while the monitor runs, so "RUN off and
//! everything else on" cannot be mistaken for a normal state; and only a stalled sample
//! path flashes the residual lamps (they are steady otherwise).
//!
//! **Operating point moved.** While commissioning learns, the board records the span of
//! the load (the active current, in phase with the voltage) and of the voltage magnitude,
//! both measured without the d-q frame's angle (`crate::range_watch`, the core's
//! `monitor_core::operating_range`: the same rule as the host's `diagnose` and HMI). When
//! afterwards either is more than 20 % of the span's largest magnitude outside it, the
//! learned healthy means no longer hold (to the paper's model a load change is a Bl
//! change): lit residual lamps are then no fault by themselves. Unless the isolation names
//! a fault (the friction class B/Bl does not count, a load change is one) or a sensor
//! fault is flagged, the FAULT lamp stays off and the RUN lamp triple-flashes instead of
//! its 1 Hz blink; the status line says `moved=true`. The span lives in RAM only: after
//! a reset without a new commissioning run the board does not judge "moved".
//!
//! # FAULT lamp and blink code
//!
//! | pattern | meaning |
//! |---|---|
//! | off | no FAULT: nothing detected, the "operating point moved" state (above), or a detection the one verdict does not call a FAULT (`app::panel_call`, the core's decision table `monitor_core::verdict`: a name below 0.5 probability, under 5 % or the friction class is watched; lamps with nothing named are watched; not commissioned, lamps with no name beyond the file's +-30 % are not judged); the residual lamps still show the core's lamps, the status line's `call=` says which |
//! | steady on | input invalid: a sensor fault flagged by the core (impossible readings), an offset out of bound or the reference out of band, no isolation; a clipped reading is none of these (held out and counted, `crate::clip_watch`) |
//! | N blinks (250 ms on / 250 ms off), then 1.5 s dark, repeating | fault detected, blink code N (table below) |
//! | 10 Hz flicker | the last commissioning failed (no progress, unusable statistics or not stored) and no fault is shown; the RUN lamp says which thresholds are in force; press the button to retry |
//!
//! The blink code names the fault the **isolation** found (`monitor_core::isolation`: the
//! full steady-state equations, which separate what the paper's four lamps cannot), in
//! the core's fault list's order plus one (`monitor_core::FAULTS`; the codes after the
//! faults, "not named" and the three phases of shorted turns, follow the list's length, so
//! a fault added to the list gets the next code and moves them up by one):
//!
//! | N | 1 | 2 | 3 | 4 | 5 | 6 | 7 | 8 | 9 | 10 | 11 | 12 | 13 |
//! |---|---|---|---|---|---|---|---|---|---|---|---|---|---|
//! | fault | Rs | Rr | Ls | Lr | (friction B/Bl: not used, watched) | (Bl: not used) | current sensor | voltage sensor | speed sensor | (not used: a FAULT always names its fault) | shorted turns, phase a | phase b | phase c |
//!
//! Codes 11-13 name the phase of shorted turns (the core's negative-sequence analysis,
//! `monitor_core::sequence`: the supply's own unbalance taken out with the measured
//! voltages, the phase from the angle of the rest against the power-factor angle), for a
//! winding part above a healthy machine's own asymmetry (3 % of I2/I1; the board keeps no
//! healthy baseline of it) at a confidence of 0.5 or more, while the lamps are judged (a
//! start or a step unbalances the currents for a while). The status line gives the phase and
//! the size (`wind=b wind_i2=0.041`).
//!
//! The FAULT lamp blinks for the one verdict's FAULT (`app::panel_call`, the core's decision
//! table): a named fault (the isolation's, or shorted turns) with its size, at a probability
//! of 0.5 or more, 5 % or more against the commissioned baseline or beyond the file's +-30 %
//! against the nominal values. B and Bl cannot be separated at any operating point (they
//! scale the same load term) and a load change moves them as much: the friction class is
//! watched, never a FAULT (the amber state, above). The lamps' own detection with nothing
//! named is watched too, so code 10 is no longer shown. The defmt status line gives the
//! isolation's name and size (`iso=rr(+0.48)`) and the paper's lamp-pattern candidates.
//! The isolation's baseline is learned by a commissioning run and stored in the flash
//! record beside the lamps' thresholds (record version 2; restored at boot); without one
//! (never commissioned, or a version 1 record) the sizes are against the nominal values.

use crate::board::Lamp;

mod blink;
pub use blink::{
    blink_code, blink_code_lamp, read_blink_code, winding_code, NOT_NAMED_CODE, WINDING_CODE_A,
};

/// State of the six lamps (`true` = lit), one field per lamp.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub struct PanelLamps {
    /// The RUN lamp.
    pub run: bool,
    /// The residual lamps r1..r4, in residual order ([`Lamp::RESIDUALS`]).
    pub residuals: [bool; 4],
    /// The FAULT lamp.
    pub fault: bool,
}

impl PanelLamps {
    /// The "monitor failed" pattern: RUN off, every other lamp on (also the panic
    /// handler's, which drives the pins of [`Lamp::ALL`] from it).
    pub const FAILED: Self = Self {
        run: false,
        residuals: [true; 4],
        fault: true,
    };

    /// The safe mode's pattern at `t_ms` (the boot gave up after failed boots in a row, or
    /// the PLL did not lock: `crate::startup::SafeModeReason::code`): r1 and r4 lit, RUN, r2
    /// and r3 dark, the FAULT lamp blinking `code` ([`blink_code_lamp`]): like no other
    /// pattern, so a board in the safe mode is told from a failed or stalled one.
    pub fn safe_mode(code: u8, t_ms: u32) -> Self {
        Self {
            run: false,
            residuals: [true, false, false, true],
            fault: blink_code_lamp(code, t_ms),
        }
    }

    /// Every lamp lit (`true`) or dark.
    pub const fn all(on: bool) -> Self {
        Self {
            run: on,
            residuals: [on; 4],
            fault: on,
        }
    }

    /// Whether `lamp` is lit.
    pub const fn is_on(&self, lamp: Lamp) -> bool {
        let [r1, r2, r3, r4] = self.residuals;
        match lamp {
            Lamp::Run => self.run,
            Lamp::R1 => r1,
            Lamp::R2 => r2,
            Lamp::R3 => r3,
            Lamp::R4 => r4,
            Lamp::Fault => self.fault,
        }
    }
}

/// What the monitor is doing, as far as the RUN lamp is concerned.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Mode {
    /// Monitoring with default thresholds: no valid commissioning record.
    NotCommissioned,
    /// A commissioning run is active (learning, or its result being stored).
    Commissioning,
    /// Monitoring with learned thresholds.
    Commissioned,
    /// No samples arrive: the monitor's results are stale and are not shown.
    SamplingStalled,
    /// The monitor failed (panic or watchdog reset).
    Failed,
}

impl Mode {
    /// A short name for logs.
    pub const fn name(self) -> &'static str {
        match self {
            Mode::NotCommissioned => "not-commissioned",
            Mode::Commissioning => "commissioning",
            Mode::Commissioned => "commissioned",
            Mode::SamplingStalled => "sampling-stalled",
            Mode::Failed => "failed",
        }
    }
}

/// Inputs of [`render`]: the panel's whole interface. The application builds it from the
/// monitor's status and the isolation (`app::panel_input`); this module depends on nothing
/// but the lamp table ([`Lamp`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct PanelInput {
    /// Panel mode.
    pub mode: Mode,
    /// Residual lamps r1..r4 as decided by the core.
    pub residual_lamps: [bool; 4],
    /// The core detected a fault.
    pub fault_detected: bool,
    /// Input invalid: a sensor fault flagged (the core's impossible readings, an offset out
    /// of bound, the reference out of band); a clip is not one.
    pub input_invalid: bool,
    /// Blink code of the fault shown: 1..=9 ([`blink_code`] of the isolated fault; 5 for
    /// the friction class), [`NOT_NAMED_CODE`] (10), or 11..=13 for shorted turns
    /// ([`winding_code`]); the numbers follow the core's fault list (module docs).
    pub fault_code: u8,
    /// The last commissioning attempt failed (shown while no fault is).
    pub commissioning_failed: bool,
    /// The built-in default motor is monitored (no valid motor record): the RUN lamp's
    /// steady 2 s of every 10 s (module docs).
    pub default_motor: bool,
    /// The crystal (HSE) did not start and the clock runs on the internal oscillator
    /// (HSI, +-1 %): the RUN lamp's steady 2 s from 5 s of every 10 s (module docs).
    pub clock_fallback: bool,
    /// The brown-out reset level in the option bytes is below the goal (level 4), so the
    /// flash records are refused and a commissioning ends "not stored": the RUN lamp's
    /// steady 2 s from 2.5 s of every 10 s (module docs).
    pub bor_below_goal: bool,
    /// Commissioned, and the operating point (load or voltage) has left the commissioned
    /// range with no fault named: the RUN lamp's triple flash, the "amber" state (module
    /// docs). The application clears `fault_detected` for the lamps' detection then.
    pub moved: bool,
    /// The range state: clipping persists in steady running, the front end's linear range
    /// is too small for this motor (`crate::clip_watch`): the RUN lamp's steady 2 s from
    /// 7.5 s of every 10 s (module docs). The application's verdict is "could not judge"
    /// then (no FAULT).
    pub clip_range: bool,
}

/// Half period of the "sampling stalled" flash, ms (2 Hz).
const STALLED_HALF_PERIOD_MS: u32 = 250;
/// Period of the "built-in default motor" mark and its steady part, ms.
const DEFAULT_MOTOR_PERIOD_MS: u32 = 10_000;
const DEFAULT_MOTOR_ON_MS: u32 = 2_000;
/// The dark gap after it, ms (so the mark is never longer than 2 s).
const DEFAULT_MOTOR_GAP_MS: u32 = 500;
/// Where the "clock on the internal oscillator" mark starts in the same 10 s period, ms:
/// the same 2 s steady and 0.5 s dark, apart from the default motor's.
const CLOCK_FALLBACK_AT_MS: u32 = 5_000;
/// Where the "brown-out level below the goal" mark starts in the same 10 s period, ms:
/// between the default motor's mark and the clock's, 2 s steady and 0.5 s dark.
const BOR_MARK_AT_MS: u32 = 2_500;
/// Where the "front end's range too small" mark starts in the same 10 s period, ms: after
/// the clock's, 2 s steady and 0.5 s dark, ending with the period.
const CLIP_RANGE_AT_MS: u32 = 7_500;

fn run_lamp(mode: Mode, t_ms: u32) -> bool {
    match mode {
        Mode::Commissioned => t_ms % 1000 < 500,
        Mode::Commissioning => t_ms % 200 < 100,
        Mode::NotCommissioned => {
            let p = t_ms % 2000;
            p < 100 || (200..300).contains(&p)
        }
        Mode::SamplingStalled => t_ms % (2 * STALLED_HALF_PERIOD_MS) < STALLED_HALF_PERIOD_MS,
        Mode::Failed => false,
    }
}

/// The RUN lamp's "operating point moved" pattern: three 100 ms flashes 100 ms apart,
/// then 1.5 s dark (period 2 s).
fn moved_run_lamp(t_ms: u32) -> bool {
    let p = t_ms % 2000;
    p < 500 && p % 200 < 100
}

/// Lamp states for `input` at time `t_ms` (any monotonic millisecond clock; wraps).
pub fn render(input: &PanelInput, t_ms: u32) -> PanelLamps {
    match input.mode {
        Mode::Failed => return PanelLamps::FAILED,
        Mode::SamplingStalled => return PanelLamps::all(run_lamp(Mode::SamplingStalled, t_ms)),
        _ => {}
    }
    let learning = input.mode == Mode::Commissioning;
    let mark_phase = t_ms % DEFAULT_MOTOR_PERIOD_MS;
    let clock_phase = mark_phase.wrapping_sub(CLOCK_FALLBACK_AT_MS);
    let bor_phase = mark_phase.wrapping_sub(BOR_MARK_AT_MS);
    let clip_phase = mark_phase.wrapping_sub(CLIP_RANGE_AT_MS);
    let (on, gap) = (
        DEFAULT_MOTOR_ON_MS,
        DEFAULT_MOTOR_ON_MS + DEFAULT_MOTOR_GAP_MS,
    );
    // The gap before the range mark: after the clock's mark (5 s + 2 s) up to 7.5 s.
    let before_clip = (CLOCK_FALLBACK_AT_MS + on..CLIP_RANGE_AT_MS).contains(&mark_phase);
    let run = match (
        input.default_motor,
        input.bor_below_goal,
        input.clock_fallback,
        input.clip_range,
    ) {
        (true, _, _, _) if mark_phase < on => true,
        (true, _, _, _) if mark_phase < gap => false,
        (_, true, _, _) if bor_phase < on => true,
        // Dark for 0.5 s on both sides, so no pattern's flash runs into it.
        (_, true, _, _) if bor_phase < gap || (on..BOR_MARK_AT_MS).contains(&mark_phase) => false,
        (_, _, true, _) if clock_phase < on => true,
        (_, _, true, _) if clock_phase < gap => false,
        (_, _, _, true) if clip_phase < on => true,
        // Dark for 0.5 s on both sides (its gap after it ends the period).
        (_, _, _, true) if clip_phase < gap || before_clip => false,
        _ if input.moved && input.mode == Mode::Commissioned => moved_run_lamp(t_ms),
        _ => run_lamp(input.mode, t_ms),
    };
    PanelLamps {
        run,
        residuals: if learning {
            [false; 4]
        } else {
            input.residual_lamps
        },
        fault: if learning {
            false
        } else if input.input_invalid {
            true
        } else if input.fault_detected {
            blink_code_lamp(input.fault_code, t_ms)
        } else {
            input.commissioning_failed && t_ms % 100 < 50
        },
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn input(mode: Mode) -> PanelInput {
        PanelInput {
            mode,
            residual_lamps: [true, false, true, false],
            fault_detected: true,
            input_invalid: false,
            fault_code: 4,
            commissioning_failed: false,
            default_motor: false,
            clock_fallback: false,
            bor_below_goal: false,
            moved: false,
            clip_range: false,
        }
    }

    /// The RUN lamp's rising edges in one 2 s period.
    fn run_flashes(inp: &PanelInput) -> usize {
        let trace: Vec<bool> = (0..200u32).map(|k| render(inp, k * 10).run).collect();
        trace.windows(2).filter(|w| !w[0] && w[1]).count() + usize::from(trace[0])
    }

    /// The longest time the RUN lamp is lit without a break in 20 s, ms.
    fn longest_run_on_ms(inp: &PanelInput) -> u32 {
        let (mut on, mut longest) = (0, 0);
        for k in 0..2_000u32 {
            on = if render(inp, k * 10).run { on + 10 } else { 0 };
            longest = longest.max(on);
        }
        longest
    }

    #[test]
    fn the_default_motor_lights_the_run_lamp_for_2_s_in_10_and_nothing_else_does() {
        for mode in NORMAL {
            let mut inp = input(mode);
            assert!(longest_run_on_ms(&inp) <= 500, "{mode:?}");
            inp.default_motor = true;
            assert_eq!(longest_run_on_ms(&inp), 2_000, "{mode:?}");
            // The steady part starts every 10 s; the mode's own pattern shows in between.
            assert!((0..200u32).all(|k| render(&inp, 20_000 + k * 10).run));
            let own = |t: u32| render(&input(mode), t).run;
            assert!((250..1000u32).all(|k| render(&inp, k * 10).run == own(k * 10)));
            // The residual and fault lamps are unchanged.
            let plain = render(&input(mode), 100);
            let marked = render(&inp, 100);
            assert_eq!(
                (plain.residuals, plain.fault),
                (marked.residuals, marked.fault)
            );
        }
        for mode in [Mode::Failed, Mode::SamplingStalled] {
            let mut inp = input(mode);
            inp.default_motor = true;
            assert!(longest_run_on_ms(&inp) <= 250, "{mode:?}");
        }
        let mut inp = input(Mode::Commissioned);
        inp.default_motor = true;
        let trace: Vec<bool> = (0..400u32)
            .map(|k| render(&inp, k * 50).is_on(Lamp::Fault))
            .collect();
        assert_eq!(read_blink_code(&trace, 50), Some(4));
    }

    /// The crystal's fallback mark: the RUN lamp steady from 5 s to 7 s of every 10 s, the
    /// mode's pattern elsewhere; apart from (and together with) the default motor's.
    #[test]
    fn the_clock_fallback_lights_the_run_lamp_for_2_s_from_5_s_in_10() {
        for mode in NORMAL {
            let mut inp = input(mode);
            inp.clock_fallback = true;
            assert_eq!(longest_run_on_ms(&inp), 2_000, "{mode:?}");
            assert!((0..200u32).all(|k| render(&inp, 15_000 + k * 10).run));
            assert!((0..50u32).all(|k| !render(&inp, 17_000 + k * 10).run));
            let own = |t: u32| render(&input(mode), t).run;
            assert!((0..500u32).all(|k| render(&inp, k * 10).run == own(k * 10)));
            inp.default_motor = true;
            assert!((0..200u32).all(|k| render(&inp, k * 10).run));
            assert!((0..200u32).all(|k| render(&inp, 5_000 + k * 10).run));
        }
    }

    /// The brown-out mark: the RUN lamp steady from 2.5 s to 4.5 s of every 10 s, the
    /// mode's pattern elsewhere; apart from (and together with) the other two marks.
    #[test]
    fn a_brown_out_level_below_the_goal_lights_the_run_lamp_for_2_s_from_2_5_s_in_10() {
        for mode in NORMAL {
            let mut inp = input(mode);
            inp.bor_below_goal = true;
            assert_eq!(longest_run_on_ms(&inp), 2_000, "{mode:?}");
            assert!((0..200u32).all(|k| render(&inp, 12_500 + k * 10).run));
            assert!((0..50u32).all(|k| !render(&inp, 14_500 + k * 10).run));
            let own = |t: u32| render(&input(mode), t).run;
            assert!((0..200u32).all(|k| render(&inp, k * 10).run == own(k * 10)));
            assert!((200..250u32).all(|k| !render(&inp, k * 10).run));
            assert!((500..1000u32).all(|k| render(&inp, k * 10).run == own(k * 10)));
            inp.default_motor = true;
            inp.clock_fallback = true;
            for from in [0, 2_500, 5_000] {
                assert!(
                    (0..200u32).all(|k| render(&inp, from + k * 10).run),
                    "{from}"
                );
            }
        }
        // The failed and stalled patterns stay as they are.
        for mode in [Mode::Failed, Mode::SamplingStalled] {
            let mut inp = input(mode);
            inp.bor_below_goal = true;
            assert!(longest_run_on_ms(&inp) <= 250, "{mode:?}");
        }
    }

    /// The range state's mark: the RUN lamp steady from 7.5 s to 9.5 s of every 10 s, dark
    /// 0.5 s either side, the mode's pattern elsewhere; apart from (and together with) the
    /// other three marks; the FAULT and residual lamps as they are.
    #[test]
    fn the_range_state_lights_the_run_lamp_for_2_s_from_7_5_s_in_10() {
        for mode in NORMAL {
            let mut inp = input(mode);
            inp.clip_range = true;
            assert_eq!(longest_run_on_ms(&inp), 2_000, "{mode:?}");
            assert!((0..200u32).all(|k| render(&inp, 17_500 + k * 10).run));
            assert!((0..50u32).all(|k| !render(&inp, 17_000 + k * 10).run));
            assert!((0..50u32).all(|k| !render(&inp, 19_500 + k * 10).run));
            let own = |t: u32| render(&input(mode), t).run;
            assert!((0..700u32).all(|k| render(&inp, k * 10).run == own(k * 10)));
            let (plain, marked) = (render(&input(mode), 8_000), render(&inp, 8_000));
            assert_eq!(
                (plain.residuals, plain.fault),
                (marked.residuals, marked.fault)
            );
            inp.default_motor = true;
            inp.bor_below_goal = true;
            inp.clock_fallback = true;
            for from in [0, 2_500, 5_000, 7_500] {
                assert!(
                    (0..200u32).all(|k| render(&inp, from + k * 10).run),
                    "{from}"
                );
            }
        }
        for mode in [Mode::Failed, Mode::SamplingStalled] {
            let mut inp = input(mode);
            inp.clip_range = true;
            assert!(longest_run_on_ms(&inp) <= 250, "{mode:?}");
        }
    }

    const NORMAL: [Mode; 3] = [
        Mode::NotCommissioned,
        Mode::Commissioning,
        Mode::Commissioned,
    ];

    #[test]
    fn the_codes_follow_the_fault_list_and_never_collide() {
        // Table 1's nine faults keep their codes: 1..=9, then 10 (not named), 11..=13.
        let codes: Vec<u8> = monitor_core::Fault::ALL
            .iter()
            .map(|f| blink_code(f.index() as u8))
            .collect();
        assert_eq!(codes, (1..=9).collect::<Vec<u8>>());
        assert_eq!(NOT_NAMED_CODE, 10);
        assert_eq!([0, 1, 2].map(winding_code), [11, 12, 13]);
        assert!(codes
            .iter()
            .all(|c| *c < NOT_NAMED_CODE && NOT_NAMED_CODE < WINDING_CODE_A));
    }

    #[test]
    fn blink_code_round_trips_for_every_candidate() {
        for code in 1..=winding_code(2) {
            let mut inp = input(Mode::Commissioned);
            inp.fault_code = code;
            let trace: Vec<bool> = (0..400u32)
                .map(|k| render(&inp, k * 50).is_on(Lamp::Fault))
                .collect();
            assert_eq!(read_blink_code(&trace, 50), Some(code), "code {code}");
        }
    }

    #[test]
    fn failed_and_stalled_patterns_are_distinct() {
        let f = render(&input(Mode::Failed), 123);
        assert_eq!(f, PanelLamps::FAILED);
        // In every normal mode the RUN lamp is lit within any 2 s window...
        for mode in NORMAL {
            let lit = (0..40u32).any(|k| render(&input(mode), 5000 + k * 50).is_on(Lamp::Run));
            assert!(lit, "{mode:?}");
        }
        // ...and the stalled pattern (all six together) appears in no other mode.
        let stalled: Vec<PanelLamps> = (0..40u32)
            .map(|k| render(&input(Mode::SamplingStalled), k * 50))
            .collect();
        assert!(stalled.contains(&PanelLamps::all(true)));
        assert!(stalled.contains(&PanelLamps::all(false)));
        assert!(stalled
            .iter()
            .all(|p| *p == PanelLamps::all(true) || *p == PanelLamps::all(false)));
        // The residual lamps flash only there: in any other mode they hold still for
        // still inputs.
        for mode in NORMAL.into_iter().chain([Mode::Failed]) {
            for failed in [false, true] {
                let mut inp = input(mode);
                inp.residual_lamps = [true; 4];
                inp.commissioning_failed = failed;
                let first = render(&inp, 0).residuals;
                let still = (0..400u32).all(|k| render(&inp, k * 5).residuals == first);
                assert!(still, "{mode:?} flashes its residual lamps");
            }
        }
    }

    #[test]
    fn residual_lamps_follow_core_except_while_learning() {
        let p = render(&input(Mode::Commissioned), 0);
        assert!(p.is_on(Lamp::R1) && !p.is_on(Lamp::R2) && p.is_on(Lamp::R3));
        let p = render(&input(Mode::Commissioning), 0);
        assert!(!p.is_on(Lamp::R1) && !p.is_on(Lamp::Fault));
    }

    #[test]
    fn a_failed_commissioning_flickers_unless_a_fault_is_shown() {
        let mut inp = input(Mode::Commissioned);
        inp.commissioning_failed = true;
        inp.fault_detected = false;
        let trace: Vec<bool> = (0..20u32)
            .map(|k| render(&inp, k * 25).is_on(Lamp::Fault))
            .collect();
        assert!(trace.contains(&true) && trace.contains(&false));
        // The RUN lamp still says which thresholds are in force.
        assert!(render(&inp, 0).run && !render(&inp, 600).run);
        inp.fault_detected = true;
        let trace: Vec<bool> = (0..400u32)
            .map(|k| render(&inp, k * 50).is_on(Lamp::Fault))
            .collect();
        assert_eq!(read_blink_code(&trace, 50), Some(4));
    }

    #[test]
    fn the_moved_state_triple_flashes_the_run_lamp_with_the_fault_lamp_off() {
        let mut inp = input(Mode::Commissioned);
        inp.fault_detected = false;
        inp.residual_lamps = [false, true, true, true];
        assert_eq!(run_flashes(&inp), 2, "commissioned: 1 Hz blink");
        inp.moved = true;
        assert_eq!(run_flashes(&inp), 3, "moved: triple flash");
        let not = input(Mode::NotCommissioned);
        assert_eq!(run_flashes(&not), 2, "not commissioned: double flash");
        for k in 0..400u32 {
            let p = render(&inp, k * 5);
            assert!(!p.is_on(Lamp::Fault) && p.residuals == [false, true, true, true]);
        }
        // Only a commissioned monitor shows it: while learning the RUN lamp says so.
        inp.mode = Mode::Commissioning;
        assert_eq!(run_flashes(&inp), 10);
        // The RUN lamp is never lit for more than 500 ms nor dark for more than 1.7 s.
        inp.mode = Mode::Commissioned;
        assert!(longest_run_on_ms(&inp) <= 500);
    }
}
