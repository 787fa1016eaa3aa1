//! The operating point the rotor is judged at ([`RotorLoad`]): the load the log says, from
//! what it has (the speed, else the voltages' power, else the current's magnitude), against
//! the rated point of the parameter file's machine ([`RatedLoadPoint`]); and the largest slip a
//! steadily running machine can have at it ([`RatedLoadPoint::max_steady_slip`]).
//!
//! # The rated point
//! A parameter file has no nameplate fields: its rated load is its viscous load, the paper's
//! `(B + Bl) w_m` that asks for the rated torque at the rated speed (`sim-host params
//! from-nameplate` writes `Bl = P / w_m^2`: `monitor_io::nameplate`, step 6). The rated slip
//! `s_r` is where the T-equivalent circuit's torque meets it,
//! `T(s) = 3 Np |I_s|^2 Re(Z_m(s)) / w_s = (B + Bl) (1 - s) w_s / Np`, `Z_m` the circuit's
//! magnetising and rotor branch in parallel, `|I_s| = V_ph / |Z(s)|` (rms); the breakdown slip
//! `s_b` is where `T(s)` peaks. For the nameplate file of the ITSC recordings' Baldor
//! (0.75 hp, 1725 rpm, 3 A) this gives 4.17 % and 3.00 A rms, the nameplate's own values.
//!
//! # The load
//! The torque at the log's slip over the rated torque, `T(s) / T(s_r)`, with the slip:
//! - from the speed, where the log has it;
//! - else from the voltages: where the circuit at the measured `|V1|` takes the measured
//!   power `P = 3/2 Re(V1 conj(I1))` (peak phasors);
//! - else from the current: where the circuit draws the measured `|I1|`
//!   (`monitor_core::sequence::slip_for_current`), when the file can draw it between
//!   `(1 - u)` times its no-load current and `(1 + u)` times its current at
//!   [`MAX_SLIP_OVER_RATED`] times the rated slip, `u` = [`CURRENT_MODEL_UNCERTAINTY`]. A
//!   current outside that range is a scale the file does not know (a DAQ's own units, a CT
//!   ratio), and the load is unknown: the ITSC recordings' currents are in the data set's
//!   own units.
//!
//! # Where MCSA applies
//! The broken-bar sidebands are driven by the rotor current: the sum of the two over the
//! torque-producing current is `delta / (3 + delta)` (Bellini et al. 2001,
//! `monitor_core::rotor_cage`), so at a fraction `x` of the rated torque they read about
//! `20 log10 x` dB below their full-load level, and at no load (slip near zero) a broken
//! cage carries almost no current and shows nothing. W. T. Thomson and M. Fenger, "Current
//! signature analysis to detect induction motor faults", IEEE Industry Applications
//! Magazine 7(4), 2001, set their severity bands on motors running near full load, and
//! M. E. H. Benbouzid, "A review of induction motors signature analysis as a medium for
//! faults detection", IEEE Trans. Ind. Electron. 47(5), 2000, notes that the sidebands
//! depend on the load and are hard to detect at light load. The rotor is judged from
//! [`MCSA_MIN_LOAD`] of the rated torque on: there the same cage reads 8 dB below its
//! full-load level, a band and a third of the bands' 6 dB; below it the bands no longer
//! grade the cage, and the finding says the load is too low.

pub use crate::windows::{MeasuredPoint, CURRENT_MODEL_UNCERTAINTY};
use monitor_core::sequence::slip_for_current;
use monitor_io::params::ParamFile;
use num_complex::Complex64;
use serde::Serialize;
use std::f64::consts::TAU;

/// The least load, as a fraction of the rated torque, at which the rotor is judged (module
/// docs, "Where MCSA applies"): the sidebands there read `20 log10 0.4` = 8 dB below their
/// full-load level, a band and a third of Thomson and Fenger's 6 dB bands, which were set on
/// motors near full load.
pub const MCSA_MIN_LOAD: f64 = 0.4;
/// The largest slip a machine runs at steadily, relative to its rated slip (or to the slip
/// at the load the log says, where that is larger): 1.5 times the rated slip is about 1.5
/// times the rated torque, past any service factor (NEMA MG 1: 1.0-1.25), which a motor's
/// overload protection does not let run. A pair about the line that gives a larger slip is
/// not the rotor's sidebands.
pub const MAX_SLIP_OVER_RATED: f64 = 1.5;

/// The rated point of a parameter file's machine (module docs, "The rated point").
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct RatedLoadPoint {
    /// The rated slip `s_r` [-]: the circuit's torque meets the viscous load `(B + Bl) w_m`.
    pub slip: f64,
    /// The rated torque `T(s_r)` [N m].
    pub torque_nm: f64,
    /// The rated current [A, phase peak].
    pub current_peak_a: f64,
    /// The no-load current `V_ph / |Rs + j w Ls|` [A, phase peak].
    pub no_load_current_peak_a: f64,
    /// The breakdown slip `s_b` [-]: where the circuit's torque peaks.
    pub breakdown_slip: f64,
}

/// The T-equivalent circuit of a parameter file, in f64 (module docs).
#[derive(Debug, Clone, Copy)]
struct EquivalentCircuit {
    rs: f64,
    rr: f64,
    xls: f64,
    xlr: f64,
    xm: f64,
    /// Phase voltage [V, rms] and supply [rad/s].
    v: f64,
    w: f64,
    np: f64,
}

impl EquivalentCircuit {
    fn of(p: &ParamFile) -> Self {
        let (m, w) = (&p.motor, TAU * p.supply.f_hz);
        EquivalentCircuit {
            rs: m.rs_ohm,
            rr: m.rr_ohm,
            xls: w * (m.ls_h - m.lm_h),
            xlr: w * (m.lr_h - m.lm_h),
            xm: w * m.lm_h,
            v: p.supply.v_ll_rms / 3f64.sqrt(),
            w,
            np: f64::from(p.motor.poles / 2).max(1.0),
        }
    }

    /// The magnetising and rotor branches in parallel at slip `s` [ohm].
    fn zm(&self, s: f64) -> Complex64 {
        let zr = Complex64::new(self.rr / s.max(1e-6), self.xlr);
        let jxm = Complex64::new(0.0, self.xm);
        jxm * zr / (jxm + zr)
    }

    /// The input impedance at slip `s` [ohm].
    fn z(&self, s: f64) -> Complex64 {
        Complex64::new(self.rs, self.xls) + self.zm(s)
    }

    /// The stator current at slip `s` and phase voltage `v` [A, rms].
    fn current(&self, s: f64, v: f64) -> f64 {
        v / self.z(s).norm().max(1e-12)
    }

    /// The electromagnetic torque at slip `s` [N m]: the air-gap power over the synchronous
    /// speed.
    fn torque(&self, s: f64) -> f64 {
        let i = self.current(s, self.v);
        3.0 * i * i * self.zm(s).re * self.np / self.w
    }

    /// The slip in `(lo, hi)` where `f` changes sign from below to above zero (bisection,
    /// 60 steps); `f` is increasing there.
    fn root(lo: f64, hi: f64, f: impl Fn(f64) -> f64) -> f64 {
        let (mut lo, mut hi) = (lo, hi);
        for _ in 0..60 {
            let mid = 0.5 * (lo + hi);
            if f(mid) < 0.0 {
                lo = mid;
            } else {
                hi = mid;
            }
        }
        0.5 * (lo + hi)
    }

    /// The breakdown slip: the torque's peak on a grid of 0.1 % up to 99 %, refined by
    /// golden-section search.
    fn breakdown(&self) -> f64 {
        let (mut best, mut at) = (f64::MIN, 0.01);
        for k in 1..990 {
            let s = f64::from(k) * 1e-3;
            let t = self.torque(s);
            if t > best {
                (best, at) = (t, s);
            }
        }
        let (mut a, mut b) = ((at - 1e-3).max(1e-4), at + 1e-3);
        let g = 0.5 * (5f64.sqrt() - 1.0);
        for _ in 0..40 {
            let (c, d) = (b - g * (b - a), a + g * (b - a));
            if self.torque(c) > self.torque(d) {
                b = d;
            } else {
                a = c;
            }
        }
        0.5 * (a + b)
    }
}

impl RatedLoadPoint {
    /// The rated point of `p`'s machine (module docs), `None` where the file has no viscous
    /// load or its circuit reaches the load at no slip below breakdown.
    pub fn of(p: &ParamFile) -> Option<Self> {
        let c = EquivalentCircuit::of(p);
        let load = p.motor.b_nms + p.motor.bl_nms;
        let sync = c.w / c.np;
        let s_b = c.breakdown();
        let excess = |s: f64| c.torque(s) - load * (1.0 - s) * sync;
        if load.is_nan() || load <= 0.0 || excess(s_b) <= 0.0 {
            return None;
        }
        let slip = EquivalentCircuit::root(1e-6, s_b, excess);
        let peak = std::f64::consts::SQRT_2;
        Some(RatedLoadPoint {
            slip,
            torque_nm: c.torque(slip),
            current_peak_a: peak * c.current(slip, c.v),
            no_load_current_peak_a: peak * c.current(0.0, c.v),
            breakdown_slip: s_b,
        })
    }

    /// The largest slip the machine runs at steadily at a load whose slip is `at_load`
    /// (where known): [`MAX_SLIP_OVER_RATED`] times the larger of the rated slip and
    /// `at_load`, and never past the breakdown slip.
    pub fn max_steady_slip(&self, at_load: Option<f64>) -> f64 {
        let base = at_load.map_or(self.slip, |s| s.max(self.slip));
        (MAX_SLIP_OVER_RATED * base).min(self.breakdown_slip)
    }
}

/// Where the load estimate comes from.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum LoadSource {
    /// The slip from the log's speed.
    Speed,
    /// The power from the log's voltages and currents.
    Voltages,
    /// The current's magnitude against the file's no-load and rated currents.
    Current,
}

/// Why the load is unknown (JSON `{"kind": ..}`).
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
#[serde(tag = "kind", rename_all = "snake_case")]
pub enum LoadUnknown {
    /// The parameter file has no rated load (B + Bl).
    NoRatedLoad,
    /// The current is outside what the file draws between no load and `top_slip`: a scale
    /// the file does not know, and the log has no speed or voltages.
    CurrentOutOfScale {
        /// The current [A, peak].
        current_peak_a: f64,
        /// The steady slip the range reaches.
        top_slip: f64,
        /// The range `[low, high]` [A, peak] with its uncertainty.
        range_a: [f64; 2],
        /// The uncertainty (fraction).
        uncertainty: f64,
    },
}

/// The load the rotor is judged at (JSON `rotor.load`; module docs).
#[derive(Debug, Clone, Default, PartialEq, Serialize)]
pub struct RotorLoad {
    /// The load torque over the rated torque, `T(s) / T(s_r)` [-]; null when unknown.
    pub fraction: Option<f64>,
    /// The slip of that load [-].
    pub slip: Option<f64>,
    /// Where the estimate comes from.
    pub source: Option<LoadSource>,
    /// The least fraction the rotor is judged at ([`MCSA_MIN_LOAD`]).
    pub min_fraction: f64,
    /// The file's rated point; null where the file gives none.
    pub rated: Option<RatedLoadPoint>,
    /// Why the load is unknown, where it is (JSON `unknown_reason`; the door spells it as
    /// `unknown_because`).
    #[serde(rename = "unknown_reason")]
    pub unknown_because: Option<LoadUnknown>,
    /// The measured current [A, phase peak] where it was read.
    pub current_peak_a: Option<f64>,
}

impl RotorLoad {
    /// The load of `p`'s machine at the slip `s` measured by the speed.
    pub fn from_speed(p: &ParamFile, s: f64) -> Self {
        Self::at_slip(p, s, LoadSource::Speed)
    }

    /// The load of `p`'s machine at slip `s` from `source`.
    fn at_slip(p: &ParamFile, s: f64, source: LoadSource) -> Self {
        let c = EquivalentCircuit::of(p);
        match RatedLoadPoint::of(p) {
            Some(r) => RotorLoad {
                fraction: Some(c.torque(s.max(0.0)) / r.torque_nm),
                slip: Some(s),
                source: Some(source),
                min_fraction: MCSA_MIN_LOAD,
                rated: Some(r),
                ..RotorLoad::default()
            },
            None => Self::unknown(None, LoadUnknown::NoRatedLoad),
        }
    }

    /// An unknown load, with why.
    fn unknown(rated: Option<RatedLoadPoint>, why: LoadUnknown) -> Self {
        RotorLoad {
            min_fraction: MCSA_MIN_LOAD,
            rated,
            unknown_because: Some(why),
            ..RotorLoad::default()
        }
    }

    /// The load of `p`'s machine from the voltages' power at `m`: the slip where the circuit
    /// at `|V1|` takes `P = 3/2 |V1| |I1| cos(angle)`.
    pub fn from_power(p: &ParamFile, m: &MeasuredPoint) -> Self {
        let c = EquivalentCircuit::of(p);
        let Some(r) = RatedLoadPoint::of(p) else {
            return Self::unknown(None, LoadUnknown::NoRatedLoad);
        };
        let power = 1.5 * m.v1_peak_v * m.i1_peak_a * m.angle_rad.cos();
        let v = m.v1_peak_v / std::f64::consts::SQRT_2;
        let p_at = |s: f64| 3.0 * v * v * (1.0 / c.z(s)).re;
        if !power.is_finite() || v.is_nan() || v <= 0.0 || power <= p_at(1e-6) {
            let mut l = Self::at_slip(p, 0.0, LoadSource::Voltages);
            l.current_peak_a = Some(m.i1_peak_a);
            return l;
        }
        if power >= p_at(r.breakdown_slip) {
            return Self::at_slip(p, r.breakdown_slip, LoadSource::Voltages);
        }
        let s = EquivalentCircuit::root(1e-6, r.breakdown_slip, |s| p_at(s) - power);
        let mut l = Self::at_slip(p, s, LoadSource::Voltages);
        l.current_peak_a = Some(m.i1_peak_a);
        l
    }

    /// The load of `p`'s machine from the current's magnitude `i1_peak_a` alone (module
    /// docs): unknown where the file cannot draw it.
    pub fn from_current(p: &ParamFile, i1_peak_a: f64) -> Self {
        let Some(r) = RatedLoadPoint::of(p) else {
            return Self::unknown(None, LoadUnknown::NoRatedLoad);
        };
        let c = EquivalentCircuit::of(p);
        let u = f64::from(CURRENT_MODEL_UNCERTAINTY);
        let top = r.max_steady_slip(None);
        let lo = (1.0 - u) * r.no_load_current_peak_a;
        let hi = (1.0 + u) * std::f64::consts::SQRT_2 * c.current(top, c.v);
        if !(lo..=hi).contains(&i1_peak_a) {
            let mut l = Self::unknown(
                Some(r),
                LoadUnknown::CurrentOutOfScale {
                    current_peak_a: i1_peak_a,
                    top_slip: top,
                    range_a: [lo, hi],
                    uncertainty: u,
                },
            );
            l.current_peak_a = Some(i1_peak_a);
            return l;
        }
        let s = slip_for_current(
            &p.motor.model::<f32>(),
            (c.v * std::f64::consts::SQRT_2) as f32,
            c.w as f32,
            i1_peak_a as f32,
        );
        let s = if f64::from(s) <= 2e-4 {
            0.0
        } else {
            f64::from(s)
        };
        let mut l = Self::at_slip(p, s, LoadSource::Current);
        l.current_peak_a = Some(i1_peak_a);
        l
    }

    /// Whether the load is known and below [`MCSA_MIN_LOAD`].
    pub fn too_low(&self) -> bool {
        self.fraction.is_some_and(|x| x < self.min_fraction)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_nameplate_files_rated_point_is_the_nameplates() {
        // The ITSC Baldor's file (examples/recordings/itsc/baldor_0p75hp.toml), estimated
        // from its nameplate: 1725 rpm of 1800 (slip 4.17 %), 3 A rms.
        let text = include_str!("../../../../examples/recordings/itsc/baldor_0p75hp.toml");
        let (p, _) = ParamFile::from_toml_str_with_columns(text, "baldor").expect("file"); // ok: test
        let r = RatedLoadPoint::of(&p).expect("rated"); // ok: test
        assert!((r.slip - 75.0 / 1800.0).abs() < 0.002, "{r:?}");
        assert!((r.current_peak_a / 2f64.sqrt() - 3.0).abs() < 0.1, "{r:?}");
        // A small motor's breakdown: 2-3 times the rated torque at 20-35 % slip.
        assert!(r.breakdown_slip > 0.2 && r.breakdown_slip < 0.4, "{r:?}");
        // No load from the speed: nothing; the rated slip: the rated torque.
        assert!(RotorLoad::from_speed(&p, 0.001).too_low());
        let full = RotorLoad::from_speed(&p, r.slip);
        assert!(
            (full.fraction.unwrap_or(0.0) - 1.0).abs() < 1e-6,
            "{full:?}"
        );
        // The current alone: the no-load current is no load, the rated current full load,
        // five times the rated current a scale the file does not know.
        let idle = RotorLoad::from_current(&p, r.no_load_current_peak_a);
        assert!(idle.too_low(), "{idle:?}");
        let rated = RotorLoad::from_current(&p, r.current_peak_a);
        assert!(
            (rated.fraction.unwrap_or(0.0) - 1.0).abs() < 0.02,
            "{rated:?}"
        );
        let scaled = RotorLoad::from_current(&p, 5.0 * r.current_peak_a);
        assert!(
            scaled.fraction.is_none()
                && !scaled.too_low()
                && matches!(
                    scaled.unknown_because,
                    Some(LoadUnknown::CurrentOutOfScale { .. })
                ),
            "{scaled:?}"
        );
    }
}
