//! The engines' sentences still there (rule 9, `sentences.rs`): each file's count of
//! sentences built outside the allowed places, at most, and why. Measured when the rule
//! came (issue 89 item 3): 434 sites in 69 files; the list only shrinks, as each moves to
//! the door.

/// A bad input's one line (the value, the field, what it must be) built into an error's
/// `String` field, or a helper that makes one.
const BAD_INPUT: &str = "a bad input's one line built into an error's String field: to become the error's typed fields, spelled by its #[error]";
/// A finding's or a note's sentence for a crew.
const FINDING: &str = "a finding's or a note's sentence spelled in the engine: to become a typed reason spelled by monitor-words";
/// Reference text carried as data.
const CATALOGUE: &str = "reference text carried as data (an option's, a column's or a range's description, a limit's source): the door's to spell";
/// An effect's catalogue and its fitted finding.
const EFFECT: &str = "an effect's catalogue text (description, equation, parameters) and its fitted finding's sentence: the door's to spell";
/// The comments of a file the engine writes.
const FILE_TEXT: &str = "the comments of the parameter file it writes: the document's words, the door's (issue 89 item 5)";
/// The core's configuration check.
const CONFIG_CHECK: &str = "the no_std ConfigError's requirement phrases (ConfigCheck::requirement): to be spelled by the error's Display or at the door";
/// The store.
const STORE: &str = "a store error's line and the trend's WARNING line about file times: a typed error and a typed warning, spelled at the door";

/// (file, sentences at most, why).
pub const SENTENCES_LEFT: &[(&str, usize, &str)] = &[
    ("crates/monitor-analysis/src/analysis.rs", 2, FINDING),
    ("crates/monitor-analysis/src/base_range.rs", 4, CATALOGUE),
    (
        "crates/monitor-analysis/src/effects/coulomb_friction.rs",
        5,
        EFFECT,
    ),
    (
        "crates/monitor-analysis/src/effects/cross_coupling_dynamics.rs",
        3,
        EFFECT,
    ),
    (
        "crates/monitor-analysis/src/effects/current_dynamics.rs",
        5,
        EFFECT,
    ),
    (
        "crates/monitor-analysis/src/effects/d_axis_dynamics.rs",
        3,
        EFFECT,
    ),
    (
        "crates/monitor-analysis/src/effects/flux_dynamics.rs",
        5,
        EFFECT,
    ),
    (
        "crates/monitor-analysis/src/effects/iron_loss.rs",
        6,
        EFFECT,
    ),
    (
        "crates/monitor-analysis/src/effects/load_torque.rs",
        7,
        EFFECT,
    ),
    ("crates/monitor-analysis/src/effects/mod.rs", 1, FINDING),
    (
        "crates/monitor-analysis/src/effects/phase_asymmetry.rs",
        6,
        EFFECT,
    ),
    (
        "crates/monitor-analysis/src/effects/plausible.rs",
        10,
        CATALOGUE,
    ),
    (
        "crates/monitor-analysis/src/effects/rotor_asymmetry.rs",
        9,
        EFFECT,
    ),
    (
        "crates/monitor-analysis/src/effects/saturation.rs",
        9,
        EFFECT,
    ),
    ("crates/monitor-analysis/src/effects/setup.rs", 2, FINDING),
    (
        "crates/monitor-analysis/src/effects/supply_unbalance.rs",
        6,
        EFFECT,
    ),
    (
        "crates/monitor-analysis/src/effects/thermal_drift.rs",
        10,
        EFFECT,
    ),
    ("crates/monitor-analysis/src/effects/user_law.rs", 6, EFFECT),
    ("crates/monitor-analysis/src/effects/windage.rs", 5, EFFECT),
    (
        "crates/monitor-analysis/src/explain/ladder/base.rs",
        6,
        CATALOGUE,
    ),
    (
        "crates/monitor-analysis/src/explain/ladder/round/choice.rs",
        1,
        FINDING,
    ),
    ("crates/monitor-analysis/src/fit/machine.rs", 1, FINDING),
    (
        "crates/monitor-analysis/src/identify/output.rs",
        16,
        FILE_TEXT,
    ),
    ("crates/monitor-analysis/src/metrics/worst.rs", 2, FINDING),
    ("crates/monitor-analysis/src/prep/decimate.rs", 6, FINDING),
    ("crates/monitor-analysis/src/rotor_asymmetry.rs", 7, FINDING),
    ("crates/monitor-analysis/src/transients.rs", 4, FINDING),
    ("crates/monitor-core/src/error.rs", 19, CONFIG_CHECK),
    ("crates/monitor-io/src/log/csv_header.rs", 4, BAD_INPUT),
    ("crates/monitor-io/src/log/exact.rs", 3, BAD_INPUT),
    ("crates/monitor-io/src/log/mapping.rs", 2, BAD_INPUT),
    ("crates/monitor-io/src/log/mapping/suggest.rs", 4, BAD_INPUT),
    ("crates/monitor-io/src/log/memory.rs", 3, BAD_INPUT),
    ("crates/monitor-io/src/log/parquet.rs", 5, BAD_INPUT),
    ("crates/monitor-io/src/log/quality/finish.rs", 3, FINDING),
    ("crates/monitor-io/src/log/quality/report.rs", 19, FINDING),
    (
        "crates/monitor-io/src/log/quality/speed_unit.rs",
        8,
        FINDING,
    ),
    (
        "crates/monitor-io/src/log/quality/wiring/fault.rs",
        9,
        FINDING,
    ),
    ("crates/monitor-io/src/log/reader.rs", 2, BAD_INPUT),
    ("crates/monitor-io/src/log/source.rs", 3, BAD_INPUT),
    ("crates/monitor-io/src/log/tdms/mod.rs", 21, BAD_INPUT),
    ("crates/monitor-io/src/log/typed.rs", 3, BAD_INPUT),
    ("crates/monitor-io/src/nameplate/circuit.rs", 17, BAD_INPUT),
    ("crates/monitor-io/src/nameplate/mod.rs", 6, BAD_INPUT),
    (
        "crates/monitor-io/src/nameplate/toml_text.rs",
        10,
        FILE_TEXT,
    ),
    ("crates/monitor-io/src/params/mod.rs", 1, BAD_INPUT),
    ("crates/monitor-io/src/params/plausibility.rs", 8, BAD_INPUT),
    ("crates/monitor-laws/src/expr.rs", 4, BAD_INPUT),
    ("crates/monitor-laws/src/expr/check.rs", 2, BAD_INPUT),
    ("crates/monitor-laws/src/file.rs", 2, BAD_INPUT),
    ("crates/monitor-replay/src/diagnose.rs", 11, FINDING),
    ("crates/monitor-replay/src/diagnose/front.rs", 2, FINDING),
    ("crates/monitor-replay/src/fields.rs", 8, CATALOGUE),
    ("crates/monitor-replay/src/options.rs", 9, BAD_INPUT),
    ("crates/monitor-sim/src/effect_spec.rs", 11, BAD_INPUT),
    ("crates/monitor-sim/src/faults.rs", 7, BAD_INPUT),
    ("crates/monitor-sim/src/pwm.rs", 5, BAD_INPUT),
    ("crates/monitor-sim/src/resolve.rs", 2, BAD_INPUT),
    ("crates/monitor-sim/src/run.rs", 8, BAD_INPUT),
    ("crates/monitor-sim/src/scenario.rs", 15, BAD_INPUT),
    ("crates/monitor-sim/src/sensors.rs", 3, BAD_INPUT),
    ("crates/monitor-sim/src/steady.rs", 2, BAD_INPUT),
    ("crates/monitor-sim/src/thermometer.rs", 2, BAD_INPUT),
    ("crates/monitor-store/src/row.rs", 34, CATALOGUE),
    ("crates/monitor-store/src/store.rs", 4, STORE),
    ("crates/monitor-store/src/trend/mod.rs", 1, CATALOGUE),
    ("crates/monitor-studies/src/bench/isolation.rs", 1, FINDING),
];
