//! `explain --compare`: compare and explain on one read of the log, with the same figures as
//! the two commands run separately.
mod analysis_common;
use analysis_common::*;
use assert_cmd::Command;

fn run(args: &[&str], params: &std::path::Path, log: &std::path::Path) -> Vec<u8> {
    Command::cargo_bin("sim-host")
        .unwrap()
        .args(args)
        .arg("--params")
        .arg(params)
        .arg(log)
        .assert()
        .success()
        .get_output()
        .stdout
        .clone()
}

fn json(out: &[u8]) -> serde_json::Value {
    serde_json::from_slice(out).expect("stdout is one JSON document")
}

#[test]
fn explain_with_compare_reads_once_and_agrees_with_the_two_commands() {
    let dir = tempfile::tempdir().unwrap();
    let truth = motor("2p2");
    let s = scenario("2p2", Some("thermal_drift"), 1);
    let log = write_log(dir.path(), "run", &truth, &s, false);
    let params = write_params(dir.path(), "nominal", &perturbed(&truth, 0.05));
    let from = format!("{}", settle_s("2p2"));

    let both = json(&run(
        &["explain", "--compare", "--json", "--from", &from],
        &params,
        &log,
    ));
    let c = json(&run(&["compare", "--json", "--from", &from], &params, &log));
    let e = json(&run(&["explain", "--json", "--from", &from], &params, &log));
    assert_eq!(both["compare"], c);
    assert_eq!(both["explain"], e);

    // Text: compare's block, then explain's.
    let text = String::from_utf8(run(
        &["explain", "--compare", "--from", &from],
        &params,
        &log,
    ))
    .unwrap();
    let (ci, ei) = (
        text.find("compare ").expect("compare block"),
        text.find("explain ").expect("explain block"),
    );
    assert!(ci < ei, "{text}");
    assert!(text.contains("normalized_rms_error"), "{text}");
}
