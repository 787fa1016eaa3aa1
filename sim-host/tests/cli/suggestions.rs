//! Issue 65: a misspelt command or option gets clap's suggestion on the one error line
//! ("did you mean ..."), exit status 2.

use assert_cmd::Command;

/// The one stderr line of a refused command line.
fn refused(args: &[&str]) -> String {
    let out = Command::cargo_bin("sim-host")
        .expect("binary")
        .args(args)
        .output()
        .expect("sim-host runs");
    assert_eq!(out.status.code(), Some(2), "{args:?}");
    assert!(out.stdout.is_empty(), "{args:?}");
    let e = String::from_utf8_lossy(&out.stderr).to_string();
    assert_eq!(e.trim_end().lines().count(), 1, "{args:?}: {e}");
    e
}

#[test]
fn a_misspelt_command_is_suggested() {
    let e = refused(&["diagnos"]);
    assert!(
        e.contains("'diagnos'") && e.contains("did you mean 'diagnose'?"),
        "{e}"
    );
}

#[test]
fn a_misspelt_option_is_suggested() {
    let e = refused(&[
        "diagnose",
        "--params",
        "p.toml",
        "log.csv",
        "--comission",
        "2:4",
    ]);
    assert!(
        e.contains("'--comission'") && e.contains("did you mean '--commission'?"),
        "{e}"
    );
}

#[test]
fn nothing_is_suggested_for_a_word_far_from_every_command() {
    let e = refused(&["xyzzyplugh"]);
    assert!(!e.contains("did you mean"), "{e}");
}
