//! The stiff supply of a run: the positive sequence, a `supply_unbalance`'s negative
//! sequence and the scenario's voltage harmonics, stepped per integrator step.

use super::machine::Machine;
use super::SupplyStep;
use std::f64::consts::PI;

/// The stiff supply: positive-sequence unit phasor `p`, rotated by `e^{j we h/2}` twice per
/// integrator step (no trig per step), plus a negative sequence with `supply_unbalance`
/// and the scenario's voltage harmonics ([`Harmonic`]).
pub(super) struct Supply {
    vpk0: f64,
    vpk: f64,
    /// The supply's angular frequency [rad/s].
    pub(super) we: f64,
    /// The integrator step [s].
    pub(super) h: f64,
    /// Negative-sequence fraction and its angle's cos and sin.
    kn: f64,
    cn: f64,
    sn: f64,
    /// The positive sequence's unit phasor.
    pub(super) p: [f64; 2],
    rot: [f64; 2],
    harmonics: Vec<Harmonic>,
}

/// A voltage harmonic of the supply ([`crate::SupplyHarmonic`]): `p^n e^{j phi}` times
/// `k` for a positive-sequence order, its conjugate for a negative-sequence one (the
/// phase voltages `k cos(n theta + phi - m n 2 pi / 3)`, m = 0, 1, 2, in the alpha-beta
/// frame).
#[derive(Debug, Clone, Copy)]
struct Harmonic {
    n: u32,
    positive: bool,
    k: f64,
    /// e^{j phi}.
    c: f64,
    s: f64,
}

impl Harmonic {
    fn of(h: &crate::SupplyHarmonic) -> Self {
        let (s, c) = h.phase_deg.to_radians().sin_cos();
        Harmonic {
            n: h.order,
            positive: h.positive_sequence(),
            k: h.fraction,
            c,
            s,
        }
    }

    /// The harmonic's unit-amplitude vector times `k` at the fundamental's unit phasor `p`.
    #[inline(always)]
    fn at(&self, p: [f64; 2]) -> [f64; 2] {
        let mut pn = [1.0, 0.0];
        let (mut base, mut e) = (p, self.n);
        while e > 0 {
            if e & 1 == 1 {
                pn = Supply::rotate(pn, base);
            }
            base = Supply::rotate(base, base);
            e >>= 1;
        }
        let [x, y] = Supply::rotate(pn, [self.c, self.s]);
        if self.positive {
            [self.k * x, self.k * y]
        } else {
            [self.k * x, -self.k * y]
        }
    }
}

impl Supply {
    pub(super) fn new(
        vpk0: f64,
        we0: f64,
        h: f64,
        unbalance: Option<(f64, f64)>,
        harmonics: &[crate::SupplyHarmonic],
    ) -> Self {
        let (kn, cn, sn) = match unbalance {
            Some((k, phi)) => (k, phi.cos(), phi.sin()),
            None => (0.0, 1.0, 0.0),
        };
        Supply {
            vpk0,
            vpk: vpk0,
            we: we0,
            h,
            kn,
            cn,
            sn,
            p: [1.0, 0.0],
            rot: [(0.5 * we0 * h).cos(), (0.5 * we0 * h).sin()],
            harmonics: harmonics.iter().map(Harmonic::of).collect(),
        }
    }

    pub(super) fn step(&mut self, s: &SupplyStep) {
        if let Some(v) = s.v_scale {
            self.vpk = self.vpk0 * v;
        }
        if let Some(f) = s.f_hz {
            self.we = 2.0 * PI * f;
            self.rot = [
                (0.5 * self.we * self.h).cos(),
                (0.5 * self.we * self.h).sin(),
            ];
        }
    }

    /// Voltage vector (alpha, beta) for the unit phasor `p`.
    #[inline(always)]
    pub(super) fn voltage(&self, p: [f64; 2]) -> [f64; 2] {
        let (kn, cn, sn) = (self.kn, self.cn, self.sn);
        let mut v = [
            p[0] + kn * (cn * p[0] + sn * p[1]),
            p[1] + kn * (sn * p[0] - cn * p[1]),
        ];
        for h in &self.harmonics {
            let [x, y] = h.at(p);
            v = [v[0] + x, v[1] + y];
        }
        [self.vpk * v[0], self.vpk * v[1]]
    }

    #[inline(always)]
    fn rotate(p: [f64; 2], r: [f64; 2]) -> [f64; 2] {
        [p[0] * r[0] - p[1] * r[1], p[0] * r[1] + p[1] * r[0]]
    }

    /// The shorted loop's current where a run starts (its forced response to the supply:
    /// the loop settles in tens of microseconds, faster than any sample), 0 without one.
    pub(super) fn loop_start(&self, machine: &Machine) -> f64 {
        let p1 = Self::rotate(Self::rotate(self.p, self.rot), self.rot);
        machine.turn.map_or(0.0, |t| {
            t.forced(self.voltage(self.p), self.voltage(p1), self.we, self.h)
        })
    }

    /// Integrates `machine` over one output sample (`nsub` steps of `h`), and the shorted
    /// loop's current `i_f` of a turn fault (exact for the supply's sinusoid).
    /// `t0` is the output sample's time [s] (the users' laws of time read it).
    pub(super) fn integrate(
        &mut self,
        machine: &Machine,
        x: &mut [f64; 6],
        i_f: &mut f64,
        nsub: u32,
        t0: f64,
    ) {
        for j in 0..nsub {
            let pm = Self::rotate(self.p, self.rot);
            let pe = Self::rotate(pm, self.rot);
            let (v0, v1) = (self.voltage(self.p), self.voltage(pe));
            let t = t0 + f64::from(j) * self.h;
            machine.rk4(x, t, self.h, v0, self.voltage(pm), v1);
            if let Some(t) = &machine.turn {
                *i_f = t.step(*i_f, v0, v1, self.we, self.h);
            }
            self.p = pe;
        }
        // Renormalise |p| = 1 (first-order Newton step: no sqrt, |p| drifts by ~1e-16/step).
        let norm = 1.5 - 0.5 * (self.p[0] * self.p[0] + self.p[1] * self.p[1]);
        self.p = [self.p[0] * norm, self.p[1] * norm];
    }
}
