//! `sim-host demo`: the main job in a few seconds ([`monitor_studies::demo`]).

use super::render;
use clap::Args;
use monitor_core::Fault;

/// Arguments of `demo`.
#[derive(Debug, Args)]
#[command(
    about = "The main job: a motor in service, a load step, a fault, the lamps and the fault named",
    long_about = "Simulate the 3 hp reference motor started direct-on-line with realistic sensors \
(12-bit ADC, noise, 1024-line encoder) and replay the sensor streams through the same core the \
firmware runs, printing a timeline of the residual lamps r1..r4, the panel's state and the fault \
candidates.\n\nThe default run is a day in service: the monitor learns the healthy motor \
(commissioning, 2-4 s); the load rises 40 % at 5 s and falls back at 6.5 s, shown as what it is (the \
amber MOVED state and a load move, no fault: the load is an unknown input); the stator resistance \
rises 50 % at 8.5 s, and the lamps light red and the fault is named with its size. --fault and \
--change choose another fault for 8.5 s.\n\n--paper runs the paper's protocol instead: one Table 1 \
fault at 5 s (default: the load friction Bl +50 %) on the paper's fixed viscous load, under which a \
Bl change is a fault.\n\nExamples:\n  sim-host demo\n  sim-host demo --fault lr --change -0.5\n  \
sim-host demo --paper"
)]
pub struct DemoArgs {
    /// Fault to inject: rs, rr, ls, lr, b, bl, current_sensor, voltage_sensor, speed_sensor
    /// (default: rs; with --paper: bl).
    #[arg(long, value_parser = super::args::parse_fault)]
    pub fault: Option<Fault>,
    /// Relative change, -0.95..5 (0.5 = +50 %; sensor faults: gain error).
    #[arg(long, default_value_t = 0.5, allow_negative_numbers = true, value_parser = parse_change)]
    pub change: f64,
    /// The paper's protocol: one fault at 5 s on its fixed viscous load (no load step).
    #[arg(long)]
    pub paper: bool,
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
    use monitor_studies::demo::DemoStory;
    let story = if args.paper {
        DemoStory::Paper {
            fault: args.fault.unwrap_or(Fault::Bl),
            change: args.change,
        }
    } else {
        DemoStory::Service {
            fault: args.fault.unwrap_or(Fault::Rs),
            change: args.change,
        }
    };
    let run = monitor_studies::demo::run(story)?;
    if args.json {
        render::json::print(&mut crate::cli::out::stdout(), &render::json::demo(&run))
    } else {
        render::text::demo(&mut crate::cli::out::text(), &run)
    }
}
