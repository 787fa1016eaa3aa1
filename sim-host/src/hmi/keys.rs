//! The HMI's keys: the one table ([`KEYS`]) the screen's footer, `--help`, docs/hmi.md
//! and the sources use.

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
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct KeyBinding {
    /// The key(s) as the user types them.
    pub keys: &'static str,
    /// Where it acts.
    pub scope: KeyScope,
    /// What it does.
    pub what: &'static str,
    /// Its few words in the screen's footer.
    pub footer: &'static str,
}

/// The HMI's keys: the one list (the screen's footer, `sim-host hmi --help` and the
/// docs/hmi.md print it; the sources act on exactly these).
pub const KEYS: &[KeyBinding] = &[
    KeyBinding {
        keys: "1..9",
        scope: KeyScope::Live,
        what: "switch Table 1 fault on/off: 1 rs 2 rr 3 ls 4 lr 5 b 6 bl 7 current_sensor 8 voltage_sensor 9 speed_sensor",
        footer: "1-9 fault",
    },
    KeyBinding {
        keys: "0",
        scope: KeyScope::Live,
        what: "clear every fault",
        footer: "0 clear",
    },
    KeyBinding {
        keys: "s",
        scope: KeyScope::Live,
        what: "size of the next fault: +50 % / -50 % / +20 % / -20 %",
        footer: "s size",
    },
    KeyBinding {
        keys: "+ -",
        scope: KeyScope::Live,
        what: "load step: Bl +10 % / -10 %",
        footer: "+- load",
    },
    KeyBinding {
        keys: "v V",
        scope: KeyScope::Live,
        what: "supply voltage step -5 % / +5 %",
        footer: "vV volt",
    },
    KeyBinding {
        keys: "f F",
        scope: KeyScope::Live,
        what: "supply frequency step -1 Hz / +1 Hz",
        footer: "fF freq",
    },
    KeyBinding {
        keys: "c",
        scope: KeyScope::Live,
        what: "start commissioning (learn the healthy thresholds over 3 s of steady running)",
        footer: "c commission",
    },
    KeyBinding {
        keys: "space",
        scope: KeyScope::Simulated,
        what: "pause / resume (live simulation and replay)",
        footer: "␣ pause",
    },
    KeyBinding {
        keys: "> <",
        scope: KeyScope::Replay,
        what: "replay speed: next (1x, 10x, max) / previous",
        footer: "<> speed",
    },
    KeyBinding {
        keys: "left right",
        scope: KeyScope::Replay,
        what: "seek -5 s / +5 s",
        footer: "←→ 5 s",
    },
    KeyBinding {
        keys: "pgup pgdn",
        scope: KeyScope::Replay,
        what: "seek -60 s / +60 s",
        footer: "PgUp/Dn 60 s",
    },
    KeyBinding {
        keys: "home end",
        scope: KeyScope::Replay,
        what: "seek to the start / to the end analysed so far",
        footer: "Home/End",
    },
    KeyBinding {
        keys: "q esc ctrl-c",
        scope: KeyScope::All,
        what: "quit",
        footer: "q quit",
    },
];

/// The key list as text (`--help`, docs/hmi.md), one key a line.
pub fn key_help() -> String {
    let mut s = String::from("Keys:\n");
    for k in KEYS {
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
