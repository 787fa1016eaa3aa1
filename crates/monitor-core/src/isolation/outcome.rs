//! The isolation's result: each fault's fit ([`Candidate`]), the heating hypothesis' fit
//! ([`Heating`]), the conclusion ([`IsolationState`]) and what it names ([`Named`]), with
//! the rules that read heating out of it.

use super::*;

/// One fault's fit.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Candidate {
    /// The fault.
    pub fault: Fault,
    /// Probability, [0, 1]; with [`Isolation::unknown_probability`] they sum to 1.
    pub probability: f32,
    /// Estimated relative change: parameter `k - 1` (0.48 for +48 %), sensor gain error
    /// (the reading is `1 + change` times the truth).
    pub change: f32,
    /// Misfit left after the fit, in standard deviations (`sqrt(chi2)`).
    pub misfit: f32,
    /// The fit's factor is at the end of the range searched (the change may be larger).
    pub at_limit: bool,
}

/// What the isolation concluded.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum IsolationState {
    /// No valid operating point (no voltage, no current, not turning at a frequency).
    #[default]
    NotJudged,
    /// The residuals are within the healthy spread: nothing to isolate.
    NoDeviation,
    /// A fault's direction fits the change.
    Isolated,
    /// No fault's direction fits: an unknown fault (or a model that does not fit the
    /// motor); the nearest candidates are listed with their misfit.
    Unknown,
}

/// The isolation's result.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Isolation {
    /// The conclusion.
    pub state: IsolationState,
    /// Every fault's fit, most probable first.
    pub candidates: [Candidate; FAULT_COUNT],
    /// Probability that the change fits none of the faults.
    pub unknown_probability: f32,
    /// The measured change from the baseline, in standard deviations (`sqrt(chi2)` of the
    /// healthy hypothesis).
    pub deviation: f32,
    /// The residuals minus the baseline mean.
    pub residuals: ParityResiduals,
    /// Angle between the top two candidates' directions (the change each fitted size makes
    /// to the residuals, weighted by the spreads) [deg], 0..180; small: they cannot be
    /// separated at this operating point.
    pub separation_deg: f32,
    /// The heating hypothesis' fit (module docs, "Heating is not a fault").
    pub heating: Heating,
}

/// The heating hypothesis' fit: Rs and Rr of the isolator's machine both times `factor`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Heating {
    /// Probability, [0, 1], ranked with the faults and the unknown fault (their
    /// probabilities and this one sum to 1).
    pub probability: f32,
    /// Resistance factor relative to the isolator's machine ([`Isolator::heating_factor`]):
    /// `1 + alpha dT` of the further rise.
    pub factor: f32,
    /// Misfit left after the fit, in standard deviations.
    pub misfit: f32,
}

impl Default for Heating {
    fn default() -> Self {
        Heating {
            probability: 0.0,
            factor: 1.0,
            misfit: 0.0,
        }
    }
}

/// Largest misfit of the heating hypothesis that is tracked, in standard deviations (the
/// square root of [`DETECT_CHI2`]): heating must explain the deviation to within the healthy
/// scatter. A fault that arrives while the winding still warms leaves a residual that
/// neither heating nor the fault alone explains; it is not taken into the temperature.
pub const HEATING_MAX_MISFIT: f32 = 4.0;
/// Tracked rise from which the winding counts as warming ([`Isolation::heating_continues`])
/// [K].
pub const WARMING_K: f32 = 5.0;
/// Largest first step of heating that is taken when heating fits best but not alone
/// ([`Isolation::heating_begins`]) [K]: a copper winding heats by at most about 10 K/s
/// (adiabatic, at a locked rotor's current density) and a deviation is seen within about
/// 2 s of rising above the healthy scatter, so a winding that starts to warm is first seen
/// less than 20 K warmer. A step fault of Rr is first seen at its full size: Rr +10 % is
/// 25 K of heating, beyond this bound, and is judged as a fault. On a machine whose Rs is a
/// small part of its impedance (the 3 hp reference motor: 1.6 %) heating and an Rr change
/// point almost the same way, and the fit alone cannot tell them apart; how the deviation
/// grew can.
pub const HEATING_ONSET_K: f32 = 20.0;
/// Share of the learned residuals' scatter a warming trend must explain to be taken out
/// of the baseline (module docs, "Heating during commissioning").
pub const WARMING_EXPLAINS: f32 = 0.75;

impl Isolation {
    /// The heating hypothesis explains the deviation alone, as a fault is named alone
    /// ([`Isolation::named`]): probability at least 0.5, [`NAME_MARGIN`] ahead of every
    /// fault and of the unknown fault, with a misfit of at most [`HEATING_MAX_MISFIT`]. Where
    /// heating and a fault cannot be told apart (an Rr change on a machine whose Rs is a
    /// small part of its impedance) nothing is taken into the temperature.
    pub fn heating_explains(&self) -> bool {
        let h = self.heating.probability;
        let runner_up = self
            .candidates
            .first()
            .map_or(0.0, |c| c.probability)
            .max(self.unknown_probability);
        matches!(
            self.state,
            IsolationState::Isolated | IsolationState::Unknown
        ) && h >= 0.5
            && h - runner_up >= NAME_MARGIN
            && self.heating.misfit <= HEATING_MAX_MISFIT
    }

    /// Once the winding is warming (a tracked rise of [`WARMING_K`] or more), heating goes
    /// on explaining a further deviation that it fits best (more probable than every fault
    /// and the unknown fault) within [`HEATING_MAX_MISFIT`]: a winding that has started to
    /// warm goes on warming, and the small steps of the tracking are where heating and an
    /// Rr change are hardest to tell apart.
    pub fn heating_continues(&self) -> bool {
        self.heating_fits_best()
    }

    /// A winding begins to warm: heating fits the deviation best (as
    /// [`Isolation::heating_continues`]) by a rise of at most [`HEATING_ONSET_K`] (a factor
    /// `k` with `|k - 1| <= alpha HEATING_ONSET_K`). Taken into the temperature like a
    /// continued warming: where Rr, the speed sensor's gain and heating point the same way,
    /// a deviation that grew from nothing is the winding's warming, not a fault.
    pub fn heating_begins(&self) -> bool {
        let onset = COPPER_ALPHA_PER_K * HEATING_ONSET_K;
        self.heating_fits_best() && (self.heating.factor - 1.0).abs() <= onset
    }

    /// Heating is more probable than every fault and the unknown fault, within
    /// [`HEATING_MAX_MISFIT`].
    fn heating_fits_best(&self) -> bool {
        let h = self.heating.probability;
        matches!(
            self.state,
            IsolationState::Isolated | IsolationState::Unknown
        ) && h > self.unknown_probability
            && self.candidates.first().is_none_or(|c| h > c.probability)
            && self.heating.misfit <= HEATING_MAX_MISFIT
    }
}

impl Default for Isolation {
    fn default() -> Self {
        Isolation {
            state: IsolationState::NotJudged,
            candidates: Fault::ALL.map(|fault| Candidate {
                fault,
                probability: 0.0,
                change: 0.0,
                misfit: 0.0,
                at_limit: false,
            }),
            unknown_probability: 0.0,
            deviation: 0.0,
            residuals: ParityResiduals::default(),
            separation_deg: 0.0,
            heating: Heating::default(),
        }
    }
}

/// What the isolation names.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Named {
    /// One fault, with probability at least [`NAME_PROBABILITY`].
    Fault(Candidate),
    /// The friction class B/Bl (they cannot be separated): their summed probability is at
    /// least 0.5; the sizes are each one's own.
    Friction {
        /// Probability of the class.
        probability: f32,
        /// B's fit.
        b: Candidate,
        /// Bl's fit.
        bl: Candidate,
    },
}

impl Named {
    /// The name's size: the fault's change, or Bl's for the friction class.
    pub fn change(&self) -> f32 {
        match self {
            Named::Fault(c) => c.change,
            Named::Friction { bl, .. } => bl.change,
        }
    }

    /// The name's probability: the fault's, or the friction class's (B's and Bl's summed).
    pub fn probability(&self) -> f32 {
        match self {
            Named::Fault(c) => c.probability,
            Named::Friction { probability, .. } => *probability,
        }
    }

    /// The name's size stands clear of what heating and the parameter file's error move:
    /// `|change| >= MIN_FAULT_CHANGE` ([`MIN_FAULT_CHANGE`]).
    pub fn stands_clear(&self) -> bool {
        self.change().abs() >= MIN_FAULT_CHANGE
    }
}

impl Isolation {
    /// The fault (or the friction class) named: state [`IsolationState::Isolated`]; a
    /// fault alone at probability [`NAME_PROBABILITY`] or more, [`NAME_MARGIN`] ahead of
    /// the runner-up (another fault, heating or the unknown fault), its size inside the
    /// range searched; the friction class at 0.5 or more; `None` otherwise (module docs,
    /// "How sure a name is").
    pub fn named(&self) -> Option<Named> {
        if self.state != IsolationState::Isolated {
            return None;
        }
        let top = *self.candidates.first()?;
        if !matches!(top.fault, Fault::B | Fault::Bl) {
            // The runner-up: another fault, heating or the unknown fault.
            let second = self
                .candidates
                .get(1)
                .map_or(0.0, |c| c.probability)
                .max(self.heating.probability)
                .max(self.unknown_probability);
            // (A size at the end of the range searched is no size: the change may be
            // larger, and a parameter file far off fits there too.)
            let alone = top.probability >= NAME_PROBABILITY
                && top.probability - second >= NAME_MARGIN
                && !top.at_limit;
            return alone.then_some(Named::Fault(top));
        }
        let find = |f: Fault| self.candidates.iter().find(|c| c.fault == f).copied();
        let (b, bl) = (find(Fault::B)?, find(Fault::Bl)?);
        let probability = b.probability + bl.probability;
        (probability >= 0.5).then_some(Named::Friction { probability, b, bl })
    }

    /// The single fault named, if one is ([`Isolation::named`] without the friction class).
    pub fn named_fault(&self) -> Option<Candidate> {
        match self.named()? {
            Named::Fault(c) => Some(c),
            Named::Friction { .. } => None,
        }
    }
}
