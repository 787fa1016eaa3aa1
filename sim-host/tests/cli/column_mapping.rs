//! Logs as a data-acquisition system writes them (issue 26): channels named `Ia`, `Va`,
//! `Time`..., in another order, with an extra channel, time in ms (or ISO 8601 text, or a
//! Parquet timestamp), currents in mA and speed in rpm, read through the parameter file's
//! `[columns]` table, give `diagnose` the same verdict and first detection as the log in the
//! schema, in CSV, TDMS and Parquet; `convert --params` writes the schema back. And the
//! reader's messages and rules (issue 29): a missing column lists the channels found and
//! suggests the closest, a duplicate column is refused with both positions, empty / NA /
//! null / NaN cells are held out alike, blank lines are counted, a channel with no finite
//! value is named.

mod daq_writers;

use assert_cmd::Command;
use daq_writers::{columns_table, daq_csv, daq_example_line, daq_parquet, daq_tdms};
use monitor_io::log::{Log, Row};
use std::f64::consts::TAU;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

fn bin() -> Command {
    Command::cargo_bin("sim-host").expect("binary")
}

fn repo() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("..")
}

fn s(p: &Path) -> &str {
    p.to_str().expect("utf8")
}

/// A command that must succeed; its stdout as JSON.
fn json(args: &[&str]) -> serde_json::Value {
    let o = bin().args(args).output().expect("run");
    assert!(
        o.status.success(),
        "{args:?}: {}",
        String::from_utf8_lossy(&o.stderr)
    );
    serde_json::from_slice(&o.stdout).expect("one JSON document")
}

/// A command that must fail with one line on stderr; the line.
fn fails(args: &[&str]) -> String {
    let o = bin().args(args).output().expect("run");
    assert!(!o.status.success(), "{args:?} should fail");
    let err = String::from_utf8_lossy(&o.stderr).trim().to_string();
    assert_eq!(err.lines().count(), 1, "{args:?}: {err}");
    err
}

/// The 2.2 kW parameter file with `columns` appended (a `[columns]` table, or nothing).
fn params_with(dir: &Path, name: &str, columns: &str) -> PathBuf {
    let base = std::fs::read_to_string(repo().join("examples/params/2p2kw.toml")).expect("read");
    let p = dir.join(name);
    std::fs::write(&p, format!("{base}\n{columns}")).expect("write");
    p
}

/// `diagnose --commission 2:4 --json` of `log` with `params`: (verdict, first detection
/// [s], the named fault).
fn verdict(params: &Path, log: &Path) -> (String, f64, String) {
    let d = json(&[
        "diagnose",
        "--params",
        s(params),
        s(log),
        "--commission",
        "2:4",
        "--json",
    ]);
    let named = d["candidates"][0]["fault"]
        .as_str()
        .unwrap_or("")
        .to_string();
    (
        d["verdict"].as_str().expect("verdict").to_string(),
        d["first_detection_s"].as_f64().expect("a first detection"),
        named,
    )
}

#[test]
fn renamed_and_rescaled_channels_give_the_same_verdict_in_every_format() {
    let dir = tempfile::tempdir().expect("tmp");
    let d = dir.path();
    let plain = params_with(d, "plain.toml", "");
    // The Rs +50 % example, as `simulate` writes it (the schema's names and units).
    let original = d.join("original.csv");
    let o = bin()
        .args(["simulate", "--params", s(&plain), "--scenario"])
        .arg(repo().join("examples/scenarios/fault_rs_2p2kw.toml"))
        .args(["--out", s(&original)])
        .output()
        .expect("run");
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let want = verdict(&plain, &original);
    assert_eq!(
        (want.0.as_str(), want.2.as_str()),
        ("fault", "rs"),
        "{want:?}"
    );
    assert!(want.1 > 5.0, "{want:?}");

    let rows = Log::read(&original).expect("read").rows;
    let ms = params_with(
        d,
        "ms.toml",
        &columns_table("{ name = \"Time\", unit = \"ms\" }"),
    );
    let csv = d.join("daq.csv");
    daq_csv(&csv, &rows, false);
    let iso_csv = d.join("daq_iso.csv");
    daq_csv(&iso_csv, &rows, true);
    let iso = params_with(
        d,
        "iso.toml",
        &columns_table("{ name = \"Time\", unit = \"iso8601\" }"),
    );
    let tdms = d.join("daq.tdms");
    daq_tdms(
        &tdms,
        &rows,
        &[("Ia", "mA"), ("Time", "ms"), ("Va", "Volts")],
    );
    let pq = d.join("daq.parquet");
    daq_parquet(&pq, &rows);
    // The timestamp's unit (microseconds) comes from the file.
    let stamp = params_with(d, "stamp.toml", &columns_table("{ name = \"timestamp\" }"));
    for (params, log) in [(&ms, &csv), (&iso, &iso_csv), (&ms, &tdms), (&stamp, &pq)] {
        let got = verdict(params, log);
        assert_eq!((&got.0, &got.2), (&want.0, &want.2), "{log:?}");
        assert!(
            (got.1 - want.1).abs() <= 0.1,
            "{log:?}: first detection {} s, the original's {} s",
            got.1,
            want.1
        );
    }
    // Without the mapping: one line naming the column, listing the channels and pointing
    // at the closest one.
    let e = fails(&["diagnose", "--params", s(&plain), s(&csv)]);
    assert!(
        e.contains("missing column 't_s'")
            && e.contains("the log has Ic, Time, Va, speed_rpm, Ia, Temp, Vb, Ib, Counts, Vc")
            && e.contains("did you mean 'Time'?")
            && e.contains("[columns]"),
        "{e}"
    );
    // convert --params writes the schema's names and SI units: that log needs no mapping.
    let back = d.join("back.csv");
    let o = bin()
        .args(["convert", "--params", s(&ms), s(&tdms), s(&back)])
        .output()
        .expect("run");
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let head = std::fs::read_to_string(&back).expect("read");
    assert!(
        head.starts_with("t_s,va_V,vb_V,vc_V,ia_A,ib_A,ic_A,wm_rad_s,enc_count\n"),
        "{}",
        &head[..80]
    );
    let got = verdict(&plain, &back);
    assert_eq!((&got.0, &got.2), (&want.0, &want.2));
    assert!((got.1 - want.1).abs() <= 0.1, "{got:?} {want:?}");
    // A TDMS unit_string that disagrees with [columns]: one line naming both units.
    let wrong = d.join("wrong.tdms");
    daq_tdms(&wrong, &rows[..100], &[("Ib", "A")]);
    let e = fails(&["diagnose", "--params", s(&ms), s(&wrong)]);
    assert!(
        e.contains("channel 'Ib'") && e.contains("'A'") && e.contains("'mA'"),
        "{e}"
    );
}

#[test]
fn a_missing_column_lists_the_channels_and_suggests_the_closest() {
    let dir = tempfile::tempdir().expect("tmp");
    let d = dir.path();
    let plain = params_with(d, "plain.toml", "");
    let csv = d.join("a.csv");
    std::fs::write(&csv, "t,Ia,Ib,Ic,Va,Vb,Vc,speed_rpm\n0,1,2,3,4,5,6,7\n").expect("write");
    let map_t = params_with(d, "t.toml", "[columns]\nt_s = { name = \"t\" }\n");
    let e = fails(&["diagnose", "--params", s(&map_t), s(&csv)]);
    assert!(
        e.contains(
            "missing column 'ia_A' (the phase currents are the minimum a log must carry); the log has t, Ia, Ib, Ic, Va, Vb, Vc, speed_rpm; did you mean 'Ia'? Map it in the parameter file's [columns] table"
        ),
        "{e}"
    );
    // A name the mapping gives, missing: said so.
    let typo = params_with(
        d,
        "typo.toml",
        "[columns]\nt_s = { name = \"t\" }\nia_A = { name = \"IA\" }\n",
    );
    let e = fails(&["diagnose", "--params", s(&typo), s(&csv)]);
    assert!(
        e.contains("missing column 'IA' (for ia_A in [columns])")
            && e.contains("did you mean 'Ia'?"),
        "{e}"
    );
    // A TDMS file timed by wf_increment on a channel the schema does not name.
    let tdms = d.join("w.tdms");
    {
        use tdms_rs::{PropertyValue, TdmsWriter};
        let mut w = TdmsWriter::create(&tdms).expect("create");
        let mut g = w.add_group("Motor").expect("group");
        for name in ["Ia", "Ib", "Ic"] {
            let mut ch = g.add_channel::<f64>(name).expect("channel");
            ch.write(&[0.0, 1.0, 2.0]).expect("write");
            ch.add_property("wf_increment", PropertyValue::Double(1e-4))
                .expect("prop");
        }
        drop(g);
        w.close().expect("close");
    }
    let e = fails(&["diagnose", "--params", s(&plain), s(&tdms)]);
    assert!(
        e.contains("missing column 't_s'")
            && e.contains("the log has Ia, Ib, Ic")
            && e.contains("channel 'Ia' has wf_increment: map it to ia_A in [columns]"),
        "{e}"
    );
    let currents = params_with(
        d,
        "i.toml",
        "[columns]\nia_A = { name = \"Ia\" }\nib_A = { name = \"Ib\" }\nic_A = { name = \"Ic\" }\n",
    );
    // ... mapped, the waveform time is found (3 rows: too few for anything, but read).
    let o = bin()
        .args(["diagnose", "--params", s(&currents), s(&tdms)])
        .output()
        .expect("run");
    let e = String::from_utf8_lossy(&o.stderr);
    assert!(!e.contains("missing column"), "{e}");
    // A Parquet file with a timestamp column and no t_s: the message names it.
    let pq = d.join("ts.parquet");
    {
        use parquet::data_type::{DoubleType, Int64Type};
        use parquet::file::writer::SerializedFileWriter;
        let schema = parquet::schema::parser::parse_message_type(
            "message m { REQUIRED INT64 ts (TIMESTAMP(MILLIS,true)); REQUIRED DOUBLE ia_A; REQUIRED DOUBLE ib_A; REQUIRED DOUBLE ic_A; }",
        )
        .expect("schema");
        let f = std::fs::File::create(&pq).expect("create");
        let mut w = SerializedFileWriter::new(f, std::sync::Arc::new(schema), Default::default())
            .expect("writer");
        let mut rg = w.next_row_group().expect("rg");
        let mut k = 0;
        while let Some(mut c) = rg.next_column().expect("col") {
            if k == 0 {
                c.typed::<Int64Type>()
                    .write_batch(&[0, 1, 2], None, None)
                    .expect("w");
            } else {
                c.typed::<DoubleType>()
                    .write_batch(&[0.0, 1.0, 2.0], None, None)
                    .expect("w");
            }
            c.close().expect("close");
            k += 1;
        }
        rg.close().expect("rg");
        w.close().expect("close");
    }
    let e = fails(&["diagnose", "--params", s(&plain), s(&pq)]);
    assert!(
        e.contains("missing column 't_s'")
            && e.contains("column 'ts' is a timestamp")
            && e.contains("t_s = { name = \"ts\" }")
            && e.contains("epoch_ms"),
        "{e}"
    );
    // A wrong [columns] entry names its key.
    for (table, says) in [
        (
            "ia_A = { name = \"Ia\", unit = \"mV\" }",
            "unit 'mV' is not one ia_A may be recorded in (A, mA)",
        ),
        (
            "ia = { name = \"Ia\" }",
            "'ia' is not a column of the schema",
        ),
        (
            "ia_A = { name = \"I\" }\nib_A = { name = \"I\" }",
            "ia_A and ib_A both name channel 'I'",
        ),
    ] {
        let p = params_with(d, "bad.toml", &format!("[columns]\n{table}\n"));
        let e = fails(&["diagnose", "--params", s(&p), s(&csv)]);
        assert!(e.contains("[columns]") && e.contains(says), "{table}: {e}");
    }
}

/// A healthy 2 s log at 5 kHz in the schema (the 2.2 kW machine), as text.
fn healthy_csv(dir: &Path) -> String {
    let sc = dir.join("sc.toml");
    std::fs::write(&sc, "duration_s = 2.0\nsample_rate_hz = 5000.0\n").expect("write");
    let out = dir.join("healthy.csv");
    let o = bin()
        .args(["simulate", "--params"])
        .arg(repo().join("examples/params/2p2kw.toml"))
        .args(["--scenario", s(&sc), "--out", s(&out)])
        .output()
        .expect("run");
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    std::fs::read_to_string(&out).expect("read")
}

/// `text` with the `ia_A` cell (5th field) of data rows `rows` (1-based) replaced by
/// `cells`, in turn.
fn with_cells(text: &str, rows: &[usize], cells: &[&str]) -> String {
    with_field(text, 4, rows, cells)
}

/// `text` with field `field` (0-based) of data rows `rows` replaced by `cells`, in turn.
fn with_field(text: &str, field: usize, rows: &[usize], cells: &[&str]) -> String {
    let mut out = String::new();
    for (k, line) in text.lines().enumerate() {
        let mut f: Vec<&str> = line.split(',').collect();
        if let Some(j) = rows.iter().position(|r| *r == k) {
            f[field] = cells[j % cells.len()];
        }
        out.push_str(&f.join(","));
        out.push('\n');
    }
    out
}

fn data_quality(dir: &Path, name: &str, text: &str) -> serde_json::Value {
    let p = dir.join(name);
    std::fs::write(&p, text).expect("write");
    let params = repo().join("examples/params/2p2kw.toml");
    json(&["diagnose", "--params", s(&params), s(&p), "--json"])["data_quality"].clone()
}

#[test]
fn missing_values_duplicates_and_blank_lines_follow_one_rule() {
    let dir = tempfile::tempdir().expect("tmp");
    let d = dir.path();
    let text = healthy_csv(d);
    let rows = [1000, 3000, 5000, 7000];
    // An empty cell, NA, null and NaN, one row each, against four NaN cells.
    let mixed = data_quality(
        d,
        "mixed.csv",
        &with_cells(&text, &rows, &["", "NA", "null", "NaN"]),
    );
    let nan = data_quality(d, "nan.csv", &with_cells(&text, &rows, &["NaN"]));
    assert_eq!(mixed["bad_cells"]["ia_A"], 4, "{mixed}");
    assert_eq!(mixed["bad_rows"], 4);
    assert_eq!(mixed["bad_cells"], nan["bad_cells"]);
    assert_eq!(mixed["rows_passed"], nan["rows_passed"]);
    let case = data_quality(
        d,
        "case.csv",
        &with_cells(&text, &rows, &["na", "NULL", " ", "inf"]),
    );
    assert_eq!(case["bad_cells"], nan["bad_cells"], "{case}");
    // The encoder count too (it used to become 0, a jump of the count).
    let enc = data_quality(
        d,
        "enc.csv",
        &with_field(&text, 8, &rows, &["", "NA", "null", "NaN"]),
    );
    assert_eq!(enc["bad_cells"]["enc_count"], 4, "{enc}");
    // Blank lines: skipped and counted.
    let blank = text.replacen("\n", "\n\n", 3).replace("\n\n\n", "\n\n");
    let q = data_quality(d, "blank.csv", &blank);
    assert!(q["blank_lines"].as_u64().is_some_and(|n| n >= 1), "{q}");
    assert!(
        q["warnings"].to_string().contains("blank lines skipped"),
        "{q}"
    );
    // A duplicated column: refused with both positions.
    let dup = d.join("dup.csv");
    std::fs::write(
        &dup,
        "t_s,ia_A,ib_A,ic_A,va_V,vb_V,vc_V,ia_A\n0,1,2,3,4,5,6,7\n",
    )
    .expect("write");
    let params = repo().join("examples/params/2p2kw.toml");
    let e = fails(&["diagnose", "--params", s(&params), s(&dup)]);
    assert!(
        e.contains("column 'ia_A' appears twice, at columns 2 and 8"),
        "{e}"
    );
    // A channel with no finite value is named (it used to be "the log has no data rows").
    let all: Vec<usize> = (1..=10_000).collect();
    let gone = d.join("gone.csv");
    std::fs::write(&gone, with_cells(&text, &all, &["NaN"])).expect("write");
    for cmd in ["diagnose", "compare", "explain"] {
        let e = fails(&[cmd, "--params", s(&params), s(&gone)]);
        assert!(
            e.contains("channel ia_A holds no finite value"),
            "{cmd}: {e}"
        );
    }
    // Currents in mA without a mapping: named, with the way out.
    let mut ma = String::new();
    for (k, line) in text.lines().enumerate() {
        let mut f: Vec<String> = line.split(',').map(str::to_string).collect();
        if k > 0 {
            for cell in &mut f[4..7] {
                *cell = format!("{}", cell.parse::<f64>().expect("num") * 1e3);
            }
        }
        ma.push_str(&f.join(","));
        ma.push('\n');
    }
    let ma_csv = d.join("ma.csv");
    std::fs::write(&ma_csv, ma).expect("write");
    let e = fails(&["diagnose", "--params", s(&params), s(&ma_csv)]);
    assert!(
        e.contains("of its 10000 values beyond +/-")
            && e.contains("_A = { name = \"...\", unit = \"mA\" }"),
        "{e}"
    );
}

/// Writes `examples/logs/daq_2p2kw.csv`: the run of `examples/scenarios/daq_2p2kw.toml`
/// as a data-acquisition system writes it. Run on purpose only:
/// `cargo test -p sim-host --test cli -- --ignored column_mapping::write_the_daq_example`.
#[test]
#[ignore = "writes the example log under examples/; run on purpose"]
fn write_the_daq_example() {
    use monitor_io::params::ParamFile;
    use monitor_sim::{simulate, Scenario};
    let params = ParamFile::load(&repo().join("examples/params/2p2kw.toml")).expect("params");
    let sc = Scenario::load(&repo().join("examples/scenarios/daq_2p2kw.toml")).expect("sc");
    let mut text = String::from("Time,Ia,Ib,Ic,Va,Vb,Vc,Speed\n");
    simulate(&params, &sc, |r: &Row| text.push_str(&daq_example_line(r))).expect("simulate");
    std::fs::write(repo().join("examples/logs/daq_2p2kw.csv"), text).expect("write");
}

/// The example DAQ log is read through its parameter file's `[columns]`: a clean healthy
/// log of the 2.2 kW machine, and the same rows as its run in the schema (to the DAQ's
/// printed resolution).
#[test]
fn the_daq_example_reads_through_its_columns_table() {
    let params = repo().join("examples/params/daq_2p2kw.toml");
    let log = repo().join("examples/logs/daq_2p2kw.csv");
    assert!(
        std::fs::metadata(&log).expect("example").len() <= 600_000,
        "the example stays small"
    );
    let d = json(&["diagnose", "--params", s(&params), s(&log), "--json"]);
    let q = &d["data_quality"];
    assert_eq!(q["time_unit"], "s", "{q}");
    assert!(
        (q["sample_rate_hz"].as_f64().expect("rate") - 1000.0).abs() < 1e-6,
        "{q}"
    );
    assert_eq!(q["bad_rows"], 0, "{q}");
    // A healthy machine: no fault named from its DAQ's units.
    assert_ne!(d["verdict"], "fault", "{}", d["verdict"]);
    // Without the table: the missing column is named, with the channels and the closest.
    let plain = repo().join("examples/params/2p2kw.toml");
    let e = fails(&["diagnose", "--params", s(&plain), s(&log)]);
    assert!(e.contains("did you mean 'Time'?"), "{e}");
    // convert gives the schema: speed back in rad/s, currents in A.
    let dir = tempfile::tempdir().expect("tmp");
    let out = dir.path().join("schema.csv");
    let o = bin()
        .args(["convert", "--params", s(&params), s(&log), s(&out)])
        .output()
        .expect("run");
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let rows = Log::read(&out).expect("read").rows;
    let last = rows.last().expect("rows");
    assert!((last.t_s - 9.999).abs() < 1e-9, "{last:?}");
    let w = last.wm_rad_s.expect("speed");
    assert!(w > 140.0 && w < 157.1, "mechanical rad/s: {w}");
    let i_peak = rows.iter().map(|r| r.i_abc[0].abs()).fold(0.0, f64::max);
    assert!(i_peak > 5.0 && i_peak < 100.0, "A: {i_peak}");
    // ... and the same verdict and data quality as the DAQ's log read through [columns].
    let schema = json(&["diagnose", "--params", s(&plain), s(&out), "--json"]);
    assert_eq!(schema["verdict"], d["verdict"]);
    assert_eq!(schema["data_quality"]["rows_passed"], q["rows_passed"]);
    assert_eq!(schema["data_quality"]["warnings"], q["warnings"]);
}

/// A headerless CSV without a time column (as a published data set writes it), the same
/// rows with a header row, and the parameter file's `[columns]` by place: the same rows; the
/// mistakes are refused with the key named.
#[test]
fn a_file_without_header_or_time_reads_through_columns_by_place() {
    let dir = tempfile::tempdir().expect("tempdir");
    let f = 1000.0;
    let mut body = String::new();
    for k in 0..2000 {
        let t = k as f64 / f;
        let i = |sh: f64| 5.0 * (TAU * 50.0 * t - sh).cos();
        writeln!(
            body,
            "{:.6},{:.6},{:.6}",
            i(0.0),
            i(TAU / 3.0),
            i(-TAU / 3.0)
        )
        .unwrap();
    }
    let bare = dir.path().join("bare.csv");
    std::fs::write(&bare, &body).expect("write");
    let headed = dir.path().join("headed.csv");
    std::fs::write(&headed, format!("Strom 1,Strom 2,Strom 3\n{body}")).expect("write");
    let by_place = "[columns]\nt_s = { sample_rate_hz = 1000.0 }\nia_A = { column = 1 }\nib_A = { column = 2 }\nic_A = { column = 3 }\n";
    let p = params_with(dir.path(), "p.toml", by_place);
    let read = |log: &Path| {
        let (_, columns) = monitor_io::log::mapping::load_params(&p).expect("params");
        let file = monitor_io::log::LogFile::open_with(
            log,
            &monitor_io::log::OpenOptions {
                group: None,
                columns,
            },
        )
        .expect("open");
        let mut rows: Vec<Row> = Vec::new();
        file.for_each_row(&mut |_| {}, &mut rows).expect("rows");
        rows
    };
    let (a, b) = (read(&bare), read(&headed));
    assert_eq!(a.len(), 2000);
    assert_eq!(a.len(), b.len());
    for (k, (x, y)) in a.iter().zip(&b).enumerate() {
        assert_eq!(x.i_abc, y.i_abc, "row {k}");
        assert!((x.t_s - k as f64 / f).abs() < 1e-12, "row {k}: {}", x.t_s);
        assert_eq!(x.t_s, y.t_s);
    }
    // diagnose reads it and says the rate.
    let v = json(&["diagnose", "--params", s(&p), s(&bare), "--json"]);
    assert_eq!(v["rows"], 2000, "{v}");
    assert!((v["data_quality"]["sample_rate_hz"].as_f64().unwrap() - 1000.0).abs() < 1e-6);
    // Without the table: refused, with the table to write.
    let plain = params_with(dir.path(), "plain.toml", "");
    let e = fails(&["diagnose", "--params", s(&plain), s(&bare)]);
    assert!(
        e.contains("no header row") && e.contains("column = 1"),
        "{e}"
    );
    // The mistakes, each naming its key.
    for (table, says) in [
        ("ia_A = { column = 0 }", "column = 0"),
        ("ia_A = { column = 1, name = \"Ia\" }", "not both"),
        ("ia_A = { sample_rate_hz = 1000.0 }", "belongs to t_s"),
        (
            "t_s = { sample_rate_hz = 1000.0, unit = \"ms\" }",
            "not both",
        ),
        ("t_s = { sample_rate_hz = -5.0 }", "not a sample rate"),
        ("ia_A = { unit = \"A\" }", "ia_A: give the channel"),
    ] {
        let p = params_with(dir.path(), "bad.toml", &format!("[columns]\n{table}\n"));
        let e = fails(&["diagnose", "--params", s(&p), s(&bare)]);
        assert!(e.contains(says), "{table}: {e}");
    }
    // A place past the line's last field is a missing column.
    let p = params_with(
        dir.path(),
        "past.toml",
        "[columns]\nt_s = { sample_rate_hz = 1000.0 }\nia_A = { column = 1 }\nib_A = { column = 2 }\nic_A = { column = 4 }\n",
    );
    let e = fails(&["diagnose", "--params", s(&p), s(&bare)]);
    assert!(e.contains("column 4") && e.contains("ic_A"), "{e}");
}
