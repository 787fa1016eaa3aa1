//! The rotor in words: the broken-bar finding from the current's sidebands, the MCSA
//! severity bands, the load it was judged at, or why it could not be judged.

use monitor_replay::{
    LoadSource, LoadUnknown, RotorBand, RotorCannot, RotorLoad, RotorReport, SlipSource, MAX_SLIP,
    MAX_SLIP_OVER_RATED, MIN_BINS, MIN_SLIP, PAIR_SNR_DB,
};

/// What the band says, in the practice's words, with its range.
pub fn band_words(b: RotorBand) -> &'static str {
    match b {
        RotorBand::NoSign => "more than 54 dB below: no sign",
        RotorBand::Watch => "48-54 dB below: a developing problem may be starting",
        RotorBand::CrackedBarOrJoint => {
            "42-48 dB below: a cracked bar or a high-resistance joint likely"
        }
        RotorBand::BrokenBars => "36-42 dB below: two or more broken bars likely",
        RotorBand::SeveralBrokenBars => {
            "less than 36 dB below: several broken bars and end-ring problems"
        }
    }
}

/// The band's finding as the report's sentence names it.
fn band_finding(b: RotorBand) -> &'static str {
    match b {
        RotorBand::NoSign => "no sign of broken bars",
        RotorBand::Watch => "watch the rotor",
        RotorBand::CrackedBarOrJoint => "rotor bar damage",
        RotorBand::BrokenBars | RotorBand::SeveralBrokenBars => "broken rotor bars",
    }
}

/// The load estimate in words: `about 3 % of the rated torque (from the speed: slip 0.12 %,
/// rated 4.17 %)`, or why it is unknown.
pub fn load_words(l: &RotorLoad) -> String {
    let (Some(x), Some(r)) = (l.fraction, l.rated) else {
        return format!(
            "the load is unknown: {}",
            l.unknown_because
                .as_ref()
                .map_or_else(|| "no estimate".to_string(), load_unknown)
        );
    };
    let slip = l.slip.unwrap_or(0.0);
    let from = match l.source {
        Some(LoadSource::Speed) => format!(
            "from the speed: slip {:.2} %, rated {:.2} %",
            100.0 * slip,
            100.0 * r.slip
        ),
        Some(LoadSource::Voltages) => format!(
            "from the voltages' power: slip {:.2} % in the file's circuit, rated {:.2} %",
            100.0 * slip,
            100.0 * r.slip
        ),
        _ => format!(
            "from the current {:.2} A against the file's no-load {:.2} A and rated {:.2} A (peak)",
            l.current_peak_a.unwrap_or(f64::NAN),
            r.no_load_current_peak_a,
            r.current_peak_a
        ),
    };
    format!("about {:.0} % of the rated torque ({from})", 100.0 * x)
}

/// Why the load is unknown.
pub fn load_unknown(w: &LoadUnknown) -> String {
    match *w {
        LoadUnknown::NoRatedLoad => "the parameter file has no rated load (B + Bl)".into(),
        LoadUnknown::CurrentOutOfScale {
            current_peak_a,
            top_slip,
            range_a,
            uncertainty,
        } => format!(
            "the current {current_peak_a:.2} A (peak) is outside what the parameter file draws between no load and {:.1} % slip ({:.2}..{:.2} A with its {:.0} % uncertainty): a scale the file does not know (a DAQ's own units, a CT ratio), and the log has no speed or voltages",
            100.0 * top_slip,
            range_a[0],
            range_a[1],
            100.0 * uncertainty
        ),
    }
}

/// Why the rotor could not be judged (after `cannot judge: `).
pub fn cannot(w: &RotorCannot, load: Option<&RotorLoad>) -> String {
    let load_text = || {
        load.map_or_else(
            || "the load is unknown: no estimate".to_string(),
            load_words,
        )
    };
    match *w {
        RotorCannot::NoCurrent => "no current to read: the log holds less than two supply periods of good current samples".into(),
        RotorCannot::NotSteady { by_speed } => format!(
            "{} is steady in no stretch of 0.2 s chunks",
            if by_speed { "the slip" } else { "the current" }
        ),
        RotorCannot::LoadTooLow { no_load } => format!(
            "the load is too low to judge the rotor ({}): {}, below the {:.0} % of the rated torque from which broken-bar sidebands are graded (their level scales with the rotor current; the MCSA severity bands of Thomson and Fenger 2001 are set near full load)",
            if no_load { "no load" } else { "light load" },
            load_text(),
            100.0 * load.map_or(monitor_replay::MCSA_MIN_LOAD, |l| l.min_fraction)
        ),
        RotorCannot::NotSidebands { slip, top } => {
            let (rated, breakdown) = load
                .and_then(|l| l.rated)
                .map_or((f64::NAN, f64::NAN), |rt| (rt.slip, rt.breakdown_slip));
            format!(
                "the pair about the line is not rotor sidebands: slip {:.2} % is implausible at this load (above {:.2} %, {MAX_SLIP_OVER_RATED} times the rated slip {:.2} % of the parameter file's machine, breakdown at {:.1} %; {})",
                100.0 * slip,
                100.0 * top,
                100.0 * rated,
                100.0 * breakdown,
                load_text()
            )
        }
        RotorCannot::SlipUnknown { largest_db_below } => format!(
            "the slip is unknown: the log has no speed (wm_rad_s or enc_count), and no pair of sidebands (1 -/+ 2s) f nor of rotation harmonics f -/+ f_r stands {PAIR_SNR_DB:.0} dB above the current's noise; the largest component where the lower sideband could be (slips {:.1}..{:.0} %) is {largest_db_below:.1} dB below the line",
            100.0 * MIN_SLIP,
            100.0 * MAX_SLIP,
        ),
        RotorCannot::SlipBelow { slip } => format!(
            "the slip {:.2} % is below {:.1} % (no load): the sidebands sit on the line, and a cage carries too little current for a broken bar to show",
            100.0 * slip,
            100.0 * MIN_SLIP
        ),
        RotorCannot::SlipAbove { slip } => format!(
            "the slip {:.1} % is above {:.0} %: a start or an overload, not a steady running point the severity bands grade",
            100.0 * slip,
            100.0 * MAX_SLIP
        ),
        RotorCannot::TooShort {
            stretch_s,
            needed_s,
            offset_hz,
        } => format!(
            "the steady stretch is {stretch_s:.2} s; {needed_s:.2} s are needed to resolve sidebands 2sf = {offset_hz:.2} Hz from the line ({MIN_BINS} bins of a Blackman-Harris window)"
        ),
        RotorCannot::NoLine => "no supply line in the current's spectrum".into(),
        RotorCannot::Noisy { floor_db_below } => format!(
            "the current's noise reads {floor_db_below:.1} dB below the line where the (1 - 2s) f sideband is read, above the 54 dB a healthy cage is told at: a longer steady record or quieter current sensors lower it"
        ),
    }
}

/// `cannot judge: ...` (JSON `rotor.cannot_judge_because`), where the rotor was not judged.
pub fn cannot_judge_because(r: &RotorReport) -> Option<String> {
    r.cannot_judge_because
        .as_ref()
        .map(|w| format!("cannot judge: {}", cannot(w, r.load.as_ref())))
}

/// The report's one sentence on the rotor (JSON `rotor.sentence`): the finding, or why there
/// is none.
pub fn sentence(r: &RotorReport) -> String {
    if let Some(why) = cannot_judge_because(r) {
        return format!("rotor: {why}");
    }
    let level = -r.level_db.unwrap_or(f64::NAN);
    let p = r.confidence.unwrap_or(0.0);
    let head = match (r.slip_source, r.band) {
        (Some(SlipSource::Sidebands), Some(b)) if b != RotorBand::NoSign => {
            "unconfirmed: a pair about the line taken for the sidebands (no speed to confirm the slip)"
        }
        (_, b) => b.map_or("", band_finding),
    };
    let noise = if r.at_noise {
        " (at the current's noise)"
    } else {
        ""
    };
    let bars = match (r.broken_bars, r.rotor_bars) {
        (Some(n), Some(nb)) if p >= 0.5 => format!("; about {n:.1} adjacent broken bars of {nb}"),
        _ => String::new(),
    };
    let source = match r.slip_source {
        Some(SlipSource::Speed) => "the speed",
        Some(SlipSource::Eccentricity) => "the rotation harmonics",
        _ => "the sideband pair",
    };
    // The probability as the verdict reads it: a named finding's confidence (a cracked bar
    // or worse), the probability of a fault for a finding the verdict calls clear ("watch",
    // or a pair not confirmed), nothing for "no sign" (its 0.00 is not a health figure).
    let p = match r.band {
        Some(RotorBand::NoSign) | None => String::new(),
        Some(RotorBand::Watch) => format!(", probability of a rotor fault {p:.2}"),
        Some(_) => format!(", confidence {p:.2}"),
    };
    format!(
        "rotor: {head}: the (1-2s)f sideband is {level:.1} dB below the supply line{noise} (band {}){p}{bars}; slip {:.2} % from {source}, {:.1} s read",
        r.band.map_or("", band_words),
        100.0 * r.slip.unwrap_or(f64::NAN),
        r.window_s.last().unwrap_or(&0.0) - r.window_s.first().unwrap_or(&0.0),
    )
}

/// The rotor finding's brief phrase for the verdict's lists.
pub fn brief(r: &RotorReport) -> String {
    match (r.level_db, r.band, r.judged) {
        (Some(level), Some(band), true) => {
            let brief = format!(
                "rotor sidebands {:.0} dB below the supply line",
                -level as f32
            );
            if band == RotorBand::Watch {
                format!("{brief} (the watch band: trend it)")
            } else {
                brief
            }
        }
        _ => format!("rotor: {}", summary(r)),
    }
}

/// The rotor finding's sentence (the findings' `summary`).
pub fn summary(r: &RotorReport) -> String {
    match (r.level_db, r.band, r.judged) {
        (Some(_), Some(_), true) => sentence(r),
        _ => cannot_judge_because(r).unwrap_or_else(|| "the sidebands were not read".to_string()),
    }
}
