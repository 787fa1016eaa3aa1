//! The isolation's and the rotor's parts of `diagnose --json`'s document
//! ([`super::DiagnoseDoc`]): their typed values with their sentences beside them.

use super::{band_words, channel_use, group_reason, load_unknown, rotor, said};
use crate::Spelling;
use monitor_replay::{
    state_name, DetectionLimit, IsolationBaseline, IsolationEvent, IsolationGroup, IsolationName,
    IsolationReport, IsolationSaid, NameGiven, ResistanceReading, RotorBand, RotorCannot,
    RotorLoad, RotorReport, SlipSource, TemperatureReport,
};
use serde::Serialize;

/// What the isolation concluded as the document carries it (`isolation`): each of
/// [`IsolationReport`]'s values under its own key (by reference; a field added to the report
/// is a compile error in [`IsolationDoc::new`] until the document carries it), each group
/// with why in words, the conclusion in words (`verdict`), and the temperature channel's use
/// in words where the log has the column.
#[derive(Debug, Clone, Serialize)]
pub struct IsolationDoc<'a> {
    /// The conclusion's name (`isolated`, `unknown`, `no_deviation` or `not_judged`).
    pub state: &'static str,
    /// The fault named or the friction class, or null.
    pub named: Option<&'a IsolationName>,
    /// The named fault's estimated relative change, or null.
    pub named_change: Option<f32>,
    /// The probability that the named fault is the fault, or null.
    pub named_probability: Option<f32>,
    /// What it concluded, with its numbers (typed).
    pub said: &'a IsolationSaid,
    /// Candidates that cannot be separated, each with why in words.
    pub groups: Vec<GroupDoc<'a>>,
    /// The change from the baseline in standard deviations.
    pub deviation_sigma: f32,
    /// Probability that no fault of the list explains the change.
    pub unknown_probability: f32,
    /// Angle between the top two candidates' directions [deg].
    pub separation_deg: f32,
    /// The parity residuals `[e_d, e_q, e_T]` minus the baseline.
    pub residuals: [f32; 3],
    /// The healthy spread of each residual.
    pub spread: [f32; 3],
    /// `learned in commissioning` or `nominal parameters`.
    pub baseline: &'a IsolationBaseline,
    /// The first name given and when [s].
    pub first_named: Option<&'a NameGiven>,
    /// When the reported isolation was made [s].
    pub judged_at_s: f64,
    /// How far the stator current is from the one the baseline was learned at.
    pub moved_from_learned: Option<f32>,
    /// The winding's temperature rise [K] (absent below the reported rise).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub winding_rise_k: Option<f32>,
    /// The windings' heating explains the change from the baseline.
    pub heating_explains: bool,
    /// What happened, with times.
    pub events: &'a [IsolationEvent],
    /// How many events are not listed.
    pub events_dropped: usize,
    /// The log's temperature channel (its keys are the document's own).
    #[serde(flatten)]
    pub temperature: &'a TemperatureReport,
    /// Rs and Rr read apart (absent where no point could carry it).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub resistances: Option<&'a ResistanceReading>,
    /// The smallest change of each fault the isolation would have seen (absent where none).
    #[serde(skip_serializing_if = "<[_]>::is_empty")]
    pub detection_limits: &'a [DetectionLimit],
    /// What it concluded, in words ([`said`]).
    pub verdict: String,
    /// The temperature channel's use in words ([`channel_use`]; absent for a log without
    /// the column).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub temperature_channel: Option<String>,
}

impl<'a> IsolationDoc<'a> {
    /// The document of `i`, its sentences in `sp`'s words.
    pub fn new(i: &'a IsolationReport, sp: &dyn Spelling) -> Self {
        let IsolationReport {
            state,
            named,
            named_change,
            named_probability,
            said: typed,
            groups,
            deviation_sigma,
            unknown_probability,
            separation_deg,
            residuals,
            spread,
            baseline,
            first_named,
            judged_at_s,
            moved_from_learned,
            winding_rise_k,
            heating_explains,
            events,
            events_dropped,
            temperature,
            resistances,
            detection_limits,
        } = i;
        IsolationDoc {
            state: state_name(*state),
            named: named.as_ref(),
            named_change: *named_change,
            named_probability: *named_probability,
            said: typed,
            groups: groups.iter().map(GroupDoc::new).collect(),
            deviation_sigma: *deviation_sigma,
            unknown_probability: *unknown_probability,
            separation_deg: *separation_deg,
            residuals: *residuals,
            spread: *spread,
            baseline,
            first_named: first_named.as_ref(),
            judged_at_s: *judged_at_s,
            moved_from_learned: *moved_from_learned,
            winding_rise_k: *winding_rise_k,
            heating_explains: *heating_explains,
            events,
            events_dropped: *events_dropped,
            temperature,
            resistances: resistances.as_ref(),
            detection_limits,
            verdict: said(typed, sp),
            temperature_channel: temperature.temperature_channel.as_ref().map(channel_use),
        }
    }
}

/// A group of candidates the isolation cannot separate, as the document carries it
/// (`isolation.groups[]`): its typed values and why in words.
#[derive(Debug, Clone, Serialize)]
pub struct GroupDoc<'a> {
    /// The group's typed values (its faults, `why`).
    #[serde(flatten)]
    pub group: &'a IsolationGroup,
    /// Why they cannot be separated ([`group_reason`]).
    pub reason: String,
}

impl<'a> GroupDoc<'a> {
    /// The document of `g`.
    pub fn new(g: &'a IsolationGroup) -> Self {
        GroupDoc {
            group: g,
            reason: group_reason(&g.reason),
        }
    }
}

/// What `diagnose` found of the rotor as the document carries it (`rotor`): each of
/// [`RotorReport`]'s values under its own key (by reference; a field added to the report is
/// a compile error in [`RotorDoc::new`] until the document carries it), its load with why it
/// is unknown in words, and its sentences.
#[derive(Debug, Clone, Serialize)]
pub struct RotorDoc<'a> {
    /// True when the sidebands were read and judged.
    pub judged: bool,
    /// Why not, typed (null when judged).
    pub cannot_judge_reason: Option<&'a RotorCannot>,
    /// The sideband was read at the current's noise.
    pub at_noise: bool,
    /// The `(1 - 2s) f` sideband relative to the supply line [dB].
    pub level_db: Option<f64>,
    /// The `(1 + 2s) f` sideband relative to the line [dB].
    pub upper_sideband_db: Option<f64>,
    /// What the record's noise gives where the sideband is read [dB].
    pub noise_floor_db: Option<f64>,
    /// Without a slip: the largest component where the lower sideband could be [dB].
    pub largest_possible_db: Option<f64>,
    /// The level's severity band.
    pub band: Option<RotorBand>,
    /// Probability that the rotor has a fault.
    pub confidence: Option<f64>,
    /// The mean slip over the stretch read.
    pub slip: Option<f64>,
    /// Where the slip comes from.
    pub slip_source: Option<&'a SlipSource>,
    /// The supply frequency over the stretch [Hz].
    pub supply_hz: Option<f64>,
    /// The sidebands' frequencies [Hz].
    pub sideband_hz: &'a [f64],
    /// The stretch read `[from, to]` [s].
    pub window_s: &'a [f64],
    /// Spectra averaged.
    pub segments: usize,
    /// The spectra's resolution [Hz].
    pub resolution_hz: Option<f64>,
    /// The resolution the sidebands need [Hz].
    pub resolution_needed_hz: Option<f64>,
    /// The torque-producing share of the current at the slip.
    pub torque_current_share: Option<f64>,
    /// The rotor resistance asymmetry the sidebands say.
    pub delta: Option<f64>,
    /// The cage's bars, null when not given.
    pub rotor_bars: Option<u32>,
    /// Adjacent broken bars the sidebands say, null without `rotor_bars`.
    pub broken_bars: Option<f64>,
    /// The load the rotor was judged at, with why it is unknown in words.
    pub load: Option<RotorLoadDoc<'a>>,
    /// The rotor in one sentence (the report's words of the rotor, as [`super::Story`]'s `rotor`).
    pub sentence: String,
    /// Why it was not judged, in words (null when judged).
    pub cannot_judge_because: Option<String>,
    /// The band's meaning ([`band_words`]; null without a band).
    pub band_meaning: Option<String>,
}

impl<'a> RotorDoc<'a> {
    /// The document of `r`.
    pub fn new(r: &'a RotorReport) -> Self {
        let RotorReport {
            judged,
            cannot_judge_because,
            at_noise,
            level_db,
            upper_sideband_db,
            noise_floor_db,
            largest_possible_db,
            band,
            confidence,
            slip,
            slip_source,
            supply_hz,
            sideband_hz,
            window_s,
            segments,
            resolution_hz,
            resolution_needed_hz,
            torque_current_share,
            delta,
            rotor_bars,
            broken_bars,
            load,
        } = r;
        RotorDoc {
            judged: *judged,
            cannot_judge_reason: cannot_judge_because.as_ref(),
            at_noise: *at_noise,
            level_db: *level_db,
            upper_sideband_db: *upper_sideband_db,
            noise_floor_db: *noise_floor_db,
            largest_possible_db: *largest_possible_db,
            band: *band,
            confidence: *confidence,
            slip: *slip,
            slip_source: slip_source.as_ref(),
            supply_hz: *supply_hz,
            sideband_hz,
            window_s,
            segments: *segments,
            resolution_hz: *resolution_hz,
            resolution_needed_hz: *resolution_needed_hz,
            torque_current_share: *torque_current_share,
            delta: *delta,
            rotor_bars: *rotor_bars,
            broken_bars: *broken_bars,
            load: load.as_ref().map(RotorLoadDoc::new),
            sentence: rotor::sentence(r),
            cannot_judge_because: rotor::cannot_judge_because(r),
            band_meaning: band.map(|b| band_words(b).to_string()),
        }
    }
}

/// The load the rotor was judged at, as the document carries it (`rotor.load`): its typed
/// values and why it is unknown in words.
#[derive(Debug, Clone, Serialize)]
pub struct RotorLoadDoc<'a> {
    /// The load's typed values.
    #[serde(flatten)]
    pub load: &'a RotorLoad,
    /// Why it is unknown ([`load_unknown`]; null where it is known).
    pub unknown_because: Option<String>,
}

impl<'a> RotorLoadDoc<'a> {
    /// The document of `l`.
    pub fn new(l: &'a RotorLoad) -> Self {
        RotorLoadDoc {
            load: l,
            unknown_because: l.unknown_because.as_ref().map(load_unknown),
        }
    }
}
