//! The one verdict: every analysis' finding in, one verdict out, by one decision table.
//!
//! Each analysis of a monitor yields a [`Finding`]: where it comes from ([`FindingSource`]: the
//! residual lamps and their isolation, the winding's negative sequence, the rotor's current
//! spectrum, the operating point, the data's quality, whether the parameter file fits), what
//! it concluded ([`State`]), and what it was judged against ([`Against`]). [`decide`] turns
//! the findings into the [`Verdict`] that every output shows: `sim-host diagnose`'s last line
//! and JSON, `explain`'s headline, the Python result, the fleet's row, the HMI and the board's
//! FAULT lamp. They all call this function, so they cannot disagree.
//!
//! # The decision table
//!
//! The first row that applies decides ([`Rule`] names the rows):
//!
//! | row | when | verdict |
//! |---|---|---|
//! | 1 [`Rule::Named`] | a finding names a fault whose size stands clear ([`Named::stands_clear`]) at a confidence of at least [`FAULT_CONFIDENCE`] | **fault**: that finding (the most confident; equal ones in [`FindingSource`] order) |
//! | 2 [`Rule::DataUntrusted`] | the data-quality finding does not trust the data | **could not judge**: what is wrong with the data |
//! | 3 [`Rule::FileMisfit`] | the parameter-fit finding says the file does not fit the log (not commissioned, a change no single fault explains, or one within the file's own uncertainty) | **could not judge**: the parameter file does not fit this log |
//! | 4 [`Rule::Watching`] | a finding names a fault below the confidence or the size a FAULT needs | **watching**: the most confident of them |
//! | 5 [`Rule::Unexplained`] | a finding's change stands out that no single fault explains (against a commissioned baseline) | **watching**: the change, with nothing named |
//! | 6 [`Rule::OutOfRange`] | the residuals saw their change only where the operating point had left the range they were judged over | **could not judge**: commission over that range |
//! | 7 [`Rule::Healthy`] | the residuals, the winding or the rotor were judged, none found anything it cannot explain, and none that could run on this log was kept from judging ([`State::NotJudged`]) | **healthy**: what was judged, and what the log lacked for the others |
//! | 8 [`Rule::NothingJudged`] | otherwise: nothing judged, or an analysis the log kept from judging | **could not judge**: what could not be judged and why |
//!
//! Two findings that disagree: a name at or above [`FAULT_CONFIDENCE`] wins over everything
//! else (row 1), so the winding's shorted turns beside residual lamps that fit no single
//! fault are a FAULT of the winding (the paper's balanced model cannot see a one-phase fault;
//! its lamps are what the short does to it); two names at or above it: the more confident.
//! The others stay in the report as findings of their own, and the verdict's text says they
//! are there. A finding that could not be judged never makes a verdict by itself; it is listed
//! as not judged.
//!
//! What the table deliberately never does: call a FAULT without a named fault with its size,
//! or at a confidence below [`FAULT_CONFIDENCE`] (a FAULT sends a crew to a motor); call
//! "healthy" beside a change nothing explains (rows 3 and 5 come first); call "could not
//! judge" beside a finding that names a fault at [`FAULT_CONFIDENCE`] or more (row 1 comes
//! first). The operating point's explanations (a load move, heating) are not faults: a finding
//! whose lamps they explain is [`State::Explained`], which row 7 counts as judged.

use crate::frames::Phase;
use crate::isolation::{within_nominal_uncertainty, MIN_FAULT_CHANGE};
use crate::signature::Fault;

/// The least confidence of a named fault for a FAULT: even odds. A confidence is a
/// calibrated probability that the named fault (and its phase) is the motor's, so at least
/// half of the FAULTs called at this confidence are right, and far more at the confidences
/// most are called at (the reliability tables in `docs/isolation.md`).
pub const FAULT_CONFIDENCE: f32 = 0.5;

/// The least level of the (1 - 2s) f sideband, in dB below the supply line, that is no sign of
/// a rotor fault (MCSA practice, Thomson and Fenger, IEEE Industry Applications Magazine 7(4),
/// 2001: below this the cage is graded "a cracked bar or a high-resistance joint likely" or
/// worse; 48-54 dB is "watch").
pub const ROTOR_FAULT_DB: f32 = 48.0;

/// Where a finding comes from. The order is the order of precedence between equally confident
/// names (the fault-specific analyses before the balanced model's residuals).
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
#[cfg_attr(feature = "serde", serde(rename_all = "snake_case"))]
pub enum FindingSource {
    /// The data-quality stage (bad cells, gaps, clipped or swapped channels; the core's sensor
    /// flags: readings no machine gives).
    DataQuality,
    /// Whether the parameter file fits the log (judged from the residuals against the file's
    /// nominal values where nothing was commissioned).
    ParameterFit,
    /// The winding: the change of the negative-sequence current (shorted turns).
    Winding,
    /// The rotor: the (1 - 2s) f sideband of the current (broken bars).
    Rotor,
    /// The residual lamps r1..r4 and their isolation (Table 1's faults with their size).
    Residuals,
    /// The operating point: load moves, heating, the range commissioned.
    OperatingPoint,
}

impl FindingSource {
    /// Every source, in precedence order.
    pub const ALL: [FindingSource; 6] = [
        FindingSource::DataQuality,
        FindingSource::ParameterFit,
        FindingSource::Winding,
        FindingSource::Rotor,
        FindingSource::Residuals,
        FindingSource::OperatingPoint,
    ];

    /// The name in reports: `data_quality`, `parameter_fit`, `winding`, `rotor`,
    /// `residuals`, `operating_point`.
    pub const fn name(self) -> &'static str {
        match self {
            FindingSource::DataQuality => "data_quality",
            FindingSource::ParameterFit => "parameter_fit",
            FindingSource::Winding => "winding",
            FindingSource::Rotor => "rotor",
            FindingSource::Residuals => "residuals",
            FindingSource::OperatingPoint => "operating_point",
        }
    }

    /// Whether the source judges the motor for faults (the residuals, the winding, the rotor),
    /// rather than the conditions of the judgement (the data, the file, the operating point).
    pub const fn judges_faults(self) -> bool {
        matches!(
            self,
            FindingSource::Residuals | FindingSource::Winding | FindingSource::Rotor
        )
    }
}

/// What a finding was judged against.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
#[cfg_attr(feature = "serde", serde(rename_all = "snake_case"))]
pub enum Against {
    /// A baseline learned on the healthy motor in a commissioning window.
    Commissioning,
    /// Healthy runs of the same motor given by the user (`diagnose --baseline`).
    HealthyRuns,
    /// The log's own steady stretches against each other: a fault switched on or off within
    /// the log is a change between them (one that was on throughout is not).
    WithinTheLog,
    /// The parameter file's nominal values.
    ParameterFile,
    /// Physics and practice alone (a healthy machine's own asymmetry, the MCSA severity
    /// bands).
    #[default]
    Nothing,
}

impl Against {
    /// The name in reports.
    pub const fn name(self) -> &'static str {
        match self {
            Against::Commissioning => "commissioning",
            Against::HealthyRuns => "healthy_runs",
            Against::WithinTheLog => "within_the_log",
            Against::ParameterFile => "parameter_file",
            Against::Nothing => "nothing",
        }
    }
}

/// A fault a finding can name.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum FaultName {
    /// One of the paper's Table 1 faults (a parameter's change or a sensor's gain error; never
    /// B or Bl alone: see [`FaultName::Friction`]).
    Table1(Fault),
    /// The friction class B/Bl (`b/bl`): B and Bl scale the same load term and cannot be
    /// separated, and a load change moves it as a fault of either would. It is watched, never
    /// a FAULT ([`NamedFault::stands_clear`]): no log without a load model tells a bearing
    /// from the load.
    Friction,
    /// Shorted turns in one phase's winding.
    ShortedTurns,
    /// Broken rotor bars (or a cracked end ring, a high-resistance joint).
    BrokenBars,
}

impl FaultName {
    /// The name in reports: Table 1's names (`rs` ... `speed_sensor`), `b/bl`,
    /// `shorted_turns`, `broken_bars`.
    pub fn name(self) -> &'static str {
        match self {
            FaultName::Table1(f) => f.name(),
            FaultName::Friction => "b/bl",
            FaultName::ShortedTurns => "shorted_turns",
            FaultName::BrokenBars => "broken_bars",
        }
    }
}

/// The size of a named fault, in the unit its analysis measures it in.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Size {
    /// A relative change (0.5: +50 %): a parameter's change or a sensor's gain error.
    Relative(f32),
    /// The change of the negative-sequence current, `|Delta I2| / |I1|` (0.05: 5 % of I1).
    OfPositiveSequence(f32),
    /// The fraction of one phase's turns that are shorted (0.3: 30 %).
    TurnsFraction(f32),
    /// The (1 - 2s) f sideband's level below the supply line [dB, positive: 42 = 42 dB below].
    DbBelowLine(f32),
}

/// A named fault with its size, phase and confidence.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct NamedFault {
    /// The fault.
    pub fault: FaultName,
    /// Its size.
    pub size: Size,
    /// Its phase, where it has one (shorted turns, one phase's sensor).
    pub phase: Option<Phase>,
    /// The calibrated probability, 0..1, that the fault (and its phase) is the motor's.
    pub confidence: f32,
}

impl NamedFault {
    /// Whether the size stands clear of what a healthy motor and its parameter file move, so
    /// that a crew would act on it, against `against`:
    /// - a relative change: at least [`MIN_FAULT_CHANGE`] (5 %: 13 K of heating on a winding,
    ///   a commissioned file's error at other operating points), and against the parameter
    ///   file's nominal values more than its own uncertainty
    ///   ([`crate::isolation::NOMINAL_UNCERTAINTY`], 30 %);
    /// - a sideband at [`ROTOR_FAULT_DB`] or less below the supply line;
    /// - shorted turns: always (their analysis names a phase only for a change that stands
    ///   clear of a healthy machine's asymmetry); a fraction of turns above zero;
    /// - the friction class: never (a load change moves it as much).
    ///
    /// A size that is not a number never stands clear.
    pub fn stands_clear(&self, against: Against) -> bool {
        if self.fault == FaultName::Friction {
            return false;
        }
        match self.size {
            Size::Relative(c) => {
                c.abs() >= MIN_FAULT_CHANGE
                    && (against != Against::ParameterFile || !within_nominal_uncertainty(c))
            }
            Size::DbBelowLine(db) => db <= ROTOR_FAULT_DB,
            Size::OfPositiveSequence(x) | Size::TurnsFraction(x) => x > 0.0,
        }
    }

    /// The isolation's name as the verdict reads it: a Table 1 fault with its change and its
    /// probability as the confidence, or the friction class with Bl's change.
    pub fn of_isolation(n: &crate::isolation::Named) -> NamedFault {
        match n {
            crate::isolation::Named::Fault(c) => NamedFault {
                fault: FaultName::Table1(c.fault),
                size: Size::Relative(c.change),
                phase: None,
                confidence: c.probability,
            },
            crate::isolation::Named::Friction {
                probability, bl, ..
            } => NamedFault {
                fault: FaultName::Friction,
                size: Size::Relative(bl.change),
                phase: None,
                confidence: *probability,
            },
        }
    }

    /// Whether this name makes a FAULT against `against`: its size stands clear and its
    /// confidence is at least [`FAULT_CONFIDENCE`] (a confidence that is not a number never
    /// does).
    pub fn is_fault(&self, against: Against) -> bool {
        self.confidence >= FAULT_CONFIDENCE && self.stands_clear(against)
    }
}

/// What a finding concluded.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum State {
    /// The log lacks what this analysis needs (a channel it does not have, a load the
    /// analysis needs, a record too short for its resolution): listed, and a verdict of
    /// healthy may still rest on the others.
    Unavailable,
    /// The analysis could run on this log but the log did not let it judge (never settled,
    /// too short after commissioning, the end unsettled with the residuals far off, the
    /// commissioning window not learned): no verdict of healthy while this stands.
    NotJudged,
    /// Judged: nothing found.
    Clear,
    /// A fault named, with its size.
    Named(NamedFault),
    /// A change stands out that no single fault explains (several faults, an unknown fault);
    /// for [`FindingSource::ParameterFit`]: the file does not fit the log; for
    /// [`FindingSource::DataQuality`]: the data cannot carry a verdict.
    Unexplained,
    /// The analysis saw a change (lit lamps) that the operating point explains (a load that
    /// moved, heating): judged, no fault. For [`FindingSource::OperatingPoint`]: it explains one.
    Explained,
    /// The analysis saw its change only where the operating point had left the range it was
    /// judged over (the load outside the commissioned range): not judged there.
    OutOfRange,
}

/// One analysis' finding, as the decision table reads it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Finding {
    /// Where it comes from.
    pub source: FindingSource,
    /// What it concluded.
    pub state: State,
    /// What it was judged against.
    pub against: Against,
}

impl Finding {
    /// A finding of `source` in `state` against `against`.
    pub const fn new(source: FindingSource, state: State, against: Against) -> Self {
        Finding {
            source,
            state,
            against,
        }
    }

    /// The name, when the finding names a fault.
    pub fn named(&self) -> Option<&NamedFault> {
        match &self.state {
            State::Named(n) => Some(n),
            _ => None,
        }
    }

    /// Whether the finding names a FAULT ([`Named::is_fault`] against its baseline).
    pub fn is_fault(&self) -> bool {
        self.named().is_some_and(|n| n.is_fault(self.against))
    }
}

/// The verdict (JSON `verdict`: `fault`, `watching`, `healthy`, `could_not_judge`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
#[cfg_attr(feature = "serde", serde(rename_all = "snake_case"))]
pub enum Verdict {
    /// A named fault with its size at a confidence of at least [`FAULT_CONFIDENCE`]: send a
    /// crew.
    Fault,
    /// A fault named below what a FAULT needs, or a change nothing explains: keep watching.
    Watching,
    /// Judged, and nothing found that the operating point does not explain.
    Healthy,
    /// The data or the set-up does not carry a verdict (the reasons say why).
    CouldNotJudge,
}

impl Verdict {
    /// The name in reports and on the board's status line.
    pub const fn name(self) -> &'static str {
        match self {
            Verdict::Fault => "fault",
            Verdict::Watching => "watching",
            Verdict::Healthy => "healthy",
            Verdict::CouldNotJudge => "could_not_judge",
        }
    }

    /// The verdict of a [`Verdict::name`].
    pub fn from_name(name: &str) -> Option<Verdict> {
        [
            Verdict::Fault,
            Verdict::Watching,
            Verdict::Healthy,
            Verdict::CouldNotJudge,
        ]
        .into_iter()
        .find(|v| v.name() == name)
    }
}

/// The row of the decision table that decided (module docs).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
#[cfg_attr(feature = "serde", serde(rename_all = "snake_case"))]
pub enum Rule {
    /// Row 1: a named fault that stands clear, at a confidence of at least
    /// [`FAULT_CONFIDENCE`].
    Named,
    /// Row 2: the data cannot carry a verdict.
    DataUntrusted,
    /// Row 3: the parameter file does not fit the log.
    FileMisfit,
    /// Row 4: a named fault below what a FAULT needs.
    Watching,
    /// Row 5: a change no single fault explains.
    Unexplained,
    /// Row 6: the change was seen only outside the range judged over.
    OutOfRange,
    /// Row 7: judged, nothing unexplained.
    Healthy,
    /// Row 8: nothing could be judged.
    NothingJudged,
}

/// What [`decide`] concluded: the verdict, the row that decided, and the finding it rests on
/// (its index in the findings given), where one decided.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Decision {
    /// The verdict.
    pub verdict: Verdict,
    /// The row of the table.
    pub rule: Rule,
    /// The index of the deciding finding in the slice given to [`decide`].
    pub by: Option<usize>,
}

/// The most confident named finding among `findings` that `keep` accepts (equal confidences:
/// the first in [`FindingSource`] order); its index.
fn most_confident(findings: &[Finding], keep: impl Fn(&Finding) -> bool) -> Option<usize> {
    let mut best: Option<(usize, f32, FindingSource)> = None;
    for (k, f) in findings.iter().enumerate() {
        let Some(n) = f.named() else { continue };
        if !keep(f) {
            continue;
        }
        // A confidence that is not a number ranks last.
        let c = if n.confidence.is_nan() {
            -1.0
        } else {
            n.confidence
        };
        let better = match best {
            None => true,
            Some((_, bc, bs)) => c > bc || (c == bc && f.source < bs),
        };
        if better {
            best = Some((k, c, f.source));
        }
    }
    best.map(|(k, _, _)| k)
}

/// The first finding of `source` in a state `pick` accepts; its index.
fn first_of(
    findings: &[Finding],
    source: Option<FindingSource>,
    pick: impl Fn(&State) -> bool,
) -> Option<usize> {
    findings
        .iter()
        .position(|f| source.is_none_or(|s| f.source == s) && pick(&f.state))
}

/// The verdict from the findings (module docs, "The decision table"). Any number of findings
/// in any order; a source may appear more than once (the first decides among equals). Never
/// panics; an empty slice is [`Rule::NothingJudged`].
pub fn decide(findings: &[Finding]) -> Decision {
    let of = |verdict, rule, by| Decision { verdict, rule, by };
    if let Some(k) = most_confident(findings, Finding::is_fault) {
        return of(Verdict::Fault, Rule::Named, Some(k));
    }
    let unexplained = |s: &State| matches!(s, State::Unexplained);
    if let Some(k) = first_of(findings, Some(FindingSource::DataQuality), unexplained) {
        return of(Verdict::CouldNotJudge, Rule::DataUntrusted, Some(k));
    }
    if let Some(k) = first_of(findings, Some(FindingSource::ParameterFit), unexplained) {
        return of(Verdict::CouldNotJudge, Rule::FileMisfit, Some(k));
    }
    if let Some(k) = most_confident(findings, |_| true) {
        return of(Verdict::Watching, Rule::Watching, Some(k));
    }
    let fault_source = |f: &Finding| f.source.judges_faults();
    if let Some(k) = findings
        .iter()
        .position(|f| fault_source(f) && unexplained(&f.state))
    {
        return of(Verdict::Watching, Rule::Unexplained, Some(k));
    }
    if let Some(k) = first_of(findings, None, |s| matches!(s, State::OutOfRange)) {
        return of(Verdict::CouldNotJudge, Rule::OutOfRange, Some(k));
    }
    let judged = findings
        .iter()
        .any(|f| fault_source(f) && matches!(f.state, State::Clear | State::Explained));
    let kept_from_judging = findings
        .iter()
        .any(|f| fault_source(f) && matches!(f.state, State::NotJudged));
    if judged && !kept_from_judging {
        return of(Verdict::Healthy, Rule::Healthy, None);
    }
    of(Verdict::CouldNotJudge, Rule::NothingJudged, None)
}

/// What a monitor sees at one moment, for its panel: the board's latest status and
/// isolation, a replay's output at a timeline point. [`Glance::decide`] gives the moment's
/// verdict by the same table as a whole log's ([`decide`]), so the board's FAULT lamp, the
/// HMI's panel and `diagnose`'s timeline agree with the verdict.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Glance {
    /// A residual lamp r1..r4 is lit.
    pub lamps_lit: bool,
    /// A sensor gives readings no machine gives (the core's sensor flags).
    pub sensor_fault: bool,
    /// What the isolation names now (a Table 1 fault or the friction class, with its size and
    /// probability), if anything.
    pub named: Option<NamedFault>,
    /// The isolation and the lamps judge against a baseline learned in commissioning (else
    /// against the parameter file's nominal values).
    pub commissioned: bool,
    /// The operating point explains the lamps: the load or the voltage left the commissioned
    /// range, or the isolation reads the lamps' change as the load's (the friction class).
    pub moved: bool,
    /// Shorted turns named by the negative-sequence analysis, if any.
    pub winding: Option<NamedFault>,
}

impl Glance {
    /// The moment's findings: the residuals, the parameter file's fit, the data's quality
    /// and the winding, as [`decide`] reads them.
    ///
    /// The residuals detect when a lamp is lit, or when the isolation names a fault against a
    /// commissioned baseline (below the lamps' thresholds its three equations can still be
    /// outside their healthy spread). A detection is the isolation's name where it gives one;
    /// else the operating point's ([`State::Explained`]) where it moved; else a change no
    /// single fault explains, which against the nominal values means the file does not fit.
    pub fn findings(&self) -> [Finding; 4] {
        let against = if self.commissioned {
            Against::Commissioning
        } else {
            Against::ParameterFile
        };
        let detected = self.lamps_lit || (self.named.is_some() && self.commissioned);
        let residual = match (detected, self.named) {
            (false, _) => State::Clear,
            (true, Some(n)) => State::Named(n),
            (true, None) if self.moved => State::Explained,
            (true, None) => State::Unexplained,
        };
        let misfit = !self.commissioned
            && match residual {
                State::Unexplained => true,
                State::Named(n) => !n.stands_clear(Against::ParameterFile),
                _ => false,
            };
        let state = |bad: bool| {
            if bad {
                State::Unexplained
            } else {
                State::Clear
            }
        };
        [
            Finding::new(FindingSource::Residuals, residual, against),
            Finding::new(
                FindingSource::ParameterFit,
                state(misfit),
                Against::ParameterFile,
            ),
            Finding::new(
                FindingSource::DataQuality,
                state(self.sensor_fault),
                Against::Nothing,
            ),
            Finding::new(
                FindingSource::Winding,
                self.winding.map_or(State::Unavailable, State::Named),
                Against::Nothing,
            ),
        ]
    }

    /// The moment's verdict ([`decide`] over [`Glance::findings`]).
    pub fn decide(&self) -> Decision {
        decide(&self.findings())
    }
}

#[cfg(test)]
mod tests;
