//! Rs and Rr read apart (`isolation.resistances`): on a log of an independent simulator
//! (motulator, the 2.2 kW machine, its own parameter file) both come back as the file's,
//! and on logs of this project's simulator a winding 30 K warm raises both alike (no
//! stator excess) while a loosening connection (Rs +10 %) shows as a 10 % excess with Rr
//! unchanged, whatever the load.

use monitor_io::log::Channels;
use monitor_io::params::ParamFile;
use monitor_replay::{diagnose_rows, ReplayOptions, ResistanceReading};
use monitor_sim::{simulate_to_vec, Scenario};
use std::path::PathBuf;

fn example(name: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("../../examples/logs")
        .join(name)
}

#[test]
fn an_independent_simulators_log_gives_back_its_own_resistances() {
    let params = ParamFile::load(&example("motulator_2p2kw_dol.toml")).expect("params"); // ok: test
    let report = monitor_replay::diagnose_file(
        &params,
        &example("motulator_2p2kw_dol.csv"),
        ReplayOptions::default(),
        &mut |_| {},
    )
    .expect("diagnoses"); // ok: test
    let r = report.report.isolation.resistances.expect("read"); // ok: test
    assert!((r.rs_factor - 1.0).abs() < 0.01, "{r:?}");
    assert!((r.rr_factor - 1.0).abs() < 0.01, "{r:?}");
    assert!(r.stator_excess.abs() < 0.005, "{r:?}");
}

fn reading(p: &ParamFile, load: f64, extra: &str) -> ResistanceReading {
    let text = format!(
        "duration_s = 4.0\nsample_rate_hz = 5000.0\nseed = 9\n[load]\nkind = \"viscous\"\n\
         steps = [{{ t_s = 0.0, bl_scale = {load} }}]\n{extra}"
    );
    let sc = Scenario::from_toml_str(&text, "resistances").expect("scenario"); // ok: test
    let rows = simulate_to_vec(p, &sc).expect("simulate"); // ok: test
    let channels = Channels {
        voltages: true,
        speed: true,
        encoder: false,
        temperature: false,
    };
    let r = diagnose_rows(p, channels, &rows, ReplayOptions::default()).expect("runs"); // ok: test
    r.isolation.resistances.expect("read") // ok: test
}

#[test]
fn heating_raises_rs_and_rr_alike_and_a_loose_connection_raises_rs_alone() {
    let warm = "[[effects]]\nname = \"thermal_drift\"\nrise_k = 30.0\ntau_s = 0.2\nat_s = 0.0\n";
    let loose = "[[faults]]\nkind = \"rs\"\nat_s = 0.0\nchange = 0.1\n";
    // Copper's 0.393 %/K over 30 K.
    let k = 1.0 + 0.00393 * 30.0;
    for p in [ParamFile::reference_2p2kw(), ParamFile::reference_3hp()] {
        for load in [0.85, 1.15] {
            let w = reading(&p, load, warm);
            assert!(
                (w.rs_factor - k).abs() < 0.01 && (w.rr_factor - k).abs() < 0.01,
                "{w:?}"
            );
            assert!(w.stator_excess.abs() < 0.003, "warm, load {load}: {w:?}");
            let l = reading(&p, load, loose);
            assert!(
                (l.stator_excess - 0.1).abs() < 0.005,
                "loose, load {load}: {l:?}"
            );
            assert!(
                (l.rr_factor - 1.0).abs() < 0.005,
                "loose, load {load}: {l:?}"
            );
        }
    }
}
