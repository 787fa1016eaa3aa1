//! A FAULT never names the wrong fault (issue 79): a month of daily logs of a small
//! high-resistance motor (Rs 24.6 ohm, Rr 17.7 ohm, Lls = Llr = 59.7 mH, Lm 0.977 H, 4 poles,
//! 400 V, 50 Hz: a 0.37 kW machine whose Rs is large against its reactances) whose
//! connection loosens from day 10 (Rs +0.5 % a day, +10 % on day 30), the windings 20-30 K
//! warmer than the parameter file with the season, the load moving every 1.5 s between 42
//! and 78 % of its rated torque (an unknown input), one 12 s log a day at 2 kHz, each judged against the parameter file as the
//! trend's month judges its logs (`diagnose`'s defaults, no commissioning).
//!
//! Before (issue 79; a reviewer's month read `FAULT ls +35 %` and `+38 %` on days 29 and 30):
//! `FAULT ls +49..60 %` on days 22 and 27-29 of the simulator's month and on days 27-29 of
//! the textbook machine's, `ls` named on the way on every other day from day 22. The stator
//! leakage and the windings' heating move this machine's residuals almost alike at light
//! load, and with the loosening on top of the heating `ls` at the file's temperature was the
//! single fault nearest. Now, against the file, a fault is fitted at any temperature of the
//! heating range and ranked only for what it explains beyond the heating: no day names a
//! fault (each is "could not judge: the parameter file does not fit this log", its
//! isolation reading heating); the loosening is Rs beyond Rr, which no single log tells from
//! Rr falling on a warmer winding, and the trend alarms it. A FAULT is Rs or nothing.
//!
//! Held on two models of the machine: this project's simulator (`monitor-sim`) and the
//! independent textbook machine (`monitor_testkit::textbook_machine`, Krause's equations,
//! no code shared with the simulator), driven for the same month. Print the days with
//! `-- --nocapture`.

use monitor_core::verdict::{FaultName, Size, Verdict};
use monitor_core::{Fault, MotorParameters, SupplyParameters};
use monitor_io::params::ParamFile;
use monitor_replay::{DiagnoseReport, IsolationEvent, IsolationName, ReplayOptions};
use monitor_sim::{simulate_to_vec, Scenario};
use monitor_testkit::textbook_machine::{self, Load, Machine};
use rayon::prelude::*;
use std::f64::consts::TAU;

/// The month's days.
const DAYS: std::ops::RangeInclusive<u32> = 1..=30;
/// One log a day: its length [s] and rate [Hz].
const LOG_S: f64 = 12.0;
const RATE_HZ: f64 = 2000.0;
/// The load moves every this many seconds.
const LOAD_EVERY_S: f64 = 1.5;
/// The load's levels (fractions of the motor's Bl, or of its rated torque on the textbook
/// machine: 42-78 % of it, a motor sized with margin), taken in turn from a place that
/// moves with the day. Light load is where the stator leakage and the heating move this
/// machine's residuals most alike.
const LEVELS: [f64; 7] = [0.6, 0.48, 0.72, 0.42, 0.78, 0.54, 0.66];

/// The machine's circuit: Rs, Rr [ohm], Lls = Llr, Lm [H].
const RS: f64 = 24.6;
const RR: f64 = 17.7;
const LL: f64 = 0.0597;
const LM: f64 = 0.977;
/// Its rated point: 370 W at 1375 rpm (2.57 N m), the viscous load's Bl [N m s] there.
const RATED_W: f64 = 370.0;
const RATED_RPM: f64 = 1375.0;
/// J of a 71-frame motor [kg m^2].
const J: f64 = 0.0009;

fn bl_nms() -> f64 {
    let w = TAU * RATED_RPM / 60.0;
    RATED_W / (w * w)
}

/// The parameter file: the machine's values at the file's temperature.
fn params() -> ParamFile {
    let bl = bl_nms();
    ParamFile {
        motor: MotorParameters {
            rs_ohm: RS,
            rr_ohm: RR,
            ls_h: LM + LL,
            lr_h: LM + LL,
            lm_h: LM,
            poles: 4,
            j_kgm2: J,
            b_nms: 0.005 * bl,
            bl_nms: bl,
            rotor_bars: None,
            lm_at: None,
        },
        supply: SupplyParameters {
            v_ll_rms: 400.0,
            f_hz: 50.0,
        },
    }
}

/// The windings' rise above the parameter file's temperature on `day` [K]: 20 to 30 K
/// with the season.
fn season_rise_k(day: u32) -> f64 {
    25.0 + 5.0 * (TAU * f64::from(day) / 30.0).sin()
}

/// The loosening connection's Rs change on `day`: +0.5 % a day from day 10.
fn loosening(day: u32) -> f64 {
    0.005 * f64::from(day.saturating_sub(10))
}

/// The load's level `k` (0: from the log's start) on `day`.
fn level(day: u32, k: usize) -> f64 {
    LEVELS[(k + day as usize) % LEVELS.len()]
}

/// The load steps of a log: (time [s], level).
fn load_steps(day: u32) -> Vec<(f64, f64)> {
    let n = (LOG_S / LOAD_EVERY_S).ceil() as usize;
    (1..n)
        .map(|k| (LOAD_EVERY_S * k as f64, level(day, k)))
        .collect()
}

/// What one day's log said.
#[derive(Debug)]
struct Day {
    day: u32,
    verdict: Verdict,
    /// The verdict's named fault: its name, size and confidence.
    finding: Option<(FaultName, f64, f32)>,
    /// Every name the isolation gave, at the log's end and on the way.
    names: Vec<IsolationName>,
    /// The verdict's line and the isolation's sentence.
    line: String,
    isolation: String,
}

fn day_of(day: u32, r: &DiagnoseReport) -> Day {
    let finding = r.verdict_finding.as_ref().and_then(|f| f.named()).map(|n| {
        let size = match n.size {
            Size::Relative(c) => f64::from(c),
            _ => f64::NAN,
        };
        (n.fault, size, n.confidence)
    });
    let mut names: Vec<IsolationName> = r
        .isolation
        .events
        .iter()
        .filter_map(|e| match e {
            IsolationEvent::Named { name, .. } => Some(*name),
            IsolationEvent::LoadMoved { .. } => None,
        })
        .collect();
    names.extend(r.isolation.named);
    Day {
        day,
        verdict: r.verdict,
        finding,
        names,
        line: monitor_words::diagnose::verdict_line(r, &monitor_words::FieldNames),
        isolation: monitor_words::diagnose::said(&r.isolation.said, &monitor_words::FieldNames),
    }
}

/// Day `day` on this project's simulator: the machine warm by the season from the log's
/// start, the viscous load stepping between the levels, Rs loosened.
fn simulated_day(day: u32) -> Day {
    let p = params();
    let steps: Vec<String> = load_steps(day)
        .iter()
        .map(|(t, l)| format!("{{ t_s = {t}, bl_scale = {l} }}"))
        .collect();
    let mut text = format!(
        "duration_s = {LOG_S}\nsample_rate_hz = {RATE_HZ}\nseed = {}\n[load]\nkind = \"viscous\"\n\
         steps = [{{ t_s = 0.0, bl_scale = {} }}, {}]\n[[effects]]\nname = \"thermal_drift\"\n\
         rise_k = {}\ntau_s = 0.2\nat_s = 0.0\n",
        7_900_000 + u64::from(day),
        level(day, 0),
        steps.join(", "),
        season_rise_k(day)
    );
    if loosening(day) > 0.0 {
        text.push_str(&format!(
            "[[faults]]\nkind = \"rs\"\nat_s = 0.0\nchange = {}\n",
            loosening(day)
        ));
    }
    let sc = Scenario::from_toml_str(&text, "month").expect("scenario"); // ok: test
    let rows = simulate_to_vec(&p, &sc).expect("simulates"); // ok: test
    let r =
        monitor_replay::diagnose_rows(&p, sc.sensors.channels(), &rows, ReplayOptions::default())
            .expect("diagnoses"); // ok: test
    day_of(day, &r)
}

/// The machine for the textbook model, Rs times `rs_factor` (the loosening).
fn textbook(rs_factor: f64) -> Machine {
    let w = TAU * RATED_RPM / 60.0;
    let bl = bl_nms();
    Machine {
        name: "0.37kW high-resistance",
        rs: RS * rs_factor,
        rr: RR,
        lls: LL,
        llr: LL,
        lm: LM,
        poles: 4,
        j: J,
        b: 0.005 * bl,
        bl,
        v_ll_rms: 400.0,
        f_hz: 50.0,
        rated_nm: RATED_W / w,
    }
}

/// Day `day` on the textbook machine: started direct on line, the load a torque stepping
/// between the levels of its rated torque, warm by the season, Rs loosened; its parameter
/// file the machine's nominal values.
fn textbook_day(day: u32, dir: &std::path::Path) -> Day {
    let nominal = textbook(1.0);
    let m = textbook(1.0 + loosening(day));
    let mut s = textbook_machine::Scenario::new(&m, LOG_S, RATE_HZ);
    let rated = m.rated_nm;
    s.load = Load::Torque {
        t0: rated * level(day, 0),
        steps: load_steps(day)
            .into_iter()
            .map(|(t, l)| (t, rated * l))
            .collect(),
    };
    s.hidden.thermal_drift = Some((season_rise_k(day), 0.2));
    s.sensors.seed = 7_950_000 + u64::from(day);
    let log = textbook_machine::write_log(dir, &format!("day{day:02}"), &m, &s);
    let p = ParamFile::from_toml_str(&nominal.params_toml(nominal.bl, 0.0), "textbook")
        .expect("parameter file"); // ok: test
    let r = monitor_replay::diagnose_file(&p, &log, ReplayOptions::default(), &mut |_| {})
        .expect("diagnoses"); // ok: test
    day_of(day, &r.report)
}

/// What is wrong in a month: a FAULT that is not Rs, a FAULT below a confidence of 0.5 or
/// without a size, and any name the isolation gave other than Rs.
fn wrong(month: &[Day]) -> Vec<String> {
    let rs = IsolationName::Fault(Fault::Rs);
    month
        .iter()
        .filter(|d| {
            let fault_wrong = d.verdict == Verdict::Fault
                && !d.finding.is_some_and(|(f, size, p)| {
                    f == FaultName::Table1(Fault::Rs) && size.is_finite() && p >= 0.5
                });
            fault_wrong || d.names.iter().any(|n| *n != rs)
        })
        .map(|d| {
            format!(
                "day {}: {:?} {:?} {:?}: {}",
                d.day, d.verdict, d.finding, d.names, d.line
            )
        })
        .collect()
}

fn print(title: &str, month: &[Day]) {
    eprintln!("{title}");
    for d in month {
        eprintln!(
            "  day {:2} ({:.0} K, Rs +{:.1} %): {:?}, named {:?}: {}\n      isolation: {}",
            d.day,
            season_rise_k(d.day),
            100.0 * loosening(d.day),
            d.verdict,
            d.names,
            d.line,
            d.isolation
        );
    }
}

#[test]
fn the_simulators_month_names_no_wrong_fault() {
    let days: Vec<u32> = DAYS.collect();
    let month: Vec<Day> = days.par_iter().map(|&d| simulated_day(d)).collect();
    print("this project's simulator", &month);
    let bad = wrong(&month);
    assert!(bad.is_empty(), "{bad:#?}");
}

#[test]
fn the_textbook_machines_month_names_no_wrong_fault() {
    let dir = tempfile::tempdir().expect("a temporary folder"); // ok: test
    let days: Vec<u32> = DAYS.collect();
    let month: Vec<Day> = days
        .par_iter()
        .map(|&d| textbook_day(d, dir.path()))
        .collect();
    print("the textbook machine", &month);
    let bad = wrong(&month);
    assert!(bad.is_empty(), "{bad:#?}");
}
