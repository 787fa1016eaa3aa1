//! The fault isolator's fits: the parity residuals under a hypothesis, the weight and the
//! size fit of each fault (module docs of [`crate::isolation`]); the joint isolation over
//! several operating points in `points`, the searches and the ranking in `search`.

mod heating;
mod points;
mod search;
mod weight;
pub use heating::HEATING_LAG_SIGMA_K;
pub use points::{ANCHOR_LOAD_BAND, ANCHOR_TORQUE_SPREAD, LOAD_LAW_SPREAD, MAX_POINTS};
pub use search::SearchHints;

use super::*;
use crate::error::{ensure, ConfigCheck, ConfigError};
use crate::{FaultTarget, SensorChannel};
use search::{fit_factor, rank, ALL_SEEN};

/// A measured point with the magnitudes of its voltage and current vectors
/// ([`fast_hypot`](crate::math::fast_hypot)), computed once for the many hypotheses a
/// search evaluates at it.
#[derive(Debug, Clone, Copy, Default)]
pub(super) struct Reading {
    /// The point (corrected for a sensor hypothesis where one applies).
    pub q: SteadyPoint,
    /// `|V|` of `q` [V].
    pub vmag: f32,
    /// `|I|` of `q` [A].
    pub imag: f32,
}

impl Reading {
    /// The readings of `q`, magnitudes computed.
    #[inline]
    pub fn of(q: &SteadyPoint) -> Self {
        Reading {
            q: *q,
            vmag: crate::math::fast_hypot(q.v.d, q.v.q),
            imag: crate::math::fast_hypot(q.i.d, q.i.q),
        }
    }
}

impl Isolator {
    /// An isolator for the nominal `motor` on a supply of peak phase voltage
    /// `v_phase_peak` [V] and `supply_hz` [Hz].
    ///
    /// # Errors
    /// The motor's [`MotorModel::validate`] error; [`ConfigCheck::PhasePeakVoltage`] or
    /// [`ConfigCheck::IsolationSupplyHz`] for a supply that is not positive and finite;
    /// [`ConfigCheck::IsolationTorqueBase`] when the torque scale
    /// ([`Isolator::torque_base_nm`]) is not positive and finite.
    pub fn new(motor: MotorModel, v_phase_peak: f32, supply_hz: f32) -> Result<Self, ConfigError> {
        motor.validate()?;
        ensure(
            v_phase_peak > 0.0 && v_phase_peak.is_finite(),
            ConfigCheck::PhasePeakVoltage,
        )?;
        ensure(
            supply_hz > 0.0 && supply_hz.is_finite(),
            ConfigCheck::IsolationSupplyHz,
        )?;
        let i_mag = v_phase_peak / (core::f32::consts::TAU * supply_hz * motor.ls_h);
        let torque_base_nm = motor.kf_per_if() * i_mag * i_mag;
        ensure(
            torque_base_nm.is_finite() && torque_base_nm > 0.0,
            ConfigCheck::IsolationTorqueBase,
        )?;
        Ok(Isolator {
            motor,
            torque_base_nm,
            baseline: Baseline::default(),
            learning: Learning::default(),
            heating_factor: 1.0,
            learned_range: crate::OperatingRange::EMPTY,
            heating_reach_k: f32::INFINITY,
            lag_sigma_k: 0.0,
            torque_unknown: false,
        })
    }

    /// The machine judged against: the parameter file's (before any heating tracked).
    pub fn motor(&self) -> &MotorModel {
        &self.motor
    }

    /// The torque scale of `e_T`: `3/2 Np Lm^2/Lr i_mag^2` with the magnetising current
    /// `i_mag = V_peak / (we Ls)` [N m] (the torque at `I_qs = i_ds`, near rated torque for
    /// common motors).
    pub fn torque_base_nm(&self) -> f32 {
        self.torque_base_nm
    }

    /// The tracked winding's resistance factor `1 + alpha dT` (Rs and Rr of the machine
    /// the isolation judges against, relative to the parameter file's): 1 until the
    /// [`Follower`] tracks a heating ([`Isolation::heating_explains`]).
    pub fn heating_factor(&self) -> f32 {
        self.heating_factor
    }

    /// The tracked winding temperature rise since commissioning [K]:
    /// `(heating_factor - 1) / alpha` ([`COPPER_ALPHA_PER_K`]).
    pub fn winding_rise_k(&self) -> f32 {
        (self.heating_factor - 1.0) / COPPER_ALPHA_PER_K
    }

    /// Takes a further heating of factor `k` into the machine judged against (the tracked
    /// factor times `k`, kept within [`HEATING_K_MIN`]..[`HEATING_K_MAX`]); a factor that
    /// is not finite and positive changes nothing.
    pub fn track_heating(&mut self, k: f32) {
        if k.is_finite() && k > 0.0 {
            self.heating_factor = crate::math::minf(
                crate::math::maxf(self.heating_factor * k, HEATING_K_MIN),
                HEATING_K_MAX,
            );
        }
    }

    /// Sets the winding's rise since commissioning to a measured `rise_k` [K] (a
    /// temperature channel: the measured temperature minus the one commissioning saw):
    /// [`Isolator::heating_factor`] becomes `k = 1 + alpha rise_k` ([`COPPER_ALPHA_PER_K`]),
    /// replacing the tracked one. Returns false, and changes nothing, for a rise that is
    /// not finite or whose `k` lies outside [`HEATING_K_MIN`]..[`HEATING_K_MAX`] (25 K
    /// cooler to 160 K warmer than commissioned: no winding heats or cools that far in
    /// service, so the channel is wrong).
    pub fn set_winding_rise_k(&mut self, rise_k: f32) -> bool {
        let k = 1.0 + COPPER_ALPHA_PER_K * rise_k;
        let ok = rise_k.is_finite() && (HEATING_K_MIN..=HEATING_K_MAX).contains(&k);
        if ok {
            self.heating_factor = k;
        }
        ok
    }

    /// The baseline in use.
    pub fn baseline(&self) -> Baseline {
        self.baseline
    }

    /// Puts a baseline into force (for example one stored after commissioning). Spreads
    /// below [`DEFAULT_SPREAD`]'s fifth are raised to it; a learned point `at` that gives
    /// no residuals is forgotten (the baseline then holds everywhere).
    ///
    /// # Errors
    /// [`ConfigCheck::BaselineMean`] or [`ConfigCheck::BaselineSpread`] for a non-finite
    /// value; the baseline in force is kept.
    pub fn set_baseline(&mut self, b: Baseline) -> Result<(), ConfigError> {
        ensure(b.mean.is_finite(), ConfigCheck::BaselineMean)?;
        ensure(b.spread.is_finite(), ConfigCheck::BaselineSpread)?;
        let mut b = b;
        if self.residuals(&b.at, None).is_none() {
            b.at = SteadyPoint::default();
        }
        b.spread = b
            .spread
            .zip_map(DEFAULT_SPREAD, |s, d| crate::math::maxf(s, 0.2 * d));
        self.baseline = b;
        self.learned_range = crate::OperatingRange::EMPTY;
        Ok(())
    }

    /// Adds a healthy operating point to the baseline being learned (commissioning), as
    /// [`Isolator::learn_at`] with the point's time counted as [`super::STEP_S`] per point
    /// (points learned at a steady pace).
    pub fn learn(&mut self, p: &SteadyPoint) {
        let t = self.learning.n as f32 * super::STEP_S;
        self.learn_at(p, t);
    }

    /// Adds a healthy operating point to the baseline being learned (commissioning), `t_s`
    /// [s] after learning began (non-decreasing from point to point). Points that give no
    /// residuals, and non-finite times, are skipped.
    pub fn learn_at(&mut self, p: &SteadyPoint, t_s: f32) {
        let Some(e) = self.residuals(p, None) else {
            return;
        };
        // The heating direction: de/dk for Rs and Rr times k (finite difference).
        let Some(warm) = self.warmer(1.0 + LEARN_DK).residuals(p, None) else {
            return;
        };
        if !t_s.is_finite() {
            return;
        }
        let l = &mut self.learning;
        if l.n == 0 {
            l.shift = e.to_array();
        }
        l.n = l.n.saturating_add(1);
        l.t_last = t_s;
        l.at.approach(p, 1.0 / l.n as f32);
        l.range.learn(p.operating_point());
        for (((sums, shift), x), w) in l
            .sums
            .iter_mut()
            .zip(l.shift)
            .zip(e.to_array())
            .zip(warm.to_array())
        {
            sums.add(x - shift, (w - x) / LEARN_DK * t_s);
        }
    }

    /// Ends learning: the learned mean and twice the learned standard deviation (at least
    /// [`LEARNED_SPREAD_FLOOR`]: a short window's scatter understates what a longer run
    /// meets) go into force. A winding that warmed (or cooled) steadily over the window at
    /// one load is taken out of both (module docs, "Heating during commissioning"): the
    /// mean is the machine's at the window's start, the spread that about the warming
    /// trend, and the tracked heating factor that at the window's end. Returns false, and
    /// keeps the baseline in force, with fewer than [`MIN_LEARNED_POINTS`] points learned
    /// (or non-finite statistics).
    pub fn finish_learning(&mut self) -> bool {
        let l = self.learning;
        self.learning = Learning::default();
        if l.n < MIN_LEARNED_POINTS {
            return false;
        }
        let n = l.n as f32;
        // The warming rate r (x = m + r u) fitted on the three residuals weighted by the
        // default spreads.
        let centred = l.sums.map(|s| s.centred(n));
        let (mut num, mut den, mut ss0) = (0.0, 0.0, 0.0);
        for ((xx, xu, uu), d) in centred.iter().zip(DEFAULT_SPREAD.to_array()) {
            let w = 1.0 / (d * d);
            num += w * xu;
            den += w * uu;
            ss0 += w * xx;
        }
        let r = if den > 0.0 { num / den } else { 0.0 };
        // The trend is a warming only at one load (a load that moved moves the residuals
        // by the file's error), of at least WARMING_K over the window (a healthy window's
        // noise makes trends of a kelvin or two), and where it explains most of the scatter.
        let one_load = l
            .range
            .load_a
            .is_some_and(|[lo, hi]| hi - lo < WIDE_SPAN * crate::math::maxf(lo.abs(), hi.abs()));
        let remaining = ss0 - r * num;
        let rise = -r * l.t_last;
        let warming = one_load
            && r.is_finite()
            && rise.abs() >= COPPER_ALPHA_PER_K * WARMING_K
            && remaining <= (1.0 - WARMING_EXPLAINS) * ss0
            && (HEATING_K_MIN..=HEATING_K_MAX).contains(&(1.0 + rise));
        let r = if warming { r } else { 0.0 };
        let mut spread = [0.0; 3];
        let mut mean = [0.0; 3];
        for ((((s, m), (xx, xu, uu)), (sums, shift)), floor) in spread
            .iter_mut()
            .zip(mean.iter_mut())
            .zip(centred)
            .zip(l.sums.iter().zip(l.shift))
            .zip(LEARNED_SPREAD_FLOOR.to_array())
        {
            let var = crate::math::maxf(xx - 2.0 * r * xu + r * r * uu, 0.0) / (n - 1.0);
            *s = crate::math::maxf(2.0 * crate::math::sqrt(var), floor);
            *m = shift + (sums.x - r * sums.u) / n;
        }
        let ok = self
            .set_baseline(Baseline {
                mean: ParityResiduals::from_array(mean),
                spread: ParityResiduals::from_array(spread),
                at: l.at,
            })
            .is_ok();
        if ok {
            self.learned_range = l.range;
            self.heating_factor = if warming { 1.0 + rise } else { 1.0 };
        }
        ok
    }

    /// The parity residuals at `p` under hypothesis `h` (`None`: the nominal machine and
    /// sensors); `None` when the point is not usable (no voltage or current, frequency
    /// not positive, non-finite values).
    pub fn residuals(&self, p: &SteadyPoint, h: Option<(Fault, f32)>) -> Option<ParityResiduals> {
        let r = self.reading_of(&Reading::of(p), h);
        self.eval_reading(&self.circuit_of(h), &r)
    }

    /// The circuit of hypothesis `h`: the tracked machine's with the parameter fault's
    /// factor applied (a sensor hypothesis leaves the circuit alone and corrects the
    /// readings instead, [`Isolator::reading_of`]).
    #[inline(never)]
    fn circuit_of(&self, h: Option<(Fault, f32)>) -> Circuit {
        let c = self.circuit();
        match h {
            Some((f, k)) if !f.is_sensor() => c.with(f, k, &self.motor),
            _ => c,
        }
    }

    /// The readings `r` corrected for hypothesis `h` (a sensor's gain `k` divided out; the
    /// magnitudes of `r` kept where the vector is not corrected).
    #[inline]
    fn reading_of(&self, r: &Reading, h: Option<(Fault, f32)>) -> Reading {
        let p = r.q;
        match h.map(|(f, k)| (f.target(), k)) {
            Some((FaultTarget::Sensor(SensorChannel::Current), k)) => Reading::of(&SteadyPoint {
                i: Dq {
                    d: p.i.d / k,
                    q: p.i.q / k,
                },
                ..p
            }),
            Some((FaultTarget::Sensor(SensorChannel::Voltage), k)) => Reading::of(&SteadyPoint {
                v: Dq {
                    d: p.v.d / k,
                    q: p.v.q / k,
                },
                ..p
            }),
            Some((FaultTarget::Sensor(SensorChannel::Speed), k)) => Reading {
                q: SteadyPoint {
                    wr_rad_s: p.wr_rad_s / k,
                    ..p
                },
                ..*r
            },
            _ => *r,
        }
    }

    /// The parity residuals of circuit `c` at the (corrected) readings `q` (see
    /// [`Isolator::residuals`]).
    fn eval(&self, c: &Circuit, q: &SteadyPoint) -> Option<ParityResiduals> {
        self.eval_reading(c, &Reading::of(q))
    }

    /// [`Isolator::eval`] of readings whose magnitudes are already known: the searches
    /// evaluate one point under many hypotheses, and the parameter faults leave the
    /// readings (and so `|V|`, `|I|`) as they are.
    #[inline(never)]
    fn eval_reading(&self, c: &Circuit, r: &Reading) -> Option<ParityResiduals> {
        let q = &r.q;
        let (i, v, we, wr) = (q.i, q.v, q.we_rad_s, q.wr_rad_s);
        let (vmag, imag) = (r.vmag, r.imag);
        if !(we > 0.0 && vmag > 0.0 && imag > 0.0 && wr.is_finite()) {
            return None;
        }
        let ws = we - wr;
        // 1 / (Rr + j ws Lr) = (Rr - j ws Lr) / den
        let den = c.rr * c.rr + ws * ws * c.lr * c.lr;
        let (yr, yi) = (c.rr / den, -ws * c.lr / den);
        let g = we * ws * c.lm * c.lm;
        let z_re = c.rs + g * yr;
        let z_im = we * c.ls + g * yi;
        let vp_d = z_re * i.d - z_im * i.q;
        let vp_q = z_re * i.q + z_im * i.d;
        // Ir = -j ws Lm I / (Rr + j ws Lr): (-j ws Lm) * (yr + j yi) * I
        let (a_re, a_im) = (ws * c.lm * yi, -ws * c.lm * yr);
        let ir_d = a_re * i.d - a_im * i.q;
        let ir_q = a_re * i.q + a_im * i.d;
        // Te = 3/2 Np Im(conj(Lm Ir) I) = 3/2 Np Lm (ir_d i_q - ir_q i_d)
        let te = 1.5 * c.np * c.lm * (ir_d * i.q - ir_q * i.d);
        let tl = c.b_total * wr / c.np;
        let e = ParityResiduals {
            voltage_d: (v.d - vp_d) / vmag,
            voltage_q: (v.q - vp_q) / vmag,
            torque: (te - tl) / self.torque_base_nm,
        };
        e.is_finite().then_some(e)
    }

    /// [`Isolator::isolate`] with the baseline's spreads multiplied by `spread_scale`
    /// (>= 1; values below 1 or not finite count as 1): a point averaged for a shorter time
    /// scatters more ([`Follower`]: `sqrt(AVERAGE_MAX_S / averaged)`).
    pub fn isolate_scaled(&self, p: &SteadyPoint, spread_scale: f32) -> Isolation {
        self.isolate_scaled_from(p, spread_scale, &mut SearchHints::default())
    }

    /// [`Isolator::isolate_scaled`] with each fault's size searched from where `hints` say
    /// it was found the last time, and `hints` updated (module docs, "Searches started
    /// from the last result").
    pub fn isolate_scaled_from(
        &self,
        p: &SteadyPoint,
        spread_scale: f32,
        hints: &mut SearchHints,
    ) -> Isolation {
        let k = if spread_scale.is_finite() {
            crate::math::maxf(spread_scale, 1.0)
        } else {
            1.0
        };
        let mut scaled = *self;
        scaled.baseline.spread = scaled.baseline.spread.map(|s| s * k);
        scaled.isolate_from(p, hints)
    }

    /// Isolates the fault at the steady operating point `p` (module docs). Never panics;
    /// an unusable point gives [`IsolationState::NotJudged`].
    pub fn isolate(&self, p: &SteadyPoint) -> Isolation {
        self.isolate_from(p, &mut SearchHints::default())
    }

    /// [`Isolator::isolate`] with the size searches started from `hints`
    /// ([`Isolator::isolate_scaled_from`]).
    pub fn isolate_from(&self, p: &SteadyPoint, hints: &mut SearchHints) -> Isolation {
        let mut out = Isolation::default();
        let Some(e0) = self.residuals(p, None) else {
            return out;
        };
        let b = self.baseline;
        out.residuals = e0 - b.mean;
        let w = self.weight(p);
        // Against the parameter file's nominal values, with the load an unknown input, the
        // torque balance (true only for the file's load) is left out.
        let w = match self.torque_unknown && !self.learned_point() {
            true => w.voltage_only().unwrap_or(w),
            false => w,
        };
        let r = Reading::of(p);
        let chi0 = self.chi2_at(&r, None, &w);
        out.deviation = crate::math::sqrt(chi0);
        if chi0 < DETECT_CHI2 {
            out.state = IsolationState::NoDeviation;
            return out;
        }
        let mut fits = [(0.0f32, 1.0f32); FAULT_COUNT];
        let use_hints = hints.begin(self.hint_at(&out), 1);
        for (fit, f) in fits.iter_mut().zip(Fault::ALL) {
            let (found, hint) = self.fit(&r, f, &w, hints.get(f, use_hints));
            *fit = found;
            hints.set(f, hint);
        }
        let heat = self.fit_heating(&r, &w);
        let eps = self.direction_uncertainty();
        if self.temperature_unknown() {
            // A winding of unknown temperature (module docs, "The temperature unknown"):
            // each fault at any temperature of the heating range, and named only for what
            // it explains beyond the heating.
            let seen = self.fits_beyond_heating(
                &mut fits,
                heat,
                |iso, f, k| iso.chi2_at(&r, Some((f, k)), &w),
                (hints, use_hints),
            );
            rank(&mut out, &mut fits, heat, (chi0, 3.0), eps, &seen);
            heating_not_unknown(&mut out);
        } else {
            rank(&mut out, &mut fits, heat, (chi0, 3.0), eps, &ALL_SEEN);
            // On a warm machine a fault is judged with the tracked temperature's lag
            // allowed for (heating itself is decided on the single fits above).
            if !out.heating_explains() {
                for (fit, f) in fits.iter_mut().zip(Fault::ALL) {
                    *fit = self.fit_on_warm(&r, f, &w, (*fit, hints.get(f, use_hints)));
                }
                rank(&mut out, &mut fits, heat, (chi0, 3.0), eps, &ALL_SEEN);
            }
        }
        out.separation_deg = self.separation(p, &e0, &out.candidates);
        out
    }

    /// Where the deviation of `out` lies, for [`SearchHints::begin`]: its residuals in
    /// spreads and its misfit's root.
    pub(super) fn hint_at(&self, out: &Isolation) -> [f32; 4] {
        let [d, q, t] = out
            .residuals
            .zip_map(self.baseline.spread, |e, s| e / s)
            .to_array();
        [d, q, t, out.deviation]
    }

    /// Whether the load is an unknown input (`diagnose`'s default): then, against the
    /// parameter file's nominal values (no learned baseline), the single point is judged on
    /// the stator-voltage equations alone, as the joint isolation always is; the torque
    /// balance holds only for the file's load. Against a learned baseline the torque's
    /// learned mean holds the commissioned load, and a load that moves reads as the
    /// friction class (module docs, "The load before the deviation").
    pub fn set_load_unknown(&mut self, unknown: bool) {
        self.torque_unknown = unknown;
    }

    /// A learned baseline with its operating point is in force.
    pub(super) fn learned_point(&self) -> bool {
        self.residuals(&self.baseline.at, None).is_some()
    }

    /// The smallest relative change of fault `f` the isolation detects at the operating
    /// point `p` on a full average ([`super::AVERAGE_MAX_S`]): the change `dk` at which the
    /// deviation from the baseline reaches [`DETECT_CHI2`], linearised,
    /// `dk = sqrt(DETECT_CHI2 / (d^T W d))` with `d = de/dk` (a finite difference of
    /// [`LIMIT_DK`]) and `W` the weight the isolation judges `p` with (the baseline's spreads,
    /// widened away from the commissioned point). A fault smaller than this is not seen:
    /// with a learned baseline it is the commissioning's own detection limit for that fault
    /// (for the 50 hp motor's Rs, a few tenths: Rs is under 1 % of its impedance). `None`
    /// where the point gives no residuals or the fault does not move them.
    pub fn detection_limit(&self, p: &SteadyPoint, f: Fault) -> Option<f32> {
        let w = self.weight(p);
        let e0 = self.residuals(p, None)?;
        let e1 = self.residuals(p, Some((f, 1.0 + LIMIT_DK)))?;
        let q = w.quadratic(&(e1 - e0)) / (LIMIT_DK * LIMIT_DK);
        (q.is_finite() && q > 0.0).then(|| crate::math::sqrt(DETECT_CHI2 / q))
    }

    /// The misfit of hypothesis `h` (fault `f` of factor `k`; `None`: the healthy machine)
    /// against the baseline under the weight `w` ([`Isolator::weight`] at the measured
    /// point, one for every hypothesis so that their misfits compare); unusable points
    /// count as infinitely bad. `r`: the measured point with its magnitudes.
    #[inline(never)]
    fn chi2_at(&self, r: &Reading, h: Option<(Fault, f32)>, w: &Sym3) -> f32 {
        self.chi2_of(
            self.eval_reading(&self.circuit_of(h), &self.reading_of(r, h)),
            w,
        )
    }

    /// The misfit of residuals `e` against the baseline under the weight `w`; infinite
    /// for no residuals (an unusable point).
    #[inline]
    fn chi2_of(&self, e: Option<ParityResiduals>, w: &Sym3) -> f32 {
        match e {
            Some(e) => w.quadratic(&(e - self.baseline.mean)),
            None => f32::INFINITY,
        }
    }

    /// Best factor `k` for fault `f`: geometric grid, then golden section around the best
    /// grid point ([`fit_factor`], from the grid point `hint`). Returns `(chi2, k)` and the
    /// hint for the next search. Not inlined: one copy for the nine faults keeps the
    /// firmware's flash small (it runs in thread mode, where a call costs nothing).
    #[inline(never)]
    fn fit(&self, r: &Reading, f: Fault, w: &Sym3, hint: u8) -> ((f32, f32), u8) {
        fit_factor(|k| self.chi2_at(r, Some((f, k)), w), hint)
    }

    /// Angle between the top two candidates' weighted directions `e(f, k*) - e(nominal)`
    /// [deg]; 180 when either direction is empty.
    fn separation(
        &self,
        p: &SteadyPoint,
        e0: &ParityResiduals,
        c: &[Candidate; FAULT_COUNT],
    ) -> f32 {
        let dir = |cand: Option<&Candidate>| -> Option<[f32; 3]> {
            let cand = cand?;
            let e = self.residuals(p, Some((cand.fault, 1.0 + cand.change)))?;
            Some(
                (e - *e0)
                    .zip_map(self.baseline.spread, |d, s| d / s)
                    .to_array(),
            )
        };
        let (Some(a), Some(b)) = (dir(c.first()), dir(c.get(1))) else {
            return 180.0;
        };
        let dot: f32 = a.iter().zip(b).map(|(x, y)| x * y).sum();
        let na = crate::math::sqrt(a.iter().map(|x| x * x).sum());
        let nb = crate::math::sqrt(b.iter().map(|x| x * x).sum());
        if !(na > 0.0 && nb > 0.0) {
            return 180.0;
        }
        let cos = crate::math::minf(crate::math::maxf(dot / (na * nb), -1.0), 1.0);
        F32Ext::acos(cos).to_degrees()
    }

    /// The nominal circuit at the tracked winding temperature (Rs and Rr times
    /// [`Isolator::heating_factor`]).
    fn circuit(&self) -> Circuit {
        let m = &self.motor;
        Circuit {
            rs: m.rs_ohm * self.heating_factor,
            rr: m.rr_ohm * self.heating_factor,
            ls: m.ls_h,
            lr: m.lr_h,
            lm: m.lm_h,
            np: m.np(),
            b_total: m.b_nms + m.bl_nms,
        }
    }
}

/// On a winding of unknown temperature, a deviation the heating explains better than the
/// unknown fault is not an unknown fault, though no fault is more probable (the faults
/// that explain nothing beyond the heating take no part in the ranking).
pub(super) fn heating_not_unknown(out: &mut Isolation) {
    if out.state == IsolationState::Unknown && out.heating.probability > out.unknown_probability {
        out.state = IsolationState::Isolated;
    }
}
