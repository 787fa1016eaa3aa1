//! The order of the modules inside each crate with more than one part (rule 1 of the
//! architecture test): a module uses only modules of a lower layer of its crate.

/// The modules of one crate: (the crate's `src/` folder, its base layer's name, the
/// modules above the base and their layers, lowest first). A module the table does not
/// list is in layer 1, the base.
pub type Inside = (&'static str, &'static [(&'static str, u8)]);

/// The crates with more than one part, and the order of their modules (rule 1).
pub const INSIDE: &[Inside] = &[
    // The firmware's library: the board's facts and the stored records at the bottom, the
    // supervisor (`app`) above what it composes, the boot at the top. Issue 82's: the
    // self-check's table beside the reset record (it reads the clock's and the supply's
    // constants), the half's read above the recovery and the acquisition, the boot block
    // above the reset record it reads, the start (the registers' sequence that hands the
    // boot composition its facts) above the boot. Issue 88's: the register layer (`regs`, the
    // binary's only) above the board and the recovery it names; the boot report above the
    // start whose facts it prints.
    (
        "src/",
        &[
            ("board", 1),
            ("flash_record", 1),
            ("liveness", 1),
            ("recovery", 1),
            ("flash_ecc", 2),
            ("regs", 2),
            ("acquisition", 2),
            ("sampling", 2),
            ("supply", 2),
            ("panel", 2),
            ("commissioning", 2),
            ("offset_trim", 3),
            ("reset_record", 3),
            ("range_watch", 3),
            ("self_check", 3),
            ("ring_read", 3),
            ("boot_block", 4),
            ("setup_guard", 4),
            ("fault_path", 4),
            ("app", 4),
            ("motor_source", 5),
            ("boot", 6),
            ("startup", 7),
            ("boot_report", 8),
        ],
    ),
    // The parameter file below the logs and the nameplate estimate.
    (
        "crates/monitor-io/src/",
        &[("params", 1), ("log", 2), ("nameplate", 2)],
    ),
    // `identify` on top of the model-vs-measurement analysis, which does not use it.
    ("crates/monitor-analysis/src/", &[("identify", 2)]),
    // One simulated scenario through the core, the studies on it, the demo, the bench.
    (
        "crates/monitor-studies/src/",
        &[
            ("experiment", 1),
            ("fault_signatures", 2),
            ("service_profile", 2),
            ("demo", 3),
            ("bench", 4),
        ],
    ),
    // The replay as a chain of stages of one shape (`stage`), from the facts a row needs up
    // to `diagnose`, the front door: the stage trait, the sample clock, the windows the
    // sequence stage hands on, the baseline at the bottom; the options, the events, the
    // rotor's demodulator, which runs inside the sequence stage; the stages side by side
    // (no stage uses another: same layer; the commissioning tracker is the lamps' own); the timeline and the
    // findings with the one verdict; the report and the data-quality stage's end; the
    // replay that holds the chain; `diagnose` (the reading thread's pipe, the data-quality
    // hand-over) on top.
    (
        "crates/monitor-replay/src/",
        &[
            ("events", 2),
            ("error", 5),
            ("options", 2),
            ("rotor", 2),
            ("sequences", 3),
            ("lamps", 3),
            ("winding", 3),
            ("isolation", 3),
            ("timeline", 4),
            ("verdict", 4),
            ("report", 5),
            ("quality", 5),
            ("replay", 6),
            ("diagnose", 7),
        ],
    ),
    // The door: the front ends' spelling of the fields at the bottom, the engines' words
    // above it, the errors' words (which read a report's words) on top.
    (
        "crates/monitor-words/src/",
        &[("diagnose", 2), ("trend", 2), ("errors", 3)],
    ),
    // The fleet run over the one-call API.
    ("crates/monitor-api/src/", &[("fleet", 2)]),
    // The stored row and the store's errors at the bottom, the Parquet mirror above them,
    // the SQLite store that writes through the mirror on top; the trend reads rows.
    (
        "crates/monitor-store/src/",
        &[
            ("row", 1),
            ("error", 1),
            ("mirror", 2),
            ("trend", 2),
            ("store", 3),
        ],
    ),
];
