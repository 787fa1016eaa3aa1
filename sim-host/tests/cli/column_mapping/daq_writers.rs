//! The log writers of a data-acquisition system (`tests/cli/column_mapping.rs`): its channels
//! named and ordered its way, with an extra channel, time in ms (or ISO 8601 text, or a
//! Parquet timestamp), currents in mA and speed in rpm, in CSV, TDMS and Parquet.

use monitor_io::log::Row;
use std::f64::consts::TAU;
use std::fmt::Write as _;
use std::path::Path;

/// The DAQ's channels, in the order it writes them: (name, schema column index in `Row`
/// order t, va, vb, vc, ia, ib, ic, wm, enc, or `None` for the extra channel).
pub const DAQ: [(&str, Option<usize>); 10] = [
    ("Ic", Some(6)),
    ("Time", Some(0)),
    ("Va", Some(1)),
    ("speed_rpm", Some(7)),
    ("Ia", Some(4)),
    ("Temp", None),
    ("Vb", Some(2)),
    ("Ib", Some(5)),
    ("Counts", Some(8)),
    ("Vc", Some(3)),
];

/// The `[columns]` table of the DAQ log; `time` is the time's entry.
pub fn columns_table(time: &str) -> String {
    format!(
        "[columns]\nt_s = {time}\nva_V = {{ name = \"Va\", unit = \"V\" }}\nvb_V = {{ name = \"Vb\" }}\n\
         vc_V = {{ name = \"Vc\" }}\nia_A = {{ name = \"Ia\", unit = \"mA\" }}\n\
         ib_A = {{ name = \"Ib\", unit = \"mA\" }}\nic_A = {{ name = \"Ic\", unit = \"mA\" }}\n\
         wm_rad_s = {{ name = \"speed_rpm\", unit = \"rpm\" }}\nenc_count = {{ name = \"Counts\" }}\n"
    )
}

/// A row's value of DAQ channel `k` in the DAQ's units (time in ms, currents in mA, speed
/// in rpm); the extra channel is a temperature.
pub fn daq_value(r: &Row, k: usize) -> f64 {
    let v = r.v_abc.expect("voltages");
    match DAQ[k].1 {
        Some(0) => r.t_s * 1e3,
        Some(c @ 1..=3) => v[c - 1],
        Some(c @ 4..=6) => r.i_abc[c - 4] * 1e3,
        Some(7) => r.wm_rad_s.expect("speed") * 60.0 / TAU,
        Some(_) => r.enc_count.expect("encoder") as f64,
        None => 41.5,
    }
}

/// The DAQ's CSV of `rows`; `iso` writes the time as ISO 8601 text instead of ms.
pub fn daq_csv(path: &Path, rows: &[Row], iso: bool) {
    let mut t = DAQ.map(|d| d.0).join(",");
    t.push('\n');
    for r in rows {
        for (k, (_, column)) in DAQ.iter().enumerate() {
            if k > 0 {
                t.push(',');
            }
            if iso && *column == Some(0) {
                // 2024-05-01T12:00:00Z plus the row's time, to the 0.1 us.
                let us = (r.t_s * 1e7).round() as u64;
                let (sec, frac) = (us / 10_000_000, us % 10_000_000);
                let (h, m, s) = (12 + sec / 3600, sec / 60 % 60, sec % 60);
                write!(t, "2024-05-01T{h:02}:{m:02}:{s:02}.{frac:07}Z").expect("fmt");
            } else {
                write!(t, "{}", daq_value(r, k)).expect("fmt");
            }
        }
        t.push('\n');
    }
    std::fs::write(path, t).expect("write");
}

/// The DAQ's TDMS file of `rows` (f64 channels, with `unit_string` where `units` says).
pub fn daq_tdms(path: &Path, rows: &[Row], units: &[(&str, &str)]) {
    use tdms_rs::{PropertyValue, TdmsWriter};
    let mut w = TdmsWriter::create(path).expect("create");
    let mut g = w.add_group("Motor").expect("group");
    for (k, (name, _)) in DAQ.iter().enumerate() {
        let vals: Vec<f64> = rows.iter().map(|r| daq_value(r, k)).collect();
        let mut ch = g.add_channel::<f64>(*name).expect("channel");
        ch.write(&vals).expect("write");
        if let Some((_, u)) = units.iter().find(|(n, _)| n == name) {
            ch.add_property("unit_string", PropertyValue::String(u.to_string()))
                .expect("prop");
        }
    }
    drop(g);
    w.close().expect("close");
}

/// The DAQ's Parquet file of `rows`: DOUBLE channels, the time as an INT64 timestamp in
/// microseconds since 1970 (`timestamp`) instead of `Time`.
pub fn daq_parquet(path: &Path, rows: &[Row]) {
    use parquet::data_type::{DoubleType, Int64Type};
    use parquet::file::writer::SerializedFileWriter;
    let mut schema = String::from("message m {");
    for (name, c) in DAQ {
        if c == Some(0) {
            schema.push_str(" REQUIRED INT64 timestamp (TIMESTAMP(MICROS,true));");
        } else {
            schema.push_str(&format!(" REQUIRED DOUBLE {name};"));
        }
    }
    schema.push('}');
    let schema =
        std::sync::Arc::new(parquet::schema::parser::parse_message_type(&schema).expect("schema"));
    let f = std::fs::File::create(path).expect("create");
    let mut w = SerializedFileWriter::new(f, schema, Default::default()).expect("writer");
    let mut rg = w.next_row_group().expect("rg");
    let mut k = 0;
    while let Some(mut c) = rg.next_column().expect("col") {
        if DAQ[k].1 == Some(0) {
            let t: Vec<i64> = rows
                .iter()
                .map(|r| 1_714_564_800_000_000 + (r.t_s * 1e6).round() as i64)
                .collect();
            c.typed::<Int64Type>()
                .write_batch(&t, None, None)
                .expect("write");
        } else {
            let v: Vec<f64> = rows.iter().map(|r| daq_value(r, k)).collect();
            c.typed::<DoubleType>()
                .write_batch(&v, None, None)
                .expect("write");
        }
        c.close().expect("close");
        k += 1;
    }
    rg.close().expect("rg close");
    w.close().expect("close");
}

/// The channels of `examples/logs/daq_2p2kw.csv`, in its order, and how each is written
/// from a row of the schema: time in ms, currents in mA, voltages in V, speed in rpm.
pub fn daq_example_line(r: &Row) -> String {
    let v = r.v_abc.expect("voltages");
    let ma = |x: f64| (x * 1e3).round() as i64;
    format!(
        "{:.2},{},{},{},{:.1},{:.1},{:.1},{:.1}\n",
        r.t_s * 1e3,
        ma(r.i_abc[0]),
        ma(r.i_abc[1]),
        ma(r.i_abc[2]),
        v[0],
        v[1],
        v[2],
        r.wm_rad_s.expect("speed") * 60.0 / TAU
    )
}
