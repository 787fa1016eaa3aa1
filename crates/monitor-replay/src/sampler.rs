//! Log rows as core samples ([`LogSampler`]): the host's counterpart of the firmware's ADC
//! sampler.

use monitor_core::{Abc, Sample};
use monitor_io::log::Row;

/// Timestamp tick rate used for replays [Hz].
pub const TICK_HZ: f64 = 1.0e6;
/// Counts per revolution of the synthesised encoder (1024 lines x 4).
pub const COUNTS_PER_REV: u32 = 4096;
/// Time the replay puts between the segments around a clock reset [s]: a long gap, after
/// which the monitor restarts its estimators and settles (the encoder count goes on by the
/// turn over it).
pub const CLOCK_RESET_GAP_S: f64 = 2.0 * monitor_io::log::quality::MAX_BRIDGED_GAP_S;

/// The core sample of `row` from `sampler`, its encoder count moved on by `enc_offset`
/// (counts handed on over a clock reset: [`super::Replay`]'s `enc_offset`).
#[inline]
pub(super) fn sample_of(sampler: &mut LogSampler, enc_offset: i64, row: &Row) -> Sample {
    if enc_offset == 0 {
        sampler.sample(row)
    } else {
        sampler.sample(&Row {
            enc_count: row.enc_count.map(|c| c.wrapping_add(enc_offset)),
            ..*row
        })
    }
}

/// Converts log rows to core samples, synthesising encoder counts from speed if needed
/// (the host's counterpart of the firmware's `drive_monitor::sampling::AdcSampler`).
///
/// The count handed to the core is one continuous count: each row advances it by the
/// encoder's own step where this row and the one before carry `enc_count`, else by the
/// speed channel's `floor(theta_m C / 2 pi)` step (`theta_m` the integral of `wm_rad_s`,
/// `C` = [`COUNTS_PER_REV`]), else not at all. A log that switches between the two (the
/// data-quality stage drops a bad count where the speed channel is good) gives no jump.
#[derive(Debug, Clone, Default)]
pub struct LogSampler {
    theta_m: f64,
    /// A row was sampled: `last_t` and `count` hold its time and count.
    started: bool,
    /// The last row's time [s].
    last_t: f64,
    /// The last row's encoder count, if it had one.
    last_enc: Option<i64>,
    /// The count handed on at the last row.
    count: i64,
    /// The speed channel's synthesised count at the last row.
    synth: i64,
}

impl LogSampler {
    /// The core sample for `row` (voltages 0 when the log has none).
    pub fn sample(&mut self, row: &Row) -> Sample {
        let started = self.started;
        let synth = match row.wm_rad_s {
            Some(w) => {
                if started {
                    self.theta_m += w * (row.t_s - self.last_t);
                }
                counts_of(self.theta_m)
            }
            // The angle did not move: its count is the last row's (0 before any row, the
            // count of the angle 0).
            None => self.synth,
        };
        let count = match (started, row.enc_count, self.last_enc) {
            (false, Some(c), _) => c,
            (false, None, _) => synth,
            (true, Some(c), Some(l)) => self.count.wrapping_add(c.wrapping_sub(l)),
            (true, _, _) if row.wm_rad_s.is_some() => {
                self.count.wrapping_add(synth.wrapping_sub(self.synth))
            }
            (true, _, _) => self.count,
        };
        self.started = true;
        self.count = count;
        self.synth = synth;
        self.last_enc = row.enc_count;
        self.last_t = row.t_s;
        let v = row.v_abc.unwrap_or([0.0; 3]);
        let i = row.i_abc;
        Sample {
            v_abc: Abc {
                a: v[0] as f32,
                b: v[1] as f32,
                c: v[2] as f32,
            },
            i_abc: Abc {
                a: i[0] as f32,
                b: i[1] as f32,
                c: i[2] as f32,
            },
            encoder_count: count as u32,
            timestamp_ticks: round_i64(row.t_s * TICK_HZ) as u32,
            v_saturated: false,
            i_saturated: false,
            clipped: false,
        }
    }
}

/// Counts per radian of the synthesised encoder, `C / 2 pi` ([`COUNTS_PER_REV`]).
const COUNTS_PER_RAD: f64 = COUNTS_PER_REV as f64 / std::f64::consts::TAU;

/// The synthesised count at the mechanical angle `theta_m` [rad]:
/// `floor(theta_m / 2 pi * C)`, to the bit, by a multiplication with [`COUNTS_PER_RAD`]
/// (a division's latency on every row is what it saves). The product and the quotient
/// differ by a few units in the last place (two roundings against one), so their floors
/// differ only where they lie within that of a whole count: where the product is within
/// `1e-12` of its magnitude of a whole number (about 2e-5 of the rows at 1e7 counts), the
/// quotient decides.
#[inline]
fn counts_of(theta_m: f64) -> i64 {
    let x = theta_m * COUNTS_PER_RAD;
    let n = floor_i64(x);
    let frac = x - n as f64;
    let tol = 1e-12 * x.abs();
    if frac > tol && frac < 1.0 - tol {
        n
    } else {
        floor_i64(theta_m / std::f64::consts::TAU * f64::from(COUNTS_PER_REV))
    }
}

/// `x.floor() as i64` (saturating; 0 for NaN) without a call into libm: the baseline
/// x86-64 target has no rounding instruction, and the replay converts every row.
fn floor_i64(x: f64) -> i64 {
    let t = x as i64;
    // `t as f64` is exact wherever x has a fraction (|x| < 2^52).
    if (t as f64) > x {
        t.saturating_sub(1)
    } else {
        t
    }
}

/// `x.round() as i64` (half away from zero, saturating; 0 for NaN), as [`floor_i64`].
fn round_i64(x: f64) -> i64 {
    let t = x as i64;
    // Exact wherever x has a fraction (|x| < 2^52).
    let frac = x - t as f64;
    if frac >= 0.5 {
        t.saturating_add(1)
    } else if frac <= -0.5 {
        t.saturating_sub(1)
    } else {
        t
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The multiplication gives the division's count, also next to whole counts.
    #[test]
    fn counts_as_the_division() {
        let division = |th: f64| (th / std::f64::consts::TAU * f64::from(COUNTS_PER_REV)).floor();
        let mut x: u64 = 0x2545_F491_4F6C_DD1D;
        let mut near_whole = 0;
        for k in 0..400_000u64 {
            x ^= x << 13;
            x ^= x >> 7;
            x ^= x << 17;
            let u = (x >> 11) as f64 / (1u64 << 53) as f64;
            let th = match k % 4 {
                // Angles of a long run, either way.
                0 => (u - 0.5) * 2e5,
                1 => u * 50.0,
                // Next to a whole count: the count's angle, a few ulps either side.
                _ => {
                    let m = ((u - 0.5) * 2e9).round();
                    let at = m / COUNTS_PER_RAD;
                    let ulps = (k % 9) as f64 - 4.0;
                    near_whole += 1;
                    at + ulps * at.abs().max(1e-300) * f64::EPSILON
                }
            };
            assert_eq!(counts_of(th), division(th) as i64, "{th:e}");
        }
        assert!(near_whole > 100_000);
        for th in [
            0.0,
            -0.0,
            1e-300,
            -1e-300,
            f64::NAN,
            f64::INFINITY,
            f64::NEG_INFINITY,
        ] {
            assert_eq!(counts_of(th), division(th) as i64, "{th:e}");
        }
    }

    #[test]
    fn floor_and_round_as_std() {
        let mut x: u64 = 0x9E37_79B9_7F4A_7C15;
        let mut values = vec![
            0.0,
            -0.0,
            0.5,
            -0.5,
            1.5,
            -1.5,
            2.5,
            0.499_999_999_999_999_94,
            -0.499_999_999_999_999_94,
            4_503_599_627_370_495.5,
            -4_503_599_627_370_495.5,
            9.223_372_036_854_775e18,
            -9.223_372_036_854_775e18,
            1e300,
            -1e300,
            f64::NAN,
            f64::INFINITY,
            f64::NEG_INFINITY,
        ];
        for k in 0..100_000 {
            x ^= x << 13;
            x ^= x >> 7;
            x ^= x << 17;
            let v = f64::from_bits(x);
            values.push(v);
            values.push(((x >> 11) as f64 / (1u64 << 53) as f64 - 0.5) * 10f64.powi(k % 20));
            values.push((k as f64 - 50_000.0) * 0.25);
        }
        for v in values {
            assert_eq!(floor_i64(v), v.floor() as i64, "{v:e}");
            assert_eq!(round_i64(v), v.round() as i64, "{v:e}");
        }
    }
}
