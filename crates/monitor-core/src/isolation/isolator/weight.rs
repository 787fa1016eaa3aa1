//! The isolator's weights (module docs of [`crate::isolation`], "Away from the learned
//! point"): the residuals' covariance at a point, widened for the parameter file's error
//! away from where the baseline was learned, and how far off the file is.

use super::*;

impl Isolator {
    /// The measured point `q` lies within the load span the baseline was learned over, and
    /// that span is a range ([`WIDE_SPAN`]), with the voltage within the learned range's
    /// margin (module docs, "Over a commissioned range").
    pub(super) fn within_learned_span(&self, q: &SteadyPoint) -> bool {
        let r = self.learned_range;
        let p = q.operating_point();
        match r.load_a {
            Some([lo, hi]) => {
                let wide = hi - lo >= WIDE_SPAN * crate::math::maxf(lo.abs(), hi.abs());
                wide && p.load_a >= lo && p.load_a <= hi && r.voltage_outside(p).is_none()
            }
            None => false,
        }
    }

    /// The weight (inverse covariance) of the residuals at the measured point `q`: the
    /// inverse of [`Isolator::covariance`], or `D^-1` where it has none.
    #[inline(never)]
    pub(super) fn weight(&self, q: &SteadyPoint) -> Sym3 {
        let diag = Sym3::diagonal_weight(&self.baseline.spread);
        self.covariance(q).and_then(|c| c.inverse()).unwrap_or(diag)
    }

    /// The weight at `q` with the tracked temperature's lag allowed for as an uncertain
    /// offset along the heating direction `h` (per kelvin): the inverse of
    /// `S + sigma_lag^2 h h^T` ([`Isolator::set_heating_reach_k`]), and `h`'s torque part
    /// times `sigma_lag` (the lag's effect on the torque balance) (the joint isolation,
    /// module docs, "Evidence across operating points").
    pub(super) fn weight_with_lag(&self, q: &SteadyPoint) -> (Sym3, f32) {
        let s = self.baseline.spread;
        let diag = Sym3::diagonal_weight(&s);
        let [a, b, z] = s.to_array();
        let mut cov = self.covariance(q).unwrap_or(Sym3 {
            xx: a * a,
            yy: b * b,
            zz: z * z,
            ..Sym3::default()
        });
        let dk = COPPER_ALPHA_PER_K;
        let h = match (
            self.warmer(1.0 + dk).residuals(q, None),
            self.residuals(q, None),
        ) {
            (Some(w), Some(e)) => (w - e).map(|x| x * self.lag_sigma_k),
            _ => return (diag, 0.0),
        };
        cov.add_outer(&h);
        (cov.inverse().unwrap_or(diag), h.torque)
    }

    /// The residuals' covariance at the measured point `q`: `S = D + sum_j d_j d_j^T`,
    /// `D = diag(spread^2)`, with `d_j` how much more the residuals move at `q` than at the
    /// learned point when circuit parameter `j` (Rs, Rr, the leakages, Lm) is off by the
    /// evidenced fraction of [`NAMEPLATE_UNCERTAINTY`] ([`Isolator::nameplate_fraction`];
    /// module docs, "Away from the learned point"). `None` (the weight is then `D^-1`)
    /// within the commissioned span, without a learned point, or where a point is not
    /// usable.
    pub(super) fn covariance(&self, q: &SteadyPoint) -> Option<Sym3> {
        if self.within_learned_span(q) {
            return None;
        }
        let (at, c0) = (self.baseline.at, self.circuit());
        let (e_here, e_at) = (self.eval(&c0, q)?, self.eval(&c0, &at)?);
        let u = self.nameplate_fraction()?;
        let [a, b, z] = self.baseline.spread.to_array();
        let mut cov = Sym3 {
            xx: a * a,
            yy: b * b,
            zz: z * z,
            ..Sym3::default()
        };
        for j in 0..5 {
            let c = c0.nameplate_off(j);
            let dj = (self.eval(&c, q)? - e_here) - (self.eval(&c, &at)? - e_at);
            cov.add_outer(&dj.map(|x| u * x));
        }
        Some(cov)
    }

    /// The relative uncertainty of the fault directions (module docs, "How sure a name
    /// is"): [`DIRECTION_UNCERTAINTY`] against a learned baseline, [`NOMINAL_UNCERTAINTY`]
    /// against the parameter file's nominal values (no learned point).
    pub(super) fn direction_uncertainty(&self) -> f32 {
        match self.nameplate_fraction() {
            Some(u) => DIRECTION_UNCERTAINTY * NAMEPLATE_UNCERTAINTY * u,
            None => NAMEPLATE_UNCERTAINTY,
        }
    }

    /// How far off the parameter file is, as a fraction of [`NAMEPLATE_UNCERTAINTY`]
    /// (module docs, "Away from the learned point"): the learned mean of the voltage
    /// residuals against what a [`NAMEPLATE_UNCERTAINTY`] error of each parameter would
    /// leave at the learned point, between [`NAMEPLATE_FLOOR`] and 1; `None` without a
    /// learned point.
    pub(super) fn nameplate_fraction(&self) -> Option<f32> {
        let (at, c0) = (self.baseline.at, self.circuit());
        let e_at = self.eval(&c0, &at)?;
        let mut expected = 0.0f32;
        for j in 0..5 {
            let g = self.eval(&c0.nameplate_off(j), &at)? - e_at;
            expected += g.voltage_d * g.voltage_d + g.voltage_q * g.voltage_q;
        }
        let (md, mq) = (self.baseline.mean.voltage_d, self.baseline.mean.voltage_q);
        let seen = crate::math::sqrt((md * md + mq * mq) / expected);
        Some(if seen.is_finite() {
            crate::math::minf(crate::math::maxf(seen, NAMEPLATE_FLOOR), 1.0)
        } else {
            1.0
        })
    }
}
