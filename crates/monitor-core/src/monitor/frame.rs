//! The monitor's d-q frame: the one angle estimator the configuration chose
//! ([`MonitorConfig::angle_source`]), its state at the end of the last block, and the
//! sin/cos the fast path turns with.

use super::MonitorConfig;
use crate::angle::{AngleSource, RotorFluxCurrentModel, SrfPll, ZeroCrossing};
use crate::frames::{park, AlphaBeta, Dq, SinCos};
use core::f32::consts::TAU;

/// The frame angle estimator in use.
#[derive(Debug, Clone, Copy)]
enum Estimator {
    /// Phase-a voltage zero crossings (voltage orientation, the paper's method).
    ZeroCrossing(ZeroCrossing),
    /// SRF-PLL on the voltage vector (voltage orientation).
    Pll(SrfPll),
    /// The rotor-flux current model (rotor-flux orientation).
    RotorFlux(RotorFluxCurrentModel),
}

impl Estimator {
    /// The estimator `cfg.angle_source` names, as at power-up: sample period
    /// `1 / sample_rate_hz`; the zero-crossing detector accepts `0.2..4` times the supply
    /// frequency with a hysteresis of 2 % of the nominal peak voltage; the rotor-flux
    /// model computes the slip from 5 % of the no-load magnetising current
    /// `v_phase_peak / (2 pi supply_hz Ls)` on.
    fn new(cfg: &MonitorConfig) -> Self {
        let dt = 1.0 / cfg.sample_rate_hz;
        let f = cfg.supply_hz;
        match cfg.angle_source {
            AngleSource::ZeroCrossing => Estimator::ZeroCrossing(ZeroCrossing::new(
                dt,
                f,
                0.2 * f,
                4.0 * f,
                0.02 * cfg.v_phase_peak,
            )),
            AngleSource::Pll => Estimator::Pll(SrfPll::new(dt, f, cfg.pll_bw_hz, cfg.v_phase_peak)),
            AngleSource::RotorFluxCurrentModel => {
                let m = &cfg.motor;
                let imr_min = 0.05 * cfg.v_phase_peak / (TAU * f * m.ls_h);
                Estimator::RotorFlux(RotorFluxCurrentModel::new(dt, m.rr_ohm, m.lr_h, imr_min))
            }
        }
    }

    /// The frame's angular frequency [rad/s].
    fn omega_rad_s(&self) -> f32 {
        match self {
            Estimator::ZeroCrossing(zc) => zc.omega_rad_s(),
            Estimator::Pll(pll) => pll.omega_rad_s(),
            Estimator::RotorFlux(rfo) => rfo.omega_rad_s(),
        }
    }

    /// Whether the state can go on after a burst of bad readings: the PLL's angle and
    /// frequency finite; the rotor-flux model's too, and its magnetising current within the
    /// current range `i_max` (a burst of huge readings leaves a finite but absurd flux that
    /// would take seconds to decay). The zero-crossing detector always restarts.
    fn is_sound(&self, i_max: f32) -> bool {
        match self {
            Estimator::ZeroCrossing(_) => false,
            Estimator::Pll(pll) => pll.theta_pll().is_finite() && pll.omega_rad_s().is_finite(),
            Estimator::RotorFlux(rfo) => {
                rfo.theta().is_finite() && rfo.imr().abs() <= i_max && rfo.omega_rad_s().is_finite()
            }
        }
    }
}

/// The d-q frame: its estimator, the estimator as it stood at the end of the last block,
/// and the sin/cos of the frame angle (for the PLL: of its own angle, voltage on +d),
/// advanced by small rotations ([`SinCos::rotated`]) between resynchronisations.
#[derive(Debug, Clone, Copy)]
pub(super) struct Frame {
    estimator: Estimator,
    /// The estimator at the end of the last block: a block with a gap inside is rolled
    /// back to it and bridged from there ([`Frame::bridge`]).
    snapshot: Estimator,
    sc: SinCos,
}

impl Frame {
    /// The frame of `cfg.angle_source`, as at power-up.
    pub(super) fn new(cfg: &MonitorConfig) -> Self {
        let estimator = Estimator::new(cfg);
        Frame {
            estimator,
            snapshot: estimator,
            sc: SinCos::default(),
        }
    }

    /// One sample: advances the estimator with the phase-a voltage `v_a`, the voltage and
    /// current vectors `v`, `i` and the electrical rotor speed `wr_rad_s`, the sample
    /// period `dt_s` apart. Returns the frame's sin/cos for this sample and the current
    /// in the frame. One trig evaluation per block (zero crossing: per sample); between
    /// resynchronisations the sin/cos turns at the estimator's frequency.
    #[inline(always)]
    pub(super) fn update(
        &mut self,
        v_a: f32,
        v: AlphaBeta,
        i: AlphaBeta,
        wr_rad_s: f32,
        dt_s: f32,
    ) -> (SinCos, Dq) {
        match &mut self.estimator {
            Estimator::ZeroCrossing(zc) => {
                let sc = SinCos::from_angle(zc.update(v_a));
                (sc, park(i, sc))
            }
            Estimator::Pll(pll) => {
                let sc_pll = self.sc;
                let w = pll.update(v, sc_pll);
                self.sc = sc_pll.rotated(w * dt_s);
                let sc = sc_pll.minus_quarter_turn();
                (sc, park(i, sc))
            }
            Estimator::RotorFlux(rfo) => {
                let sc = self.sc;
                let i_dq = park(i, sc);
                rfo.update(i_dq, wr_rad_s);
                self.sc = sc.rotated(rfo.omega_rad_s() * dt_s);
                (sc, i_dq)
            }
        }
    }

    /// End of a block: puts the sin/cos back on the estimator's angle (PLL, rotor flux).
    /// Returns the zero-crossing detector's lock (`None` with the other estimators).
    #[inline(always)]
    pub(super) fn resync(&mut self) -> Option<bool> {
        match &self.estimator {
            Estimator::ZeroCrossing(zc) => return Some(zc.locked()),
            Estimator::Pll(pll) => self.sc = SinCos::from_angle(pll.theta_pll()),
            Estimator::RotorFlux(rfo) => self.sc = SinCos::from_angle(rfo.theta()),
        }
        None
    }

    /// The frame's angular frequency [rad/s] (the supply frequency in steady state).
    #[inline(always)]
    pub(super) fn omega_rad_s(&self) -> f32 {
        self.estimator.omega_rad_s()
    }

    /// Keeps the estimator as it stands at the end of a block.
    #[inline(always)]
    pub(super) fn take_snapshot(&mut self) {
        self.snapshot = self.estimator;
    }

    /// Bridges `missing_s` seconds without samples: back to the snapshot, then the angle
    /// advanced over the missing time at the present frequency, the sin/cos on it.
    #[cold]
    #[inline(never)]
    pub(super) fn bridge(&mut self, missing_s: f32) {
        self.estimator = self.snapshot;
        match &mut self.estimator {
            Estimator::ZeroCrossing(zc) => zc.skip(missing_s),
            Estimator::Pll(pll) => {
                pll.skip(missing_s);
                self.sc = SinCos::from_angle(pll.theta_pll());
            }
            Estimator::RotorFlux(rfo) => {
                rfo.skip(missing_s);
                self.sc = SinCos::from_angle(rfo.theta());
            }
        }
    }

    /// Restarts the estimator as at power-up, when `all` or when its state is not sound
    /// (see `Estimator::is_sound`), and the sin/cos always.
    #[cold]
    #[inline(never)]
    pub(super) fn restart(&mut self, cfg: &MonitorConfig, all: bool) {
        if all || !self.estimator.is_sound(cfg.limits.i_max) {
            self.estimator = Estimator::new(cfg);
        }
        self.sc = SinCos::default();
    }
}
