//! The streaming TDMS writer ([`TdmsLogWriter`]): one segment per [`SEGMENT_ROWS`] rows,
//! little-endian, format version 4713 (the layout: [`super`]).

use super::{GROUP, SEGMENT_ROWS};
use crate::log::{Channels, Column, Row};
use std::fs::File;
use std::io::{BufWriter, Write};

/// The streaming TDMS writer behind [`crate::log::LogWriter`] for `.tdms` outputs: rows are
/// buffered per channel and written as one segment per [`SEGMENT_ROWS`] rows.
pub(in crate::log) struct TdmsLogWriter {
    channels: Channels,
    t: Vec<f64>,
    /// Voltages a, b, c, currents a, b, c, speed (the SGL channels, in `Column` order).
    f: [Vec<f32>; 7],
    enc: Vec<i64>,
    /// Segments written so far.
    segments: u64,
    /// The present SGL channels: (column, index into `f`).
    sgl: Vec<(Column, usize)>,
}

/// Appends a TDMS string (u32 length, UTF-8 bytes).
fn put_str(b: &mut Vec<u8>, s: &str) {
    b.extend_from_slice(&(s.len() as u32).to_le_bytes());
    b.extend_from_slice(s.as_bytes());
}

/// Appends a DBL property.
fn put_f64_property(b: &mut Vec<u8>, name: &str, x: f64) {
    put_str(b, name);
    b.extend_from_slice(&10u32.to_le_bytes());
    b.extend_from_slice(&x.to_le_bytes());
}

impl TdmsLogWriter {
    /// A writer for a log with `channels`.
    pub fn new(channels: Channels) -> Self {
        let sgl = Column::MEASURED
            .into_iter()
            .enumerate()
            .filter(|(_, c)| channels.has(*c))
            .map(|(k, c)| (c, k))
            .collect();
        TdmsLogWriter {
            channels,
            t: Vec::with_capacity(SEGMENT_ROWS),
            f: Default::default(),
            enc: Vec::new(),
            segments: 0,
            sgl,
        }
    }

    /// The bytes of one row (for size estimates).
    pub fn row_bytes(channels: Channels) -> u64 {
        crate::log::source::binary_row_bytes(channels)
    }

    /// Buffers a row; writes a segment when [`SEGMENT_ROWS`] are buffered.
    pub fn write_row<W: Write>(&mut self, out: &mut W, r: &Row) -> std::io::Result<()> {
        self.t.push(r.t_s);
        let v = r.v_abc.unwrap_or_default();
        let vals = [
            v[0],
            v[1],
            v[2],
            r.i_abc[0],
            r.i_abc[1],
            r.i_abc[2],
            r.wm_rad_s.unwrap_or_default(),
        ];
        for &(_, k) in &self.sgl {
            self.f[k].push(vals[k] as f32);
        }
        if self.channels.encoder {
            self.enc.push(r.enc_count.unwrap_or_default());
        }
        if self.t.len() >= SEGMENT_ROWS {
            self.flush_segment(out)?;
        }
        Ok(())
    }

    /// Writes the buffered rows as one segment (nothing when none are buffered, except an
    /// empty log's one metadata segment, so that the file names its channels).
    pub fn flush_segment<W: Write>(&mut self, out: &mut W) -> std::io::Result<()> {
        let n = self.t.len();
        if n == 0 && self.segments > 0 {
            return Ok(());
        }
        let meta = self.metadata(n);
        let raw_len = n as u64 * Self::row_bytes(self.channels);
        out.write_all(&lead_in(meta.len() as u64, raw_len))?;
        out.write_all(&meta)?;
        self.write_raw(out)?;
        self.t.clear();
        self.f.iter_mut().for_each(Vec::clear);
        self.enc.clear();
        self.segments += 1;
        Ok(())
    }

    /// The segment's channels in writing order: (column, TDMS data type: 10 DBL, 9 SGL,
    /// 4 I64).
    fn segment_channels(&self) -> Vec<(Column, u32)> {
        let mut chans: Vec<(Column, u32)> = vec![(Column::Time, 10)];
        chans.extend(self.sgl.iter().map(|&(c, _)| (c, 9)));
        if self.channels.encoder {
            chans.push((Column::Encoder, 4));
        }
        chans
    }

    /// The waveform properties (`wf_start_offset` [s], `wf_increment` [s]) the first
    /// segment carries, from its times; (0, 0) for later segments and when no rate is known.
    fn waveform(&self) -> (f64, f64) {
        if self.segments > 0 {
            return (0.0, 0.0);
        }
        let rate = crate::log::sample_rate_hz(&self.t);
        (
            self.t.first().copied().unwrap_or(0.0),
            rate.map_or(0.0, |r| 1.0 / r),
        )
    }

    /// The segment's metadata for `n` rows: in the first segment the root and group objects
    /// too, and on every channel the waveform properties when an increment is known.
    fn metadata(&self, n: usize) -> Vec<u8> {
        let first = self.segments == 0;
        let chans = self.segment_channels();
        let (start, increment) = self.waveform();
        let mut meta = Vec::new();
        let objects = chans.len() as u32 + if first { 2 } else { 0 };
        meta.extend_from_slice(&objects.to_le_bytes());
        if first {
            for path in ["/".to_string(), format!("/'{GROUP}'")] {
                put_str(&mut meta, &path);
                meta.extend_from_slice(&u32::MAX.to_le_bytes());
                meta.extend_from_slice(&0u32.to_le_bytes());
            }
        }
        for (c, ty) in &chans {
            put_str(&mut meta, &format!("/'{GROUP}'/'{}'", c.name()));
            meta.extend_from_slice(&20u32.to_le_bytes());
            meta.extend_from_slice(&ty.to_le_bytes());
            meta.extend_from_slice(&1u32.to_le_bytes());
            meta.extend_from_slice(&(n as u64).to_le_bytes());
            if first && increment > 0.0 {
                meta.extend_from_slice(&2u32.to_le_bytes());
                put_f64_property(&mut meta, "wf_increment", increment);
                put_f64_property(&mut meta, "wf_start_offset", start);
            } else {
                meta.extend_from_slice(&0u32.to_le_bytes());
            }
        }
        meta
    }

    /// Writes the buffered raw data, channel after channel (time, SGL channels, encoder).
    fn write_raw<W: Write>(&self, out: &mut W) -> std::io::Result<()> {
        let mut raw = Vec::with_capacity(8 * self.t.len());
        for x in &self.t {
            raw.extend_from_slice(&x.to_le_bytes());
        }
        out.write_all(&raw)?;
        for &(_, k) in &self.sgl {
            raw.clear();
            for x in &self.f[k] {
                raw.extend_from_slice(&x.to_le_bytes());
            }
            out.write_all(&raw)?;
        }
        raw.clear();
        for x in &self.enc {
            raw.extend_from_slice(&x.to_le_bytes());
        }
        out.write_all(&raw)
    }
}

/// A segment's lead-in (28 bytes) for `meta_len` bytes of metadata and `raw_len` of raw
/// data: tag, ToC (metadata, new object list, raw data), version 4713, lengths.
fn lead_in(meta_len: u64, raw_len: u64) -> Vec<u8> {
    let mut lead = Vec::with_capacity(28);
    lead.extend_from_slice(b"TDSm");
    // kTocMetaData | kTocNewObjList | kTocRawData
    lead.extend_from_slice(&((1u32 << 1) | (1 << 2) | (1 << 3)).to_le_bytes());
    lead.extend_from_slice(&4713u32.to_le_bytes());
    lead.extend_from_slice(&(meta_len + raw_len).to_le_bytes());
    lead.extend_from_slice(&meta_len.to_le_bytes());
    lead
}

/// Convenience for tests and [`crate::log::LogWriter`]: flush the last segment into a buffered
/// file.
pub(in crate::log) fn finish(
    w: &mut TdmsLogWriter,
    out: &mut BufWriter<File>,
) -> std::io::Result<()> {
    w.flush_segment(out)?;
    out.flush()
}
