//! Where the leftover lives, in words ([`monitor_analysis::leftover`]): a few short lines
//! (none over [`LINE_MAX`] characters) that say which equations, which windows, which
//! frequencies and what the model's remaining error follows, and the law it points to;
//! and the same lines in the JSON document [`LeftoverDoc`] (`leftover.summary`, and each
//! line's reading as `leftover.lines[].says`).

use monitor_analysis::effects::sig;
use monitor_analysis::leftover::{
    Correlate, Equation, ErrorSpectrum, LawHint, Leftover, LineReading, LineReadingOnLog,
    NoSpectrum, OperatingVariable, ShaftAngle, Stretches, ANGLE_SHARE_MIN,
};
use monitor_analysis::strata::StratumKind;

mod doc;
pub use doc::{LeftoverDoc, LineDoc};

/// The longest line spelled here [characters].
pub const LINE_MAX: usize = 160;
/// The most spectral lines spelled one a line (the JSON holds them all).
pub const LINES_SPELLED: usize = 3;

/// The leftover `l` as the lines a crew reads, first the headline (no indentation; a
/// front end indents the lines after the first).
pub fn lines(l: &Leftover) -> Vec<String> {
    if l.at_floor {
        return vec![format!(
            "leftover: none: the error {} is {:.2}x its noise floor (within {}x): nothing is left to place",
            sig(l.error),
            l.ratio_to_floor,
            l.band
        )];
    }
    let mut out = vec![format!(
        "leftover: the error {} is {} its noise floor; where it lives:",
        sig(l.error),
        times(l.ratio_to_floor)
    )];
    out.push(equations(l));
    out.extend(in_time(l));
    out.extend(spectrum(l));
    out.extend(
        l.lines
            .iter()
            .take(LINES_SPELLED)
            .map(|x| format!("  at {}", line(x))),
    );
    out.extend(follows(l));
    if let Some(h) = l.hint {
        out.push(format!("law to try: {}", hint(h)));
    }
    out
}

/// A multiple of the noise floor: `12.3x`, and beyond 999x (a noise-free log's floor is next
/// to nothing) `more than 999x`, the ratio saying no more there.
fn times(r: f64) -> String {
    if r < 999.5 {
        format!("{r:.1}x")
    } else {
        "more than 999x".into()
    }
}

/// An equation's name.
pub fn equation(e: Equation) -> &'static str {
    match e {
        Equation::StatorQ => "stator q current",
        Equation::StatorD => "stator d current",
        Equation::Mechanics => "mechanics (speed)",
    }
}

/// What a stratum of the log is.
pub fn stratum(k: StratumKind) -> &'static str {
    match k {
        StratumKind::Start => "start",
        StratumKind::Transient => "supply or speed steps",
        StratumKind::LoadMove => "load moves",
        StratumKind::Steady => "steady stretches",
    }
}

/// The equations' shares of the error beyond the sensor noise.
fn equations(l: &Leftover) -> String {
    let parts: Vec<String> = l
        .equations
        .iter()
        .filter(|e| e.share >= 0.005)
        .map(|e| format!("{} {:.0} %", equation(e.equation), 100.0 * e.share))
        .collect();
    if parts.is_empty() {
        return "equations: no equation's error stands above its sensor noise".into();
    }
    format!(
        "equations: {} of the error beyond the sensor noise",
        parts.join(", ")
    )
}

/// The strata's kinds with their shares of the error and of the time, and the stratum
/// that holds the most for its length.
fn in_time(l: &Leftover) -> Vec<String> {
    let parts: Vec<String> = l
        .in_time
        .iter()
        .filter(|k| k.share >= 0.005 || k.time_share >= 0.005)
        .map(|k| {
            format!(
                "{} {:.0} % / {:.0} %",
                stratum(k.kind),
                100.0 * k.share,
                100.0 * k.time_share
            )
        })
        .collect();
    let mut out = vec![format!(
        "in time (% of the error / % of the log): {}",
        parts.join("; ")
    )];
    if let Some(w) = l.windows.first() {
        out.push(format!(
            "most for its length: {} {:.2}-{:.2} s, {:.0} % of the error in {:.0} % of the log",
            stratum(w.kind),
            w.t_start_s,
            w.t_end_s,
            100.0 * w.share,
            100.0 * w.time_share
        ));
    }
    out
}

/// How the spectrum was taken (and that no line stands out, when none does), or why not;
/// and the share of the error that is an offset, when it is most of it.
fn spectrum(l: &Leftover) -> Vec<String> {
    match &l.spectrum {
        ErrorSpectrum::Refused {
            because: NoSpectrum::NoStretch { longest_s, needs_s },
        } => vec![format!(
            "lines: not judged: no stretch after the start is {needs_s} s long (the longest: {longest_s:.2} s)"
        )],
        ErrorSpectrum::Taken {
            stretches,
            segments,
            segment_s,
            resolution_hz,
            offset_share,
            shaft_hz,
            supply_hz,
            slip,
        } => {
            let on = match stretches {
                Stretches::Steady => "steady stretches",
                Stretches::AfterStart => "after the start, load moves included",
                Stretches::AfterStartWithSteps => "after the start, supply steps included",
            };
            let head = if l.lines.is_empty() {
                "lines: none stands out"
            } else {
                "lines"
            };
            let mut out = vec![format!(
                "{head} ({on}, {segments} x {segment_s:.1} s, resolution {resolution_hz:.2} Hz; shaft {shaft_hz:.1} Hz, supply {supply_hz:.1} Hz, slip {:.1} %)",
                100.0 * slip
            )];
            if *offset_share >= 0.5 {
                out.push(format!(
                    "offset: {:.0} % of the error there is constant over a segment (a static mismatch, not a pulsation)",
                    100.0 * offset_share
                ));
            }
            out
        }
    }
}

/// A line of the spectrum: its frequency, share, amplitude and reading (the two readings
/// by their symbols where the log cannot tell them apart).
fn line(x: &monitor_analysis::leftover::SpectralLine) -> String {
    let what = match &x.also {
        Some(r) => format!(
            "{} or {}",
            reading_as(&x.reading, false),
            reading_as(r, false)
        ),
        None => reading(&x.reading),
    };
    format!(
        "{:.2} Hz: {:.0} % of the error, {} {} in the {}: {what}",
        x.frequency_hz,
        100.0 * x.share,
        sig(x.amplitude),
        x.unit,
        equation(x.equation),
    )
}

/// What a line's frequency is, with the frequency the reading expects on the log
/// (`the shaft frequency f_r (24.00 Hz here)`).
pub fn reading(r: &LineReadingOnLog) -> String {
    reading_as(r, true)
}

/// A reading by its symbol (`2 s f`), with what it means when `full`, and the frequency
/// it expects on the log.
fn reading_as(r: &LineReadingOnLog, full: bool) -> String {
    let k = r.multiple;
    let symbol = match (r.reading, k) {
        (LineReading::ShaftFrequency, 1) => "f_r".to_string(),
        (LineReading::ShaftFrequency, k) => format!("{k} f_r"),
        (LineReading::TwiceSlipFrequency, _) => "2 s f".to_string(),
        (LineReading::SupplyFrequency, 1) => "f".to_string(),
        (LineReading::SupplyFrequency, k) => format!("{k} f"),
        (LineReading::NotNamed, _) => {
            return "no physical reading (not the shaft's, the slip's or the supply's frequency)"
                .to_string()
        }
    };
    let meaning = match (r.reading, k) {
        (LineReading::ShaftFrequency, 1) => "the shaft frequency f_r".to_string(),
        (LineReading::ShaftFrequency, 2) => "twice the shaft frequency, 2 f_r".to_string(),
        (LineReading::ShaftFrequency, k) => format!("{k} times the shaft frequency, {k} f_r"),
        (LineReading::TwiceSlipFrequency, _) => {
            "2 s f, the (1 +/- 2 s) f sidebands of a rotor asymmetry".to_string()
        }
        (LineReading::SupplyFrequency, 1) => {
            "the supply frequency f (an offset in a phase current)".to_string()
        }
        (LineReading::SupplyFrequency, 2) => "2 f, the negative sequence".to_string(),
        (LineReading::SupplyFrequency, 6) => "6 f, the supply's 5th and 7th harmonics".to_string(),
        (LineReading::SupplyFrequency, k) => format!("{k} f, {k} times the supply frequency"),
        (LineReading::NotNamed, _) => String::new(),
    };
    let what = if full { meaning } else { symbol };
    match r.expected_hz {
        Some(f) => format!("{what} ({f:.2} Hz here)"),
        None => what,
    }
}

/// A variable's name.
fn variable(v: OperatingVariable) -> &'static str {
    match v {
        OperatingVariable::Speed => "the speed",
        OperatingVariable::Load => "the load current",
        OperatingVariable::Voltage => "the voltage",
    }
}

/// How often a revolution.
fn per_revolution(k: u32) -> String {
    match k {
        1 => "once per revolution".into(),
        2 => "twice per revolution".into(),
        k => format!("{k} times per revolution"),
    }
}

/// What the error follows and what it does not (one line each, when there is any).
fn follows(l: &Leftover) -> Vec<String> {
    let mut yes: Vec<String> = l
        .shaft_angle
        .iter()
        .filter(|a| a.share >= ANGLE_SHARE_MIN)
        .map(|a| {
            format!(
                "the shaft angle {} ({:.0} % of the error)",
                per_revolution(a.per_revolution),
                100.0 * a.share
            )
        })
        .collect();
    let mut no: Vec<String> = Vec::new();
    if let Some(a) = strongest_angle(&l.shaft_angle).filter(|a| a.share < ANGLE_SHARE_MIN) {
        no.push(format!(
            "the shaft angle (at most {:.0} %)",
            100.0 * a.share
        ));
    }
    let mut still: Vec<&str> = Vec::new();
    for c in &l.follows {
        correlate(c, &mut yes, &mut no, &mut still);
    }
    let mut out = Vec::new();
    if !yes.is_empty() {
        out.push(format!("follows: {}", yes.join("; ")));
    }
    if !no.is_empty() || !still.is_empty() {
        let mut s = format!("does not follow: {}", no.join("; "));
        if !still.is_empty() {
            if !no.is_empty() {
                s.push_str("; ");
            }
            let verb = if still.len() == 1 { "does" } else { "do" };
            s.push_str(&format!("{} {verb} not vary", still.join(", ")));
        }
        out.push(s);
    }
    out
}

/// The projection on the shaft angle that holds the most.
fn strongest_angle(a: &[ShaftAngle]) -> Option<&ShaftAngle> {
    a.iter().max_by(|x, y| x.share.total_cmp(&y.share))
}

/// One correlate into what the error follows, does not, or cannot be set against.
fn correlate(
    c: &Correlate,
    yes: &mut Vec<String>,
    no: &mut Vec<String>,
    still: &mut Vec<&'static str>,
) {
    let name = variable(c.variable);
    match c.r {
        Some(r) if c.follows => yes.push(format!("{name} (r = {r:+.2})")),
        Some(r) => no.push(format!("{name} (r = {r:+.2})")),
        None => still.push(name),
    }
}

/// The law a hint points to, with the `acts_on` of a user's law where one is written.
pub fn hint(h: LawHint) -> String {
    match h {
        LawHint::LoadOfShaftAngle { per_revolution: k } => format!(
            "a load torque of the shaft angle theta, {} (acts_on = \"load_torque\", an expression in theta)",
            per_revolution(k)
        ),
        LawHint::RotorAsymmetry => {
            "the rotor's asymmetry (broken bars): the library's rotor_asymmetry".into()
        }
        LawHint::NegativeSequence => {
            "a negative sequence: the library's supply_unbalance or phase_asymmetry".into()
        }
        LawHint::CurrentOffset => {
            "none of the model: an offset in a phase current is the sensor's (zero it)".into()
        }
        LawHint::SupplyHarmonics => {
            "the supply's harmonics or the saturation's: a magnetising inductance of the flux psi_m (acts_on = \"magnetising_inductance\")".into()
        }
        LawHint::LoadOfSpeed => {
            "a load torque of the speed w (acts_on = \"load_torque\", an expression in w)".into()
        }
        LawHint::MagnetisingOfFlux => {
            "a magnetising inductance of the flux psi_m (acts_on = \"magnetising_inductance\"), or a no-load table".into()
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use monitor_analysis::leftover::{
        EquationShare, KindShare, SpectralLine, Stretches, WindowShare,
    };
    use monitor_analysis::strata::StratumKind;

    /// A leftover with every part at its widest: three equations, four kinds of strata,
    /// five lines each with a second reading, every variable followed or not, both
    /// projections on the shaft angle, the longest hint.
    fn widest(hint: LawHint) -> Leftover {
        let reading = |reading, multiple| LineReadingOnLog {
            reading,
            multiple,
            expected_hz: Some(12345.678),
        };
        let eq = |equation: Equation, share| EquationShare {
            equation,
            rms_error: 123.456,
            unit: equation.unit(),
            normalized: 0.5,
            noise: 0.01,
            share,
        };
        let kinds = [
            StratumKind::Start,
            StratumKind::Transient,
            StratumKind::LoadMove,
            StratumKind::Steady,
        ];
        Leftover {
            error: 0.123456,
            noise_floor: 0.000123,
            ratio_to_floor: 12345.6,
            band: 1.12,
            at_floor: false,
            equations: vec![
                eq(Equation::Mechanics, 0.333),
                eq(Equation::StatorQ, 0.333),
                eq(Equation::StatorD, 0.333),
            ],
            in_time: kinds
                .iter()
                .map(|&kind| KindShare {
                    kind,
                    strata: 12,
                    t_start_s: 1234.5,
                    t_end_s: 2345.6,
                    share: 0.255,
                    time_share: 0.255,
                })
                .collect(),
            windows: vec![WindowShare {
                kind: StratumKind::Transient,
                t_start_s: 12345.678,
                t_end_s: 12346.789,
                share: 0.999,
                time_share: 0.011,
            }],
            spectrum: ErrorSpectrum::Taken {
                stretches: Stretches::AfterStart,
                segments: 32,
                segment_s: 4.096,
                resolution_hz: 0.244,
                offset_share: 0.999,
                shaft_hz: 1234.5,
                supply_hz: 1234.5,
                slip: -0.999,
            },
            lines: (0..5)
                .map(|_| SpectralLine {
                    frequency_hz: 12345.678,
                    reading: reading(LineReading::TwiceSlipFrequency, 1),
                    also: Some(reading(LineReading::SupplyFrequency, 6)),
                    equation: Equation::Mechanics,
                    amplitude: 12345.678,
                    unit: "rad/s",
                    share: 0.999,
                    prominence: 1e6,
                })
                .collect(),
            follows: [
                OperatingVariable::Speed,
                OperatingVariable::Load,
                OperatingVariable::Voltage,
            ]
            .iter()
            .enumerate()
            .map(|(k, &variable)| Correlate {
                variable,
                r: (k > 0).then_some(-0.999),
                span: 0.5,
                varies: k > 0,
                follows: k == 1,
                bins: 100,
            })
            .collect(),
            shaft_angle: [1, 2]
                .iter()
                .map(|&per_revolution| ShaftAngle {
                    per_revolution,
                    share: 0.999,
                    equation: Equation::StatorQ,
                    amplitude: 1.0,
                    unit: "A",
                })
                .collect(),
            hint: Some(hint),
        }
    }

    /// Every line at its widest fits in [`LINE_MAX`] characters with a front end's
    /// indentation (up to six spaces).
    #[test]
    fn no_line_is_longer_than_a_crew_reads() {
        let hints = [
            LawHint::LoadOfShaftAngle { per_revolution: 12 },
            LawHint::RotorAsymmetry,
            LawHint::NegativeSequence,
            LawHint::CurrentOffset,
            LawHint::SupplyHarmonics,
            LawHint::LoadOfSpeed,
            LawHint::MagnetisingOfFlux,
        ];
        for h in hints {
            let ls = lines(&widest(h));
            assert!(ls.len() >= 8, "{ls:#?}");
            for l in &ls {
                assert!(
                    l.chars().count() + 6 <= LINE_MAX,
                    "{} chars: {l}",
                    l.chars().count()
                );
            }
        }
        let mut refused = widest(LawHint::LoadOfSpeed);
        refused.spectrum = ErrorSpectrum::Refused {
            because: NoSpectrum::NoStretch {
                longest_s: 1234.5,
                needs_s: 0.5,
            },
        };
        for l in lines(&refused) {
            assert!(l.chars().count() + 6 <= LINE_MAX, "{l}");
        }
    }

    /// At the floor, one line and no place claimed; the readings name the shaft, the slip
    /// and the supply, with the frequency each expects.
    #[test]
    fn at_the_floor_nothing_is_placed_and_each_reading_names_its_physics() {
        let mut l = widest(LawHint::LoadOfSpeed);
        l.at_floor = true;
        l.ratio_to_floor = 1.05;
        let ls = lines(&l);
        assert_eq!(ls.len(), 1);
        assert!(ls[0].contains("nothing is left to place"), "{ls:?}");
        let r = |reading, multiple| {
            super::reading(&LineReadingOnLog {
                reading,
                multiple,
                expected_hz: Some(24.0),
            })
        };
        assert_eq!(
            r(LineReading::ShaftFrequency, 1),
            "the shaft frequency f_r (24.00 Hz here)"
        );
        assert!(r(LineReading::ShaftFrequency, 2).starts_with("twice the shaft"));
        assert!(r(LineReading::TwiceSlipFrequency, 1).contains("(1 +/- 2 s) f sidebands"));
        assert!(r(LineReading::SupplyFrequency, 2).contains("negative sequence"));
    }
}
