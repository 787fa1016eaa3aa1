//! The ladder's base changes in words: each change with its interval, what a change of each
//! parameter likely means, and why a change the fit reads is no finding (not separable from
//! the effects, an effect in its place, unsteady over the log).

use monitor_analysis::effects::{sig, ApartBy, ALPHA_CU_PER_K};
use monitor_analysis::explain::ladder::{BaseChange, InPlace, NotSeparable, Unsteady};
use monitor_analysis::fit::machine::BaseKey;

/// One base change with its interval: `Rs +19 % (±2 %)`; B + Bl where the file holds none
/// (or changed more than twofold) as its value.
pub fn base_change(c: &BaseChange) -> String {
    let half = c
        .interval
        .map(|[lo, hi]| 0.5 * (hi - lo))
        .unwrap_or(f64::INFINITY);
    if c.base == BaseKey::B && (c.file_value == 0.0 || c.change.abs() > 1.0) {
        // A viscous load the file does not hold: the value, not a share of the file's
        // bearing friction.
        return format!(
            "{} {} N m s/rad (the file's {})",
            c.base.symbol(),
            sig(c.value),
            sig(c.file_value)
        );
    }
    if half.is_finite() {
        format!(
            "{} {:+.0} % (±{:.0} %)",
            c.base.symbol(),
            100.0 * c.change,
            (100.0 * half).max(1.0)
        )
    } else {
        format!("{} {:+.0} %", c.base.symbol(), 100.0 * c.change)
    }
}

/// What the base changes `c` mean, in a drive engineer's words: each named change with its
/// interval and its likely reading, then the parameters the log does not identify.
pub fn base_changes(c: &[BaseChange]) -> String {
    let mut parts = resistances(c);
    for (k, why) in OTHER_READINGS {
        if let Some(x) = c.iter().find(|x| x.base == k && x.changed) {
            parts.push(format!("{}: {why}", base_change(x)));
        }
    }
    let unidentified: Vec<&str> = c
        .iter()
        .filter(|x| !x.identified)
        .map(|x| x.base.symbol())
        .collect();
    for x in c {
        if let Some(n) = &x.not_separable {
            parts.push(not_separable(x, n));
        }
        if let Some(p) = &x.in_place {
            parts.push(in_place(x, p));
        }
        if let Some(u) = &x.unsteady {
            parts.push(unsteady(x, u));
        }
    }
    let unchanged: Vec<&str> = c
        .iter()
        .filter(|x| x.identified && !x.changed && !x.questioned())
        .filter(|x| !matches!(x.base, BaseKey::Rs | BaseKey::Rr) || parts.is_empty())
        .map(|x| x.base.symbol())
        .collect();
    if parts.is_empty() {
        parts.push("no base parameter differs from the file's by more than this log shows".into());
    }
    if !unchanged.is_empty() {
        parts.push(format!("unchanged: {}", unchanged.join(", ")));
    }
    if !unidentified.is_empty() {
        parts.push(format!(
            "not identified by this log (kept near the file's values): {}",
            unidentified.join(", ")
        ));
    }
    parts.join("; ")
}

/// `B + Bl +89 % (±15 %) is not separable from compressor on this log: without it the model
/// still reaches 1.01x its noise floor`: a change the fit reads that only trades with the
/// effects' values (or the other base parameters), no finding. Or, where an effect's law
/// ran to its range's end without the change ([`monitor_analysis::explain::ladder::LawShape`]):
/// `Rr -23 % (±1 %) is not separable from saturation on this log: with Rr at the file's
/// value, saturation's exponent runs from 8.26 to the end of its fit range (14) ...`.
fn not_separable(x: &BaseChange, n: &NotSeparable) -> String {
    let from = if n.traded_with.is_empty() {
        String::new()
    } else {
        format!(
            " from {}",
            n.traded_with
                .iter()
                .map(|e| e.name())
                .collect::<Vec<_>>()
                .join(" and ")
        )
    };
    if let Some(l) = &n.shape {
        return format!(
            "{} is not separable from {} on this log: with {} at the file's value, {}'s {} runs \
             from {} to the end of its fit range ({}) and the model reaches {:.2}x its noise \
             floor; the change trades with the law's shape, whose curve is not the machine's",
            base_change(x),
            l.effect,
            x.base.symbol(),
            l.effect,
            l.parameter,
            sig(l.with_change),
            sig(l.bound),
            n.ratio_without
        );
    }
    format!(
        "{} is not separable{from} on this log: without it the model still reaches {:.2}x its noise floor",
        base_change(x),
        n.ratio_without
    )
}

/// `B + Bl 0.102 N m s/rad (the file's 0.00501) is not separable from windage on this log:
/// windage in its place ... reaches 2.44x its noise floor (3.09x with the change); ...`: a
/// change an effect of the library fits as well in its place ([`InPlace`]), no finding.
fn in_place(x: &BaseChange, p: &InPlace) -> String {
    let head = format!(
        "{} is not separable from {} on this log: {} in its place, with {} at the file's value",
        base_change(x),
        p.effect,
        p.effect,
        x.base.symbol()
    );
    if p.better {
        return format!(
            "{head}, fits it better ({:.2}x its noise floor against {:.2}x with the change; {}): \
             the change is what the model made of {} (the ladder's round judged {} beside the \
             change, where it added little)",
            p.ratio_in_place, p.ratio_with_change, p.fitted.summary, p.effect, p.effect
        );
    }
    format!(
        "{head}, fits it as well ({:.2}x its noise floor against {:.2}x with the change; {}): {}",
        p.ratio_in_place,
        p.ratio_with_change,
        p.fitted.summary,
        apart(p.apart_by)
    )
}

/// `J -9 % (±1 %) is not the same in the log's two halves (-8 % and +9 %): ...`: a change
/// that moves with the operating point ([`Unsteady`]), no finding.
fn unsteady(x: &BaseChange, u: &Unsteady) -> String {
    format!(
        "{} is not the same in the log's two halves ({:+.0} % and {:+.0} %): it carries what the \
         model lacks, not a change of the machine",
        base_change(x),
        100.0 * u.first,
        100.0 * u.second
    )
}

/// The likely reading of a change of each base parameter other than the resistances.
const OTHER_READINGS: [(BaseKey, &str); 4] = [
    (
        BaseKey::Lm,
        "the magnetising inductance differs from the file's (a no-load test at another voltage, or saturation)",
    ),
    (
        BaseKey::Leakage,
        "the leakage inductances differ from the file's (a locked-rotor test's split or its saturated leakage paths)",
    ),
    (
        BaseKey::J,
        "the inertia differs from the file's (the coupled load's)",
    ),
    (
        BaseKey::B,
        "the viscous friction differs from the file's (a viscous load the file leaves out, bearings, seals)",
    ),
];

/// The changes of Rs and Rr in `c` in words: both risen alike read as a warm machine (its
/// rise in K at copper's 0.393 %/K), else each with its likely reading.
fn resistances(c: &[BaseChange]) -> Vec<String> {
    let get = |k: BaseKey| c.iter().find(|x| x.base == k);
    let changed = |k: BaseKey| get(k).is_some_and(|x| x.changed);
    let (rs, rr) = (get(BaseKey::Rs), get(BaseKey::Rr));
    let spelled = |x: Option<&BaseChange>| x.map_or_else(String::new, base_change);
    let (a, b) = (rs.map_or(0.0, |x| x.change), rr.map_or(0.0, |x| x.change));
    let alike = a > 0.0 && b > 0.0 && (a - b).abs() <= 0.3 * a.max(b);
    let (rs_changed, rr_changed) = (changed(BaseKey::Rs), changed(BaseKey::Rr));
    if rs_changed && rr_changed && alike {
        return vec![format!(
            "{}, {}: both windings warmer than the file's values, about {:.0} K (copper 0.393 %/K)",
            spelled(rs),
            spelled(rr),
            0.5 * (a + b) / ALPHA_CU_PER_K
        )];
    }
    let mut parts = Vec::new();
    if rs_changed {
        parts.push(format!(
            "{}{}: {}",
            spelled(rs),
            if rr_changed { "" } else { ", Rr unchanged" },
            if a > 0.0 {
                "the file's Rs is cold, or the stator is warm (a loosening connection adds to it too)"
            } else {
                "the file's Rs is higher than the winding's (measured warm, or with its leads)"
            }
        ));
    }
    if rr_changed {
        parts.push(format!(
            "{}{}: the rotor's resistance differs from the file's (a locked-rotor test at line frequency reads the skin effect's Rr; a warm cage)",
            spelled(rr),
            if rs_changed { "" } else { ", Rs unchanged" },
        ));
    }
    parts
}

/// Why two readings are one on a log, and what kind of log tells them apart ([`ApartBy`]).
pub(super) fn apart(by: ApartBy) -> &'static str {
    match by {
        ApartBy::Reversal => {
            "on a shaft that turns one way a constant torque and dry friction are one torque; \
             a reversal or a run down to standstill tells them apart"
        }
        ApartBy::SwappedPhases => {
            "at one connection a winding's asymmetry and a supply's unbalance add the same \
             negative-sequence current; two supply phases exchanged at the terminals tell them apart"
        }
        ApartBy::SpeedRange => {
            "a fan's torque grows with the square of the speed and viscous friction with the \
             speed, over a narrow range of speed the two are one slope; a start or a run over \
             a wide range of speed tells them apart"
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use monitor_analysis::explain::ladder::LawShape;
    use monitor_analysis::EffectId;

    /// Motulator's saturating 2.2 kW machine: Rr -23 % read beside the library's saturation
    /// law, whose knee exponent runs to its bound with Rr at the file's value.
    fn rr(not_separable: NotSeparable) -> BaseChange {
        BaseChange {
            base: BaseKey::Rr,
            change: -0.23,
            interval: Some([-0.24, -0.22]),
            file_value: 2.2,
            value: 1.69,
            unit: "ohm",
            identified: true,
            changed: false,
            not_separable: Some(not_separable),
            unsteady: None,
            in_place: None,
        }
    }

    #[test]
    fn a_change_that_trades_with_a_laws_shape_names_the_law_and_its_bound() {
        let n = NotSeparable {
            error_without: 0.0233,
            ratio_without: 4.70,
            removes: 0.58,
            traded_with: vec![EffectId::SATURATION],
            shape: Some(LawShape {
                effect: EffectId::SATURATION,
                parameter: "exponent".into(),
                with_change: 8.26,
                bound: 14.0,
            }),
        };
        let c = rr(n.clone());
        let s = base_changes(std::slice::from_ref(&c));
        assert!(
            s.contains("Rr -23 % (±1 %) is not separable from saturation"),
            "{s}"
        );
        assert!(
            s.contains("exponent runs from 8.26 to the end of its fit range (14.0)"),
            "{s}"
        );
        assert!(s.contains("4.70x"), "{s}");
        // The other reason: the model without the change still reaches the floor's band.
        let band = rr(NotSeparable {
            shape: None,
            ratio_without: 1.05,
            ..n
        });
        let s = base_changes(std::slice::from_ref(&band));
        assert!(s.contains("still reaches 1.05x its noise floor"), "{s}");
        assert!(!s.contains("fit range"), "{s}");
    }
}
