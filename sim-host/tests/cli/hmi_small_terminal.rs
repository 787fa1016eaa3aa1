//! Issue 65: in a terminal too small for the HMI's panel (60x15) the screen says so and
//! names the size it needs, instead of silently hiding rows r2..r4: through the library's
//! drawing on ratatui's test backend, and end to end with the binary in a tmux pane (skipped,
//! with a note, where tmux is not installed).

use ratatui::backend::TestBackend;
use ratatui::Terminal;
use sim_host::hmi::size::{draw_if_too_small, too_small, MIN_HEIGHT, MIN_WIDTH};
use std::process::{Command, Output};
use std::time::{Duration, Instant};

/// What a `w` x `h` test terminal shows after the size check, as one string, and whether it
/// drew the note.
fn drawn(w: u16, h: u16) -> (String, bool) {
    let mut t = Terminal::new(TestBackend::new(w, h)).expect("test terminal");
    let mut noted = false;
    t.draw(|f| noted = draw_if_too_small(f)).expect("draw");
    let buf = t.backend().buffer();
    let rows: Vec<String> = (0..h)
        .map(|y| {
            (0..w)
                .map(|x| buf[(x, y)].symbol().to_string())
                .collect::<String>()
                .trim_end()
                .to_string()
        })
        .collect();
    (rows.join(" "), noted)
}

#[test]
fn a_60x15_terminal_is_told_it_is_too_small() {
    let (screen, noted) = drawn(60, 15);
    assert!(noted);
    assert!(
        screen.contains(&format!(
            "terminal 60x15 is too small: need {MIN_WIDTH}x{MIN_HEIGHT}"
        )),
        "{screen}"
    );
    // The panel fits from its own size on; one row or column less is too small.
    assert_eq!(too_small(MIN_WIDTH, MIN_HEIGHT), None);
    assert_eq!(too_small(80, 24), None);
    assert!(too_small(MIN_WIDTH - 1, MIN_HEIGHT).is_some());
    assert!(too_small(MIN_WIDTH, MIN_HEIGHT - 1).is_some());
    let (_, fits) = drawn(80, 24);
    assert!(!fits);
    // A tiny terminal gets what fits of the note, and no panic.
    let (tiny, noted) = drawn(12, 3);
    assert!(noted && tiny.contains("terminal"), "{tiny}");
}

fn tmux(socket: &str, args: &[&str]) -> Output {
    Command::new("tmux")
        .arg("-L")
        .arg(socket)
        .args(args)
        .output()
        .expect("tmux runs")
}

#[test]
fn the_binary_in_a_60x15_pane_says_the_terminal_is_too_small() {
    if !Command::new("tmux")
        .arg("-V")
        .output()
        .is_ok_and(|o| o.status.success())
    {
        eprintln!("note: tmux is not installed: the end-to-end small-terminal test is skipped");
        return;
    }
    let socket = format!("sim-host-hmi-small-{}", std::process::id());
    let bin = assert_cmd::cargo::cargo_bin("sim-host");
    let cmd = format!("'{}' hmi; echo EXITED $?; sleep 60", bin.display());
    let o = tmux(
        &socket,
        &[
            "new-session",
            "-d",
            "-s",
            "hmi",
            "-x",
            "60",
            "-y",
            "15",
            &cmd,
        ],
    );
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let until = Instant::now() + Duration::from_secs(60);
    let pane = loop {
        let out = tmux(&socket, &["capture-pane", "-p", "-t", "hmi"]);
        let pane = String::from_utf8_lossy(&out.stdout).into_owned();
        if pane.contains("too small") || Instant::now() > until {
            break pane;
        }
        std::thread::sleep(Duration::from_millis(200));
    };
    // q still quits.
    let _ = tmux(&socket, &["send-keys", "-t", "hmi", "q"]);
    let quit_until = Instant::now() + Duration::from_secs(30);
    let after = loop {
        let out = tmux(&socket, &["capture-pane", "-p", "-t", "hmi"]);
        let after = String::from_utf8_lossy(&out.stdout).into_owned();
        if after.contains("EXITED") || Instant::now() > quit_until {
            break after;
        }
        std::thread::sleep(Duration::from_millis(200));
    };
    let _ = tmux(&socket, &["kill-server"]);
    assert!(
        pane.contains(&format!(
            "terminal 60x15 is too small: need {MIN_WIDTH}x{MIN_HEIGHT}"
        )),
        "the pane shows:\n{pane}"
    );
    assert!(!pane.contains("r2 "), "a cut panel:\n{pane}");
    assert!(after.contains("EXITED 0"), "after q:\n{after}");
}
