//! The rotor finding of `diagnose` (JSON `rotor`, [`RotorReport`]): broken rotor bars from
//! the stator current's spectrum, graded as motor current signature analysis (MCSA)
//! practice grades them, on a streaming replay of any length.
//!
//! # Method
//! An asymmetric cage (broken bars, a cracked end ring, a high-resistance joint) makes a
//! backward rotor field that induces `(1 - 2s) f` in the stator current; the `2 s f`
//! torque and speed ripple it causes adds `(1 + 2s) f` (`monitor_core::rotor_cage`).
//! 1. While the rows stream, the current space vector is turned back by the supply angle
//!    and averaged over blocks of an eighth of a supply period ([`baseband`]): a complex
//!    baseband at about 8 f with the line at 0 Hz and the sidebands at -/+ 2 s f; the last
//!    [`MAX_STRETCH_S`] are kept. Per row a complex product and a few sums.
//! 2. At the end, the longest steady stretch of that record ([`stretch`]): chunks of 0.2 s
//!    whose slip stays within [`SLIP_STEADY`] of the stretch's mean (a 0.4 % speed wobble
//!    at 3 % slip is 13 % of the slip: steady); without a speed, whose current magnitude
//!    stays within [`LOAD_STEADY`].
//! 3. The slip: from the speed channel (`wm_rad_s` or `enc_count`), else from a symmetric
//!    pair about the line in the stretch's spectrum standing [`PAIR_SNR_DB`] above its
//!    noise: the rotation-frequency components at -/+ f_r = -/+ f (1 - s) / Np
//!    (eccentricity, always present to some degree in a real machine), else the sidebands
//!    themselves at -/+ 2 s f; else "cannot judge", with the largest component anywhere
//!    the sidebands could be. A pair is only as good as its identification: another
//!    modulation of the current at the same distance (a load's, the supply's) gives a
//!    wrong slip (module docs' limits in `docs/rotor.md`).
//! 4. The spectra ([`spectrum`]): Welch segments of at most 20 s, each re-centred on its
//!    supply frequency, Blackman-Harris window, zero-padded 4x; the sidebands read as the
//!    largest bin within [`SLIP_STEADY`] of 2 s f (each segment at its own slip),
//!    relative to the line, averaged over the segments. The resolution rule of the
//!    `explain` analysis holds: the search interval clear of the line's main lobe,
//!    `2 s f >= MIN_BINS / T`.
//! 5. Where MCSA applies ([`load`]): the load from the speed, else the voltages' power,
//!    else the current's magnitude, against the parameter file's rated point; below
//!    [`MCSA_MIN_LOAD`] of the rated torque the rotor is not judged ("the load is too low
//!    to judge the rotor"), and a pair about the line whose slip the machine cannot run at
//!    steadily at that load ([`MAX_SLIP_OVER_RATED`] times its rated slip, or its breakdown
//!    slip) is not taken for the sidebands.
//! 6. The judgement ([`judge`]): the level of the `(1 - 2s) f` sideband in dB below the
//!    line and its band ([`RotorBand`]), the probability of a rotor fault, and, with the
//!    parameter file's `rotor_bars`, the adjacent broken bars
//!    (`monitor_core::rotor_cage`, at the torque-producing share of the current the
//!    parameter file's rotor time constant gives at the measured slip).
//!
//! # The bands
//! W. T. Thomson and M. Fenger, "Current signature analysis to detect induction motor
//! faults", IEEE Industry Applications Magazine 7(4), 2001, grade the `(1 - 2s) f`
//! sideband by how far it lies below the supply line: more than about 54 dB no sign of
//! broken bars; 48-54 dB watch (a developing problem may be starting); 42-48 dB a cracked
//! bar or a high-resistance joint likely; 36-42 dB two or more broken bars likely; less
//! than 36 dB several broken bars and end-ring problems. The grading assumes a motor near
//! its rated load: the sidebands scale with the rotor current, so at half load the same
//! cage reads about 6 dB lower (the report gives the torque share beside the level).
//! Other published guidelines put the edges 2-5 dB higher (for example healthy below
//! -50 dB, incipient -50..-45, moderate -45..-40, severe above -35 dB): the edges are
//! known to a few dB ([`EDGE_SPREAD_DB`]).
//!
//! # Confidence
//! The probability that the rotor has a fault: that the sideband's true level (what a
//! noise-free record of this motor would read) stands above the edge where the literature
//! starts naming bar damage, [`FAULT_EDGE_DB`] (48 dB below the line: "watch" is a finding
//! below one half, a cracked bar or worse above). The measured level is taken net of what
//! the record's noise gives in the search interval (its expected largest bin); the
//! probability is the normal distribution of the distance to the edge over the reading's
//! noise and the edge's own spread ([`judge::fault_probability`]); where the slip came from
//! the sideband pair itself, at most [`PAIR_ONLY_CONFIDENCE`]. What is not in it: a
//! healthy cage's own asymmetry, and load oscillations at 2 s f (a reciprocating load, a
//! gearbox) that put the same sidebands into the current; the bands take the first as
//! below 54 dB, the second needs the load's knowledge.

mod baseband;
mod judge;
mod load;
mod spectrum;
mod stretch;
#[cfg(test)]
mod tests;

pub use baseband::RotorFront;
pub use judge::band_of;
pub use load::{
    LoadSource, LoadUnknown, MeasuredPoint, RatedLoadPoint, RotorLoad, MAX_SLIP_OVER_RATED,
    MCSA_MIN_LOAD,
};
pub use spectrum::blackman_harris;

use monitor_io::params::ParamFile;
use serde::Serialize;

/// Half-width of the 4-term Blackman-Harris window's main lobe [bins of 1/T] (F. J.
/// Harris, "On the use of windows for harmonic analysis with the discrete Fourier
/// transform", Proc. IEEE 66(1), 1978, table I and fig. 69); outside it the leakage of any
/// tone stays below -92 dB.
pub const MAIN_LOBE_HALF_BINS: f64 = 4.0;
/// Fewest frequency bins between the line and a sideband: the sideband's search interval,
/// +/- [`SLIP_STEADY`] of 2 s f, clear of the line's main lobe,
/// `MAIN_LOBE_HALF_BINS / (1 - SLIP_STEADY)` = 5; a record of `T` s resolves sidebands
/// from `2 s f >= MIN_BINS / T` on.
pub const MIN_BINS: f64 = 5.0;
// The sideband's search interval starts (1 - SLIP_STEADY) MIN_BINS bins from the line: at
// the main lobe's edge or beyond (checked when compiled).
const _: () = assert!(MIN_BINS * (1.0 - SLIP_STEADY) >= MAIN_LOBE_HALF_BINS - 1e-9);
/// The 4-term Blackman-Harris window's coefficients a0..a3 (-92 dB sidelobes; Harris
/// 1978): w(k) = a0 - a1 cos(2 pi k/n) + a2 cos(4 pi k/n) - a3 cos(6 pi k/n).
pub const BLACKMAN_HARRIS_4: [f64; 4] = [0.35875, 0.48829, 0.14128, 0.01168];
/// Smallest slip the sidebands are judged at: below it they sit within 2 s f = 0.3 Hz (at
/// 50 Hz) of the line, a steady record of 17 s at least, and a motor at no load carries
/// too little rotor current for a broken bar to show.
pub const MIN_SLIP: f64 = 0.003;
/// Largest slip a pair of components about the line is taken for the sidebands or the
/// rotation harmonics at (small motors run at up to about 8 % at rated load); a stretch
/// whose slip from the speed is larger (a start, an overload) is not judged.
pub const MAX_SLIP: f64 = 0.12;
/// Largest variation of the slip over the analysed stretch, relative to its mean; also
/// the half-width of the sidebands' search interval relative to 2 s f.
pub const SLIP_STEADY: f64 = 0.2;
/// Largest variation of the current magnitude over a stretch judged steady without a
/// speed (relative): at rated load `|I|` moves by about half the torque current's
/// relative change, so 5 % holds the slip within about [`SLIP_STEADY`].
pub const LOAD_STEADY: f64 = 0.05;
/// Longest record kept and read [s]: 300 s resolve 3.3 mHz; a 1 h log's whole record
/// would sharpen nothing the report reads.
pub const MAX_STRETCH_S: f64 = 300.0;
/// How far above the spectrum's noise a pair about the line must stand to give the slip
/// [dB of power]: a noise bin exceeds its mean by 10 dB with probability e^-10, both of a
/// pair at once about e^-20.
pub const PAIR_SNR_DB: f64 = 10.0;
/// The largest confidence a finding whose slip came from the sideband pair itself may
/// have: the pair is taken for the rotor's only by assumption (another modulation of the
/// current at the same distance from the line, a load's, the supply's, a winding fault
/// switched on and off, makes the same pair: on real recordings of shorted turns at no
/// load, pairs at 2-9 Hz from the line read 42-50 dB below it), so it stays a finding
/// below one half, to be confirmed by a speed or the rotation harmonics.
pub const PAIR_ONLY_CONFIDENCE: f64 = 0.45;
/// The fault edge [dB relative to the line]: 48 dB below it, where Thomson and Fenger's
/// bands pass from "watch" to a cracked bar or joint (module docs).
pub const FAULT_EDGE_DB: f64 = -48.0;
/// How well the published edges agree [dB]: the spread [`judge::fault_probability`] gives
/// the edge (module docs).
pub const EDGE_SPREAD_DB: f64 = 2.0;

/// MCSA practice's severity band of the `(1 - 2s) f` sideband (Thomson and Fenger 2001;
/// module docs).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum RotorBand {
    /// More than 54 dB below the line.
    NoSign,
    /// 48-54 dB below.
    Watch,
    /// 42-48 dB below.
    CrackedBarOrJoint,
    /// 36-42 dB below.
    BrokenBars,
    /// Less than 36 dB below.
    SeveralBrokenBars,
}

impl RotorBand {
    /// Every band, from the quietest.
    pub const ALL: [RotorBand; 5] = [
        RotorBand::NoSign,
        RotorBand::Watch,
        RotorBand::CrackedBarOrJoint,
        RotorBand::BrokenBars,
        RotorBand::SeveralBrokenBars,
    ];

    /// The band's upper edge [dB relative to the line] (infinite for the last).
    pub fn upper_db(self) -> f64 {
        match self {
            RotorBand::NoSign => -54.0,
            RotorBand::Watch => -48.0,
            RotorBand::CrackedBarOrJoint => -42.0,
            RotorBand::BrokenBars => -36.0,
            RotorBand::SeveralBrokenBars => f64::INFINITY,
        }
    }
}

/// Where the slip the sidebands are read at comes from.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum SlipSource {
    /// The log's speed channel (`wm_rad_s`) or encoder count (`enc_count`).
    Speed,
    /// The rotation-frequency pair `f -/+ f_r` (eccentricity) in the current.
    Eccentricity,
    /// The sideband pair `(1 -/+ 2s) f` itself.
    Sidebands,
}

/// Why the rotor could not be judged (JSON `rotor.cannot_judge_reason`, `{"kind": ..}`).
#[derive(Debug, Clone, PartialEq, Serialize)]
#[serde(tag = "kind", rename_all = "snake_case")]
pub enum RotorCannot {
    /// Less than two supply periods of good current samples.
    NoCurrent,
    /// No steady stretch of 0.2 s chunks (of the slip where the log has a speed, else of
    /// the current).
    NotSteady {
        /// The slip was followed (the log has a speed).
        by_speed: bool,
    },
    /// The load is below [`MCSA_MIN_LOAD`] of the rated torque.
    LoadTooLow {
        /// Below a tenth of the rated torque ("no load"), else "light load".
        no_load: bool,
    },
    /// A pair about the line at a slip the machine cannot run at steadily at this load.
    NotSidebands {
        /// The pair's slip.
        slip: f64,
        /// The steady slip the machine reaches at this load.
        top: f64,
    },
    /// No speed, and no pair of sidebands nor of rotation harmonics stands above the noise.
    SlipUnknown {
        /// The largest component where the lower sideband could be [dB below the line].
        largest_db_below: f64,
    },
    /// The slip is below [`MIN_SLIP`] (no load).
    SlipBelow {
        /// The slip.
        slip: f64,
    },
    /// The slip is above [`MAX_SLIP`] (a start or an overload).
    SlipAbove {
        /// The slip.
        slip: f64,
    },
    /// The steady stretch is too short to resolve the sidebands.
    TooShort {
        /// Its length [s].
        stretch_s: f64,
        /// The length needed [s].
        needed_s: f64,
        /// The sidebands' distance from the line `2 s f` [Hz].
        offset_hz: f64,
    },
    /// No supply line in the current's spectrum.
    NoLine,
    /// The current's noise, where the sideband is read, is above what a healthy cage is told
    /// at.
    Noisy {
        /// The noise [dB below the line].
        floor_db_below: f64,
    },
}

/// What `diagnose` found of the rotor (JSON `rotor`; module docs).
#[derive(Debug, Clone, Default, Serialize)]
pub struct RotorReport {
    /// True when the sidebands were read and judged.
    pub judged: bool,
    /// Why not, null when judged (JSON `cannot_judge_reason`, `{"kind": ..}` with its
    /// numbers; the door spells it as `cannot_judge_because`, and the report's one
    /// `sentence`).
    #[serde(rename = "cannot_judge_reason")]
    pub cannot_judge_because: Option<RotorCannot>,
    /// The sideband was read at the current's noise (a judgement of "below the noise").
    pub at_noise: bool,
    /// The `(1 - 2s) f` sideband relative to the supply line [dB] (negative: -45.0 is
    /// 45 dB below the line).
    pub level_db: Option<f64>,
    /// The `(1 + 2s) f` sideband relative to the line [dB].
    pub upper_sideband_db: Option<f64>,
    /// What the record's noise gives where the sideband is read (its expected largest
    /// bin) relative to the line [dB].
    pub noise_floor_db: Option<f64>,
    /// Without a slip: the largest component anywhere the lower sideband could be (slips
    /// [`MIN_SLIP`]..[`MAX_SLIP`]) relative to the line [dB]; an upper bound of the level.
    pub largest_possible_db: Option<f64>,
    /// The level's severity band ([`RotorBand`]; the door spells its meaning as
    /// `band_meaning`).
    pub band: Option<RotorBand>,
    /// Probability that the rotor has a fault (module docs, "Confidence"); below one half
    /// for the "watch" band and quieter.
    pub confidence: Option<f64>,
    /// The mean slip over the stretch read [-].
    pub slip: Option<f64>,
    /// Where the slip comes from.
    pub slip_source: Option<SlipSource>,
    /// The supply frequency over the stretch [Hz].
    pub supply_hz: Option<f64>,
    /// The sidebands' frequencies `[(1 - 2s) f, (1 + 2s) f]` [Hz].
    pub sideband_hz: Vec<f64>,
    /// The stretch read `[from, to]` [s].
    pub window_s: Vec<f64>,
    /// Spectra averaged (Welch segments of at most `SEGMENT_S`, 20 s).
    pub segments: usize,
    /// The spectra's resolution `1/T` [Hz].
    pub resolution_hz: Option<f64>,
    /// The resolution the sidebands need, `2 s f / MIN_BINS` [Hz].
    pub resolution_needed_hz: Option<f64>,
    /// The torque-producing share of the current `I_q / |I|` at the slip (the parameter
    /// file's rotor time constant).
    pub torque_current_share: Option<f64>,
    /// The rotor resistance asymmetry the sidebands say (`monitor_core::rotor_cage`).
    pub delta: Option<f64>,
    /// The cage's bars (the parameter file's `rotor_bars`), null when not given.
    pub rotor_bars: Option<u32>,
    /// Adjacent broken bars the sidebands say, null without `rotor_bars`.
    pub broken_bars: Option<f64>,
    /// The load the rotor was judged at, against the parameter file's rated point
    /// ([`RotorLoad`]): below [`MCSA_MIN_LOAD`] of the rated torque the rotor is not judged.
    pub load: Option<RotorLoad>,
}

/// What the rotor finding needs of the parameter file and the log.
#[derive(Debug, Clone, Copy)]
pub(super) struct RotorMachine {
    /// Pole pairs.
    pub np: f64,
    /// Nominal supply frequency [Hz].
    pub f0: f64,
    /// Rotor time constant Lr/Rr [s].
    pub tau_r_s: f64,
    /// The cage's bars, where given.
    pub bars: Option<u32>,
}

impl RotorMachine {
    /// The machine of `p`.
    pub fn of(p: &ParamFile) -> Self {
        RotorMachine {
            np: f64::from(p.motor.poles / 2).max(1.0),
            f0: p.supply.f_hz,
            tau_r_s: p.motor.lr_h / p.motor.rr_ohm,
            bars: p.motor.rotor_bars,
        }
    }
}

mod read;
pub use read::rotor_report;

/// The rotor stage: its rows reach it inside the sequence stage (the demodulator runs on
/// the sequence stage's reference angle, [`RotorFront`]); at the end it reads the record
/// with the operating points the winding measured ([`RotorClosing`]).
#[derive(Debug, Clone, Copy)]
pub(crate) struct RotorStage {
    params: ParamFile,
}

/// What the chain hands the rotor at the end.
pub(crate) struct RotorClosing<'a> {
    /// The demodulator's record (`None`: the sequence stage was lent and never given back).
    pub(crate) front: Option<&'a RotorFront>,
    /// The steady operating points the winding measured, with their stretches [s].
    pub(crate) measured: &'a [([f64; 2], MeasuredPoint)],
}

impl RotorStage {
    /// The stage for `params`' machine.
    pub(crate) fn new(params: &ParamFile) -> Self {
        RotorStage { params: *params }
    }
}

impl crate::stage::Finish for RotorStage {
    type Closing<'a> = RotorClosing<'a>;
    type Finding = RotorReport;

    fn finish(self, c: RotorClosing<'_>) -> RotorReport {
        c.front.map_or_else(RotorReport::default, |f| {
            rotor_report(f, &self.params, c.measured)
        })
    }
}
