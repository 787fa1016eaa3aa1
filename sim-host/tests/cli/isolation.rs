//! Fault isolation through the command line (`diagnose`'s `isolation` and the candidates'
//! `change`): a log simulated by `sim-host simulate` of a machine the code was not
//! developed on (`examples/params/11kw_2pole.toml`), a load step then a fault, diagnosed with
//! a parameter file that is off. (The isolation beyond Table 1 on the three machines, through
//! the library: `crates/monitor-studies/tests/studies/isolation.rs`.)

use std::path::Path;

/// The wrong confident name found by hand (docs/isolation.md, "Away from the learned operating point"): the
/// 11 kW machine at 1 kHz, a load step to 0.7 x Bl at 6 s, then Rr +50 % at 8 s, diagnosed
/// through the command line with a parameter file 15-20 % off (Rs +20 %, Rr -19 %, Lm
/// -15 %, leakages -13 %) and commissioned at the first load. Before the isolation
/// allowed for the parameter file's error away from the learned point it named
/// `current_sensor -27 %` at p = 0.95. Now: no wrong fault at >= 0.5 (the friction class,
/// which a load change is, or the injected Rr with its size), and the verdict says the current moved from where the
/// baseline was learned.
#[test]
fn a_load_step_then_a_fault_with_a_parameter_file_that_is_off_names_no_wrong_fault() {
    let dir = tempfile::tempdir().unwrap(); // ok: test
    let third = Path::new(env!("CARGO_MANIFEST_DIR")).join("../examples/params/11kw_2pole.toml");
    let truth = std::fs::read_to_string(&third).unwrap(); // ok: test
    let off = truth
        .replace("rs_ohm = 0.42", "rs_ohm = 0.504")
        .replace("rr_ohm = 0.36", "rr_ohm = 0.29")
        .replace("ls_h = 0.108", "ls_h = 0.0935")
        .replace("lr_h = 0.109", "lr_h = 0.0935")
        .replace("lm_h = 0.104", "lm_h = 0.0885");
    assert_ne!(
        off, truth,
        "the 11 kW file's values changed: update the test"
    );
    let off_path = dir.path().join("off.toml");
    std::fs::write(&off_path, off).unwrap(); // ok: test
    let scenario = dir.path().join("rr.toml");
    std::fs::write(
        &scenario,
        "duration_s = 12.0\nsample_rate_hz = 1000.0\nseed = 5\n\n[[load.steps]]\nt_s = 6.0\nbl_scale = 0.7\n\n[[faults]]\nkind = \"rr\"\nat_s = 8.0\nchange = 0.5\n",
    )
    .unwrap(); // ok: test
    let log = dir.path().join("rr.csv");
    let bin = env!("CARGO_BIN_EXE_sim-host");
    let sim = std::process::Command::new(bin)
        .args(["simulate", "--params"])
        .arg(&third)
        .arg("--scenario")
        .arg(&scenario)
        .arg("--out")
        .arg(&log)
        .output()
        .unwrap(); // ok: test
    assert!(
        sim.status.success(),
        "{}",
        String::from_utf8_lossy(&sim.stderr)
    );
    let out = std::process::Command::new(bin)
        .args(["diagnose", "--json", "--commission", "3:5.5", "--params"])
        .arg(&off_path)
        .arg(&log)
        .output()
        .unwrap(); // ok: test
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap(); // ok: test
    let iso = &v["isolation"];
    eprintln!("{}", iso["verdict"]);
    // Nothing wrong named: the friction class (a load change is one to the paper's model)
    // or the injected Rr +50 % with its size (the torque against the load measured just
    // before the change tells it since issue 24), or nothing.
    let named = iso["named"].as_str();
    match named {
        None | Some("b/bl") => {}
        Some("rr") => {
            let size = iso["named_change"].as_f64().unwrap_or(f64::NAN); // ok: test
            assert!(
                (size - 0.5).abs() <= 0.1,
                "rr named with size {size}: {iso}"
            );
        }
        Some(other) => panic!("{other} named: {iso}"), // ok: test
    }
    for c in v["candidates"].as_array().unwrap() {
        // ok: test
        let (f, p) = (
            c["fault"].as_str().unwrap(),
            c["probability"].as_f64().unwrap(),
        ); // ok: test
        assert!(p < 0.5 || f == "b" || f == "bl" || f == "rr", "{c}");
    }
    let moved = iso["moved_from_learned"].as_f64().unwrap(); // ok: test
    assert!(moved < -0.15, "the current fell with the load: {moved}");
    // Where nothing is named, the verdict says why: the point is away from the learned one.
    let said = if named == Some("rr") {
        "The rotor resistance Rr changed by +50 %"
    } else {
        "from where the baseline was learned"
    };
    assert!(
        iso["verdict"].as_str().is_some_and(|s| s.contains(said)),
        "{iso}"
    );
}
