//! The rotor finding at the end of a replay ([`rotor_report`]): the steady stretch, the
//! slip, the sidebands read from the Welch segments, and the judgement (module docs of
//! `super`).

use super::baseband::{Block, RotorFront};
use super::judge::{band_of, bars_of, fault_probability, noise_max, torque_share};
use super::load::{MeasuredPoint, RotorLoad};
use super::spectrum::{segments, spectrum, Spectrum, SEGMENT_S};
use super::stretch::{chunks, longest_run, Chunk};
use super::{
    RotorCannot, RotorMachine, RotorReport, SlipSource, MAIN_LOBE_HALF_BINS, MAX_SLIP, MIN_BINS,
    MIN_SLIP, PAIR_SNR_DB, SLIP_STEADY,
};
use monitor_io::params::ParamFile;
use std::f64::consts::TAU;
use std::ops::Range;

/// The sidebands read over a stretch's segments, relative to the line.
#[derive(Debug, Clone, Copy, Default)]
struct SidebandReading {
    /// Mean power of the lower and upper sidebands' largest bins.
    lower: f64,
    upper: f64,
    /// Mean noise power per bin near them.
    noise: f64,
    /// Independent bins searched per sideband.
    bins: f64,
    /// Segments averaged.
    k: usize,
    /// Their resolution [Hz], mean supply frequency [Hz] and mean slip.
    resolution_hz: f64,
    f_supply: f64,
    slip: f64,
}

/// The rotor finding of the record `front` of a log of the machine `params` (module docs
/// of `super`): judged, or "cannot judge" with what was missing.
/// `measured`: the voltages' operating points over the log's steady stretches (`[from, to]`
/// [s] and the point), where it has voltages; the one holding the rotor's stretch's middle
/// gives the load where the log has no speed ([`RotorLoad`]).
pub fn rotor_report(
    front: &RotorFront,
    params: &ParamFile,
    measured: &[([f64; 2], MeasuredPoint)],
) -> RotorReport {
    let m = RotorMachine::of(params);
    let r = RotorReport {
        rotor_bars: m.bars,
        ..RotorReport::default()
    };
    let blocks: Vec<Block> = front.blocks().iter().copied().collect();
    let bs = front.block_s();
    if blocks.len() < 16 {
        return cannot(r, RotorCannot::NoCurrent);
    }
    let by_speed = blocks.iter().any(|b| b.wm.is_finite());
    let ch = chunks(&blocks, bs, m.np);
    let Some(run) = longest_run(&ch, by_speed) else {
        return cannot(r, RotorCannot::NotSteady { by_speed });
    };
    let span = span_of(&ch, run.clone());
    let mut r = r;
    r.window_s = [span.start, span.end - 1]
        .iter()
        .filter_map(|&k| blocks.get(k).map(|b| b.t_s))
        .collect();
    let stretch = blocks.get(span).unwrap_or(&[]);
    let speed_slip = by_speed.then(|| {
        let s = ch.get(run).unwrap_or(&[]);
        s.iter().map(|c| c.slip).sum::<f64>() / s.len().max(1) as f64
    });
    let load = load_of(params, stretch, speed_slip, measured);
    r.load = Some(load.clone());
    if load.too_low() {
        let no_load = load.fraction.is_some_and(|x| x < NO_LOAD);
        return cannot(r, RotorCannot::LoadTooLow { no_load });
    }
    let mut planner = rustfft::FftPlanner::new();
    let slip = match speed_slip {
        Some(s) => Some((s, SlipSource::Speed)),
        None => slip_from_pairs(&mut r, &mut planner, stretch, bs, &m, &load),
    };
    let Some((s, source)) = slip else {
        return r;
    };
    r.slip = Some(s);
    r.slip_source = Some(source);
    read_and_judge(r, &mut planner, stretch, bs, &m, (by_speed, s))
}

/// Below this fraction of the rated torque a load too low to judge is "no load" in the
/// finding's words, above it "light load".
const NO_LOAD: f64 = 0.1;

/// The load over `stretch` (module docs of [`super::load`]): from the speed's slip where
/// measured, else from the voltages' operating point holding the stretch's middle, else from
/// the current's mean magnitude.
fn load_of(
    params: &ParamFile,
    stretch: &[Block],
    speed_slip: Option<f64>,
    measured: &[([f64; 2], MeasuredPoint)],
) -> RotorLoad {
    if let Some(s) = speed_slip {
        return RotorLoad::from_speed(params, s);
    }
    let mid = match (stretch.first(), stretch.last()) {
        (Some(a), Some(b)) => 0.5 * (a.t_s + b.t_s),
        _ => f64::NAN,
    };
    if let Some((_, m)) = measured
        .iter()
        .find(|(w, _)| (w[0]..=w[1]).contains(&mid))
        .or_else(|| measured.first())
    {
        return RotorLoad::from_power(params, m);
    }
    let n = stretch.len().max(1) as f64;
    let i1 = stretch
        .iter()
        .map(|b| f64::from(b.z[0]).hypot(f64::from(b.z[1])))
        .sum::<f64>()
        / n;
    RotorLoad::from_current(params, i1)
}

/// The blocks of the chunks `run`.
fn span_of(ch: &[Chunk], run: Range<usize>) -> Range<usize> {
    let first = ch.get(run.start).map_or(0, |c| c.first);
    let end = ch.get(run.end.wrapping_sub(1)).map_or(first, |c| c.end);
    first..end
}

/// `r` with the reason it cannot judge.
fn cannot(mut r: RotorReport, why: RotorCannot) -> RotorReport {
    r.judged = false;
    r.cannot_judge_because = Some(why);
    r
}

/// The segments' length in blocks for sidebands `fs` [Hz] from the line (at least
/// [`SEGMENT_S`], and twice what [`MIN_BINS`] needs), blocks `bs` [s] apart.
fn segment_blocks(fs: f64, bs: f64) -> usize {
    ((SEGMENT_S.max(2.0 * MIN_BINS / fs.max(1e-9)) / bs).round() as usize).max(16)
}

/// The spectra of `stretch`'s segments ([`segments`]) of `seg_blocks` blocks.
fn spectra<'a>(
    planner: &'a mut rustfft::FftPlanner<f64>,
    stretch: &'a [Block],
    bs: f64,
    m: &'a RotorMachine,
    seg_blocks: usize,
) -> impl Iterator<Item = Spectrum> + 'a {
    segments(0..stretch.len(), seg_blocks)
        .into_iter()
        .filter_map(move |r| spectrum(planner, stretch.get(r)?, bs, TAU * m.f0, m.np))
}

/// The slip from a pair about the line in the stretch's averaged spectrum: the sidebands
/// themselves, else the rotation harmonics (module docs of `super`); `None`, with `r` saying
/// why and the largest component where the sidebands could be, when neither stands
/// [`PAIR_SNR_DB`] above the noise.
fn slip_from_pairs(
    r: &mut RotorReport,
    planner: &mut rustfft::FftPlanner<f64>,
    stretch: &[Block],
    bs: f64,
    m: &RotorMachine,
    load: &RotorLoad,
) -> Option<(f64, SlipSource)> {
    let fs_min = 2.0 * MIN_SLIP * m.f0;
    let mut avg: Option<Spectrum> = None;
    let mut k = 0usize;
    for s in spectra(planner, stretch, bs, m, segment_blocks(fs_min, bs)) {
        k += 1;
        match avg.as_mut() {
            Some(a) => a.add(&s),
            None => avg = Some(s),
        }
    }
    let mut avg = avg?;
    avg.scale(k as f64);
    let f = avg.f_supply.abs();
    let res = avg.resolution_hz;
    let clear = (MAIN_LOBE_HALF_BINS + 1.0) * res;
    let noise = avg.noise((clear, f), &[], k)?;
    let side = (2.0 * MIN_SLIP * f).max(clear)..2.0 * MAX_SLIP * f;
    let rot = f * (1.0 - MAX_SLIP) / m.np..f * (1.0 - MIN_SLIP) / m.np;
    // The rotation harmonics first (present in every real machine, and no sign of a fault),
    // then the sidebands; a pair whose refined distance gives a slip outside the range
    // searched is something else.
    // A slip the machine cannot run at steadily at this load (past 1.5 times its rated
    // slip, or its breakdown slip: `super::load`) is not the rotor's either.
    let steady = load.rated.map(|rt| rt.max_steady_slip(load.slip));
    let plausible = |s: f64| (0.0..=MAX_SLIP).contains(&s);
    let at_load = |s: f64| steady.is_none_or(|top| s <= top);
    let from_rotation = pair(&avg, rot, noise).map(|d| 1.0 - m.np * d / f);
    if let Some(s) = from_rotation.filter(|s| plausible(*s) && at_load(*s)) {
        return Some((s, SlipSource::Eccentricity));
    }
    let from_sidebands = pair(&avg, side.clone(), noise).map(|d| d / (2.0 * f));
    if let Some(s) = from_sidebands.filter(|s| plausible(*s)) {
        if let Some(top) = steady.filter(|top| s > *top) {
            *r = cannot(
                std::mem::take(r),
                RotorCannot::NotSidebands { slip: s, top },
            );
            return None;
        }
        return Some((s, SlipSource::Sidebands));
    }
    let (_, largest) = avg.peak(-side.end, -side.start);
    r.largest_possible_db = Some(10.0 * largest.max(1e-30).log10());
    *r = cannot(
        std::mem::take(r),
        RotorCannot::SlipUnknown {
            largest_db_below: -10.0 * largest.max(1e-30).log10(),
        },
    );
    None
}

/// The Blackman-Harris window's highest sidelobe [dB] (Harris 1978): what a line leaks
/// outside its main lobe.
const SIDELOBE_DB: f64 = -92.0;

/// The distance [Hz] of the strongest symmetric pair about the line at distances in
/// `range` [Hz] whose weaker member stands [`PAIR_SNR_DB`] above the `noise` per bin (and
/// above the window's sidelobes)
/// (members within one resolution bin of `-/+ d`; `d` refined to half their distance).
fn pair(s: &Spectrum, range: Range<f64>, noise: f64) -> Option<f64> {
    let res = s.resolution_hz;
    // Above the noise and above the window's own leakage (its sidelobes, -92 dB: a
    // noise-free record's line leaks a symmetric "pair" there).
    let need = noise.max(10f64.powf(SIDELOBE_DB / 10.0)) * 10f64.powf(PAIR_SNR_DB / 10.0);
    let steps = ((range.end - range.start) / s.df).max(0.0) as usize;
    (0..=steps)
        .map(|j| range.start + j as f64 * s.df)
        .map(|d| {
            let lo = s.peak(-d - res, -d + res);
            let hi = s.peak(d - res, d + res);
            (0.5 * (hi.0 - lo.0), lo.1.min(hi.1))
        })
        .filter(|&(d, p)| p >= need && d > 0.0)
        .max_by(|a, b| a.1.total_cmp(&b.1))
        .map(|(d, _)| d)
}

/// Reads the sidebands over `stretch` at the slip (`per_segment`: each segment's own from
/// the speed, else `s` throughout) and judges them.
fn read_and_judge(
    mut r: RotorReport,
    planner: &mut rustfft::FftPlanner<f64>,
    stretch: &[Block],
    bs: f64,
    m: &RotorMachine,
    (per_segment, s): (bool, f64),
) -> RotorReport {
    let f = m.f0;
    let fs = 2.0 * s.abs() * f;
    r.resolution_needed_hz = Some(fs / MIN_BINS);
    if s < MIN_SLIP {
        return cannot(r, RotorCannot::SlipBelow { slip: s });
    }
    if s > MAX_SLIP {
        return cannot(r, RotorCannot::SlipAbove { slip: s });
    }
    let t = stretch.len() as f64 * bs;
    if t < MIN_BINS / fs {
        r.resolution_hz = Some(1.0 / t.max(bs));
        return cannot(
            r,
            RotorCannot::TooShort {
                stretch_s: t,
                needed_s: MIN_BINS / fs,
                offset_hz: fs,
            },
        );
    }
    let mut sum = SidebandReading::default();
    for sp in spectra(planner, stretch, bs, m, segment_blocks(fs, bs)) {
        let slip = if per_segment { sp.slip } else { s };
        if let Some(x) = read_segment(&sp, slip) {
            add(&mut sum, &x);
        }
    }
    if sum.k == 0 {
        return cannot(r, RotorCannot::NoLine);
    }
    let k = sum.k as f64;
    for x in [
        &mut sum.lower,
        &mut sum.upper,
        &mut sum.noise,
        &mut sum.bins,
    ] {
        *x /= k;
    }
    sum.resolution_hz /= k;
    sum.f_supply /= k;
    sum.slip /= k;
    judge(r, &sum, m)
}

/// Adds segment reading `x` into `sum`.
fn add(sum: &mut SidebandReading, x: &SidebandReading) {
    sum.lower += x.lower;
    sum.upper += x.upper;
    sum.noise += x.noise;
    sum.bins += x.bins;
    sum.k += 1;
    sum.resolution_hz += x.resolution_hz;
    sum.f_supply += x.f_supply;
    sum.slip += x.slip;
}

/// One segment's sidebands at slip `s`: the largest bins within [`SLIP_STEADY`] of
/// `-/+ 2 s f` (the lower on the side opposite the supply's rotation) and the noise near
/// them (the median outside the sidebands' intervals and their second harmonics').
fn read_segment(sp: &Spectrum, s: f64) -> Option<SidebandReading> {
    let f = sp.f_supply;
    let c = 2.0 * s * f.abs();
    if c.is_nan() || c <= 0.0 {
        return None;
    }
    let h = SLIP_STEADY * c;
    let dir = if f < 0.0 { 1.0 } else { -1.0 };
    let (_, lower) = sp.peak(dir * c - h, dir * c + h);
    let (_, upper) = sp.peak(-dir * c - h, -dir * c + h);
    let res = sp.resolution_hz;
    let wide = h + MAIN_LOBE_HALF_BINS * res;
    let skip = [
        (c - wide, c + wide),
        (-c - wide, -c + wide),
        (2.0 * c - 2.0 * wide, 2.0 * c + 2.0 * wide),
        (-2.0 * c - 2.0 * wide, -2.0 * c + 2.0 * wide),
    ];
    let region = (MAIN_LOBE_HALF_BINS * res, (3.0 * c).max(c + 40.0 * res));
    let noise = sp
        .noise(region, &skip, 1)
        .or_else(|| sp.noise((region.0, f.abs()), &skip, 1))?;
    Some(SidebandReading {
        lower,
        upper,
        noise,
        bins: (2.0 * h / res).max(1.0),
        k: 1,
        resolution_hz: res,
        f_supply: f.abs(),
        slip: s,
    })
}

/// The judgement of the averaged reading `x` (module docs of `super`).
fn judge(mut r: RotorReport, x: &SidebandReading, m: &RotorMachine) -> RotorReport {
    let db = |p: f64| 10.0 * p.max(1e-30).log10();
    let (s, f) = (x.slip, x.f_supply);
    r.slip = Some(s);
    r.supply_hz = Some(f);
    r.sideband_hz = vec![(1.0 - 2.0 * s) * f, (1.0 + 2.0 * s) * f];
    r.segments = x.k;
    r.resolution_hz = Some(x.resolution_hz);
    let level = db(x.lower);
    let floor = noise_max(x.noise, x.bins);
    r.level_db = Some(level);
    r.upper_sideband_db = Some(db(x.upper));
    r.noise_floor_db = Some(db(floor));
    let mut p = fault_probability(x.lower, x.noise, x.bins, x.k);
    if r.slip_source == Some(SlipSource::Sidebands) {
        p = p.min(super::PAIR_ONLY_CONFIDENCE);
    }
    r.confidence = Some(p);
    let share = torque_share(s, TAU * f, m.tau_r_s);
    r.torque_current_share = Some(share);
    (r.delta, r.broken_bars) = bars_of(x.lower.sqrt(), x.upper.sqrt(), share, m.bars);
    // A reading at the noise says only "below the noise": a judgement where the noise is
    // below what a healthy cage reads, none above it.
    let at_noise = x.lower < 2.0 * floor;
    if at_noise && db(floor) > super::RotorBand::NoSign.upper_db() {
        return cannot(
            r,
            RotorCannot::Noisy {
                floor_db_below: -db(floor),
            },
        );
    }
    r.band = Some(band_of(level));
    r.judged = true;
    r.at_noise = at_noise;
    r
}
