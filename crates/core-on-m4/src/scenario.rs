//! Shared between the QEMU program and its host-side generator (the root test
//! `tests/firmware/qemu_replay_data.rs`, which simulates the log with sim-host): the monitor configuration of the replay and the binary formats of the
//! embedded log (`data/replay.bin`) and of the host's expected outputs
//! (`data/expected.bin`). `no_std`, depends only on `monitor_core`.
//!
//! replay.bin: `b"RPL1"`, `u32` sample count, then per sample 7 x `u16` LE: ADC codes of
//! va, vb, vc, ia, ib, ic (12 bit, the board's +-400 V / +-10 A front end) and the 16-bit
//! encoder counter. Timestamps are implicit: sample k is at `k * TICKS_PER_SAMPLE`.
//!
//! expected.bin: `b"EXP1"`, `u32` checkpoint count, `u32` spacing in samples, then per
//! checkpoint (after sample `(j+1)*spacing - 1`): residuals r1..r4, speed_rad_s,
//! frame_omega_rad_s (`f32` LE each), lamps bitmask (`u8`, bit k = r(k+1)), fault_detected
//! (`u8`), 2 bytes zero: 28 bytes.

use monitor_core::{Abc, MonitorConfig, MonitorOutput, MotorModel, Sample};

/// Sample rate of the replay, Hz.
pub const SAMPLE_RATE_HZ: f32 = 10_000.0;
/// Timestamp ticks per sample (1 MHz ticks).
pub const TICKS_PER_SAMPLE: u32 = 100;
/// Bytes per sample record.
pub const SAMPLE_BYTES: usize = 14;
/// Bytes per checkpoint record.
pub const CHECK_BYTES: usize = 28;
/// Header bytes of replay.bin.
pub const REPLAY_HEADER: usize = 8;
/// Header bytes of expected.bin.
pub const EXPECTED_HEADER: usize = 12;
/// Volts per ADC code (+-400 V over 4095 codes), as in the firmware's board file.
pub const VOLT_PER_LSB: f32 = 800.0 / 4095.0;
/// Amperes per ADC code (+-10 A over 4095 codes).
pub const AMP_PER_LSB: f32 = 20.0 / 4095.0;
/// Zero code.
pub const MID: f32 = 4095.0 / 2.0;

/// The 2.2 kW reference machine (Bl for 14.6 N m near rated speed), in the
/// core's precision.
pub fn motor() -> MotorModel {
    monitor_core::reference::MOTOR_2P2KW.motor.model()
}

/// Monitor configuration of the replay: the firmware's settings (16-bit encoder
/// counter, 4096 counts/rev, 1 MHz ticks) with a short settling time so the slow path
/// and the lamp logic run within the replay.
pub fn config() -> MonitorConfig {
    let mut c = MonitorConfig::new(motor(), 50.0, 400.0, SAMPLE_RATE_HZ);
    c.tick_hz = 1_000_000.0;
    c.encoder.counter_bits = 16;
    c.encoder.counts_per_rev = 4096;
    c.limits.v_max = 400.0;
    c.limits.i_max = 10.0;
    c.settle_s = 0.05;
    // A 1.2 s replay: a short quasi-steady gate so the lamps get to act within it.
    c.gate_hold_s = 0.1;
    c.gate_timeout_s = 0.4;
    c
}

pub fn u16_at(b: &[u8], at: usize) -> u16 {
    match b.get(at..at + 2) {
        Some(&[x, y]) => u16::from_le_bytes([x, y]),
        _ => 0,
    }
}

/// Little-endian `u32` at `at` (0 when out of range).
pub fn u32_at(b: &[u8], at: usize) -> u32 {
    match b.get(at..at + 4) {
        Some(&[a, b2, c, d]) => u32::from_le_bytes([a, b2, c, d]),
        _ => 0,
    }
}

/// Little-endian `f32` at `at` (NaN when out of range).
pub fn f32_at(b: &[u8], at: usize) -> f32 {
    match b.get(at..at + 4) {
        Some(&[a, b2, c, d]) => f32::from_le_bytes([a, b2, c, d]),
        _ => f32::NAN,
    }
}

/// Sample `k` of a replay.bin image.
#[inline]
pub fn sample(replay: &[u8], k: usize) -> Sample {
    let at = REPLAY_HEADER + k * SAMPLE_BYTES;
    let c = |n: usize| u16_at(replay, at + 2 * n);
    let v = |n: usize| (f32::from(c(n)) - MID) * VOLT_PER_LSB;
    let i = |n: usize| (f32::from(c(n)) - MID) * AMP_PER_LSB;
    let sat = |n: usize| c(n) == 0 || c(n) >= 4095;
    Sample {
        v_abc: Abc {
            a: v(0),
            b: v(1),
            c: v(2),
        },
        i_abc: Abc {
            a: i(3),
            b: i(4),
            c: i(5),
        },
        encoder_count: u32::from(c(6)),
        timestamp_ticks: (k as u32).wrapping_mul(TICKS_PER_SAMPLE),
        v_saturated: sat(0) || sat(1) || sat(2),
        i_saturated: sat(3) || sat(4) || sat(5),
        clipped: false,
    }
}

/// One checkpoint's values.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Check {
    /// r1..r4, speed, frame omega.
    pub values: [f32; 6],
    /// Lamp bitmask.
    pub lamps: u8,
    /// Fault detected.
    pub fault: bool,
}

impl Check {
    /// From a monitor output.
    pub fn of(o: &MonitorOutput) -> Self {
        let r = o.residuals;
        let mut lamps = 0u8;
        for (k, l) in o.lamps.iter().enumerate() {
            if *l {
                lamps |= 1 << k;
            }
        }
        Check {
            values: [r[0], r[1], r[2], r[3], o.speed_rad_s, o.frame_omega_rad_s],
            lamps,
            fault: o.fault_detected,
        }
    }

    /// Checkpoint `j` of an expected.bin image.
    pub fn read(expected: &[u8], j: usize) -> Self {
        let at = EXPECTED_HEADER + j * CHECK_BYTES;
        let mut values = [0.0f32; 6];
        for (n, v) in values.iter_mut().enumerate() {
            *v = f32_at(expected, at + 4 * n);
        }
        Check {
            values,
            lamps: expected.get(at + 24).copied().unwrap_or(0xFF),
            fault: expected.get(at + 25).copied().unwrap_or(0) != 0,
        }
    }

    /// Serialized form (28 bytes).
    #[allow(dead_code)] // used by the host generator only
    pub fn bytes(&self) -> [u8; CHECK_BYTES] {
        let mut out = [0u8; CHECK_BYTES];
        for (n, v) in self.values.iter().enumerate() {
            if let Some(dst) = out.get_mut(4 * n..4 * n + 4) {
                dst.copy_from_slice(&v.to_le_bytes());
            }
        }
        if let Some(x) = out.get_mut(24) {
            *x = self.lamps;
        }
        if let Some(x) = out.get_mut(25) {
            *x = u8::from(self.fault);
        }
        out
    }
}
