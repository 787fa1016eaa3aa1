//! Issue 86, item 1: a log whose channels are not what their names say is named as wiring,
//! with the `[columns]` mapping that fixes it, on logs this project did not make: motulator's
//! 2.2 kW and 50 hp machines (`sim-host/tests/data/motulator`) and a real recording of
//! shorted turns (`examples/recordings/itsc`). The mix-ups are made the way a DAQ makes
//! them, through the parameter file's `[columns]` (two channels read under each other's
//! names, a channel's sign turned), and the fix the finding gives, applied on top, must
//! leave a log the check passes.

use monitor_io::log::quality::wiring::{PhaseSet, WiringFault};
use monitor_io::log::quality::{BadCells, CellLimits, CleanSink, QualityStage, TimeBase};
use monitor_io::log::{Column, ColumnMapping, LogFile, OpenOptions, Row};
use monitor_io::params::{load_columns_table, ColumnEntry, ColumnsTable, ParamFile};
use std::path::{Path, PathBuf};

struct Nothing;

impl CleanSink for Nothing {
    fn begin(&mut self, _base: &TimeBase) -> bool {
        true
    }
    fn row(&mut self, _row: &Row, _bad: BadCells) -> bool {
        true
    }
    fn new_segment(&mut self, _why: monitor_io::log::quality::SegmentBreak) -> bool {
        true
    }
    fn restart(&mut self) {}
}

fn repo(rel: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../..")
        .join(rel)
}

/// The wiring findings of `log` read through `table` for the machine of `params`.
fn wiring(log: &Path, params: &Path, table: &ColumnsTable) -> Vec<WiringFault> {
    let p = ParamFile::load_with_columns(params).expect("params").0; // ok: test
    let columns = ColumnMapping::from_table(table, p.motor.poles / 2).expect("mapping"); // ok: test
    let file = LogFile::open_with(
        log,
        &OpenOptions {
            group: None,
            columns,
        },
    )
    .expect("log"); // ok: test
    let mut sink = Nothing;
    let mut stage = QualityStage::new(&mut sink, CellLimits::for_params(&p), file.shown());
    file.for_each_row(&mut |_| {}, &mut stage).expect("read"); // ok: test
    stage.finish().expect("quality").wiring // ok: test
}

/// A case: its name, the columns table of the mix-up, and the finding that must name it.
type Case = (&'static str, ColumnsTable, fn(&WiringFault) -> bool);

/// `table` with column `c` reading the channel named `name` (its sign turned where `invert`).
fn with(mut table: ColumnsTable, c: Column, name: &str, invert: bool) -> ColumnsTable {
    let e = table.entry(c.name().to_string()).or_default();
    if e.column.is_none() {
        e.name = Some(name.to_string());
    }
    if invert {
        e.invert = Some(!e.invert.unwrap_or(false));
    }
    table
}

/// `table` with every fix of `found` applied on top (the name each fixed column is to read
/// is the channel its `reads` column reads in `table`).
fn fixed(table: &ColumnsTable, found: &[WiringFault]) -> ColumnsTable {
    let mut out = table.clone();
    for f in found {
        let before = out.clone();
        for fix in f.fix() {
            let reads = before
                .get(fix.reads.name())
                .cloned()
                .unwrap_or_else(|| ColumnEntry {
                    name: Some(fix.reads.name().to_string()),
                    ..ColumnEntry::default()
                });
            let mut e = reads;
            if fix.invert {
                e.invert = Some(!e.invert.unwrap_or(false));
            }
            out.insert(fix.column.name().to_string(), e);
        }
    }
    out
}

/// Exchanges the channels of columns `a` and `b` in `table`.
fn exchange(table: ColumnsTable, a: Column, b: Column) -> ColumnsTable {
    let entry = |t: &ColumnsTable, c: Column| {
        t.get(c.name()).cloned().unwrap_or_else(|| ColumnEntry {
            name: Some(c.name().to_string()),
            ..ColumnEntry::default()
        })
    };
    let (ea, eb) = (entry(&table, a), entry(&table, b));
    let mut t = table;
    t.insert(a.name().to_string(), eb);
    t.insert(b.name().to_string(), ea);
    t
}

#[test]
fn third_party_logs_of_two_sizes_name_each_mix_up_as_wiring_and_its_fix_passes() {
    let data = repo("sim-host/tests/data/motulator");
    for (log, params) in [
        ("kw2p2_control.csv", "kw2p2.toml"),
        ("hp50_load_step.csv", "hp50.toml"),
    ] {
        let (log, params) = (data.join(log), data.join(params));
        let none = ColumnsTable::new();
        assert!(wiring(&log, &params, &none).is_empty(), "{log:?} as made");
        let both = exchange(
            exchange(none.clone(), Column::Vb, Column::Vc),
            Column::Ib,
            Column::Ic,
        );
        let currents = exchange(none.clone(), Column::Ia, Column::Ic);
        let reversed = with(none.clone(), Column::Ib, "ib_A", true);
        let cases: [Case; 3] = [
            ("b and c exchanged in V and I", both, |f| {
                matches!(
                    f,
                    WiringFault::PhaseOrderReversed {
                        shaft_backwards: false,
                        ..
                    }
                )
            }),
            ("ia and ic exchanged", currents, |f| {
                matches!(
                    f,
                    WiringFault::Exchanged {
                        set: PhaseSet::Currents,
                        first: Column::Ic,
                        second: Column::Ia,
                        ..
                    }
                )
            }),
            ("ib reversed", reversed, |f| {
                matches!(
                    f,
                    WiringFault::Reversed {
                        channel: Column::Ib,
                        ..
                    }
                )
            }),
        ];
        for (what, table, expected) in cases {
            let found = wiring(&log, &params, &table);
            assert!(found.iter().any(expected), "{log:?}, {what}: {found:?}");
            let after = wiring(&log, &params, &fixed(&table, &found));
            assert!(after.is_empty(), "{log:?}, {what}, fixed: {after:?}");
        }
    }
}

#[test]
fn a_real_recording_with_one_current_reversed_is_named_and_as_published_passes() {
    let params = repo("examples/recordings/itsc/baldor_0p75hp.toml");
    let table = load_columns_table(&params).expect("columns"); // ok: test
    for log in ["SC_A1_B0_C0_001.csv", "SC_HLT_001.csv"] {
        let log = repo("examples/recordings/itsc").join(log);
        assert!(wiring(&log, &params, &table).is_empty(), "{log:?}");
        let reversed = with(table.clone(), Column::Ia, "", true);
        let found = wiring(&log, &params, &reversed);
        assert!(
            matches!(
                found[..],
                [WiringFault::Reversed {
                    channel: Column::Ia,
                    ..
                }]
            ),
            "{log:?}: {found:?}"
        );
        assert!(wiring(&log, &params, &fixed(&reversed, &found)).is_empty());
    }
}
