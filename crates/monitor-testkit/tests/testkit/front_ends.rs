//! The front ends reach the library through its facade, `monitor-api`.
//!
//! The command line (`sim-host`) and the Python package (`python/`) list, among the
//! workspace's crates, only the core (the shared vocabulary: faults, phases, effects, the
//! verdict, the firmware's status line), `monitor-api` (the facade: the files, the
//! simulator, the replay and the analyses a front end may use, `monitor_api::{files, sim,
//! replay, analysis}`), and the crates beside it (`monitor-studies`, `monitor-store`). The
//! libraries below the facade (`monitor-io`, `monitor-sim`, `monitor-replay`,
//! `monitor-analysis`) may be their `[dev-dependencies]` only, for the tests' own logs.
//! Cargo then refuses any `use` of them in `src/`.

use std::path::Path;

/// The workspace crates a front end may list in `[dependencies]`.
const ALLOWED: [&str; 4] = [
    "monitor-core",
    "monitor-api",
    "monitor-studies",
    "monitor-store",
];

/// The front ends' manifests, from the workspace's root.
const FRONT_ENDS: [&str; 2] = ["sim-host/Cargo.toml", "python/Cargo.toml"];

/// The workspace crates (`path` or `workspace = true` dependencies named `monitor-*`) of a
/// manifest's `[dependencies]` that the facade rule does not allow.
fn beside_the_facade(manifest: &str) -> Vec<String> {
    let toml: toml::Table = manifest.parse().expect("a manifest");
    toml.get("dependencies")
        .and_then(|d| d.as_table())
        .into_iter()
        .flatten()
        .map(|(name, _)| name.clone())
        .filter(|name| name.starts_with("monitor-") && !ALLOWED.contains(&name.as_str()))
        .collect()
}

#[test]
fn the_front_ends_reach_the_library_through_monitor_api() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../..");
    for rel in FRONT_ENDS {
        let text = std::fs::read_to_string(root.join(rel)).expect(rel);
        let bad = beside_the_facade(&text);
        assert!(
            bad.is_empty(),
            "{rel}: [dependencies] lists {bad:?}: reach them through monitor-api's facade \
             (monitor_api::files, sim, replay, analysis), or as [dev-dependencies] for tests"
        );
    }
}

#[test]
fn the_rule_sees_a_library_below_the_facade() {
    let manifest = "[dependencies]\nmonitor-api.workspace = true\nmonitor-replay.workspace = true\n\n[dev-dependencies]\nmonitor-sim.workspace = true\n";
    assert_eq!(
        beside_the_facade(manifest),
        vec!["monitor-replay".to_string()]
    );
}
