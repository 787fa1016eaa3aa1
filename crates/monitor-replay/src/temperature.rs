//! The log's temperature channel (`t_winding_c`) in the isolation: the winding's rise
//! since commissioning measured instead of inferred from the resistances
//! ([`monitor_core::isolation::Follower::set_measured_rise_k`]; the residuals correct only
//! the probe's lag, within [`monitor_core::isolation::PROBE_LAG_K`]), while the channel is
//! plausible.
//!
//! The commissioned temperature is the mean of the channel's readings over the
//! commissioning window; after it the rise is `reading - commissioned`, so only the rise
//! matters: a probe on the stator frame that reads a constant below the winding gives the
//! same rise. A channel is not used (and says why, once, for the rest of the log; the
//! isolation then tracks the heating from the resistances, from the factor last in force)
//! when:
//! - it gave no reading inside -40..250 degC ([`PLAUSIBLE_C`]) for [`GAP_S`] (NaN, empty,
//!   beyond the range: a broken thermocouple reads an open circuit), or none during
//!   commissioning;
//! - it jumped by more than a winding can heat in that time: [`MAX_HEATING_K_PER_S`] times
//!   the time between the readings, plus [`JUMP_SLACK_K`];
//! - it stayed at one value for [`STUCK_S`] (a converter that stopped: a real probe's
//!   noise moves the last digit);
//! - the resistances disagree with it: the isolation, with the measured rise in force,
//!   finds that heating alone explains a deviation of more than [`DISAGREE_K`] for
//!   [`DISAGREE_S`] (a probe that lost contact with the winding, a reading frozen
//!   inside the noise).

use monitor_core::isolation::{Follower, COPPER_ALPHA_PER_K};
use monitor_core::Isolation;
use serde::Serialize;

/// What `diagnose` reports of the temperature channel (keys of `isolation`; every field
/// absent, JSON, for a log without the column).
#[derive(Debug, Clone, Default, Serialize, PartialEq)]
pub struct TemperatureReport {
    /// The channel's last plausible reading [degC] (the winding's or the frame's, as the
    /// log's probe sits).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub winding_temperature_c: Option<f32>,
    /// The rise since commissioning the channel measured [K] (its reading minus the mean
    /// over the commissioning window), while it is used: Rs and Rr are compensated with it
    /// (`1 + 0.00393 rise`) instead of tracked from the residuals.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub measured_rise_k: Option<f32>,
    /// Whether the channel is used, or why not (JSON `temperature_channel_state`; the door
    /// spells it as `temperature_channel`: `used`, or `not used: <why>`; the isolation then
    /// tracks the heating from the resistances).
    #[serde(
        rename = "temperature_channel_state",
        skip_serializing_if = "Option::is_none"
    )]
    pub temperature_channel: Option<ChannelUse>,
}

/// Whether the log's temperature channel is used (JSON `{"kind": ..}`).
#[derive(Debug, Clone, Copy, Serialize, PartialEq)]
#[serde(tag = "kind", rename_all = "snake_case")]
pub enum ChannelUse {
    /// Used: Rs and Rr are compensated with its rise.
    Used,
    /// Not used, and why.
    NotUsed {
        /// Why.
        why: ChannelDropped,
    },
}

/// Why the temperature channel is not used (JSON `{"kind": ..}` with its numbers).
#[derive(Debug, Clone, Copy, Serialize, PartialEq)]
#[serde(tag = "kind", rename_all = "snake_case")]
pub enum ChannelDropped {
    /// No plausible reading (inside [`PLAUSIBLE_C`]) for [`GAP_S`] from `since_s`.
    NoReading {
        /// The last plausible reading's time [s].
        since_s: f64,
    },
    /// No plausible reading while commissioning learned.
    NoneWhileCommissioning,
    /// One value for [`STUCK_S`] from `since_s`.
    Stuck {
        /// The value [degC].
        value_c: f64,
        /// Since when [s].
        since_s: f64,
    },
    /// A jump faster than a winding heats ([`MAX_HEATING_K_PER_S`]).
    Jumped {
        /// The reading before [degC].
        from_c: f64,
        /// The reading after [degC].
        to_c: f64,
        /// Between the two [s].
        dt_s: f64,
        /// When [s].
        at_s: f64,
    },
    /// The resistances disagree with the channel by more than [`DISAGREE_K`].
    Disagrees {
        /// The resistances' winding minus the channel's reading [K].
        off_k: f32,
        /// Since when [s].
        since_s: f64,
    },
    /// A rise the core refuses (beyond what a winding reaches in service).
    BeyondService {
        /// The rise [K].
        rise_k: f32,
    },
    /// No commissioning: the rise counts from the temperature commissioning saw.
    NoCommissioning,
}

/// The plausible range of a winding or frame temperature [degC]: from an unheated machine
/// at -40 degC to 250 degC, beyond every insulation class's hot spot (H: 180 degC).
pub const PLAUSIBLE_C: (f64, f64) = (-40.0, 250.0);
/// Longest time without a plausible reading before the channel is not used [s]; shorter
/// gaps hold the last reading.
pub const GAP_S: f64 = 10.0;
/// Fastest heating of a winding [K/s]: a copper winding heats adiabatically by
/// `J^2 rho / (c d)`, 4.4 K/s at a locked rotor's 30 A/mm^2 (six times a rated 5 A/mm^2;
/// rho 1.7e-8 ohm m, c d 3.45e6 J/(m^3 K)); twice that for margin.
pub const MAX_HEATING_K_PER_S: f64 = 10.0;
/// A reading's noise and resolution allowed beside [`MAX_HEATING_K_PER_S`] [K].
pub const JUMP_SLACK_K: f64 = 5.0;
/// How long one unchanged value makes the channel stuck [s].
pub const STUCK_S: f64 = 30.0;
/// A disagreement between the channel and the resistances larger than this is not the
/// probe's lag [K] (a thermocouple's few seconds behind a winding warming by 3 K/s: 10 K).
pub const DISAGREE_K: f32 = 20.0;
/// How long the disagreement must last [s] (the isolation's averaging and confirmation).
pub const DISAGREE_S: f64 = 3.0;

/// The channel's state over a replay.
#[derive(Debug, Clone, Default, PartialEq)]
pub(super) struct TemperatureChannel {
    /// The log has the column.
    present: bool,
    /// Sum and count of the plausible readings while commissioning learned.
    learn_sum: f64,
    learn_n: u64,
    /// The mean reading of commissioning [degC], once it ended.
    commissioned_c: Option<f64>,
    /// The last plausible reading: time [s] and value [degC].
    last: Option<(f64, f64)>,
    /// When the reading last changed value [s].
    changed_at_s: f64,
    /// Since when the resistances disagree with the channel [s].
    disagree_since_s: Option<f64>,
    /// Why the channel is not used (from then on).
    not_used: Option<ChannelDropped>,
    /// When the first reading came [s] (the gap counts from it).
    first_s: Option<f64>,
}

/// Whether `x` is a plausible temperature ([`PLAUSIBLE_C`]).
fn plausible(x: f64) -> bool {
    x.is_finite() && (PLAUSIBLE_C.0..=PLAUSIBLE_C.1).contains(&x)
}

impl TemperatureChannel {
    /// The channel of a log with (`present`) or without the column.
    pub fn new(present: bool) -> Self {
        TemperatureChannel {
            present,
            ..Default::default()
        }
    }

    /// The log has the column.
    #[inline]
    pub fn present(&self) -> bool {
        self.present
    }

    /// The reading at `t` [s] (`None`: the log has no column); `learning`: commissioning
    /// learns now; `learned`: a learned baseline is in force. Returns the measured rise
    /// since commissioning to put in force [K], `None` when the channel is not (or not yet)
    /// used.
    pub fn observe(
        &mut self,
        t: f64,
        reading: Option<f64>,
        learning: bool,
        learned: bool,
    ) -> Option<f32> {
        if !self.present || self.not_used.is_some() {
            return None;
        }
        let first = *self.first_s.get_or_insert(t);
        let x = reading.filter(|x| plausible(*x));
        if let Some(x) = x {
            self.check_jump(t, x);
            if self.last.is_none_or(|(_, v)| v != x) {
                self.changed_at_s = t;
            }
            self.last = Some((t, x));
            if learning {
                self.learn_sum += x;
                self.learn_n += 1;
            }
        }
        let since = self.last.map_or(first, |(s, _)| s);
        if t - since > GAP_S {
            self.drop_channel(ChannelDropped::NoReading { since_s: since });
        }
        if learned && !learning && self.commissioned_c.is_none() {
            if self.learn_n == 0 {
                self.drop_channel(ChannelDropped::NoneWhileCommissioning);
            }
            self.commissioned_c = Some(self.learn_sum / self.learn_n.max(1) as f64);
        }
        if learned && t - self.changed_at_s > STUCK_S {
            let v = self.last.map_or(f64::NAN, |l| l.1);
            self.drop_channel(ChannelDropped::Stuck {
                value_c: v,
                since_s: self.changed_at_s,
            });
        }
        if self.not_used.is_some() || !learned {
            return None;
        }
        let (_, now) = self.last?;
        Some((now - self.commissioned_c?) as f32)
    }

    /// A plausible reading `x` at `t` against the last one: more than a winding can heat
    /// in between drops the channel.
    fn check_jump(&mut self, t: f64, x: f64) {
        let Some((t0, x0)) = self.last else {
            return;
        };
        let allowed = MAX_HEATING_K_PER_S * (t - t0) + JUMP_SLACK_K;
        if (x - x0).abs() > allowed {
            self.drop_channel(ChannelDropped::Jumped {
                from_c: x0,
                to_c: x,
                dt_s: t - t0,
                at_s: t,
            });
        }
    }

    /// After an isolation at `t` made with the channel's rise in force, corrected by the
    /// residuals for the probe's lag `lag_k` [K] (`None`: no measured rise in force): the
    /// resistances' own heating fit against the channel ([`DISAGREE_K`], [`DISAGREE_S`]).
    pub fn after_isolation(&mut self, t: f64, iso: &Isolation, lag_k: Option<f32>) {
        let Some(lag_k) = lag_k.filter(|_| self.not_used.is_none()) else {
            self.disagree_since_s = None;
            return;
        };
        // (The heating fit is relative to the machine judged against: the measured one
        // with its lag correction.)
        let off_k = lag_k + (iso.heating.factor - 1.0) / COPPER_ALPHA_PER_K;
        if iso.heating_explains() && off_k.abs() > DISAGREE_K {
            let since = *self.disagree_since_s.get_or_insert(t);
            if t - since >= DISAGREE_S {
                self.drop_channel(ChannelDropped::Disagrees {
                    off_k,
                    since_s: since,
                });
            }
        } else {
            self.disagree_since_s = None;
        }
    }

    /// Reads `reading` at `t` ([`TemperatureChannel::observe`]) and puts the measured rise
    /// in force in `follower` (none: the follower tracks from the resistances); a rise the
    /// core refuses (beyond 25 K cooler .. 160 K warmer) drops the channel.
    pub fn put_in_force(
        &mut self,
        follower: &mut Follower,
        t: f64,
        reading: Option<f64>,
        learning: bool,
    ) {
        if !self.present {
            return;
        }
        let rise = self.observe(t, reading, learning, follower.learned());
        if !follower.set_measured_rise_k(rise) {
            self.drop_channel(ChannelDropped::BeyondService {
                rise_k: rise.unwrap_or(f32::NAN),
            });
            follower.set_measured_rise_k(None);
        }
    }

    /// The report's fields.
    pub fn report(&self) -> TemperatureReport {
        if !self.present {
            return TemperatureReport::default();
        }
        TemperatureReport {
            winding_temperature_c: self.last_c().map(|x| x as f32),
            measured_rise_k: self.rise_k().map(|x| x as f32),
            temperature_channel: Some(match self.not_used() {
                Some(why) => ChannelUse::NotUsed { why },
                None if self.commissioned_c.is_none() => ChannelUse::NotUsed {
                    why: ChannelDropped::NoCommissioning,
                },
                None => ChannelUse::Used,
            }),
        }
    }

    fn drop_channel(&mut self, why: ChannelDropped) {
        self.not_used.get_or_insert(why);
    }

    /// Why the channel is not used, if it is not.
    pub fn not_used(&self) -> Option<ChannelDropped> {
        self.not_used
    }

    /// The last plausible reading [degC].
    pub fn last_c(&self) -> Option<f64> {
        self.last.map(|l| l.1)
    }

    /// The measured rise since commissioning [K] at the last plausible reading, while the
    /// channel is used.
    pub fn rise_k(&self) -> Option<f64> {
        if self.not_used.is_some() {
            return None;
        }
        Some(self.last_c()? - self.commissioned_c?)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Feeds `f(t)` at 100 Hz from 0 to `end_s`, commissioning over 1..3 s.
    fn run(end_s: f64, f: impl Fn(f64) -> f64) -> TemperatureChannel {
        let mut c = TemperatureChannel::new(true);
        for k in 0..(end_s * 100.0) as usize {
            let t = k as f64 * 0.01;
            let learning = (1.0..3.0).contains(&t);
            c.observe(t, Some(f(t)), learning, t >= 3.0);
        }
        c
    }

    /// A plausible warming (1 K/s with 0.1 K steps of noise) is used, its rise counted
    /// from the commissioned mean; NaN, a jump, a value stuck and one out of range are not.
    #[test]
    fn plausible_channels_are_used_and_liars_are_named() {
        let noise = |t: f64| 0.1 * ((t * 37.0).sin() * 3.0).round();
        let warm = run(40.0, |t| 20.0 + (t - 3.0).max(0.0) + noise(t));
        assert_eq!(warm.not_used(), None);
        let rise = warm.rise_k().unwrap();
        assert!((rise - 37.0).abs() < 0.5, "{rise}");
        let nan = run(40.0, |t| if t > 10.0 { f64::NAN } else { 20.0 + noise(t) });
        assert!(
            matches!(nan.not_used(), Some(ChannelDropped::NoReading { since_s }) if (since_s - 10.0).abs() < 0.05),
            "{nan:?}"
        );
        let jump = run(40.0, |t| {
            20.0 + noise(t) + if t > 10.0 { 60.0 } else { 0.0 }
        });
        assert!(
            matches!(jump.not_used(), Some(ChannelDropped::Jumped { to_c, .. }) if to_c > 75.0),
            "{jump:?}"
        );
        let stuck = run(60.0, |t| if t > 10.0 { 21.0 } else { 20.0 + noise(t) });
        assert!(
            matches!(stuck.not_used(), Some(ChannelDropped::Stuck { value_c, .. }) if value_c == 21.0),
            "{stuck:?}"
        );
        let hot = run(40.0, |t| if t > 10.0 { 400.0 } else { 20.0 + noise(t) });
        assert!(hot.not_used().is_some(), "{hot:?}");
        // A log without the column: nothing, and nothing to say.
        let mut none = TemperatureChannel::new(false);
        assert_eq!(none.observe(5.0, None, false, true), None);
        assert_eq!(none.not_used(), None);
    }
}
