//! The log formats behind the one reader (`monitor_io::log`): CSV, TDMS and Parquet give the
//! same rows, the same verdicts and figures and the same one-line errors; `convert` copies
//! a log between them exactly; TDMS files from elsewhere (several groups, time in the
//! waveform properties, layouts not read) are handled as documented.

use assert_cmd::Command;
use monitor_analysis::{prep::ReadOptions, Analysis, Options};
use monitor_io::log::{Channels, Format, Log, LogFile, LogWriter, OpenOptions, Row};
use monitor_io::params::ParamFile;
use monitor_replay::{diagnose_file, ReplayOptions};
use monitor_sim::{simulate, Scenario};
use std::path::{Path, PathBuf};

fn bin() -> Command {
    Command::cargo_bin("sim-host").expect("binary")
}

fn repo() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("..")
}

fn params() -> ParamFile {
    ParamFile::load(&repo().join("examples/params/2p2kw.toml")).expect("params")
}

/// The Rs +50 % example run (8 s at 10 kHz, 12-bit sensors, every channel) written to
/// `path` by the one writer.
fn simulate_to(path: &Path) {
    let sc = Scenario::load(&repo().join("examples/scenarios/fault_rs_2p2kw.toml")).expect("sc");
    let mut w = LogWriter::create(path, sc.sensors.channels()).expect("create");
    simulate(&params(), &sc, |r: &Row| w.write_row(r).expect("row")).expect("simulate");
    w.finish().expect("finish");
}

/// `sim-host convert IN OUT`, which must succeed.
fn convert(from: &Path, to: &Path) {
    let o = bin()
        .arg("convert")
        .arg(from)
        .arg(to)
        .output()
        .expect("run");
    assert!(
        o.status.success(),
        "convert {from:?} {to:?}: {}",
        String::from_utf8_lossy(&o.stderr)
    );
}

/// A command that must fail with one line on stderr; the line.
fn fails(args: &[&str]) -> String {
    let o = bin().args(args).output().expect("run");
    assert!(!o.status.success(), "{args:?} should fail");
    let err = String::from_utf8_lossy(&o.stderr).trim().to_string();
    assert_eq!(err.lines().count(), 1, "{args:?}: {err}");
    err
}

/// A JSON document with every mention of the log's path replaced by "LOG".
fn json_without(path: &Path, v: &impl serde::Serialize) -> String {
    serde_json::to_string(v)
        .expect("json")
        .replace(&path.display().to_string(), "LOG")
}

#[test]
fn every_format_gives_the_same_rows_verdicts_and_figures() {
    let dir = tempfile::tempdir().expect("tmp");
    let csv = dir.path().join("run.csv");
    simulate_to(&csv);
    let tdms = dir.path().join("run.tdms");
    let pq = dir.path().join("run.parquet");
    convert(&csv, &tdms);
    convert(&csv, &pq);
    // Written directly by the simulator in each format, too.
    let direct_pq = dir.path().join("direct.parquet");
    let direct_tdms = dir.path().join("direct.tdms");
    simulate_to(&direct_pq);
    simulate_to(&direct_tdms);

    // The same rows: every writer keeps t_s at f64 and the channels at f32. The binary
    // formats hold the f32 values themselves, bit for bit the same in TDMS and Parquet;
    // the CSV holds their shortest decimal, which reads back as a f64 within 6e-8 of them.
    let want = Log::read(&csv).expect("csv");
    assert_eq!(want.rows.len(), 80_000);
    assert!(want.channels.voltages && want.channels.speed && want.channels.encoder);
    let binary = Log::read(&pq).expect("parquet");
    for p in [&tdms, &direct_pq, &direct_tdms] {
        let got = Log::read(p).expect("read");
        assert_eq!(got.channels, want.channels, "{p:?}");
        same_rows(&got.rows, &binary.rows, 0.0, p);
    }
    same_rows(&want.rows, &binary.rows, 6e-8, &csv);
    assert_eq!(LogFile::open(&pq).expect("pq").format(), Format::Parquet);
    assert_eq!(LogFile::open(&tdms).expect("tdms").format(), Format::Tdms);
    // Back to CSV: byte for byte the simulator's CSV.
    for p in [&tdms, &pq] {
        let back = dir
            .path()
            .join(format!("back_{}.csv", Format::of_path(p).extension()));
        convert(p, &back);
        assert!(
            std::fs::read(&back).expect("back") == std::fs::read(&csv).expect("csv"),
            "{p:?} -> CSV differs from the original CSV"
        );
    }

    // diagnose: the same report (lamps, candidates, times, data quality) from each.
    let opts = ReplayOptions {
        commission: Some(monitor_replay::CommissionWindow::of(2.0, 4.0)),
        ..Default::default()
    };
    let p = params();
    let d_csv = diagnose_file(&p, &csv, opts, &mut |_| {}).expect("diagnose csv");
    assert!(
        d_csv.report.first_detection_s.is_some_and(|t| t > 5.0),
        "the Rs step is detected from the CSV: {:?}",
        d_csv.report.first_detection_s
    );
    let want_diag = json_without(&csv, &d_csv.report);
    let mut pq_diag = String::new();
    for f in [&pq, &tdms] {
        let d = diagnose_file(&p, f, opts, &mut |_| {}).expect("diagnose");
        let got = json_without(f, &d.report);
        same_json(&got, &want_diag, f);
        if pq_diag.is_empty() {
            pq_diag = got;
        } else {
            assert_eq!(got, pq_diag, "TDMS and Parquet hold the same values");
        }
    }

    // compare: the same figures.
    let cmp = |f: &Path| {
        let a = Analysis::load(f, p, ReadOptions::default(), &mut |_| {}).expect("load");
        let out = a
            .compare(&Options {
                effects: vec![],
                fit_base: true,
                laws: Default::default(),
            })
            .expect("compare");
        (json_without(f, &out.report), json_without(f, &a.quality))
    };
    let want_cmp = cmp(&csv);
    assert!(
        want_cmp.0.contains("normalized_rms_error"),
        "{}",
        want_cmp.0
    );
    let pq_cmp = cmp(&pq);
    same_json(&pq_cmp.0, &want_cmp.0, &pq);
    same_json(&pq_cmp.1, &want_cmp.1, &pq);
    assert_eq!(cmp(&tdms), pq_cmp, "TDMS and Parquet hold the same values");
}

/// The rows are the same, each value within `rel` of the other (relative, or absolute
/// below 1).
fn same_rows(got: &[Row], want: &[Row], rel: f64, what: &Path) {
    assert_eq!(got.len(), want.len(), "{what:?}");
    let close = |a: f64, b: f64| (a - b).abs() <= rel * a.abs().max(b.abs()).max(1.0);
    for (k, (g, w)) in got.iter().zip(want).enumerate() {
        let gv = g.v_abc.unwrap_or_default();
        let wv = w.v_abc.unwrap_or_default();
        let ok = g.t_s == w.t_s
            && g.enc_count == w.enc_count
            && (0..3).all(|i| close(g.i_abc[i], w.i_abc[i]) && close(gv[i], wv[i]))
            && close(g.wm_rad_s.unwrap_or(0.0), w.wm_rad_s.unwrap_or(0.0));
        assert!(ok, "{what:?}: row {k} differs: {g:?} against {w:?}");
    }
}

/// Two JSON documents with the same keys, strings and booleans, and numbers within a
/// relative 1e-4 (the CSV's decimal rounding of the f32 values, 6e-8, through the fits).
fn same_json(got: &str, want: &str, what: &Path) {
    fn walk(g: &serde_json::Value, w: &serde_json::Value, at: &str, what: &Path) {
        use serde_json::Value as V;
        match (g, w) {
            (V::Number(a), V::Number(b)) => {
                let (a, b) = (
                    a.as_f64().unwrap_or(f64::NAN),
                    b.as_f64().unwrap_or(f64::NAN),
                );
                assert!(
                    (a - b).abs() <= 1e-4 * a.abs().max(b.abs()).max(1e-3),
                    "{what:?} {at}: {a} against {b}"
                );
            }
            (V::Array(a), V::Array(b)) => {
                assert_eq!(a.len(), b.len(), "{what:?} {at}");
                for (k, (x, y)) in a.iter().zip(b).enumerate() {
                    walk(x, y, &format!("{at}[{k}]"), what);
                }
            }
            (V::Object(a), V::Object(b)) => {
                let ka: Vec<_> = a.keys().collect();
                let kb: Vec<_> = b.keys().collect();
                assert_eq!(ka, kb, "{what:?} {at}");
                for (k, x) in a {
                    walk(x, &b[k], &format!("{at}.{k}"), what);
                }
            }
            _ => assert_eq!(g, w, "{what:?} {at}"),
        }
    }
    let g: serde_json::Value = serde_json::from_str(got).expect("json");
    let w: serde_json::Value = serde_json::from_str(want).expect("json");
    walk(&g, &w, "", what);
}

/// The message of opening `path`, with the path replaced by "LOG".
fn open_error(path: &Path, opts: &OpenOptions) -> String {
    LogFile::open_with(path, opts)
        .expect_err("must fail")
        .to_string()
        .replace(&path.display().to_string(), "LOG")
}

/// A Parquet file with DOUBLE columns `names` and three rows.
fn parquet_with(path: &Path, names: &[&str]) {
    use parquet::data_type::DoubleType;
    use parquet::file::writer::SerializedFileWriter;
    let mut schema = String::from("message m {");
    for n in names {
        schema.push_str(&format!(" REQUIRED DOUBLE {n};"));
    }
    schema.push('}');
    let schema =
        std::sync::Arc::new(parquet::schema::parser::parse_message_type(&schema).expect("schema"));
    let f = std::fs::File::create(path).expect("create");
    let mut w = SerializedFileWriter::new(f, schema, Default::default()).expect("writer");
    let mut rg = w.next_row_group().expect("rg");
    while let Some(mut c) = rg.next_column().expect("col") {
        c.typed::<DoubleType>()
            .write_batch(&[0.0, 1e-4, 2e-4], None, None)
            .expect("write");
        c.close().expect("close");
    }
    rg.close().expect("rg close");
    w.close().expect("close");
}

/// A TDMS file (written by the tdms-rs crate, as another program would) with the given
/// groups of f64 channels `(name, values)` and, on each channel, `props`.
/// A group: its name and its channels `(name, values)`.
type Group<'a> = (&'a str, Vec<(&'a str, Vec<f64>)>);

fn tdms_with(path: &Path, groups: &[Group<'_>], props: &[(&str, f64)]) {
    use tdms_rs::{PropertyValue, TdmsWriter};
    let mut w = TdmsWriter::create(path).expect("create");
    for (g, chans) in groups {
        let mut grp = w.add_group(*g).expect("group");
        for (name, vals) in chans {
            let mut ch = grp.add_channel::<f64>(*name).expect("channel");
            ch.write(vals).expect("write");
            for (k, v) in props {
                ch.add_property(*k, PropertyValue::Double(*v))
                    .expect("prop");
            }
        }
    }
    w.close().expect("close");
}

#[test]
fn missing_channels_give_the_same_one_line_error_in_every_format() {
    let dir = tempfile::tempdir().expect("tmp");
    let csv = dir.path().join("m.csv");
    std::fs::write(&csv, "t_s,ia_A,ib_A\n0,1,2\n").expect("write");
    let pq = dir.path().join("m.parquet");
    parquet_with(&pq, &["t_s", "ia_A", "ib_A"]);
    let tdms = dir.path().join("m.tdms");
    let v = vec![0.0, 1e-4, 2e-4];
    tdms_with(
        &tdms,
        &[(
            "log",
            vec![("t_s", v.clone()), ("ia_A", v.clone()), ("ib_A", v.clone())],
        )],
        &[],
    );
    let opts = OpenOptions::default();
    let want = open_error(&csv, &opts);
    // The column, why it is needed and the channels the log has (issue 26: and where to
    // map one of them).
    assert!(
        want.starts_with(
            "LOG: missing column 'ic_A' (the phase currents are the minimum a log must carry); the log has t_s, ia_A, ib_A;"
        ) && want.contains("[columns]"),
        "{want}"
    );
    assert_eq!(open_error(&pq, &opts), want);
    // (The tdms-rs writer stores a group's channels sorted by name.)
    assert_eq!(
        open_error(&tdms, &opts),
        want.replace("t_s, ia_A, ib_A", "ia_A, ib_A, t_s")
    );
    // Two voltages of three, the same in each.
    let csv2 = dir.path().join("v.csv");
    std::fs::write(&csv2, "t_s,va_V,vb_V,ia_A,ib_A,ic_A\n0,1,2,3,4,5\n").expect("write");
    let pq2 = dir.path().join("v.parquet");
    parquet_with(&pq2, &["t_s", "va_V", "vb_V", "ia_A", "ib_A", "ic_A"]);
    let want = open_error(&csv2, &opts);
    assert!(want.contains("'vc_V'"), "{want}");
    assert_eq!(open_error(&pq2, &opts), want);
    // And from the command line, one line naming the file and the column.
    let params = repo().join("examples/params/2p2kw.toml");
    for f in [&csv, &pq, &tdms] {
        let e = fails(&[
            "diagnose",
            "--params",
            params.to_str().expect("utf8"),
            f.to_str().expect("utf8"),
        ]);
        assert!(
            e.contains("missing column 'ic_A'") && e.contains(&f.display().to_string()),
            "{e}"
        );
    }
    // A group on a CSV or Parquet log is a mistake, said so.
    let g = OpenOptions {
        group: Some("x".into()),
        ..Default::default()
    };
    assert!(open_error(&csv, &g).contains("TDMS group"));
    assert!(open_error(&pq, &g).contains("TDMS group"));
}

#[test]
fn tdms_groups_and_waveform_time() {
    let dir = tempfile::tempdir().expect("tmp");
    let f = dir.path().join("daq.tdms");
    let n = 5000;
    let sine = |ph: f64| -> Vec<f64> {
        (0..n)
            .map(|k| 10.0 * (2.0 * std::f64::consts::PI * 50.0 * k as f64 / 5000.0 + ph).sin())
            .collect()
    };
    // LabVIEW style: no t_s channel, the time in wf_start_offset and wf_increment; and a
    // second group of other channels.
    tdms_with(
        &f,
        &[
            (
                "Motor",
                vec![
                    ("ia_A", sine(0.0)),
                    ("ib_A", sine(-2.0944)),
                    ("ic_A", sine(2.0944)),
                ],
            ),
            ("Ambient", vec![("temp_C", vec![21.0; n])]),
        ],
        &[("wf_increment", 2e-4), ("wf_start_offset", 1.5)],
    );
    let e = open_error(&f, &OpenOptions::default());
    assert_eq!(
        e,
        "LOG: the TDMS file has several groups ('Motor', 'Ambient'): name one with group"
    );
    let e = open_error(
        &f,
        &OpenOptions {
            group: Some("Pump".into()),
            ..Default::default()
        },
    );
    assert!(
        e.contains("no group 'Pump'") && e.contains("'Motor', 'Ambient'"),
        "{e}"
    );
    let opts = OpenOptions {
        group: Some("Motor".into()),
        ..Default::default()
    };
    let file = LogFile::open_with(&f, &opts).expect("open");
    assert_eq!(file.channels(), Channels::default());
    let mut rows: Vec<Row> = Vec::new();
    assert_eq!(
        file.for_each_row(&mut |_| {}, &mut rows).expect("read"),
        n as u64
    );
    assert_eq!(rows[0].t_s, 1.5);
    assert!((rows[n - 1].t_s - (1.5 + (n - 1) as f64 * 2e-4)).abs() < 1e-12);
    assert_eq!(rows[7].i_abc[1], sine(-2.0944)[7]);
    // The group without the currents names what it lacks.
    let e = open_error(
        &f,
        &OpenOptions {
            group: Some("Ambient".into()),
            ..Default::default()
        },
    );
    assert!(
        e.contains("missing column 't_s'") && e.contains("wf_increment"),
        "{e}"
    );
    // From the command line: the one-line error, then convert with --group gives a CSV
    // with t_s.
    let e = fails(&["convert", f.to_str().expect("utf8"), "x.csv"]);
    assert!(e.contains("--group"), "{e}");
    let out = dir.path().join("daq.csv");
    let o = bin()
        .args(["convert", "--group", "Motor"])
        .arg(&f)
        .arg(&out)
        .output()
        .expect("run");
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let text = std::fs::read_to_string(&out).expect("csv");
    assert!(
        text.starts_with("t_s,ia_A,ib_A,ic_A\n1.5,"),
        "{}",
        &text[..40]
    );
}

#[test]
fn an_empty_or_truncated_tdms_is_refused_naming_it() {
    // A recording cut short (an interrupted copy, a full disk) must be refused as such, not
    // as "no group" or as a layout to defragment.
    let dir = tempfile::tempdir().expect("tmp");
    let f = dir.path().join("w.tdms");
    let rows: Vec<Row> = (0..120_000)
        .map(|k| Row {
            t_s: k as f64 * 1e-4,
            v_abc: None,
            i_abc: [1.0, -1.0, 0.0],
            wm_rad_s: None,
            enc_count: None,
            t_winding_c: None,
        })
        .collect();
    Log {
        channels: Channels {
            voltages: false,
            speed: false,
            encoder: false,
            temperature: false,
        },
        rows,
    }
    .write(&f)
    .expect("write");
    let bytes = std::fs::read(&f).expect("read");
    for (cut, want) in [
        (0, "empty"),
        (20, "truncated"),
        (600, "truncated"),
        (bytes.len() - 1000, "truncated"),
    ] {
        let t = dir.path().join(format!("cut{cut}.tdms"));
        std::fs::write(&t, &bytes[..cut]).expect("write");
        let err = open_error(&t, &OpenOptions::default());
        assert!(err.contains(want), "{cut} bytes: {err}");
    }
}

#[test]
fn the_tdms_we_write_is_what_the_crate_reads() {
    let dir = tempfile::tempdir().expect("tmp");
    let f = dir.path().join("w.tdms");
    let n = 150_000; // three segments
    let rows: Vec<Row> = (0..n)
        .map(|k| Row {
            t_s: 0.25 + k as f64 * 1e-4,
            v_abc: None,
            i_abc: [k as f64, -(k as f64), 0.5],
            wm_rad_s: Some(150.0),
            enc_count: Some(k as i64 * 3),
            t_winding_c: None,
        })
        .collect();
    Log {
        channels: Channels {
            voltages: false,
            speed: true,
            encoder: true,
            temperature: false,
        },
        rows: rows.clone(),
    }
    .write(&f)
    .expect("write");
    let t = tdms_rs::TdmsFile::open(&f).expect("tdms-rs opens it");
    let g = t.group("log").expect("group");
    let names: Vec<String> = g.channels().map(|c| c.name().to_string()).collect();
    assert_eq!(
        names,
        ["t_s", "ia_A", "ib_A", "ic_A", "wm_rad_s", "enc_count"]
    );
    let ia = g.channel("ia_A").expect("ia");
    assert_eq!(ia.len(), n);
    let mut v = vec![0f32; n];
    ia.read(0..n, &mut v).expect("read");
    assert_eq!(v[123_456], 123_456.0);
    let mut enc = vec![0i64; 3];
    g.channel("enc_count")
        .expect("enc")
        .read(n - 3..n, &mut enc)
        .expect("read");
    assert_eq!(
        enc,
        [3 * (n as i64 - 3), 3 * (n as i64 - 2), 3 * (n as i64 - 1)]
    );
    match ia.property("wf_increment") {
        Some(tdms_rs::PropertyValue::Double(x)) => assert!((x - 1e-4).abs() < 1e-12, "{x}"),
        p => panic!("wf_increment {p:?}"),
    }
    match ia.property("wf_start_offset") {
        Some(tdms_rs::PropertyValue::Double(x)) => assert_eq!(*x, 0.25),
        p => panic!("wf_start_offset {p:?}"),
    }
    assert_eq!(Log::read(&f).expect("back").rows, rows);
    // A layout the reader would misread is refused by name: the same file with its first
    // segment marked interleaved.
    let mut bytes = std::fs::read(&f).expect("bytes");
    bytes[4] |= 1 << 5;
    let bad = dir.path().join("interleaved.tdms");
    std::fs::write(&bad, bytes).expect("write");
    let e = open_error(&bad, &OpenOptions::default());
    assert!(
        e.contains("interleaved") && e.contains("TDMS Defragment"),
        "{e}"
    );
}

#[test]
fn convert_never_overwrites_its_input_and_names_bad_cells() {
    let dir = tempfile::tempdir().expect("tmp");
    let csv = dir.path().join("a.csv");
    std::fs::write(&csv, "t_s,ia_A,ib_A,ic_A\n0,1,2,-3\n0.001,1,2,-3\n").expect("write");
    let s = csv.to_str().expect("utf8");
    let e = fails(&["convert", s, s]);
    assert!(e.contains("refusing to overwrite the input"), "{e}");
    assert_eq!(
        std::fs::read_to_string(&csv).expect("csv").lines().count(),
        3
    );
    // A time cell that is not a number: the exact reader's line and column, and no output
    // left behind. (Text in a measured column is a bad cell, converted as NaN.)
    let bad = dir.path().join("bad.csv");
    std::fs::write(&bad, "t_s,ia_A,ib_A,ic_A\n0,1,2,-3\n0.001x,1,2,-3\n").expect("write");
    let out = dir.path().join("bad.parquet");
    let e = fails(&[
        "convert",
        bad.to_str().expect("utf8"),
        out.to_str().expect("utf8"),
    ]);
    assert!(e.contains("line 3") && e.contains("t_s"), "{e}");
    assert!(!out.exists());
    let leftovers = std::fs::read_dir(dir.path())
        .expect("dir")
        .filter(|e| {
            e.as_ref()
                .map(|e| e.file_name().to_string_lossy().starts_with(".sim-host-"))
                .unwrap_or(false)
        })
        .count();
    assert_eq!(leftovers, 0, "temporary files left");
    // --json says what was done.
    let out = dir.path().join("a.parquet");
    let o = bin()
        .args(["convert", "--json", s, out.to_str().expect("utf8")])
        .output()
        .expect("run");
    assert!(o.status.success());
    let j: serde_json::Value = serde_json::from_slice(&o.stdout).expect("json");
    assert_eq!(j["rows"], 2);
    assert_eq!(j["output_format"], "Parquet");
    assert_eq!(j["input_format"], "CSV");
}
