//! In-memory logs from Python through Arrow's C stream interface: any object with
//! `__arrow_c_stream__` (a pyarrow Table; the package turns a DataFrame or a dict of arrays
//! into one) is imported without a copy through a file, its columns handed to the library
//! as a [`MemoryLog`] (numbers as f64, a null as NaN, timestamps with their unit), read
//! from there through the same path as a file.
//!
//! The import uses the `arrow-array` crate's `ffi` feature only (the C data interface's
//! structures and their release), not the whole `arrow` crate nor `pyo3-arrow` (which
//! brings `arrow` with its compute kernels, `numpy` and `chrono-tz`): the wheel builds no
//! more than it reads.

use arrow_array::cast::AsArray;
use arrow_array::ffi_stream::{FFI_ArrowArrayStream, RecordBatchStreamReader};
use arrow_array::types::{
    Float32Type, Float64Type, Int16Type, Int32Type, Int64Type, Int8Type, UInt16Type, UInt32Type,
    UInt64Type, UInt8Type,
};
use arrow_array::{Array, ArrowPrimitiveType, RecordBatchReader};
use arrow_schema::{DataType, TimeUnit};
use monitor_api::files::{MemoryLog, MemoryValues};
use pyo3::prelude::*;
use pyo3::types::{PyCapsule, PyCapsuleMethods};

/// Data that cannot be read as a log's columns (the package raises it as a `LogError`).
#[derive(Debug, thiserror::Error)]
pub enum ArrowInError {
    /// The object gives no Arrow stream.
    #[error("{origin}: not readable as Arrow data ({why})")]
    NotArrow {
        /// How messages name the data.
        origin: String,
        /// What went wrong.
        why: String,
    },
    /// The stream failed while it was read.
    #[error("{origin}: cannot read its Arrow stream: {why}")]
    Stream {
        /// How messages name the data.
        origin: String,
        /// The stream's error.
        why: String,
    },
    /// A batch's column is of another type than the schema says.
    #[error("{origin}: a batch's column of type {found} differs from the schema's")]
    Batch {
        /// How messages name the data.
        origin: String,
        /// The column's type.
        found: String,
    },
}

fn not_arrow(origin: &str, why: impl ToString) -> ArrowInError {
    ArrowInError::NotArrow {
        origin: origin.to_string(),
        why: why.to_string(),
    }
}

fn stream_error(origin: &str, why: impl ToString) -> ArrowInError {
    ArrowInError::Stream {
        origin: origin.to_string(),
        why: why.to_string(),
    }
}

/// Takes the Arrow stream out of a `arrow_array_stream` capsule (the capsule is left with
/// a released stream, which its destructor ignores).
///
/// # Errors
/// [`ArrowInError::NotArrow`] naming `origin` when the capsule is not an Arrow stream.
#[allow(unsafe_code)]
fn take_stream(
    capsule: &Bound<'_, PyCapsule>,
    origin: &str,
) -> Result<FFI_ArrowArrayStream, ArrowInError> {
    let named = capsule
        .name()
        .ok()
        .flatten()
        .is_some_and(|n| n.to_bytes() == b"arrow_array_stream");
    if !named || capsule.pointer().is_null() {
        return Err(not_arrow(
            origin,
            "__arrow_c_stream__ did not return an Arrow stream",
        ));
    }
    // SAFETY: a capsule named "arrow_array_stream" holds a valid, initialised, aligned
    // `ArrowArrayStream` (the Arrow PyCapsule interface); `from_raw` moves it out and
    // marks the original released, as the C stream interface's "move" prescribes.
    Ok(unsafe { FFI_ArrowArrayStream::from_raw(capsule.pointer().cast()) })
}

/// The values of a primitive array as f64 (a null as NaN), appended to `out`.
fn extend<T: ArrowPrimitiveType>(
    a: &dyn Array,
    out: &mut Vec<f64>,
    conv: impl Fn(T::Native) -> f64,
) {
    let p = a.as_primitive::<T>();
    if p.null_count() == 0 {
        out.extend(p.values().iter().map(|v| conv(*v)));
    } else {
        out.extend(p.iter().map(|v| v.map_or(f64::NAN, &conv)));
    }
}

/// Appends `a`'s values to `out`; `None` for a type that does not hold numbers.
fn append(a: &dyn Array, out: &mut Vec<f64>) -> Option<()> {
    match a.data_type() {
        DataType::Float64 => extend::<Float64Type>(a, out, |v| v),
        DataType::Float32 => extend::<Float32Type>(a, out, f64::from),
        DataType::Int64 => extend::<Int64Type>(a, out, |v| v as f64),
        DataType::Int32 => extend::<Int32Type>(a, out, f64::from),
        DataType::Int16 => extend::<Int16Type>(a, out, f64::from),
        DataType::Int8 => extend::<Int8Type>(a, out, f64::from),
        DataType::UInt64 => extend::<UInt64Type>(a, out, |v| v as f64),
        DataType::UInt32 => extend::<UInt32Type>(a, out, f64::from),
        DataType::UInt16 => extend::<UInt16Type>(a, out, f64::from),
        DataType::UInt8 => extend::<UInt8Type>(a, out, f64::from),
        _ => append_timestamps(a, out)?,
    }
    Some(())
}

/// The unit of a timestamp type (`epoch_s` ... `epoch_ns`).
fn timestamp_unit(t: &DataType) -> Option<&'static str> {
    match t {
        DataType::Timestamp(u, _) => Some(match u {
            TimeUnit::Second => "epoch_s",
            TimeUnit::Millisecond => "epoch_ms",
            TimeUnit::Microsecond => "epoch_us",
            TimeUnit::Nanosecond => "epoch_ns",
        }),
        _ => None,
    }
}

/// The counts of a timestamp array as f64 (a null as NaN), appended to `out`; `None` for
/// another type.
fn append_timestamps(a: &dyn Array, out: &mut Vec<f64>) -> Option<()> {
    use arrow_array::types::{
        TimestampMicrosecondType as Us, TimestampMillisecondType as Ms,
        TimestampNanosecondType as Ns, TimestampSecondType as S,
    };
    match a.data_type() {
        DataType::Timestamp(TimeUnit::Second, _) => extend::<S>(a, out, |v| v as f64),
        DataType::Timestamp(TimeUnit::Millisecond, _) => extend::<Ms>(a, out, |v| v as f64),
        DataType::Timestamp(TimeUnit::Microsecond, _) => extend::<Us>(a, out, |v| v as f64),
        DataType::Timestamp(TimeUnit::Nanosecond, _) => extend::<Ns>(a, out, |v| v as f64),
        _ => return None,
    }
    Some(())
}

/// True for the types [`append`] reads.
fn holds_numbers(t: &DataType) -> bool {
    use DataType::*;
    matches!(
        t,
        Float64 | Float32 | Int64 | Int32 | Int16 | Int8 | UInt64 | UInt32 | UInt16 | UInt8
    ) || timestamp_unit(t).is_some()
}

/// The log held by `data` (an object with `__arrow_c_stream__`), named `origin` in
/// messages ("DataFrame", "pyarrow Table", "dict").
///
/// # Errors
/// [`ArrowInError`] naming `origin` when `data` has no Arrow stream or the stream fails.
pub fn memory_log(data: &Bound<'_, PyAny>, origin: &str) -> Result<MemoryLog, ArrowInError> {
    let capsule = data
        .call_method0("__arrow_c_stream__")
        .map_err(|e| not_arrow(origin, e))?;
    let capsule = capsule
        .downcast::<PyCapsule>()
        .map_err(|_| not_arrow(origin, "__arrow_c_stream__ did not return a capsule"))?;
    let stream = take_stream(capsule, origin)?;
    let reader = RecordBatchStreamReader::try_new(stream).map_err(|e| stream_error(origin, e))?;
    let schema = reader.schema();
    let fields = schema.fields();
    let mut values: Vec<Option<Vec<f64>>> = fields
        .iter()
        .map(|f| holds_numbers(f.data_type()).then(Vec::new))
        .collect();
    for batch in reader {
        let batch = batch.map_err(|e| stream_error(origin, e))?;
        for (col, out) in batch.columns().iter().zip(values.iter_mut()) {
            let Some(out) = out else { continue };
            append(col.as_ref(), out).ok_or_else(|| ArrowInError::Batch {
                origin: origin.to_string(),
                found: col.data_type().to_string(),
            })?;
        }
    }
    let mut log = MemoryLog::new();
    for (f, v) in fields.iter().zip(values) {
        let kind = match (v, timestamp_unit(f.data_type())) {
            (Some(values), Some(unit)) => MemoryValues::Timestamps { unit, values },
            (Some(v), None) => MemoryValues::Numbers(v),
            (None, _) => MemoryValues::Other {
                type_name: f.data_type().to_string(),
            },
        };
        log.push(f.name().clone(), kind);
    }
    Ok(log)
}
