//! TDMS logs (NI LabVIEW's Technical Data Management Streaming format): read through the
//! `tdms-rs` crate, written by a small streaming writer of our own ([`TdmsLogWriter`]).
//!
//! Reading: the channels of one group, named like the CSV columns ([`Column::name`]); the
//! group is the file's only group or the one `--group` names (several groups and none named:
//! an error listing them). The time is the `t_s` channel, or else the waveform properties
//! LabVIEW writes on each channel, `wf_start_offset + k * wf_increment` [s] (taken from
//! `ia_A`). The log's start, where LabVIEW wrote it, is a channel's `wf_start_time` (a TDMS
//! timestamp: seconds since 1904-01-01 UTC and a fraction of 2^-64 s; the time channel's,
//! else `ia_A`'s, else the first channel's that has one; [`super::LogFile::start_time`]).
//! Numeric channels of any width are read as f64. Layouts `tdms-rs` does not read
//! (big-endian, interleaved or DAQmx raw data, incremental metadata, several chunks in one
//! segment) are refused with one line naming the layout, rather than read wrongly: NI's
//! "TDMS Defragment" rewrites such a file into the plain layout.
//!
//! Writing: one segment per [`SEGMENT_ROWS`] rows (lead-in, metadata, raw data, channel
//! after channel), little-endian, format version 4713; `t_s` as DBL, the voltages, currents
//! and speed as SGL (the precision of every writer, see [`super::LogWriter`]), `enc_count`
//! as I64. Every channel carries `wf_increment` and `wf_start_offset` (from the first
//! segment's times), so LabVIEW and DIAdem show a time axis.

use super::source::{not_a_log, BinarySource, ColumnMap, OpenOptions, Opened};
use super::{Column, LogError, Row};
use std::fs::File;
use std::io::{Read, Seek, SeekFrom};
use std::path::Path;
use tdms_rs::{DataType, PropertyValue, TdmsFile};

mod writer;
pub(super) use writer::{finish, TdmsLogWriter};

/// Rows per written segment.
pub const SEGMENT_ROWS: usize = 1 << 16;
/// Rows per read pass over the channels.
const READ_ROWS: usize = 1 << 16;
/// The group the writer puts the channels in.
pub const GROUP: &str = "log";

/// Where the time of a TDMS log comes from.
#[derive(Debug, Clone, Copy, PartialEq)]
enum TimeSource {
    /// The `t_s` channel.
    Channel,
    /// `start + k * increment` [s].
    Waveform { start: f64, increment: f64 },
}

/// A TDMS log opened for reading: its group, channel names and time source.
#[derive(Debug, Clone)]
pub(super) struct TdmsSource {
    group: String,
    time: TimeSource,
    rows: u64,
    /// The group's `wf_start_time` [s since 1970-01-01 UTC], if a channel has one.
    start_utc_s: Option<f64>,
}

/// Seconds from 1904-01-01 (LabVIEW's epoch) to 1970-01-01.
const LABVIEW_TO_UNIX_S: i64 = 2_082_844_800;

/// A TDMS timestamp property as seconds since 1970-01-01 UTC; `None` for another type and
/// for the zero timestamp (LabVIEW's "not set").
fn unix_seconds(p: &PropertyValue) -> Option<f64> {
    match p {
        PropertyValue::TimeStamp((secs, frac)) if (*secs, *frac) != (0, 0) => {
            Some((secs - LABVIEW_TO_UNIX_S) as f64 + *frac as f64 / 18_446_744_073_709_551_616.0)
        }
        _ => None,
    }
}

/// The `wf_start_time` of group `g`: the time channel's, else `ia_A`'s, else the first
/// channel's that has one [s since 1970-01-01 UTC].
fn start_time(g: &tdms_rs::TdmsGroup<'_>, mapping: &super::ColumnMapping) -> Option<f64> {
    let of = |ch: &tdms_rs::TdmsChannel<'_>| ch.property("wf_start_time").and_then(unix_seconds);
    [Column::Time, Column::Ia]
        .iter()
        .find_map(|c| g.channel(mapping.name_of(*c)).as_ref().and_then(of))
        .or_else(|| g.channels().find_map(|ch| of(&ch)))
}

fn tdms_error(shown: &str, e: &tdms_rs::TdmsError) -> LogError {
    not_a_log(
        shown,
        format!(
            "not a readable TDMS file: {}",
            crate::one_line(&e.to_string())
        ),
    )
}

/// A property as a number (seconds for the waveform properties).
fn number(p: &PropertyValue) -> Option<f64> {
    Some(match p {
        PropertyValue::Double(x) => *x,
        PropertyValue::Float(x) => f64::from(*x),
        PropertyValue::I32(x) => f64::from(*x),
        PropertyValue::I64(x) => *x as f64,
        PropertyValue::U32(x) => f64::from(*x),
        PropertyValue::U64(x) => *x as f64,
        _ => return None,
    })
}

/// A TDMS file too short for what its segments declare, as [`LogError::NotALog`]
/// (`why`: what is missing).
fn truncated(shown: &str, why: String) -> LogError {
    not_a_log(
        shown,
        format!("the TDMS file is truncated: {why} (an interrupted recording or copy; re-export it, or rewrite it with LabVIEW's TDMS Defragment)"),
    )
}

/// A TDMS layout not read here (`what`: "big-endian data", ...), as [`LogError::NotALog`].
fn refused_layout(shown: &str, what: &str) -> LogError {
    not_a_log(
        shown,
        format!("TDMS with {what} is not read here: rewrite it with LabVIEW's TDMS Defragment (one plain segment layout) or convert it to CSV or Parquet"),
    )
}

/// One segment's lead-in (28 bytes).
struct LeadIn {
    /// The table-of-contents mask (kTocMetaData = bit 1, ...).
    mask: u32,
    /// Bytes after the lead-in (`u64::MAX`: up to the end of the file).
    next: u64,
    /// Offset of the raw data in the bytes after the lead-in.
    raw_off: u64,
}

impl LeadIn {
    /// Parses the lead-in at byte `pos`.
    ///
    /// # Errors
    /// [`LogError::NotALog`] without the `TDSm` tag, or for a layout `tdms-rs` would misread
    /// (big-endian, interleaved or DAQmx raw data, incremental metadata).
    fn parse(lead: &[u8; 28], pos: u64, shown: &str) -> Result<Self, LogError> {
        if &lead[0..4] != b"TDSm" {
            return Err(not_a_log(
                shown,
                format!("not a TDMS file: no segment tag at byte {pos}"),
            ));
        }
        let word = |i: usize| u32::from_le_bytes([lead[i], lead[i + 1], lead[i + 2], lead[i + 3]]);
        let long = |i: usize| {
            let mut b = [0u8; 8];
            b.copy_from_slice(&lead[i..i + 8]);
            u64::from_le_bytes(b)
        };
        let mask = word(4);
        if mask & (1 << 6) != 0 {
            return Err(refused_layout(shown, "big-endian data"));
        }
        if mask & (1 << 5) != 0 {
            return Err(refused_layout(shown, "interleaved data"));
        }
        if mask & (1 << 7) != 0 {
            return Err(refused_layout(shown, "DAQmx raw data"));
        }
        if mask & (1 << 1) != 0 && mask & (1 << 2) == 0 {
            return Err(refused_layout(shown, "incremental metadata"));
        }
        Ok(LeadIn {
            mask,
            next: long(12),
            raw_off: long(20),
        })
    }
}

/// Refuses the layouts `tdms-rs` would misread and files that end early: walks the
/// segments' lead-ins (28 bytes each, [`LeadIn`]); returns the bytes of raw data they hold
/// ([`check_chunks`] compares them with the channels' lengths).
fn walk_segments(path: &Path, shown: &str) -> Result<u64, LogError> {
    let io = |source| LogError::Io {
        path: shown.to_string(),
        source,
    };
    let mut f = File::open(path).map_err(io)?;
    let len = f.metadata().map_err(io)?.len();
    if len == 0 {
        return Err(not_a_log(shown, "the TDMS file is empty (0 bytes)".into()));
    }
    if len < 28 {
        return Err(truncated(
            shown,
            format!("{len} bytes, shorter than one segment's 28-byte lead-in"),
        ));
    }
    let mut pos = 0u64;
    let mut raw = 0u64;
    while pos + 28 <= len {
        f.seek(SeekFrom::Start(pos)).map_err(io)?;
        let mut lead = [0u8; 28];
        f.read_exact(&mut lead).map_err(io)?;
        let LeadIn {
            mask,
            next,
            raw_off,
        } = LeadIn::parse(&lead, pos, shown)?;
        if next != u64::MAX && (pos + 28).saturating_add(next) > len {
            return Err(truncated(shown, format!(
                "the segment at byte {pos} declares {next} bytes after its lead-in, the file has {} more",
                len - pos - 28
            )));
        }
        let end = if next == u64::MAX {
            len
        } else {
            pos + 28 + next
        };
        if mask & (1 << 3) != 0 {
            raw += end.saturating_sub(pos + 28 + raw_off);
        }
        pos = end;
    }
    if pos < len {
        return Err(truncated(
            shown,
            format!(
                "{} bytes after the last segment, less than a lead-in",
                len - pos
            ),
        ));
    }
    Ok(raw)
}

/// Refuses a file whose raw data (`raw` bytes, [`walk_segments`]) is not exactly what the
/// channels' lengths account for (several data chunks in a segment).
fn check_chunks(shown: &str, raw: u64, file: &TdmsFile) -> Result<(), LogError> {
    let mut expected = 0u64;
    for g in file.groups() {
        for c in g.channels() {
            let size = c.dtype().itemsize() as u64;
            if size == 0 {
                // A string channel: its size is not known from the length; skip the check.
                return Ok(());
            }
            expected += size * c.len() as u64;
        }
    }
    if raw != expected {
        return Err(refused_layout(shown, "several data chunks in a segment"));
    }
    Ok(())
}

/// The group to read: `group` when the file has it, else the file's only group.
///
/// # Errors
/// [`LogError::NotALog`] for a group that is not there or a file without groups;
/// [`LogError::Group`] for several groups and none named (the message lists them).
fn pick_group(names: &[String], group: Option<&str>, shown: &str) -> Result<String, LogError> {
    let listed = || {
        names
            .iter()
            .map(|n| format!("'{n}'"))
            .collect::<Vec<_>>()
            .join(", ")
    };
    match group {
        Some(g) if names.iter().any(|n| n == g) => Ok(g.to_string()),
        Some(g) => Err(not_a_log(
            shown,
            format!("no group '{g}' in the file (its groups: {})", listed()),
        )),
        None => match names {
            [one] => Ok(one.clone()),
            [] => Err(not_a_log(shown, "the TDMS file has no group".into())),
            _ => Err(LogError::Group {
                path: shown.to_string(),
                given: None,
                why: format!("the TDMS file has several groups ({})", listed()),
            }),
        },
    }
}

/// The unit channel `ch` (column `c`) is read in ([`super::mapping::resolve_unit`]: the
/// mapping's, checked against the channel's `unit_string`).
///
/// # Errors
/// [`LogError::NotALog`] for a channel that does not hold numbers; [`LogError::Unit`] as
/// `resolve_unit`.
fn channel_unit(
    ch: &tdms_rs::TdmsChannel<'_>,
    c: Column,
    mapping: &super::ColumnMapping,
    shown: &str,
) -> Result<Option<super::ChannelUnit>, LogError> {
    if ch.dtype().itemsize() == 0 || matches!(ch.dtype(), DataType::TimeStamp | DataType::Boolean) {
        return Err(not_a_log(
            shown,
            format!(
                "channel '{}' holds {:?} values, not numbers",
                ch.name(),
                ch.dtype()
            ),
        ));
    }
    let recorded = match ch.property("unit_string") {
        Some(PropertyValue::String(u)) => Some(u.as_str()),
        _ => None,
    };
    super::mapping::resolve_unit(shown, c, ch.name(), mapping.unit_of(c), recorded)
}

/// The units of the mapped channels of a group ([`channel_unit`]), indexed like
/// [`Column::ALL`], and their (name, length) in that order.
type ChannelFacts = (
    [Option<super::ChannelUnit>; Column::COUNT],
    Vec<(String, usize)>,
);

/// The units and lengths of the mapped channels of group `g` ([`ChannelFacts`]).
///
/// # Errors
/// As [`channel_unit`].
fn channel_facts(
    g: &tdms_rs::TdmsGroup<'_>,
    columns: &ColumnMap,
    mapping: &super::ColumnMapping,
    shown: &str,
) -> Result<ChannelFacts, LogError> {
    let mut lens = Vec::new();
    let mut units = [None; Column::COUNT];
    for (k, c) in Column::ALL.iter().enumerate() {
        if columns.field[k].is_none() {
            continue;
        }
        let Some(ch) = g.channel(&columns.names[k]) else {
            continue;
        };
        units[k] = channel_unit(&ch, *c, mapping, shown)?;
        lens.push((columns.names[k].clone(), ch.len()));
    }
    Ok((units, lens))
}

/// Where the time of group `g` comes from: the mapped time channel, else the waveform
/// properties of the mapped `ia_A` channel (`wf_increment` > 0 [s]).
///
/// # Errors
/// [`LogError::MissingColumn`] when neither is there (naming a channel that has
/// `wf_increment` under another name, if one does).
fn time_source(
    g: &tdms_rs::TdmsGroup<'_>,
    columns: &ColumnMap,
    mapping: &super::ColumnMapping,
    found: &[String],
    shown: &str,
) -> Result<TimeSource, LogError> {
    if columns.of(Column::Time).is_some() {
        return Ok(TimeSource::Channel);
    }
    let wave = g.channel(mapping.name_of(Column::Ia)).and_then(|ch| {
        let inc = ch.property("wf_increment").and_then(number)?;
        let start = ch
            .property("wf_start_offset")
            .and_then(number)
            .unwrap_or(0.0);
        (inc.is_finite() && inc > 0.0).then_some(TimeSource::Waveform {
            start,
            increment: inc,
        })
    });
    if let Some(w) = wave {
        return Ok(w);
    }
    // A channel timed by its waveform properties under another name: say so.
    let elsewhere = g
        .channels()
        .find(|ch| ch.property("wf_increment").is_some())
        .map(|ch| {
            format!(
                "; channel '{}' has wf_increment: map it to ia_A in [columns] and the time comes from it",
                ch.name()
            )
        })
        .unwrap_or_default();
    Err(super::mapping::missing_column(
        shown,
        Column::Time,
        mapping,
        found,
        &format!(
            "every analysis needs the time: a {} channel, or wf_increment on {}{elsewhere}",
            mapping.name_of(Column::Time),
            mapping.name_of(Column::Ia)
        ),
    ))
}

/// The rows of group `group`: the common length of its channels (`lens`: name, length).
///
/// # Errors
/// [`LogError::NotALog`] for channels of different lengths.
fn common_length(lens: &[(String, usize)], group: &str, shown: &str) -> Result<usize, LogError> {
    let rows = lens.first().map(|l| l.1).unwrap_or(0);
    if let Some((n, l)) = lens.iter().find(|l| l.1 != rows) {
        return Err(not_a_log(
            shown,
            format!(
                "channels of different lengths in group '{group}': {} has {rows} values, {n} {l}",
                lens[0].0
            ),
        ));
    }
    Ok(rows)
}

impl TdmsSource {
    /// Opens `path`: picks the group, maps the schema's channels and the time source.
    ///
    /// # Errors
    /// [`LogError::NotALog`] for a file `tdms-rs` cannot read, a layout it would misread,
    /// several groups and none named (the message lists them), a group that is not there,
    /// channels of different lengths or of a non-numeric type;
    /// [`LogError::MissingColumn`] as for a CSV log (the time may instead come from
    /// `wf_increment`).
    pub fn open(
        path: &Path,
        shown: &str,
        opts: &OpenOptions,
    ) -> Result<(Self, ColumnMap), LogError> {
        let mapping = &opts.columns;
        let raw = walk_segments(path, shown)?;
        let file = TdmsFile::open(path).map_err(|e| tdms_error(shown, &e))?;
        check_chunks(shown, raw, &file)?;
        let names: Vec<String> = file.groups().map(|g| g.name().to_string()).collect();
        let name = pick_group(&names, opts.group.as_deref(), shown)?;
        let g = file
            .group(&name)
            .ok_or_else(|| not_a_log(shown, format!("no group '{name}'")))?;
        let found: Vec<String> = g.channels().map(|c| c.name().to_string()).collect();
        let mut columns = ColumnMap::locate(&found, mapping, shown)?;
        let (units, lens) = channel_facts(&g, &columns, mapping, shown)?;
        let time = time_source(&g, &columns, mapping, &found, shown)?;
        super::source::check_columns(
            &columns,
            shown,
            time == TimeSource::Channel,
            mapping,
            &found,
        )?;
        // (The waveform time is in seconds: wf_increment's unit.)
        columns.set_units(&units, mapping);
        let rows = common_length(&lens, &name, shown)?;
        let start_utc_s = start_time(&g, mapping);
        Ok((
            TdmsSource {
                group: name,
                time,
                rows: rows as u64,
                start_utc_s,
            },
            columns,
        ))
    }
}

impl TdmsSource {
    /// The log's start from a channel's `wf_start_time` [s since 1970-01-01 UTC].
    pub(super) fn start_utc_s(&self) -> Option<f64> {
        self.start_utc_s
    }
}

/// The group's channels read a segment at a time.
impl BinarySource for TdmsSource {
    fn rows(&self) -> u64 {
        self.rows
    }

    fn for_each_row(
        &self,
        log: &Opened<'_>,
        progress: &mut dyn FnMut(f64),
        on_row: &mut dyn FnMut(&Row) -> bool,
    ) -> Result<u64, LogError> {
        let (path, shown, columns) = (log.path(), log.shown(), log.columns());
        let file = TdmsFile::open(path).map_err(|e| tdms_error(shown, &e))?;
        let g = file
            .group(&self.group)
            .ok_or_else(|| not_a_log(shown, format!("no group '{}'", self.group)))?;
        let chans: Vec<Option<tdms_rs::TdmsChannel<'_>>> = (0..Column::ALL.len())
            .map(|k| columns.field[k].and_then(|_| g.channel(&columns.names[k])))
            .collect();
        let n = self.rows as usize;
        let mut cols: Vec<Vec<f64>> = vec![Vec::new(); Column::ALL.len()];
        let mut handed = 0u64;
        let mut start = 0usize;
        while start < n {
            let end = (start + READ_ROWS).min(n);
            for (k, ch) in chans.iter().enumerate() {
                if let Some(ch) = ch {
                    read_f64(ch, start..end, &mut cols[k]).map_err(|e| tdms_error(shown, &e))?;
                }
            }
            let mut v = [0.0f64; Column::COUNT];
            for i in 0..end - start {
                for (k, c) in cols.iter().enumerate() {
                    if let Some(x) = c.get(i) {
                        v[k] = *x;
                    }
                }
                if let TimeSource::Waveform {
                    start: t0,
                    increment,
                } = self.time
                {
                    v[0] = t0 + (start + i) as f64 * increment;
                }
                handed += 1;
                if !on_row(&super::source::row_from_values(&v, columns)) {
                    return Ok(handed);
                }
            }
            progress(end as f64 / n.max(1) as f64);
            start = end;
        }
        Ok(handed)
    }
}

/// Reads `range` of a numeric channel into `out` as f64.
fn read_f64(
    ch: &tdms_rs::TdmsChannel<'_>,
    range: std::ops::Range<usize>,
    out: &mut Vec<f64>,
) -> Result<(), tdms_rs::TdmsError> {
    fn typed<T: tdms_rs::api::reader::Pod + Default + Into<f64>>(
        ch: &tdms_rs::TdmsChannel<'_>,
        range: std::ops::Range<usize>,
        out: &mut Vec<f64>,
    ) -> Result<(), tdms_rs::TdmsError> {
        let mut buf = vec![T::default(); range.len()];
        ch.read(range, &mut buf)?;
        out.clear();
        out.extend(buf.into_iter().map(Into::into));
        Ok(())
    }
    match ch.dtype() {
        DataType::Double => typed::<f64>(ch, range, out),
        DataType::Float => typed::<f32>(ch, range, out),
        DataType::I8 => typed::<i8>(ch, range, out),
        DataType::I16 => typed::<i16>(ch, range, out),
        DataType::I32 => typed::<i32>(ch, range, out),
        DataType::U8 => typed::<u8>(ch, range, out),
        DataType::U16 => typed::<u16>(ch, range, out),
        DataType::U32 => typed::<u32>(ch, range, out),
        DataType::I64 => {
            let mut buf = vec![0i64; range.len()];
            ch.read(range, &mut buf)?;
            out.clear();
            out.extend(buf.into_iter().map(|x| x as f64));
            Ok(())
        }
        DataType::U64 => {
            let mut buf = vec![0u64; range.len()];
            ch.read(range, &mut buf)?;
            out.clear();
            out.extend(buf.into_iter().map(|x| x as f64));
            Ok(())
        }
        _ => Err(tdms_rs::TdmsError::TypeMismatch),
    }
}
