//! `sim-host board-record P.toml --out motor.bin`: the board's motor record (the parameter
//! file's `[motor]` and `[supply]`, the sensor scaling and offsets, the encoder's line count
//! direction and pull-ups) in the layout of `monitor_core::motor_record`, which the firmware reads
//! from its flash page at boot (`docs/firmware.md` has the probe-rs command that writes it).
//! The output is written atomically and is never the input.

use super::output_guard::OutputGuard;
use anyhow::Context;
use clap::Args;
use monitor_api::files::ParamFile;
use monitor_core::motor_record::MotorRecord;
use std::path::PathBuf;

/// Arguments of `board-record`.
#[derive(Debug, Args)]
#[command(
    about = "Write the board's motor record (flash image) from a parameter file",
    long_about = "Write the firmware's motor record: the parameter file's [motor] and [supply], \
the sensor full scales and zero offsets, and the encoder's line count, direction and pull-ups, as the \
132-byte CRC-checked record the firmware reads from flash at boot. The output is written \
atomically and is never the input.\n\nOutput: `wrote FILE (132 bytes)`, or with --json one JSON \
document {out, bytes} on stdout.\n\nExample:\n  sim-host board-record P.toml --out motor.bin"
)]
pub struct BoardRecordArgs {
    /// The parameter file ([motor] and [supply]).
    pub params: PathBuf,
    /// The record to write (atomically; never the input).
    #[arg(long, value_name = "FILE")]
    pub out: PathBuf,
    /// Current sensor full scale [A] (the reading at the ADC's full scale), > 0.
    #[arg(long, default_value_t = 10.0)]
    pub current_full_scale_a: f32,
    /// Voltage sensor full scale [V], > 0.
    #[arg(long, default_value_t = 400.0)]
    pub voltage_full_scale_v: f32,
    /// Zero-current reading of the three phases [ADC counts] (12-bit mid-scale 2047.5).
    #[arg(long, default_value_t = 2047.5)]
    pub current_offset_counts: f32,
    /// Zero-voltage reading of the three phases [ADC counts].
    #[arg(long, default_value_t = 2047.5)]
    pub voltage_offset_counts: f32,
    /// Encoder lines per revolution (quadrature counts are 4 x lines), >= 1.
    #[arg(long, default_value_t = 1024)]
    pub encoder_lines: u16,
    /// The encoder counts down when the motor turns forward.
    #[arg(long)]
    pub encoder_reversed: bool,
    /// The MCU's internal pull-ups on the encoder inputs off (on by default, as an
    /// open-collector encoder needs): for an encoder that drives both levels or a board
    /// with pull-ups of its own.
    #[arg(long)]
    pub encoder_no_pull_up: bool,
    /// Print one JSON document on stdout ({out, bytes}) instead of the line.
    #[arg(long)]
    pub json: bool,
}

/// Runs `board-record`.
///
/// # Errors
/// The parameter file cannot be read or is rejected, a value is out of range, the output
/// is the input, or the write fails.
pub fn run(args: &BoardRecordArgs) -> anyhow::Result<()> {
    OutputGuard::new(&[&args.params]).check_files(&[&args.out])?;
    let params = ParamFile::load(&args.params)?;
    let record = MotorRecord {
        motor: params.motor,
        supply: params.supply,
        current_full_scale_a: args.current_full_scale_a,
        voltage_full_scale_v: args.voltage_full_scale_v,
        current_offset_counts: [args.current_offset_counts; 3],
        voltage_offset_counts: [args.voltage_offset_counts; 3],
        encoder_lines: args.encoder_lines,
        encoder_reversed: args.encoder_reversed,
        encoder_pull_up: !args.encoder_no_pull_up,
    };
    let bytes = record.to_bytes();
    if let Err(e) = MotorRecord::parse(&bytes) {
        anyhow::bail!(
            "{}: the record is rejected by the firmware's parser ({e:?}): check the parameters and options",
            args.params.display()
        );
    }
    monitor_api::files::write_atomic(&args.out, &bytes)
        .with_context(|| format!("writing {}", args.out.display()))?;
    let mut stdout = super::out::stdout();
    if args.json {
        let doc = serde_json::json!({
            "out": args.out.display().to_string(),
            "bytes": bytes.len(),
        });
        super::render::json::print(&mut stdout, &doc)
    } else {
        use std::io::Write;
        writeln!(
            stdout,
            "wrote {} ({} bytes)",
            args.out.display(),
            bytes.len()
        )?;
        Ok(())
    }
}
