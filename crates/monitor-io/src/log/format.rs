//! A log's file format ([`Format`]), by the file's extension.

/// A log's file format, chosen by the file's extension (case-insensitive): `.tdms` is TDMS,
/// `.parquet` or `.pq` Parquet, anything else CSV (`.csv`, `.txt`, none).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Format {
    /// Comma-separated text with a header row (the schema of `docs/design.md`).
    Csv,
    /// NI TDMS, one group of channels.
    Tdms,
    /// Apache Parquet, one number column per channel.
    Parquet,
}

impl Format {
    /// Every format.
    pub const ALL: [Format; 3] = [Format::Csv, Format::Tdms, Format::Parquet];

    /// The format of a path, by its extension.
    pub fn of_path(path: &std::path::Path) -> Format {
        let ext = path
            .extension()
            .and_then(|e| e.to_str())
            .map(str::to_ascii_lowercase)
            .unwrap_or_default();
        match ext.as_str() {
            "tdms" => Format::Tdms,
            "parquet" | "pq" => Format::Parquet,
            _ => Format::Csv,
        }
    }

    /// The format's name ("CSV", "TDMS", "Parquet").
    pub fn name(self) -> &'static str {
        match self {
            Format::Csv => "CSV",
            Format::Tdms => "TDMS",
            Format::Parquet => "Parquet",
        }
    }

    /// The usual extension, without the dot.
    pub fn extension(self) -> &'static str {
        match self {
            Format::Csv => "csv",
            Format::Tdms => "tdms",
            Format::Parquet => "parquet",
        }
    }
}
