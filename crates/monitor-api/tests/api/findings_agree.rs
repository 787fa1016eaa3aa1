//! Issue 86, item 4: a finding's state is its text's. On the 2.2 kW reference machine
//! (2 kHz logs, a few seconds each):
//! - a 60 Hz parameter file on a 50 Hz log is a data-quality finding that stops the
//!   verdict (it read `FAULT rr +44 %` from the wrong file, `data_quality clear` beside a
//!   warning that said so);
//! - the lamps' first signature match that the verdict does not name is said to be a
//!   candidate dropped, with the fault the verdict names (Ls +50 %: the lamps first matched
//!   rr);
//! - heating read against the parameter file is not "since commissioning".
//!
//! About 2 s in the test profile.

use monitor_api::{self as api, DiagnoseRequest, ParamsSource};
use monitor_core::verdict::Rule;
use monitor_replay::{CommissionWindow, Detail, DiagnoseReport, ReplayOptions, Verdict};
use std::path::Path;

fn params() -> String {
    let p = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples/params/2p2kw.toml");
    std::fs::read_to_string(p).expect("params") // ok: test
}

fn run(dir: &Path, file: &str, scenario: &str, commission: Option<(f64, f64)>) -> DiagnoseReport {
    let log = dir.join(format!("{}.csv", scenario.len()));
    let sim = params();
    api::simulate_to_file(
        ParamsSource::Toml {
            text: &sim,
            origin: "2p2kw",
        },
        scenario,
        &log,
    )
    .expect("simulates"); // ok: test
    let req = DiagnoseRequest {
        options: ReplayOptions {
            commission: commission.map(|(a, b)| CommissionWindow::of(a, b)),
            ..ReplayOptions::default()
        },
        ..DiagnoseRequest::default()
    };
    let p = ParamsSource::Toml {
        text: file,
        origin: "the file",
    };
    api::diagnose(p, &log, &req, &mut |_| {})
        .expect("diagnoses")
        .report // ok: test
}

#[test]
fn the_verdict_its_findings_and_its_events_say_one_thing() {
    let dir = tempfile::tempdir().expect("temp dir"); // ok: test
    let file = params();
    // The supply's frequency against the file's.
    let wrong = file.replace("f_hz = 50.0", "f_hz = 60.0");
    assert_ne!(wrong, file);
    let healthy = "duration_s = 5.0\nsample_rate_hz = 2000.0\nseed = 2\n";
    let r = run(dir.path(), &wrong, healthy, Some((1.5, 3.5)));
    assert_eq!(r.verdict, Verdict::CouldNotJudge);
    assert_eq!(r.verdict_rule, Rule::DataUntrusted);
    assert!(!r.data_quality.trusted);
    // A first signature match the verdict drops is said so, with the verdict's fault.
    let ls = "duration_s = 10.0\nsample_rate_hz = 2000.0\nseed = 3\n\
              [[faults]]\nkind = \"ls\"\nat_s = 6.0\nchange = 0.5\n";
    let r = run(dir.path(), &file, ls, Some((1.5, 5.0)));
    assert_eq!(r.verdict, Verdict::Fault);
    let doc = api::words::diagnose::document(&r, &api::words::FieldNames);
    let said = doc["detections_said"].as_array().expect("said").clone(); // ok: test
    assert_eq!(said.len(), r.detections.len());
    let verdict_fault = r
        .verdict_finding
        .as_ref()
        .and_then(|f| f.named())
        .map(api::words::diagnose::fault_text)
        .expect("named"); // ok: test
    for (d, s) in r.detections.iter().zip(&said) {
        let s = s.as_str().unwrap_or_default();
        if !verdict_fault.starts_with(d.fault.name()) {
            assert!(s.contains("dropped") && s.contains(&verdict_fault), "{s}");
        }
    }
    assert!(
        r.detections
            .iter()
            .any(|d| !verdict_fault.starts_with(d.fault.name())),
        "the case this test is about: {:?} beside {verdict_fault}",
        r.detections
    );
    // Heating against the file.
    let warm = "duration_s = 12.0\nsample_rate_hz = 2000.0\nseed = 3\n\
                [[effects]]\nname = \"thermal_drift\"\nrise_k = 40.0\ntau_s = 3.0\n";
    let r = run(dir.path(), &file, warm, None);
    let op = r
        .findings
        .iter()
        .find(|f| {
            matches!(
                f.detail,
                Detail::OperatingPointMoved {
                    rise_k: Some(_),
                    ..
                }
            )
        })
        .expect("the heating named"); // ok: test
    let s = api::words::diagnose::summary(op, &r, &api::words::FieldNames);
    assert!(
        !s.contains("since commissioning") && s.contains("parameter file"),
        "{s}"
    );
}
