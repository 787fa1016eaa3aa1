//! The command line's own library: the live terminal HMI's model and its three sources
//! ([`hmi`]: a simulated motor, a log replayed in time, a board's status lines over RTT).
//! The commands themselves are the binary (`src/main.rs`, `src/cli/`); the libraries they
//! call are the workspace's crates in `crates/` (`docs/architecture.md`).

pub mod flags;
pub mod hmi;
