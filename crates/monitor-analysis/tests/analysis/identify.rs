//! `monitor_analysis::identify` against known circuits: six machines (0.37 kW to 50 hp, the
//! same as `crates/monitor-io/tests/io/nameplate.rs`; five published), each simulated from
//! standstill with ±8 % supply steps and the default 12-bit sensors (ADC quantisation and
//! noise), identified from the nameplate estimate (`params from-nameplate`'s, its nameplate
//! computed from the circuit at rated power by the analytic steady state) at 5 and 10 kHz:
//! Rs, Rr, the total leakage and Lm against the published circuit (10 %) and against the
//! same circuit with the start file's leakage split (1 %; the split is what no terminal log
//! can tell). Also: a log that cannot identify some parameters says so, and the identified
//! parameters name the same faults as the true ones. (The command, `sim-host identify`:
//! `sim-host/tests/cli/identify.rs`.) The machines: `monitor_testkit::identify_machines`.
//!
//! All ten runs (3 s logs) take about 2 s in the test profile.

use monitor_analysis::identify::{identify, Identification, InverseGamma, Samples};
use monitor_io::log::{Channels, Row};
use monitor_io::params::ParamFile;
use monitor_sim::{Scenario, SensorSpec, SupplyStep};
use monitor_testkit::identify_machines::{machines, Machine};

/// A start from standstill with ±8 % supply steps every 0.5 s from 1 s (time for the
/// largest machine to run up), 12-bit sensors with their default noise.
fn healthy_log(m: &Machine, rate_hz: f64, duration_s: f64) -> Vec<Row> {
    let mut sc = Scenario::steady(duration_s, rate_hz);
    sc.sensors = SensorSpec::default();
    sc.supply.steps = (0..)
        .map(|k| 1.0 + 0.5 * k as f64)
        .take_while(|t| *t < duration_s)
        .enumerate()
        .map(|(k, t)| SupplyStep {
            t_s: t,
            v_scale: Some(if k % 2 == 0 { 0.92 } else { 1.0 }),
            f_hz: None,
        })
        .collect();
    monitor_sim::simulate_to_vec(&m.truth(), &sc).expect("simulates")
}

fn channels() -> Channels {
    Channels {
        voltages: true,
        speed: true,
        encoder: true,
        temperature: false,
    }
}

/// The machine's circuit re-expressed with the stator leakage share `f` = Lls / (Lls +
/// Llr): the T-circuit with that split and the same terminal behaviour (the same
/// inverse-Gamma parameters L_sigma = Lls + Lm Llr / Lr, L_M = Lm^2 / Lr and
/// R_R = Rr (Lm / Lr)^2; Slemon, "Modelling of induction machines for electric drives",
/// IEEE Trans. Ind. Appl. 25(6), 1989). Returns [Rs, Rr, Lls + Llr, Lm].
fn with_split(t: [f64; 5], f: f64) -> [f64; 4] {
    let [rs, rr, lls, llr, lm] = t;
    let lr = lm + llr;
    let (l_sigma, l_m, r_r) = (lls + lm * llr / lr, lm * lm / lr, rr * (lm / lr).powi(2));
    // For a total leakage L: Lm from L_M = Lm^2 / (Lm + (1 - f) L), then L_sigma(L),
    // increasing in L: bisection.
    let lm_of = |l: f64| 0.5 * (l_m + (l_m * l_m + 4.0 * l_m * (1.0 - f) * l).sqrt());
    let sigma_of = |l: f64| {
        let m = lm_of(l);
        f * l + m * (1.0 - f) * l / (m + (1.0 - f) * l)
    };
    let (mut lo, mut hi) = (0.0, 10.0 * l_sigma);
    for _ in 0..200 {
        let mid = 0.5 * (lo + hi);
        if sigma_of(mid) < l_sigma {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    let l = 0.5 * (lo + hi);
    let m = lm_of(l);
    let lr_f = m + (1.0 - f) * l;
    [rs, r_r * (lr_f / m).powi(2), l, m]
}

/// Relative errors of (Rs, Rr, Lls + Llr, Lm) against `truth`.
fn errors(name: &str, truth: [f64; 4], id: &Identification) -> [f64; 4] {
    let mut e = [f64::NAN; 4];
    for (k, t) in truth.iter().enumerate() {
        let v = id.estimates[k]
            .value
            .unwrap_or_else(|| panic!("{name}: {} not identified", id.estimates[k].name));
        e[k] = v / t - 1.0;
    }
    e
}

fn pct(e: [f64; 4]) -> String {
    format!(
        "Rs {:+.2} %, Rr {:+.2} %, Lls+Llr {:+.2} %, Lm {:+.2} %",
        100.0 * e[0],
        100.0 * e[1],
        100.0 * e[2],
        100.0 * e[3]
    )
}

/// Identifies machine `m` from a 3 s log at `rate_hz`: the errors against the published
/// circuit, against the same circuit with the start file's leakage split, and of the
/// split-free (inverse-Gamma) form against the circuit's.
fn check_machine(m: &Machine, rate_hz: f64) -> ([f64; 4], [f64; 4], [f64; 4]) {
    let rows = healthy_log(m, rate_hz, 3.0);
    let s =
        Samples::from_rows(&rows, channels(), f64::NEG_INFINITY, f64::INFINITY).expect("samples");
    let id = identify(&m.start(), &s, &mut |_| {}).expect("identifies");
    let raw = errors(m.name, [m.t[0], m.t[1], m.t[2] + m.t[3], m.t[4]], &id);
    let eq = errors(m.name, with_split(m.t, id.stator_leakage_share), &id);
    let [rs, rr, lls, llr, lm] = m.t;
    let truth_g = InverseGamma::of_t_circuit(rs, rr, lls, llr, lm);
    let g = id.inverse_gamma.expect("all four identified");
    let gamma = [
        g.rs_ohm / truth_g.rs_ohm - 1.0,
        g.r_r_ohm / truth_g.r_r_ohm - 1.0,
        g.l_sigma_h / truth_g.l_sigma_h - 1.0,
        g.l_m_h / truth_g.l_m_h - 1.0,
    ];
    eprintln!(
        "{} at {} kHz: {} | with the start's split {:.2}: {} | inverse-Gamma R_R {:+.2} %, L_sigma {:+.2} %, \
         L_M {:+.2} % (current error {:.2} %, start {:.2} %)",
        m.name,
        rate_hz / 1000.0,
        pct(raw),
        id.stator_leakage_share,
        pct(eq),
        100.0 * gamma[1],
        100.0 * gamma[2],
        100.0 * gamma[3],
        100.0 * id.relative_rms_error,
        100.0 * id.relative_rms_error_start
    );
    (raw, eq, gamma)
}

/// The bars: against the circuit with the start file's leakage split (what a log can
/// determine) within 1 %, and its split-free (inverse-Gamma) form within 1 %; against the
/// published circuit within 10 %. A machine is judged in the form it is published in:
/// motulator publishes its 2.2 kW machine in inverse-Gamma form (all its leakage on the
/// stator side), and a T-circuit with the nameplate estimate's 0.4 : 0.6 split (NEMA
/// design B) has an Rr (1 + 0.6 L / Lm)^2 - 1 = +11.6 % above that form's R_R: the same
/// terminals, which no log can tell apart. Its T-circuit errors are printed only.
fn check_rate(rate_hz: f64) {
    for m in machines() {
        let (raw, eq, gamma) = check_machine(&m, rate_hz);
        let inverse_gamma_published = m.name.starts_with("motulator");
        for (k, what) in ["Rs", "Rr", "Lls + Llr", "Lm"].iter().enumerate() {
            assert!(
                eq[k].abs() <= 0.01 && gamma[k].abs() <= 0.01,
                "{} at {rate_hz} Hz: {what} off by {:+.2} % from the equivalent circuit ({:+.2} % in \
                 inverse-Gamma form)",
                m.name,
                100.0 * eq[k],
                100.0 * gamma[k]
            );
            let published = if inverse_gamma_published {
                gamma[k]
            } else {
                raw[k]
            };
            assert!(
                published.abs() <= 0.10,
                "{} at {rate_hz} Hz: {what} off by {:+.1} % from the published circuit",
                m.name,
                100.0 * published
            );
        }
    }
}

#[test]
fn six_machines_at_5_khz_from_the_nameplate_estimate() {
    check_rate(5000.0);
}

#[test]
fn six_machines_at_10_khz_from_the_nameplate_estimate() {
    check_rate(10_000.0);
}

#[test]
fn steady_running_at_one_point_says_what_it_cannot_identify() {
    let all = machines();
    let m = &all[0];
    // No supply steps: a start, then 1.5 s of steady running at one point, fitted alone.
    let mut sc = Scenario::steady(3.0, 5000.0);
    sc.sensors = SensorSpec::default();
    let rows = monitor_sim::simulate_to_vec(&m.truth(), &sc).expect("simulates");
    let s = Samples::from_rows(&rows, channels(), 1.5, f64::INFINITY).expect("samples");
    assert!(!s.starts_dead);
    let id = identify(&m.start(), &s, &mut |_| {}).expect("runs");
    let not: Vec<&str> = id
        .estimates
        .iter()
        .filter(|e| e.value.is_none())
        .map(|e| e.name.as_str())
        .collect();
    eprintln!("one steady point: not identified {not:?}");
    for e in &id.estimates {
        eprintln!("  {} {:?} {:?}", e.name, e.value, e.not_identified_because);
    }
    assert!(not.contains(&"J"), "{not:?}");
    let electrical = ["Rs", "Rr", "Lls + Llr", "Lm"];
    assert!(
        electrical.iter().filter(|n| not.contains(n)).count() >= 2,
        "one steady point gives two real equations for four parameters: {not:?}"
    );
    for e in id.estimates.iter().filter(|e| e.value.is_none()) {
        assert!(e
            .not_identified_because
            .as_deref()
            .is_some_and(|w| !w.is_empty()));
    }
}

/// The fault the isolation names for `fault` at `change` on `truth`, the replay told
/// `told` (the Table 1 protocol: commissioning 2-4 s, the fault at 4.5 s).
fn named(
    truth: &ParamFile,
    told: &ParamFile,
    fault: monitor_core::Fault,
    change: f64,
) -> Option<monitor_replay::IsolationName> {
    use monitor_studies::fault_signatures::{scenario, Protocol};
    let proto = Protocol::default();
    let opts = monitor_replay::ReplayOptions {
        angle_source: proto.angle_source,
        commission: Some(proto.commission),
        ..Default::default()
    };
    let sc = scenario(Some((fault, change)), &proto);
    monitor_studies::experiment::simulate_and_replay(truth, told, &sc, opts, |_, _| {})
        .expect("runs")
        .finish()
        .isolation
        .named
}

/// The reference machine's parameters identified from the Table 1 protocol's healthy
/// run (a start with the viscous load, 10 kHz, 12-bit sensors), 4 s, from its nameplate
/// estimate.
fn identified(truth: &ParamFile, m: &Machine) -> ParamFile {
    use monitor_studies::fault_signatures::{scenario, Protocol};
    let proto = Protocol::default();
    let rows = monitor_sim::simulate_to_vec(truth, &scenario(None, &proto)).expect("simulates");
    let s = Samples::from_rows(&rows, channels(), 0.0, 4.0).expect("samples");
    identify(&m.start(), &s, &mut |_| {})
        .expect("identifies")
        .params
}

/// The stretch goal: `diagnose` with the identified parameters names the same fault as
/// with the true ones, for every Table 1 fault at ±50 % on two motors: the 3 hp reference
/// motor and the Simscape 4 kW machine (a circuit the project was not developed on). With
/// `MONITOR_FULL_SWEEPS=1` also the 2.2 kW reference, where the bar is lower: never a
/// different fault. Its machine has no stator leakage and the nameplate estimate splits
/// the leakage 0.4 : 0.6; measured: the `ls` fault (which on that machine scales Lm
/// itself) at ±50 % is named with the true parameters and left unnamed with the
/// identified ones, the 16 other cases agree.
#[test]
fn the_identified_parameters_name_the_same_faults_as_the_true_ones() {
    use rayon::prelude::*;
    let mut motors = vec![(
        ParamFile::reference_3hp(),
        Machine {
            name: "3 hp reference",
            p_kw: 3.0 * 0.7457,
            v_ll: 220.0,
            f_hz: 60.0,
            t: [0.0; 5],
            j: 0.0,
        },
    )];
    let simscape = machines()
        .into_iter()
        .find(|m| m.name == "Simscape 4 kW")
        .expect("listed");
    motors.push((simscape.truth(), simscape));
    if std::env::var("MONITOR_FULL_SWEEPS").is_ok_and(|v| v == "1") {
        motors.push((
            ParamFile::reference_2p2kw(),
            Machine {
                name: "2.2 kW reference",
                p_kw: 2.2,
                v_ll: 400.0,
                f_hz: 50.0,
                t: [0.0; 5],
                j: 0.0,
            },
        ));
    }
    for (truth, mut m) in motors {
        let p = truth.motor;
        m.t = [p.rs_ohm, p.rr_ohm, p.ls_h - p.lm_h, p.lr_h - p.lm_h, p.lm_h];
        m.j = p.j_kgm2;
        m.v_ll = truth.supply.v_ll_rms;
        m.f_hz = truth.supply.f_hz;
        let told = identified(&truth, &m);
        let cases: Vec<(monitor_core::Fault, f64)> = monitor_core::Fault::ALL
            .iter()
            .flat_map(|f| [(*f, 0.5), (*f, -0.5)])
            .collect();
        let exact = m.name != "2.2 kW reference";
        let diffs: Vec<String> = cases
            .par_iter()
            .filter_map(|&(f, c)| {
                let a = named(&truth, &truth, f, c);
                let b = named(&truth, &told, f, c);
                eprintln!("{} {f} {c:+}: true {a:?}, identified {b:?}", m.name);
                let wrong = if exact { a != b } else { b.is_some() && a != b };
                wrong.then(|| format!("{f} {c:+}: true params name {a:?}, identified {b:?}"))
            })
            .collect();
        assert!(diffs.is_empty(), "{}: {diffs:#?}", m.name);
    }
}
