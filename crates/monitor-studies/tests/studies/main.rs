//! The integration tests of `monitor-studies`, one test binary (issue 89): each module below was a
//! binary of its own (`tests/<module>.rs`), each linking the whole workspace. One
//! module's tests: `cargo test -p monitor-studies --test studies -- <module>::`.

// Shared by the modules below.
mod calibration_cases;
mod small_motor;

mod clipped_sensors;
mod heating;
mod isolation;
mod isolation_bench;
mod isolation_calibration;
mod load_move_onset;
mod month_of_logs;
mod no_false_alarm;
mod operating_points;
mod sample_rates;
mod sensor_gain_steps;
mod service_logs;
mod table1;
mod temperature_channel;
