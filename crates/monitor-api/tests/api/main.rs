//! The integration tests of `monitor-api`, one test binary (issue 89): each module below was a
//! binary of its own (`tests/<module>.rs`), each linking the whole workspace. One
//! module's tests: `cargo test -p monitor-api --test api -- <module>::`.

mod bad_encoder_cells;
mod detection_limits;
mod diagnose_explain_agree;
mod fault_from_the_start;
mod field_names;
mod findings_agree;
mod output_guard;
