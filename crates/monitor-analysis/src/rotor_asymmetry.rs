//! `rotor_asymmetry` (an unequal rotor cage: broken rotor bars, a cracked end ring): the
//! motor current signature analysis (MCSA) report users of that fault expect: the
//! (1 - 2s) f and (1 + 2s) f sidebands of the stator current in dB below the fundamental
//! and the 2 s f speed ripple.
//!
//! The effect model itself (`compare` / `explain`) is `super::effects`' `RotorAsymmetry`.
//!
//! # Broken bars
//! For an N-bar cage with n adjacent broken bars the equivalent rotor phase resistance
//! asymmetry is delta = 3n / (N - 3n), n = delta N / (3 (1 + delta)) (Kliman, Koegl,
//! Stein, Endicott, Madden, IEEE Trans. Energy Convers. 3(4), 1988; Bellini, Filippetti,
//! Franceschini, Tassoni, Kliman, IEEE Trans. Ind. Appl. 37(5), 2001). It is an
//! approximation: it takes the broken bars' current as redistributed over the healthy
//! bars of one rotor pole pitch, and ignores inter-bar currents (which make real
//! sidebands smaller) and the end-ring resistance. The formula lives in the core
//! (`monitor_core::rotor_cage`, shared with the simulator and `diagnose`'s rotor finding);
//! the analysis only reads it.
//!
//! # MCSA resolution
//! The sidebands lie 2 s f from the fundamental (3.6 Hz for the 3 hp motor at 3 % slip),
//! and a record of T seconds resolves 1/T (one bin). The current is windowed with the
//! 4-term Blackman-Harris window (coefficients 0.35875, 0.48829, 0.14128, 0.01168; F. J.
//! Harris, "On the use of windows for harmonic analysis with the discrete Fourier
//! transform", Proc. IEEE 66(1), 1978, table I and fig. 69): its main lobe is +/- 4 bins
//! wide ([`MAIN_LOBE_HALF_BINS`]) and outside it the leakage of any tone stays below
//! -92 dB, far below the sidebands of a healthy cage (-50 to -60 dB on real motors, Thomson
//! and Fenger, IEEE Ind. Appl. Magazine 7(4), 2001). The rule: a sideband is read when its
//! whole search interval, 2 s f +/- [`SLIP_STEADY`] of it (the slip is known to that), lies
//! outside the fundamental's main lobe, i.e. 2 s f (1 - SLIP_STEADY) >= 4 bins:
//! [`MIN_BINS`] = 4 / (1 - 0.2) = 5 bins, T >= 5 / (2 s f) = 2.5 / (s f): 1.4 s at 3 % slip
//! and 60 Hz, 2 s at 2.5 % and 50 Hz, 5 s at 1 % and 50 Hz (the Hann window this replaces
//! needed 10 bins, 4x longer records, for its slowly falling leakage). The transform is
//! zero-padded 4x, so the peaks are read within 1/8 bin of their true frequency, where
//! the window's scalloping loss is below 0.1 dB (Harris's 0.83 dB at 1/2 bin). A shorter
//! steady stretch, a slip below [`MIN_SLIP`] or a slip that varies by more than
//! [`SLIP_STEADY`] of itself is "cannot judge" (saying how long a record is needed).
//!
//! # Broken bars from the spectrum
//! The asymmetry delta makes a backward-rotating rotor current at -s f (in rotor
//! coordinates): the resistance mismatch's negative-sequence part, (delta/3) Rr, times the
//! forward rotor current I_r, drives the backward circuit, whose impedance at small slip
//! is the rotor resistance Rr (1 + delta/3) (the stator is short-circuited at (1 - 2s) f by
//! the supply): I_b / I_r = (delta/3) / (1 + delta/3) = delta / (3 + delta). In the stator
//! it is the (1 - 2s) f sideband; the 2 s f speed ripple moves part of it to (1 + 2s) f, and
//! the sum of the two does not depend on the inertia (Bellini, Filippetti, Franceschini,
//! Tassoni, Kliman, IEEE Trans. Ind. Appl. 37(5), 2001). The rotor current seen in the
//! stator is the torque-producing (q, rotor-flux frame) part I_q of the current, the
//! magnetizing part carries no sideband. Hence, from the spectrum
//! ```text
//!   r = (I_(1-2s)f + I_(1+2s)f) / I_q,   delta = 3 r / (1 - r),   n = r N / (1 + 2 r)
//! ```
//! (the last with Kliman's n = delta N / (3 (1 + delta)), i.e. r = n / (N - 2n)). Its
//! approximations: small slip (the backward circuit's leakage reactance s omega L_sigma
//! neglected against Rr), the stator's impedance at (1 - 2s) f neglected, the
//! magnetizing-to-leakage coupling Lm^2/(Ls Lr) taken as 1, and the cage model's own
//! (no inter-bar currents, which make real sidebands smaller: a real cage's estimate is a
//! lower bound). The report gives it beside the fit's delta; `explain` names
//! `rotor_asymmetry` only when the two agree ([`fit_and_spectrum_agree`]).

use super::prep::Prepared;
use monitor_core::rotor_cage::{broken_bars_of_delta, delta_of_sideband_ratio};
/// The MCSA's shared rules and constants, one home with `diagnose`'s rotor finding
/// ([`monitor_replay`]'s `rotor`): the Blackman-Harris window, its main lobe, the resolution
/// rule, the least and the steady slip, the longest stretch read (a longer steady stretch
/// is cut to its last `max(MAX_STRETCH_S, 4 MIN_BINS / (2 s f))` seconds).
pub use monitor_replay::{
    blackman_harris, BLACKMAN_HARRIS_4, MAIN_LOBE_HALF_BINS, MAX_STRETCH_S, MIN_BINS, MIN_SLIP,
    SLIP_STEADY,
};
use rustfft::num_complex::Complex;
use serde::Serialize;
use std::f64::consts::PI;

/// The spectrum's and the fit's delta agree when they are within this factor (2) of each
/// other ([`fit_and_spectrum_agree`]): the spectral relation's approximations (module doc)
/// are well within it, a healthy cage's fitted noise (a small delta, no sidebands) is not.
pub const AGREE_FACTOR: f64 = 2.0;

/// The asymmetry delta the sidebands say (module doc, "Broken bars from the spectrum"):
/// `r = (10^(lower_db/20) + 10^(upper_db/20)) / q_share`, `delta = 3 r / (1 - r)`, where
/// `q_share` = I_q / I_1 is the torque-producing share of the current (0..1]. `None` when
/// `q_share` is not positive or r >= 1 (sidebands as large as the torque current: not the
/// first-order relation's range).
pub fn spectral_delta(lower_db: f64, upper_db: f64, q_share: f64) -> Option<f64> {
    let lin = |db: f64| 10f64.powf(db / 20.0);
    let r = (lin(lower_db) + lin(upper_db)) / q_share;
    if q_share.is_nan() || q_share <= 0.0 {
        return None;
    }
    delta_of_sideband_ratio(r)
}

/// True when the spectrum's delta and the fit's agree within [`AGREE_FACTOR`] of each
/// other (both positive): what `explain` requires before it names `rotor_asymmetry`.
pub fn fit_and_spectrum_agree(fit_delta: f64, spectral_delta: f64) -> bool {
    fit_delta > 0.0
        && spectral_delta > 0.0
        && spectral_delta <= AGREE_FACTOR * fit_delta
        && fit_delta <= AGREE_FACTOR * spectral_delta
}

/// The rotor's bar count N for the broken-bar figures, from the one place every caller
/// reads it: `given` (`explain --rotor-bars N`) when given; else the parameter file's
/// (`_params`: its `[motor]` table holds no bar count yet; its key is read here once it
/// does). A count turns the fitted and the spectral asymmetry into adjacent broken bars
/// ([`McsaReport::equivalent_broken_bars`], [`McsaReport::spectral_broken_bars`]).
pub fn rotor_bar_count(_params: &monitor_io::params::ParamFile, given: Option<u32>) -> Option<f64> {
    given.map(f64::from)
}

/// The motor current signature analysis of a log (`explain`'s `rotor_asymmetry` key).
#[derive(Debug, Clone, Serialize, Default)]
pub struct McsaReport {
    /// True when the sidebands could be judged; else see `cannot_judge_because`.
    pub judged: bool,
    /// Why the log cannot be judged ("cannot judge: ...").
    #[serde(skip_serializing_if = "Option::is_none")]
    pub cannot_judge_because: Option<String>,
    /// Lower sideband (1 - 2s) f, dB relative to the fundamental (negative).
    pub lower_sideband_db: Option<f64>,
    /// Upper sideband (1 + 2s) f, dB relative to the fundamental.
    pub upper_sideband_db: Option<f64>,
    /// Mean slip over the analysed stretch [-].
    pub slip: Option<f64>,
    /// Supply frequency f [Hz].
    pub fundamental_hz: Option<f64>,
    /// The sidebands' frequencies [(1 - 2s) f, (1 + 2s) f] [Hz].
    pub sideband_hz: Vec<f64>,
    /// The 2 s f speed ripple: frequency [Hz] and amplitude (peak) [rad/s, mechanical].
    pub speed_ripple_hz: Option<f64>,
    /// Amplitude of the 2 s f speed ripple (peak, mechanical) [rad/s].
    pub speed_ripple_rad_s: Option<f64>,
    /// Fitted (or given) delta the broken-bar figure is computed from.
    pub delta: Option<f64>,
    /// Rotor bar count N ([`rotor_bar_count`]: `--rotor-bars`, or the parameter file).
    pub rotor_bars: Option<f64>,
    /// Equivalent adjacent broken bars n = delta N / (3 (1 + delta)) (null without a bar
    /// count or without a fitted delta).
    pub equivalent_broken_bars: Option<f64>,
    /// Torque-producing share of the current I_q / I_1 over the analysed stretch (rotor-flux
    /// frame; the spectral estimate's reference, module doc).
    pub torque_current_share: Option<f64>,
    /// The asymmetry delta the sidebands say ([`spectral_delta`]).
    pub spectral_delta: Option<f64>,
    /// Adjacent broken bars the sidebands say, n = r N / (1 + 2r) (module doc; null
    /// without a bar count or without judged sidebands).
    pub spectral_broken_bars: Option<f64>,
    /// Whether the fitted `delta` and `spectral_delta` agree ([`fit_and_spectrum_agree`];
    /// null when either is missing).
    pub fit_and_spectrum_agree: Option<bool>,
    /// Frequency resolution 1/T of the analysed stretch [Hz].
    pub resolution_hz: Option<f64>,
    /// Resolution needed: 2 s f / [`MIN_BINS`] [Hz].
    pub resolution_needed_hz: Option<f64>,
    /// Analysed stretch [t_start, t_end] [s] (steady slip).
    pub window_s: Vec<f64>,
    /// Phase-a current spectrum around the fundamental (f/2 .. 3f/2), for the plot:
    /// (frequency [Hz], dB relative to the fundamental).
    #[serde(skip)]
    pub spectrum: Vec<(f64, f64)>,
}

/// The stretch at the end of the log over which the slip is steady: from the last 0.2 s
/// block whose mean slip differs from the final quarter's median by more than
/// [`SLIP_STEADY`] of it, to the end. Returns (first sample, slip series per sample).
fn steady_stretch(d: &Prepared) -> (usize, Vec<f64>) {
    let len = d.len();
    let slip: Vec<f64> = (0..len)
        .map(|k| 1.0 - d.omega_r[k] / d.omega_s[k].abs().max(1e-6))
        .collect();
    let mut tail: Vec<f64> = slip[3 * len / 4..].to_vec();
    tail.sort_by(f64::total_cmp);
    let med = tail.get(tail.len() / 2).copied().unwrap_or(0.0);
    let blk = ((0.2 / d.dt_s).round() as usize).max(1);
    let mut start = 0;
    let mut k = len;
    while k >= blk {
        let m = slip[k - blk..k].iter().sum::<f64>() / blk as f64;
        if (m - med).abs() > SLIP_STEADY * med.abs().max(MIN_SLIP) {
            start = k;
            break;
        }
        k -= blk;
    }
    (start, slip)
}

/// Blackman-Harris-windowed amplitude spectrum of `x` sampled every `dt`, zero-padded 4x: (bin
/// spacing [Hz], peak amplitudes per bin from 0 Hz to at least `f_max` [Hz] (or to the
/// Nyquist frequency)). The real series is transformed as a complex one of half the length
/// (even samples real, odd imaginary) and the bins are unpacked from it: the same values
/// to rounding as a full-length complex FFT, in half the time and memory (a 1 h log's
/// stretch is 4 M samples, padded to 16 M).
fn spectrum(
    planner: &mut rustfft::FftPlanner<f64>,
    x: &[f64],
    dt: f64,
    f_max: f64,
) -> (f64, Vec<f64>) {
    let n = x.len();
    let nfft = (4 * n).next_power_of_two().max(2);
    let half = nfft / 2;
    let mean = x.iter().sum::<f64>() / n.max(1) as f64;
    let mut buf: Vec<Complex<f64>> = vec![Complex::new(0.0, 0.0); half];
    let mut wsum = 0.0;
    for (k, v) in x.iter().enumerate() {
        let w = blackman_harris(k, n);
        wsum += w;
        let y = (v - mean) * w;
        if k % 2 == 0 {
            buf[k / 2].re = y;
        } else {
            buf[k / 2].im = y;
        }
    }
    planner.plan_fft_forward(half).process(&mut buf);
    let df = 1.0 / (nfft as f64 * dt);
    let bins = ((f_max / df).ceil() as usize).saturating_add(2).min(half);
    let amp = (0..bins)
        .map(|k| {
            // X[k] = E[k] + e^{-j 2 pi k / nfft} O[k], E and O the even and odd samples'
            // transforms: E = (Z[k] + Z*[-k]) / 2, O = (Z[k] - Z*[-k]) / 2j.
            let a = buf[k];
            let b = buf[(half - k) % half].conj();
            let e = (a + b) * 0.5;
            let o = (a - b) * Complex::new(0.0, -0.5);
            let (s, c) = (-2.0 * PI * k as f64 / nfft as f64).sin_cos();
            let c = e + Complex::new(c, s) * o;
            2.0 * c.norm() / wsum.max(1e-12)
        })
        .collect();
    (df, amp)
}

/// Why the current spectrum contradicts a fitted asymmetry `fit_delta` (`explain` then
/// does not name `rotor_asymmetry`): the sidebands were judged ([`mcsa`]) and their
/// [`spectral_delta`] does not agree with it ([`fit_and_spectrum_agree`]). `None` when they
/// agree or when the spectrum cannot judge (it then says nothing either way).
pub fn spectrum_contradicts(d: &Prepared, np: f64, fit_delta: f64) -> Option<String> {
    let m = mcsa(d, np, None, Some(fit_delta));
    let spectral = m.spectral_delta?;
    (m.fit_and_spectrum_agree == Some(false)).then(|| {
        format!(
            "the current spectrum's sidebands ({:.1} / {:.1} dB) say delta {}, not the fitted {} (within {AGREE_FACTOR}x)",
            m.lower_sideband_db.unwrap_or(f64::NAN),
            m.upper_sideband_db.unwrap_or(f64::NAN),
            super::effects::sig(spectral),
            super::effects::sig(fit_delta),
        )
    })
}

/// Largest amplitude within `f0 +/- half` [Hz]: (frequency, amplitude).
fn peak(df: f64, amp: &[f64], f0: f64, half: f64) -> (f64, f64) {
    let a = ((f0 - half) / df).floor().max(0.0) as usize;
    let b = (((f0 + half) / df).ceil() as usize).min(amp.len().saturating_sub(1));
    (a..=b)
        .map(|k| (k as f64 * df, amp[k]))
        .fold((f0, 0.0), |m, x| if x.1 > m.1 { x } else { m })
}

/// The spectral broken-bar estimate of a judged report `r` (its sidebands read) over the
/// samples `seg`: the torque-current share, [`spectral_delta`], its broken bars of
/// `r.rotor_bars` and the agreement with `r.delta` (module doc).
fn spectral_estimate(r: &mut McsaReport, d: &Prepared, seg: std::ops::Range<usize>) {
    let mean = |x: &[f64]| x.iter().sum::<f64>() / x.len().max(1) as f64;
    let part = |x: &[f64]| mean(x.get(seg.clone()).unwrap_or(&[]));
    let (id, iq) = (part(&d.id), part(&d.iq));
    let share = iq.abs() / id.hypot(iq).max(1e-12);
    r.torque_current_share = Some(share);
    r.spectral_delta = r
        .lower_sideband_db
        .zip(r.upper_sideband_db)
        .and_then(|(l, u)| spectral_delta(l, u, share));
    r.spectral_broken_bars = r
        .rotor_bars
        .zip(r.spectral_delta)
        .map(|(nb, dl)| broken_bars_of_delta(dl, nb));
    r.fit_and_spectrum_agree = r
        .delta
        .zip(r.spectral_delta)
        .map(|(f, s)| fit_and_spectrum_agree(f, s));
}

/// The MCSA of the log: stator current sidebands at (1 -/+ 2s) f in dB below the
/// fundamental (phase-a current, Blackman-Harris window over the steady stretch at the end of the
/// log, at most [`MAX_STRETCH_S`] of it), the 2 s f speed ripple, and the equivalent
/// broken bars for `bars` N when `delta` is known. `np` is the number of pole pairs. "Cannot judge" (with the reason) without a
/// speed column, on a slip below [`MIN_SLIP`] or not steady, or a stretch too short for
/// the resolution (see the module doc).
pub fn mcsa(d: &Prepared, np: f64, bars: Option<f64>, delta: Option<f64>) -> McsaReport {
    let mut r = McsaReport {
        delta,
        rotor_bars: bars,
        equivalent_broken_bars: bars.zip(delta).map(|(nb, dl)| broken_bars_of_delta(dl, nb)),
        ..Default::default()
    };
    if d.omega_r.len() != d.len() || d.len() < 16 {
        return cannot_judge(r, "needs the speed column wm_rad_s for the slip".into());
    }
    let (a, slip) = steady_stretch(d);
    // The last 0.2 s block itself off the final quarter's slip: no steady stretch at all
    // (the log ends in a step or a start).
    let Some(st) = Stretch::at_end(d, &slip, a) else {
        return cannot_judge(r, "the slip is not steady at the end of the log".into());
    };
    r.window_s = vec![st.t_a, st.t_end];
    r.slip = Some(st.s);
    r.fundamental_hz = Some(st.f1);
    r.resolution_hz = Some(1.0 / st.t_len.max(d.dt_s));
    if st.s < MIN_SLIP {
        return cannot_judge(
            r,
            format!(
                "the slip {:.4} is below {MIN_SLIP} (no load): the sidebands sit on the fundamental",
                st.s
            ),
        );
    }
    let fs = 2.0 * st.s * st.f1;
    r.sideband_hz = vec![(1.0 - 2.0 * st.s) * st.f1, (1.0 + 2.0 * st.s) * st.f1];
    r.resolution_needed_hz = Some(fs / MIN_BINS);
    if let Some(why) = st.unsteady_or_short(d, &slip, fs) {
        return cannot_judge(r, why);
    }
    // One planner for both spectra (same length: the plan and its twiddles are reused).
    let mut planner = rustfft::FftPlanner::new();
    current_sidebands(&mut r, d, &st, fs, &mut planner);
    speed_ripple(&mut r, d, &st, np, fs, &mut planner);
    r.judged = true;
    r
}

/// The report `r` with the reason it cannot judge.
fn cannot_judge(mut r: McsaReport, why: String) -> McsaReport {
    r.cannot_judge_because = Some(format!("cannot judge: {why}"));
    r
}

/// The steady stretch at the end of the log the spectra are taken over.
struct Stretch {
    /// Its first sample (it runs to the log's end).
    a: usize,
    /// Its first and last time [s].
    t_a: f64,
    t_end: f64,
    /// Its mean slip and supply frequency [Hz].
    s: f64,
    f1: f64,
    /// Its length [s].
    t_len: f64,
}

impl Stretch {
    /// The stretch from sample `a` (where [`steady_stretch`] found the slip `slip` steady)
    /// to the end, cut to [`MAX_STRETCH_S`] (or 4x the length the sidebands need) when
    /// longer; `None` when it holds fewer than 16 samples.
    fn at_end(d: &Prepared, slip: &[f64], a: usize) -> Option<Self> {
        let (Some(&t_a), Some(&t_end)) = (d.t_s.get(a), d.t_s.last()) else {
            return None;
        };
        if d.len() - a < 16 {
            return None;
        }
        let mean_of = |a: usize| {
            let seg = a..d.len();
            let s = slip[seg.clone()].iter().sum::<f64>() / seg.len().max(1) as f64;
            let f1 = d.omega_s[seg.clone()].iter().map(|w| w.abs()).sum::<f64>()
                / seg.len().max(1) as f64
                / (2.0 * PI);
            (s, f1)
        };
        let (s, f1) = mean_of(a);
        let keep_s = MAX_STRETCH_S.max(4.0 * MIN_BINS / (2.0 * s * f1).max(1e-9));
        let keep = ((keep_s / d.dt_s) as usize).max(16);
        let (a, t_a, s, f1) = if d.len() - a > keep {
            let a = d.len() - keep;
            let (s, f1) = mean_of(a);
            (a, d.t_s.get(a).copied().unwrap_or(t_a), s, f1)
        } else {
            (a, t_a, s, f1)
        };
        Some(Stretch {
            a,
            t_a,
            t_end,
            s,
            f1,
            t_len: (d.len() - a) as f64 * d.dt_s,
        })
    }

    /// Why the stretch cannot resolve sidebands at `fs` = 2 s f from the fundamental: its
    /// slip (0.2 s means) moves by more than twice [`SLIP_STEADY`], or it is shorter than
    /// [`MIN_BINS`] / `fs`. `None` when it can.
    fn unsteady_or_short(&self, d: &Prepared, slip: &[f64], fs: f64) -> Option<String> {
        let (lo, hi) = slip[self.a..d.len()]
            .chunks(((0.2 / d.dt_s) as usize).max(1))
            .map(|c| c.iter().sum::<f64>() / c.len() as f64)
            .fold((f64::MAX, f64::MIN), |(l, h), x| (l.min(x), h.max(x)));
        if hi - lo > 2.0 * SLIP_STEADY * self.s {
            return Some(format!("the slip is not steady ({lo:.4}..{hi:.4})"));
        }
        let t_len = self.t_len;
        (t_len < MIN_BINS / fs).then(|| format!(
            "the steady stretch is {t_len:.2} s; {:.2} s are needed to resolve sidebands 2sf = {fs:.2} Hz from the fundamental ({MIN_BINS} bins of a Blackman-Harris window)",
            MIN_BINS / fs
        ))
    }
}

/// The phase-a current's sidebands at `fs` = 2 s f either side of the fundamental over
/// the stretch `st`, in dB below it, the estimates from them, and the spectrum around the
/// fundamental.
fn current_sidebands(
    r: &mut McsaReport,
    d: &Prepared,
    st: &Stretch,
    fs: f64,
    planner: &mut rustfft::FftPlanner<f64>,
) {
    let seg = st.a..d.len();
    let f1 = st.f1;
    let ia: Vec<f64> = d.i_ab[seg.clone()].iter().map(|c| c.re).collect();
    let (df, amp) = spectrum(planner, &ia, d.dt_s, (1.5 * f1).max(f1 + 1.6 * fs));
    let (ff, af) = peak(df, &amp, f1, 0.3 * fs);
    let db = |x: f64| 20.0 * (x.max(1e-300) / af.max(1e-300)).log10();
    let (_, al) = peak(df, &amp, ff - fs, SLIP_STEADY * fs);
    let (_, au) = peak(df, &amp, ff + fs, SLIP_STEADY * fs);
    r.lower_sideband_db = Some(db(al));
    r.upper_sideband_db = Some(db(au));
    spectral_estimate(r, d, seg);
    r.spectrum = (((0.5 * f1) / df) as usize..((1.5 * f1) / df).min(amp.len() as f64) as usize)
        .map(|k| (k as f64 * df, db(amp[k])))
        .collect();
}

/// The mechanical speed's ripple at about `fs` = 2 s f over the stretch `st` (`np` pole
/// pairs).
fn speed_ripple(
    r: &mut McsaReport,
    d: &Prepared,
    st: &Stretch,
    np: f64,
    fs: f64,
    planner: &mut rustfft::FftPlanner<f64>,
) {
    let wm: Vec<f64> = d.omega_r[st.a..d.len()].iter().map(|w| w / np).collect();
    let (dfw, aw) = spectrum(planner, &wm, d.dt_s, 1.3 * fs);
    let (fw, a_w) = peak(dfw, &aw, fs, 0.2 * fs);
    r.speed_ripple_hz = Some(fw);
    r.speed_ripple_rad_s = Some(a_w);
}

#[cfg(test)]
mod tests;
