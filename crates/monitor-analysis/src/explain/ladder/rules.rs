//! The ladder's rules, in numbers: the test a step passes, the noise-floor band it stops
//! within, how finely the held-back split cuts the log, how many samples its fits run on,
//! and how a round narrows its candidates.
//!
//! # The held-back split
//! The log is cut into strata by its events ([`crate::strata::strata`]: the start, supply
//! or speed transients, load moves, steady stretches), and every stratum into an even
//! number of alternating windows ([`super::split::stratified_heldback`]), so that each kind of
//! event the log holds falls in both the fitted and the held-back part. A fixed
//! interleave of the whole log can put a log's only load step in the fitted part and leave
//! the held-back windows blind to the effect that explains it.
//!
//! # The test a step passes
//! A step is kept when the candidate removes at least [`STEP_MIN`] (10 %) of the held-back
//! error beyond the noise floor that the model had before the step
//! ([`crate::explain::explained_fraction`], each parameter costing [`crate::explain::PARAM_PENALTY`] of the
//! held-back error), and lowers the whole-log error. The held-back error is an
//! out-of-sample estimate: a candidate that only fits noise does not lower it, and one that
//! absorbs another effect lowers it less than the effect itself. An information criterion
//! (AIC, BIC) would count each of the log's 10⁴-10⁶ samples as an independent observation,
//! while a model's error is structural and correlated over whole events: every candidate
//! would pass. The threshold is the largest share a candidate without effect removed on the
//! effect-free control logs of the test matrix (a textbook machine written inside the test,
//! three sizes, starts and steps: under 10 %), doubled (docs/model-vs-measurement.md).

use crate::effects::ApartBy;
use crate::explain::NOISE_MARGIN;
use crate::fit::machine::BaseKey;
use monitor_core::effect::EffectKind;

/// A step must remove at least this share (10 %) of the held-back error beyond the noise
/// floor that the model had before it (this module's doc, "The test a step passes").
pub const STEP_MIN: f64 = 0.1;
/// The noise-floor band: an error within this factor of its noise floor, on the whole log
/// and on the held-back part, has nothing left to explain (the same margin as
/// [`NOISE_MARGIN`]: a model error beyond the noise of half the noise floor).
pub const FLOOR_BAND: f64 = NOISE_MARGIN;
/// Supply periods of the longest logs [`FLOOR_BAND`] was set on (10 s at 50 Hz: the
/// ladder's benchmark and the analysis sweeps' logs). A longer log's band narrows
/// ([`FloorBand::of_periods`]).
pub const BAND_PERIODS: f64 = 500.0;
/// The narrowest band, as the model error beyond the noise it lets through, in units of
/// the noise floor (0.25: 1.03x the floor). The floor is measured, not known: on long
/// clean logs whose model is complete (the 40 s controls of motulator's 2.2 kW machine,
/// the 3 hp and 0.37 kW machines) the error ends 0.98-1.02x it, so a band inside that
/// would send a control's ladder on to fit the floor's own error.
pub const BAND_EXCESS_MIN: f64 = 0.25;

/// The noise-floor band of one log: the ratio to its floor within which the ladder stops,
/// and the matching model error beyond the noise below which nothing is left to explain
/// (the step's test reads a share of an excess below it as 0).
///
/// The excess `x` is half the noise floor on a log of up to [`BAND_PERIODS`] supply
/// periods ([`FLOOR_BAND`], 1.12x), and shrinks with the square root of the log's length
/// beyond, `x = 0.5 sqrt(BAND_PERIODS / periods)`, to [`BAND_EXCESS_MIN`] at four times
/// as long; the ratio is `FLOOR_BAND sqrt(1 + x²) / sqrt(1.25)` (1.12x at `x = 0.5`,
/// 1.03x at 0.25). A model error is correlated over an event, not over a sample: what a
/// log adds to the evidence is its supply periods, each a new look at every stretch of
/// its service, and an excess estimated over four times as many periods is known to half
/// the spread. A 40 s log at 60 Hz of a 3 hp machine warming by 50 K ended at 1.04x with the
/// dynamics alone and never tried the drift, which its 2 400 periods show (issue 87).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FloorBand {
    /// Stop within this factor of the noise floor (whole log and held-back part).
    pub ratio: f64,
    /// The model error beyond the noise (`sqrt(E² - N²)`) in units of the floor `N`
    /// below which there is nothing left to explain.
    pub excess: f64,
    /// What each parameter of a candidate costs, as a share of its held-back error:
    /// [`crate::explain::PARAM_PENALTY`] on a log of up to [`BAND_PERIODS`] supply periods,
    /// and that times `(x / 0.5)²` beyond, as the band's excess `x` narrows. The penalty
    /// raises a candidate's squared error by about `2 PARAM_PENALTY` of the floor's square
    /// a parameter, a margin set against short logs' excess of `0.5² = 0.25`: a 40 s log's
    /// excess of `0.25² = 0.0625` leaves a three-parameter candidate nothing to win at the
    /// short logs' rate (`0.12`).
    pub penalty: f64,
}

impl FloorBand {
    /// The band of a log of `periods` supply periods (the working series' supply angle
    /// over 2 pi; not finite or not positive: the short log's band).
    pub fn of_periods(periods: f64) -> Self {
        const X_SHORT: f64 = 0.5;
        let x = if periods.is_finite() && periods > BAND_PERIODS {
            (X_SHORT * (BAND_PERIODS / periods).sqrt()).max(BAND_EXCESS_MIN)
        } else {
            X_SHORT
        };
        FloorBand {
            ratio: FLOOR_BAND * ((1.0 + x * x) / (1.0 + X_SHORT * X_SHORT)).sqrt(),
            excess: x,
            penalty: crate::explain::PARAM_PENALTY * (x / X_SHORT).powi(2),
        }
    }

    /// The share of the model error beyond the noise floor `noise` that a change from
    /// `e_base` to `e_with` removes ([`crate::explain::explained_fraction`] with this band's
    /// excess as the least there is to explain).
    pub fn explained(&self, e_base: f64, e_with: f64, noise: f64) -> f64 {
        crate::explain::explained_fraction_beyond(e_base, e_with, noise, self.excess)
    }
}

/// Longest held-back or fitted window of a stratum [s] before it is cut further: a steady
/// stretch is interleaved at least this finely.
pub const WINDOW_MAX_S: f64 = 0.5;
/// Longest window of an event's stratum (a start, a transient, a load move) [s]: an event
/// is interleaved finely, so that its fastest part (a start's acceleration) is in both
/// parts.
pub const EVENT_WINDOW_MAX_S: f64 = 0.08;
/// Largest number of samples a ladder's fit simulates (a longer log is fitted on a coarser
/// copy and measured on the working series). A third of explain's
/// ([`crate::MAX_FIT_SAMPLES`]): a round fits every candidate, a ladder has several rounds,
/// and a few parameters are fitted as well from 20 000 samples (a 10 s log at 2 kHz still
/// resolves the stator transient time constant, 3 samples or more of it: the dynamics
/// effects are refused on a series that does not, [`crate::transients::not_proposed`]).
pub const LADDER_FIT_SAMPLES: usize = 20_000;
/// Largest fit copy of a long log whose dynamics need more samples than
/// [`LADDER_FIT_SAMPLES`] ([`super::rung::fit_thinning`]): six times as many, a minute at
/// 2 kHz at the log's own rate, beyond which the copy is thinned to this size and the
/// dynamics effects are refused as unresolved. At 60 000 a 40 s log at 2 kHz of a 0.37 kW
/// machine (a 2.1 ms stator transient) was fitted at 1 kHz, its dynamics refused, and its
/// ladder stopped at 11x the floor with "nothing plausible helps", warming or not.
pub const LADDER_MAX_FIT_SAMPLES: usize = 120_000;
/// Iterations of a round's screening fit of every candidate (`round/`): enough to rank
/// them; the [`FINALISTS`] best are then fitted in full.
pub const SCREEN_ITER: usize = 6;
/// How many screened candidates of a round are fitted in full (plus the best by held-back
/// error alone when it is not among them).
pub const FINALISTS: usize = 3;
/// Pairs are tried only while the held-back error is above this multiple (2) of its noise
/// floor: two effects that need each other leave a large error alone (the windage
/// scenario's flux dynamics and load torque, 65x the floor without them); near the floor a
/// pair's test would weigh two effects' worth of parameters against a few per cent of noise,
/// and the round took 40 % of a ladder's time.
pub const PAIRS_ABOVE: f64 = 2.0;
/// The most the whole-log error may grow, as a multiple, when a base change is held at the
/// file's value and the change still be read as trading with an effect's law's shape
/// ([`super::LawShape`], `end.rs`): the change carries less than half of the error the
/// model has without it. On motulator's saturating 2.2 kW machine Rr -23 % grows the error
/// 1.6-1.8x when held off, with the saturation law's knee exponent at its bound; B + Bl,
/// the load's own viscous friction, grows it 34x (and there the law ran out too: the
/// saturation switched off to stand in for the friction).
pub const SHAPE_TRADE_MAX: f64 = 2.0;
/// How many single candidates the pair search pairs: those that lowered the training cost
/// most. With 3 the windage scenario's second step (flux dynamics with a load torque, the
/// fourth single of its round) is not found and the ladder stops at 65x its floor.
pub const PAIR_FROM: usize = 4;
/// Supply periods in the shortest window of a stratum (an event's stratum is cut into two
/// windows at least, each this long where the event allows).
pub const WINDOW_MIN_PERIODS: f64 = 2.0;
/// A refitted base parameter that differs from the file's by less than this (3 %) is not a
/// change the ladder names, whatever its interval.
pub const BASE_CHANGE_MIN: f64 = 0.03;

/// How much more error beyond the noise floor the one law may leave than the pair (and a
/// confusable partner than the chosen effect, `apart.rs`) and still be said to fit the log
/// as well (10 %: the pair's two parameters against the one law's two, on the same fit).
pub const AS_ONE_WITHIN: f64 = 0.10;

/// The library effects a base change may stand in for, with what tells the two apart
/// (`end.rs`, `Ladder::in_place`): a fan's torque `k w |w|` carried as viscous friction
/// `B + Bl` (a fan's log read B + Bl 20 times the file's, the inertia -9 % and the rotor
/// resistance beside it to bend `B w` into `k w²` over the start; windage in its place,
/// with B + Bl at the file's value, fitted the log better: 2.44x its floor against 3.09x).
pub const IN_PLACE_OF_BASE: [(BaseKey, EffectKind, ApartBy); 1] =
    [(BaseKey::B, EffectKind::Windage, ApartBy::SpeedRange)];

/// A change is [`super::report::Unsteady`] when its two halves' readings differ by more
/// than both halves' 95 % intervals together and by more than this share (one half) of the
/// change itself: on logs whose model is complete the halves agree within a few per cent
/// of the change (a warm stator's Rs +19.8 % and +18.6 %), while a change that carries a
/// law's shortfall moves with the operating point (the inertia of a fan's log read beside
/// viscous friction in place of the fan: -8 % on the half with the start, +9 % on the other).
pub const UNSTEADY_SHARE: f64 = 0.5;
