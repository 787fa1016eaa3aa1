//! The architecture suite's allowances: the files and functions let past its size rules,
//! each with its reason and its own ceiling (the rules in `tests/testkit/architecture.rs`).

/// Files allowed over 600: (path, lines at most, why).
pub const LONG_FILES: &[(&str, usize, &str)] = &[
    (
        "sim-host/src/cli/render/plot.rs",
        877,
        "the one place every chart is drawn with plotters: axes, series, the legend and the SVG's record of what its legend drew (each chart's <desc>, which the chart test reads); its parts share one reader, the person changing how a chart looks",
    ),
    (
        "sim-host/src/cli/render/charts.rs",
        660,
        "the table of every chart a command draws and the series each chart is made of, one function a chart: read as one list when a chart is added or renamed",
    ),
    (
        "tests/firmware/registers.rs",
        800,
        "the register layer held to RM0440 one register after another, read as one list beside the manual; docs/firmware.md's mutation table cites its assertions by line",
    ),
    (
        "tests/firmware/reset_log.rs",
        650,
        "the reset log's rules (its pages, marks, entries, wear and report) read together; docs/firmware.md's mutation table cites its assertions by line",
    ),
];
/// Functions allowed over 60: (path, function, lines at most, why).
pub const LONG_FUNCTIONS: &[(&str, &str, usize, &str)] = &[
    (
        "crates/monitor-words/src/diagnose/findings.rs",
        "summary_of",
        113,
        "the door: one arm per variant of the replay's `Detail`, each finding's sentence; one enum's sentences are read together",
    ),
    (
        "crates/monitor-words/src/diagnose/isolation.rs",
        "said",
        109,
        "the door: one arm per variant of `IsolationSaid`, the isolation's conclusion in words",
    ),
    (
        "crates/monitor-words/src/explain.rs",
        "verdict",
        85,
        "the door: one arm per variant of explain's typed conclusion",
    ),
    (
        "crates/monitor-words/src/trend.rs",
        "sentence",
        90,
        "the door: one arm per variant of `TrendReason`, the trend's reason in words",
    ),
    (
        "crates/monitor-core/src/isolation/isolator/points.rs",
        "isolate_points_anchored_from",
        77,
        "one search over the heating range for every fault over the operating points together: its steps share the candidate's state (the fit at each temperature and the best so far); not yet split",
    ),
    (
        "crates/monitor-core/src/isolation/isolator/search.rs",
        "rank",
        66,
        "the ranking of the fitted faults, beyond the heating, in one pass; not yet split",
    ),
    (
        "crates/monitor-store/src/trend/analyse.rs",
        "indicator_trend",
        76,
        "one indicator's trend from the stored rows (the reference, the fit, the series, the run at the FAULT level); not yet split",
    ),
    (
        "crates/monitor-store/src/trend/analyse.rs",
        "judge",
        66,
        "the slope, scatter, alarm and reason of one indicator in one pass; not yet split",
    ),
];
