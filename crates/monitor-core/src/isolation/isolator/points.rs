//! The isolation over several operating points (evidence across operating points, module
//! docs of [`crate::isolation`]): each hypothesis fitted jointly over the points, with the
//! torque compared with the load known at an anchor.

use super::heating::HEATING_STEPS;
use super::search::{fit_factor, golden, rank, ALL_SEEN};
use super::*;

impl Isolator {
    /// Isolates the fault from several steady operating points together (evidence across
    /// operating points): each hypothesis' misfit is the sum of its misfits at the points,
    /// each point weighted at itself ([`Isolator::weight`], its spreads times its
    /// `spread_scale` >= 1) and fitted with one size for all. The load at each point is an
    /// unknown input: only the stator-voltage equations (`e_d`, `e_q`) count, the torque
    /// balance (which holds only for the load model assumed) is left out, so B and Bl are
    /// not judged here. Faults whose directions
    /// coincide at one operating point (Ls, Rr and the speed sensor near rated load) part
    /// at another. The heating hypothesis takes part as in [`Isolator::isolate`]. At most
    /// [`MAX_POINTS`] points are used (the first ones); none usable gives
    /// [`IsolationState::NotJudged`].
    pub fn isolate_points(&self, points: &[(SteadyPoint, f32)]) -> Isolation {
        self.isolate_points_anchored(points, None)
    }

    /// [`Isolator::isolate_points`] with the load known at one point: `anchor`, the last
    /// steady point judged healthy before the deviation began (module docs, "The load
    /// before the deviation"). At the first point (the first steady point of the deviation,
    /// the nearest to the anchor in time), if its active current is within
    /// [`ANCHOR_LOAD_BAND`] of the anchor's, the torque the circuit gives under the
    /// hypothesis is compared with the anchor's load carried to the point's speed by the
    /// paper's viscous law (the nominal machine's torque at the anchor times the speeds'
    /// ratio, [`LOAD_LAW_SPREAD`] allowed). A sensor gain step, which moves neither the
    /// machine nor its load, is thus judged with the torque balance (a current sensor's
    /// error scales the torque computed from the currents, a voltage sensor's does not),
    /// and an Rr change at one load level parts from a speed-sensor error (the one slows
    /// the machine and its viscous load, the other only the reading); a load step leaves the
    /// voltage equations to decide.
    pub fn isolate_points_anchored(
        &self,
        points: &[(SteadyPoint, f32)],
        anchor: Option<&SteadyPoint>,
    ) -> Isolation {
        self.isolate_points_anchored_from(points, anchor, &mut SearchHints::default())
    }

    /// [`Isolator::isolate_points_anchored`] with each fault's size searched from where
    /// `hints` say it was found the last time, and `hints` updated (module docs, "Searches
    /// started from the last result").
    pub fn isolate_points_anchored_from(
        &self,
        points: &[(SteadyPoint, f32)],
        anchor: Option<&SteadyPoint>,
        hints: &mut SearchHints,
    ) -> Isolation {
        let mut out = Isolation::default();
        let (used, n) = self.weighted_points(points);
        let used = used.get(..n).unwrap_or(&[]);
        let Some(first) = used.first().map(|(r, _, _, _)| r.q) else {
            return out;
        };
        let load = anchor.and_then(|a| {
            Some(AnchorLoad {
                torque_nm: self.torque_nm(a, None)?,
                active_a: a.operating_point().load_a,
                wr_rad_s: a.wr_rad_s,
            })
        });
        let chi0 = self.chi2_points(used, load, None);
        out.deviation = crate::math::sqrt(chi0);
        if let Some(e0) = self.residuals(&first, None) {
            out.residuals = e0 - self.baseline.mean;
        }
        // Each point adds two or three equations: the detection threshold grows with them.
        if chi0 < DETECT_CHI2 * n as f32 {
            out.state = IsolationState::NoDeviation;
            return out;
        }
        let mut fits = [(0.0f32, 1.0f32); FAULT_COUNT];
        let use_hints = hints.begin(self.hint_at(&out), n);
        for (fit, f) in fits.iter_mut().zip(Fault::ALL) {
            let (found, hint) = fit_factor(
                |k| self.chi2_points(used, load, Some((f, k))),
                hints.get(f, use_hints),
            );
            *fit = found;
            hints.set(f, hint);
        }
        let (lo, hi) = self.heating_range();
        let heat = golden(
            |k| self.warmer(k).chi2_points(used, load, None),
            lo,
            hi,
            HEATING_STEPS,
        );
        // A winding of unknown temperature (module docs, "The temperature unknown"): each
        // fault at any temperature of the heating range, named only for what it explains
        // beyond the heating; over two load levels or more a fault on a warm winding parts
        // from another on a winding warmed differently.
        let seen = if self.temperature_unknown() {
            self.fits_beyond_heating(
                &mut fits,
                heat,
                |iso, f, k| iso.chi2_points(used, load, Some((f, k))),
                (hints, use_hints),
            )
        } else {
            ALL_SEEN
        };
        let dims = 2.0 * n as f32 + if load.is_some() { 1.0 } else { 0.0 };
        rank(
            &mut out,
            &mut fits,
            heat,
            (chi0, dims),
            self.direction_uncertainty(),
            &seen,
        );
        if self.temperature_unknown() {
            super::heating_not_unknown(&mut out);
        }
        if let Some(e0) = self.residuals(&first, None) {
            out.separation_deg = self.separation(&first, &e0, &out.candidates);
        }
        out
    }

    /// The usable points of `points` (at most [`MAX_POINTS`], the first ones) with their
    /// weights: each point's voltage-equation weight with the tracked temperature's lag
    /// allowed for ([`Isolator::weight_with_lag`], [`Sym3::voltage_only`]) under the
    /// baseline's spreads times its spread scale (>= 1; values below 1 or not finite count
    /// as 1), that scale, and the lag's torque spread. Returns the array and how many of it
    /// are filled.
    fn weighted_points(
        &self,
        points: &[(SteadyPoint, f32)],
    ) -> ([WeightedPoint; MAX_POINTS], usize) {
        let mut used = [(Reading::default(), Sym3::default(), 1.0f32, 0.0f32); MAX_POINTS];
        let mut n = 0;
        for (p, scale) in points.iter().take(MAX_POINTS) {
            let k = if scale.is_finite() {
                crate::math::maxf(*scale, 1.0)
            } else {
                1.0
            };
            let mut scaled = *self;
            scaled.baseline.spread = scaled.baseline.spread.map(|s| s * k);
            if self.residuals(p, None).is_none() {
                continue;
            }
            let (w, lag_torque) = scaled.weight_with_lag(p);
            let Some(w) = w.voltage_only() else {
                continue;
            };
            if let Some(slot) = used.get_mut(n) {
                *slot = (Reading::of(p), w, k, lag_torque);
                n += 1;
            }
        }
        (used, n)
    }

    /// The joint misfit of hypothesis `h` over the weighted points `used`: the torque
    /// comparison with the anchor's `load` at the first point ([`Isolator::chi2_load`];
    /// the first steady point of the deviation, the one nearest the anchor in time) plus
    /// each point's voltage-equation misfit ([`Isolator::chi2_at`]).
    fn chi2_points(
        &self,
        used: &[WeightedPoint],
        load: Option<AnchorLoad>,
        h: Option<(Fault, f32)>,
    ) -> f32 {
        // One circuit for every point; each point's readings corrected for `h`.
        let c = self.circuit_of(h);
        let mut first = 0.0;
        let sum = used
            .iter()
            .enumerate()
            .map(|(n, (r, w, k, lag))| {
                let r = self.reading_of(r, h);
                let e = self.eval_reading(&c, &r);
                if n == 0 {
                    first = self.chi2_load(&c, &r, e, load, (*k, *lag));
                }
                self.chi2_of(e, w)
            })
            .sum::<f32>();
        first + sum
    }

    /// The air-gap torque the circuit gives at `p` under hypothesis `h` [N m]
    /// (`Te = e_T T_base + (B + Bl) wr / Np`, the torque of [`ParityResiduals::torque`]);
    /// `None` where the point gives no residuals.
    fn torque_nm(&self, p: &SteadyPoint, h: Option<(Fault, f32)>) -> Option<f32> {
        let (c, r) = (self.circuit_of(h), self.reading_of(&Reading::of(p), h));
        let e = self.eval_reading(&c, &r)?;
        Some(e.torque * self.torque_base_nm + c.b_total * r.q.wr_rad_s / c.np)
    }

    /// The misfit of the torque at the point `r` (its readings corrected for the
    /// hypothesis, `e` its residuals under the hypothesis' circuit `c`) against the load
    /// known at the anchor (`load`; `None`: no term). The sensor correction applies to the
    /// point, not to the anchor, measured before; the load is taken as unchanged where the
    /// active current moved by at most [`ANCHOR_LOAD_BAND`] from the anchor's (else no
    /// term), and as the paper's viscous load `T0 wr / wr0` there; the spread is
    /// [`ANCHOR_TORQUE_SPREAD`] times `scale`, widened by [`LOAD_LAW_SPREAD`] times the
    /// speed's relative change times `T0`, and the tracked temperature's lag `s_lag` (in the
    /// torque balance's units).
    fn chi2_load(
        &self,
        c: &Circuit,
        r: &Reading,
        e: Option<ParityResiduals>,
        load: Option<AnchorLoad>,
        (scale, s_lag): (f32, f32),
    ) -> f32 {
        let Some(a) = load else {
            return 0.0;
        };
        let (q, t0) = (&r.q, a.torque_nm);
        // (The anchor was measured before the deviation: its readings stand as they are.)
        let ia = crate::OperatingPoint::with_magnitude(q.v.d, q.v.q, q.i.d, q.i.q, r.vmag).load_a;
        let i0 = a.active_a;
        let moved = (ia - i0) / crate::math::maxf(i0.abs(), 1e-6);
        if !(moved.abs() <= ANCHOR_LOAD_BAND) {
            return 0.0;
        }
        let Some(e) = e else {
            return f32::INFINITY;
        };
        let te = e.torque * self.torque_base_nm + c.b_total * q.wr_rad_s / c.np;
        let speed = q.wr_rad_s / crate::math::maxf(a.wr_rad_s.abs(), 1.0);
        let t_load = t0 * speed;
        let s_law = LOAD_LAW_SPREAD * (speed - 1.0) * t0 / self.torque_base_nm;
        let s = ANCHOR_TORQUE_SPREAD * scale;
        // The parameter file's own torque error: what commissioning learned as the torque
        // balance's healthy mean (zero for a file that fits the machine; a nameplate 20 %
        // off leaves several per cent, and the change of that error between the anchor and
        // a faulty point is of its order).
        let s_file = self.baseline.mean.torque;
        let d = (te - t_load) / self.torque_base_nm;
        let var = s * s + s_law * s_law + s_file * s_file + s_lag * s_lag;
        if var > 0.0 {
            d * d / var
        } else {
            0.0
        }
    }
}

/// Largest relative change of the active current from the anchor's (the sensor
/// correction of the hypothesis applied) at which the load is taken as unchanged
/// ([`Isolator::isolate_points_anchored`]): 6 %. The active current follows the input
/// power: at a constant load the faults of the list move it by their losses, a few per
/// cent (Rr +50 % about 3 %), while a load step of 10 % or more moves it by about as much.
pub const ANCHOR_LOAD_BAND: f32 = 0.06;

/// Uncertainty of the load's speed law around the paper's viscous `T ~ wr`
/// ([`Isolator::isolate_points_anchored`]): the exponent 1 +- 0.25, times the speed's
/// relative change from the anchor.
pub const LOAD_LAW_SPREAD: f32 = 0.25;

/// Spread of the torque comparison with the anchor, as a fraction of `T_base`: twice the
/// learned floor of the torque balance ([`LEARNED_SPREAD_FLOOR`]), for the two points'
/// scatter together.
pub const ANCHOR_TORQUE_SPREAD: f32 = 2.0 * LEARNED_SPREAD_FLOOR.torque;

/// Most operating points [`Isolator::isolate_points`] combines.
pub const MAX_POINTS: usize = 4;

/// One operating point of the joint isolation: the point, its voltage-equation weight, its
/// spread scale (>= 1) and the tracked temperature's lag in the torque balance
/// ([`Isolator::isolate_points_anchored`]).
type WeightedPoint = (Reading, Sym3, f32, f32);

/// The load known at the anchor ([`Isolator::isolate_points_anchored`]): the nominal
/// machine's air-gap torque there [N m], the anchor's active current [A] and its electrical
/// rotor speed [rad/s].
#[derive(Debug, Clone, Copy)]
struct AnchorLoad {
    torque_nm: f32,
    active_a: f32,
    wr_rad_s: f32,
}
