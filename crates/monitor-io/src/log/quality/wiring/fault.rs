//! What the wiring check finds ([`WiringFault`]) and the column mapping that fixes it
//! ([`ColumnFix`]); the check is the parent module's.

use crate::log::Column;
use serde::Serialize;

/// One set of phase channels.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum PhaseSet {
    /// `va_V`, `vb_V`, `vc_V`.
    Voltages,
    /// `ia_A`, `ib_A`, `ic_A`.
    Currents,
}

impl PhaseSet {
    /// The set's columns a, b, c.
    pub const fn columns(self) -> [Column; 3] {
        match self {
            PhaseSet::Voltages => [Column::Va, Column::Vb, Column::Vc],
            PhaseSet::Currents => [Column::Ia, Column::Ib, Column::Ic],
        }
    }
}

/// One entry of the column mapping that fixes a wiring fault: schema column `column` is to
/// read the log's channel now read as `reads`, its sign turned where `invert` (the
/// parameter file's `[columns]`: `ib_A = { name = "ic_A" }`, `ia_A = { name = "ia_A",
/// invert = true }`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
pub struct ColumnFix {
    /// The schema column.
    #[serde(serialize_with = "column_name")]
    pub column: Column,
    /// The channel it is to read (by the schema name it is read under now).
    #[serde(serialize_with = "column_name")]
    pub reads: Column,
    /// Its sign turned.
    pub invert: bool,
}

fn column_name<S: serde::Serializer>(c: &Column, s: S) -> Result<S::Ok, S::Error> {
    s.serialize_str(c.name())
}

/// What the wiring check found (JSON `data_quality.wiring[]`, `{"kind": ..}`, with `fix`,
/// the mapping that repairs it, and `sentence`).
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
#[serde(tag = "kind", rename_all = "snake_case")]
pub enum WiringFault {
    /// Two channels of one set read the same value on `share` of the rows.
    Duplicated {
        /// The first channel.
        #[serde(serialize_with = "column_name")]
        first: Column,
        /// The second.
        #[serde(serialize_with = "column_name")]
        second: Column,
        /// Share of the rows, 0..1.
        share: f64,
    },
    /// One channel's sign is reversed: its set sums to `zero_sequence` times a phase's RMS.
    Reversed {
        /// The channel.
        #[serde(serialize_with = "column_name")]
        channel: Column,
        /// RMS of the set's sum over a phase's RMS (a healthy set: about 0).
        zero_sequence: f64,
    },
    /// Two channels of one set are exchanged: the currents turn against the voltages
    /// (`coherence`, `|S|` over `|V| |I|`, about 0), and exchanging these two gives a
    /// motor's power-factor angle `angle_deg`.
    Exchanged {
        /// The set whose channels are exchanged (the one that turns against the shaft, or
        /// against the voltages without a speed).
        set: PhaseSet,
        /// The first channel.
        #[serde(serialize_with = "column_name")]
        first: Column,
        /// The second.
        #[serde(serialize_with = "column_name")]
        second: Column,
        /// `|S| / (|V| |I|)` as logged.
        coherence: f64,
        /// The power-factor angle with the two exchanged back [deg].
        angle_deg: f64,
    },
    /// Voltages and currents both turn backwards (phase order a-c-b): b and c exchanged in
    /// both sets, or the motor runs backwards (`shaft_backwards`: the speed says so).
    PhaseOrderReversed {
        /// The speed channel's mean is negative: the motor turns backwards and the monitor,
        /// which judges a forward machine, needs the speed's sign turned too.
        shaft_backwards: bool,
        /// The current vector's turn, -1 for a pure negative sequence.
        turn: f64,
    },
    /// The current channels are rotated one phase against the voltages (each reads the
    /// next phase's current): the power-factor angle `angle_deg` is no motor's.
    Rotated {
        /// The current channels' rotation that repairs it: 1 (ia_A reads ib_A's ...) or 2.
        by: u8,
        /// The power-factor angle as logged [deg].
        angle_deg: f64,
    },
    /// The voltages and currents turn forward but the speed channel reads the shaft
    /// backwards: its sign.
    SpeedReversed {
        /// The speed channel's mean [rad/s].
        mean_rad_s: f64,
    },
    /// Without voltages: the currents turn against the shaft's direction (two current
    /// channels exchanged, or the speed's sign).
    CurrentsAgainstShaft {
        /// The speed channel's mean [rad/s].
        mean_rad_s: f64,
    },
}

/// A pair exchanged in `set` (a, b, c indices).
fn exchanged(set: PhaseSet, p: (usize, usize)) -> [ColumnFix; 2] {
    let c = set.columns();
    [
        ColumnFix {
            column: c[p.0],
            reads: c[p.1],
            invert: false,
        },
        ColumnFix {
            column: c[p.1],
            reads: c[p.0],
            invert: false,
        },
    ]
}

impl WiringFault {
    /// The column mapping that repairs the log (empty where none can: a duplicated
    /// channel holds no copy of the phase it replaced).
    pub fn fix(&self) -> Vec<ColumnFix> {
        let col = |c| ColumnFix {
            column: c,
            reads: c,
            invert: true,
        };
        match *self {
            WiringFault::Duplicated { .. } => Vec::new(),
            WiringFault::Reversed { channel, .. } => vec![col(channel)],
            WiringFault::Exchanged {
                set, first, second, ..
            } => {
                let k = |c: Column| set.columns().iter().position(|x| *x == c).unwrap_or(0);
                exchanged(set, (k(first), k(second))).to_vec()
            }
            WiringFault::PhaseOrderReversed {
                shaft_backwards, ..
            } => {
                let mut f = exchanged(PhaseSet::Voltages, (1, 2)).to_vec();
                f.extend(exchanged(PhaseSet::Currents, (1, 2)));
                if shaft_backwards {
                    f.push(col(Column::Speed));
                }
                f
            }
            WiringFault::Rotated { by, .. } => {
                let c = PhaseSet::Currents.columns();
                (0..3)
                    .map(|k| ColumnFix {
                        column: c[k],
                        reads: c[(k + usize::from(by)) % 3],
                        invert: false,
                    })
                    .collect()
            }
            WiringFault::SpeedReversed { .. } => vec![col(Column::Speed)],
            WiringFault::CurrentsAgainstShaft { .. } => {
                exchanged(PhaseSet::Currents, (1, 2)).to_vec()
            }
        }
    }

    /// The fix as the parameter file's `[columns]` entries in dotted keys, for a log with
    /// the schema's channel names (`ib_A.name = "ic_A"; ic_A.name = "ib_A"`,
    /// `ia_A.invert = true`), one entry a line in the file.
    pub fn fix_entries(&self) -> String {
        self.fix()
            .iter()
            .flat_map(|f| {
                let c = f.column.name();
                [
                    (f.reads != f.column).then(|| format!("{c}.name = \"{}\"", f.reads.name())),
                    f.invert.then(|| format!("{c}.invert = true")),
                ]
            })
            .flatten()
            .collect::<Vec<_>>()
            .join("; ")
    }

    /// What was found, in one line, with the fix.
    pub fn sentence(&self) -> String {
        match self {
            WiringFault::Duplicated { .. } => self.what(),
            _ => format!("{}; fix: [columns] {}", self.what(), self.fix_entries()),
        }
    }

    /// What was found, without the fix.
    fn what(&self) -> String {
        match *self {
            WiringFault::Duplicated {
                first,
                second,
                share,
            } => format!(
                "{} and {} read the same value on {:.0} % of the rows: one channel duplicates the other (a copied column, or two inputs on one sensor)",
                first.name(),
                second.name(),
                100.0 * share
            ),
            WiringFault::Reversed {
                channel,
                zero_sequence,
            } => format!(
                "{} is reversed (a sensor mounted the other way): the set sums to {zero_sequence:.1} times a phase, to 0 with its sign turned",
                channel.name()
            ),
            WiringFault::Exchanged {
                set: PhaseSet::Currents,
                first,
                second,
                ..
            } => format!(
                "{} and {} are exchanged: the currents turn against the voltages",
                first.name(),
                second.name()
            ),
            WiringFault::Exchanged {
                set: PhaseSet::Voltages,
                first,
                second,
                ..
            } => format!(
                "{} and {} are exchanged: the voltages turn against the currents and the shaft",
                first.name(),
                second.name()
            ),
            WiringFault::PhaseOrderReversed {
                shaft_backwards: false,
                ..
            } => "V and I turn backwards (a-c-b): b, c exchanged in both sets".to_string(),
            WiringFault::PhaseOrderReversed {
                shaft_backwards: true,
                ..
            } => "motor runs backwards (a-c-b, speed < 0)".to_string(),
            WiringFault::Rotated { angle_deg, .. } => format!(
                "the currents are rotated one phase (power-factor angle {angle_deg:.0} deg, a motor's is 0..90)"
            ),
            WiringFault::SpeedReversed { mean_rad_s } => format!(
                "wm_rad_s reads the shaft backwards (mean {mean_rad_s:.1} rad/s) while the voltages and currents turn forward"
            ),
            WiringFault::CurrentsAgainstShaft { mean_rad_s } => format!(
                "the currents turn against the shaft (speed mean {mean_rad_s:.1} rad/s): two current channels are exchanged, or wm_rad_s's sign"
            ),
        }
    }
}

/// The JSON of the report's wiring faults: each fault's fields with its `fix` and its
/// `sentence`.
pub fn serialize_all<S: serde::Serializer>(all: &[WiringFault], s: S) -> Result<S::Ok, S::Error> {
    #[derive(Serialize)]
    struct Json<'a> {
        #[serde(flatten)]
        fault: &'a WiringFault,
        fix: Vec<ColumnFix>,
        sentence: String,
    }
    s.collect_seq(all.iter().map(|f| Json {
        fault: f,
        fix: f.fix(),
        sentence: f.sentence(),
    }))
}
