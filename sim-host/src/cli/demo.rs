//! `sim-host demo`: the main job in a few seconds ([`sim_host::demo`]).

use super::render;
use clap::Args;
use monitor_core::Fault;

/// Arguments of `demo`.
#[derive(Debug, Args)]
#[command(
    about = "The main job: simulate a motor, inject a fault mid-run, watch the lamps and the named fault",
    long_about = "Simulate the 3 hp reference motor started direct-on-line with the paper's \
viscous load and realistic sensors (12-bit ADC, noise, 1024-line encoder), replay the sensor streams \
through the same core the firmware runs, learn the healthy residuals (commissioning, 2-4 s), inject a \
fault at 5 s and print a timeline of the residual lamps r1..r4 and the fault candidates of the paper's \
Table 1.\n\nExample:\n  sim-host demo --fault lr --change -0.5"
)]
pub struct DemoArgs {
    /// Fault to inject: rs, rr, ls, lr, b, bl, current_sensor, voltage_sensor, speed_sensor.
    #[arg(long, default_value = "bl", value_parser = super::parse_fault)]
    pub fault: Fault,
    /// Relative change, -0.95..5 (0.5 = +50 %; sensor faults: gain error).
    #[arg(long, default_value_t = 0.5, allow_negative_numbers = true, value_parser = parse_change)]
    pub change: f64,
    /// Print one JSON document on stdout instead of the timeline.
    #[arg(long)]
    pub json: bool,
}

fn parse_change(s: &str) -> Result<f64, String> {
    let x: f64 = s
        .trim()
        .parse()
        .map_err(|_| format!("'{s}' is not a number"))?;
    if x > -0.95 && x < 5.0 {
        Ok(x)
    } else {
        Err(format!("{x} is outside -0.95..5"))
    }
}

/// Runs `demo`.
///
/// # Errors
/// Simulator errors (not expected for the reference motor) or an I/O error on stdout.
pub fn run(args: &DemoArgs) -> anyhow::Result<()> {
    let run = sim_host::demo::run(args.fault, args.change)?;
    if args.json {
        render::json::print(&render::json::demo(&run))
    } else {
        render::text::demo(&run)
    }
}
