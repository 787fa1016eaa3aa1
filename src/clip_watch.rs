//! Whether clipping persists in steady running, in thread mode: the **range state**, the
//! front end's linear range too small for this motor.
//!
//! A clipped sample (a conversion at or beyond its channel's linear range,
//! `acquisition::sum_clipped`) is held out of the residuals and counted (`clip=`), and names
//! nothing: a direct-on-line start's inrush, five to seven times the running current for a
//! few hundred milliseconds, clips a current front end sized for the running current on
//! every start, and that is no fault of the sensor. Clipping that goes on while the motor
//! runs steadily is another matter: the readings the monitor needs are then beyond the
//! front end, every clipped block is held out, and the monitor cannot judge the motor.
//!
//! **The rule.** Thread mode's statuses are cut into windows of [`WINDOW_MS`] (2 s) of
//! samples. A window is **steady running** when the shaft turned one way throughout, at
//! least [`MIN_SPEED_RAD_S`] (10 rad/s, about 95 rpm), and its slowest status is within
//! [`STEADY_SPREAD`] (5 %) of its fastest: a start (the shaft accelerating from rest), a stop
//! and a stall are not steady; a running motor's load changes move its speed by its slip,
//! a few per cent. Clipping **persists** when more than [`CLIP_PERMILLE`] (1 %) of the
//! samples of [`WINDOWS`] (3) consecutive steady windows, 6 s of uninterrupted steady
//! running, are clipped: then the range state is set. It is cleared by as many consecutive
//! steady windows with at most [`CLEAR_PERMILLE`] (0.1 %) clipped; a window that is not
//! steady starts either count again and leaves the state as it is.
//!
//! Why these numbers: a sample is counted clipped with the 16 after it (the filter's
//! memory, `acquisition::ClipHold`), so one isolated clip counts 17 samples, 0.09 % of a
//! window: noise spikes stay below the clearing level. A front end whose range a steady
//! current's peaks exceed by as little as 1 % clips around every peak of every phase:
//! about a third of the samples, far above 1 %. A DOL start's inrush falls in a window
//! that is not steady (the shaft accelerates from rest through it), and the windows after
//! it hold no clip; a restart of a motor still turning (a short supply dip) clips one
//! window, not three. A motor stalled at high current is not running (below the speed
//! floor): its clips are counted, its blocks held out, and no range is judged.
//!
//! On the board (`app::Supervisor`) the range state sets the status line's `clip_range=`,
//! the panel's range mark (the RUN lamp steady from 7.5 s to 9.5 s of every 10 s,
//! `crate::panel`) and the verdict "could not judge" (the FAULT lamp dark, no sensor
//! named: `app::panel_call`); a change is logged with the front ends that clipped.

/// The length of a window [ms] (converted to samples at the sample rate).
pub const WINDOW_MS: u32 = 2_000;
/// Consecutive steady windows that set (or clear) the range state.
pub const WINDOWS: u8 = 3;
/// A steady window with more clipped samples than this, per mille of its samples, counts
/// towards the range state (1 %).
pub const CLIP_PERMILLE: u32 = 10;
/// A steady window with at most this many clipped samples, per mille, counts towards
/// clearing it (0.1 %).
pub const CLEAR_PERMILLE: u32 = 1;
/// The least shaft speed of steady running [rad/s] (about 95 rpm).
pub const MIN_SPEED_RAD_S: f32 = 10.0;
/// The largest spread of the shaft speed over a steady window, as a fraction of its
/// fastest status (5 %).
pub const STEADY_SPREAD: f32 = 0.05;

/// What the watch reads of one status (`app::MonitorStatus::clip_moment`).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct ClipMoment {
    /// Samples since boot (wrapping).
    pub samples: u32,
    /// Clipped samples since boot (wrapping): any front end.
    pub clipped: u32,
    /// Samples in which a voltage channel clipped (wrapping).
    pub clipped_voltage: u32,
    /// Samples in which a current channel clipped (wrapping).
    pub clipped_current: u32,
    /// The shaft's speed [rad/s].
    pub speed_rad_s: f32,
}

/// A change of the range state, for the log.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct RangeChange {
    /// The range state now: clipping persists in steady running.
    pub too_small: bool,
    /// The voltage front end clipped in the window that decided it.
    pub voltage: bool,
    /// The current front end clipped in the window that decided it.
    pub current: bool,
    /// The clipped samples of that window, per mille.
    pub permille: u32,
}

/// The window being measured: the counts at its start and the speed's extremes so far.
#[derive(Clone, Copy, Debug, PartialEq)]
struct Window {
    start: ClipMoment,
    slowest: f32,
    fastest: f32,
}

impl Window {
    /// A window that starts at `m`, its speed's extremes at `m`'s speed.
    fn starting_at(m: &ClipMoment) -> Self {
        Self {
            start: *m,
            slowest: m.speed_rad_s,
            fastest: m.speed_rad_s,
        }
    }

    /// Widens the speed's extremes by `speed` [rad/s]. NaN is neither: a speed that is
    /// not a number makes the window not steady ([`steady`]).
    fn track(&mut self, speed: f32) {
        self.slowest = if speed < self.slowest || speed.is_nan() {
            speed
        } else {
            self.slowest
        };
        self.fastest = if speed > self.fastest || speed.is_nan() {
            speed
        } else {
            self.fastest
        };
    }
}

/// The clip watch (module docs).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ClipWatch {
    window_samples: u32,
    window: Option<Window>,
    /// Consecutive steady windows over [`CLIP_PERMILLE`].
    over: u8,
    /// Consecutive steady windows at or under [`CLEAR_PERMILLE`].
    under: u8,
    too_small: bool,
}

impl ClipWatch {
    /// A watch at `sample_rate_hz` (windows of [`WINDOW_MS`] of samples).
    pub const fn new(sample_rate_hz: u32) -> Self {
        Self {
            window_samples: sample_rate_hz.saturating_mul(WINDOW_MS / 1_000),
            window: None,
            over: 0,
            under: 0,
            too_small: false,
        }
    }

    /// The range state: clipping persists in steady running (module docs).
    pub const fn too_small(&self) -> bool {
        self.too_small
    }

    /// Feeds one status; at the end of a window applies the rule and returns a change of
    /// the range state, if any.
    pub fn observe(&mut self, m: &ClipMoment) -> Option<RangeChange> {
        let Some(w) = &mut self.window else {
            self.window = Some(Window::starting_at(m));
            return None;
        };
        w.track(m.speed_rad_s);
        let samples = m.samples.wrapping_sub(w.start.samples);
        if samples < self.window_samples.max(1) {
            return None;
        }
        let w = *w;
        self.window = Some(Window::starting_at(m));
        let clipped = m.clipped.wrapping_sub(w.start.clipped);
        let permille_x = |n: u32| u64::from(n) * 1_000;
        let share = (permille_x(clipped) / u64::from(samples)) as u32;
        let over = permille_x(clipped) > u64::from(CLIP_PERMILLE) * u64::from(samples);
        let clean = permille_x(clipped) <= u64::from(CLEAR_PERMILLE) * u64::from(samples);
        let (over, clean) = if steady(w.slowest, w.fastest) {
            (over, clean)
        } else {
            (false, false)
        };
        self.over = if over { self.over.saturating_add(1) } else { 0 };
        self.under = if clean {
            self.under.saturating_add(1)
        } else {
            0
        };
        let now = if self.too_small {
            self.under < WINDOWS
        } else {
            self.over >= WINDOWS
        };
        if now == self.too_small {
            return None;
        }
        self.too_small = now;
        Some(RangeChange {
            too_small: now,
            voltage: m.clipped_voltage != w.start.clipped_voltage,
            current: m.clipped_current != w.start.clipped_current,
            permille: share,
        })
    }
}

/// Whether a window whose statuses' speeds lay within `slowest..=fastest` [rad/s] was steady
/// running: one way throughout, at least [`MIN_SPEED_RAD_S`], the spread within
/// [`STEADY_SPREAD`] of the fastest (by magnitude); `false` for speeds that are not numbers.
fn steady(slowest: f32, fastest: f32) -> bool {
    let (low, high) = if fastest <= 0.0 {
        (-fastest, -slowest)
    } else {
        (slowest, fastest)
    };
    low >= MIN_SPEED_RAD_S && high - low <= STEADY_SPREAD * high
}

#[cfg(test)]
mod tests {
    use super::*;

    const FS: u32 = 10_000;

    /// Feeds `seconds` of statuses every 50 ms (the board's thread-mode period, 500
    /// samples), `per_s` clipped samples a second spread over them (in the current front
    /// end), the speed `speed(t)`; the changes seen.
    fn run(
        watch: &mut ClipWatch,
        at: &mut ClipMoment,
        seconds: f32,
        per_s: u32,
        speed: impl Fn(f32) -> f32,
    ) -> Vec<RangeChange> {
        let mut changes = Vec::new();
        let ticks = (seconds * 20.0).round() as u32;
        for k in 0..ticks {
            let clipped = per_s * (k + 1) / 20 - per_s * k / 20;
            at.samples = at.samples.wrapping_add(500);
            at.clipped = at.clipped.wrapping_add(clipped);
            at.clipped_current = at.clipped_current.wrapping_add(clipped);
            at.speed_rad_s = speed(k as f32 / 20.0);
            changes.extend(watch.observe(at));
        }
        changes
    }

    #[test]
    fn clipping_that_persists_in_steady_running_sets_the_range_state_and_a_start_does_not() {
        let mut w = ClipWatch::new(FS);
        let mut at = ClipMoment {
            samples: u32::MAX - 3_000,
            ..ClipMoment::default()
        };
        // A start: 60 % clipped through the first 0.5 s while the shaft accelerates, none
        // after (10 s in all: five windows).
        let start = |t: f32| 150.0 * (t / 0.8).min(1.0);
        assert!(run(&mut w, &mut at, 0.5, 6_000, start).is_empty());
        assert!(run(&mut w, &mut at, 9.5, 0, |_| 150.0).is_empty());
        assert!(!w.too_small());
        // Steady running, 20 % clipped: set at the end of the third window clipped
        // throughout (6 s), with the front end that clipped.
        let changes = run(&mut w, &mut at, 5.9, 2_000, |_| 150.0);
        assert!(changes.is_empty(), "{changes:?}");
        let changes = run(&mut w, &mut at, 2.0, 2_000, |_| 150.0);
        assert_eq!(
            changes,
            [RangeChange {
                too_small: true,
                voltage: false,
                current: true,
                permille: 200
            }]
        );
        assert!(w.too_small());
        // A stop (not steady) leaves it; steady running clean for 6 s clears it.
        assert!(run(&mut w, &mut at, 4.0, 0, |t| 150.0 - 40.0 * t).is_empty());
        assert!(w.too_small());
        let changes = run(&mut w, &mut at, 8.0, 0, |_| -120.0);
        assert_eq!(changes.len(), 1);
        assert!(!changes[0].too_small && !w.too_small());
    }

    /// "More than 1 %": steady windows with 1 % of their samples clipped, 200 of 20 000,
    /// set nothing however long; 1.01 %, 202, sets the state at the end of the third.
    #[test]
    fn exactly_one_percent_clipped_sets_nothing_and_just_over_sets_it() {
        let mut w = ClipWatch::new(FS);
        let mut at = ClipMoment::default();
        assert!(run(&mut w, &mut at, 30.0, 100, |_| 150.0).is_empty());
        let changes = run(&mut w, &mut at, 8.0, 101, |_| 150.0);
        assert_eq!(changes.len(), 1, "{changes:?}");
        assert!(changes[0].too_small && w.too_small());
    }

    /// A motor slowing from 150 to 100 rad/s over 8 s, 12.5 rad/s a window (more than 8 %
    /// of its fastest status), is not running steadily, either way round: its clips set
    /// nothing.
    #[test]
    fn a_motor_slowing_down_is_not_steady_running() {
        for sign in [1.0, -1.0] {
            let mut w = ClipWatch::new(FS);
            let mut at = ClipMoment::default();
            let slowing = |t: f32| sign * (150.0 - 6.25 * t);
            assert!(run(&mut w, &mut at, 8.0, 2_000, slowing).is_empty());
            assert!(!w.too_small());
        }
    }

    /// "At most 0.1 %" counts towards clearing: steady windows of 20 999 samples with 21
    /// clipped (0.100 05 %) leave the range state set however many; windows of 20 000 with
    /// 20 clipped (0.1 %) clear it at the end of the third.
    #[test]
    fn at_most_a_tenth_of_a_percent_clipped_clears_the_range_state() {
        let mut w = ClipWatch::new(FS);
        let mut at = ClipMoment::default();
        assert_eq!(run(&mut w, &mut at, 8.0, 2_000, |_| 150.0).len(), 1);
        assert!(w.too_small());
        // One status a window: `samples` more, `clipped` of them clipped, still at 150 rad/s.
        let mut window = |samples: u32, clipped: u32| {
            at.samples += samples;
            at.clipped += clipped;
            at.clipped_current += clipped;
            w.observe(&at)
        };
        for _ in 0..6 {
            assert_eq!(window(20_999, 21), None);
        }
        assert_eq!(window(20_000, 20), None);
        assert_eq!(window(20_000, 20), None);
        let cleared = window(20_000, 20).expect("cleared at the third window");
        assert!(!cleared.too_small && cleared.permille == 1);
        assert!(!w.too_small());
    }

    #[test]
    fn isolated_clips_a_stall_and_an_interrupted_clip_set_nothing() {
        // A clip a second (17 samples with the hold: 0.085 %), steady: nothing.
        let mut w = ClipWatch::new(FS);
        let mut at = ClipMoment::default();
        assert!(run(&mut w, &mut at, 30.0, 17, |_| 150.0).is_empty());
        // A stalled rotor clipping every sample: not running, nothing.
        assert!(run(&mut w, &mut at, 30.0, 10_000, |_| 0.3).is_empty());
        // Clipping steadily, but the speed swinging by 10 %: not steady, nothing.
        let swing = |t: f32| 150.0 + 8.0 * (t * 3.0).sin();
        assert!(run(&mut w, &mut at, 30.0, 5_000, swing).is_empty());
        // Clipped steady running interrupted by a restart every 4 s: never three steady
        // windows clipped in a row.
        let mut w = ClipWatch::new(FS);
        let mut at = ClipMoment::default();
        for _ in 0..5 {
            assert!(run(&mut w, &mut at, 4.0, 5_000, |_| 150.0).is_empty());
            assert!(run(&mut w, &mut at, 2.0, 5_000, |t| 20.0 + 60.0 * t).is_empty());
        }
        assert!(!w.too_small());
        // The same without the restarts is set.
        assert_eq!(run(&mut w, &mut at, 8.0, 5_000, |_| 150.0).len(), 1);
        // A speed that is not a number is no steady running.
        assert!(!steady(f32::NAN, 150.0) && !steady(150.0, f32::NAN));
        assert!(steady(145.0, 150.0) && steady(-150.0, -145.0) && !steady(-150.0, 150.0));
    }
}
