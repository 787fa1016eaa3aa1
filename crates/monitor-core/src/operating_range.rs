//! The operating range learned in commissioning, and when the operating point has left it.
//!
//! The learned healthy means of the residuals hold only near the operating point they were
//! learned at: to the paper's simplified D-Q model ("Fault Diagnosis of Induction Motor
//! Using D-Q Simplified Model and Parity Equations", Energies 2022, 15(22), 8372, MDPI,
//! doi:10.3390/en15228372) a load change is a Bl change, and a voltage change moves the
//! residuals' means. While commissioning learns, the span `[min, max]` of the load and of
//! the voltage is recorded ([`OperatingRange::learn`]); afterwards a value more than
//! [`RANGE_MARGIN`] of the span's largest magnitude outside it means the operating point
//! has *moved* ([`OperatingRange::moved`]): lamps lit there are not, by themselves, a fault.
//!
//! Both quantities are measured without the model's d-q frame, whose angle comes from the
//! speed reading and the parameter file (a speed-sensor fault turns it, and with it `Iqs`
//! and `Vqs`, without the machine's operating point moving at all):
//! ```text
//!   |V| = sqrt(V_ds^2 + V_qs^2),   I_active = (V_ds i_ds + V_qs i_qs) / |V|
//! ```
//! (amplitude-invariant d-q: `|V|` is the phase voltage's peak, `I_active` the peak of the
//! current's part in phase with the voltage, `P = 1.5 |V| I_active`), both unchanged by
//! any rotation of the frame ([`OperatingPoint`]).
//!
//! The host's replay (`diagnose`, the HMI, the demo) and the firmware's panel use this one
//! rule. Pure arithmetic on `f32`, no allocation, no panic.

use crate::math::{fast_hypot, maxf, minf};
use crate::MonitorOutput;

/// Departure from the commissioned range that counts as "moved" (fraction of the range's
/// largest magnitude): 20 %. A load step of that size is what the learned means do not
/// cover, while the faults the lamps are for move the operating point less (Rr +50 % at
/// constant load torque moves the load current by about 8 %; a Bl +50 % fault moves it
/// like a 50 % load step and is, to the paper's model, one).
pub const RANGE_MARGIN: f32 = 0.2;

/// Below this voltage magnitude [V] the active current is undefined (NaN).
const MIN_VOLTAGE_V: f32 = 1e-3;

/// The operating point measured without the d-q frame's angle (module docs).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct OperatingPoint {
    /// The active current `I_active = (V_ds i_ds + V_qs i_qs) / |V|` [A peak]; NaN with
    /// `|V|` at or below 1 mV.
    pub load_a: f32,
    /// The voltage magnitude `|V| = sqrt(V_ds^2 + V_qs^2)` [V peak, phase].
    pub voltage_v: f32,
}

impl OperatingPoint {
    /// The operating point of d-q voltages `vds_v`, `vqs_v` [V] and currents `ids_a`,
    /// `iqs_a` [A] with the voltage magnitude `voltage_v` [V] computed by the caller (the
    /// host passes the standard library's `hypot`, so that its reports keep their digits;
    /// [`OperatingPoint::from_dq`] uses the core's [`fast_hypot`]).
    pub fn with_magnitude(vds_v: f32, vqs_v: f32, ids_a: f32, iqs_a: f32, voltage_v: f32) -> Self {
        let load_a = if voltage_v > MIN_VOLTAGE_V {
            (vds_v * ids_a + vqs_v * iqs_a) / voltage_v
        } else {
            f32::NAN
        };
        Self { load_a, voltage_v }
    }

    /// The operating point of d-q voltages and currents, `|V|` by [`fast_hypot`] (relative
    /// error at f32 rounding level).
    pub fn from_dq(vds_v: f32, vqs_v: f32, ids_a: f32, iqs_a: f32) -> Self {
        Self::with_magnitude(vds_v, vqs_v, ids_a, iqs_a, fast_hypot(vds_v, vqs_v))
    }

    /// The operating point of a monitor output: its filtered `V_ds` ([`MonitorOutput::vds`])
    /// and the model's inputs `i_ds = i_f`, `V_qs`, `I_qs` ([`MonitorOutput::operating`]).
    pub fn of_output(out: &MonitorOutput) -> Self {
        let o = &out.operating;
        Self::from_dq(out.vds, o.vqs, o.i_f, o.iqs)
    }
}

/// Widens `span` (`[min, max]`, `None` before the first value) to hold `x`; a value that
/// is not finite is left out.
pub fn widen(span: &mut Option<[f32; 2]>, x: f32) {
    if !x.is_finite() {
        return;
    }
    let s = span.get_or_insert([x, x]);
    s[0] = minf(s[0], x);
    s[1] = maxf(s[1], x);
}

/// How far `x` lies outside `span` (`[min, max]`), as a signed fraction of the span's
/// largest magnitude (positive above, negative below); `None` inside or within
/// [`RANGE_MARGIN`] of it (a NaN `x` is inside).
pub fn outside(span: [f32; 2], x: f32) -> Option<f32> {
    let [lo, hi] = span;
    let scale = maxf(maxf(lo.abs(), hi.abs()), 1e-6);
    let f = if x > hi {
        (x - hi) / scale
    } else if x < lo {
        (x - lo) / scale
    } else {
        0.0
    };
    (f.abs() > RANGE_MARGIN).then_some(f)
}

/// The span of the load and the voltage seen while commissioning learned (module docs).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct OperatingRange {
    /// Span of the active current `[min, max]` [A peak]; `None` before a finite value.
    pub load_a: Option<[f32; 2]>,
    /// Span of the voltage magnitude `[min, max]` [V peak]; `None` before a finite value.
    pub voltage_v: Option<[f32; 2]>,
}

impl OperatingRange {
    /// Nothing learned yet.
    pub const EMPTY: Self = Self {
        load_a: None,
        voltage_v: None,
    };

    /// Widens the range to hold `p` (call it for the quasi-steady outputs while
    /// commissioning learns).
    pub fn learn(&mut self, p: OperatingPoint) {
        widen(&mut self.load_a, p.load_a);
        widen(&mut self.voltage_v, p.voltage_v);
    }

    /// Whether anything was learned.
    pub fn is_learned(&self) -> bool {
        self.load_a.is_some() || self.voltage_v.is_some()
    }

    /// How far the load of `p` lies outside the learned span ([`outside`]).
    pub fn load_outside(&self, p: OperatingPoint) -> Option<f32> {
        self.load_a.and_then(|s| outside(s, p.load_a))
    }

    /// How far the voltage of `p` lies outside the learned span ([`outside`]).
    pub fn voltage_outside(&self, p: OperatingPoint) -> Option<f32> {
        self.voltage_v.and_then(|s| outside(s, p.voltage_v))
    }

    /// The operating point `p` has moved: its load or its voltage lies more than
    /// [`RANGE_MARGIN`] outside the learned span. False with nothing learned.
    pub fn moved(&self, p: OperatingPoint) -> bool {
        self.load_outside(p).is_some() || self.voltage_outside(p).is_some()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_active_current_does_not_depend_on_the_frame_angle() {
        // V = 300 V along d, I = 10 A at 30 degrees behind it: I_active = 10 cos 30 deg.
        let (v, i, phi) = (300.0f32, 10.0f32, 30f32.to_radians());
        let want = i * phi.cos();
        for k in 0..8 {
            let th = k as f32 * 0.7;
            let p = OperatingPoint::from_dq(
                v * th.cos(),
                v * th.sin(),
                i * (th - phi).cos(),
                i * (th - phi).sin(),
            );
            assert!((p.load_a - want).abs() < 1e-3 * want, "{p:?}");
            assert!((p.voltage_v - v).abs() < 1e-3 * v, "{p:?}");
        }
        assert!(OperatingPoint::from_dq(0.0, 0.0, 5.0, 5.0).load_a.is_nan());
    }

    #[test]
    fn a_step_beyond_the_margin_has_moved_and_one_within_it_has_not() {
        let mut r = OperatingRange::EMPTY;
        let at = |load_a, voltage_v| OperatingPoint { load_a, voltage_v };
        assert!(!r.moved(at(100.0, 100.0)), "nothing learned: never moved");
        r.learn(at(4.0, 310.0));
        r.learn(at(f32::NAN, 311.0));
        r.learn(at(5.0, 309.0));
        assert_eq!(r.load_a, Some([4.0, 5.0]));
        assert_eq!(r.voltage_v, Some([309.0, 311.0]));
        // +30 % load: 6.5 A is 1.5 A = 30 % of 5 A above the span.
        assert!(r.moved(at(6.5, 310.0)));
        let f = r.load_outside(at(6.5, 310.0)).unwrap(); // ok: test
        assert!((f - 0.3).abs() < 1e-6, "{f}");
        // +10 %: within the margin.
        assert!(!r.moved(at(5.5, 310.0)));
        // Below: 2.9 A is 1.1 A = 22 % of 5 A below.
        assert!(r.load_outside(at(2.9, 310.0)).unwrap() < -RANGE_MARGIN); // ok: test
                                                                          // The voltage alone.
        assert!(r.moved(at(4.5, 240.0)));
        assert!(!r.moved(at(f32::NAN, 310.0)));
    }
}
