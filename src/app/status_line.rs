//! The board's status line built from thread mode's view: the values the core's one format
//! (`monitor_core::status_line`) writes every panel period.

use super::*;
use monitor_core::status_line::StatusLine;

/// The status line of status `s`, its isolation `iso` (the fault named, its size and
/// probability: [`isolation_summary`]) and the winding temperature rise the isolation
/// tracks since commissioning (`rise_k` [K]); `panel`: the panel's mode and the one
/// verdict on the lamps ([`Mode::name`], [`Verdict::name`] of [`panel_call`]);
/// `max_update_cycles`: the longest `Monitor::update` [CPU cycles]; `board`: the counters
/// the firmware keeps outside the sample path's status (overruns, restarts, the stack's
/// high-water mark); `supply`: the latest VDDA [V] (0 before the first reading or when
/// unreadable) and the brown-out level (255: reserved).
pub fn status_line(
    s: &MonitorStatus,
    iso: Option<&Isolation>,
    rise_k: f32,
    panel: (&'static str, &'static str),
    max_update_cycles: u32,
    board: BoardCounters,
    supply: (f32, u8),
) -> StatusLine<'static> {
    let (mode, call) = panel;
    let name = |c: Option<(Fault, f32)>| c.map_or(("none", 0.0), |(f, p)| (f.name(), p));
    let sens = s.sensor_fault;
    StatusLine {
        residuals: s.residuals,
        lamps: s.residual_lamps,
        fault: s.fault_detected,
        call,
        top: name(s.top),
        second: name(s.second),
        speed_rad_s: s.speed_rad_s,
        zero_crossing_locked: s.zero_crossing_locked,
        mode,
        run: (s.run.id, s.run.blocks_learned, s.run.blocks_needed),
        overruns: board.overruns,
        restarts: board.restarts,
        samples: s.samples,
        max_update_cycles,
        iqs_a: s.operating.iqs,
        ids_a: s.operating.i_f,
        vqs_v: s.operating.vqs,
        frame_hz: s.frame_hz,
        quasi_steady: s.quasi_steady,
        evaluating: s.evaluating,
        sensors: (sens.current, sens.voltage, sens.speed),
        mid: s.bands.map(|b| b.0),
        half: s.bands.map(|b| b.1),
        isolation: isolation_summary(iso),
        winding: s.winding.map_or(("none", 0.0), |(p, r)| (p.name(), r)),
        moved: s.moved,
        winding_rise_k: rise_k,
        vdda_v: supply.0,
        bor: supply.1,
        clipped: s.clipped,
        encoder_rejects: s.encoder_rejects,
        stack_used_bytes: board.stack_used_bytes,
        clip_range: s.clip_range,
    }
}

/// The counters the status line takes from the firmware besides the sample path's status.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct BoardCounters {
    /// `overruns=`: the ADC DMA rings lapped since boot.
    pub overruns: u32,
    /// `restarts=`: the acquisition's recoveries since boot.
    pub restarts: u32,
    /// `stack=`: the stack's high-water mark since boot [bytes] (`crate::stack`).
    pub stack_used_bytes: u32,
}
