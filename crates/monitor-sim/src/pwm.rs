//! Inverter-fed supply: a two-level PWM inverter's switching ripple on the phase voltages
//! and currents of a simulated log, as a measurement front end with a single-pole
//! anti-alias filter sees them ([`apply_pwm`]). A post-processing step on the rows of
//! [`crate::simulate`] (run it at the rate the acquisition samples, 80 kHz for the board's
//! oversampling): the machine is simulated on the sinusoidal supply as before, and the
//! switching ripple is added on top. Nothing else of the simulator changes.
//!
//! # Model
//! The inverter is modulated by the rows' phase voltages (the references `v_x*`), with the
//! min-max zero sequence of space-vector modulation (`m_x = v_x* - (max + min) / 2`, the
//! linear range up to `V_dc / sqrt(3)` peak), regular sampling symmetric PWM: in carrier
//! period `k`, `[k T_c, (k + 1) T_c)`, the references are taken at its centre and each
//! pole is at `+V_dc / 2` for the duty `d_x = 1/2 + m_x / V_dc` of the period, centred, at
//! `-V_dc / 2` otherwise. The phase-to-neutral voltage of the star-connected machine is the
//! pole voltage less the poles' mean, so over every carrier period it averages to the
//! reference exactly: the ripple `e_x = v_xn - v_x*` has no fundamental. It drops across
//! the machine's transient inductance `sigma L_s = L_s - L_m^2 / L_r`, so the current
//! ripple is `di_x/dt = e_x / (sigma L_s)` (the back EMF is the fundamental's), taken with
//! zero mean over each carrier period. Both ripples pass the front end's single-pole RC
//! (corner `f_RC`; `None`: no filter), solved exactly for the piecewise-constant voltage
//! and the piecewise-linear current; the references themselves pass unfiltered, as the
//! simulator's sinusoidal rows do (the RC's lag at 50 Hz is 0.18 degrees at 16 kHz).
//!
//! Limits: no dead time, no device drops, no DC-link ripple, no overmodulation (the duty
//! is clamped to 0..1 beyond the linear range, and then the period's mean is no longer the
//! reference); the current ripple does not act back on the machine's flux.

use super::SimError;
use monitor_io::log::Row;
use monitor_io::params::ParamFile;

/// The inverter and the front end ([`apply_pwm`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PwmSpec {
    /// Carrier (switching) frequency [Hz], > 0.
    pub carrier_hz: f64,
    /// DC-link voltage [V], > 0.
    pub dc_link_v: f64,
    /// The front end's single-pole anti-alias corner [Hz] (`None`: no filter).
    pub front_end_cutoff_hz: Option<f64>,
    /// The machine's transient inductance `sigma L_s` [H], > 0 (the current ripple's).
    pub transient_inductance_h: f64,
}

impl PwmSpec {
    /// The inverter for `params`' machine at `carrier_hz`: the DC link 1.15 x the line
    /// voltage's peak (`1.15 sqrt(2) V_ll`, 650 V for 400 V: the rated voltage at 87 % of
    /// the linear range), `sigma L_s` from the file, the board's 16 kHz front end (1 kohm,
    /// 10 nF).
    pub fn for_machine(params: &ParamFile, carrier_hz: f64) -> Self {
        let m = &params.motor;
        PwmSpec {
            carrier_hz,
            dc_link_v: 1.15 * std::f64::consts::SQRT_2 * params.supply.v_ll_rms,
            front_end_cutoff_hz: Some(1.0 / (std::f64::consts::TAU * 1.0e3 * 10.0e-9)),
            transient_inductance_h: m.ls_h - m.lm_h * m.lm_h / m.lr_h,
        }
    }

    fn check(&self) -> Result<(), SimError> {
        let bad = |key: &str, message: &str| {
            Err(SimError::Invalid {
                key: format!("pwm.{key}"),
                message: message.into(),
            })
        };
        if !(self.carrier_hz > 0.0 && self.carrier_hz.is_finite()) {
            return bad("carrier_hz", "must be positive");
        }
        if !(self.dc_link_v > 0.0 && self.dc_link_v.is_finite()) {
            return bad("dc_link_v", "must be positive");
        }
        if !(self.transient_inductance_h > 0.0 && self.transient_inductance_h.is_finite()) {
            return bad("transient_inductance_h", "must be positive");
        }
        if self
            .front_end_cutoff_hz
            .is_some_and(|f| !(f > 0.0 && f.is_finite()))
        {
            return bad("front_end_cutoff_hz", "must be positive");
        }
        Ok(())
    }
}

/// One phase's front-end state: the filtered voltage and current ripple.
#[derive(Debug, Clone, Copy, Default)]
struct Filtered {
    v: f64,
    i: f64,
}

/// The rows with the inverter's ripple added (module docs): `v_abc` and `i_abc` of each
/// row plus the ripple at its time, through the front end. The rows must be in time order
/// and carry voltages (they are the references).
///
/// # Errors
/// [`SimError::Invalid`] for a spec out of range (`pwm.*`) or rows without voltages
/// (`pwm.rows`).
pub fn apply_pwm(rows: &[Row], spec: &PwmSpec) -> Result<Vec<Row>, SimError> {
    spec.check()?;
    let refs: Vec<[f64; 3]> = rows
        .iter()
        .map(|r| r.v_abc)
        .collect::<Option<_>>()
        .ok_or_else(|| SimError::Invalid {
            key: "pwm.rows".into(),
            message: "the rows carry no voltages to modulate".into(),
        })?;
    let mut out = rows.to_vec();
    let (Some(first), Some(last)) = (rows.first(), rows.last()) else {
        return Ok(out);
    };
    let tc = 1.0 / spec.carrier_hz;
    let tau = spec
        .front_end_cutoff_hz
        .map(|f| 1.0 / (std::f64::consts::TAU * f));
    let mut state = [Filtered::default(); 3];
    let mut k = (first.t_s / tc).floor();
    while k * tc <= last.t_s {
        let start = k * tc;
        let centre = reference_at(rows, &refs, start + tc / 2.0);
        let period = Period::new(centre, spec, start, tc);
        period.run(&mut state, tau, rows, &mut out, start);
        k += 1.0;
    }
    Ok(out)
}

/// The references at time `t`, linear between the rows around it (the first or last row
/// outside them).
fn reference_at(rows: &[Row], refs: &[[f64; 3]], t: f64) -> [f64; 3] {
    let n = rows.partition_point(|r| r.t_s <= t);
    match (
        n.checked_sub(1).and_then(|i| rows.get(i).zip(refs.get(i))),
        rows.get(n).zip(refs.get(n)),
    ) {
        (Some((r0, v0)), Some((r1, v1))) if r1.t_s > r0.t_s => {
            let w = (t - r0.t_s) / (r1.t_s - r0.t_s);
            [0, 1, 2].map(|x| v0[x] + w * (v1[x] - v0[x]))
        }
        (Some((_, v)), _) | (None, Some((_, v))) => *v,
        (None, None) => [0.0; 3],
    }
}

/// One carrier period: its segments (start time, each phase's ripple voltage) and the
/// current ripple's value at each segment's start and its mean.
struct Period {
    /// (segment start [s], ripple voltage per phase [V]); the last entry closes the period.
    segments: Vec<(f64, [f64; 3])>,
    /// The current ripple at each segment's start, less the period's mean [A].
    i_start: Vec<[f64; 3]>,
    inductance_h: f64,
}

impl Period {
    fn new(reference: [f64; 3], spec: &PwmSpec, start: f64, tc: f64) -> Self {
        let mean = reference.iter().sum::<f64>() / 3.0;
        let v_ref = reference.map(|v| v - mean);
        let hi = v_ref.iter().copied().fold(f64::MIN, f64::max);
        let lo = v_ref.iter().copied().fold(f64::MAX, f64::min);
        let half = spec.dc_link_v / 2.0;
        let duty = v_ref.map(|v| (0.5 + (v - (hi + lo) / 2.0) / spec.dc_link_v).clamp(0.0, 1.0));
        let on = duty.map(|d| start + (1.0 - d) * tc / 2.0);
        let off = duty.map(|d| start + (1.0 + d) * tc / 2.0);
        let mut edges: Vec<f64> = on.iter().chain(off.iter()).copied().collect();
        edges.push(start);
        edges.sort_by(f64::total_cmp);
        let mut segments: Vec<(f64, [f64; 3])> = edges
            .iter()
            .map(|&t| {
                let pole = [0, 1, 2].map(|x| {
                    if t >= on[x] && t < off[x] {
                        half
                    } else {
                        -half
                    }
                });
                let common = pole.iter().sum::<f64>() / 3.0;
                (t, [0, 1, 2].map(|x| pole[x] - common - v_ref[x]))
            })
            .collect();
        segments.push((start + tc, [0.0; 3]));
        // The current ripple: the integral of e / (sigma Ls), its period mean taken out.
        let l = spec.transient_inductance_h;
        let mut i_start = Vec::with_capacity(segments.len());
        let mut i_now = [0.0; 3];
        let mut mean_i = [0.0; 3];
        i_start.push(i_now);
        for w in segments.windows(2) {
            let (&(t0, e), &(t1, _)) = (&w[0], &w[1]);
            let dt = t1 - t0;
            for ((m, i), e) in mean_i.iter_mut().zip(&mut i_now).zip(e) {
                *m += (*i + e * dt / (2.0 * l)) * dt / tc;
                *i += e * dt / l;
            }
            i_start.push(i_now);
        }
        for i in &mut i_start {
            for (i, m) in i.iter_mut().zip(&mean_i) {
                *i -= m;
            }
        }
        Period {
            segments,
            i_start,
            inductance_h: l,
        }
    }

    /// Runs the front end's state through the period and adds the ripple to every row of
    /// `rows` in it (into `out`, the same index).
    fn run(
        &self,
        state: &mut [Filtered; 3],
        tau: Option<f64>,
        rows: &[Row],
        out: &mut [Row],
        start: f64,
    ) {
        let first = rows.partition_point(|r| r.t_s < start);
        let mut at = first;
        for (j, w) in self.segments.windows(2).enumerate() {
            let (&(t0, e), &(t1, _)) = (&w[0], &w[1]);
            let i0 = self.i_start[j];
            let slope = e.map(|v| v / self.inductance_h);
            let mut from = *state;
            let mut t_from = t0;
            while let (Some(row), Some(o)) = (rows.get(at), out.get_mut(at)) {
                if row.t_s >= t1 {
                    break;
                }
                let now = advance(from, t_from - t0, row.t_s - t0, e, i0, slope, tau);
                if let Some(v) = o.v_abc.as_mut() {
                    for (v, n) in v.iter_mut().zip(&now) {
                        *v += n.v;
                    }
                }
                for (i, n) in o.i_abc.iter_mut().zip(&now) {
                    *i += n.i;
                }
                from = now;
                t_from = row.t_s;
                at += 1;
            }
            *state = advance(from, t_from - t0, t1 - t0, e, i0, slope, tau);
        }
    }
}

/// The front end's state from `s0` to `s1` [s since the segment's start] with the
/// ripple voltage `e` constant and the current ripple `i0 + slope s` (exact single-pole
/// solutions; no filter: the inputs themselves).
fn advance(
    from: [Filtered; 3],
    s0: f64,
    s1: f64,
    e: [f64; 3],
    i0: [f64; 3],
    slope: [f64; 3],
    tau: Option<f64>,
) -> [Filtered; 3] {
    [0, 1, 2].map(|x| {
        let ramp_at = |s: f64| i0[x] + slope[x] * s;
        match tau {
            None => Filtered {
                v: e[x],
                i: ramp_at(s1),
            },
            Some(tau) => {
                let decay = (-(s1 - s0) / tau).exp();
                // y' = (u - y) / tau; u = a + b s: y = u - b tau + (y0 - u0 + b tau) decay.
                let b = slope[x];
                Filtered {
                    v: e[x] + (from[x].v - e[x]) * decay,
                    i: ramp_at(s1) - b * tau + (from[x].i - ramp_at(s0) + b * tau) * decay,
                }
            }
        }
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn rows_at(rate_hz: f64, n: usize, v: impl Fn(f64) -> [f64; 3]) -> Vec<Row> {
        (0..n)
            .map(|k| {
                let t = k as f64 / rate_hz;
                Row {
                    t_s: t,
                    v_abc: Some(v(t)),
                    i_abc: [0.0; 3],
                    wm_rad_s: None,
                    enc_count: None,
                    t_winding_c: None,
                }
            })
            .collect()
    }

    fn spec(cutoff: Option<f64>) -> PwmSpec {
        PwmSpec {
            carrier_hz: 4_000.0,
            dc_link_v: 600.0,
            front_end_cutoff_hz: cutoff,
            transient_inductance_h: 0.01,
        }
    }

    /// Unfiltered, the phase-to-neutral voltage of a two-level inverter takes only the
    /// levels 0, +-V_dc/3, +-2 V_dc/3, and its mean over a carrier period is the reference.
    #[test]
    fn the_levels_are_the_inverters_and_the_period_mean_is_the_reference() {
        let reference = [150.0, -40.0, -110.0];
        // 4 MHz rows over one carrier period.
        let rows = rows_at(4.0e6, 1_000, |_| reference);
        let out = apply_pwm(&rows, &spec(None)).unwrap();
        let mut mean = [0.0; 3];
        for r in &out {
            let v = r.v_abc.unwrap();
            for (m, x) in mean.iter_mut().zip(v) {
                let level = x / 200.0;
                assert!(
                    (level - level.round()).abs() < 1e-9 && level.abs() <= 2.0,
                    "{v:?}"
                );
                *m += x / 1_000.0;
            }
        }
        for (m, r) in mean.iter().zip(reference) {
            // The mean of 1000 points of a waveform whose edges fall between them.
            assert!((m - r).abs() < 1.0, "{mean:?}");
        }
        // The current ripple: zero mean over the period, a triangle of about
        // e dt / L (peak-to-peak under V_dc T_c / (4 L) = 3.75 A).
        let i_mean: f64 = out.iter().map(|r| r.i_abc[0]).sum::<f64>() / 1_000.0;
        let i_pp = out.iter().map(|r| r.i_abc[0]).fold(f64::MIN, f64::max)
            - out.iter().map(|r| r.i_abc[0]).fold(f64::MAX, f64::min);
        assert!(i_mean.abs() < 1e-3, "{i_mean}");
        assert!(i_pp > 0.1 && i_pp < 3.75, "{i_pp}");
    }

    /// Through the front end's RC the ripple's rms falls as a first-order low-pass says
    /// for the carrier's harmonics: at a 1.6 kHz corner, far below the 4 kHz carrier, to a
    /// small fraction; the mean stays the reference.
    #[test]
    fn the_front_end_filters_the_ripple() {
        let reference = [100.0, 0.0, -100.0];
        let rows = rows_at(4.0e6, 40_000, |_| reference);
        let rms = |out: &[Row]| {
            let tail = &out[20_000..];
            (tail
                .iter()
                .map(|r| (r.v_abc.unwrap()[0] - reference[0]).powi(2))
                .sum::<f64>()
                / tail.len() as f64)
                .sqrt()
        };
        let raw = rms(&apply_pwm(&rows, &spec(None)).unwrap());
        let filtered = rms(&apply_pwm(&rows, &spec(Some(1_600.0))).unwrap());
        assert!(raw > 100.0, "{raw}");
        assert!(filtered < 0.5 * raw, "{filtered} against {raw}");
        assert!(apply_pwm(
            &rows,
            &PwmSpec {
                carrier_hz: 0.0,
                ..spec(None)
            }
        )
        .is_err());
    }
}
