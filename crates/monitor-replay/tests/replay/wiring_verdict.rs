//! Issue 86, item 1: wiring is judged before any verdict. A fault log of the simulator
//! (Rr +50 % after commissioning, on the 2.2 kW and the 3 hp reference machines) names
//! its fault as logged; with b and c exchanged in both the voltages and the currents, with
//! two currents exchanged, or with one current reversed, it names no fault: the verdict is
//! "could not judge" on the data quality, whose reason is the wiring finding. No report
//! holds a negative-sequence ratio above 100 % as a judged winding's measurement.

use monitor_core::verdict::Rule;
use monitor_io::log::quality::wiring::WiringFault;
use monitor_io::log::{Channels, Row};
use monitor_io::params::ParamFile;
use monitor_replay::{diagnose_rows, CommissionWindow, DiagnoseReport, ReplayOptions, Verdict};
use monitor_sim::{simulate_to_vec, Scenario};

fn log(params: &ParamFile) -> Vec<Row> {
    let text = "duration_s = 6.0\nsample_rate_hz = 2000.0\nseed = 8\n\
                [[faults]]\nkind = \"rr\"\nat_s = 3.5\nchange = 0.5\n";
    let sc = Scenario::from_toml_str(text, "wiring").expect("scenario"); // ok: test
    simulate_to_vec(params, &sc).expect("simulate") // ok: test
}

fn diagnose(params: &ParamFile, rows: &[Row]) -> DiagnoseReport {
    let channels = Channels {
        voltages: true,
        speed: true,
        encoder: false,
        temperature: false,
    };
    let opts = ReplayOptions {
        commission: Some(CommissionWindow::of(1.2, 3.2)),
        allow_incomplete: true,
        ..ReplayOptions::default()
    };
    diagnose_rows(params, channels, rows, opts).expect("diagnose") // ok: test
}

type Mutation = (&'static str, fn(&mut Row), fn(&WiringFault) -> bool);

#[test]
fn mixed_up_channels_are_wiring_never_a_fault_on_two_motor_sizes() {
    let mutations: [Mutation; 3] = [
        (
            "b and c exchanged in V and I",
            |r| {
                if let Some(v) = r.v_abc.as_mut() {
                    v.swap(1, 2);
                }
                r.i_abc.swap(1, 2);
            },
            |f| matches!(f, WiringFault::PhaseOrderReversed { .. }),
        ),
        (
            "ib and ic exchanged",
            |r| r.i_abc.swap(1, 2),
            |f| matches!(f, WiringFault::Exchanged { .. }),
        ),
        (
            "ia reversed",
            |r| r.i_abc[0] = -r.i_abc[0],
            |f| matches!(f, WiringFault::Reversed { .. }),
        ),
    ];
    for params in [ParamFile::reference_2p2kw(), ParamFile::reference_3hp()] {
        let rows = log(&params);
        let clean = diagnose(&params, &rows);
        assert_eq!(
            clean.verdict,
            Verdict::Fault,
            "as logged: {:?}",
            clean.verdict_finding
        );
        assert!(clean.data_quality.wiring.is_empty());
        for (what, m, expected) in mutations {
            let mut mixed = rows.clone();
            mixed.iter_mut().for_each(m);
            let rep = diagnose(&params, &mixed);
            assert!(
                rep.data_quality.wiring.iter().any(expected),
                "{what}: {:?}",
                rep.data_quality.wiring
            );
            assert_eq!(
                rep.verdict,
                Verdict::CouldNotJudge,
                "{what}: {:?}",
                rep.verdict_finding
            );
            assert_eq!(rep.verdict_rule, Rule::DataUntrusted, "{what}");
            assert!(
                rep.findings.iter().all(|f| f.named().is_none()),
                "{what}: {:?}",
                rep.findings
            );
        }
    }
}
