//! Shared test scenarios of the workspace, a dev-only crate (`publish = false`): the
//! library crates and the command line take it as a `[dev-dependency]` only, and nothing
//! ships with it. It sits beside the libraries, above the simulator (it uses
//! `monitor-core`, `monitor-io` and `monitor-sim` and nothing higher), so the tests of
//! `monitor-replay`, `monitor-analysis`, `monitor-studies`, `monitor-store` and `sim-host`
//! can use it without a cycle; `monitor-sim`'s own tests do not.
//!
//! * [`analysis_common`]: simulated scenarios and logs of the model-vs-measurement tests.
//! * [`identify_machines`]: the six machines (0.37 kW to 50 hp) the `identify` tests
//!   identify, with their nameplates and the start files estimated from them.
//! * [`small_motor`]: the 0.37 kW and 50 hp machines beside the two reference motors.
//! * [`text`]: the command line's text as a test reads it (a wrapped verdict line joined).
//! * [`textbook_machine`]: an independent textbook induction machine (the ladder's logs),
//!   checked against physics by `tests/testkit/textbook_machine_physics.rs`.
//!
//! Its own tests also hold the workspace's architecture test (`tests/testkit/architecture.rs`),
//! which reads every crate's sources.

pub mod analysis_common;
pub mod identify_machines;
pub mod small_motor;
pub mod text;
pub mod textbook_machine;
