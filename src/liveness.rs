//! Liveness of the sample path: noticing that samples stopped arriving, restarting the
//! acquisition, and petting the watchdog only while samples flow.
//!
//! Two watchers, one on each side of the sample path:
//! - [`AdcWait`] in the sample task: how long one wait for a trigger's ADC data may take,
//!   and what to do when it times out (restart the acquisition: trigger, both ADCs and
//!   their DMA rings, the timestamps). A wait never blocks the task for longer than
//!   [`AdcWait::timeout_us`].
//! - [`SampleWatch`] in thread mode: looks at the sample counter of the latest status every
//!   panel period. The watchdog is petted only when the counter advanced by at least half
//!   the samples the period should have brought; after [`STALL_AFTER_MS`] without that the
//!   panel shows "sampling stalled" and the firmware logs an error; after
//!   [`RECORD_STALL_AFTER_MS`] the firmware writes the reason into the reset record, so
//!   that the watchdog reset that follows if the restarts do not help is reported as a
//!   stalled sample path at the next boot. The independent watchdog resets the MCU
//!   [`crate::app::WATCHDOG_TIMEOUT_MS`] after the last pet.
//!
//! ```text
//!  samples flow ──► pet every period ──────────────────────────────────────────────────┐
//!  no samples ──► sample task: wait times out (2 ms) ─► restart acquisition, again and again│
//!             └─► thread: no pet; 100 ms: panel "stalled" + error; 300 ms: reset record ───┤
//!                 samples again ─► pet, panel normal, "recovered" ◄───────────────────────┘
//!                 still none at 500 ms after the last pet ─► watchdog reset ─► boot reports it
//! ```

/// A run is **up** once samples have flowed, with the watchdog petted, this long [ms]: its
/// failed boots in a row end (`crate::boot_block`, the safe mode's count).
pub const UP_AFTER_MS: u32 = 10_000;
/// A run is **long up** after this long [ms] (10 minutes): the next boot writes the reset
/// log's "up" mark, which gives the log's rate limit its full entries back.
pub const LONG_UP_AFTER_MS: u32 = 600_000;

/// Time without samples after which the sample path counts as stalled, ms.
pub const STALL_AFTER_MS: u32 = 100;
/// Time without samples after which the stall is written to the reset record, ms (before
/// the watchdog's 500 ms).
pub const RECORD_STALL_AFTER_MS: u32 = 300;
/// Time after boot during which no samples at all is not yet a stall (the sample task
/// starts its acquisition), ms.
pub const STARTUP_GRACE_MS: u32 = 200;
/// Sample periods one wait for ADC data may take before the acquisition is restarted.
pub const ADC_WAIT_PERIODS: u32 = 20;
/// Shortest wait for ADC data, us (the restart itself takes about 20 us).
pub const ADC_WAIT_MIN_US: u32 = 1_000;

/// The sample task's wait for ADC data: its timeout and the restarts after timeouts.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct AdcWait {
    timeout_us: u32,
    consecutive: u32,
    restarts: u32,
}

/// What the sample task does after a wait for ADC data timed out: restart the acquisition.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Restart {
    /// Restarts since data last arrived, this one included (1 = the first).
    pub attempt: u32,
    /// Log this one (the first of a stall and every 100th after it, so a long stall does
    /// not flood the log).
    pub log: bool,
}

impl AdcWait {
    /// The wait for `sample_rate_hz` (> 0): [`ADC_WAIT_PERIODS`] sample periods, at least
    /// [`ADC_WAIT_MIN_US`] (2 ms at 10 kHz).
    pub fn new(sample_rate_hz: u32) -> Self {
        let period_us = 1_000_000 / sample_rate_hz.max(1);
        Self {
            timeout_us: (ADC_WAIT_PERIODS * period_us).max(ADC_WAIT_MIN_US),
            consecutive: 0,
            restarts: 0,
        }
    }

    /// Longest wait for one sample's data, us.
    pub fn timeout_us(&self) -> u32 {
        self.timeout_us
    }

    /// A wait timed out: the acquisition is to be restarted.
    pub fn timed_out(&mut self) -> Restart {
        self.consecutive = self.consecutive.saturating_add(1);
        self.restarts = self.restarts.saturating_add(1);
        Restart {
            attempt: self.consecutive,
            log: self.consecutive % 100 == 1,
        }
    }

    /// Data arrived. Returns the number of restarts it took when this ends a stall.
    pub fn data(&mut self) -> Option<u32> {
        let n = core::mem::take(&mut self.consecutive);
        (n > 0).then_some(n)
    }

    /// Restarts since boot.
    pub fn restarts(&self) -> u32 {
        self.restarts
    }
}

/// What [`SampleWatch::poll`] decided.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Watch {
    /// Pet the watchdog now: samples flow (or the acquisition is still starting).
    pub pet_watchdog: bool,
    /// The sample path is stalled: the latest status is stale.
    pub stalled: bool,
    /// What changed at this poll, to log or record.
    pub change: Option<LivenessChange>,
}

/// A change of the sample path's liveness.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum LivenessChange {
    /// No samples for [`STALL_AFTER_MS`]: log an error.
    Stalled {
        /// Time since samples last arrived, ms.
        for_ms: u32,
    },
    /// Still none after [`RECORD_STALL_AFTER_MS`]: write the reset record.
    RecordStall {
        /// Time since samples last arrived, ms.
        for_ms: u32,
    },
    /// Samples arrive again after a stall: log it and clear the reset record.
    Recovered {
        /// How long the stall lasted, ms.
        after_ms: u32,
    },
}

/// Thread mode's watch on the sample counter.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct SampleWatch {
    sample_rate_hz: u32,
    boot_ms: u32,
    seen_samples: bool,
    last_count: u32,
    last_poll_ms: u32,
    last_advance_ms: u32,
    stalled: bool,
    recorded: bool,
}

impl SampleWatch {
    /// A watch for samples at `sample_rate_hz`, started at `now_ms`.
    pub fn new(sample_rate_hz: u32, now_ms: u32) -> Self {
        Self {
            sample_rate_hz,
            boot_ms: now_ms,
            seen_samples: false,
            last_count: 0,
            last_poll_ms: now_ms,
            last_advance_ms: now_ms,
            stalled: false,
            recorded: false,
        }
    }

    /// Looks at the sample counter `count` (wrapping) at `now_ms` (wrapping ms clock).
    pub fn poll(&mut self, count: u32, now_ms: u32) -> Watch {
        let dt_ms = now_ms.wrapping_sub(self.last_poll_ms);
        let advanced = count.wrapping_sub(self.last_count);
        // Half of what the period should have brought (at least one sample).
        let needed = ((u64::from(self.sample_rate_hz) * u64::from(dt_ms) / 2000) as u32).max(1);
        let flowing = advanced >= needed;
        self.last_poll_ms = now_ms;
        self.last_count = count;
        if flowing {
            self.seen_samples = true;
        }
        let starting = !self.seen_samples && now_ms.wrapping_sub(self.boot_ms) < STARTUP_GRACE_MS;
        if flowing || starting {
            let change = self.stalled.then(|| LivenessChange::Recovered {
                after_ms: now_ms.wrapping_sub(self.last_advance_ms),
            });
            self.last_advance_ms = now_ms;
            self.stalled = false;
            self.recorded = false;
            return Watch {
                pet_watchdog: true,
                stalled: false,
                change,
            };
        }
        let for_ms = now_ms.wrapping_sub(self.last_advance_ms);
        let mut change = None;
        if !self.stalled && for_ms >= STALL_AFTER_MS {
            self.stalled = true;
            change = Some(LivenessChange::Stalled { for_ms });
        } else if self.stalled && !self.recorded && for_ms >= RECORD_STALL_AFTER_MS {
            self.recorded = true;
            change = Some(LivenessChange::RecordStall { for_ms });
        }
        Watch {
            pet_watchdog: false,
            stalled: self.stalled,
            change,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn adc_wait_restarts_and_logs_sparingly() {
        let mut w = AdcWait::new(10_000);
        assert_eq!(w.timeout_us(), 2_000);
        assert_eq!(AdcWait::new(50_000).timeout_us(), ADC_WAIT_MIN_US);
        assert_eq!(w.data(), None);
        let logged: Vec<u32> = (0..250)
            .map(|_| w.timed_out())
            .filter(|r| r.log)
            .map(|r| r.attempt)
            .collect();
        assert_eq!(logged, [1, 101, 201]);
        assert_eq!(w.data(), Some(250));
        assert_eq!(w.data(), None);
        assert_eq!(w.timed_out().attempt, 1);
        assert_eq!(w.restarts(), 251);
    }

    #[test]
    fn the_watchdog_is_petted_only_while_samples_flow() {
        let mut w = SampleWatch::new(10_000, 0);
        // Starting: no samples yet, within the grace time.
        assert!(w.poll(0, 50).pet_watchdog);
        let mut count = 0u32;
        let mut t = 50;
        for _ in 0..10 {
            t += 50;
            count = count.wrapping_add(500);
            let p = w.poll(count, t);
            assert!(p.pet_watchdog && !p.stalled && p.change.is_none());
        }
        // A trickle (a tenth of the rate) is not flowing.
        t += 50;
        count += 50;
        assert!(!w.poll(count, t).pet_watchdog);
        // Stopped: stalled after 100 ms, recorded after 300 ms.
        let mut changes = Vec::new();
        for _ in 0..8 {
            t += 50;
            let p = w.poll(count, t);
            assert!(!p.pet_watchdog);
            changes.extend(p.change);
        }
        assert_eq!(
            changes,
            [
                LivenessChange::Stalled { for_ms: 100 },
                LivenessChange::RecordStall { for_ms: 300 }
            ]
        );
        t += 50;
        count = count.wrapping_add(500);
        let p = w.poll(count, t);
        assert!(p.pet_watchdog && !p.stalled);
        assert_eq!(p.change, Some(LivenessChange::Recovered { after_ms: 500 }));
    }

    #[test]
    fn no_samples_after_the_grace_time_is_a_stall_and_the_counter_may_wrap() {
        let mut w = SampleWatch::new(10_000, 1_000);
        let p = w.poll(0, 1_300);
        assert!(!p.pet_watchdog);
        assert_eq!(p.change, Some(LivenessChange::Stalled { for_ms: 300 }));
        let mut w = SampleWatch::new(10_000, u32::MAX - 20);
        assert!(w.poll(u32::MAX - 10, u32::MAX).pet_watchdog);
        assert!(w.poll(600, 40).pet_watchdog, "counter and clock wrapped");
    }

    /// The start-up grace is [`STARTUP_GRACE_MS`] from boot and no more: with no sample
    /// yet, the watchdog is petted at 199 ms and not at 200 ms.
    #[test]
    fn the_start_up_grace_ends_at_200_ms() {
        let mut w = SampleWatch::new(10_000, 5_000);
        assert!(w.poll(0, 5_199).pet_watchdog);
        assert!(!w.poll(0, 5_200).pet_watchdog);
    }
}
