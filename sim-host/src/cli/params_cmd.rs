//! `sim-host params ...`: commands that make a parameter file. `params from-nameplate`
//! estimates one from a motor's nameplate (the nameplate estimate of `monitor_api::files::Nameplate`); the output is written
//! atomically and never over an existing file unless `--force`.

use super::output_guard::OutputGuard;
use clap::{Args, Subcommand, ValueEnum};
use monitor_api::files::{Connection, Nameplate, NemaDesign};
use std::io::Write;
use std::path::PathBuf;

/// Arguments of `params`.
#[derive(Debug, Args)]
#[command(
    about = "Make a parameter file (from a nameplate)",
    long_about = "Make a parameter file ([motor] and [supply], docs/design.md section 11).\n\n\
Example:\n  sim-host params from-nameplate --power-kw 2.2 --voltage-v 400 --current-a 4.8 \\\n    \
--frequency-hz 50 --speed-rpm 1438 --power-factor 0.77 --efficiency 0.863 --out P.toml"
)]
pub struct ParamsArgs {
    /// The subcommand.
    #[command(subcommand)]
    pub cmd: ParamsCmd,
}

/// The `params` subcommands. (Plain comments on the variants: clap would take a doc
/// comment as the command's help.)
#[derive(Debug, Subcommand)]
pub enum ParamsCmd {
    // Estimate the T-equivalent circuit from a nameplate.
    FromNameplate(FromNameplateArgs),
}

/// Winding connection on the command line.
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum ConnectionArg {
    /// Star (wye).
    Star,
    /// Delta (the file holds the star equivalent; the winding's own values are 3x).
    Delta,
}

/// NEMA design letter on the command line.
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum DesignArg {
    /// Design A (Xls = Xlr).
    A,
    /// Design B, general purpose, and IEC design N (Xls = 0.4 Xl).
    B,
    /// Design C, double cage (Xls = 0.3 Xl).
    C,
    /// Design D, high slip (Xls = Xlr).
    D,
}

/// Arguments of `params from-nameplate`.
#[derive(Debug, Args)]
#[command(
    about = "Estimate a parameter file from a motor's nameplate (a starting point, with ranges)",
    override_usage = "sim-host params from-nameplate [OPTIONS] --power-kw <KW> --voltage-v <V> --current-a <A>\n       \
--frequency-hz <HZ> --speed-rpm <RPM> --power-factor <PF> --efficiency <ETA>",
    long_about = "Estimate the parameter file of a 3-phase cage induction motor from its \
nameplate: the T-equivalent circuit (Rs, Rr, Lls, Llr, Lm, per phase of the star equivalent), \
the poles, the supply, and the mechanics (J, B, Bl).\n\n\
What a nameplate gives: the rated point (output power, line-to-line voltage, line current, \
frequency, speed, power factor, efficiency). That fixes the impedance at rated slip and the \
rotor copper loss (slip x air-gap power); the rest is closed by typical values, each stated \
in the output with its range:\n  \
- the total leakage: 0.12 of V_ph/I, or, better, from --locked-rotor-ratio (IA/IN from the \
catalogue, or the NEMA code letter);\n  \
- the leakage split by NEMA design (IEEE Std 112);\n  \
- friction and windage 0.5 % of P; iron and stray losses lumped into Rs;\n  \
- J from a catalogue power-size fit (x3 either way; the motor alone), Bl the paper's viscous \
load at rated torque.\n\n\
How far off: on six machines (0.37 kW to 50 hp, docs/own-motor.md) Rs, Rr, the \
total leakage and Lm came within 23 % with IA/IN given (the bar: 35 %); without it, within \
25 % but for the leakage of one atypical machine (+72 %). Real motors add what a nameplate hides (deep bars, saturation, \
temperature): treat the file as a starting point and refine it with a log of the healthy \
motor.\n\n\
Each value is written with its range and source as a TOML comment; --json prints them as \
one JSON document. Without --out the TOML goes to stdout. A nameplate no induction motor can \
have (efficiency or power factor outside 0..1, a speed at or above synchronous, power that \
disagrees with sqrt3 V I pf eta) is refused, naming the option.\n\n\
Example:\n  sim-host params from-nameplate --power-kw 2.2 --voltage-v 400 --current-a 4.8 \\\n    \
--frequency-hz 50 --speed-rpm 1438 --power-factor 0.77 --efficiency 0.863 --out P.toml\n  \
sim-host simulate --params P.toml --scenario S.toml --out D.csv"
)]
pub struct FromNameplateArgs {
    /// Rated output (shaft) power [kW].
    #[arg(long, value_name = "KW")]
    pub power_kw: f64,
    /// Rated line-to-line voltage [V] (for a 230/400 V motor: the one its current is for).
    #[arg(long, value_name = "V")]
    pub voltage_v: f64,
    /// Rated line current [A] at that voltage.
    #[arg(long, value_name = "A")]
    pub current_a: f64,
    /// Rated frequency [Hz].
    #[arg(long, value_name = "HZ")]
    pub frequency_hz: f64,
    /// Rated speed [rpm].
    #[arg(long, value_name = "RPM")]
    pub speed_rpm: f64,
    /// Rated power factor (cos phi, 0..1).
    #[arg(long, value_name = "PF")]
    pub power_factor: f64,
    /// Rated efficiency, a fraction (0.863, not 86.3).
    #[arg(long, value_name = "ETA")]
    pub efficiency: f64,
    /// Number of poles (default: inferred from speed and frequency).
    #[arg(long)]
    pub poles: Option<u32>,
    /// Winding connection (the voltage and current are line values either way).
    #[arg(long, value_enum, default_value_t = ConnectionArg::Star)]
    pub connection: ConnectionArg,
    /// Locked-rotor current over rated current, IA/IN (catalogue or NEMA code letter):
    /// sets the total leakage.
    #[arg(long, value_name = "RATIO")]
    pub locked_rotor_ratio: Option<f64>,
    /// NEMA design letter (the stator/rotor leakage split; IEC design N is B).
    #[arg(long, value_enum, default_value_t = DesignArg::B)]
    pub nema_design: DesignArg,
    /// Carry the [columns] table of this file over (a parameter file of another motor on
    /// the same DAQ, or a file holding the table alone): the log's channel names and units.
    #[arg(long, value_name = "FILE")]
    pub columns_from: Option<PathBuf>,
    /// Write the parameter file here (atomically) instead of printing it.
    #[arg(long, value_name = "FILE")]
    pub out: Option<PathBuf>,
    /// Overwrite --out when it exists.
    #[arg(long)]
    pub force: bool,
    /// Print one JSON document (values, ranges, sources) on stdout.
    #[arg(long)]
    pub json: bool,
}

impl FromNameplateArgs {
    /// The nameplate these arguments give.
    pub fn nameplate(&self) -> Nameplate {
        Nameplate {
            power_kw: self.power_kw,
            voltage_v: self.voltage_v,
            current_a: self.current_a,
            frequency_hz: self.frequency_hz,
            speed_rpm: self.speed_rpm,
            power_factor: self.power_factor,
            efficiency: self.efficiency,
            poles: self.poles,
            connection: match self.connection {
                ConnectionArg::Star => Connection::Star,
                ConnectionArg::Delta => Connection::Delta,
            },
            locked_rotor_ratio: self.locked_rotor_ratio,
            design: match self.nema_design {
                DesignArg::A => NemaDesign::A,
                DesignArg::B => NemaDesign::B,
                DesignArg::C => NemaDesign::C,
                DesignArg::D => NemaDesign::D,
            },
        }
    }
}

/// Runs `params`.
///
/// # Errors
/// As the subcommand.
pub fn run(args: &ParamsArgs) -> anyhow::Result<()> {
    match &args.cmd {
        ParamsCmd::FromNameplate(a) => run_from_nameplate(a),
    }
}

/// Runs `params from-nameplate`.
///
/// # Errors
/// A refused nameplate (one line naming the option), an existing `--out` without
/// `--force`, or a write error.
pub fn run_from_nameplate(args: &FromNameplateArgs) -> anyhow::Result<()> {
    if let Some(out) = &args.out {
        // The command reads no file: the guard has no input to protect, and an existing
        // parameter file (perhaps tuned by hand) is kept unless --force.
        OutputGuard::new(&[]).check_new_file(out, args.force)?;
    }
    let (estimate, toml) =
        monitor_api::params_from_nameplate(&args.nameplate(), args.columns_from.as_deref())?;
    super::out::write_out(args.out.as_deref(), toml.as_bytes())?;
    let mut stdout = super::out::stdout();
    if args.json {
        let doc = monitor_api::nameplate_document(&estimate, &toml, args.out.as_deref());
        writeln!(stdout, "{}", serde_json::to_string_pretty(&doc)?)?;
    } else if let Some(out) = &args.out {
        writeln!(stdout, "wrote {}", out.display())?;
    } else {
        write!(stdout, "{toml}")?;
    }
    Ok(())
}
