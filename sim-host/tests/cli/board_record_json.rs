//! Issue 65: `board-record --json` prints one JSON document of what the text line says (the
//! file written and its size), like every other command's `--json`.

use assert_cmd::Command;

#[test]
fn board_record_json_names_the_file_and_its_size() {
    let dir = tempfile::tempdir().expect("temp dir");
    let params =
        std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../examples/params/3hp.toml");
    let out = dir.path().join("motor.bin");
    let run = Command::cargo_bin("sim-host")
        .expect("binary")
        .args(["board-record", "--json", "--out"])
        .arg(&out)
        .arg(&params)
        .output()
        .expect("sim-host runs");
    assert!(
        run.status.success(),
        "{}",
        String::from_utf8_lossy(&run.stderr)
    );
    let doc: serde_json::Value = serde_json::from_slice(&run.stdout).expect("one JSON document");
    let written = std::fs::metadata(&out)
        .expect("the record is written")
        .len();
    assert_eq!(doc["bytes"].as_u64(), Some(written), "{doc}");
    assert_eq!(
        doc["out"].as_str(),
        Some(out.to_str().expect("utf8")),
        "{doc}"
    );
    assert_eq!(doc.as_object().map(|o| o.len()), Some(2), "{doc}");
    // Without --json: the one line, unchanged.
    let text = Command::cargo_bin("sim-host")
        .expect("binary")
        .args(["board-record", "--out"])
        .arg(&out)
        .arg(&params)
        .output()
        .expect("sim-host runs");
    let line = String::from_utf8_lossy(&text.stdout);
    assert_eq!(line, format!("wrote {} ({written} bytes)\n", out.display()));
}
