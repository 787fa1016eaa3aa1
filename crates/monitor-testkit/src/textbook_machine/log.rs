//! The textbook machine run through a scenario and logged: the samples, the CSV log with
//! sensor noise and 12-bit quantisation, and the equivalent circuit's steady state the
//! physics test compares with.

use super::*;

/// One logged sample without sensor effects: t, v_abc, i_abc, w_m (and the state).
#[derive(Clone, Copy, Debug)]
pub struct Sample {
    pub t: f64,
    pub v: [f64; 3],
    pub i: [f64; 3],
    pub w: f64,
    pub x: State,
}

fn abc(x: [f64; 2]) -> [f64; 3] {
    let s3 = 3f64.sqrt() / 2.0;
    [x[0], -0.5 * x[0] + s3 * x[1], -0.5 * x[0] - s3 * x[1]]
}

/// Simulates `s` on `m`: the ideal samples at the log rate (the first at t = 0).
pub fn simulate(m: &Machine, s: &Scenario) -> Vec<Sample> {
    let model = Model { m, s };
    let per = (1.0 / (s.rate_hz * s.step_s)).round().max(1.0) as usize;
    let h = 1.0 / (s.rate_hz * per as f64);
    let n = (s.duration_s * s.rate_hz).round() as usize;
    let mut x = model.initial();
    let mut out = Vec::with_capacity(n + 1);
    for k in 0..=n {
        let t = k as f64 / s.rate_hz;
        let p = model.point(t, &x);
        out.push(Sample {
            t,
            v: abc(p.v),
            i: abc(p.is),
            w: x[4],
            x,
        });
        if k == n {
            break;
        }
        for j in 0..per {
            x = model.rk4(t + j as f64 * h, &x, h);
        }
    }
    out
}

/// A full scale as a data-acquisition engineer would set it: 1.25 x the largest value,
/// rounded up to a multiple of `unit`.
fn full_scale(max: f64, unit: f64) -> f64 {
    (1.25 * max / unit).ceil().max(1.0) * unit
}

/// Writes the log (CSV: t_s, va_V, vb_V, vc_V, ia_A, ib_A, ic_A, wm_rad_s) with sensor
/// noise and quantisation; returns its path.
pub fn write_log(dir: &Path, name: &str, m: &Machine, s: &Scenario) -> PathBuf {
    let samples = simulate(m, s);
    let maxv = samples
        .iter()
        .flat_map(|r| r.v)
        .fold(0.0f64, |a, b| a.max(b.abs()));
    let maxi = samples
        .iter()
        .flat_map(|r| r.i)
        .fold(0.0f64, |a, b| a.max(b.abs()));
    let maxw = samples.iter().fold(0.0f64, |a, r| a.max(r.w.abs()));
    let ranges = [
        full_scale(maxv, 50.0),
        full_scale(maxi, 5.0),
        full_scale(maxw.max(m.w_sync()), 10.0),
    ];
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(s.sensors.seed);
    let unit = Normal::new(0.0, 1.0).expect("normal");
    let levels = f64::from(1u32 << s.sensors.bits);
    let mut sense = |x: f64, range: f64| -> f64 {
        let y = x + s.sensors.noise * range * unit.sample(&mut rng);
        let q = 2.0 * range / levels;
        ((y / q).round() * q).clamp(-range, range - q)
    };
    let mut csv = String::with_capacity(samples.len() * 80);
    csv.push_str("t_s,va_V,vb_V,vc_V,ia_A,ib_A,ic_A,wm_rad_s\n");
    for r in &samples {
        let _ = write!(csv, "{}", r.t);
        for v in r.v {
            let _ = write!(csv, ",{:.4}", sense(v, ranges[0]));
        }
        for i in r.i {
            let _ = write!(csv, ",{:.5}", sense(i, ranges[1]));
        }
        let _ = writeln!(csv, ",{:.5}", sense(r.w, ranges[2]));
    }
    let path = dir.join(format!("{name}.csv"));
    std::fs::write(&path, csv).expect("write log");
    path
}

/// The T-equivalent circuit's steady state at slip `slip` and rated supply (linear
/// machine): (peak stator current [A], electromagnetic torque [N m]).
pub fn equivalent_circuit(m: &Machine, slip: f64) -> (f64, f64) {
    let we = 2.0 * PI * m.f_hz;
    let c = |re: f64, im: f64| (re, im);
    let mul = |a: (f64, f64), b: (f64, f64)| (a.0 * b.0 - a.1 * b.1, a.0 * b.1 + a.1 * b.0);
    let div = |a: (f64, f64), b: (f64, f64)| {
        let d = b.0 * b.0 + b.1 * b.1;
        ((a.0 * b.0 + a.1 * b.1) / d, (a.1 * b.0 - a.0 * b.1) / d)
    };
    let add = |a: (f64, f64), b: (f64, f64)| (a.0 + b.0, a.1 + b.1);
    let zs = c(m.rs, we * m.lls);
    let zm = c(0.0, we * m.lm);
    let zr = c(m.rr / slip, we * m.llr);
    let zpar = div(mul(zm, zr), add(zm, zr));
    let v = c(m.v_peak(), 0.0);
    let is = div(v, add(zs, zpar));
    let ir = div(mul(is, zm), add(zm, zr));
    let ir2 = ir.0 * ir.0 + ir.1 * ir.1;
    // Air-gap power 1.5 |I_r|^2 R_r / s (peak phasors) over the synchronous speed.
    let te = 1.5 * ir2 * m.rr / slip / (we / m.pp());
    (is.0.hypot(is.1), te)
}
