//! The one output guard, through the API every front end calls (issue 65): `simulate`'s
//! `out` may not be the scenario or the parameter file it reads, by any spelling (`./`) or
//! link; the call refuses before anything is written, naming both files, and the inputs
//! keep their bytes. The fleet's store may not be a file the run reads. A short scenario
//! (0.05 s) keeps each run quick.

use monitor_api::files::{NamedFile, OverwriteError};
use monitor_api::fleet::{check_fleet_outputs, MotorTable};
use monitor_api::{self as api, ApiError, ErrorKind, ParamsSource, ScenarioSource};
use std::path::{Path, PathBuf};

const SCENARIO: &str = "duration_s = 0.05\nsample_rate_hz = 2000.0\nseed = 1\n";

/// A folder with a copy of the 2.2 kW parameter file (`p.toml`) and the scenario
/// (`sc.toml`).
fn setup() -> (tempfile::TempDir, PathBuf, PathBuf) {
    let dir = tempfile::tempdir().expect("tmp");
    let params = dir.path().join("p.toml");
    let from = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples/params/2p2kw.toml");
    std::fs::copy(from, &params).expect("copy params");
    let scenario = dir.path().join("sc.toml");
    std::fs::write(&scenario, SCENARIO).expect("write scenario");
    (dir, params, scenario)
}

/// `simulate_to_file` into `out`: refused as an [`OverwriteError`] naming `field` and `out`,
/// with both inputs unchanged.
fn refused(params: &Path, scenario: &Path, out: &Path, field: &str) {
    let before = [
        std::fs::read(params).unwrap(),
        std::fs::read(scenario).unwrap(),
    ];
    let e = api::simulate_to_file(
        ParamsSource::Path(params),
        ScenarioSource::Path(scenario),
        out,
    )
    .expect_err("an output that is an input is refused");
    assert!(
        matches!(e, ApiError::Overwrite(OverwriteError::Input { .. })),
        "{e:?}"
    );
    assert_eq!(e.kind(), ErrorKind::Option);
    let msg = e.to_string();
    assert!(
        msg.contains(&format!("(the {field})"))
            && msg.contains(&format!("out = {}", out.display()))
            && !msg.contains('\n')
            && !msg.contains("--"),
        "{msg}"
    );
    let after = [
        std::fs::read(params).unwrap(),
        std::fs::read(scenario).unwrap(),
    ];
    assert_eq!(before, after, "an input was written");
}

#[test]
fn out_may_not_be_the_scenario_or_the_parameter_file() {
    let (dir, params, scenario) = setup();
    refused(&params, &scenario, &scenario, "scenario");
    refused(&params, &scenario, &params, "params");
    // Another spelling of each: `./` and `..`.
    let dotted = dir.path().join(".").join("sc.toml");
    refused(&params, &scenario, &dotted, "scenario");
    let up = dir.path().join("sub");
    std::fs::create_dir(&up).unwrap();
    refused(&params, &scenario, &up.join("..").join("p.toml"), "params");
    // No temporary file was left beside them.
    let names: Vec<_> = std::fs::read_dir(dir.path()).unwrap().flatten().collect();
    assert_eq!(names.len(), 3, "{names:?}");
}

#[cfg(unix)]
#[test]
fn out_may_not_be_a_link_to_an_input() {
    let (dir, params, scenario) = setup();
    let soft = dir.path().join("log.csv");
    std::os::unix::fs::symlink(&scenario, &soft).unwrap();
    refused(&params, &scenario, &soft, "scenario");
    let hard = dir.path().join("hard.csv");
    std::fs::hard_link(&params, &hard).unwrap();
    refused(&params, &scenario, &hard, "params");
    // The scenario as its text: only the parameter file is an input file.
    let e = api::simulate_to_file(ParamsSource::Path(&params), SCENARIO, &hard).unwrap_err();
    assert!(e.to_string().contains("(the params)"), "{e}");
}

#[test]
fn a_new_output_is_written_whole() {
    let (dir, params, scenario) = setup();
    let out = dir.path().join("run.csv");
    let s = api::simulate_to_file(
        ParamsSource::Path(&params),
        ScenarioSource::Path(&scenario),
        &out,
    )
    .expect("simulates");
    assert!(s.rows > 0);
    let text = std::fs::read_to_string(&out).unwrap();
    assert!(text.starts_with("t_s,"), "{}", &text[..40.min(text.len())]);
    assert_eq!(text.lines().count() as u64, s.rows + 1);
}

#[test]
fn the_fleet_store_may_not_be_a_file_the_run_reads() {
    let (dir, params, _) = setup();
    let table_file = dir.path().join("motors.toml");
    let text = "[[motor]]\nname = \"m\"\nparams = \"p.toml\"\nlogs = \"m_*\"\n";
    std::fs::write(&table_file, text).unwrap();
    let table = MotorTable::load(&table_file).unwrap();
    let log = dir.path().join("m_1.csv");
    std::fs::write(&log, "t_s,ia_A,ib_A,ic_A\n0,1,2,-3\n").unwrap();
    let logs = vec![log.clone()];
    let check = |store: &Path| {
        check_fleet_outputs(
            Some(&table_file),
            &table,
            &logs,
            &[NamedFile::new("store", store)],
        )
    };
    for (input, field) in [(&table_file, "motors"), (&params, "params"), (&log, "logs")] {
        let e = check(&dir.path().join(".").join(input.file_name().unwrap())).unwrap_err();
        assert!(e.to_string().contains(&format!("(the {field})")), "{e}");
    }
    check(&dir.path().join("history.db")).expect("a new store");
}
