//! The full-order machine fitted to a log's first seconds against its parameter file, for
//! `diagnose` where nothing is commissioned (`monitor_replay::StartFit`): the residuals
//! against the file's nominal values cannot tell a fault present from the first sample
//! from the file's own error, a start or a load change in the log can. The fit is
//! `identify`'s (`monitor_analysis::identify`), on at most [`FIT_WINDOW_S`] of the log.

use monitor_analysis::identify::{identify, Samples};
use monitor_io::log::{LogFile, Row, RowSink};
use monitor_io::params::ParamFile;
use monitor_replay::{FitParameter, FittedChange, StartFit};

/// The most of the log's start the machine is fitted to [s]: a direct-on-line start and
/// its settling, or a load step after it, for the machines the project ships (a 37 kW
/// start takes about 2 s); a longer window costs time and adds no excitation.
pub const FIT_WINDOW_S: f64 = 6.0;

/// The rows of the log's first [`FIT_WINDOW_S`].
struct Head {
    rows: Vec<Row>,
    t0: Option<f64>,
}

impl RowSink for Head {
    fn row(&mut self, row: &Row) -> bool {
        let t0 = *self.t0.get_or_insert(row.t_s);
        if row.t_s - t0 > FIT_WINDOW_S {
            return false;
        }
        self.rows.push(*row);
        true
    }
    fn restart(&mut self) {
        self.rows.clear();
        self.t0 = None;
    }
}

/// The least ratio of the largest to the smallest mean square of the current over
/// [`MOVE_WINDOW_S`] windows for the log's head to excite the fit: a start draws 25-50
/// times its running current's square, a 30 % load step about 1.5 times; steady running
/// (a few per cent) leaves every parameter flat, and the fit would only spend its
/// iterations finding so.
pub const MOVES_MIN: f64 = 1.3;
/// The windows [`MOVES_MIN`] is judged over [s].
pub const MOVE_WINDOW_S: f64 = 0.1;

/// Whether the current moves enough within `rows` to excite the fit ([`MOVES_MIN`]).
fn moves(rows: &[Row]) -> bool {
    let Some(first) = rows.first() else {
        return false;
    };
    let mut windows: Vec<(f64, u32)> = Vec::new();
    for r in rows {
        let k = ((r.t_s - first.t_s) / MOVE_WINDOW_S) as usize;
        if windows.len() <= k {
            windows.resize(k + 1, (0.0, 0));
        }
        let i2: f64 = r.i_abc.iter().map(|x| x * x).sum();
        if i2.is_finite() {
            windows[k].0 += i2;
            windows[k].1 += 1;
        }
    }
    let means: Vec<f64> = windows
        .iter()
        .filter(|w| w.1 > 0)
        .map(|w| w.0 / f64::from(w.1))
        .collect();
    let (lo, hi) = means.iter().fold((f64::INFINITY, 0.0f64), |(lo, hi), m| {
        (lo.min(*m), hi.max(*m))
    });
    hi > MOVES_MIN * lo && lo > 0.0
}

/// The machine of `params` fitted to the head of `file`, where the log has its voltages
/// and the fit runs (a log that leaves every parameter flat identifies none of them; a
/// log the model cannot be driven by gives `None`).
pub(crate) fn fit(params: &ParamFile, file: &LogFile) -> Option<StartFit> {
    let channels = file.channels();
    if !channels.voltages {
        return None;
    }
    let mut head = Head {
        rows: Vec::new(),
        t0: None,
    };
    file.for_each_row(&mut |_| {}, &mut head).ok()?;
    if !moves(&head.rows) {
        return None;
    }
    let samples =
        Samples::from_rows(&head.rows, channels, f64::NEG_INFINITY, f64::INFINITY).ok()?;
    let id = identify(params, &samples, &mut |_| {}).ok()?;
    let parameters = [
        FitParameter::Rs,
        FitParameter::Rr,
        FitParameter::Leakage,
        FitParameter::Lm,
    ];
    let changes = id
        .estimates
        .iter()
        .zip(parameters)
        .filter_map(|(e, parameter)| {
            let rel = |x: f64| (x / e.start - 1.0) as f32;
            Some(FittedChange {
                parameter,
                change: rel(e.value?),
                low: rel(e.lo?),
                high: rel(e.hi?),
            })
        })
        .collect();
    Some(StartFit {
        from_s: id.window_s.0,
        to_s: id.window_s.1,
        relative_rms_error: id.relative_rms_error,
        changes,
    })
}
