//! The integration tests of `drive-monitor`, one test binary (issue 89): each module below was a
//! binary of its own (`tests/<module>.rs`), each linking the whole workspace. One
//! module's tests: `cargo test -p drive-monitor --test firmware -- <module>::`.

mod adc_rules;
mod boot_bookkeeping;
mod boot_clock;
mod bring_up;
mod debug_halt;
mod flash_record;
mod inverter_fed;
mod logging_never_blocks;
mod motor_source;
mod mutation_table;
mod panel_docs;
mod panel_patterns;
mod qemu_replay_data;
mod registers;
mod reset_log;
mod ring_latency;
mod status_line;
mod under_the_hal;
