//! Commissioning in words: the thresholds in force, the advice, the notes where the
//! operating point left the commissioned range, why a window was not learned, and what the
//! log could not feed.

use monitor_replay::{
    CommissionAdvice, CommissioningReport, FirstPointMisfit, NotLearned, NotLearnedWhy,
    RangeDeparture, RangeNote, RangeQuantity, SkippedAnalysis, Thresholds,
};

use crate::spelling::Spelling;
use monitor_replay::OptionField;

/// A commissioned range's quantity, in words.
pub fn quantity(q: RangeQuantity) -> &'static str {
    match q {
        RangeQuantity::Load => "load (active current)",
        RangeQuantity::Voltage => "voltage (|V|)",
    }
}

/// What leaving the range means for the learned means.
fn meaning(q: RangeQuantity) -> &'static str {
    match q {
        RangeQuantity::Load => "to the paper's model a load change is a Bl change",
        RangeQuantity::Voltage => {
            "the learned healthy means hold only at the voltage they were learned at"
        }
    }
}

/// The timeline's note beside a lit lamp (JSON `timeline[].range_note`,
/// `commissioning.outside_range[].note`): `load (active current) 9.52 is 47 % above the
/// commissioned range 6.47..6.48: to the paper's model a load change is a Bl change`.
pub fn range_note(d: &[RangeDeparture]) -> String {
    d.iter()
        .map(|d| {
            format!(
                "{} {:.2} is {:.0} % {} the commissioned range {:.2}..{:.2}: {}",
                quantity(d.quantity),
                d.value,
                100.0 * d.fraction.abs(),
                if d.fraction > 0.0 { "above" } else { "below" },
                d.span[0],
                d.span[1],
                meaning(d.quantity)
            )
        })
        .collect::<Vec<_>>()
        .join("; ")
}

/// A range note's words (`note`).
pub fn note(n: &RangeNote) -> String {
    range_note(&n.departures)
}

/// The thresholds in force (JSON `commissioning.thresholds`).
pub fn thresholds(t: &Thresholds) -> String {
    let fixed = |f: f32| {
        format!(
            "fixed: |r| > {:.1} % against the nominal parameters",
            100.0 * f
        )
    };
    match *t {
        Thresholds::Fixed { fixed: f } => fixed(f),
        Thresholds::Learned {
            from_s,
            to_s,
            k_sigma,
        } => format!("learned over {from_s}..{to_s:.2} s: mean +/- {k_sigma} spreads"),
        Thresholds::FixedIncomplete { fixed: f } => {
            format!("{} (commissioning incomplete)", fixed(f))
        }
        Thresholds::NotUsed => {
            "none: the residuals did not run (the log lacks the voltages or the speed)".into()
        }
    }
}

/// Why a commissioning window was not learned.
pub fn not_learned_why(w: &NotLearnedWhy) -> String {
    match *w {
        NotLearnedWhy::EndsBeforeWindow { end_s } => {
            format!("the log ends at {end_s:.2} s, before the window starts")
        }
        NotLearnedWhy::TooLittle {
            learned_s,
            by_s,
            needed_s,
            cancelled,
        } => format!(
            "learned {learned_s:.2} s of evaluated running by {by_s:.2} s, {needed_s:.2} s at least needed ({}); the lamps were off while learning",
            if cancelled {
                "the window held too little quasi-steady running with usable data"
            } else {
                "the log ended first"
            }
        ),
    }
}

/// The window asked for and why it was not learned: `--commission 2:4: why`.
pub fn not_learned(n: &NotLearned, sp: &dyn Spelling) -> String {
    format!(
        "{}: {}",
        sp.option(OptionField::Commission, &n.window.to_string()),
        not_learned_why(&n.why)
    )
}

/// The advice (JSON `commissioning.advice`).
pub fn advice(a: &CommissionAdvice, sp: &dyn Spelling) -> String {
    match a {
        CommissionAdvice::CommissionOverRange => format!(
            "the thresholds are fixed against the parameter file's nominal values; a real motor's parameters differ by 10-30 %, so commission ({}) over healthy running that covers the whole load and voltage range",
            sp.hint(OptionField::Commission, "START:END")
        ),
        CommissionAdvice::NotLearned(n) => not_learned(n, sp),
    }
}

/// The first quasi-steady point already past a fixed threshold, without commissioning.
pub fn first_point_misfit(m: &FirstPointMisfit, sp: &dyn Spelling) -> String {
    format!(
        "at the first quasi-steady point ({:.2} s) r{} = {:+.3} already passes its fixed threshold ({:.3}): the parameter file does not fit this motor, or a fault was there from the start; commission ({}) on healthy running to tell them apart",
        m.t_s,
        m.residual + 1,
        m.value,
        m.threshold,
        sp.hint(OptionField::Commission, "START:END")
    )
}

/// An analysis the log could not feed, with the column it needs (JSON `skipped`).
pub fn skipped(s: SkippedAnalysis) -> &'static str {
    match s {
        SkippedAnalysis::ResidualsNeedVoltages => {
            "residuals r1..r4 and fault signatures: need the voltages va_V, vb_V, vc_V (Vqs)"
        }
        SkippedAnalysis::ResidualsNeedSpeed => {
            "residuals r1..r4 and fault signatures: need the speed (wm_rad_s or enc_count)"
        }
    }
}

/// The commissioning part of the report in words: its thresholds and advice.
pub fn report_words(c: &CommissioningReport, sp: &dyn Spelling) -> (String, Option<String>) {
    (
        thresholds(&c.thresholds),
        c.advice.as_ref().map(|a| advice(a, sp)),
    )
}
