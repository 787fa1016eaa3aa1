//! The integration tests of `monitor-store`, one test binary (issue 89): each module below was a
//! binary of its own (`tests/<module>.rs`), each linking the whole workspace. One
//! module's tests: `cargo test -p monitor-store --test store -- <module>::`.

mod held_out_month;
mod store;
mod store_time_source;
mod theil_sen;
mod trend_month;
mod trend_view;
