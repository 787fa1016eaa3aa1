//! Scenario files: the examples parse and run; bad keys are named; the CLI writes a CSV in
//! the log schema (`docs/design.md`) and refuses to overwrite an input.

use monitor_io::log::Log;
use monitor_io::params::ParamFile;
use monitor_sim::{self as sim, Scenario};
use std::path::PathBuf;

fn examples() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../examples")
}

#[test]
fn sim_example_files_parse_and_run() {
    let p = ParamFile::load(&examples().join("params/2p2kw.toml")).unwrap();
    assert_eq!(p, ParamFile::reference_2p2kw());
    let p3 = ParamFile::load(&examples().join("params/3hp.toml")).unwrap();
    let r3 = ParamFile::reference_3hp();
    assert!((p3.motor.lm_h - r3.motor.lm_h).abs() < 1e-6);
    let mut n = 0;
    for e in std::fs::read_dir(examples().join("scenarios")).unwrap() {
        let path = e.unwrap().path();
        let mut sc = Scenario::load(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
        // Shortened to 0.3 s: the events after it are left out (a scenario's events must
        // lie inside its run, which simulate checks).
        sc.duration_s = sc.duration_s.min(0.3);
        let end = sc.duration_s;
        sc.faults.retain(|f| f.at_s < end);
        sc.supply.steps.retain(|s| s.t_s < end);
        sc.load.steps.retain(|s| s.t_s < end);
        let rows = sim::simulate_to_vec(&p, &sc).unwrap();
        assert_eq!(
            rows.len(),
            (sc.duration_s * sc.sample_rate_hz).round() as usize
        );
        n += 1;
    }
    assert!(n >= 10);
}

#[test]
fn sim_scenario_errors_name_the_key() {
    let cases = [
        ("duration_s = 1.0\nsample_rate_hz = 1000.0\nsede = 3\n", "sede"),
        ("duration_s = 1.0\n", "sample_rate_hz"),
        (
            "duration_s = 1.0\nsample_rate_hz = 1000.0\n[[effects]]\nname = \"thermal_drift\"\nrise = 3.0\n",
            "rise",
        ),
        (
            "duration_s = 1.0\nsample_rate_hz = 1000.0\n[[effects]]\nname = \"saturaton\"\n",
            "saturaton",
        ),
        (
            "duration_s = 1.0\nsample_rate_hz = 1000.0\n[[faults]]\nkind = \"rs\"\nat_s = 0.5\n",
            "faults.change",
        ),
        (
            "duration_s = 1.0\nsample_rate_hz = 1000.0\n[[faults]]\nkind = \"rs\"\nat_s = 0.5\nchange = -1.5\n",
            "faults.change",
        ),
        ("duration_s = -1.0\nsample_rate_hz = 1000.0\n", "duration_s"),
        (
            "duration_s = 1.0\nsample_rate_hz = 1000.0\n[sensors]\nadc_bits = 40\n",
            "sensors.adc_bits",
        ),
        (
            "duration_s = 1.0\nsample_rate_hz = 1000.0\n[load]\nkind = \"viscous\"\nsteps = [{ t_s = 1.0, torque_nm = 3.0 }]\n",
            "load.steps",
        ),
    ];
    for (text, key) in cases {
        let e = Scenario::from_toml_str(text, "s.toml")
            .unwrap_err()
            .to_string();
        assert!(e.contains(key), "{e}");
        assert!(!e.contains('\n'), "{e}");
    }
    // Out-of-range effect parameters name the effect and the key.
    let e = Scenario::from_toml_str(
        "duration_s = 1.0\nsample_rate_hz = 1000.0\n[[effects]]\nname = \"phase_asymmetry\"\nfraction = 0.6\n",
        "s.toml",
    )
    .unwrap_err()
    .to_string();
    assert!(e.contains("effects.phase_asymmetry.fraction"), "{e}");
}

#[test]
fn sim_scenario_round_trips_through_toml() {
    let p = examples().join("scenarios/full_example.toml");
    let sc = Scenario::load(&p).unwrap();
    let back = Scenario::from_toml_str(&sc.to_toml_string(), "x").unwrap();
    assert_eq!(sc, back);
}

#[test]
fn sim_cli_writes_the_csv_schema_and_refuses_to_overwrite_inputs() {
    let dir = tempfile::tempdir().unwrap();
    let sc = dir.path().join("s.toml");
    std::fs::write(
        &sc,
        "duration_s = 0.2\nsample_rate_hz = 5000.0\n[[faults]]\nkind = \"rs\"\nat_s = 0.1\nchange = 0.5\n",
    )
    .unwrap();
    let params = examples().join("params/2p2kw.toml");
    let out = dir.path().join("d.csv");
    let o = assert_cmd::Command::cargo_bin("sim-host")
        .unwrap()
        .args(["simulate", "--json", "--params"])
        .arg(&params)
        .arg("--scenario")
        .arg(&sc)
        .arg("--out")
        .arg(&out)
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let j: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    assert_eq!(j["rows"], 1000);
    let text = std::fs::read_to_string(&out).unwrap();
    assert!(text.starts_with("t_s,va_V,vb_V,vc_V,ia_A,ib_A,ic_A,wm_rad_s,enc_count\n"));
    let log = Log::read(&out).unwrap();
    assert_eq!(log.rows.len(), 1000);
    // Refuses to overwrite the scenario.
    let o = assert_cmd::Command::cargo_bin("sim-host")
        .unwrap()
        .args(["simulate", "--params"])
        .arg(&params)
        .arg("--scenario")
        .arg(&sc)
        .arg("--out")
        .arg(&sc)
        .output()
        .unwrap();
    assert!(!o.status.success());
    assert!(std::fs::read_to_string(&sc)
        .unwrap()
        .starts_with("duration_s"));
    // Bad TOML: one line naming the key.
    std::fs::write(
        &sc,
        "duration_s = 0.2\nsample_rate_hz = 5000.0\nbogus_key = 1\n",
    )
    .unwrap();
    let o = assert_cmd::Command::cargo_bin("sim-host")
        .unwrap()
        .args(["simulate", "--params"])
        .arg(&params)
        .arg("--scenario")
        .arg(&sc)
        .arg("--out")
        .arg(dir.path().join("e.csv"))
        .output()
        .unwrap();
    assert!(!o.status.success());
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(
        err.contains("bogus_key") && err.trim().lines().count() == 1,
        "{err}"
    );
}

#[test]
fn values_the_run_would_not_carry_out_are_refused_by_key() {
    let p = ParamFile::reference_2p2kw();
    let head = "duration_s = 1.0\nsample_rate_hz = 1000.0\n";
    let cases = [
        (
            "[[faults]]\nkind = \"rs\"\nat_s = 2.0\nchange = 0.5\n",
            "faults.at_s",
        ),
        (
            "[[faults]]\nkind = \"rs\"\nat_s = 1e9\nchange = 0.5\n",
            "faults.at_s",
        ),
        (
            "[supply]\nsteps = [{ t_s = 1.5, v_scale = 0.9 }]\n",
            "supply.steps.t_s",
        ),
        ("[supply]\nf_hz = 1e6\n", "supply.f_hz"),
        (
            "[[faults]]\nkind = \"current_sensor\"\nat_s = 0.5\nmode = \"offset\"\noffset = 1e9\n",
            "faults.offset",
        ),
        (
            "[[faults]]\nkind = \"voltage_sensor\"\nat_s = 0.5\nmode = \"gain\"\nchange = -1.0\n",
            "faults.change",
        ),
    ];
    for (tail, key) in cases {
        let sc = Scenario::from_toml_str(&format!("{head}{tail}"), "s.toml").unwrap();
        let e = sim::simulate_to_vec(&p, &sc).unwrap_err().to_string();
        assert!(e.contains(key), "{tail}: {e}");
        assert!(!e.contains('\n'), "{e}");
    }
    let tiny =
        Scenario::from_toml_str("duration_s = 1e-9\nsample_rate_hz = 1000.0\n", "s").unwrap();
    let e = sim::simulate_to_vec(&p, &tiny).unwrap_err().to_string();
    assert!(e.contains("duration_s") && e.contains("rows"), "{e}");
    // The same run with its events inside the duration goes.
    let ok = Scenario::from_toml_str(
        &format!("{head}[[faults]]\nkind = \"rs\"\nat_s = 0.5\nchange = 0.5\n"),
        "s.toml",
    )
    .unwrap();
    assert_eq!(sim::simulate_to_vec(&p, &ok).unwrap().len(), 1000);
}

#[test]
fn a_diverged_run_names_the_value_it_followed() {
    // Values no motor has, that the checks before the run let through, end in a message
    // that names the scenario key the machine diverged after (or, from the start, where to
    // look), not a bare time.
    let p = ParamFile::reference_2p2kw();
    let run = |toml: &str| {
        let sc = Scenario::from_toml_str(toml, "test").expect("scenario"); // ok: test
        sim::simulate(&p, &sc, |_| {})
            .expect_err("diverges") // ok: test
            .to_string()
    };
    let after_fault = run(
        "duration_s = 1.0\nsample_rate_hz = 5000.0\nfaults = [{ kind = \"rs\", at_s = 0.5, change = 1e6 }]\n",
    );
    assert!(
        after_fault.contains("diverged")
            && after_fault.contains("faults")
            && after_fault.contains("rs")
            && after_fault.contains("0.5 s"),
        "{after_fault}"
    );
    let from_start = run(
        "duration_s = 1.0\nsample_rate_hz = 5000.0\n[load]\nkind = \"torque\"\ntorque_nm = 1e12\n",
    );
    assert!(
        from_start.contains("from the start") && from_start.contains("load.torque_nm"),
        "{from_start}"
    );
}
