//! The QEMU program's embedded data (`crates/core-on-m4/data/{replay,expected}.bin`) is a
//! simulated log and the host build of the core's answers to it, and stays in step with
//! both: this test regenerates them and compares with the committed files.
//!
//! The log: the 2.2 kW reference machine (sim-host simulator, ideal sensors) started
//! direct-on-line with a 14.6 N m load torque; 1.2 s from t = 2 s at 10 kHz, with the rotor
//! resistance rising 50 % at t = 2.3 s; quantised by the board's front end (+-400 V,
//! +-10 A, 12 bit) and a 16-bit encoder counter. The expected outputs are the host's
//! `Monitor` at every 100th sample.
//!
//! After a change to the core or to the scenario, regenerate with
//! `REGENERATE_QEMU_DATA=1 cargo test --test firmware -- qemu_replay_data::` and commit the files; then
//! `cargo qemu-core` checks the Cortex-M4F build against them.

#[path = "../../crates/core-on-m4/src/scenario.rs"]
#[allow(dead_code, missing_docs)]
mod scenario;

use monitor_core::Fault;
use monitor_core::Monitor;
use monitor_io::params::ParamFile;
use monitor_sim::{simulate, FaultSpec, LoadKind, LoadSpec, Scenario};
use std::path::PathBuf;

const START_S: f64 = 2.0;
const SAMPLES: usize = 12_000;
const SPACING: usize = 100;

fn generate() -> (Vec<u8>, Vec<u8>) {
    let p = ParamFile::reference_2p2kw();
    let mut sc = Scenario::steady(START_S + SAMPLES as f64 / 10_000.0 + 0.01, 10_000.0);
    sc.load = LoadSpec {
        kind: LoadKind::Torque,
        torque_nm: Some(14.6),
        bl_nms: None,
        steps: vec![],
    };
    sc.faults
        .push(FaultSpec::parametric(Fault::Rr, START_S + 0.3, 0.5));
    let mut replay = Vec::with_capacity(scenario::REPLAY_HEADER + SAMPLES * scenario::SAMPLE_BYTES);
    replay.extend_from_slice(b"RPL1");
    replay.extend_from_slice(&(SAMPLES as u32).to_le_bytes());
    let code = |x: f64, per_lsb: f32| -> u16 {
        (x / f64::from(per_lsb) + f64::from(scenario::MID) + 0.5).clamp(0.0, 4095.0) as u16
    };
    let mut n = 0usize;
    simulate(&p, &sc, |row| {
        if row.t_s + 1e-9 < START_S || n >= SAMPLES {
            return;
        }
        n += 1;
        let v = row.v_abc.unwrap_or_default();
        let mut words = [0u16; 7];
        for k in 0..3 {
            words[k] = code(v[k], scenario::VOLT_PER_LSB);
            words[3 + k] = code(row.i_abc[k], scenario::AMP_PER_LSB);
        }
        words[6] = (row.enc_count.unwrap_or_default() & 0xFFFF) as u16;
        for w in words {
            replay.extend_from_slice(&w.to_le_bytes());
        }
    })
    .expect("simulate");
    assert_eq!(n, SAMPLES);

    let mut monitor = Monitor::new(scenario::config()).expect("config");
    let mut expected = Vec::new();
    expected.extend_from_slice(b"EXP1");
    expected.extend_from_slice(&((SAMPLES / SPACING) as u32).to_le_bytes());
    expected.extend_from_slice(&(SPACING as u32).to_le_bytes());
    let mut lamps_seen = 0u8;
    for k in 0..SAMPLES {
        let out = *monitor.update(&scenario::sample(&replay, k));
        if (k + 1) % SPACING == 0 {
            let c = scenario::Check::of(&out);
            lamps_seen |= c.lamps;
            expected.extend_from_slice(&c.bytes());
        }
    }
    // The replay exercises the lamps: the Rr fault lights r1 before the end.
    assert!(lamps_seen & 1 != 0, "the replay never lights r1");
    (replay, expected)
}

#[test]
fn qemu_replay_data_is_the_simulated_log_and_the_hosts_answers() {
    let dir = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("crates/core-on-m4/data");
    let (replay, expected) = generate();
    if std::env::var_os("REGENERATE_QEMU_DATA").is_some() {
        std::fs::write(dir.join("replay.bin"), &replay).expect("write replay.bin");
        std::fs::write(dir.join("expected.bin"), &expected).expect("write expected.bin");
        return;
    }
    let committed_replay = std::fs::read(dir.join("replay.bin")).expect("replay.bin");
    let committed_expected = std::fs::read(dir.join("expected.bin")).expect("expected.bin");
    assert!(
        committed_replay == replay,
        "crates/core-on-m4/data/replay.bin is stale: REGENERATE_QEMU_DATA=1 cargo test --test firmware -- qemu_replay_data::"
    );
    assert!(
        committed_expected == expected,
        "crates/core-on-m4/data/expected.bin is stale: REGENERATE_QEMU_DATA=1 cargo test --test firmware -- qemu_replay_data::"
    );
}
