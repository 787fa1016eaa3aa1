//! LED panel: which lamp shows what, and the blink codes.
//!
//! A pure function of the monitor's state and the time ([`render`]), so the exact
//! patterns are tested on the host. The firmware calls it every 50 ms and copies the
//! result to the pins (see `board.rs` for the pin of each [`Lamp`]).
//!
//! # Panel
//!
//! | lamp | pin | meaning |
//! |---|---|---|
//! | RUN | PA5 (LD2) | monitor alive, see patterns below |
//! | R1..R4 | PB8, PB9, PB10, PB12 | residual r_k beyond its threshold (steady on) |
//! | FAULT | PB13 | fault detected; blinks the top candidate (blink code) |
//!
//! # RUN lamp patterns (period 2 s)
//!
//! | pattern | meaning |
//! |---|---|
//! | 1 Hz blink (500 ms on / 500 ms off) | monitoring, commissioned |
//! | double flash (100 on, 100 off, 100 on, 1700 off) | monitoring, NOT commissioned (no valid record: default thresholds) |
//! | 5 Hz blink (100 on / 100 off) | commissioning (learning healthy thresholds) |
//! | off, all five other lamps steady on | MONITOR FAILED (panic or watchdog reset; see the defmt log) |
//!
//! The RUN lamp is never off for more than 1.7 s while the monitor runs, so "RUN off and
//! everything else on" cannot be mistaken for a normal state.
//!
//! # FAULT lamp and blink code
//!
//! | pattern | meaning |
//! |---|---|
//! | off | no fault detected |
//! | N blinks (250 ms on / 250 ms off), then 1.5 s dark, repeating | fault detected, top candidate N (table below) |
//! | steady on | input invalid: ADC saturated or a sensor fault flagged by the core, no isolation |
//! | 10 Hz flicker | commissioning failed (record could not be written / learning failed); press the button to retry |
//!
//! Blink code N = position in the core's `Fault::ALL` plus one:
//!
//! | N | 1 | 2 | 3 | 4 | 5 | 6 | 7 | 8 | 9 |
//! |---|---|---|---|---|---|---|---|---|---|
//! | candidate | Rs | Rr | Ls | Lr | B | Bl | current sensor | voltage sensor | speed sensor |
//!
//! Candidates with equal signatures (Rs/Rr, B/Bl, Ls/voltage sensor) cannot be told
//! apart by the method; the lamp shows the first of the tied pair and the defmt log
//! lists the probabilities of all candidates.

/// One lamp of the panel; the discriminant is its index in [`PanelLamps::on`].
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Lamp {
    /// Run / healthy (PA5).
    Run = 0,
    /// Residual r1 beyond threshold (PB8).
    R1 = 1,
    /// Residual r2 beyond threshold (PB9).
    R2 = 2,
    /// Residual r3 beyond threshold (PB10).
    R3 = 3,
    /// Residual r4 beyond threshold (PB12).
    R4 = 4,
    /// Fault / blink code (PB13).
    Fault = 5,
}

impl Lamp {
    /// All lamps in index order.
    pub const ALL: [Lamp; 6] = [
        Lamp::Run,
        Lamp::R1,
        Lamp::R2,
        Lamp::R3,
        Lamp::R4,
        Lamp::Fault,
    ];
}

/// State of the six lamps, indexed by [`Lamp`] (`true` = lit).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub struct PanelLamps {
    /// Lit state per lamp, `on[Lamp::X as usize]`.
    pub on: [bool; 6],
}

impl PanelLamps {
    /// Whether `lamp` is lit.
    pub fn is_on(&self, lamp: Lamp) -> bool {
        self.on.get(lamp as usize).copied().unwrap_or(false)
    }

    /// The "monitor failed" pattern: RUN off, every other lamp on.
    pub const FAILED: Self = Self {
        on: [false, true, true, true, true, true],
    };
}

/// What the monitor is doing, as far as the panel is concerned.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Mode {
    /// Monitoring with default thresholds: no valid commissioning record.
    NotCommissioned,
    /// Learning the healthy thresholds.
    Commissioning,
    /// Monitoring with learned thresholds.
    Commissioned,
    /// The last commissioning attempt failed (monitoring continues).
    CommissioningFailed,
    /// The monitor failed (panic or watchdog reset).
    Failed,
}

/// Inputs of [`render`], taken from the latest monitor output.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct PanelInput {
    /// Panel mode.
    pub mode: Mode,
    /// Residual lamps r1..r4 as decided by the core.
    pub residual_lamps: [bool; 4],
    /// The core detected a fault.
    pub fault_detected: bool,
    /// Input invalid (ADC saturated / sensor fault flag).
    pub input_invalid: bool,
    /// Index of the top fault candidate in `Fault::ALL` (0..=8), if any.
    pub top_candidate: Option<u8>,
}

impl PanelInput {
    /// The panel's inputs for the latest core output in `mode`: the residual lamps, the
    /// fault lamp, "input invalid" when a sensor fault is flagged with no residual lamp
    /// lit, and the top candidate's blink code.
    pub fn from_output(mode: Mode, out: &monitor_core::MonitorOutput) -> Self {
        PanelInput {
            mode,
            residual_lamps: out.lamps,
            fault_detected: out.fault_detected,
            input_invalid: out.sensor_fault.any() && !out.lamps.iter().any(|l| *l),
            top_candidate: out.top().map(|(f, _)| f.index() as u8),
        }
    }
}

/// Blink code of a candidate index: `index + 1` (1..=9).
pub const fn blink_code(candidate_index: u8) -> u8 {
    candidate_index.saturating_add(1)
}

const BLINK_ON_MS: u32 = 250;
const BLINK_SLOT_MS: u32 = 500;
const BLINK_GAP_MS: u32 = 1500;

/// Fault lamp state at `t_ms` for blink code `n` (>= 1): `n` pulses of 250 ms in 500 ms
/// slots, then 1.5 s dark; period `n * 500 + 1500` ms.
pub fn blink_code_lamp(n: u8, t_ms: u32) -> bool {
    if n == 0 {
        return false;
    }
    let period = u32::from(n) * BLINK_SLOT_MS + BLINK_GAP_MS;
    let phase = t_ms % period;
    phase < u32::from(n) * BLINK_SLOT_MS && phase % BLINK_SLOT_MS < BLINK_ON_MS
}

fn run_lamp(mode: Mode, t_ms: u32) -> bool {
    match mode {
        Mode::Commissioned => t_ms % 1000 < 500,
        Mode::Commissioning => t_ms % 200 < 100,
        Mode::NotCommissioned | Mode::CommissioningFailed => {
            let p = t_ms % 2000;
            p < 100 || (200..300).contains(&p)
        }
        Mode::Failed => false,
    }
}

/// Lamp states for `input` at time `t_ms` (any monotonic millisecond clock; wraps).
pub fn render(input: &PanelInput, t_ms: u32) -> PanelLamps {
    if input.mode == Mode::Failed {
        return PanelLamps::FAILED;
    }
    let mut out = PanelLamps::default();
    out.on[Lamp::Run as usize] = run_lamp(input.mode, t_ms);
    if input.mode != Mode::Commissioning {
        out.on[1..5].copy_from_slice(&input.residual_lamps);
    }
    out.on[Lamp::Fault as usize] = if input.mode == Mode::CommissioningFailed {
        t_ms % 100 < 50
    } else if input.mode == Mode::Commissioning {
        false
    } else if input.input_invalid {
        true
    } else if input.fault_detected {
        match input.top_candidate {
            Some(i) => blink_code_lamp(blink_code(i), t_ms),
            None => true,
        }
    } else {
        false
    };
    out
}

/// Decode a blink code from a recorded fault-lamp trace sampled every `step_ms`
/// (counts the pulses of the first complete group). For tests and for users who log
/// the pin; returns `None` if no complete group is seen.
pub fn read_blink_code(trace: &[bool], step_ms: u32) -> Option<u8> {
    let gap_steps = (BLINK_GAP_MS / step_ms.max(1)) as usize;
    // find the end of a dark gap, then count rising edges until the next gap
    let mut dark = 0usize;
    let mut start = None;
    for (k, &on) in trace.iter().enumerate() {
        if on {
            if dark >= gap_steps.saturating_sub(1) {
                start = Some(k);
                break;
            }
            dark = 0;
        } else {
            dark += 1;
        }
    }
    let start = start?;
    let mut pulses = 0u8;
    let mut prev = false;
    let mut dark = 0usize;
    for &on in trace.get(start..)? {
        if on && !prev {
            pulses = pulses.saturating_add(1);
        }
        dark = if on { 0 } else { dark + 1 };
        if dark >= gap_steps.saturating_sub(1) {
            return Some(pulses);
        }
        prev = on;
    }
    None
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
            top_candidate: Some(3),
        }
    }

    #[test]
    fn blink_code_round_trips_for_every_candidate() {
        for i in 0..9u8 {
            let mut inp = input(Mode::Commissioned);
            inp.top_candidate = Some(i);
            let trace: Vec<bool> = (0..400u32)
                .map(|k| render(&inp, k * 50).is_on(Lamp::Fault))
                .collect();
            assert_eq!(read_blink_code(&trace, 50), Some(i + 1), "candidate {i}");
        }
    }

    #[test]
    fn failed_pattern_is_distinct() {
        let f = render(&input(Mode::Failed), 123);
        assert_eq!(f, PanelLamps::FAILED);
        // In every other mode the RUN lamp is lit within any 2 s window.
        for mode in [
            Mode::NotCommissioned,
            Mode::Commissioning,
            Mode::Commissioned,
            Mode::CommissioningFailed,
        ] {
            let lit = (0..40u32).any(|k| render(&input(mode), 5000 + k * 50).is_on(Lamp::Run));
            assert!(lit, "{mode:?}");
        }
    }

    #[test]
    fn residual_lamps_follow_core_except_while_learning() {
        let p = render(&input(Mode::Commissioned), 0);
        assert!(p.is_on(Lamp::R1) && !p.is_on(Lamp::R2) && p.is_on(Lamp::R3));
        let p = render(&input(Mode::Commissioning), 0);
        assert!(!p.is_on(Lamp::R1) && !p.is_on(Lamp::Fault));
    }
}
