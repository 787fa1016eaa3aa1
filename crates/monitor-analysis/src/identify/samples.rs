//! The log's samples as `identify`'s model needs them, and why a log or a start file
//! cannot be identified from ([`IdentifyError`]).

use monitor_io::log::{Channels, Row};
use nalgebra::Complex;

/// Why identification could not run (one line each).
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum IdentifyError {
    /// The log has no phase voltages.
    #[error("the log has no voltages (va_V, vb_V, vc_V): identify drives the model with the measured phase voltages")]
    NoVoltages,
    /// The window holds less than [`MIN_DURATION_S`] of regular samples.
    #[error("{span_s:.3} s of log in the window: identify needs at least {MIN_DURATION_S} s of regular samples")]
    TooShort {
        /// The window's span [s].
        span_s: f64,
    },
    /// An interval between samples is not the rate's.
    #[error("the samples are not regular at t = {at_s} s (an interval of {interval_s:.3e} s where the rate gives {dt_s:.3e} s): give a window without gaps (from_s/to_s)")]
    Irregular {
        /// Where [s].
        at_s: f64,
        /// The interval found [s].
        interval_s: f64,
        /// The interval the rate gives [s].
        dt_s: f64,
    },
    /// A value that is not a number.
    #[error(
        "a value that is not a number at t = {at_s} s: give a window without it (from_s/to_s)"
    )]
    NotANumber {
        /// Where [s].
        at_s: f64,
    },
    /// The currents are zero throughout.
    #[error("the currents are zero throughout: nothing to identify")]
    NoCurrent,
    /// The log starts in running and has no speed channel.
    #[error("the log starts in running and has no speed (wm_rad_s): identify needs the speed channel, or a log that starts from standstill (a direct-on-line start)")]
    RunningWithoutSpeed,
    /// The start parameter file is not a machine the model can simulate.
    #[error("the start parameter file is not a machine identify can start from (Rs {rs_ohm}, Rr {rr_ohm}, Lls {lls_h}, Llr {llr_h}, Lm {lm_h}, J {j_kgm2}, poles {poles}): each must be > 0 (Lls, Llr >= 0, their sum > 0)")]
    NotAMachine {
        /// Rs [ohm].
        rs_ohm: f64,
        /// Rr [ohm].
        rr_ohm: f64,
        /// Lls [H].
        lls_h: f64,
        /// Llr [H].
        llr_h: f64,
        /// Lm [H].
        lm_h: f64,
        /// J [kg m^2].
        j_kgm2: f64,
        /// Poles.
        poles: u32,
    },
}

/// The log's samples as the model needs them.
#[derive(Debug, Clone)]
pub struct Samples {
    /// Sample interval [s].
    pub dt_s: f64,
    /// Time of the first sample [s].
    pub t0_s: f64,
    /// Phase voltages, alpha and beta (amplitude-invariant Clarke) [V].
    pub v_ab: Vec<[f64; 2]>,
    /// Phase currents, alpha and beta [A].
    pub i_ab: Vec<[f64; 2]>,
    /// Mechanical speed [rad/s], when the log has it.
    pub wm_rad_s: Option<Vec<f64>>,
    /// RMS of the measured current vector [A] (> 0).
    pub i_rms_a: f64,
    /// The log starts de-energised (first current below 5 % of the first 0.1 s's peak).
    pub starts_dead: bool,
    /// The supply's voltage vector at the first sample, alpha + j beta [V].
    pub v0: Complex<f64>,
    /// The supply's angular frequency over the first 0.1 s [rad/s].
    pub supply_w_rad_s: f64,
}

/// Shortest log `identify` accepts [s].
pub const MIN_DURATION_S: f64 = 0.2;

fn clarke(x: [f64; 3]) -> [f64; 2] {
    [
        (2.0 * x[0] - x[1] - x[2]) / 3.0,
        (x[1] - x[2]) / 3f64.sqrt(),
    ]
}

/// The sample interval of the times `times` [s]: regular, spanning at least
/// [`MIN_DURATION_S`].
///
/// # Errors
/// [`IdentifyError::TooShort`], [`IdentifyError::Irregular`].
fn regular_interval(times: &[f64]) -> Result<f64, IdentifyError> {
    let rate = monitor_io::log::sample_rate_hz(times).unwrap_or(0.0);
    let span_s = times.last().zip(times.first()).map_or(0.0, |(b, a)| b - a);
    if rate.is_nan() || rate <= 0.0 || span_s < MIN_DURATION_S {
        return Err(IdentifyError::TooShort { span_s });
    }
    let dt_s = 1.0 / rate;
    match times
        .windows(2)
        .find(|w| ((w[1] - w[0]) * rate - 1.0).abs() > 0.25)
    {
        Some(w) => Err(IdentifyError::Irregular {
            at_s: w[0],
            interval_s: w[1] - w[0],
            dt_s,
        }),
        None => Ok(dt_s),
    }
}

impl Samples {
    /// The rows of `channels` between `from_s` and `to_s`.
    ///
    /// # Errors
    /// No voltages, a non-finite value (naming its time), times that are not regular,
    /// fewer than [`MIN_DURATION_S`] seconds, no current, a log that starts in running
    /// without a speed channel ([`IdentifyError`]).
    pub fn from_rows(
        rows: &[Row],
        channels: Channels,
        from_s: f64,
        to_s: f64,
    ) -> Result<Samples, IdentifyError> {
        if !channels.voltages {
            return Err(IdentifyError::NoVoltages);
        }
        let rows: Vec<&Row> = rows
            .iter()
            .filter(|r| r.t_s >= from_s && r.t_s <= to_s)
            .collect();
        let times: Vec<f64> = rows.iter().map(|r| r.t_s).collect();
        let dt_s = regular_interval(&times)?;
        let mut s = Samples {
            dt_s,
            t0_s: times.first().copied().unwrap_or(0.0),
            v_ab: Vec::with_capacity(rows.len()),
            i_ab: Vec::with_capacity(rows.len()),
            wm_rad_s: channels.speed.then(Vec::new),
            i_rms_a: 0.0,
            starts_dead: false,
            v0: Complex::new(0.0, 0.0),
            supply_w_rad_s: 0.0,
        };
        for r in rows {
            s.push(r)?;
        }
        s.finish_head()?;
        Ok(s)
    }

    /// Appends row `r` (its voltages and currents in alpha-beta, its speed).
    ///
    /// # Errors
    /// [`IdentifyError::NotANumber`].
    fn push(&mut self, r: &Row) -> Result<(), IdentifyError> {
        let v = r.v_abc.unwrap_or([f64::NAN; 3]);
        let finite = v.iter().chain(&r.i_abc).all(|x| x.is_finite())
            && r.wm_rad_s.is_none_or(f64::is_finite);
        if !finite {
            return Err(IdentifyError::NotANumber { at_s: r.t_s });
        }
        self.v_ab.push(clarke(v));
        self.i_ab.push(clarke(r.i_abc));
        if let Some(w) = self.wm_rad_s.as_mut() {
            w.push(r.wm_rad_s.unwrap_or(0.0));
        }
        Ok(())
    }

    /// The current's RMS, the supply's phasor and frequency, and whether the log starts
    /// de-energised.
    fn finish_head(&mut self) -> Result<(), IdentifyError> {
        let n = self.i_ab.len();
        let sq: f64 = self.i_ab.iter().map(|i| i[0] * i[0] + i[1] * i[1]).sum();
        self.i_rms_a = (sq / n.max(1) as f64).sqrt();
        if self.i_rms_a.is_nan() || self.i_rms_a <= 0.0 {
            return Err(IdentifyError::NoCurrent);
        }
        let head = ((0.1 / self.dt_s) as usize).clamp(2, n);
        let norm = |i: &[f64; 2]| i[0].hypot(i[1]);
        let peak = self.i_ab[..head].iter().map(norm).fold(0.0, f64::max);
        self.starts_dead = self.i_ab.first().is_none_or(|i| norm(i) < 0.05 * peak);
        let c = |v: &[f64; 2]| Complex::new(v[0], v[1]);
        let turn: f64 = self.v_ab[..head]
            .windows(2)
            .map(|w| (c(&w[1]) * c(&w[0]).conj()).arg())
            .sum();
        let w = turn / ((head - 1) as f64 * self.dt_s);
        self.supply_w_rad_s = w;
        // The positive-sequence phasor at t0 by least squares over the head (v_k = V
        // e^{j w t_k}): the mean of v_k e^{-j w t_k}, a single sample's noise averaged out.
        self.v0 = self.v_ab[..head]
            .iter()
            .enumerate()
            .map(|(k, v)| c(v) * Complex::from_polar(1.0, -w * k as f64 * self.dt_s))
            .sum::<Complex<f64>>()
            / head as f64;
        if !self.starts_dead && self.wm_rad_s.is_none() {
            return Err(IdentifyError::RunningWithoutSpeed);
        }
        Ok(())
    }
}
