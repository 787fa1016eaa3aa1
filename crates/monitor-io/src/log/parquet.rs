//! Parquet logs: the CSV's columns ([`Column::name`]) as number columns, read and written
//! through the `parquet` crate's column API (no arrow).
//!
//! Reading: top-level columns named like the CSV header; DOUBLE, FLOAT, INT32 or INT64
//! (nullable columns are accepted, a null is handed over as NaN for the data-quality stage to
//! judge); uncompressed, snappy or lz4 (what pandas, pyarrow and Spark write by default; a
//! file in another codec is refused naming it). The row groups are decoded in parallel
//! (rayon, a batch ahead of the rows being handed over), so memory is a few row groups
//! whatever the log's length; the rows are handed over [`HAND_ROWS`] at a time
//! ([`RowSink::rows`]).
//!
//! Writing: `t_s` as DOUBLE, the voltages, currents and speed as FLOAT (the precision of
//! every writer, see [`super::LogWriter`]), `enc_count` as INT64, all REQUIRED, plain
//! encoding, uncompressed (sensor noise does not compress), [`ROW_GROUP_ROWS`] rows per row
//! group.

use super::mapping::ColumnMapping;
use super::source::{not_a_log, BinarySource, ColumnMap, Opened};
use super::typed::FieldType;
use super::{Channels, Column, LogError, Row, RowSink};
use parquet::basic::{Compression, Encoding, LogicalType, TimeUnit, Type as PhysicalType};
use parquet::column::reader::{ColumnReader, ColumnReaderImpl};
use parquet::data_type::{DataType, DoubleType, FloatType, Int64Type};
use parquet::errors::ParquetError;
use parquet::file::metadata::ParquetMetaData;
use parquet::file::properties::{EnabledStatistics, WriterProperties};
use parquet::file::reader::{FileReader, SerializedFileReader};
use parquet::file::writer::SerializedFileWriter;
use parquet::schema::types::SchemaDescriptor;
use rayon::prelude::*;
use std::fs::File;
use std::ops::ControlFlow;
use std::path::Path;
use std::sync::Arc;

/// Rows per written row group (9 MB with every channel).
pub const ROW_GROUP_ROWS: usize = 1 << 18;

/// A Parquet log opened for reading: its rows per row group.
#[derive(Debug, Clone)]
pub(super) struct ParquetSource {
    groups: Vec<u64>,
}

fn pq_error(shown: &str, e: &ParquetError) -> LogError {
    not_a_log(
        shown,
        format!(
            "not a readable Parquet file: {}",
            crate::one_line(&e.to_string())
        ),
    )
}

/// The unit of a timestamp column (`epoch_ms`, `epoch_us`, `epoch_ns`), `None` for any
/// other logical type.
fn timestamp_unit(t: Option<&LogicalType>) -> Option<&'static str> {
    match t {
        Some(LogicalType::Timestamp(ts)) => Some(match ts.unit {
            TimeUnit::MILLIS => "epoch_ms",
            TimeUnit::MICROS => "epoch_us",
            TimeUnit::NANOS => "epoch_ns",
        }),
        _ => None,
    }
}

/// One decoded row group: the values of each [`Column::ALL`] column (empty when absent).
type Decoded = [Vec<f64>; Column::COUNT];

/// Each leaf column's type, as [`super::typed`] checks them.
fn field_types(schema: &SchemaDescriptor) -> Vec<FieldType> {
    (0..schema.num_columns())
        .map(|j| {
            let c = schema.column(j);
            let ty = c.physical_type();
            FieldType {
                not_numbers: (!matches!(
                    ty,
                    PhysicalType::DOUBLE
                        | PhysicalType::FLOAT
                        | PhysicalType::INT32
                        | PhysicalType::INT64
                ))
                .then(|| ty.to_string()),
                timestamp: timestamp_unit(c.logical_type_ref()),
            }
        })
        .collect()
}

/// Refuses a file whose mapped columns (`field`: leaf indices) are compressed with a codec
/// this build does not read (uncompressed, snappy and lz4 are read).
///
/// # Errors
/// [`LogError::NotALog`] naming the column and its codec.
fn check_codecs(
    meta: &ParquetMetaData,
    field: &[Option<usize>],
    shown: &str,
) -> Result<(), LogError> {
    let schema = meta.file_metadata().schema_descr();
    for rg in meta.row_groups() {
        for j in field.iter().flatten() {
            let codec = rg.column(*j).compression();
            if !matches!(
                codec,
                Compression::UNCOMPRESSED
                    | Compression::SNAPPY
                    | Compression::LZ4_RAW
                    | Compression::LZ4
            ) {
                return Err(not_a_log(
                    shown,
                    format!("column '{}' is compressed with {codec}, which this build does not read (uncompressed, snappy or lz4): rewrite the file with one of those", schema.column(*j).name()),
                ));
            }
        }
    }
    Ok(())
}

impl ParquetSource {
    /// Opens `path` and maps the schema's columns.
    ///
    /// # Errors
    /// [`LogError::NotALog`] for a file that is not Parquet, a schema column that is not a
    /// number or a codec not built in; [`LogError::MissingColumn`] as for a CSV log.
    pub fn open(
        path: &Path,
        shown: &str,
        mapping: &ColumnMapping,
    ) -> Result<(Self, ColumnMap), LogError> {
        let f = File::open(path).map_err(|source| LogError::Io {
            path: shown.to_string(),
            source,
        })?;
        let r = SerializedFileReader::new(f).map_err(|e| pq_error(shown, &e))?;
        let meta = r.metadata();
        let schema = meta.file_metadata().schema_descr();
        // Leaf columns by their dotted path: a top-level column is its name.
        let found: Vec<String> = (0..schema.num_columns())
            .map(|j| schema.column(j).path().string())
            .collect();
        let held = ("DOUBLE, FLOAT, INT32 or INT64", "the file");
        let columns =
            super::typed::typed_columns(&found, &field_types(schema), mapping, shown, held)?;
        check_codecs(meta, &columns.field, shown)?;
        let groups = meta
            .row_groups()
            .iter()
            .map(|g| g.num_rows().max(0) as u64)
            .collect();
        Ok((ParquetSource { groups }, columns))
    }
}

/// Row groups decoded in parallel, a batch ahead of the rows handed over on this thread.
impl BinarySource for ParquetSource {
    fn rows(&self) -> u64 {
        self.groups.iter().sum()
    }

    fn for_each_row(
        &self,
        log: &Opened<'_>,
        progress: &mut dyn FnMut(f64),
        on_row: &mut dyn FnMut(&Row) -> bool,
    ) -> Result<u64, LogError> {
        self.for_each_block(log, progress, &mut OnRow(on_row))
    }

    fn for_each_block(
        &self,
        log: &Opened<'_>,
        progress: &mut dyn FnMut(f64),
        sink: &mut dyn RowSink,
    ) -> Result<u64, LogError> {
        let (path, shown, columns) = (log.path(), log.shown(), log.columns());
        let ng = self.groups.len();
        let per_batch = rayon::current_num_threads().max(1) * 2;
        let total = self.rows().max(1) as f64;
        let decode_batch = |from: usize| -> Vec<Result<Decoded, LogError>> {
            (from..(from + per_batch).min(ng))
                .into_par_iter()
                .map(|g| decode(path, g, columns).map_err(|e| pq_error(shown, &e)))
                .collect()
        };
        let mut current = decode_batch(0);
        let mut from = 0usize;
        let mut handed = 0u64;
        while !current.is_empty() {
            let next_from = from + current.len();
            let mut next: Option<Vec<Result<Decoded, LogError>>> = None;
            let mut outcome: Option<Result<(), LogError>> = None;
            rayon::in_place_scope(|s| {
                if next_from < ng {
                    let nx = &mut next;
                    let d = &decode_batch;
                    s.spawn(move |_| *nx = Some(d(next_from)));
                }
                for res in current.drain(..) {
                    let cols = match res {
                        Ok(c) => c,
                        Err(e) => {
                            outcome = Some(Err(e));
                            return;
                        }
                    };
                    if !hand_rows(&cols, columns, &mut handed, sink) {
                        outcome = Some(Ok(()));
                        return;
                    }
                    progress((handed as f64 / total).min(1.0));
                }
            });
            if let Some(o) = outcome {
                return o.map(|_| handed);
            }
            current = next.unwrap_or_default();
            from = next_from;
        }
        Ok(handed)
    }
}

/// A closure given each row, as a [`RowSink`].
struct OnRow<'a>(&'a mut dyn FnMut(&Row) -> bool);

impl RowSink for OnRow<'_> {
    fn row(&mut self, row: &Row) -> bool {
        (self.0)(row)
    }
    fn restart(&mut self) {}
}

/// Rows handed over at a time ([`RowSink::rows`]).
const HAND_ROWS: usize = 256;

/// Hands the rows of one decoded row group to `on_row`, counting them in `handed`; false
/// when `on_row` asked to stop. Each row is built from the columns directly, cut to the
/// group's length (no bounds checks, no array of the row's values), with the values
/// [`super::source::row_from_values`] gives; a present column shorter than the group (a
/// truncated file) takes the general path, [`hand_ragged_rows`].
#[inline]
fn hand_rows(
    cols: &Decoded,
    columns: &ColumnMap,
    handed: &mut u64,
    sink: &mut dyn RowSink,
) -> bool {
    let n = cols.iter().find(|c| !c.is_empty()).map_or(0, Vec::len);
    let short = |k: usize| cols[k].len() < n;
    if (0..Column::COUNT).any(|k| columns.field[k].is_some() && short(k)) {
        return hand_ragged_rows(cols, columns, handed, &mut |r| sink.row(r));
    }
    // An absent column reads as zeros (the general path's value of a cell never set),
    // or as any full column where the row leaves its value out (speed, count,
    // temperature, the voltages without `va_V`).
    let unread = |k: usize| {
        k >= Column::Speed as usize || ((1..=3).contains(&k) && columns.field[1].is_none())
    };
    let zeros = if (0..Column::COUNT).any(|k| short(k) && !unread(k)) {
        vec![0.0; n]
    } else {
        Vec::new()
    };
    let ia = &cols[Column::Ia as usize];
    let filler = if zeros.is_empty() { ia } else { &zeros };
    let cut: [&[f64]; Column::COUNT] = std::array::from_fn(|k| cols[k].get(..n).unwrap_or(filler));
    if columns.scaled {
        hand_columns::<true>(&cut, n, columns, handed, sink)
    } else {
        hand_columns::<false>(&cut, n, columns, handed, sink)
    }
}

/// [`hand_rows`] of columns `c` of `n` values each (`SCALED`: `columns.scaled`, the
/// values multiplied by their unit's factor), [`HAND_ROWS`] rows at a time.
#[inline(always)]
fn hand_columns<const SCALED: bool>(
    c: &[&[f64]; Column::COUNT],
    n: usize,
    columns: &ColumnMap,
    handed: &mut u64,
    sink: &mut dyn RowSink,
) -> bool {
    let has = |c: Column| columns.of(c).is_some();
    let (has_v, has_w, has_e, has_temp) = (
        has(Column::Va),
        has(Column::Speed),
        has(Column::Encoder),
        has(Column::Temperature),
    );
    let (k, offset) = (&columns.scale, columns.temp_offset);
    let s = |j: usize, x: f64| if SCALED { x * k[j] } else { x };
    let mut rows = Vec::with_capacity(HAND_ROWS.min(n));
    let mut from = 0;
    while from < n {
        let to = (from + HAND_ROWS).min(n);
        let (t, va, vb, vc) = (
            &c[0][from..to],
            &c[1][from..to],
            &c[2][from..to],
            &c[3][from..to],
        );
        let (ia, ib, ic) = (&c[4][from..to], &c[5][from..to], &c[6][from..to]);
        let (wm, enc, temp) = (&c[7][from..to], &c[8][from..to], &c[9][from..to]);
        rows.clear();
        rows.extend((0..to - from).map(|i| Row {
            t_s: s(0, t[i]),
            v_abc: has_v.then(|| [s(1, va[i]), s(2, vb[i]), s(3, vc[i])]),
            i_abc: [s(4, ia[i]), s(5, ib[i]), s(6, ic[i])],
            wm_rad_s: has_w.then(|| s(7, wm[i])),
            enc_count: has_e.then(|| super::enc_count_of(enc[i])),
            t_winding_c: has_temp.then(|| (temp[i] + offset) * k[9]),
        }));
        if let ControlFlow::Break(stop) = sink.rows(&rows) {
            *handed += stop as u64 + 1;
            return false;
        }
        *handed += rows.len() as u64;
        from = to;
    }
    true
}

/// [`hand_rows`] when a present column is shorter than the group: each row from an array
/// of the row's values, a cell past its column's end keeping the value before.
#[cold]
fn hand_ragged_rows(
    cols: &Decoded,
    columns: &ColumnMap,
    handed: &mut u64,
    on_row: &mut dyn FnMut(&Row) -> bool,
) -> bool {
    let n = cols.iter().find(|c| !c.is_empty()).map_or(0, Vec::len);
    let mut v = [0.0f64; Column::COUNT];
    for i in 0..n {
        for (k, c) in cols.iter().enumerate() {
            if let Some(x) = c.get(i) {
                v[k] = *x;
            }
        }
        *handed += 1;
        if !on_row(&super::source::row_from_values(&v, columns)) {
            return false;
        }
    }
    true
}

/// Decodes row group `g` (its own file handle: the parquet crate's `File` reader seeks a
/// shared file offset, so parallel readers must not share one).
fn decode(path: &Path, g: usize, columns: &ColumnMap) -> Result<Decoded, ParquetError> {
    let r = SerializedFileReader::new(File::open(path)?)?;
    let rg = r.get_row_group(g)?;
    let n = rg.metadata().num_rows().max(0) as usize;
    let mut out: Decoded = Default::default();
    for (k, f) in columns.field.iter().enumerate() {
        let Some(j) = *f else { continue };
        let max_def = rg.metadata().column(j).column_descr().max_def_level();
        out[k] = match rg.get_column_reader(j)? {
            ColumnReader::DoubleColumnReader(mut c) => read_typed(&mut c, n, max_def, |x| x)?,
            ColumnReader::FloatColumnReader(mut c) => read_typed(&mut c, n, max_def, f64::from)?,
            ColumnReader::Int32ColumnReader(mut c) => read_typed(&mut c, n, max_def, f64::from)?,
            ColumnReader::Int64ColumnReader(mut c) => read_typed(&mut c, n, max_def, |x| x as f64)?,
            _ => return Err(ParquetError::General("not a number column".into())),
        };
    }
    Ok(out)
}

/// Reads the `n` records of a flat column as f64; nulls (definition level below `max_def`)
/// become NaN.
fn read_typed<T: DataType>(
    r: &mut ColumnReaderImpl<T>,
    n: usize,
    max_def: i16,
    conv: impl Fn(T::T) -> f64,
) -> Result<Vec<f64>, ParquetError>
where
    T::T: Copy,
{
    let mut vals: Vec<T::T> = Vec::with_capacity(n);
    let mut defs: Vec<i16> = Vec::new();
    let mut records = 0usize;
    while records < n {
        let (got, _, _) = if max_def > 0 {
            r.read_records(n - records, Some(&mut defs), None, &mut vals)?
        } else {
            r.read_records(n - records, None, None, &mut vals)?
        };
        if got == 0 {
            break;
        }
        records += got;
    }
    if max_def == 0 {
        return Ok(vals.into_iter().map(conv).collect());
    }
    let mut it = vals.into_iter();
    Ok(defs
        .iter()
        .map(|&d| {
            if d == max_def {
                it.next().map_or(f64::NAN, &conv)
            } else {
                f64::NAN
            }
        })
        .collect())
}

/// The streaming Parquet writer behind [`super::LogWriter`] for `.parquet` outputs.
pub(super) struct ParquetLogWriter {
    channels: Channels,
    w: SerializedFileWriter<File>,
    t: Vec<f64>,
    /// The FLOAT columns present, in `Column` order, and their values.
    f: Vec<(Column, Vec<f32>)>,
    enc: Vec<i64>,
}

impl ParquetLogWriter {
    /// Starts a file with `channels` into `file`.
    pub fn new(file: File, channels: Channels) -> Result<Self, ParquetError> {
        let f: Vec<(Column, Vec<f32>)> = Column::MEASURED
            .into_iter()
            .filter(|c| channels.has(*c))
            .map(|c| (c, Vec::with_capacity(ROW_GROUP_ROWS)))
            .collect();
        let mut schema = String::from("message log {\n  REQUIRED DOUBLE t_s;\n");
        for (c, _) in &f {
            schema.push_str(&format!("  REQUIRED FLOAT {};\n", c.name()));
        }
        if channels.encoder {
            schema.push_str("  REQUIRED INT64 enc_count;\n");
        }
        schema.push('}');
        let schema = Arc::new(parquet::schema::parser::parse_message_type(&schema)?);
        let props = WriterProperties::builder()
            .set_compression(Compression::UNCOMPRESSED)
            .set_dictionary_enabled(false)
            .set_encoding(Encoding::PLAIN)
            .set_statistics_enabled(EnabledStatistics::Chunk)
            .set_created_by(format!("sim-host {}", env!("CARGO_PKG_VERSION")))
            .build();
        Ok(ParquetLogWriter {
            channels,
            w: SerializedFileWriter::new(file, schema, Arc::new(props))?,
            t: Vec::with_capacity(ROW_GROUP_ROWS),
            f,
            enc: Vec::new(),
        })
    }

    /// The bytes of one row (for size estimates).
    pub fn row_bytes(channels: Channels) -> u64 {
        super::source::binary_row_bytes(channels)
    }

    /// Buffers a row; writes a row group when [`ROW_GROUP_ROWS`] are buffered.
    pub fn write_row(&mut self, r: &Row) -> Result<(), ParquetError> {
        self.t.push(r.t_s);
        for (c, vals) in &mut self.f {
            vals.push(r.value(*c).unwrap_or_default() as f32);
        }
        if self.channels.encoder {
            self.enc.push(r.enc_count.unwrap_or_default());
        }
        if self.t.len() >= ROW_GROUP_ROWS {
            self.flush_group()?;
        }
        Ok(())
    }

    fn flush_group(&mut self) -> Result<(), ParquetError> {
        if self.t.is_empty() {
            return Ok(());
        }
        let mut rg = self.w.next_row_group()?;
        let mut k = 0usize;
        while let Some(mut col) = rg.next_column()? {
            if k == 0 {
                col.typed::<DoubleType>().write_batch(&self.t, None, None)?;
            } else if let Some((_, vals)) = self.f.get(k - 1) {
                col.typed::<FloatType>().write_batch(vals, None, None)?;
            } else {
                col.typed::<Int64Type>()
                    .write_batch(&self.enc, None, None)?;
            }
            col.close()?;
            k += 1;
        }
        rg.close()?;
        self.t.clear();
        self.f.iter_mut().for_each(|(_, v)| v.clear());
        self.enc.clear();
        Ok(())
    }

    /// Writes the last row group and the footer.
    pub fn finish(mut self) -> Result<(), ParquetError> {
        self.flush_group()?;
        self.w.close()?;
        Ok(())
    }
}

#[cfg(test)]
#[path = "parquet_tests.rs"]
mod tests;
