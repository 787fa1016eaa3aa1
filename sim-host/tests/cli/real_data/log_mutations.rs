//! What a data-acquisition system or a careless export does to a log
//! (`tests/cli/real_data.rs`): each mutation named, with what the data-quality stage must
//! report about it.

use super::f;
use monitor_io::log::Row;
use serde_json::Value;

/// Mutations of a clean log, each named, with what the data-quality stage must report.
pub type Mutation = (&'static str, fn(&[Row]) -> Vec<Row>, fn(&Value) -> bool);

pub fn mutations() -> Vec<Mutation> {
    vec![
        // One row missing among the first 64 (the old rate estimate looked at those).
        (
            "drop_one_early",
            |r| [&r[..30], &r[31..]].concat(),
            |q| q["dropped_samples"] == 1,
        ),
        // 0.1 % of single samples dropped, spread over the log.
        (
            "drop_0.1_percent",
            |r| {
                r.iter()
                    .enumerate()
                    .filter(|(k, _)| k % 997 != 500)
                    .map(|(_, x)| *x)
                    .collect()
            },
            |q| f(&q["dropped_samples"]) > 80.0 && q["trusted"] == true,
        ),
        // 10 ms missing every second.
        (
            "miss_10ms_each_second",
            |r| {
                r.iter()
                    .filter(|x| x.t_s < 1.0 || !(0.5..0.51).contains(&(x.t_s % 1.0)))
                    .copied()
                    .collect()
            },
            |q| f(&q["gaps_bridged"]) >= 7.0 && f(&q["longest_bridged_gap_s"]) > 0.009,
        ),
        // Time in milliseconds.
        (
            "time_in_ms",
            |r| {
                r.iter()
                    .map(|x| Row {
                        t_s: x.t_s * 1e3,
                        ..*x
                    })
                    .collect()
            },
            |q| q["time_unit"] == "ms" && (f(&q["sample_rate_hz"]) - 1e4).abs() < 1.0,
        ),
        // Every 1000th row written twice.
        (
            "repeated_rows",
            |r| {
                r.iter()
                    .enumerate()
                    .flat_map(|(k, x)| {
                        if k % 1000 == 0 {
                            vec![*x, *x]
                        } else {
                            vec![*x]
                        }
                    })
                    .collect()
            },
            |q| f(&q["repeated_or_backward_rows"]) >= 8.0,
        ),
        // One timestamp in 5000 off by 0.37 s (a clock glitch), the row itself fine.
        (
            "timestamp_glitches",
            |r| {
                r.iter()
                    .enumerate()
                    .map(|(k, x)| Row {
                        t_s: x.t_s + if k % 5000 == 1000 { 0.37 } else { 0.0 },
                        ..*x
                    })
                    .collect()
            },
            |q| f(&q["timestamp_glitches"]) >= 17.0,
        ),
        // Software timestamps: +/- 20 % of a period of jitter.
        (
            "jittered_timestamps",
            |r| {
                r.iter()
                    .enumerate()
                    .map(|(k, x)| Row {
                        t_s: x.t_s + 2e-5 * ((k as f64 * 0.618_034).fract() * 2.0 - 1.0),
                        ..*x
                    })
                    .collect()
            },
            |q| f(&q["timestamp_jitter_rms_s"]) > 5e-6 && q["trusted"] == true,
        ),
        // One NaN, one inf, one 1e308 current cell.
        (
            "bad_cells",
            |r| {
                let mut v = r.to_vec();
                v[50_000].i_abc[0] = f64::NAN;
                v[60_000].i_abc[1] = f64::INFINITY;
                v[70_000].i_abc[2] = 1e308;
                v
            },
            |q| q["bad_rows"] == 3 && q["bad_cells"]["ia_A"] == 1,
        ),
        // A 50 ms burst of 1e30 A.
        (
            "burst_1e30",
            |r| {
                let mut v = r.to_vec();
                for x in &mut v[40_000..40_500] {
                    x.i_abc = [1e30, -1e30, 0.0];
                }
                v
            },
            |q| q["glitch_bursts"] == 1 && (f(&q["longest_burst_s"]) - 0.05).abs() < 1e-3,
        ),
        // The acquisition clock stalls for 0.8 s (repeated timestamps) before the fault.
        (
            "stalled_clock",
            |r| {
                let t = r[45_000].t_s;
                r.iter()
                    .enumerate()
                    .map(|(k, x)| Row {
                        t_s: if (45_000..53_000).contains(&k) {
                            t
                        } else {
                            x.t_s
                        },
                        ..*x
                    })
                    .collect()
            },
            |q| q["time_drop_runs"] == 1 && q["long_gaps"] == 1 && q["trusted"] == true,
        ),
    ]
}
