//! The isolation in words: its verdict sentence ([`said`]), why candidates cannot be
//! separated ([`group_reason`]), its events ([`event_line`]) and the temperature channel.

use monitor_core::isolation::COPPER_ALPHA_PER_K;
use monitor_core::Fault;
use monitor_replay::{
    ChannelDropped, ChannelUse, CoreSaid, GroupWhy, IsolationEvent, IsolationSaid, Nearest,
    NotIsolatedWhy, RangeDeparture, SensorKind, Stale, NOMINAL_UNCERTAINTY,
};

use crate::spelling::Spelling;
use monitor_replay::OptionField;

/// A size as a signed whole percentage (the isolation's).
fn pct(x: f32) -> String {
    format!("{:+.0} %", 100.0 * x)
}

/// The sentence's subject for fault `f`.
fn fault_phrase(f: Fault) -> &'static str {
    match f {
        Fault::Rs => "The stator resistance Rs",
        Fault::Rr => "The rotor resistance Rr",
        Fault::Ls => "The stator leakage inductance (Ls)",
        Fault::Lr => "The rotor leakage inductance (Lr)",
        Fault::B => "The machine friction B",
        Fault::Bl => "The load friction Bl",
        Fault::CurrentSensor => "The current sensors' gain",
        Fault::VoltageSensor => "The voltage sensors' gain",
        Fault::SpeedSensor => "The speed sensor's gain",
    }
}

/// The nearest faults: `rs +30 % (p 0.40), ...`.
fn nearest(n: &[Nearest]) -> String {
    n.iter()
        .map(|c| format!("{} {} (p {:.2})", c.fault, pct(c.change), c.probability))
        .collect::<Vec<_>>()
        .join(", ")
}

/// The sentence on a current `away` from the learned point, or nothing.
fn away_text(away: Option<f32>) -> String {
    away.map_or(String::new(), |m| format!(
        " The current is {} from where the baseline was learned: there the parameter file's error is allowed for, and a fault is named only if it stands out from it (commission at this load to judge here).",
        pct(m)
    ))
}

/// The core's conclusion in one sentence.
fn core_sentence(c: &CoreSaid) -> String {
    match c {
        CoreSaid::LitWithoutDeviation { deviation } => format!(
            "The lamps lit, but the machine's steady-state equations deviate by only {deviation:.1} standard deviations: no fault can be isolated."
        ),
        CoreSaid::NoDeviation => {
            "The steady-state equations fit the nominal machine: nothing to isolate.".into()
        }
        CoreSaid::NotJudged => "No usable operating point was isolated.".into(),
        CoreSaid::MovedFar {
            moved,
            deviation,
            nearest: n,
        } => format!(
            "The operating point moved far from the commissioned one (current {}): the healthy baseline learned there does not hold here, so the deviation ({deviation:.0} standard deviations) is not judged as a fault; the nearest single faults would be {}. Commission at this load to judge it.",
            pct(*moved),
            nearest(n)
        ),
        CoreSaid::Unknown {
            deviation,
            nearest: n,
            away,
        } => format!(
            "A change of {deviation:.0} standard deviations that no single fault explains (an unknown fault, several faults, or a parameter file that does not fit); nearest: {}.{}",
            nearest(n),
            away_text(*away)
        ),
        CoreSaid::Fault {
            fault,
            change,
            probability,
        } => format!(
            "{} changed by {} (p {probability:.2}).",
            fault_phrase(*fault),
            pct(*change)
        ),
        CoreSaid::Friction {
            probability,
            b_change,
            bl_change,
        } => format!(
            "The friction class b/bl changed by {} (p {probability:.2}): load friction Bl {}, or the same torque as machine friction B {}; they cannot be separated.",
            pct(*bl_change),
            pct(*bl_change),
            pct(*b_change)
        ),
        CoreSaid::Several { nearest: n, away } => format!(
            "The change fits more than one fault and none alone: {}.{}",
            nearest(n),
            away_text(*away)
        ),
    }
}

/// The stale conclusion's tail: ` (judged at 3.20 s; ...)`.
fn stale_tail(s: &Stale) -> String {
    format!(
        " (judged at {:.2} s; the operating point was not steady in the last {:.1} s of the log)",
        s.judged_at_s, s.unsteady_s
    )
}

/// What left the commissioned range, as the moved point's note says it: `load (active
/// current) 9.52 is 47 % above the commissioned 6.47..6.48`.
pub fn moved_note(d: &[RangeDeparture]) -> String {
    d.iter()
        .map(|d| {
            format!(
                "{} {:.2} is {:.0} % {} the commissioned {:.2}..{:.2}",
                super::commissioning::quantity(d.quantity),
                d.value,
                100.0 * d.fraction.abs(),
                if d.fraction > 0.0 { "above" } else { "below" },
                d.span[0],
                d.span[1]
            )
        })
        .collect::<Vec<_>>()
        .join("; ")
}

/// The isolation's verdict (JSON `isolation.verdict`) of what it concluded.
pub fn said(s: &IsolationSaid, sp: &dyn Spelling) -> String {
    match s {
        IsolationSaid::NotIsolated { why } => format!(
            "The fault could not be isolated: {}.",
            match why {
                NotIsolatedWhy::MachineUnusable => {
                    "the parameter file's machine cannot be used by the isolation"
                }
                NotIsolatedWhy::NoSteadyPoint => {
                    "no settled, quasi-steady operating point with voltage was evaluated"
                }
            }
        ),
        IsolationSaid::WithinFileError {
            fault,
            change,
            probability,
            lamps_lit,
        } => format!(
            "The nearest fault, {fault} {} (p {probability:.2}), is within the parameter file's own uncertainty (+/-{:.0} %){}: not named, a file that far off the machine moves the residuals as much. Commission on the healthy machine to judge changes this small.",
            pct(*change),
            100.0 * NOMINAL_UNCERTAINTY,
            if *lamps_lit { "" } else { " while every lamp stayed dark" }
        ),
        IsolationSaid::Stale { core, stale } => format!(
            "{}{}",
            core_sentence(core).trim_end_matches('.'),
            stale_tail(stale)
        ),
        IsolationSaid::Heating {
            rise_k,
            lamps_lit,
            withdrawn,
        } => {
            let withdrawn = withdrawn.map_or(String::new(), |g| {
                format!(
                    " ({} was named at {:.2} s while the tracked temperature lagged, and withdrawn.)",
                    g.name, g.t_s
                )
            });
            format!(
                "The windings warmed by {rise_k:.0} K since commissioning (Rs and Rr {} together, copper 0.393 %/K): heating, not a fault; the warm machine's steady-state equations fit{}.{withdrawn}",
                pct(rise_k * COPPER_ALPHA_PER_K),
                if *lamps_lit {
                    "; the lamps lit because their residuals were learned on the cold machine"
                } else {
                    ""
                }
            )
        }
        IsolationSaid::FileHeating { rise_k } => format!(
            "The change is what windings about {:.0} K {} than the parameter file assumes give (Rs and Rr {} together, copper 0.393 %/K): heating, not a fault. Against the file's nominal values a change this small is as much the file's own error; commission on the healthy machine to judge it.",
            rise_k.abs(),
            if *rise_k > 0.0 { "warmer" } else { "cooler" },
            pct(rise_k * COPPER_ALPHA_PER_K)
        ),
        IsolationSaid::LoadMoved { last } => {
            let what = last.map_or(String::new(), |(t, a0, a1)| {
                format!(
                    " (at {t:.2} s the active current went from {a0:.2} to {a1:.2} A, {})",
                    pct(a1 / a0 - 1.0)
                )
            });
            format!(
                "The load moved{what}: an operating-point change, not a fault; the stator-voltage equations, with the load as an unknown input, fit the machine. (A change of the machine's friction B cannot be told from a load change without a load model: for the paper's fixed viscous load, where a Bl change is a fault, give {}.)",
                sp.hint(OptionField::Load, "viscous")
            )
        }
        IsolationSaid::Concluded { core, joint } => {
            let s = core_sentence(core);
            match joint {
                Some(j) if j.anchored => format!(
                    "{} (from {} operating point{} since the change: the stator-voltage equations, which need no load model, and the torque against the load measured just before the change)",
                    s.trim_end_matches('.'),
                    j.points,
                    if j.points == 1 { "" } else { "s" }
                ),
                Some(j) => format!(
                    "{} (from {} operating points together: the stator-voltage equations only, which need no load model)",
                    s.trim_end_matches('.'),
                    j.points
                ),
                None => s,
            }
        }
        IsolationSaid::SensorPhase {
            sensor,
            phase,
            gain_error,
            stale,
        } => format!(
            "The phase {} {} sensor's gain changed by {} (the zero sequence of the three readings names it; one phase's error is a third of that on the three-phase vector){}",
            phase.name(),
            match sensor {
                SensorKind::Current => "current",
                SensorKind::Voltage => "voltage",
            },
            pct(*gain_error),
            stale.as_ref().map_or(".".to_string(), stale_tail)
        ),
        IsolationSaid::OutsideRange {
            departures,
            deviation,
        } => format!(
            "Not judged as a fault: the operating point moved outside the commissioned range ({}), where the healthy baseline does not hold; the deviation there ({deviation:.0} standard deviations) fits no single fault, as a new load would not. Commission over this load to judge it.",
            moved_note(departures)
        ),
    }
}

/// Why a group of candidates cannot be separated.
pub fn group_reason(w: &GroupWhy) -> String {
    match w {
        GroupWhy::FrictionClass => "both scale the load term (B + Bl) wr of the torque balance: one friction class at every operating point".into(),
        GroupWhy::RotorResistanceAndSpeedSensor { separation_deg } => format!("in steady state the rotor circuit depends on Rr/slip only, so an Rr change and a small speed-sensor gain error change the currents alike (directions {separation_deg:.1} deg apart); only the torque balance with the assumed viscous load, a speed transient, or a load change of 20 % or more (the isolation then fits the operating points together) tells them apart"),
        GroupWhy::CurrentAndVoltageSensors { separation_deg } => format!("both scale the measured impedance V/I; only the torque balance separates them, and it is weak at light load (directions {separation_deg:.1} deg apart)"),
        GroupWhy::CloseDirections { separation_deg } => format!("their directions in the residual space are {separation_deg:.1} deg apart at this operating point; a load change of 20 % or more may separate them (the isolation then fits the operating points together)"),
    }
}

/// One event for the text report, e.g. `  601.70 s  load moved: active current 6.21 ->
/// 4.36 A (-30 %), an operating-point change` or `3000.50 s  named rr +20 % (p 0.99)`.
pub fn event_line(e: &IsolationEvent) -> String {
    match e {
        IsolationEvent::Named {
            t_s,
            name,
            change,
            probability,
        } => {
            // A size under 10 % to a tenth of a per cent: "+0 %" says nothing.
            let digits = usize::from(change.abs() < 0.095);
            format!(
                "{t_s:9.2} s  named {name} {:+.digits$} % (p {probability:.2})",
                100.0 * change
            )
        }
        IsolationEvent::LoadMoved { t_s, from_a, to_a } => format!(
            "{t_s:9.2} s  load moved: active current {from_a:.2} -> {to_a:.2} A ({:+.0} %), an operating-point change",
            100.0 * (to_a / from_a - 1.0)
        ),
    }
}

/// The temperature channel's use: `used`, or `not used: <why>`.
pub fn channel_use(u: &ChannelUse) -> String {
    match u {
        ChannelUse::Used => "used".into(),
        ChannelUse::NotUsed { why } => format!("not used: {}", channel_dropped(why)),
    }
}

/// Why the temperature channel is not used.
pub fn channel_dropped(why: &ChannelDropped) -> String {
    use monitor_replay::temperature_limits::{GAP_S, MAX_HEATING_K_PER_S, PLAUSIBLE_C, STUCK_S};
    match why {
        ChannelDropped::NoReading { since_s } => format!(
            "no reading inside {:.0}..{:.0} degC for {GAP_S:.0} s from {since_s:.1} s (NaN, empty or out of range)",
            PLAUSIBLE_C.0, PLAUSIBLE_C.1
        ),
        ChannelDropped::NoneWhileCommissioning => "no plausible reading during commissioning".into(),
        ChannelDropped::Stuck { value_c, since_s } => format!(
            "stuck at {value_c:.1} degC from {since_s:.1} s ({STUCK_S:.0} s without a change)"
        ),
        ChannelDropped::Jumped {
            from_c,
            to_c,
            dt_s,
            at_s,
        } => format!(
            "jumped from {from_c:.1} to {to_c:.1} degC in {dt_s:.2} s at {at_s:.1} s (a winding heats by at most {MAX_HEATING_K_PER_S:.0} K/s)"
        ),
        ChannelDropped::Disagrees { off_k, since_s } => format!(
            "the resistances say the winding is {off_k:+.0} K from the channel's reading since {since_s:.1} s"
        ),
        ChannelDropped::BeyondService { rise_k } => format!(
            "a rise of {rise_k:.0} K since commissioning is beyond what a winding reaches in service"
        ),
        ChannelDropped::NoCommissioning => {
            "no commissioning (the rise counts from the temperature commissioning saw)".into()
        }
    }
}
