//! Logs held in memory: columns a program hands over (the Python package's DataFrames,
//! Arrow tables and dicts of arrays), read through the same path as a file: the
//! `[columns]` mapping and its units, the same column checks as a Parquet file's
//! ([`super::typed`]), the same [`super::Row`]s for the data-quality stage. Messages name
//! the data as its owner calls it ("DataFrame: missing column 'ia_A'"), never a file.

use super::mapping::ColumnMapping;
use super::source::{BinarySource, ColumnMap, Opened};
use super::typed::FieldType;
use super::{Column, LogError, Row};
use std::sync::Arc;

/// The values of one in-memory column.
#[derive(Debug, Clone, PartialEq)]
pub enum MemoryValues {
    /// Numbers (a missing value is NaN, for the data-quality stage to judge).
    Numbers(Vec<f64>),
    /// A timestamp column: counts of `unit` (`epoch_ms`, `epoch_us` or `epoch_ns`) since
    /// the epoch, as a Parquet `TIMESTAMP` column is read.
    Timestamps {
        /// `epoch_ms`, `epoch_us` or `epoch_ns`.
        unit: &'static str,
        /// The counts (a missing value is NaN).
        values: Vec<f64>,
    },
    /// A column of something else (text, dates, ...): refused if a schema column maps to
    /// it, ignored otherwise.
    Other {
        /// Its type, as the owner names it (for the message).
        type_name: String,
    },
}

impl MemoryValues {
    /// Rows held (none for [`MemoryValues::Other`]).
    fn len(&self) -> Option<usize> {
        match self {
            MemoryValues::Numbers(v) | MemoryValues::Timestamps { values: v, .. } => Some(v.len()),
            MemoryValues::Other { .. } => None,
        }
    }

    fn values(&self) -> &[f64] {
        match self {
            MemoryValues::Numbers(v) | MemoryValues::Timestamps { values: v, .. } => v,
            MemoryValues::Other { .. } => &[],
        }
    }
}

/// A log held in memory: named columns of equal length, in their owner's order.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct MemoryLog {
    columns: Vec<(String, MemoryValues)>,
}

impl MemoryLog {
    /// An empty log (no columns).
    pub fn new() -> Self {
        MemoryLog::default()
    }

    /// Adds the column `name` (after the others).
    pub fn push(&mut self, name: impl Into<String>, values: MemoryValues) {
        self.columns.push((name.into(), values));
    }

    /// The number columns' rows: the first's (0 without any).
    pub fn rows(&self) -> usize {
        self.columns.iter().find_map(|(_, v)| v.len()).unwrap_or(0)
    }

    /// The columns' names, in order.
    pub fn names(&self) -> Vec<String> {
        self.columns.iter().map(|(n, _)| n.clone()).collect()
    }
}

/// An in-memory log opened for reading.
#[derive(Debug, Clone)]
pub(super) struct MemorySource {
    log: Arc<MemoryLog>,
}

impl MemorySource {
    /// Maps the columns of `log` (shown as `shown`) as a Parquet file's are.
    ///
    /// # Errors
    /// [`LogError::NotALog`] for a mapped column that is not numbers, or number columns of
    /// different lengths; [`LogError::MissingColumn`], [`LogError::DuplicateColumn`] and
    /// [`LogError::Unit`] as for a file.
    pub fn open(
        log: Arc<MemoryLog>,
        shown: &str,
        mapping: &ColumnMapping,
    ) -> Result<(Self, ColumnMap), LogError> {
        let n = log.rows();
        if let Some((name, v)) = log
            .columns
            .iter()
            .find(|(_, v)| v.len().is_some_and(|k| k != n))
        {
            return Err(LogError::NotALog {
                path: shown.to_string(),
                why: format!(
                    "column '{name}' has {} rows and the first column {n}: the columns must be of one length",
                    v.len().unwrap_or(0)
                ),
            });
        }
        let found = log.names();
        let types: Vec<FieldType> = log
            .columns
            .iter()
            .map(|(_, v)| match v {
                MemoryValues::Numbers(_) => FieldType {
                    not_numbers: None,
                    timestamp: None,
                },
                MemoryValues::Timestamps { unit, .. } => FieldType {
                    not_numbers: None,
                    timestamp: Some(unit),
                },
                MemoryValues::Other { type_name } => FieldType {
                    not_numbers: Some(type_name.clone()),
                    timestamp: None,
                },
            })
            .collect();
        let held = ("floats or integers", "the data");
        let columns = super::typed::typed_columns(&found, &types, mapping, shown, held)?;
        Ok((MemorySource { log }, columns))
    }
}

/// Rows handed over from the columns in place.
impl BinarySource for MemorySource {
    fn rows(&self) -> u64 {
        self.log.rows() as u64
    }

    fn for_each_row(
        &self,
        log: &Opened<'_>,
        progress: &mut dyn FnMut(f64),
        on_row: &mut dyn FnMut(&Row) -> bool,
    ) -> Result<u64, LogError> {
        let columns = log.columns();
        let cols: [&[f64]; Column::COUNT] = columns.field.map(|f| {
            f.and_then(|j| self.log.columns.get(j))
                .map_or(&[][..], |(_, v)| v.values())
        });
        let n = self.log.rows();
        let mut v = [0.0f64; Column::COUNT];
        for i in 0..n {
            for (x, c) in v.iter_mut().zip(&cols) {
                if let Some(y) = c.get(i) {
                    *x = *y;
                }
            }
            if !on_row(&super::source::row_from_values(&v, columns)) {
                return Ok(i as u64 + 1);
            }
            if (i + 1) % 65_536 == 0 {
                progress((i + 1) as f64 / n as f64);
            }
        }
        Ok(n as u64)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::log::mapping::ChannelUnit;
    use crate::log::{LogFile, LogWriter, OpenOptions};

    /// A short log: a 50 Hz current set, the voltages, the speed.
    fn rows() -> Vec<Row> {
        (0..500)
            .map(|k| {
                let t = k as f64 * 1e-3;
                let ph = |s: f64| 10.0 * (2.0 * std::f64::consts::PI * 50.0 * t + s).sin();
                Row {
                    t_s: t,
                    v_abc: Some([ph(0.0) * 23.0, ph(-2.1) * 23.0, ph(2.1) * 23.0]),
                    i_abc: [ph(0.0), ph(-2.1), ph(2.1)],
                    wm_rad_s: Some(150.0 + t),
                    enc_count: None,
                    t_winding_c: None,
                }
            })
            .collect()
    }

    fn memory_of(rows: &[Row], current_scale: f64) -> MemoryLog {
        let mut m = MemoryLog::new();
        m.push(
            "t_s",
            MemoryValues::Numbers(rows.iter().map(|r| r.t_s).collect()),
        );
        for (p, name) in ["va_V", "vb_V", "vc_V"].iter().enumerate() {
            let v = rows
                .iter()
                .map(|r| r.v_abc.unwrap_or_default()[p])
                .collect();
            m.push(*name, MemoryValues::Numbers(v));
        }
        for (p, name) in ["ia_A", "ib_A", "ic_A"].iter().enumerate() {
            let v = rows.iter().map(|r| r.i_abc[p] * current_scale).collect();
            m.push(*name, MemoryValues::Numbers(v));
        }
        let w = rows
            .iter()
            .map(|r| r.wm_rad_s.unwrap_or_default())
            .collect();
        m.push("wm_rad_s", MemoryValues::Numbers(w));
        m.push(
            "note",
            MemoryValues::Other {
                type_name: "string".into(),
            },
        );
        m
    }

    fn read(f: &LogFile) -> Vec<Row> {
        let mut got: Vec<Row> = Vec::new();
        f.for_each_row(&mut |_| {}, &mut got).unwrap();
        got
    }

    #[test]
    fn data_in_memory_reads_as_the_same_parquet_file() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("a.parquet");
        let mut w = LogWriter::create(
            &path,
            crate::log::Channels {
                voltages: true,
                speed: true,
                encoder: false,
                temperature: false,
            },
        )
        .unwrap();
        for r in rows() {
            w.write_row(&r).unwrap();
        }
        w.finish().unwrap();
        let from_file = read(&LogFile::open(&path).unwrap());
        let mem = memory_of(&from_file, 1.0);
        let f = LogFile::from_memory(Arc::new(mem), "DataFrame", &OpenOptions::default()).unwrap();
        assert_eq!(f.channels(), LogFile::open(&path).unwrap().channels());
        assert_eq!(read(&f), from_file);
    }

    #[test]
    fn the_mapping_and_units_apply_and_errors_name_the_data() {
        let mut mapping = ColumnMapping::new(2);
        for (c, name) in [
            (Column::Ia, "ia_A"),
            (Column::Ib, "ib_A"),
            (Column::Ic, "ic_A"),
        ] {
            mapping
                .set(c, name, Some(ChannelUnit::parse(c, "mA").unwrap()))
                .unwrap();
        }
        let opts = OpenOptions {
            group: None,
            columns: mapping,
        };
        let f = LogFile::from_memory(Arc::new(memory_of(&rows(), 1000.0)), "dict", &opts).unwrap();
        for (a, b) in read(&f).iter().zip(rows()) {
            assert!((a.i_abc[0] - b.i_abc[0]).abs() < 1e-9, "{a:?} {b:?}");
        }
        let mut m = memory_of(&rows(), 1.0);
        m.columns.retain(|(n, _)| n != "ia_A");
        let e = LogFile::from_memory(Arc::new(m), "DataFrame", &OpenOptions::default())
            .unwrap_err()
            .to_string();
        assert!(e.starts_with("DataFrame: missing column 'ia_A'"), "{e}");
        let mut m = memory_of(&rows(), 1.0);
        m.push("t_s2", MemoryValues::Numbers(vec![0.0]));
        let e = LogFile::from_memory(Arc::new(m), "pyarrow Table", &OpenOptions::default())
            .unwrap_err()
            .to_string();
        assert!(e.contains("pyarrow Table: column 't_s2' has 1 rows"), "{e}");
    }
}
