//! The integration tests of `monitor-io`, one test binary (issue 89): each module below was a
//! binary of its own (`tests/<module>.rs`), each linking the whole workspace. One
//! module's tests: `cargo test -p monitor-io --test io -- <module>::`.

mod nameplate;
mod text_cells;
mod wiring_mix_ups;
