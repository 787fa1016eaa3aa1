//! The Parquet mirror: one small file per stored row in a Hive-style partitioned dataset,
//! `PATH.parquet/motor=<id>/day=<YYYY-MM-DD>/<id hash>.parquet`, the layout pandas, pyarrow,
//! Dask and Spark read as one table (`motor` and `day` come from the folders' names and are
//! not repeated inside the files). Each file is written under a temporary name in its
//! folder and renamed, so a reader never sees half a file.

use crate::error::HistoryError;
use crate::row::{content_hash, Cell, Kind, StoredRow, COLUMNS};
use parquet::basic::Compression;
use parquet::data_type::{ByteArray, ByteArrayType, DoubleType, Int64Type};
use parquet::file::properties::WriterProperties;
use parquet::file::writer::SerializedFileWriter;
use std::path::{Path, PathBuf};
use std::sync::Arc;

/// The partition columns (folder names, not inside the files).
pub const PARTITIONS: [&str; 2] = ["motor", "day"];

/// The suffix of a file being written.
const TEMP_SUFFIX: &str = ".parquet.tmp";

/// The mirror's folder of the store at `store`: its path with `.parquet` added.
pub fn dir_of(store: &Path) -> PathBuf {
    let mut s = store.as_os_str().to_owned();
    s.push(".parquet");
    PathBuf::from(s)
}

/// A partition value as a folder name: bytes other than ASCII letters, digits, `-`, `_`
/// and `.` percent-encoded (pyarrow's Hive partitioning decodes them).
pub fn encode_segment(v: &str) -> String {
    let mut out = String::new();
    for b in v.bytes() {
        if b.is_ascii_alphanumeric() || b"-_.".contains(&b) {
            out.push(char::from(b));
        } else {
            out.push_str(&format!("%{b:02X}"));
        }
    }
    out
}

/// The mirror file of `row` under `dir`.
pub fn file_of(dir: &Path, row: &StoredRow) -> PathBuf {
    dir.join(format!(
        "motor={}",
        encode_segment(row.str("motor").unwrap_or_default())
    ))
    .join(format!("day={}", row.str("day").unwrap_or_default()))
    .join(format!("{}.parquet", content_hash(row.log_id().as_bytes())))
}

/// Writes `row`'s file (temporary name, then renamed).
///
/// # Errors
/// [`HistoryError::Mirror`] when the folder or the file cannot be written.
pub fn write_row(dir: &Path, row: &StoredRow) -> Result<(), HistoryError> {
    let path = file_of(dir, row);
    let bad = |p: &Path, m: String| HistoryError::Mirror {
        path: p.display().to_string(),
        message: m,
    };
    let folder = path.parent().unwrap_or(dir);
    std::fs::create_dir_all(folder).map_err(|e| bad(folder, e.to_string()))?;
    let tmp = path.with_extension("parquet.tmp");
    let file = std::fs::File::create(&tmp).map_err(|e| bad(&tmp, e.to_string()))?;
    write_file(file, row).map_err(|e| bad(&tmp, e.to_string()))?;
    std::fs::rename(&tmp, &path).map_err(|e| bad(&path, e.to_string()))
}

/// The Parquet schema of the kept columns (all but the partitions), all optional.
fn schema_of(kept: &[(usize, Kind)]) -> String {
    let mut schema = String::from("message stored_row {\n");
    for (i, kind) in kept {
        let name = COLUMNS.get(*i).map_or("", |c| c.name);
        schema.push_str(&match kind {
            Kind::Text => format!("  OPTIONAL BYTE_ARRAY {name} (UTF8);\n"),
            Kind::Int => format!("  OPTIONAL INT64 {name};\n"),
            Kind::Real => format!("  OPTIONAL DOUBLE {name};\n"),
        });
    }
    schema.push('}');
    schema
}

/// Writes one cell (a column of one row, or a null of the column's `kind`).
fn write_cell(
    col: &mut parquet::file::writer::SerializedColumnWriter<'_>,
    cell: &Cell,
    kind: Kind,
) -> Result<(), parquet::errors::ParquetError> {
    let def = [i16::from(!matches!(cell, Cell::Null))];
    match (cell, kind) {
        (Cell::Text(t), _) => col.typed::<ByteArrayType>().write_batch(
            &[ByteArray::from(t.as_str())],
            Some(&def),
            None,
        )?,
        (Cell::Int(v), _) => col
            .typed::<Int64Type>()
            .write_batch(&[*v], Some(&def), None)?,
        (Cell::Real(v), _) => col
            .typed::<DoubleType>()
            .write_batch(&[*v], Some(&def), None)?,
        (Cell::Null, Kind::Text) => {
            col.typed::<ByteArrayType>()
                .write_batch(&[], Some(&def), None)?
        }
        (Cell::Null, Kind::Int) => col
            .typed::<Int64Type>()
            .write_batch(&[], Some(&def), None)?,
        (Cell::Null, Kind::Real) => col
            .typed::<DoubleType>()
            .write_batch(&[], Some(&def), None)?,
    };
    Ok(())
}

fn write_file(
    file: std::fs::File,
    row: &StoredRow,
) -> Result<(), Box<dyn std::error::Error + Send + Sync>> {
    let kept: Vec<(usize, Kind)> = COLUMNS
        .iter()
        .enumerate()
        .filter(|(_, c)| !PARTITIONS.contains(&c.name))
        .map(|(i, c)| (i, c.kind))
        .collect();
    let schema = Arc::new(parquet::schema::parser::parse_message_type(&schema_of(
        &kept,
    ))?);
    let props = WriterProperties::builder()
        .set_compression(Compression::UNCOMPRESSED)
        .set_created_by(format!("monitor-store {}", env!("CARGO_PKG_VERSION")))
        .build();
    let mut w = SerializedFileWriter::new(file, schema, Arc::new(props))?;
    let mut rg = w.next_row_group()?;
    let mut k = 0usize;
    while let Some(mut col) = rg.next_column()? {
        let (i, kind) = kept.get(k).copied().unwrap_or((usize::MAX, Kind::Real));
        write_cell(&mut col, row.cells.get(i).unwrap_or(&Cell::Null), kind)?;
        col.close()?;
        k += 1;
    }
    rg.close()?;
    w.close()?;
    Ok(())
}

/// Removes the temporary files a killed run left under `dir`.
///
/// # Errors
/// [`HistoryError::Mirror`] when the folder cannot be listed or a file removed.
pub fn remove_temporaries(dir: &Path) -> Result<(), HistoryError> {
    if !dir.is_dir() {
        return Ok(());
    }
    let bad = |p: &Path, e: std::io::Error| HistoryError::Mirror {
        path: p.display().to_string(),
        message: e.to_string(),
    };
    let mut stack = vec![dir.to_path_buf()];
    while let Some(d) = stack.pop() {
        for entry in std::fs::read_dir(&d).map_err(|e| bad(&d, e))? {
            let p = entry.map_err(|e| bad(&d, e))?.path();
            if p.is_dir() {
                stack.push(p);
            } else if p.to_string_lossy().ends_with(TEMP_SUFFIX) {
                std::fs::remove_file(&p).map_err(|e| bad(&p, e))?;
            }
        }
    }
    Ok(())
}
