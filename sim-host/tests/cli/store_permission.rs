//! Issue 65: a store in a folder that cannot be written is refused with one line naming the
//! store ("permission denied: cannot write the store PATH ..."), not SQLite's "unable to
//! open database file".
//!
//! A superuser writes anyway: then the command runs as `nobody` through `setpriv` where it
//! can, and the test is skipped with a note where it cannot.

use assert_cmd::Command;
use std::os::unix::fs::PermissionsExt;
use std::path::Path;

/// Whether this process can create a file in `dir`.
fn can_write(dir: &Path) -> bool {
    let probe = dir.join("probe");
    let ok = std::fs::write(&probe, b"").is_ok();
    let _ = std::fs::remove_file(&probe);
    ok
}

/// `sim-host` as a user the folder's mode applies to: this process, or `nobody` through
/// `setpriv` when this process can write the read-only folder (a superuser); `None` when
/// neither is possible.
fn sim_host_denied_by(read_only: &Path) -> Option<Command> {
    let bin = assert_cmd::cargo::cargo_bin("sim-host");
    if !can_write(read_only) {
        return Some(Command::new(bin));
    }
    let nobody = ["--reuid=65534", "--regid=65534", "--clear-groups"];
    let works = std::process::Command::new("setpriv")
        .args(nobody)
        .arg("true")
        .status()
        .is_ok_and(|s| s.success());
    if !works {
        return None;
    }
    let mut c = Command::new("setpriv");
    c.args(nobody).arg(bin);
    Some(c)
}

#[test]
fn a_store_in_a_read_only_folder_is_refused_naming_it() {
    let dir = tempfile::tempdir().expect("temp dir");
    // Readable by every user (the command may run as another), the store's folder read-only.
    std::fs::set_permissions(dir.path(), std::fs::Permissions::from_mode(0o755)).expect("chmod");
    let examples = Path::new(env!("CARGO_MANIFEST_DIR")).join("../examples/logs");
    let motors = dir.path().join("motors.toml");
    std::fs::write(
        &motors,
        format!(
            "[[motor]]\nname = \"m\"\nparams = {:?}\nlogs = \"*\"\n",
            examples
                .join("motulator_2p2kw_dol.toml")
                .display()
                .to_string()
        ),
    )
    .expect("write the table");
    let folder = dir.path().join("read_only");
    std::fs::create_dir(&folder).expect("mkdir");
    std::fs::set_permissions(&folder, std::fs::Permissions::from_mode(0o555)).expect("chmod");
    let Some(mut cmd) = sim_host_denied_by(&folder) else {
        eprintln!(
            "note: {} is writable here (root) and setpriv cannot drop to nobody: skipped",
            folder.display()
        );
        return;
    };
    let store = folder.join("history.db");
    let out = cmd
        .arg("fleet")
        .arg(&motors)
        .arg(examples.join("motulator_2p2kw_dol.csv"))
        .arg("--store")
        .arg(&store)
        .output()
        .expect("sim-host runs");
    let e = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{e}");
    assert_eq!(e.trim_end().lines().count(), 1, "{e}");
    assert!(
        e.contains(&format!(
            "permission denied: cannot write the store {}",
            store.display()
        )) && e.contains("not writable"),
        "{e}"
    );
    assert!(!e.contains("unable to open database file"), "{e}");
    assert!(!store.exists());
}
