//! The charts of `explain --ladder` (drawn and written by [`super::plot`]): the error after
//! each step onto the noise-floor band ([`ladder_chart`]), and over time before and after
//! each step with the log's events marked ([`ladder_time_chart`]).

use super::plot::{Chart, Series};
use monitor_api::analysis::{LadderReport, LadderStep, FLOOR_BAND};

/// The chart `explain --ladder` writes: the error after each step onto the floor band.
pub const LADDER: &str = "ladder";
/// ... and the error over time before and after each step, the log's events marked.
pub const LADDER_TIME: &str = "ladder_time";
/// Every chart `explain --ladder` writes.
pub const LADDER_CHARTS: [&str; 2] = [LADDER, LADDER_TIME];

/// The ladder chart's name of step `k` (`s`), as its tick reads: its number (the table's)
/// and what it added (`1: +load_torque`), refitted (`2: base refit`) or removed
/// (`3: +saturation -load_torque`).
fn step_name(k: usize, s: &LadderStep) -> String {
    let mut name = match s.effect {
        None => "base refit".to_string(),
        Some(_) => s
            .added
            .iter()
            .map(|e| format!("+{}", e.name()))
            .collect::<Vec<_>>()
            .join(" "),
    };
    for d in &s.dropped {
        name.push_str(&format!(" -{}", d.name()));
    }
    format!("{k}: {name}")
}

/// `explain --ladder`'s chart: the whole-log and the held-back error after each step (step 0:
/// the model as configured) on a logarithmic axis, with the noise floor and the band's top
/// ([`FLOOR_BAND`] times it) as lines: the error falls step by step onto the band. The x
/// axis has one tick per step, named by what the step added ([`step_name`]).
pub fn ladder_chart(r: &LadderReport) -> Chart<'static> {
    let mut whole = vec![(0.0, r.start.error)];
    let mut held = vec![(0.0, r.start.heldback_error)];
    let mut floor = vec![(0.0, r.start.noise_floor)];
    for (k, s) in r.ladder.iter().enumerate() {
        let x = (k + 1) as f64;
        whole.push((x, s.error));
        held.push((x, s.heldback_error));
        floor.push((x, s.noise_floor));
    }
    let band: Vec<(f64, f64)> = floor.iter().map(|&(x, y)| (x, FLOOR_BAND * y)).collect();
    let line = |label: String, points: Vec<(f64, f64)>, color: usize, dashed: bool| Series {
        label,
        points,
        color,
        scatter: false,
        dashed,
    };
    let omitted = (!r.start.error.is_finite()).then(|| monitor_api::words::ladder::stopped(r));
    Chart {
        stem: LADDER,
        title: "The ladder: the model's error after each step, onto the noise floor",
        x_label: "step: what it added (+ an effect, or the base parameters refitted), as the table numbers it",
        y_label: "normalized RMS error",
        series: vec![
            line("whole log".into(), whole.clone(), 0, false),
            Series {
                label: "whole log (each step)".into(),
                points: whole,
                color: 0,
                scatter: true,
                dashed: false,
            },
            line("held-back windows".into(), held, 1, false),
            line("noise floor".into(), floor, 2, true),
            line(
                format!("floor band ({FLOOR_BAND}x the floor)"),
                band,
                3,
                true,
            ),
        ],
        log_y: true,
        omitted,
        x_names: std::iter::once("0: as configured".to_string())
            .chain(r.ladder.iter().enumerate().map(|(k, s)| step_name(k + 1, s)))
            .collect(),
    }
}

/// The colours of the steps' lines on [`ladder_time_chart`] (the configured model is red
/// and dashed, the chosen model refitted blue, the floor grey, the events cyan): no two
/// entries of a chart share a colour, so a ladder of more steps draws its first and its
/// last [`STEP_COLOURS`]`.len() / 2` ([`drawn_steps`]).
const STEP_COLOURS: [usize; 6] = [2, 3, 4, 6, 7, 8];

/// The steps of a ladder of `n` steps [`ladder_time_chart`] draws (0-based): every one, or
/// for a longer ladder the first and the last three.
fn drawn_steps(n: usize) -> Vec<usize> {
    let m = STEP_COLOURS.len();
    if n <= m {
        (0..n).collect()
    } else {
        (0..m / 2).chain(n - m / 2..n).collect()
    }
}

/// `explain --ladder`'s chart over time: the model's error per supply period as configured
/// (dashed), after each kept step (named as on [`ladder_chart`]'s axis; [`drawn_steps`]), and
/// the chosen model refitted on the whole log, on a logarithmic axis, with the end's noise
/// floor and the log's events (the start's end, supply or speed steps, load moves: the
/// strata of the held-back split) as vertical lines: where in the log each step took the
/// error down.
pub fn ladder_time_chart(r: &LadderReport) -> Chart<'static> {
    let mut series = step_lines(r);
    let drawn = |p: &&(f64, f64)| p.0.is_finite() && p.1.is_finite() && p.1 > 0.0;
    let all: Vec<(f64, f64)> = series
        .iter()
        .flat_map(|s| s.points.iter().filter(drawn).copied())
        .collect();
    let span = |v: &dyn Fn(&(f64, f64)) -> f64| {
        all.iter()
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), p| {
                (a.min(v(p)), b.max(v(p)))
            })
    };
    let ((t0, t1), (lo, hi)) = (span(&|p| p.0), span(&|p| p.1));
    let floor = r
        .final_fit
        .as_ref()
        .map(|f| f.noise_floor)
        .or_else(|| r.ladder.last().map(|s| s.noise_floor))
        .unwrap_or(r.start.noise_floor);
    if floor.is_finite() && floor > 0.0 && t1 > t0 {
        series.push(Series {
            label: "noise floor (end)".into(),
            points: vec![(t0, floor), (t1, floor)],
            color: 5,
            scatter: false,
            dashed: true,
        });
    }
    series.extend(event_marks(r, (lo.min(floor), hi)));
    let omitted = all
        .is_empty()
        .then(|| monitor_api::words::ladder::stopped(r));
    Chart {
        stem: LADDER_TIME,
        title: "The ladder over time: the model's error before and after each step",
        x_label: "time [s] (cyan lines: the log's events)",
        y_label: "normalized RMS error per supply period",
        series,
        log_y: true,
        omitted,
        x_names: Vec::new(),
    }
}

/// The error over time of the model as configured (red, dashed), after each drawn step
/// ([`drawn_steps`], named by [`step_name`]) and refitted at the end (blue).
fn step_lines(r: &LadderReport) -> Vec<Series> {
    let line = |label: String, points: &Vec<(f64, f64)>, color: usize, dashed: bool| Series {
        label,
        points: points.clone(),
        color,
        scatter: false,
        dashed,
    };
    let mut series = vec![line(
        "0: as configured".into(),
        &r.start.error_over_time,
        1,
        true,
    )];
    for (j, k) in drawn_steps(r.ladder.len()).into_iter().enumerate() {
        let s = &r.ladder[k];
        series.push(line(
            step_name(k + 1, s),
            &s.error_over_time,
            STEP_COLOURS[j],
            false,
        ));
    }
    if let Some(f) = &r.final_fit {
        series.push(line(
            "end: refitted on the whole log".into(),
            &f.error_over_time,
            0,
            false,
        ));
    }
    series
}

/// The log's events of `r`'s split as vertical lines from `lo` to `hi` (pen lifted between
/// them): the start's end, and where each supply or speed step and each load move begins
/// and ends (the strata's boundaries: a load move's stratum opens a little before the step
/// and closes once the speed has settled); `None` for a log without events (or nothing
/// drawn).
fn event_marks(r: &LadderReport, (lo, hi): (f64, f64)) -> Option<Series> {
    if !(lo.is_finite() && hi.is_finite() && lo > 0.0 && hi > lo) {
        return None;
    }
    let mut points = Vec::new();
    let mut kinds: Vec<&str> = Vec::new();
    for s in &r.split.strata {
        let (times, what) = match s.kind {
            "start" => (vec![s.t_end_s], "the start's end"),
            "transient" => (vec![s.t_start_s, s.t_end_s], "supply or speed steps"),
            "load_move" => (vec![s.t_start_s, s.t_end_s], "load moves"),
            _ => continue,
        };
        for t in times {
            points.extend([(t, lo), (t, hi), (f64::NAN, f64::NAN)]);
        }
        if !kinds.contains(&what) {
            kinds.push(what);
        }
    }
    (!kinds.is_empty()).then(|| Series {
        label: format!(
            "log events (where each begins and ends): {}",
            kinds.join(", ")
        ),
        points,
        color: 9,
        scatter: false,
        dashed: false,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every step of a short ladder, the first and the last three of a long one: never more
    /// lines than colours, none twice.
    #[test]
    fn a_long_ladder_draws_its_first_and_last_steps() {
        assert_eq!(drawn_steps(0), Vec::<usize>::new());
        assert_eq!(drawn_steps(4), vec![0, 1, 2, 3]);
        assert_eq!(drawn_steps(6), vec![0, 1, 2, 3, 4, 5]);
        assert_eq!(drawn_steps(9), vec![0, 1, 2, 6, 7, 8]);
    }
}
