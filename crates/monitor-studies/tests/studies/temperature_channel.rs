//! A log with a winding-temperature channel (`t_winding_c`): the isolation compensates Rs
//! and Rr with the measured rise since commissioning (copper 0.393 %/K) instead of inferring
//! it from the residuals, and does not use a channel that lies (`monitor_replay`,
//! "Heating is not a fault" in docs/isolation.md).
//!
//! The motors (the 3 hp and 2.2 kW reference motors and a 0.37 kW machine) are commissioned
//! cold over 1.5-3.5 s; from 4 s their windings warm by 60 or 100 K with a thermal time
//! constant of 20-30 s (the simulator's `thermal_drift`; at most 5 K/s, a locked rotor's
//! adiabatic heating); the channel is a probe of 2 s time constant, sampled and held every
//! second, 0.1 K of noise:
//! - no fault named, and the reported rise within 5 K of the winding's true rise at the end
//!   of the log (the probe lags by its 2 s plus half the hold: 1.5 K at the end);
//! - an Rs +30 % fault on the warm motor named with its size against the warm Rs;
//! - a channel that sticks or breaks (NaN) is said to be not used, and the result is no
//!   worse than without the channel;
//! - a probe on the frame, reading a constant 15 K below the winding, gives the same
//!   verdict and rise (only the rise counts);
//! - the column read under a DAQ's own name in degF and K;
//! - the simulated probe is slow (one reading a hold period, lagging the winding) and
//!   leaves every other column as it was.
//!
//! Twelve 40-70 s replays at 2 kHz: a few seconds in the test profile on 2 cores.

use crate::small_motor;

use monitor_core::Fault;
use monitor_io::log::{ChannelUnit, Column, ColumnMapping, LogFile, OpenOptions, Row};
use monitor_io::params::ParamFile;
use monitor_replay::{DiagnoseReport, IsolationName, Verdict};
use monitor_sim::{Scenario, SensorSpec, TemperatureSpec};
use rayon::prelude::*;

/// Copper's temperature coefficient [1/K] (IEC 60228).
const ALPHA: f64 = 0.00393;

/// Warming from 4 s by `rise_k` with time constant `tau_s`, over `duration_s` at 2 kHz;
/// `fault` on top; `probe` the temperature channel (none: no column).
fn run(
    p: &ParamFile,
    duration_s: f64,
    (rise_k, tau_s): (f64, f64),
    fault: Option<(Fault, f64, f64)>,
    probe: Option<TemperatureSpec>,
) -> DiagnoseReport {
    let mut sc = Scenario::steady(duration_s, 2000.0);
    sc.sensors = SensorSpec {
        temperature: probe,
        ..SensorSpec::default()
    };
    sc.seed = 11;
    small_motor::replay_warming(p, sc, (rise_k, tau_s), fault)
}

/// The winding's true rise at `t_s` (heating from 4 s).
fn rise_at(rise_k: f64, tau_s: f64, t_s: f64) -> f64 {
    rise_k * (1.0 - (-(t_s - 4.0) / tau_s).exp())
}

/// A probe in the winding (the simulator's defaults: 20 degC at the start, 2 s, 1 s hold).
fn probe() -> TemperatureSpec {
    TemperatureSpec::default()
}

fn summary(r: &DiagnoseReport) -> String {
    let i = &r.isolation;
    format!(
        "{:?}, named {:?} {:?} (first {:?}), rise {:?} (tracked {:?}), {:?} at {:?} degC",
        r.verdict,
        i.named,
        i.named_change,
        i.first_named.map(|g| (g.name.to_string(), g.t_s)),
        i.temperature.measured_rise_k,
        i.winding_rise_k,
        i.temperature.temperature_channel,
        i.temperature.winding_temperature_c
    )
}

#[test]
fn warming_with_a_temperature_channel_is_a_measured_rise_not_a_fault() {
    let cases: Vec<(&str, ParamFile, f64, f64)> = small_motor::three_motors()
        .into_iter()
        .flat_map(|(n, p)| [(n, p, 60.0, 20.0), (n, p, 100.0, 30.0)])
        .collect();
    let bad: Vec<String> = cases
        .par_iter()
        .filter_map(|(name, p, rise, tau)| {
            let end = 60.0;
            let r = run(p, end, (*rise, *tau), None, Some(probe()));
            let truth = rise_at(*rise, *tau, end);
            let line = format!(
                "{name} +{rise} K tau {tau} s ({truth:.1} K): {}",
                summary(&r)
            );
            eprintln!("{line}");
            let t = &r.isolation.temperature;
            let ok = r.verdict != Verdict::Fault
                && r.isolation.named.is_none()
                && t.temperature_channel == Some(monitor_replay::ChannelUse::Used)
                && t
                    .measured_rise_k
                    .is_some_and(|m| (f64::from(m) - truth).abs() <= 5.0)
                // The reading is the winding's: 20 degC plus the rise.
                && t
                    .winding_temperature_c
                    .is_some_and(|c| (f64::from(c) - 20.0 - truth).abs() <= 5.0);
            (!ok).then_some(line)
        })
        .collect();
    assert!(bad.is_empty(), "{bad:#?}");
}

#[test]
fn an_rs_fault_on_a_warm_motor_is_named_against_the_warm_rs() {
    let bad: Vec<String> = small_motor::three_motors()
        .par_iter()
        .filter_map(|(name, p)| {
            // Warm by 60 K (tau 20 s: 55 K at 55 s, still rising), Rs +30 % at 55 s.
            let r = run(
                p,
                66.0,
                (60.0, 20.0),
                Some((Fault::Rs, 55.0, 0.3)),
                Some(probe()),
            );
            let line = format!("{name} warm, rs +30 %: {}", summary(&r));
            eprintln!("{line}");
            // The size is against the warm Rs: a fit against the cold Rs would read
            // (1.3 (1 + alpha 55) - 1) = +58 %.
            let c = f64::from(r.isolation.named_change.unwrap_or(f32::NAN));
            let rs = r
                .candidates
                .iter()
                .find(|c| c.fault == Fault::Rs)
                .map(|c| (c.probability, f64::from(c.change.unwrap_or(f32::NAN))));
            let cold_size = 1.3 * (1.0 + ALPHA * rise_at(60.0, 20.0, 55.0)) - 1.0;
            assert!(cold_size > 0.5, "{cold_size}");
            // On the 3 hp motor Rs is 1.6 % of the impedance: one operating point leaves
            // rs shared with the voltage sensor and friction (as on a cold motor), so no
            // name reaches the confidence a FAULT needs: WATCHING (never healthy) with rs
            // among the candidates. On the 2.2 kW motor the probe's lag (the temperature is
            // known to a few kelvin) leaves rs at p 0.5-0.9 beside the voltage sensor
            // (issue 48's calibrated probability): named, or the same.
            let named_rs = r.isolation.named == Some(IsolationName::Fault(Fault::Rs))
                && (c - 0.3).abs() <= 0.075;
            let shared = matches!(r.verdict, Verdict::Fault | Verdict::Watching)
                && r.isolation.named.is_none()
                && rs.is_some_and(|(p, c)| p >= 0.2 && (c - 0.3).abs() <= 0.075);
            let ok = match *name {
                "0.37 kW" => named_rs,
                _ => named_rs || shared,
            };
            (!ok).then_some(line)
        })
        .collect();
    assert!(bad.is_empty(), "{bad:#?}");
}

#[test]
fn a_channel_that_lies_is_not_used_and_does_no_harm() {
    let liars = [
        (
            "stuck from 6 s",
            TemperatureSpec {
                stuck_at_s: Some(6.0),
                ..probe()
            },
        ),
        (
            "NaN from 20 s",
            TemperatureSpec {
                lost_at_s: Some(20.0),
                ..probe()
            },
        ),
    ];
    let motors: Vec<(&str, ParamFile)> = small_motor::three_motors()
        .into_iter()
        .filter(|(n, _)| *n != "0.37 kW")
        .collect();
    let bad: Vec<String> = motors
        .par_iter()
        .flat_map(|(name, p)| {
            let heat = (60.0, 20.0);
            let without = run(p, 60.0, heat, None, None);
            eprintln!("{name} without a channel: {}", summary(&without));
            liars
                .iter()
                .filter_map(|(what, spec)| {
                    let r = run(p, 60.0, heat, None, Some(spec.clone()));
                    let line = format!("{name} channel {what}: {}", summary(&r));
                    eprintln!("{line}");
                    let said = r
                        .isolation
                        .temperature
                        .temperature_channel
                        .is_some_and(|s| matches!(s, monitor_replay::ChannelUse::NotUsed { .. }));
                    // No worse: no fault named where the run without the channel names
                    // none, no FAULT verdict where it has none, and the rise the
                    // resistances track within 15 K of the truth where it is.
                    let truth = rise_at(heat.0, heat.1, 60.0);
                    let close = |r: &DiagnoseReport| {
                        r.isolation
                            .winding_rise_k
                            .is_some_and(|s| (f64::from(s) - truth).abs() <= 15.0)
                    };
                    let ok = said
                        && (r.isolation.named.is_none() || without.isolation.named.is_some())
                        && (r.verdict != Verdict::Fault || without.verdict == Verdict::Fault)
                        && (close(&r) || !close(&without));
                    (!ok).then_some(line)
                })
                .collect::<Vec<_>>()
        })
        .collect();
    assert!(bad.is_empty(), "{bad:#?}");
}

#[test]
fn a_frame_probe_offset_by_a_constant_gives_the_same_verdict() {
    let (_, p) = small_motor::three_motors()
        .into_iter()
        .find(|(n, _)| *n == "2.2 kW")
        .expect("2.2 kW");
    let heat = (80.0, 25.0);
    let winding = run(&p, 50.0, heat, None, Some(probe()));
    let frame = run(
        &p,
        50.0,
        heat,
        None,
        Some(TemperatureSpec {
            start_c: 25.0,
            offset_k: -15.0,
            ..probe()
        }),
    );
    eprintln!(
        "winding probe: {}\nframe probe: {}",
        summary(&winding),
        summary(&frame)
    );
    assert_eq!(frame.verdict, winding.verdict);
    assert_eq!(frame.isolation.named, winding.isolation.named);
    assert_eq!(
        frame.isolation.temperature.temperature_channel,
        Some(monitor_replay::ChannelUse::Used)
    );
    let rise =
        |r: &DiagnoseReport| f64::from(r.isolation.temperature.measured_rise_k.expect("rise"));
    assert!(
        (rise(&frame) - rise(&winding)).abs() <= 1.0,
        "only the rise counts"
    );
    // The readings differ by the frame's offset and the start's 5 K.
    let reading =
        |r: &DiagnoseReport| f64::from(r.isolation.temperature.winding_temperature_c.expect("c"));
    assert!((reading(&frame) - reading(&winding) + 10.0).abs() <= 1.0);
}

/// The column under a DAQ's own name and unit, through the `[columns]` table's mapping:
/// degF and K are converted to degC (68 degF and 293.15 K are 20 degC); without a mapping
/// the column is looked up by its schema name; a log without it has no temperature.
#[test]
fn the_column_is_read_in_the_daqs_units() {
    let dir = tempfile::tempdir().expect("tmp");
    let read = |text: &str, mapping: ColumnMapping| -> Vec<Row> {
        let path = dir.path().join("t.csv");
        std::fs::write(&path, text).expect("write");
        let opts = OpenOptions {
            columns: mapping,
            ..OpenOptions::default()
        };
        let file = LogFile::open_with(&path, &opts).expect("open");
        let mut rows: Vec<Row> = Vec::new();
        file.for_each_row(&mut |_| {}, &mut rows).expect("rows");
        rows
    };
    let text = "t_s,ia_A,ib_A,ic_A,Temp\n0,1,2,3,68\n0.001,1,2,3,212\n";
    for (unit, want) in [
        (ChannelUnit::DegF, [20.0, 100.0]),
        (ChannelUnit::DegC, [68.0, 212.0]),
    ] {
        let mut m = ColumnMapping::new(2);
        m.set(Column::Temperature, "Temp", Some(unit)).expect("map");
        let rows = read(text, m);
        for (r, w) in rows.iter().zip(want) {
            let c = r.t_winding_c.expect("temperature");
            assert!((c - w).abs() < 1e-9, "{unit:?}: {c} for {w}");
        }
    }
    let mut m = ColumnMapping::new(2);
    m.set(Column::Temperature, "Temp", Some(ChannelUnit::Kelvin))
        .expect("map");
    let rows = read("t_s,ia_A,ib_A,ic_A,Temp\n0,1,2,3,293.15\n", m);
    assert!((rows[0].t_winding_c.expect("c") - 20.0).abs() < 1e-9);
    // The schema's name, in degC; and no column, no temperature.
    let rows = read(
        "t_s,ia_A,ib_A,ic_A,t_winding_c\n0,1,2,3,41.5\n",
        ColumnMapping::default(),
    );
    assert_eq!(rows[0].t_winding_c, Some(41.5));
    let rows = read("t_s,ia_A,ib_A,ic_A\n0,1,2,3\n", ColumnMapping::default());
    assert_eq!(rows[0].t_winding_c, None);
    // Every column of the schema at once, on the fast path and (a quoted cell) the exact one.
    let all = "t_s,va_V,vb_V,vc_V,ia_A,ib_A,ic_A,wm_rad_s,enc_count,t_winding_c\n";
    for line in ["0,1,2,3,4,5,6,7,8,41.5\n", "0,1,2,3,4,5,6,7,\"8\",41.5\n"] {
        let rows = read(&format!("{all}{line}{line}"), ColumnMapping::default());
        assert_eq!(rows.len(), 2, "{line}");
        assert_eq!(rows[1].enc_count, Some(8), "{line}");
        assert_eq!(rows[1].t_winding_c, Some(41.5), "{line}");
    }
    // A temperature cannot be given in a current's unit, nor a current in degC.
    let mut m = ColumnMapping::new(2);
    assert!(m
        .set(Column::Temperature, "Temp", Some(ChannelUnit::Amperes))
        .is_err());
    assert!(m.set(Column::Ia, "Ia", Some(ChannelUnit::DegC)).is_err());
    assert!(ChannelUnit::parse(Column::Temperature, "degF").is_ok());
    assert!(ChannelUnit::parse(Column::Temperature, "rpm").is_err());
}

/// The simulated channel is a slow probe: a new reading at most once a hold period, lagging
/// the winding (start temperature plus the `thermal_drift` rise) by no more than its time
/// constant and hold times the warming rate; asking for it leaves every other column as it
/// was (its noise has a stream of its own).
#[test]
fn the_simulated_channel_is_a_slow_probe_and_leaves_the_other_columns_alone() {
    use monitor_sim::{simulate, EffectSpec};
    let p = ParamFile::reference_2p2kw();
    let rows = |probe: Option<TemperatureSpec>| {
        let mut sc = Scenario::steady(10.0, 2000.0);
        sc.sensors = SensorSpec {
            temperature: probe,
            ..SensorSpec::default()
        };
        sc.effects.push(
            toml::from_str::<EffectSpec>(
                "name = \"thermal_drift\"\nrise_k = 60.0\ntau_s = 20.0\nat_s = 4.0\n",
            )
            .expect("effect"),
        );
        let mut out: Vec<Row> = Vec::new();
        simulate(&p, &sc, |r: &Row| out.push(*r)).expect("simulate");
        out
    };
    let plain = rows(None);
    let with = rows(Some(probe()));
    assert_eq!(plain.len(), with.len());
    for (a, b) in plain.iter().zip(&with) {
        assert_eq!(a.t_winding_c, None);
        assert_eq!(
            *a,
            Row {
                t_winding_c: None,
                ..*b
            }
        );
    }
    let readings: Vec<f64> = with.iter().map(|r| r.t_winding_c.expect("t")).collect();
    let changes = readings.windows(2).filter(|w| w[0] != w[1]).count();
    assert!(
        changes <= 10,
        "a new reading once a second: {changes} changes in 10 s"
    );
    let last = *readings.last().expect("rows");
    let t_end = with.last().expect("rows").t_s;
    let winding = 20.0 + rise_at(60.0, 20.0, t_end);
    let rate = 60.0 / 20.0 * (-(t_end - 4.0) / 20.0f64).exp();
    let max_lag = rate * (2.0 + 1.0);
    assert!(
        last <= winding + 0.5 && last >= winding - max_lag - 0.5,
        "reading {last:.2} degC, winding {winding:.2} degC, lag at most {max_lag:.1} K"
    );
}
