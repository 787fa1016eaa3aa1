//! The files a front end reads and writes, from `monitor-io`: logs (CSV, TDMS, Parquet;
//! [`LogFile`], [`LogWriter`], the `[columns]` table [`ColumnMapping`]), parameter files
//! ([`ParamFile`]), the nameplate estimate ([`Nameplate`]), the near names of a misspelt one ([`near_names`]) and the atomic write every output
//! goes through ([`write_atomic`]), after the one guard against overwriting an input
//! ([`check_outputs`], [`check_output_folder`], [`same_file`]). The command line and the HMI reach them here, not in
//! `monitor-io` itself: this list is what a front end may use.

pub use monitor_io::log::mapping::{load_params, near_names};
pub use monitor_io::log::quality::DataQuality;
pub use monitor_io::log::{
    check_output_folder, check_outputs, same_file, write_atomic, Channels, ColumnMapping, Format,
    LogError, LogFile, LogWriter, MemoryLog, MemoryValues, NamedFile, OpenOptions, OverwriteError,
    Row, RowSink,
};
pub use monitor_io::nameplate::{Connection, Nameplate, NemaDesign};
pub use monitor_io::one_line;
pub use monitor_io::params::ParamFile;
