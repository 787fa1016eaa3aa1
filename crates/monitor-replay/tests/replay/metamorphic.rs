//! Metamorphic robustness: single mutations of a healthy and a faulty log (what data
//! acquisition systems and damaged files do to logs) must never turn the healthy verdict
//! into a named fault, nor change the faulty log's named fault. Each mutation ends in the
//! right answer, in "could not judge" with a reason, or in a refusal naming the problem.
//!
//! The logs: the 2.2 kW reference machine, 10 s at 5 kHz with 12-bit noise, a DOL start,
//! commissioned over 2..4 s; the faulty one has Rr +50 % from 6 s. The speed comes from the
//! encoder count alone (no `wm_rad_s`), the harder case for the encoder mutations; a second
//! set runs with both speed channels.

use monitor_core::Fault;
use monitor_io::log::{Channels, Row, ENC_COUNT_UNREADABLE};
use monitor_io::params::ParamFile;
use monitor_replay::{diagnose_rows, DiagnoseReport, IsolationName, ReplayOptions, Verdict};
use monitor_sim::{simulate_to_vec, Scenario};

const RATE_HZ: f64 = 5000.0;

fn log(fault: bool) -> Vec<Row> {
    let text = format!(
        "duration_s = 10.0\nsample_rate_hz = {RATE_HZ}\nseed = 3\n[sensors]\nencoder = true\n{}",
        if fault {
            "[[faults]]\nkind = \"rr\"\nat_s = 6.0\nchange = 0.5\n"
        } else {
            ""
        }
    );
    let sc = Scenario::from_toml_str(&text, "metamorphic").expect("scenario"); // ok: test
    simulate_to_vec(&ParamFile::reference_2p2kw(), &sc).expect("simulate") // ok: test
}

fn diagnose(rows: &[Row], speed: bool) -> Result<DiagnoseReport, String> {
    let channels = Channels {
        voltages: true,
        speed,
        encoder: true,
        temperature: false,
    };
    let rows: Vec<Row> = rows
        .iter()
        .map(|r| Row {
            wm_rad_s: r.wm_rad_s.filter(|_| speed),
            ..*r
        })
        .collect();
    let opts = ReplayOptions {
        commission: Some(monitor_replay::CommissionWindow::of(2.0, 4.0)),
        ..ReplayOptions::default()
    };
    diagnose_rows(&ParamFile::reference_2p2kw(), channels, &rows, opts).map_err(|e| e.to_string())
}

/// Index of the row at `t` [s].
fn at(t: f64) -> usize {
    (t * RATE_HZ) as usize
}

type Mutation = (&'static str, fn(Vec<Row>) -> Vec<Row>);

/// The mutations, each one class of what the data-quality stage must catch.
fn mutations() -> Vec<Mutation> {
    vec![
        ("encoder count NaN in one row", |mut r| {
            r[at(5.0)].enc_count = Some(ENC_COUNT_UNREADABLE);
            r
        }),
        ("encoder count 2^63-1 in one row", |mut r| {
            r[at(5.0)].enc_count = Some(i64::MAX);
            r
        }),
        ("53 corrupted encoder counts", |mut r| {
            let mut x = 0x2545_f491_4f6c_dd1du64;
            for k in 0..53 {
                x ^= x << 13;
                x ^= x >> 7;
                x ^= x << 17;
                let i = at(4.5) + 97 * k;
                r[i].enc_count = Some(x as i64);
            }
            r
        }),
        (
            "encoder count unreadable from 5 s (a 64-bit counter past 2^53)",
            |mut r| {
                for x in &mut r[at(5.0)..] {
                    x.enc_count = Some(ENC_COUNT_UNREADABLE);
                }
                r
            },
        ),
        ("16-bit encoder counter", |mut r| {
            for x in &mut r {
                x.enc_count = x.enc_count.map(|c| c.rem_euclid(1 << 16));
            }
            r
        }),
        ("encoder counter wrapping at 2^63", |mut r| {
            for x in &mut r {
                x.enc_count = x.enc_count.map(|c| c.wrapping_add(i64::MAX - 300_000));
            }
            r
        }),
        ("encoder counter re-zeroed at 5 s", |mut r| {
            let c0 = r[at(5.0)].enc_count.unwrap_or(0);
            for x in &mut r[at(5.0)..] {
                x.enc_count = x.enc_count.map(|c| c - c0);
            }
            r
        }),
        ("clock reset: 1 s back at 7.5 s", |mut r| {
            for x in &mut r[at(7.5)..] {
                x.t_s -= 1.0;
            }
            r
        }),
        ("2 s stall, rows lost", |r| {
            [&r[..at(6.5)], &r[at(8.5)..]].concat()
        }),
        ("10 s lost in a stall", |mut r| {
            for x in &mut r[at(6.5)..] {
                x.t_s += 10.0;
            }
            r
        }),
        ("two copies concatenated", |r| [r.clone(), r].concat()),
        ("sample rate halves at 6 s", |r| {
            let tail: Vec<Row> = r[at(6.0)..].iter().step_by(2).copied().collect();
            [&r[..at(6.0)], &tail[..]].concat()
        }),
        ("phase-a current frozen for 2 s", |mut r| {
            let held = r[at(6.5)].i_abc[0];
            for x in &mut r[at(6.5)..at(8.5)] {
                x.i_abc[0] = held;
            }
            r
        }),
        ("currents ib and ic swapped", |mut r| {
            for x in &mut r {
                x.i_abc.swap(1, 2);
            }
            r
        }),
        ("ia copied over ib", |mut r| {
            for x in &mut r {
                x.i_abc[1] = x.i_abc[0];
            }
            r
        }),
        ("all currents zero", |mut r| {
            for x in &mut r {
                x.i_abc = [0.0; 3];
            }
            r
        }),
        ("NaN and inf current cells", |mut r| {
            r[at(5.0)].i_abc[1] = f64::NAN;
            r[at(7.0)].i_abc[2] = f64::INFINITY;
            r
        }),
        ("1 % of the samples dropped", |r| {
            r.into_iter()
                .enumerate()
                .filter(|(k, _)| k % 100 != 37)
                .map(|(_, x)| x)
                .collect()
        }),
        ("time in milliseconds", |mut r| {
            for x in &mut r {
                x.t_s *= 1000.0;
            }
            r
        }),
        ("0.5 s log of the start only", |mut r| {
            r.truncate(at(0.5));
            r
        }),
    ]
}

/// Whether a verdict withheld says why: the finding it rests on, or a fault-judging
/// finding that could not judge (what the door spells as `verdict_withheld_because`).
fn gives_a_reason(r: &DiagnoseReport) -> bool {
    r.verdict_finding.is_some()
        || r.findings
            .iter()
            .any(|f| f.source().judges_faults() && f.judged_nothing())
}

/// What a mutation may end in, for the log's true answer `named` (None: healthy).
fn judge(
    name: &str,
    outcome: &Result<DiagnoseReport, String>,
    named: Option<Fault>,
) -> Result<(), String> {
    let r = match outcome {
        Err(e) if !e.trim().is_empty() => return Ok(()),
        Err(_) => return Err(format!("{name}: refused without a reason")),
        Ok(r) => r,
    };
    match (r.verdict, named) {
        (Verdict::CouldNotJudge, _) if !gives_a_reason(r) => {
            Err(format!("{name}: could not judge, but gives no reason"))
        }
        (Verdict::CouldNotJudge, _) => Ok(()),
        // A name below the size a fault needs, said with its reason: no crew sent.
        (Verdict::Watching, _) if !gives_a_reason(r) => {
            Err(format!("{name}: watching, but gives no reason"))
        }
        (Verdict::Watching, _) => Ok(()),
        (Verdict::Healthy, None) => Ok(()),
        (Verdict::Healthy, Some(f)) => Err(format!("{name}: the {f:?} fault was missed")),
        (Verdict::Fault, want) => {
            let got: Vec<Fault> = r.detections.iter().map(|d| d.fault).collect();
            let isolated = r.isolation.named;
            match want {
                None => Err(format!(
                    "{name}: a healthy log judged faulty: detections {got:?}, isolated {isolated:?}"
                )),
                Some(f)
                    if isolated.is_none_or(|n| n == IsolationName::Fault(f))
                        && got.iter().all(|g| *g == f) =>
                {
                    Ok(())
                }
                Some(f) => Err(format!(
                    "{name}: {f:?} became detections {got:?}, isolated {isolated:?}"
                )),
            }
        }
    }
}

fn check_all(speed: bool) {
    let healthy = log(false);
    let faulty = log(true);
    // The unmutated logs give the right answers (else the test proves nothing).
    let h = diagnose(&healthy, speed).expect("healthy log"); // ok: test
    assert_eq!(h.verdict, Verdict::Healthy, "{:?}", h.findings);
    let f = diagnose(&faulty, speed).expect("faulty log"); // ok: test
    assert_eq!(f.verdict, Verdict::Fault);
    assert_eq!(f.isolation.named, Some(IsolationName::Fault(Fault::Rr)));
    let mut wrong = Vec::new();
    for (name, mutate) in mutations() {
        for (rows, truth) in [(&healthy, None), (&faulty, Some(Fault::Rr))] {
            let outcome = diagnose(&mutate(rows.clone()), speed);
            if let Err(e) = judge(name, &outcome, truth) {
                wrong.push(e);
            }
        }
    }
    assert!(
        wrong.is_empty(),
        "{} wrong:\n{}",
        wrong.len(),
        wrong.join("\n")
    );
}

#[test]
fn single_mutations_never_name_a_wrong_fault_encoder_only() {
    check_all(false);
}

#[test]
fn single_mutations_never_name_a_wrong_fault_with_a_speed_channel() {
    check_all(true);
}
