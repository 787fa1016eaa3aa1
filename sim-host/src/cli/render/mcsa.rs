//! `explain`'s motor current signature analysis (`rotor_asymmetry` key): its text lines and
//! the current spectrum around the fundamental with the (1 -/+ 2s) f sidebands marked.

use super::plot::{self, Chart, Series};
use monitor_api::analysis::McsaReport;

/// File stem of the spectrum chart `explain --plot DIR` writes.
pub const CHART: &str = "mcsa_spectrum";

/// Text lines of the report (for the human table).
pub fn text(r: &McsaReport) -> String {
    let mut s = String::from("  rotor (motor current signature analysis):\n");
    match (
        &r.cannot_judge_because,
        r.lower_sideband_db,
        r.upper_sideband_db,
    ) {
        (Some(why), _, _) => s.push_str(&format!("    {why}\n")),
        (None, Some(l), Some(u)) => {
            let f = |i: usize| r.sideband_hz.get(i).copied().unwrap_or(f64::NAN);
            s.push_str(&format!(
                "    sidebands: {l:.1} dB at (1-2s)f = {:.2} Hz, {u:.1} dB at (1+2s)f = {:.2} Hz (below the fundamental {:.2} Hz; slip {:.4})\n",
                f(0),
                f(1),
                r.fundamental_hz.unwrap_or(f64::NAN),
                r.slip.unwrap_or(f64::NAN)
            ));
            s.push_str(&format!(
                "    speed ripple at 2sf = {:.2} Hz: {:.4} rad/s peak; resolution {:.3} Hz (needed {:.3} Hz) over {:.2}..{:.2} s\n",
                r.speed_ripple_hz.unwrap_or(f64::NAN),
                r.speed_ripple_rad_s.unwrap_or(f64::NAN),
                r.resolution_hz.unwrap_or(f64::NAN),
                r.resolution_needed_hz.unwrap_or(f64::NAN),
                r.window_s.first().copied().unwrap_or(f64::NAN),
                r.window_s.last().copied().unwrap_or(f64::NAN),
            ));
        }
        _ => {}
    }
    if let (Some(n), Some(nb)) = (r.equivalent_broken_bars, r.rotor_bars) {
        s.push_str(&format!(
            "    fitted delta {:.3}: about {n:.1} adjacent broken bars of {nb:.0} (delta = 3n/(N - 3n), an approximation)\n",
            r.delta.unwrap_or(f64::NAN)
        ));
    }
    if let Some(d) = r.spectral_delta {
        let bars = match (r.spectral_broken_bars, r.rotor_bars) {
            (Some(n), Some(nb)) => format!(": about {n:.1} adjacent broken bars of {nb:.0}"),
            (None, None) => {
                " (the number of broken bars needs the rotor's bar count: --rotor-bars N)".into()
            }
            _ => String::new(),
        };
        let agree = match r.fit_and_spectrum_agree {
            Some(true) => "; the fit and the spectrum agree",
            Some(false) => "; the fit and the spectrum disagree, so rotor_asymmetry is not named",
            None => "",
        };
        s.push_str(&format!(
            "    from the sidebands: delta {d:.3}{bars}{agree}\n"
        ));
    }
    s
}

/// The spectrum chart: phase-a current in dB relative to the fundamental, f/2..3f/2, with
/// vertical markers at the two sidebands. None when the log could not be judged.
pub fn chart(r: &McsaReport) -> Option<Chart<'static>> {
    if !r.judged || r.spectrum.is_empty() {
        return None;
    }
    let lo = r
        .spectrum
        .iter()
        .map(|p| p.1)
        .fold(f64::MAX, f64::min)
        .max(-140.0);
    let marker = |f: f64, label: &str, color: usize| Series {
        label: label.to_string(),
        points: vec![(f, lo), (f, 0.0)],
        color,
        scatter: false,
        dashed: false,
    };
    let f = |i: usize| r.sideband_hz.get(i).copied().unwrap_or(f64::NAN);
    Some(Chart {
        stem: CHART,
        title: "Stator current spectrum (phase a, Blackman-Harris window) with the (1-2s)f and (1+2s)f sidebands",
        x_label: "frequency [Hz]",
        y_label: "amplitude [dB re fundamental]",
        series: vec![
            Series {
                label: "i_a spectrum".into(),
                points: plot::thin(
                    &r.spectrum
                        .iter()
                        .map(|&(x, y)| (x, y.max(lo)))
                        .collect::<Vec<_>>(),
                    8000,
                ),
                color: 0,
                scatter: false,
                dashed: false,
            },
            marker(f(0), &format!("(1-2s)f = {:.2} Hz", f(0)), 1),
            marker(f(1), &format!("(1+2s)f = {:.2} Hz", f(1)), 2),
        ],
        log_y: false,
        omitted: None,
        x_names: Vec::new(),
    })
}
