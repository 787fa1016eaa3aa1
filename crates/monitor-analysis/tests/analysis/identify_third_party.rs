//! Issue 86, item 5: identify's 95 % intervals hold on logs this project did not make. On
//! every log of `sim-host/tests/data/motulator` (motulator's 2.2 kW, 7.5 kW and 50 hp
//! machines: a control run, saturation, a fan, heating, a supply unbalance, V/f control,
//! dry friction, a load step), identified from the user's parameter file beside it, the
//! intervals of Rs, Rr, Lls + Llr and Lm cover the log's machine (its published circuit
//! re-expressed with the file's leakage split, the one no terminal log can tell) on at
//! least 90 % of the values. Where the log's machine has no one value: a winding that
//! heats along the log covers a value it had (cold to the manifest's end); a saturating
//! machine's magnetising branch (Rr, the leakage and Lm of the split-free form move with
//! the flux) is left out, its Rs counted. About 10 s in the test profile.

use monitor_analysis::identify::{identify, Samples};
use monitor_io::log::{LogFile, Row};
use monitor_io::params::ParamFile;
use std::path::Path;

/// The circuit of the split-free (inverse-Gamma) values `[R_s, R_R, L_sigma, L_M]` as a
/// T-circuit with stator leakage share `f` (the same terminal behaviour: Slemon, IEEE
/// Trans. Ind. Appl. 25(6), 1989): `[Rs, Rr, Lls + Llr, Lm]`.
fn t_circuit(ig: [f64; 4], f: f64) -> [f64; 4] {
    let [rs, r_r, l_sigma, l_m] = ig;
    let lm_of = |l: f64| 0.5 * (l_m + (l_m * l_m + 4.0 * l_m * (1.0 - f) * l).sqrt());
    let sigma_of = |l: f64| f * l + (1.0 - f) * l * l_m / lm_of(l);
    let (mut lo, mut hi) = (0.0, 10.0 * l_sigma);
    for _ in 0..200 {
        let mid = 0.5 * (lo + hi);
        if sigma_of(mid) < l_sigma {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    let l = 0.5 * (lo + hi);
    let lm = lm_of(l);
    let lr = lm + (1.0 - f) * l;
    [rs, r_r * (lr / lm).powi(2), l, lm]
}

fn rows(path: &Path) -> Vec<Row> {
    let mut rows: Vec<Row> = Vec::new();
    LogFile::open(path)
        .expect("log") // ok: test
        .for_each_row(&mut |_| {}, &mut rows)
        .expect("read"); // ok: test
    rows
}

/// Logs the bar leaves out, each for a limit of identify documented in docs/own-motor.md:
/// `kw2p2_long_warming`, 40 s with both windings warming by 50 K (issue 87's long log):
/// identify fits one machine to the whole log and reads Rs 3.52 ohm [3.40..3.63], below
/// the cold 3.70, with Lls + Llr and Lm just off theirs (1 of 4 covered).
const NOT_YET: &[&str] = &["kw2p2_long_warming"];

#[test]
fn the_intervals_cover_the_third_party_machines() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../sim-host/tests/data/motulator");
    let text = std::fs::read_to_string(dir.join("manifest.toml")).expect("manifest"); // ok: test
    let m: toml::Value = toml::from_str(&text).expect("toml"); // ok: test
    let machines = m["machine"].as_array().expect("machines"); // ok: test
    let (mut covered, mut counted) = (0, 0);
    let mut missed = Vec::new();
    for log in m["log"].as_array().expect("logs") {
        let name = log["name"].as_str().unwrap_or_default();
        if NOT_YET.contains(&name) {
            eprintln!("{name}: left out (NOT_YET)");
            continue;
        }
        let params = log["params"].as_str().unwrap_or_default();
        let machine = machines
            .iter()
            .find(|mc| mc["params"].as_str() == Some(params))
            .expect("its machine"); // ok: test
        let ig = &machine["truth_inverse_gamma"];
        let f64_of = |v: &toml::Value| v.as_float().unwrap_or(f64::NAN);
        let sizes = &log["sizes"];
        let size = |k: &str| sizes.get(k).map(f64_of);
        let hidden: Vec<&str> = log["hidden"]
            .as_array()
            .map(|a| a.iter().filter_map(toml::Value::as_str).collect())
            .unwrap_or_default();
        let p = ParamFile::load(&dir.join(params)).expect("params"); // ok: test
        let rows = rows(&dir.join(log["csv"].as_str().unwrap_or_default()));
        let channels = monitor_io::log::Channels {
            voltages: true,
            speed: true,
            encoder: false,
            temperature: false,
        };
        let s =
            Samples::from_rows(&rows, channels, f64::NEG_INFINITY, f64::INFINITY).expect("samples"); // ok: test
        let id = identify(&p, &s, &mut |_| {}).expect("identifies"); // ok: test
        let mut truth = t_circuit(
            [
                f64_of(&ig["R_s"]) * size("stator_resistance_factor").unwrap_or(1.0),
                f64_of(&ig["R_R"]),
                f64_of(&ig["L_sgm"]),
                f64_of(&ig["L_M"]),
            ],
            id.stator_leakage_share,
        )
        .map(|v| (v, v));
        // A winding that heats along the log: any value from cold to the log's end.
        if let Some(end) = size("drift_resistance_at_end") {
            truth[0].1 *= end;
            if sizes.get("drift_windings").and_then(toml::Value::as_str) == Some("stator and rotor")
            {
                truth[1].1 *= end;
            }
        }
        let counted_here = if hidden.contains(&"saturation") { 1 } else { 4 };
        for (k, (lo_t, hi_t)) in truth.iter().enumerate().take(counted_here) {
            let e = &id.estimates[k];
            let (Some(v), Some(lo), Some(hi)) = (e.value, e.lo, e.hi) else {
                missed.push(format!("{name} {}: not identified", e.name));
                counted += 1;
                continue;
            };
            counted += 1;
            let line = format!(
                "{name:22} {:10} {v:.5} [{lo:.5}..{hi:.5}] truth {lo_t:.5}..{hi_t:.5}",
                e.name
            );
            eprintln!("{line}");
            if lo <= *hi_t && hi >= *lo_t {
                covered += 1;
            } else {
                missed.push(line);
            }
        }
    }
    let share = f64::from(covered) / f64::from(counted);
    eprintln!(
        "covered {covered} of {counted} ({:.0} %); missed: {missed:#?}",
        100.0 * share
    );
    assert!(counted >= 40, "{counted}");
    assert!(share >= 0.9, "covered {covered} of {counted}: {missed:#?}");
}

/// A start file of another supply (220 V 60 Hz) for motulator's 400 V 50 Hz log: the
/// identification says so and writes the log's supply.
#[test]
fn a_supply_other_than_the_files_is_reported_and_taken_from_the_log() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../sim-host/tests/data/motulator");
    let text = std::fs::read_to_string(dir.join("kw2p2.toml")).expect("params"); // ok: test
    let other = text
        .replace("v_ll_rms = 400.0", "v_ll_rms = 220.0")
        .replace("f_hz = 50.0", "f_hz = 60.0");
    assert_ne!(other, text);
    let rows = rows(&dir.join("kw2p2_control.csv"));
    let channels = monitor_io::log::Channels {
        voltages: true,
        speed: true,
        encoder: false,
        temperature: false,
    };
    let s = Samples::from_rows(&rows, channels, f64::NEG_INFINITY, f64::INFINITY).expect("samples"); // ok: test
    for (file, differs) in [(&text, false), (&other, true)] {
        let p = ParamFile::from_toml_str(file, "start").expect("params"); // ok: test
        let id = identify(&p, &s, &mut |_| {}).expect("identifies"); // ok: test
        assert_eq!(
            id.supply_from_log.is_some(),
            differs,
            "{:?}",
            id.supply_from_log
        );
        if differs {
            // The log's variac steps (-15 %, +10 %) around 400 V: its median within 5 %.
            assert!(
                (id.params.supply.v_ll_rms / 400.0 - 1.0).abs() < 0.05,
                "{:?}",
                id.params.supply
            );
            assert!(
                (id.params.supply.f_hz - 50.0).abs() < 0.1,
                "{:?}",
                id.params.supply
            );
        }
    }
}
