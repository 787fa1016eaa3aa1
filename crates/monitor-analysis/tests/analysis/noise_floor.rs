//! The full-order model at the noise floor (issue 23): on effect-free noisy logs with a
//! direct-on-line start, V/f steps and a supply voltage step, at 2, 5 and 10 kHz, the four
//! dynamics effects bring `compare`'s whole-log error to within 1.5x the noise floor, on
//! logs of the project's simulator AND of machine models the project's code did not make:
//! an independent textbook induction machine written here (flux-linkage states, its own
//! integrator and sampling) and the motulator log of `examples/logs` with sensor noise
//! added here. A hidden thermal drift (+60 K, tau 12 s, 40 s log with a start, 2 kHz,
//! default 12-bit sensors) is then named first, claimed and sized.
//!
//! The figures (`--nocapture`) are the accuracy table of docs/model-vs-measurement.md:
//! ```text
//! MONITOR_FULL_SWEEPS=1 cargo test --release -p monitor-analysis --test analysis noise_floor:: -- --nocapture
//! ```
//! By default a representative subset runs (each log source once, each rate once); the
//! thermal-drift logs (40 s) run with `MONITOR_FULL_SWEEPS=1` only (`.ci/run` runs it).
use crate::analysis_common;
use analysis_common::*;
use monitor_io::log::{Channels, Log, Row};
use monitor_io::params::{ParamFile, SensorRanges};
use monitor_sim::{Scenario, SupplyStep};
use monitor_testkit::small_motor;
use rand::SeedableRng;
use rand_distr::{Distribution, Normal};
use std::f64::consts::{PI, TAU};
use std::path::{Path, PathBuf};

/// All four dynamics effects: the full-order T-equivalent machine.
const FULL: [&str; 4] = [
    "flux_dynamics",
    "current_dynamics",
    "d_axis_dynamics",
    "cross_coupling_dynamics",
];

/// Length of the effect-free logs [s].
const DURATION_S: f64 = 3.4;

/// The supply of the effect-free logs: direct-on-line start at 0, a V/f step to 60 % at
/// 1.5 s, back to rated at 2.2 s, a 10 % voltage dip at 2.8 s: (time [s], voltage scale,
/// frequency scale) from each time on.
const SUPPLY: [(f64, f64, f64); 4] = [
    (0.0, 1.0, 1.0),
    (1.5, 0.6, 0.6),
    (2.2, 1.0, 1.0),
    (2.8, 0.9, 1.0),
];

/// Where a log comes from.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Source {
    /// The project's simulator (`monitor_sim`), default 12-bit sensors.
    Simulator,
    /// The textbook machine of [`textbook_rows`], 12-bit-like sensors added here.
    Textbook,
    /// The motulator log of `examples/logs` up to 2.4 s (the start, before its load
    /// step), sensors added here, rows kept at the rate asked for.
    Motulator,
}

/// 12-bit-like sensors as the simulator's defaults describe them (`SensorSpec`): white
/// noise of 0.05 % of the range, then a 12-bit quantiser over +/- the range; the ranges of
/// [`SensorRanges`] (the speed is left exact, as the simulator's default leaves it).
fn add_sensors(rows: &mut [Row], v_range: f64, i_range: f64, seed: u64) {
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(seed);
    let mut sense = |x: f64, range: f64| {
        let lsb = 2.0 * range / 4096.0;
        let noisy = x + Normal::new(0.0, 0.0005 * range).unwrap().sample(&mut rng);
        ((noisy / lsb).round() * lsb).clamp(-range, range)
    };
    for r in rows {
        if let Some(v) = r.v_abc.as_mut() {
            for x in v.iter_mut() {
                *x = sense(*x, v_range);
            }
        }
        for x in r.i_abc.iter_mut() {
            *x = sense(*x, i_range);
        }
    }
}

/// A textbook induction machine (Krause's T-equivalent circuit in the stationary frame,
/// flux linkages as states, amplitude-invariant space vectors), written here apart from
/// the project's simulator and model:
/// ```text
///   dpsi_s/dt = v_s - Rs i_s,   dpsi_r/dt = -Rr i_r + j Np w_m psi_r
///   i_s = (Lr psi_s - Lm psi_r) / D,   i_r = (Ls psi_r - Lm psi_s) / D,   D = Ls Lr - Lm^2
///   J dw_m/dt = (3/2) Np Im(conj(psi_s) i_s) - (B + Bl) w_m
/// ```
/// fed by the balanced supply [`SUPPLY`] (phase peak sqrt(2/3) V_ll), integrated by RK4 in
/// steps of at most 5 us and point-sampled at `rate_hz`; ideal sensors.
fn textbook_rows(p: &ParamFile, rate_hz: f64) -> Vec<Row> {
    use monitor_analysis::prep::C64;
    let m = &p.motor;
    let np = f64::from(m.poles) / 2.0;
    let det = m.ls_h * m.lr_h - m.lm_h * m.lm_h;
    let btot = m.b_nms + m.bl_nms;
    let currents = |ps: C64, pr: C64| {
        (
            (ps * m.lr_h - pr * m.lm_h) / det,
            (pr * m.ls_h - ps * m.lm_h) / det,
        )
    };
    // State: psi_s, psi_r, w_m.
    let deriv = |x: &(C64, C64, f64), v: C64| {
        let (is, ir) = currents(x.0, x.1);
        let te = 1.5 * np * (x.0.conj() * is).im;
        (
            v - is * m.rs_ohm,
            C64::new(0.0, np * x.2) * x.1 - ir * m.rr_ohm,
            (te - btot * x.2) / m.j_kgm2,
        )
    };
    let v_peak = p.supply.v_ll_rms * (2.0f64 / 3.0).sqrt();
    let f0 = p.supply.f_hz;
    let segment = |t: f64| {
        SUPPLY
            .iter()
            .rev()
            .find(|s| t >= s.0 - 1e-12)
            .copied()
            .unwrap_or(SUPPLY[0])
    };
    let sub = (200_000.0 / rate_hz).ceil() as usize;
    let h = 1.0 / (rate_hz * sub as f64);
    let n = (DURATION_S * rate_hz).round() as usize;
    let mut x = (C64::default(), C64::default(), 0.0);
    let mut theta = 0.0;
    let mut rows = Vec::with_capacity(n + 1);
    // Phase b lags phase a by 120 degrees: x_b = Re(x e^{-j 2 pi / 3}).
    let a = C64::from_polar(1.0, -TAU / 3.0);
    for k in 0..=n {
        let t = k as f64 / rate_hz;
        let (_, vs, _) = segment(t);
        let v = C64::from_polar(vs * v_peak, theta);
        let (is, _) = currents(x.0, x.1);
        rows.push(Row {
            t_s: t,
            v_abc: Some([v.re, (v * a).re, (v * a.conj()).re]),
            i_abc: [is.re, (is * a).re, (is * a.conj()).re],
            wm_rad_s: Some(x.2),
            enc_count: None,
            t_winding_c: None,
        });
        for j in 0..sub {
            let t0 = t + j as f64 * h;
            // The supply over this step (steps fall on the step grid).
            let (_, vs, fs) = segment(t0 + 0.5 * h);
            let w = TAU * f0 * fs;
            let at = |s: f64| C64::from_polar(vs * v_peak, theta + w * s);
            let add = |x: &(C64, C64, f64), d: &(C64, C64, f64), s: f64| {
                (x.0 + d.0 * s, x.1 + d.1 * s, x.2 + d.2 * s)
            };
            let k1 = deriv(&x, at(0.0));
            let k2 = deriv(&add(&x, &k1, 0.5 * h), at(0.5 * h));
            let k3 = deriv(&add(&x, &k2, 0.5 * h), at(0.5 * h));
            let k4 = deriv(&add(&x, &k3, h), at(h));
            x = (
                x.0 + (k1.0 + (k2.0 + k3.0) * 2.0 + k4.0) * (h / 6.0),
                x.1 + (k1.1 + (k2.1 + k3.1) * 2.0 + k4.1) * (h / 6.0),
                x.2 + (k1.2 + 2.0 * (k2.2 + k3.2) + k4.2) * (h / 6.0),
            );
            theta = (theta + w * h) % (2.0 * PI);
        }
    }
    rows
}

/// The motulator log of `examples/logs` (10 kHz, no noise) up to 2.4 s, every
/// `10 kHz / rate_hz`-th row.
fn motulator_rows(rate_hz: f64) -> Vec<Row> {
    let path =
        Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples/logs/motulator_2p2kw_dol.csv");
    let text = std::fs::read_to_string(path).expect("motulator log");
    let every = (10_000.0 / rate_hz).round() as usize;
    text.lines()
        .skip(1)
        .map(|l| {
            l.split(',')
                .map(|c| c.parse::<f64>().expect("number"))
                .collect::<Vec<f64>>()
        })
        .take_while(|c| c[0] < 2.4)
        .step_by(every)
        .map(|c| Row {
            t_s: c[0],
            v_abc: Some([c[1], c[2], c[3]]),
            i_abc: [c[4], c[5], c[6]],
            wm_rad_s: Some(c[7]),
            enc_count: None,
            t_winding_c: None,
        })
        .collect()
}

/// The motulator log's machine (`examples/logs/motulator_2p2kw_dol.toml`).
fn motulator_params() -> ParamFile {
    let path =
        Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples/logs/motulator_2p2kw_dol.toml");
    ParamFile::from_toml_str(&std::fs::read_to_string(path).expect("toml"), "motulator")
        .expect("params")
}

/// The project simulator's scenario of [`SUPPLY`], default sensors.
fn simulator_scenario(p: &ParamFile, rate_hz: f64) -> Scenario {
    let mut s = Scenario::steady(DURATION_S, rate_hz);
    s.sensors = sensors(1);
    s.supply.steps = SUPPLY[1..]
        .iter()
        .map(|&(t_s, v, f)| SupplyStep {
            t_s,
            v_scale: Some(v),
            f_hz: Some(f * p.supply.f_hz),
        })
        .collect();
    s
}

/// Writes the effect-free log of `source` for motor `which` at `rate_hz`, with sensors
/// (`noisy`) or without.
fn effect_free_log(
    dir: &Path,
    source: Source,
    which: &str,
    rate_hz: f64,
    noisy: bool,
) -> (PathBuf, ParamFile) {
    let name = format!("{source:?}_{which}_{rate_hz}_{noisy}");
    if source == Source::Simulator {
        let p = motor(which);
        let mut s = simulator_scenario(&p, rate_hz);
        if !noisy {
            s.sensors = sensors(0);
        }
        return (write_log(dir, &name, &p, &s, false), p);
    }
    let (p, mut rows) = match source {
        Source::Motulator => (motulator_params(), motulator_rows(rate_hz)),
        _ => {
            let p = motor(which);
            let rows = textbook_rows(&p, rate_hz);
            (p, rows)
        }
    };
    if noisy {
        let r = SensorRanges::new(&p.motor, p.supply.v_ll_rms, p.supply.f_hz);
        add_sensors(&mut rows, r.v_range_v, r.i_range_a, 23);
    }
    let log = Log {
        channels: Channels {
            voltages: true,
            speed: true,
            encoder: false,
            temperature: false,
        },
        rows,
    };
    let path = dir.join(format!("{name}.csv"));
    log.write(&path).expect("write log");
    (path, p)
}

/// One row of the accuracy table: `compare` with the four dynamics effects over the whole
/// log: (error, noise floor). Printed beside them: the floor's parts (the output noise
/// alone as the reduced model's phase currents see it, then as the full-order model's
/// do), and with `ideal` the same log's error without sensors (the model's own share).
fn accuracy(dir: &Path, source: Source, which: &str, rate_hz: f64, ideal: bool) -> (f64, f64) {
    use monitor_analysis::metrics::{noise_floor, Weights};
    let (log, p) = effect_free_log(dir, source, which, rate_hz, true);
    let a = analyse(&log, &p, 0.0);
    let out = a.compare(&opts(&FULL)).unwrap();
    let r = out.report;
    let w = Weights::new(&a.data, 0, usize::MAX);
    let mut q = out.prediction.clone();
    let half_phase = {
        q.predicts_d_axis = false;
        noise_floor(&a.data, &w, Some((&q, &q)))
    };
    let own_phase = {
        q.predicts_d_axis = true;
        noise_floor(&a.data, &w, Some((&q, &q)))
    };
    let e_ideal = if ideal {
        let (log, p) = effect_free_log(dir, source, which, rate_hz, false);
        let a = analyse(&log, &p, 0.0);
        format!(
            "{:.5}",
            a.compare(&opts(&FULL)).unwrap().report.normalized_rms_error
        )
    } else {
        "-".into()
    };
    let ch: Vec<String> = r
        .channels
        .iter()
        .map(|c| format!("{} {:.4}", c.channel, c.rms_error))
        .collect();
    eprintln!(
        "| {source:?} | {which} | {rate_hz:.0} | {:.4} | {:.4} | {:.2} | {half_phase:.4} | {own_phase:.4} | {e_ideal} | {} |",
        r.normalized_rms_error,
        r.noise_floor,
        r.normalized_rms_error / r.noise_floor,
        ch.join(", ")
    );
    (r.normalized_rms_error, r.noise_floor)
}

/// The table's header.
const HEADER: &str = "| source | motor | rate [Hz] | error | noise floor | ratio | output noise, q axis only | output noise, both axes | error, ideal sensors | per channel RMS error |";

/// Every case with the floor's parts and the ideal-sensor error (a probe, ignored:
/// `--ignored --nocapture`; `SOURCE` = Simulator, Textbook or Motulator, `MOTOR`, `RATE`
/// pick cases, default all).
#[test]
#[ignore]
fn noise_floor_probe() {
    let dir = tempfile::tempdir().unwrap();
    let env = |k: &str| std::env::var(k).ok();
    eprintln!("{HEADER}");
    for (source, which) in CASES {
        for rate in RATES {
            if env("SOURCE").is_some_and(|s| s != format!("{source:?}"))
                || env("MOTOR").is_some_and(|m| m != which)
                || env("RATE").is_some_and(|r| r.parse::<f64>().ok() != Some(rate))
            {
                continue;
            }
            accuracy(dir.path(), source, which, rate, true);
        }
    }
}

/// The log sources and motors of the effect-free cases.
const CASES: [(Source, &str); 5] = [
    (Source::Simulator, "2p2"),
    (Source::Simulator, "3hp"),
    (Source::Textbook, "2p2"),
    (Source::Textbook, "3hp"),
    (Source::Motulator, "2p2"),
];

/// The log rates [Hz].
const RATES: [f64; 3] = [2000.0, 5000.0, 10_000.0];

/// Effect-free noisy logs of the three sources at 2, 5 and 10 kHz: the four dynamics
/// effects' error is within 1.5x the noise floor (and not below 0.7x: a floor that is too
/// large would pass the first bound for any model).
#[test]
fn full_order_model_reaches_the_noise_floor_on_logs_it_describes() {
    let dir = tempfile::tempdir().unwrap();
    let cases = sweep(
        "sources x motors x rates",
        CASES
            .into_iter()
            .flat_map(|(s, w)| RATES.map(|r| (s, w, r))),
        |c| {
            matches!(
                c,
                (Source::Simulator, "2p2", 2000.0)
                    | (Source::Textbook, "3hp", 5000.0)
                    | (Source::Motulator, _, 10_000.0)
            )
        },
    );
    let mut failures = Vec::new();
    eprintln!("{HEADER}");
    for (source, which, rate) in cases {
        let (e, floor) = accuracy(dir.path(), source, which, rate, false);
        let ratio = e / floor;
        if !(0.7..=1.5).contains(&ratio) {
            failures.push(format!(
                "{source:?} {which} {rate}: {e:.4} = {ratio:.2}x the floor {floor:.4}"
            ));
        }
    }
    assert!(failures.is_empty(), "{failures:#?}");
}

/// The hidden thermal drift of issue 23 on motor `p`: +60 K with tau 12 s from the
/// switch-on, a 40 s log at 2 kHz with a direct-on-line start onto the paper's viscous
/// load, default (12-bit, noisy) sensors; `explain` with the four dynamics effects and
/// the parameter file `nominal`. Returns the top candidate, `unexplained`, its explained
/// fraction and its fitted rise [K] and time constant [s] (NaN when it is not
/// `thermal_drift`).
fn thermal_case(
    dir: &Path,
    name: &str,
    p: &ParamFile,
    nominal: &ParamFile,
) -> (String, bool, f64, f64, f64) {
    let env = |k: &str, v: f64| std::env::var(k).map_or(v, |x| x.parse().expect("number"));
    let mut s = Scenario::steady(env("DURATION", 40.0), 2000.0);
    s.sensors = sensors(1);
    let rise = env("RISE", 60.0);
    let spec = format!("name = \"thermal_drift\"\nrise_k = {rise}\ntau_s = 12.0\nat_s = 0.0\n");
    s.effects = vec![toml::from_str(&spec).expect("effect")];
    let log = write_log(dir, &format!("thermal_{name}"), p, &s, false);
    let a = analyse(&log, nominal, 0.0);
    let ex = a.explain(&opts(&FULL), &|_| {}).unwrap().report;
    if std::env::var("COMPARE").is_ok() {
        let mut with = FULL.to_vec();
        with.push("thermal_drift");
        for e in [&FULL[..], &with[..]] {
            let c = a.compare(&opts(e)).unwrap().report;
            eprintln!(
                "{name} compare {} effects: {:.4}, floor {:.4} ({:.2}x)",
                e.len(),
                c.normalized_rms_error,
                c.noise_floor,
                c.normalized_rms_error / c.noise_floor
            );
        }
    }
    let top = ex.ranking.first();
    let value = |k: &str| {
        top.filter(|c| c.effect.name() == "thermal_drift")
            .and_then(|c| c.parameters.get(k))
            .map_or(f64::NAN, |v| v.value)
    };
    let r = (
        top.map_or("-".to_string(), |c| c.effect.name().to_string()),
        ex.unexplained,
        top.map_or(0.0, |c| c.explained_fraction),
        value("rise_k"),
        value("tau_s"),
    );
    eprintln!(
        "{name}: top {} ({:.0} %), unexplained {}, rise {:.1} K, tau {:.2} s; {:?}",
        r.0,
        100.0 * r.2,
        r.1,
        r.3,
        r.4,
        ex.conclusion
    );
    r
}

/// Issue 23's done-when on two motors (3 hp, 2.2 kW): the hidden thermal drift of
/// [`thermal_case`], the parameter file 5 % off as in the hidden-effect protocol
/// (`analysis_effects.rs`): `thermal_drift` ranked first, the verdict not `unexplained`,
/// the rise within 20 % of 60 K and tau within 30 % of 12 s. Measured (the 40 s logs are
/// fitted on a coarsened series): 3 hp 63.8 K, 10.1 s, 2.2 kW 59.5 K, 12.4 s; before
/// issue 23's floor and coarsening fixes the verdict was `unexplained` (20 %, 34 %).
/// Part of the full sweeps (`MONITOR_FULL_SWEEPS=1`; two 40 s logs, a minute).
#[test]
fn hidden_thermal_drift_is_named_and_sized() {
    if !in_this_run("hidden_thermal_drift_is_named_and_sized") {
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    let mut failures = Vec::new();
    for which in ["3hp", "2p2"] {
        let p = motor(which);
        // Rise within 20 % of 60 K, tau within 30 % of 12 s (NaN: not fitted, fails).
        let (top, unexplained, _, rise, tau) =
            thermal_case(dir.path(), which, &p, &perturbed(&p, 0.05));
        if top != "thermal_drift"
            || unexplained
            || !(48.0..=72.0).contains(&rise)
            || !(8.4..=15.6).contains(&tau)
        {
            failures.push(format!(
                "{which}: top {top}, unexplained {unexplained}, rise {rise:.1} K, tau {tau:.2} s"
            ));
        }
    }
    assert!(failures.is_empty(), "{failures:#?}");
}

/// Probe of [`thermal_case`] on the three motors (ignored: `--ignored --nocapture`;
/// `OFF` = the parameter file's error, default 0: true values; `RISE` [K] and `DURATION`
/// [s] change the case; `COMPARE=1` adds `compare`'s error and floor without and with
/// `thermal_drift`).
#[test]
#[ignore]
fn thermal_drift_probe() {
    let dir = tempfile::tempdir().unwrap();
    let off: f64 = std::env::var("OFF").map_or(0.0, |v| v.parse().expect("OFF"));
    let motors = [
        ("3hp", motor("3hp")),
        ("2p2", motor("2p2")),
        ("0p37", small_motor::small_0p37kw()),
    ];
    for (name, p) in motors {
        thermal_case(dir.path(), name, &p, &perturbed(&p, off));
    }
}
