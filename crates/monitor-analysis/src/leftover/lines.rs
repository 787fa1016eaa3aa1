//! The leftover's spectral lines: the error's spectrum on the steady stretches, its
//! strongest lines, and what each line is at (the shaft's, the slip's, the supply's
//! frequencies).

use super::series::ErrorSeries;
use super::{Equation, LINE_PROMINENCE, LINE_SHARE_MIN, MAX_LINES};
use crate::metrics::fft;
use crate::prep::{Prepared, C64};
use crate::simplified_model::{MachineConstants, Prediction};
use crate::strata::StratumKind;
use serde::Serialize;

/// The shortest segment the spectrum is taken on [s] (a resolution of 2 Hz).
pub const SEGMENT_MIN_S: f64 = 0.5;
/// The longest [s] (a resolution of 0.25 Hz: 2 s f at 1 % slip on 50 Hz is 1 Hz).
pub const SEGMENT_MAX_S: f64 = 4.0;
/// The most segments averaged.
const MAX_SEGMENTS: usize = 32;
/// The lowest bin a line may sit in: below, the window's leakage of the error's offset and
/// slow drift.
const K_MIN: usize = 4;
/// Half the width [bins] of a Hann window's main lobe: a line's power is summed over
/// its peak bin and this many on each side.
const LOBE: usize = 2;
/// Half the span [bins] of the neighbourhood a peak's prominence is measured against.
const NEIGHBOURHOOD: usize = 40;
/// A reading matches a line within this share (1.5 %) of its frequency, or
/// [`MATCH_BINS`] bins, whichever is wider.
const MATCH_SHARE: f64 = 0.015;
/// ... or within this many bins.
const MATCH_BINS: f64 = 2.0;
/// The highest multiple of the shaft frequency a line is read as.
const SHAFT_MULTIPLES: u32 = 4;
/// The highest multiple of the supply frequency a line is read as.
const SUPPLY_MULTIPLES: u32 = 12;

/// Which samples the spectrum was taken on.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Stretches {
    /// The steady stretches (no start, no supply step, no load move).
    Steady,
    /// The log after its start, outside supply steps, load moves included: no steady
    /// stretch was long enough (a load that moves all the time).
    AfterStart,
    /// The whole log after its start, supply steps included: no stretch outside them was
    /// long enough (a supply stepped all the time).
    AfterStartWithSteps,
}

/// Why the spectrum could not be taken (JSON `leftover.spectrum.because`).
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
#[serde(tag = "kind", rename_all = "snake_case")]
pub enum NoSpectrum {
    /// No stretch after the start is long enough.
    NoStretch {
        /// The longest such stretch [s].
        longest_s: f64,
        /// The length a segment needs [s] ([`SEGMENT_MIN_S`]).
        needs_s: f64,
    },
}

/// How the spectrum was taken (JSON `leftover.spectrum`).
#[derive(Debug, Clone, PartialEq, Serialize)]
#[serde(tag = "state", rename_all = "snake_case")]
pub enum ErrorSpectrum {
    /// Taken.
    Taken {
        /// On which samples.
        stretches: Stretches,
        /// Segments averaged (Hann window, half overlapping).
        segments: usize,
        /// Each segment's length [s].
        segment_s: f64,
        /// The frequency resolution [Hz]: the bin spacing 1 / `segment_s` (the window's
        /// main lobe is four bins wide).
        resolution_hz: f64,
        /// The share (0..1) of the stretches' error that is a constant offset over a
        /// segment (no line: a static mismatch).
        offset_share: f64,
        /// The shaft's rotation frequency f_r = w_m / 2 pi over the segments [Hz] (from the
        /// measured speed; the model's without a speed column).
        shaft_hz: f64,
        /// The supply frequency f over the segments [Hz].
        supply_hz: f64,
        /// The slip s = (f - Np f_r) / f.
        slip: f64,
    },
    /// Not taken, and why.
    Refused {
        /// Why.
        because: NoSpectrum,
    },
}

/// What a line's frequency is (JSON `leftover.lines[].reading`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum LineReading {
    /// A multiple of the shaft's rotation frequency f_r (`multiple` 1: the shaft frequency
    /// itself; a torque or an asymmetry once per revolution).
    ShaftFrequency,
    /// 2 s f: the phase currents' (1 +/- 2 s) f sidebands (a rotor asymmetry).
    TwiceSlipFrequency,
    /// A multiple of the supply frequency f in the rotor-flux frame (1: an offset in a
    /// phase current; 2: the negative sequence; 6: the 5th and 7th harmonics).
    SupplyFrequency,
    /// None of these.
    NotNamed,
}

/// A reading of a line and the frequency it expects on this log.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct LineReadingOnLog {
    /// The reading.
    pub reading: LineReading,
    /// Of which multiple of its frequency (1 for 2 s f and for none).
    pub multiple: u32,
    /// The frequency the reading expects on this log [Hz] (null for none).
    pub expected_hz: Option<f64>,
}

/// A line of the error's spectrum (JSON `leftover.lines[]`).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct SpectralLine {
    /// Its frequency in the rotor-flux frame [Hz] (interpolated between bins).
    pub frequency_hz: f64,
    /// Its reading (JSON `reading`, `multiple`, `expected_hz` on the line).
    #[serde(flatten)]
    pub reading: LineReadingOnLog,
    /// A second reading as near: the log cannot tell the two apart.
    pub also: Option<LineReadingOnLog>,
    /// The equation it is strongest in.
    pub equation: Equation,
    /// Its amplitude there (the sinusoid's peak) [`unit`].
    pub amplitude: f64,
    /// The amplitude's unit.
    pub unit: &'static str,
    /// Its share (0..1) of the stretches' error (mean square, equations summed).
    pub share: f64,
    /// Its peak over the median of the spectrum around it.
    pub prominence: f64,
}

/// The runs `a..b` of the strata of `kinds`, adjacent ones joined.
fn runs_of(
    strata: &[(StratumKind, usize, usize)],
    len: usize,
    kinds: &[StratumKind],
) -> Vec<(usize, usize)> {
    let mut out: Vec<(usize, usize)> = Vec::new();
    for &(k, a, b) in strata {
        let (a, b) = (a.min(len), b.min(len));
        if !kinds.contains(&k) || b <= a {
            continue;
        }
        match out.last_mut() {
            Some(last) if last.1 == a => last.1 = b,
            _ => out.push((a, b)),
        }
    }
    out
}

/// The samples `a..b` of the runs the spectrum may use: the steady strata; where none is as
/// long as a segment (`min_len`), the runs of steady and load-move strata; where none of
/// those either, every stratum after the start. Else the longest after the start.
fn runs(
    strata: &[(StratumKind, usize, usize)],
    len: usize,
    min_len: usize,
) -> Result<(Stretches, Vec<(usize, usize)>), f64> {
    use StratumKind::{LoadMove, Steady, Transient};
    let longest = |r: &[(usize, usize)]| r.iter().map(|(a, b)| b - a).max().unwrap_or(0);
    let mut widest = 0;
    for (stretches, kinds) in [
        (Stretches::Steady, &[Steady][..]),
        (Stretches::AfterStart, &[Steady, LoadMove][..]),
        (
            Stretches::AfterStartWithSteps,
            &[Steady, LoadMove, Transient][..],
        ),
    ] {
        let r = runs_of(strata, len, kinds);
        widest = longest(&r);
        if widest >= min_len {
            return Ok((stretches, r));
        }
    }
    Err(widest as f64)
}

/// The segments' length [samples] on `runs`: the longest the runs and the `cap` allow (any
/// even length: the FFT is rustfft's mixed-radix), halved while its segments would cover
/// less than half the runs' samples and the half is at least `min_len` (a log of several
/// steady stretches is not read on its longest alone).
fn segment_len(runs: &[(usize, usize)], cap: usize, min_len: usize) -> usize {
    let total: usize = runs.iter().map(|(a, b)| b - a).sum();
    let covered = |n: usize| -> usize { runs.iter().map(|(a, b)| (b - a) / n * n).sum() };
    let longest = runs.iter().map(|(a, b)| b - a).max().unwrap_or(0);
    let mut n = (longest.min(cap) & !1).max(min_len.max(2));
    while 2 * covered(n) < total && n / 2 >= min_len {
        n = (n / 2) & !1;
    }
    n
}

/// The segments' starts: half overlapping in each run long enough, at most
/// [`MAX_SEGMENTS`] (evenly chosen).
fn segment_starts(runs: &[(usize, usize)], n: usize) -> Vec<usize> {
    let mut out = Vec::new();
    for &(a, b) in runs {
        let mut o = a;
        while o + n <= b {
            out.push(o);
            o += n / 2;
        }
    }
    if out.len() > MAX_SEGMENTS {
        let m = out.len();
        out = (0..MAX_SEGMENTS)
            .map(|i| out[i * m / MAX_SEGMENTS])
            .collect();
    }
    out
}

/// The averaged one-sided spectra of the error's channels over `starts` (segments of `n`
/// samples), each bin as the mean square it holds (normalised by the channel's scale), and
/// per channel the mean square of the segments and of their offsets.
struct Spectra {
    per_channel: Vec<Vec<f64>>,
    total: f64,
    offset: f64,
}

fn spectra(es: &ErrorSeries, starts: &[usize], n: usize) -> Spectra {
    let win: Vec<f64> = (0..n)
        .map(|k| 0.5 - 0.5 * (std::f64::consts::TAU * k as f64 / n as f64).cos())
        .collect();
    let sum_w2: f64 = win.iter().map(|w| w * w).sum();
    let s = starts.len().max(1) as f64;
    let mut total = 0.0;
    let mut offset = 0.0;
    let mut per_channel = Vec::with_capacity(es.channels.len());
    let mut buf = vec![C64::new(0.0, 0.0); n];
    for c in &es.channels {
        let mut p = vec![0.0; n / 2];
        for &o in starts {
            let x = |j: usize| c.e(o + j) / c.scale;
            let mean = (0..n).map(x).sum::<f64>() / n as f64;
            total += (0..n).map(|j| x(j).powi(2)).sum::<f64>() / n as f64 / s;
            offset += mean * mean / s;
            for (j, (b, w)) in buf.iter_mut().zip(&win).enumerate() {
                *b = C64::new((x(j) - mean) * w, 0.0);
            }
            fft(&mut buf);
            for (k, pk) in p.iter_mut().enumerate().skip(1) {
                *pk += 2.0 * buf[k].norm_sqr() / (n as f64 * sum_w2) / s;
            }
        }
        per_channel.push(p);
    }
    Spectra {
        per_channel,
        total,
        offset,
    }
}

/// The median of `v` (empty: 0).
fn median(mut v: Vec<f64>) -> f64 {
    if v.is_empty() {
        return 0.0;
    }
    let mid = v.len() / 2;
    let (_, m, _) = v.select_nth_unstable_by(mid, |a, b| a.total_cmp(b));
    *m
}

/// The log's frequencies over the segments: the shaft's f_r [Hz] (the measured speed, or the
/// model's), the supply's f [Hz] and the slip.
fn frequencies(
    d: &Prepared,
    n: &MachineConstants,
    p: &Prediction,
    starts: &[usize],
    len: usize,
) -> (f64, f64, f64) {
    let speed = if d.channels.speed && d.omega_r.len() >= d.len() {
        &d.omega_r
    } else {
        &p.omega_r
    };
    let (mut wr, mut ws, mut c) = (0.0, 0.0, 0usize);
    for &o in starts {
        for k in o..o + len {
            wr += speed[k].abs();
            ws += d.omega_s[k].abs();
            c += 1;
        }
    }
    let c = c.max(1) as f64;
    let (wr, ws) = (wr / c, ws / c);
    let f_r = wr / (n.np.max(1.0) * std::f64::consts::TAU);
    let f_s = ws / std::f64::consts::TAU;
    let slip = if ws > 0.0 { (ws - wr) / ws } else { 0.0 };
    (f_r, f_s, slip)
}

/// What a line at `f` [Hz] is (bins of `df`) on a log of shaft frequency `f_r`, supply
/// frequency `f_s` and slip `slip`: the nearest reading within its tolerance, and a second
/// one as near.
fn read(
    f: f64,
    df: f64,
    f_r: f64,
    f_s: f64,
    slip: f64,
) -> (LineReadingOnLog, Option<LineReadingOnLog>) {
    let mut cands: Vec<LineReadingOnLog> = Vec::new();
    if f_r > K_MIN as f64 * df {
        cands.extend((1..=SHAFT_MULTIPLES).map(|k| LineReadingOnLog {
            reading: LineReading::ShaftFrequency,
            multiple: k,
            expected_hz: Some(k as f64 * f_r),
        }));
    }
    let two_sf = 2.0 * slip * f_s;
    if two_sf > K_MIN as f64 * df {
        cands.push(LineReadingOnLog {
            reading: LineReading::TwiceSlipFrequency,
            multiple: 1,
            expected_hz: Some(two_sf),
        });
    }
    if f_s > K_MIN as f64 * df {
        cands.extend((1..=SUPPLY_MULTIPLES).map(|k| LineReadingOnLog {
            reading: LineReading::SupplyFrequency,
            multiple: k,
            expected_hz: Some(k as f64 * f_s),
        }));
    }
    let off = |r: &LineReadingOnLog| {
        let e = r.expected_hz.unwrap_or(f64::INFINITY);
        (f - e).abs() / (MATCH_SHARE * e).max(MATCH_BINS * df)
    };
    let mut near: Vec<(f64, LineReadingOnLog)> = cands
        .into_iter()
        .map(|r| (off(&r), r))
        .filter(|(o, _)| *o <= 1.0)
        .collect();
    near.sort_by(|a, b| a.0.total_cmp(&b.0));
    let mut it = near.into_iter().map(|(_, r)| r);
    let first = it.next().unwrap_or(LineReadingOnLog {
        reading: LineReading::NotNamed,
        multiple: 1,
        expected_hz: None,
    });
    (first, it.next())
}

/// The error's spectrum on the log's steady stretches ([`runs`]) and its claimed lines
/// (module doc of [`super`]), or why it could not be taken.
pub(super) fn spectrum(
    d: &Prepared,
    n: &MachineConstants,
    p: &Prediction,
    es: &ErrorSeries,
    strata: &[(StratumKind, usize, usize)],
) -> Result<(ErrorSpectrum, Vec<SpectralLine>), NoSpectrum> {
    let dt = d.dt_s.max(1e-9);
    let min_len = (SEGMENT_MIN_S / dt).ceil() as usize;
    let (stretches, runs) = runs(strata, es.len(), min_len).map_err(|l| NoSpectrum::NoStretch {
        longest_s: l * dt,
        needs_s: SEGMENT_MIN_S,
    })?;
    let seg = segment_len(&runs, (SEGMENT_MAX_S / dt).round() as usize, min_len);
    let starts = segment_starts(&runs, seg);
    let sp = spectra(es, &starts, seg);
    let df = 1.0 / (seg as f64 * dt);
    let (f_r, f_s, slip) = frequencies(d, n, p, &starts, seg);
    let lines = claimed_lines(es, &sp, df, (f_r, f_s, slip));
    let basis = ErrorSpectrum::Taken {
        stretches,
        segments: starts.len(),
        segment_s: seg as f64 * dt,
        resolution_hz: df,
        offset_share: if sp.total > 0.0 {
            sp.offset / sp.total
        } else {
            0.0
        },
        shaft_hz: f_r,
        supply_hz: f_s,
        slip,
    };
    Ok((basis, lines))
}

/// The prominence of bin `k` of the summed spectrum `sum` and the median around it (its
/// baseline), when `k` is a peak: above every other bin of its lobe.
fn peak_at(sum: &[f64], k: usize) -> Option<(f64, f64)> {
    let peak = sum[k];
    let is_max = (k - LOBE..=k + LOBE).all(|j| j == k || sum[j] < peak);
    if !is_max || peak <= 0.0 {
        return None;
    }
    let lo = k.saturating_sub(NEIGHBOURHOOD).max(1);
    let hi = (k + NEIGHBOURHOOD).min(sum.len() - 1);
    let around: Vec<f64> = (lo..=hi)
        .filter(|j| j.abs_diff(k) > LOBE + 1)
        .map(|j| sum[j])
        .collect();
    let base = median(around);
    Some((peak / base.max(f64::MIN_POSITIVE), base))
}

/// The frequency [Hz] of the peak at bin `k` of `sum` (bins of `df` Hz) between the bins:
/// a Gaussian through the three bins about it (the Hann window's lobe is near one).
fn between_bins(sum: &[f64], k: usize, df: f64) -> f64 {
    let ln = |v: f64| v.max(f64::MIN_POSITIVE).ln();
    let (a, b, g) = (ln(sum[k - 1]), ln(sum[k]), ln(sum[k + 1]));
    let den = a - 2.0 * b + g;
    let delta = if den.abs() > 1e-12 {
        (0.5 * (a - g) / den).clamp(-0.5, 0.5)
    } else {
        0.0
    };
    (k as f64 + delta) * df
}

/// The lines of the spectra `sp` (bins of `df` Hz) that stand out ([`LINE_PROMINENCE`]) and
/// carry a share of the error ([`LINE_SHARE_MIN`]), largest first, each read against the
/// log's frequencies `(f_r, f_s, slip)`.
fn claimed_lines(
    es: &ErrorSeries,
    sp: &Spectra,
    df: f64,
    freqs: (f64, f64, f64),
) -> Vec<SpectralLine> {
    let half = sp.per_channel.first().map_or(0, Vec::len);
    let sum: Vec<f64> = (0..half)
        .map(|k| sp.per_channel.iter().map(|p| p[k]).sum())
        .collect();
    let mut out = Vec::new();
    if half < K_MIN + LOBE + 2 || sp.total <= 0.0 {
        return out;
    }
    for k in K_MIN..half - LOBE - 1 {
        let Some((prominence, base)) = peak_at(&sum, k) else {
            continue;
        };
        let lobe = (k - LOBE)..=(k + LOBE);
        let width = (2 * LOBE + 1) as f64;
        let share = (lobe.clone().map(|j| sum[j]).sum::<f64>() - width * base) / sp.total;
        if prominence < LINE_PROMINENCE || share < LINE_SHARE_MIN {
            continue;
        }
        // Where the line is strongest, and its amplitude there.
        let (c, ms) = sp
            .per_channel
            .iter()
            .enumerate()
            .map(|(c, p)| (c, lobe.clone().map(|j| p[j]).sum::<f64>()))
            .max_by(|a, b| a.1.total_cmp(&b.1))
            .unwrap_or((0, 0.0));
        let ch = &es.channels[c];
        let f = between_bins(&sum, k, df);
        let (reading, also) = read(f, df, freqs.0, freqs.1, freqs.2);
        out.push(SpectralLine {
            frequency_hz: f,
            reading,
            also,
            equation: ch.equation,
            amplitude: (2.0 * ms).sqrt() * ch.scale,
            unit: ch.equation.unit(),
            share,
            prominence,
        });
    }
    out.sort_by(|a, b| b.share.total_cmp(&a.share));
    out.truncate(MAX_LINES);
    out
}
