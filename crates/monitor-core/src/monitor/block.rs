//! What the monitor keeps per block: the fast path's accumulators (extremes for the
//! plausibility check, sums of the d-q quantities), the block-rate filters and checks, the
//! sensor-fault hold, and the values derived once from the configuration.

use super::{MonitorConfig, Sample, SensorFlags, SensorLimits};
use crate::error::ConfigError;
use crate::filter::{LowPass, LowPassState, Svf, SvfState};
use crate::frames::Dq;
use crate::residuals::{Derivatives, Operating};
use crate::sequence::Complex32;
use core::f32::consts::TAU;

/// Values derived once from the configuration (the per-sample state is apart, in
/// [`super::Monitor`]). A block is `decimation` samples; times are in blocks.
#[derive(Debug, Clone, Copy)]
pub(super) struct Derived {
    /// Sample period `1 / sample_rate_hz` [s].
    pub(super) dt_s: f32,
    /// Block period `decimation / sample_rate_hz` (as `dt_s x decimation`) [s].
    pub(super) block_dt_s: f32,
    /// Blocks per second, `sample_rate_hz / decimation` [Hz].
    pub(super) block_rate_hz: f32,
    /// Pole pairs: electrical speed per mechanical speed.
    pub(super) np: f32,
    /// `limits.v_max` and `limits.i_max` as bit patterns: a reading's |value| whose bits
    /// are above them is out of range (NaN and infinity too).
    pub(super) v_max_bits: u32,
    /// See `v_max_bits`.
    pub(super) i_max_bits: u32,
    /// `(min_voltage_frac v_phase_peak)^2` [V^2]: the running threshold of |V|^2.
    pub(super) v_run_min2: f32,
    /// `settle_s` in blocks.
    pub(super) settle_blocks: u32,
    /// How long a sensor fault is held: one second in blocks.
    pub(super) hold_blocks: u32,
    /// Blocks between two negative-sequence results (ten a second), >= 1.
    pub(super) report_every: u16,
    /// `gate_hold_s` in blocks.
    pub(super) gate_blocks: u32,
    /// `gate_timeout_s` in blocks.
    pub(super) gate_timeout_blocks: u32,
    /// The floors of the gate's relative rates: the no-load magnetising current [A] (for
    /// I_qs and i_ds), 10 % of the nominal voltage [V] and 10 % of the synchronous speed
    /// [rad/s].
    pub(super) gate_floor_a: f32,
    /// See `gate_floor_a`.
    pub(super) gate_floor_v: f32,
    /// See `gate_floor_a`.
    pub(super) gate_floor_rad_s: f32,
    /// Block lengths in ticks accepted as on time: `block_ticks_lo..=block_ticks_lo +
    /// block_ticks_span` (half a sample period either side of `decimation` periods).
    pub(super) block_ticks_lo: u32,
    /// See `block_ticks_lo`.
    pub(super) block_ticks_span: u32,
    /// Expected ticks per block.
    pub(super) block_ticks: u32,
    /// The longest block (with a gap inside) that is bridged, in ticks.
    pub(super) max_gap_ticks: u32,
}

/// The no-load operating point of the nominal machine on the nominal supply: no torque
/// current, the magnetising current `v_phase_peak / (2 pi supply_hz Ls)`, the nominal
/// voltage and the synchronous electrical speed.
pub(super) fn no_load_reference(cfg: &MonitorConfig) -> Operating {
    Operating {
        iqs: 0.0,
        i_f: cfg.v_phase_peak / (TAU * cfg.supply_hz * cfg.motor.ls_h),
        vqs: cfg.v_phase_peak,
        wr_rad_s: TAU * cfg.supply_hz,
    }
}

impl Derived {
    /// The values for a validated `cfg`.
    pub(super) fn new(cfg: &MonitorConfig) -> Self {
        let dt = 1.0 / cfg.sample_rate_hz;
        let dec = f32::from(cfg.decimation);
        let slow_dt = dt * dec;
        let slow_hz = cfg.sample_rate_hz / dec;
        let v_run_min = cfg.min_voltage_frac * cfg.v_phase_peak;
        Derived {
            dt_s: dt,
            block_dt_s: slow_dt,
            block_rate_hz: slow_hz,
            np: cfg.motor.np(),
            v_max_bits: cfg.limits.v_max.to_bits(),
            i_max_bits: cfg.limits.i_max.to_bits(),
            v_run_min2: v_run_min * v_run_min,
            settle_blocks: (cfg.settle_s * slow_hz) as u32,
            hold_blocks: slow_hz as u32,
            report_every: ((0.1 * slow_hz) as u16).max(1),
            gate_blocks: (cfg.gate_hold_s * slow_hz) as u32,
            gate_timeout_blocks: (cfg.gate_timeout_s * slow_hz) as u32,
            gate_floor_a: no_load_reference(cfg).i_f,
            gate_floor_v: 0.1 * cfg.v_phase_peak,
            gate_floor_rad_s: 0.1 * TAU * cfg.supply_hz,
            block_ticks_lo: (cfg.tick_hz * dt * (dec - 0.5)) as u32,
            block_ticks_span: (cfg.tick_hz * dt) as u32,
            block_ticks: (cfg.tick_hz * slow_dt + 0.5) as u32,
            max_gap_ticks: (cfg.tick_hz * (slow_dt + cfg.max_bridged_gap_s)) as u32,
        }
    }
}

/// The extremes of a block's readings and its ADC saturation flags, for the plausibility
/// check at the block's end (one check per block instead of one per sample).
#[derive(Debug, Clone, Copy, Default)]
pub(super) struct BlockExtremes {
    /// Bit 0: a current channel saturated; bit 1: a voltage channel; bit 2: a reading
    /// clipped ([`Sample::clipped`]: held out, no sensor named).
    saturated: u8,
    /// The largest |phase voltage| as bit pattern (the sign bit cleared).
    v_bits: u32,
    /// The largest |phase current| as bit pattern.
    i_bits: u32,
}

impl BlockExtremes {
    /// Adds one sample's readings.
    #[inline(always)]
    pub(super) fn add(&mut self, s: &Sample) {
        self.saturated |=
            u8::from(s.i_saturated) | (u8::from(s.v_saturated) << 1) | (u8::from(s.clipped) << 2);
        let m = 0x7fff_ffffu32;
        let vb = (s.v_abc.a.to_bits() & m)
            .max(s.v_abc.b.to_bits() & m)
            .max(s.v_abc.c.to_bits() & m);
        let ib = (s.i_abc.a.to_bits() & m)
            .max(s.i_abc.b.to_bits() & m)
            .max(s.i_abc.c.to_bits() & m);
        self.v_bits = self.v_bits.max(vb);
        self.i_bits = self.i_bits.max(ib);
    }

    /// Ends the block: the sensors whose readings were impossible (saturated, out of range,
    /// not finite) against the limits as bit patterns ([`Derived::v_max_bits`]), whether a
    /// reading was clipped (the block held out, no sensor named), and the extremes cleared
    /// for the next block.
    #[inline(always)]
    pub(super) fn take_verdict(&mut self, k: &Derived) -> (SensorFlags, bool) {
        let bad = SensorFlags {
            current: (self.saturated & 1 != 0) | (self.i_bits > k.i_max_bits),
            voltage: (self.saturated & 2 != 0) | (self.v_bits > k.v_max_bits),
            speed: false,
        };
        let clipped = self.saturated & 4 != 0;
        *self = BlockExtremes::default();
        (bad, clipped)
    }
}

/// The means of a block's d-q quantities.
#[derive(Debug, Clone, Copy)]
pub(super) struct BlockMeans {
    /// Stator current in the frame, (i_ds, I_qs) [A].
    pub(super) i: Dq,
    /// Stator voltage V_qs [V].
    pub(super) v_q: f32,
    /// The current in the frame turning backwards (the negative sequence's) [A].
    pub(super) n: Dq,
}

/// The fast path's block accumulator: sums of the d-q quantities over the block.
#[derive(Debug, Clone, Copy, Default)]
pub(super) struct BlockSums {
    i_d: f32,
    i_q: f32,
    v_q: f32,
    n_d: f32,
    n_q: f32,
    /// Samples summed.
    len: u16,
}

impl BlockSums {
    /// Adds one sample: the current `i` and the voltage's q component in the frame, the
    /// current `n` in the frame turning backwards.
    #[inline(always)]
    pub(super) fn add(&mut self, i: Dq, v_q: f32, n: Dq) {
        self.i_d += i.d;
        self.i_q += i.q;
        self.v_q += v_q;
        self.n_d += n.d;
        self.n_q += n.q;
        self.len += 1;
    }

    /// Samples summed so far.
    #[inline(always)]
    pub(super) fn len(&self) -> u16 {
        self.len
    }

    /// Forgets the block.
    pub(super) fn clear(&mut self) {
        *self = BlockSums::default();
    }

    /// The block's means, and the sums cleared for the next block.
    #[inline(always)]
    pub(super) fn take_means(&mut self) -> BlockMeans {
        let k = 1.0 / f32::from(self.len.max(1));
        let a = *self;
        self.clear();
        BlockMeans {
            i: Dq {
                d: a.i_d * k,
                q: a.i_q * k,
            },
            v_q: a.v_q * k,
            n: Dq {
                d: a.n_d * k,
                q: a.n_q * k,
            },
        }
    }
}

/// The block-rate filters of the d-q quantities: the model's inputs (with derivatives),
/// the negative-sequence current and V_ds. Three configurations (the model's corner, the
/// sequences' corner, V_ds's low-pass) and one state per signal.
#[derive(Debug, Clone, Copy)]
pub(super) struct DqFilters {
    /// The model inputs' filter at `filter_hz`.
    dq: Svf,
    /// The negative sequences' filter at `sequence_hz`.
    seq: Svf,
    /// V_ds's low-pass at `filter_hz`.
    lp: LowPass,
    /// I_qs [A].
    iqs: SvfState,
    /// i_ds [A].
    ids: SvfState,
    /// V_qs [V].
    vqs: SvfState,
    /// The electrical rotor speed [rad/s].
    wr: SvfState,
    /// The negative sequence's d component [A].
    nd: SvfState,
    /// The negative sequence's q component [A].
    nq: SvfState,
    /// The voltage's negative sequence, d and q (each block's last sample) [V]: the
    /// supply's own unbalance, taken out before a winding is named.
    vnd: SvfState,
    vnq: SvfState,
    /// V_ds of each block's last sample [V].
    vds: LowPassState,
    /// The model inputs' slow trend, for the quasi-steady gate ([`Trend`]).
    trend: Trend,
}

impl DqFilters {
    /// The filters at `filter_hz` (the negative sequence's at `sequence_hz`), fed every
    /// `block_dt_s`.
    ///
    /// # Errors
    /// The filters' own checks ([`Svf::new`], [`LowPass::new`]); a configuration that
    /// passed [`MonitorConfig::validate`] passes them.
    pub(super) fn new(cfg: &MonitorConfig, block_dt_s: f32) -> Result<Self, ConfigError> {
        Ok(DqFilters {
            dq: Svf::new(cfg.filter_hz, block_dt_s)?,
            seq: Svf::new(cfg.sequence_hz, block_dt_s)?,
            lp: LowPass::new(cfg.filter_hz, block_dt_s)?,
            iqs: SvfState::default(),
            ids: SvfState::default(),
            vqs: SvfState::default(),
            wr: SvfState::default(),
            nd: SvfState::default(),
            nq: SvfState::default(),
            vnd: SvfState::default(),
            vnq: SvfState::default(),
            vds: LowPassState::default(),
            trend: Trend::new(block_dt_s)?,
        })
    }

    /// Feeds a block's means and the electrical rotor speed `wr_rad_s`.
    #[inline(always)]
    pub(super) fn update(&mut self, m: &BlockMeans, wr_rad_s: f32) {
        self.dq.update(&mut self.iqs, m.i.q);
        self.dq.update(&mut self.ids, m.i.d);
        self.dq.update(&mut self.vqs, m.v_q);
        self.dq.update(&mut self.wr, wr_rad_s);
        self.seq.update(&mut self.nd, m.n.d);
        self.seq.update(&mut self.nq, m.n.q);
        self.trend
            .update([self.iqs.y(), self.ids.y(), self.vqs.y(), self.wr.y()]);
    }

    /// Feeds the voltage's negative sequence of a block's last sample [V].
    #[inline(always)]
    pub(super) fn update_voltage_negative(&mut self, vn: Dq) {
        self.seq.update(&mut self.vnd, vn.d);
        self.seq.update(&mut self.vnq, vn.q);
    }

    /// Feeds V_ds of a block's last sample [V] and returns it filtered.
    #[inline(always)]
    pub(super) fn update_vds(&mut self, vds: f32) -> f32 {
        self.lp.update(&mut self.vds, vds)
    }

    /// Forgets every state (a restart after a non-finite state).
    pub(super) fn reset(&mut self) {
        for f in [
            &mut self.iqs,
            &mut self.ids,
            &mut self.vqs,
            &mut self.wr,
            &mut self.nd,
            &mut self.nq,
            &mut self.vnd,
            &mut self.vnq,
        ] {
            f.reset();
        }
        self.vds.reset();
        self.trend = Trend {
            states: Default::default(),
            ..self.trend
        };
    }

    /// The filtered model inputs.
    #[inline(always)]
    pub(super) fn operating(&self) -> Operating {
        Operating {
            iqs: self.iqs.y(),
            i_f: self.ids.y(),
            vqs: self.vqs.y(),
            wr_rad_s: self.wr.y(),
        }
    }

    /// The positive sequence's filtered Park components `(i_ds, I_qs)` [A].
    #[inline(always)]
    pub(super) fn positive(&self) -> Complex32 {
        Complex32::new(self.ids.y(), self.iqs.y())
    }

    /// The current's negative sequence `(d, q)`, filtered [A].
    #[inline(always)]
    pub(super) fn negative(&self) -> Complex32 {
        Complex32::new(self.nd.y(), self.nq.y())
    }

    /// The voltage's negative sequence `(d, q)`, filtered [V].
    #[inline(always)]
    pub(super) fn voltage_negative(&self) -> Complex32 {
        Complex32::new(self.vnd.y(), self.vnq.y())
    }

    /// The derivatives of eq. (36) for the block's last inputs `iqs` and `wr_rad_s`.
    #[inline(always)]
    pub(super) fn derivatives(&self, iqs: f32, wr_rad_s: f32) -> Derivatives {
        Derivatives {
            diqs: self.iqs.dy(),
            ddiqs: self.dq.ddy(&self.iqs, iqs),
            dwr: self.wr.dy(),
            ddwr: self.dq.ddy(&self.wr, wr_rad_s),
            dvqs: self.vqs.dy(),
        }
    }

    /// Whether any of I_qs, i_ds, V_qs, wr changes faster than `per_s` of itself (plus its
    /// floor, [`Derived::gate_floor_a`]) per second.
    #[inline(always)]
    pub(super) fn changing(&self, per_s: f32, k: &Derived) -> bool {
        let fast = |f: &SvfState, floor: f32| f.dy().abs() > per_s * (f.y().abs() + floor);
        fast(&self.iqs, k.gate_floor_a)
            || fast(&self.ids, k.gate_floor_a)
            || fast(&self.vqs, k.gate_floor_v)
            || fast(&self.wr, k.gate_floor_rad_s)
    }

    /// Whether the slow trend of I_qs, i_ds, V_qs or wr ([`Trend`]) moves faster than
    /// `per_s` of itself (plus its floor) per second.
    #[inline(always)]
    pub(super) fn trend_changing(&self, per_s: f32, k: &Derived) -> bool {
        self.trend.changing(
            per_s,
            [
                k.gate_floor_a,
                k.gate_floor_a,
                k.gate_floor_v,
                k.gate_floor_rad_s,
            ],
        )
    }
}

/// Corner of the quasi-steady gate's trend filters [Hz]: two first-order low-passes in
/// cascade pass a ripple at `f` by about `(TREND_HZ / f)^2` (a broken rotor bar's `2 s f`
/// torque ripple at 1-10 Hz by 1/4 to 1/400) and follow a load or supply step within about
/// a second.
pub(super) const TREND_HZ: f32 = 0.5;

/// The slow trend of the model inputs (I_qs, i_ds, V_qs, wr, filtered): each through two
/// first-order low-passes at [`TREND_HZ`] in cascade; its rate of change is the second
/// stage's derivative, `w_c (s1 - s2)`. A ripple moves the fast filters' derivatives but
/// not the trend; a transient moves both (the gate's use: `MonitorConfig::steady_gate_per_s`).
#[derive(Debug, Clone, Copy)]
pub(super) struct Trend {
    lp: LowPass,
    /// `2 pi TREND_HZ` [rad/s].
    wc: f32,
    /// The two stages of each input.
    states: [[LowPassState; 2]; 4],
}

impl Trend {
    /// The filters fed every `block_dt_s` [s].
    ///
    /// # Errors
    /// [`LowPass::new`]'s checks (a validated configuration passes them).
    fn new(block_dt_s: f32) -> Result<Self, ConfigError> {
        Ok(Trend {
            lp: LowPass::new(TREND_HZ, block_dt_s)?,
            wc: core::f32::consts::TAU * TREND_HZ,
            states: Default::default(),
        })
    }

    /// Feeds the inputs `x`.
    #[inline(always)]
    fn update(&mut self, x: [f32; 4]) {
        for (s, x) in self.states.iter_mut().zip(x) {
            let [a, b] = s;
            let y = self.lp.update(a, x);
            self.lp.update(b, y);
        }
    }

    /// Whether any trend moves faster than `per_s` of itself plus its `floors` per second.
    #[inline(always)]
    fn changing(&self, per_s: f32, floors: [f32; 4]) -> bool {
        self.states.iter().zip(floors).any(|([a, b], floor)| {
            (self.wc * (a.y() - b.y())).abs() > per_s * (b.y().abs() + floor)
        })
    }
}

/// The block-rate low-passes of the running and plausibility checks: |V|^2 and the 3-wire
/// sums (`|ia + ib + ic|` against `max |i|`, the same for the voltages), one configuration
/// and five states.
#[derive(Debug, Clone, Copy)]
pub(super) struct Checks {
    lp: LowPass,
    /// |V|^2 [V^2] (compared with [`Derived::v_run_min2`]: no square root per block).
    vmag2: LowPassState,
    isum: LowPassState,
    imax: LowPassState,
    vsum: LowPassState,
    vmax: LowPassState,
}

impl Checks {
    /// The low-passes at 5 Hz (or a fifth of the block rate when lower), fed every
    /// `block_dt_s`.
    ///
    /// # Errors
    /// [`LowPass::new`]'s checks (a validated configuration passes them).
    pub(super) fn new(block_rate_hz: f32, block_dt_s: f32) -> Result<Self, ConfigError> {
        Ok(Checks {
            lp: LowPass::new(5.0f32.min(0.2 * block_rate_hz), block_dt_s)?,
            vmag2: LowPassState::default(),
            isum: LowPassState::default(),
            imax: LowPassState::default(),
            vsum: LowPassState::default(),
            vmax: LowPassState::default(),
        })
    }

    /// Feeds |V|^2 [V^2].
    #[inline(always)]
    pub(super) fn update_vmag2(&mut self, vmag2: f32) {
        self.lp.update(&mut self.vmag2, vmag2);
    }

    /// |V|^2 low-passed [V^2].
    #[inline(always)]
    pub(super) fn vmag2(&self) -> f32 {
        self.vmag2.y()
    }

    /// The sum checks on sample `s` (3-wire machine: the phase currents sum to zero, and
    /// the voltages unless `voltage_sum_frac` is 0): the sensors whose sums are too large.
    #[inline(always)]
    pub(super) fn sums(&mut self, s: &Sample, l: &SensorLimits) -> SensorFlags {
        let i = s.i_abc;
        let lp = self.lp;
        let isum = lp.update(&mut self.isum, (i.a + i.b + i.c).abs());
        let imax = lp.update(
            &mut self.imax,
            crate::math::maxf(crate::math::maxf(i.a.abs(), i.b.abs()), i.c.abs()),
        );
        let current = isum > l.current_sum_frac * imax + 1e-3 * l.i_max;
        let mut voltage = false;
        if l.voltage_sum_frac > 0.0 {
            let v = s.v_abc;
            let vsum = lp.update(&mut self.vsum, (v.a + v.b + v.c).abs());
            let vmax = lp.update(
                &mut self.vmax,
                crate::math::maxf(crate::math::maxf(v.a.abs(), v.b.abs()), v.c.abs()),
            );
            voltage = vsum > l.voltage_sum_frac * vmax + 1e-3 * l.v_max;
        }
        SensorFlags {
            current,
            voltage,
            speed: false,
        }
    }
}

/// Blocks left of each sensor fault's hold.
#[derive(Debug, Clone, Copy, Default)]
pub(super) struct SensorHold {
    current: u32,
    voltage: u32,
    speed: u32,
}

impl SensorHold {
    /// Holds the sensors flagged in `bad` for `blocks` (at least 1).
    pub(super) fn hold(&mut self, bad: SensorFlags, blocks: u32) {
        for (h, b) in [
            (&mut self.current, bad.current),
            (&mut self.voltage, bad.voltage),
            (&mut self.speed, bad.speed),
        ] {
            if b {
                *h = blocks.max(1);
            }
        }
    }

    /// One block less of every hold.
    #[inline(always)]
    pub(super) fn age(&mut self) {
        self.current = self.current.saturating_sub(1);
        self.voltage = self.voltage.saturating_sub(1);
        self.speed = self.speed.saturating_sub(1);
    }

    /// The sensor faults still held.
    #[inline(always)]
    pub(super) fn flags(&self) -> SensorFlags {
        SensorFlags {
            current: self.current > 0,
            voltage: self.voltage > 0,
            speed: self.speed > 0,
        }
    }
}
