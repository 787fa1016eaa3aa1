//! The cases of the isolation's calibration (`isolation_calibration.rs`, beside it): each drawn
//! from its seed, simulated and replayed (its module docs say what is drawn).
#![allow(dead_code)]

use monitor_core::{AngleSource, Fault};
use monitor_io::params::ParamFile;
use monitor_replay::{IsolationEvent, IsolationName, ReplayOptions};
use monitor_sim::{EffectSpec, FaultSpec, LoadSpec, LoadStep, Scenario, SensorSpec};
use monitor_testkit::small_motor;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

/// The three motors.
pub fn motors() -> [(&'static str, ParamFile); 3] {
    [
        ("3 hp", ParamFile::reference_3hp()),
        ("2.2 kW", ParamFile::reference_2p2kw()),
        ("50 hp", small_motor::krause_50hp()),
    ]
}

/// Log length [s], sample rate [Hz] and when the fault arrives [s].
pub const DURATION_S: f64 = 30.0;
pub const RATE_HZ: f64 = 4000.0;
pub const FAULT_AT_S: f64 = 16.0;
/// How often the moving load steps [s].
const LOAD_PERIOD_S: f64 = 3.0;

/// One drawn case.
#[derive(Debug, Clone, Copy)]
pub struct Case {
    pub seed: u64,
    pub motor: usize,
    pub fault: Option<(Fault, f64)>,
    pub angle: AngleSource,
    /// Rise [K], time constant [s], from [s].
    pub warming: Option<(f64, f64, f64)>,
    pub moving: bool,
    /// The file's factors on Rs, Rr, the leakages and Lm (true machine times these).
    pub file_off: Option<[f64; 4]>,
    pub noise_scale: f64,
    pub commissioned: bool,
}

/// Draws the case of `seed` (module docs).
pub fn draw(seed: u64) -> Case {
    let mut g = ChaCha8Rng::seed_from_u64(seed);
    let sign = |g: &mut ChaCha8Rng| if g.gen_bool(0.5) { 1.0 } else { -1.0 };
    let fault = if g.gen_bool(0.12) {
        None
    } else {
        let f = Fault::ALL[g.gen_range(0..Fault::ALL.len())];
        let sizes: &[f64] = if f.is_sensor() {
            &[0.05, 0.1, 0.2, 0.35]
        } else {
            &[0.05, 0.1, 0.2, 0.35, 0.5]
        };
        let size = sizes[g.gen_range(0..sizes.len())] * sign(&mut g);
        Some((f, size))
    };
    let moving = g.gen_bool(0.5);
    let warming = g.gen_bool(0.5).then(|| {
        let from = if g.gen_bool(0.5) { 0.0 } else { 6.0 };
        (g.gen_range(10.0..60.0), g.gen_range(20.0..300.0), from)
    });
    let file_off = g.gen_bool(0.5).then(|| {
        [
            1.0 + sign(&mut g) * g.gen_range(0.08..0.2),
            1.0 + sign(&mut g) * g.gen_range(0.08..0.2),
            1.0 + sign(&mut g) * g.gen_range(0.1..0.2),
            1.0 + sign(&mut g) * g.gen_range(0.03..0.08),
        ]
    });
    Case {
        seed,
        motor: g.gen_range(0..3),
        fault,
        angle: if g.gen_bool(0.5) {
            AngleSource::RotorFluxCurrentModel
        } else {
            AngleSource::Pll
        },
        warming,
        moving,
        file_off,
        noise_scale: if g.gen_bool(0.25) { 4.0 } else { 1.0 },
        commissioned: g.gen_bool(0.9),
    }
}

/// The parameter file of `p` off by `k` (Rs, Rr, leakages, Lm).
pub fn off(p: &ParamFile, k: [f64; 4]) -> ParamFile {
    let mut q = *p;
    let m = &mut q.motor;
    let (lls, llr) = (m.ls_h - m.lm_h, m.lr_h - m.lm_h);
    m.rs_ohm *= k[0];
    m.rr_ohm *= k[1];
    m.lm_h *= k[3];
    m.ls_h = m.lm_h + k[2] * lls;
    m.lr_h = m.lm_h + k[2] * llr;
    q
}

/// The case's scenario on the true machine `p`, and its commissioning window.
pub fn scenario(c: &Case, p: &ParamFile) -> (Scenario, (f64, f64)) {
    let mut sc = Scenario::steady(DURATION_S, RATE_HZ);
    sc.seed = c.seed;
    let mut sensors = SensorSpec::default();
    let ranges = p.sensor_ranges();
    // (Room for a +35 % voltage gain error: no flat tops.)
    sensors.v_range_v = Some(1.5 * ranges.v_range_v);
    sensors.noise_v = Some(c.noise_scale * 0.0005 * 1.5 * ranges.v_range_v);
    sensors.noise_i = Some(c.noise_scale * 0.0005 * ranges.i_range_a);
    sc.sensors = sensors;
    let mut g = ChaCha8Rng::seed_from_u64(c.seed ^ 0x10AD);
    let window = if c.moving {
        let mut first = [0.7, 0.9, 1.1, 1.3];
        for k in (1..first.len()).rev() {
            first.swap(k, g.gen_range(0..=k));
        }
        let mut steps = Vec::new();
        let mut t = LOAD_PERIOD_S;
        let mut k = 0;
        while t < DURATION_S {
            let level = first
                .get(k)
                .copied()
                .unwrap_or_else(|| g.gen_range(0.7..1.3));
            steps.push(LoadStep {
                t_s: t,
                torque_nm: None,
                bl_scale: Some(level),
            });
            k += 1;
            t += LOAD_PERIOD_S;
        }
        sc.load = LoadSpec {
            bl_nms: Some(p.motor.bl_nms),
            steps,
            ..LoadSpec::default()
        };
        (2.0, 14.0)
    } else {
        (2.5, 5.5)
    };
    if let Some((rise, tau, from)) = c.warming {
        let toml =
            format!("name = \"thermal_drift\"\nrise_k = {rise}\ntau_s = {tau}\nat_s = {from}\n");
        sc.effects
            .push(toml::from_str::<EffectSpec>(&toml).expect("effect"));
    }
    if let Some((f, change)) = c.fault {
        sc.faults.push(FaultSpec::at_change(f, FAULT_AT_S, change));
    }
    (sc, window)
}

/// A name given, its probability, and whether it is the injected fault's.
#[derive(Debug, Clone, Copy)]
pub struct Scored {
    pub p: f32,
    pub right: bool,
}

/// One case's outcome.
#[derive(Debug, Clone)]
pub struct CaseOutcome {
    pub case: Case,
    /// The name at the end.
    pub last: Option<(IsolationName, Scored, f32)>,
    /// Every name given on the way (the events).
    pub given: Vec<(IsolationName, Scored, f64)>,
    pub verdict: String,
}

/// The name right for `fault` (none for B, Bl and healthy logs: the load is unknown).
pub fn right_name(fault: Option<(Fault, f64)>) -> Option<IsolationName> {
    match fault {
        Some((Fault::B | Fault::Bl, _)) | None => None,
        Some((f, _)) => Some(IsolationName::Fault(f)),
    }
}

/// The case's true machine, its parameter file, scenario and replay options.
pub fn setup(c: &Case) -> (ParamFile, ParamFile, Scenario, ReplayOptions) {
    let (_, truth) = motors()[c.motor];
    let file = c.file_off.map_or(truth, |k| off(&truth, k));
    let (sc, window) = scenario(c, &truth);
    let opts = ReplayOptions {
        angle_source: c.angle,
        commission: c
            .commissioned
            .then_some(monitor_replay::CommissionWindow::of(window.0, window.1)),
        allow_incomplete: true,
        ..Default::default()
    };
    (truth, file, sc, opts)
}

/// Simulates and replays case `c`, scored.
pub fn run(c: Case) -> CaseOutcome {
    let (truth, file, sc, opts) = setup(&c);
    let r = monitor_studies::experiment::simulate_and_replay(&truth, &file, &sc, opts, |_, _| {})
        .expect("runs")
        .finish();
    let want = right_name(c.fault);
    let score = |n: IsolationName, p: f32| Scored {
        p,
        right: Some(n) == want,
    };
    let last = r.isolation.named.map(|n| {
        let p = r.isolation.named_probability.unwrap_or(f32::NAN);
        (n, score(n, p), r.isolation.named_change.unwrap_or(f32::NAN))
    });
    let given = r
        .isolation
        .events
        .iter()
        .filter_map(|e| match e {
            IsolationEvent::Named {
                t_s,
                name,
                probability,
                ..
            } => Some((*name, score(*name, *probability), *t_s)),
            IsolationEvent::LoadMoved { .. } => None,
        })
        .collect();
    CaseOutcome {
        case: c,
        last,
        given,
        verdict: format!("{:?}", r.verdict),
    }
}
