//! The integration tests of `monitor-testkit`, one test binary (issue 89): each module below was a
//! binary of its own (`tests/<module>.rs`), each linking the whole workspace. One
//! module's tests: `cargo test -p monitor-testkit --test testkit -- <module>::`.

// The syntax the architecture suite reads (its files, paths and rules), shared by
// `architecture`, `entry_modules` and `one_door`.
mod architecture_syntax;

mod architecture;
mod entry_modules;
mod front_ends;
mod one_door;
mod textbook_machine_physics;
