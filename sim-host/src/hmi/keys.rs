//! The HMI's keys: the one table ([`keys`]) the screen's footer, `--help`, docs/hmi.md
//! and the sources use. The fault keys follow the core's fault list
//! (`monitor_core::FAULTS`): fault `k` on the `k`-th of [`FAULT_KEY_CHARS`] (`1`..`9`,
//! then letters no other key uses), so a fault added to the list gets a key.

use monitor_core::Fault;
use std::borrow::Cow;

/// A key the HMI reacts to (the binary maps the terminal's key events onto these).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Key {
    /// A printable character.
    Char(char),
    /// Left arrow.
    Left,
    /// Right arrow.
    Right,
    /// Page up.
    PageUp,
    /// Page down.
    PageDown,
    /// Home.
    Home,
    /// End.
    End,
    /// Escape.
    Esc,
}

/// Which source a key belongs to.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum KeyScope {
    /// Every source.
    All,
    /// The live simulation.
    Live,
    /// A log replay.
    Replay,
    /// The live simulation and a log replay, not the firmware's status lines (which run at
    /// the board's pace).
    Simulated,
}

/// One key binding: the key as printed, the sources it acts in, and what it does.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct KeyBinding {
    /// The key(s) as the user types them.
    pub keys: Cow<'static, str>,
    /// Where it acts.
    pub scope: KeyScope,
    /// What it does.
    pub what: Cow<'static, str>,
    /// Its few words in the screen's footer.
    pub footer: Cow<'static, str>,
}

/// The keys of the faults, in the order of the core's fault list: the digits, then the
/// letters no other binding of [`keys`] uses.
pub const FAULT_KEY_CHARS: &str = "123456789abdeghijklmnoprtuwxyz";

/// The key that switches fault `f` (`None` only beyond [`FAULT_KEY_CHARS`]).
pub fn fault_key(f: Fault) -> Option<char> {
    FAULT_KEY_CHARS.chars().nth(f.index())
}

/// The fault key `c` switches, if any.
pub fn fault_of_key(c: char) -> Option<Fault> {
    let k = FAULT_KEY_CHARS.chars().position(|x| x == c)?;
    Fault::ALL.get(k).copied()
}

/// The fault keys' binding: `1..9 switch Table 1 fault on/off: 1 rs 2 rr ..` from the
/// core's fault list.
fn fault_binding() -> KeyBinding {
    let keyed: Vec<(char, Fault)> = Fault::ALL
        .into_iter()
        .filter_map(|f| Some((fault_key(f)?, f)))
        .collect();
    // The runs of keys: the digits, the letters.
    let mut runs: Vec<(char, char)> = Vec::new();
    for (c, _) in &keyed {
        match runs.last_mut() {
            Some((first, last)) if first.is_ascii_digit() == c.is_ascii_digit() => *last = *c,
            _ => runs.push((*c, *c)),
        }
    }
    let span = |sep: &str| {
        runs.iter()
            .map(|(a, b)| format!("{a}{sep}{b}"))
            .collect::<Vec<_>>()
    };
    let names: Vec<String> = keyed.iter().map(|(c, f)| format!("{c} {f}")).collect();
    KeyBinding {
        keys: span("..").join(" ").into(),
        scope: KeyScope::Live,
        what: format!("switch Table 1 fault on/off: {}", names.join(" ")).into(),
        footer: format!("{} fault", span("-").concat()).into(),
    }
}

/// The HMI's keys: the one list (the screen's footer, `sim-host hmi --help` and the
/// docs/hmi.md print it; the sources act on exactly these).
pub fn keys() -> Vec<KeyBinding> {
    std::iter::once(fault_binding())
        .chain(OTHER_KEYS.iter().cloned())
        .collect()
}

/// The keys besides the faults'.
const OTHER_KEYS: &[KeyBinding] = &[
    KeyBinding {
        keys: Cow::Borrowed("0"),
        scope: KeyScope::Live,
        what: Cow::Borrowed("clear every fault"),
        footer: Cow::Borrowed("0 clear"),
    },
    KeyBinding {
        keys: Cow::Borrowed("s"),
        scope: KeyScope::Live,
        what: Cow::Borrowed("size of the next fault: +50 % / -50 % / +20 % / -20 %"),
        footer: Cow::Borrowed("s size"),
    },
    KeyBinding {
        keys: Cow::Borrowed("+ -"),
        scope: KeyScope::Live,
        what: Cow::Borrowed("load step: Bl +10 % / -10 %"),
        footer: Cow::Borrowed("+- load"),
    },
    KeyBinding {
        keys: Cow::Borrowed("v V"),
        scope: KeyScope::Live,
        what: Cow::Borrowed("supply voltage step -5 % / +5 %"),
        footer: Cow::Borrowed("vV volt"),
    },
    KeyBinding {
        keys: Cow::Borrowed("f F"),
        scope: KeyScope::Live,
        what: Cow::Borrowed("supply frequency step -1 Hz / +1 Hz"),
        footer: Cow::Borrowed("fF freq"),
    },
    KeyBinding {
        keys: Cow::Borrowed("c"),
        scope: KeyScope::Live,
        what: Cow::Borrowed(
            "start commissioning (learn the healthy thresholds over 3 s of steady running)",
        ),
        footer: Cow::Borrowed("c commission"),
    },
    KeyBinding {
        keys: Cow::Borrowed("space"),
        scope: KeyScope::Simulated,
        what: Cow::Borrowed("pause / resume (live simulation and replay)"),
        footer: Cow::Borrowed("␣ pause"),
    },
    KeyBinding {
        keys: Cow::Borrowed("> <"),
        scope: KeyScope::Replay,
        what: Cow::Borrowed("replay speed: next (1x, 10x, max) / previous"),
        footer: Cow::Borrowed("<> speed"),
    },
    KeyBinding {
        keys: Cow::Borrowed("left right"),
        scope: KeyScope::Replay,
        what: Cow::Borrowed("seek -5 s / +5 s"),
        footer: Cow::Borrowed("←→ 5 s"),
    },
    KeyBinding {
        keys: Cow::Borrowed("pgup pgdn"),
        scope: KeyScope::Replay,
        what: Cow::Borrowed("seek -60 s / +60 s"),
        footer: Cow::Borrowed("PgUp/Dn 60 s"),
    },
    KeyBinding {
        keys: Cow::Borrowed("home end"),
        scope: KeyScope::Replay,
        what: Cow::Borrowed("seek to the start / to the end analysed so far"),
        footer: Cow::Borrowed("Home/End"),
    },
    KeyBinding {
        keys: Cow::Borrowed("q esc ctrl-c"),
        scope: KeyScope::All,
        what: Cow::Borrowed("quit"),
        footer: Cow::Borrowed("q quit"),
    },
];

/// The key list as text (`--help`, docs/hmi.md), one key a line.
pub fn key_help() -> String {
    let mut s = String::from("Keys:\n");
    for k in keys() {
        let scope = match k.scope {
            // (Simulated: the key's words say where it acts.)
            KeyScope::All | KeyScope::Simulated => "",
            KeyScope::Live => " (live)",
            KeyScope::Replay => " (replay)",
        };
        s.push_str(&format!("  {:<13} {}{}\n", k.keys, k.what, scope));
    }
    s
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_fault_has_a_key_no_other_binding_uses() {
        let others: Vec<char> = OTHER_KEYS
            .iter()
            .flat_map(|k| k.keys.split_whitespace())
            .filter(|w| w.chars().count() == 1)
            .filter_map(|w| w.chars().next())
            .chain(['=', ' ', 'q'])
            .collect();
        for f in Fault::ALL {
            let c = fault_key(f).unwrap_or_else(|| panic!("{f} has no key"));
            assert!(
                !others.contains(&c),
                "{f}'s key {c} is bound to something else"
            );
            assert_eq!(fault_of_key(c), Some(f));
        }
        assert_eq!(fault_of_key('0'), None);
    }

    #[test]
    fn the_nine_faults_read_as_before() {
        let b = fault_binding();
        assert_eq!((b.keys.as_ref(), b.footer.as_ref()), ("1..9", "1-9 fault"));
        assert_eq!(
            b.what,
            "switch Table 1 fault on/off: 1 rs 2 rr 3 ls 4 lr 5 b 6 bl 7 current_sensor 8 voltage_sensor 9 speed_sensor"
        );
    }
}
