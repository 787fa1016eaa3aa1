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

/// A model that diverges (the motulator log's start with two of the four dynamics effects
/// and no flux dynamics: its predicted current runs away within milliseconds) gets no error
/// figure: the text says "not judged" and when, the JSON has `diverged_at_s` and the
/// reason under `implausible_because`, and the model is not plausible. A convergent model
/// of the same log has no `diverged_at_s`.
#[test]
fn a_diverged_model_reports_no_error_figure() {
    let root = format!("{}/..", env!("CARGO_MANIFEST_DIR"));
    let params = std::path::PathBuf::from(format!("{root}/examples/logs/motulator_2p2kw_dol.toml"));
    let log = std::path::PathBuf::from(format!("{root}/examples/logs/motulator_2p2kw_dol.csv"));
    let effects = ["--effects", "d_axis_dynamics,cross_coupling_dynamics"];
    let text = String::from_utf8(run(&[&["compare"][..], &effects].concat(), &params, &log))
        .expect("utf-8");
    assert!(
        text.contains("normalized_rms_error: not judged: the model diverged at"),
        "{text}"
    );
    let j = json(&run(
        &[&["compare", "--json"][..], &effects].concat(),
        &params,
        &log,
    ));
    let t = j["diverged_at_s"].as_f64().expect("diverged_at_s");
    assert!((0.0..1.0).contains(&t), "{t}");
    assert_eq!(j["plausible"], false);
    assert!(j["implausible_because"][0]
        .as_str()
        .is_some_and(|w| w.starts_with("the model diverged")));
    let ok = json(&run(&["compare", "--json", "--to", "2.4"], &params, &log));
    assert!(ok.get("diverged_at_s").is_none(), "{ok}");
}
