//! `sim-host hmi` end to end in a real terminal: tmux runs it in an 80x24 pane, the test
//! types the keys a user would (commission, inject Bl +50 %, quit; and Ctrl-C) and reads
//! the pane. Skipped, with a note, where tmux is not installed (`.ci/run` installs it).

use std::process::{Command, Output};
use std::time::{Duration, Instant};

/// A tmux server of this test's own (its own socket), killed when dropped.
struct Tmux {
    socket: String,
}

impl Tmux {
    fn start(name: &str) -> Option<Tmux> {
        let ok = Command::new("tmux")
            .arg("-V")
            .output()
            .is_ok_and(|o| o.status.success());
        if !ok {
            eprintln!("note: tmux is not installed: the end-to-end HMI test is skipped");
            return None;
        }
        Some(Tmux {
            socket: format!("sim-host-hmi-{name}-{}", std::process::id()),
        })
    }

    fn run(&self, args: &[&str]) -> Output {
        Command::new("tmux")
            .arg("-L")
            .arg(&self.socket)
            .args(args)
            .output()
            .expect("tmux runs")
    }

    /// Starts `sim-host hmi` in an 80x24 pane; the shell prints its exit status after.
    fn hmi(&self) {
        let bin = env!("CARGO_BIN_EXE_sim-host");
        let cmd = format!("'{bin}' hmi; echo EXITED $?; sleep 60");
        let o = self.run(&[
            "new-session",
            "-d",
            "-s",
            "hmi",
            "-x",
            "80",
            "-y",
            "24",
            &cmd,
        ]);
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    }

    fn pane(&self) -> String {
        String::from_utf8_lossy(&self.run(&["capture-pane", "-p", "-t", "hmi"]).stdout).into_owned()
    }

    fn keys(&self, keys: &str) {
        assert!(self.run(&["send-keys", "-t", "hmi", keys]).status.success());
    }

    /// Waits until the pane shows every one of `texts` (at most a minute).
    fn wait_for(&self, texts: &[&str]) -> String {
        let until = Instant::now() + Duration::from_secs(60);
        loop {
            let pane = self.pane();
            if texts.iter().all(|t| pane.contains(t)) {
                return pane;
            }
            assert!(
                Instant::now() < until,
                "waited for {texts:?}; the pane shows:\n{pane}"
            );
            std::thread::sleep(Duration::from_millis(200));
        }
    }
}

impl Drop for Tmux {
    fn drop(&mut self) {
        let _ = self.run(&["kill-server"]);
    }
}

#[test]
fn a_user_commissions_injects_a_fault_and_quits() {
    let Some(t) = Tmux::start("keys") else { return };
    t.hmi();
    let pane = t.wait_for(&["DRIVE MONITOR", "healthy", "q quit"]);
    assert!(pane.lines().count() <= 24 && pane.lines().all(|l| l.chars().count() <= 80));
    t.keys("c");
    t.wait_for(&["learned thresholds in force", "(learned)"]);
    // A +30 % load step with no fault: residual lamps, the amber MOVED lamp, no FAULT.
    t.keys("+");
    t.keys("+");
    t.keys("+");
    let pane = t.wait_for(&["MOVED ●", "load (active", "load x1.30", "r2 ●"]);
    assert!(!pane.contains("FAULT"), "{pane}");
    // Back to the commissioned load, then Rs +50 %: the red FAULT lamp and `rs +` first.
    t.keys("-");
    t.keys("-");
    t.keys("-");
    t.wait_for(&["load x1.00", "FAULT ○"]);
    t.keys("1");
    let pane = t.wait_for(&["FAULT ●", "named: rs +", "rs +50%"]);
    let header = pane
        .lines()
        .find(|l| l.contains("FAULT ●"))
        .unwrap_or_default();
    assert!(
        header
            .split(" s  ")
            .nth(1)
            .is_some_and(|h| h.starts_with("rs +")),
        "{pane}"
    );
    t.keys("q");
    let pane = t.wait_for(&["EXITED 0"]);
    // The alternate screen is left: the HMI is gone from the terminal.
    assert!(!pane.contains("DRIVE MONITOR"), "{pane}");
}

#[test]
fn ctrl_c_restores_the_terminal() {
    let Some(t) = Tmux::start("ctrlc") else {
        return;
    };
    t.hmi();
    t.wait_for(&["DRIVE MONITOR", "q quit"]);
    t.keys("C-c");
    let pane = t.wait_for(&["EXITED 0"]);
    assert!(!pane.contains("DRIVE MONITOR"), "{pane}");
    // Raw mode is off again: the shell echoes what is typed.
    t.keys("echo typed-after-exit");
    t.wait_for(&["typed-after-exit"]);
}
