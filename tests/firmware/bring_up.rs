//! The bring-up a first board gets (issue 51): `cargo fw-run`'s runner lets the firmware's
//! own handlers run (probe-rs catches neither the reset nor the HardFault), and
//! docs/firmware.md's bring-up checklist puts the steps in the order a board needs them:
//! the probe and the part's revision, the motor record into flash, the crystal, the
//! debugger, the brown-out level, the run with the handlers visible, the registers read
//! back (`cargo fw bring-up`), the boot report, ..., an hour without an overrun, the fault
//! injections.

use std::path::Path;

fn read(rel: &str) -> String {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join(rel);
    std::fs::read_to_string(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()))
}

#[test]
fn the_runner_lets_the_firmwares_handlers_run() {
    let config = read(".cargo/config.toml");
    let runner = config
        .lines()
        .find(|l| l.trim_start().starts_with("runner"))
        .expect("a runner in .cargo/config.toml");
    for flag in [
        "probe-rs run",
        "--chip STM32G474RETx",
        "--no-catch-reset",
        "--no-catch-hardfault",
    ] {
        assert!(runner.contains(flag), "the runner lacks {flag}: {runner}");
    }
}

#[test]
fn the_bring_up_list_runs_record_brown_out_handlers_boot_report() {
    let docs = read("docs/firmware.md");
    let start = docs.find("## Bring-up checklist").expect("the checklist");
    let end = docs[start + 3..]
        .find("\n## ")
        .map_or(docs.len(), |e| start + 3 + e);
    let list = &docs[start..end];
    // The numbered items' titles, in order.
    let titles: Vec<&str> = list
        .lines()
        .filter_map(|l| {
            let (n, rest) = l.split_once(". **")?;
            n.trim().parse::<u32>().ok()?;
            rest.split("**").next()
        })
        .collect();
    let at = |what: &str| {
        titles
            .iter()
            .position(|t| t.to_lowercase().contains(what))
            .unwrap_or_else(|| panic!("no step {what:?} in {titles:?}"))
    };
    let order = [
        at("probe and the part"),
        at("motor record"),
        at("crystal"),
        at("debugger"),
        at("brown-out"),
        at("handlers visible"),
        at("cargo fw bring-up"),
        at("boot report"),
        at("virtual com port"),
        at("offset trim"),
        at("status line"),
        at("commission"),
        at("an hour"),
        at("fault injections"),
        at("faults that recover"),
    ];
    assert!(order.windows(2).all(|w| w[0] < w[1]), "{titles:?}");
    // The brown-out step names the command that programs it.
    assert!(list.contains("cargo fw bor"));
    // Issue 74's checks are in the list: flip-link before the first run, the counters on
    // the status line, the stored reference, the clock security system, the panel's marks,
    // the range state (clipping that persists in steady running).
    for needle in [
        "cargo\n   install flip-link --locked",
        "`clip=`",
        "`enc_rej=`",
        "`stack=`",
        "readings corrected by",
        "clock security system",
        "from 2.5 s to 4.5 s",
        "115 200 baud",
        "`clip_range=false`",
        "from 7.5 s to 9.5 s",
        // Issue 82's: the part's revision, the registers read back, the hour, the injections.
        "REV_ID",
        "ES0430",
        "`overruns=0`",
        "*a breakpoint*",
        "*the encoder unplugged*",
        "*an input at the rail*",
        "*a stopped crystal*",
        "*a stack-overflow build*",
        "*power cuts*",
        "*a supply ramp through 2.8 V*",
        "*a forced reset loop*",
        "SAFE MODE (code 1)",
    ] {
        assert!(list.contains(needle), "the checklist lacks {needle:?}");
    }
}
