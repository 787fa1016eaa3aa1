//! A user's law ([`monitor_laws::Law`], `--laws FILE`) as an entry of the effect library:
//! set up, fitted, judged and reported as the library's effects are.
//!
//! Where it acts decides what it writes into the model ([`ModelTerms`]):
//! - `load_torque`: a shaft torque of the sample's time `t`, the model's speed `w` and the
//!   shaft's angle `theta` (integrated from the log's measured speed, 0 at the analysed
//!   span's first sample), added to eq. (29)'s torque balance;
//! - `stator_resistance`, `rotor_resistance`: the resistance per sample over the parameter
//!   file's value, on Rs, or on Rr alone (both scaled, the stator's scale divided back);
//! - `magnetising_inductance`: Lm of the magnetising flux, as the library's saturation
//!   acts: per sample from the measured magnetising current in the reduced model
//!   (`psi_m = Lm(psi_m) |i_f|`, solved on a grid of currents and interpolated), and on the
//!   model's own flux in the full-order model ([`MagnetisingLaw::Shape`]);
//! - `magnetising_curve`: a no-load test's curve is the stator inductance Ls of the stator
//!   flux (`psi_s = sqrt(V^2 - (Rs I)^2) / w`, `Ls = psi_s / I`: what the test measures,
//!   whatever split of the leakage the file holds), so the full-order model saturates
//!   the Gamma-equivalent circuit (no stator leakage, the machine's transient inductance
//!   on the rotor side) on its stator flux; the reduced model takes `Ls - Lls` as its Lm.
//!
//! Its parameters are fitted from their start within their bounds (which are also their
//! physical range: a value pinned at a bound is refused as the library's are); a parameter
//! in radians is also started a quarter and a half turn away (an amplitude and a phase
//! started half a turn off descend to the amplitude's zero bound). A law that gives no
//! number (NaN or infinity) on the log is refused as a candidate with that reason.

use super::{
    About, Contribution, EffectModel, EffectParam, EffectValuesError, FitParam, FitSetup, Needs,
    SetupError,
};
use crate::prep::Prepared;
use crate::simplified_model::{
    LmShape, MachineConstants, MagnetisingLaw, ModelTerms, SampleTorque,
};
use monitor_laws::{ActsOn, Law, LawInputs, MagnetisingCurve, Variable};
use std::sync::Arc;

/// Where a user's law's physical range comes from.
const BASIS: &str = "the bounds of the law file";

/// Points of the grid of magnetising currents the reduced model's Lm is interpolated on.
const LM_GRID: usize = 512;

/// A user's law as an effect (module doc).
#[derive(Debug, Clone)]
pub struct LawEffect {
    law: Arc<Law>,
    about: About,
    params: Vec<EffectParam>,
}

impl LawEffect {
    /// The effect of the law `law`.
    pub fn new(law: Arc<Law>) -> Self {
        let params = law
            .params
            .iter()
            .map(|p| EffectParam {
                name: p.name,
                unit: p.unit,
                doc: "a parameter of the user's law",
                range: (p.low, p.high),
                per: None,
                basis: BASIS,
            })
            .collect();
        let about = About {
            kind: law.id,
            description: "",
            equations: "",
            parameters: &[],
        };
        LawEffect { law, about, params }
    }

    /// The law.
    pub fn law(&self) -> &Arc<Law> {
        &self.law
    }
}

/// The shaft's angle [rad] at each sample of `d`: the measured speed integrated by the
/// trapezoidal rule from 0 at the first sample (empty without a speed).
fn shaft_angle(d: &Prepared, np: f64) -> Vec<f64> {
    if d.omega_r.len() != d.len() || np <= 0.0 {
        return Vec::new();
    }
    let mut theta = Vec::with_capacity(d.len());
    let mut acc = 0.0;
    for k in 0..d.len() {
        if k > 0 {
            let dt = d.t_s[k] - d.t_s[k - 1];
            acc += 0.5 * (d.omega_r[k] + d.omega_r[k - 1]) / np * dt;
        }
        theta.push(acc);
    }
    theta
}

/// The law's inputs at sample `k` of `d` with the shaft's angle `theta` and the speed `w`.
fn inputs(d: &Prepared, theta: &[f64], k: usize, w: f64) -> LawInputs {
    LawInputs {
        t_s: d.t_s.get(k).copied().unwrap_or(0.0),
        w_rad_s: w,
        theta_rad: theta.get(k).copied().unwrap_or(0.0),
        psi_m_wb: 0.0,
    }
}

/// The measured mechanical speed at sample `k` (0 without one).
fn measured_w(d: &Prepared, np: f64, k: usize) -> f64 {
    d.omega_r.get(k).map_or(0.0, |w| w / np.max(1e-9))
}

impl EffectModel for LawEffect {
    fn about(&self) -> &About {
        &self.about
    }
    fn description(&self) -> &str {
        self.law
            .expression()
            .unwrap_or("a no-load test's magnetising curve")
    }
    fn equations(&self) -> &str {
        self.law.acts_on.name()
    }
    fn parameters(&self) -> &[EffectParam] {
        &self.params
    }
    /// The shaft's angle comes from the measured speed.
    fn needs(&self) -> Needs {
        if self.law.uses(Variable::Theta) {
            Needs::VOLTAGES_AND_SPEED
        } else {
            Needs::VOLTAGES
        }
    }
    /// A load torque of the speed carries its speed-dependent part itself.
    fn takes_viscous_part(&self) -> bool {
        self.law.acts_on == ActsOn::LoadTorque && self.law.uses(Variable::W)
    }
    /// A load law of the speed alone (no `t`, no `theta`).
    fn load_torque_at(&self, values: &[f64], w_rad_s: f64) -> Option<f64> {
        let of_speed_alone = self.law.acts_on == ActsOn::LoadTorque
            && !self.law.uses(Variable::T)
            && !self.law.uses(Variable::Theta);
        let x = LawInputs {
            t_s: 0.0,
            w_rad_s,
            theta_rad: 0.0,
            psi_m_wb: 0.0,
        };
        of_speed_alone
            .then(|| self.law.eval(values, &x))
            .filter(|v| v.is_finite())
    }
    /// A law that gives no number on this log at the fitted values.
    fn contradicted_by(
        &self,
        d: &Prepared,
        n: &MachineConstants,
        fitted: &[f64],
    ) -> Result<Option<String>, EffectValuesError> {
        self.check(fitted)?;
        Ok(self.not_finite(d, n, fitted).map(|t| {
            format!("the law gives no number (NaN or infinity) at t = {t:.3} s with these values")
        }))
    }
    fn setup(&self, d: &Prepared, n: &MachineConstants) -> Result<FitSetup, SetupError> {
        self.needs().met_by(d)?;
        let params: Vec<FitParam> = self
            .params
            .iter()
            .zip(&self.law.params)
            .map(|(e, p)| {
                let scale = if p.start != 0.0 {
                    p.start.abs()
                } else {
                    0.1 * (p.high - p.low)
                };
                e.fit(p.start, (p.low, p.high), scale.max(1e-300), 1.0)
            })
            .collect();
        let starts: Vec<f64> = params.iter().map(|p| p.init).collect();
        if self.not_finite(d, n, &starts).is_some() {
            return Err(SetupError::NotFinite);
        }
        let curve = match self.law.table() {
            Some(t) => Some(Arc::new(
                t.curve(n.rs_ohm, 0.0, n.v_phase_peak * 1.5f64.sqrt(), n.f_hz)
                    .map_err(|_| {
                        SetupError::NothingToFit(
                            "the no-load table does not fit the parameter file's machine",
                        )
                    })?,
            )),
            None => None,
        };
        let alt = self.alt_starts(&starts);
        let on_log = LawOnLog {
            law: Arc::clone(&self.law),
            curve,
        };
        Ok(FitSetup::new(on_log, params)?.with_alt_init(alt)?)
    }
}

impl LawEffect {
    /// `values` checked against the law's parameters.
    fn check(&self, values: &[f64]) -> Result<(), EffectValuesError> {
        if values.len() == self.law.params.len() {
            Ok(())
        } else {
            Err(EffectValuesError::Count {
                effect: self.law.id,
                expected: self.law.params.len(),
                got: values.len(),
            })
        }
    }

    /// The first time of `d` where the law at `values` gives no number (the load torque at
    /// the measured speed, a resistance, Lm over the log's range of flux).
    fn not_finite(&self, d: &Prepared, n: &MachineConstants, values: &[f64]) -> Option<f64> {
        let theta = shaft_angle(d, n.np);
        let psi_hi = 2.0 * n.lm_h * d.i_f.iter().fold(0.0f64, |a, i| a.max(i.abs()));
        (0..d.len()).step_by(1 + d.len() / 2000).find_map(|k| {
            let mut x = inputs(d, &theta, k, measured_w(d, n.np, k));
            x.psi_m_wb = psi_hi * k as f64 / d.len().max(1) as f64;
            let v = match self.law.acts_on {
                ActsOn::MagnetisingCurve => 1.0,
                _ => self.law.eval(values, &x),
            };
            (!v.is_finite()).then_some(x.t_s)
        })
    }

    /// Other starts for the parameters in radians: a quarter and a half turn away, kept
    /// within their bounds.
    fn alt_starts(&self, starts: &[f64]) -> Vec<Vec<f64>> {
        let mut out = Vec::new();
        for (i, p) in self.law.params.iter().enumerate() {
            if p.unit != "rad" {
                continue;
            }
            for shift in [0.5, 1.0, -0.5] {
                let mut s = starts.to_vec();
                let mut v = p.start + shift * std::f64::consts::PI;
                let span = p.high - p.low;
                if span >= 2.0 * std::f64::consts::PI {
                    while v > p.high {
                        v -= 2.0 * std::f64::consts::PI;
                    }
                    while v < p.low {
                        v += 2.0 * std::f64::consts::PI;
                    }
                }
                s[i] = v.clamp(p.low, p.high);
                if s[i] != p.start {
                    out.push(s);
                }
            }
        }
        out
    }
}

/// A user's law set up on a log.
struct LawOnLog {
    law: Arc<Law>,
    /// A no-load table's curve for the file's machine.
    curve: Option<Arc<MagnetisingCurve>>,
}

/// A user's load torque on the shaft: the law at the sample's time and shaft angle and the
/// model's speed.
#[derive(Debug)]
struct LawTorque {
    law: Arc<Law>,
    values: Vec<f64>,
    t_s: Arc<[f64]>,
    theta: Arc<[f64]>,
}

impl SampleTorque for LawTorque {
    #[inline]
    fn torque_nm(&self, k: usize, wm_rad_s: f64) -> f64 {
        let x = LawInputs {
            t_s: self.t_s.get(k).copied().unwrap_or(0.0),
            w_rad_s: wm_rad_s,
            theta_rad: self.theta.get(k).copied().unwrap_or(0.0),
            psi_m_wb: 0.0,
        };
        self.law.eval(&self.values, &x)
    }
}

impl LawOnLog {
    /// Lm [H] at the flux `psi` [Wb] for `values`.
    fn lm_at(&self, values: &[f64], psi: f64) -> f64 {
        match &self.curve {
            Some(c) => c.lm_h(psi),
            None => self.law.eval(
                values,
                &LawInputs {
                    psi_m_wb: psi,
                    ..LawInputs::default()
                },
            ),
        }
    }

    /// Lm over the file's at each sample's measured magnetising current (the reduced
    /// model's scale), and the law's shape for the full-order model.
    fn magnetising(&self, values: &[f64], d: &Prepared, n: &MachineConstants, t: &mut ModelTerms) {
        // A no-load curve is Ls of the stator flux: Lm is Ls less the file's stator leakage.
        let stator = self.curve.is_some();
        let lls = if stator { n.lls_h } else { 0.0 };
        let lm0 = self.lm_at(values, 0.0);
        let lm = |psi: f64| self.lm_at(values, psi);
        let i_max = 1.05 * d.i_f.iter().fold(0.0f64, |a, i| a.max(i.abs())) + 1e-9;
        let grid: Vec<f64> = (0..LM_GRID)
            .map(|j| {
                let i = i_max * j as f64 / (LM_GRID - 1) as f64;
                solve_flux(&lm, lm0, i) / i.max(1e-12)
            })
            .collect();
        let at = |i: f64| {
            let x = (i.abs() / i_max * (LM_GRID - 1) as f64).min((LM_GRID - 1) as f64);
            let j = (x.floor() as usize).min(LM_GRID - 2);
            let f = x - j as f64;
            let (a, b) = (grid[j.max(1)], grid[(j + 1).max(1)]);
            if j == 0 {
                lm0 + (b - lm0) * f
            } else {
                a + (b - a) * f
            }
        };
        t.scale_magnetising_inductance(d.i_f.iter().map(|&i| (at(i) - lls).max(1e-9) / n.lm_h));
        let (law, curve, values) = (Arc::clone(&self.law), self.curve.clone(), values.to_vec());
        let shape = move |psi: f64| {
            let l = match &curve {
                Some(c) => c.lm_h(psi),
                None => law.eval(
                    &values,
                    &LawInputs {
                        psi_m_wb: psi,
                        ..LawInputs::default()
                    },
                ),
            };
            l / lm0
        };
        t.magnetising.law = Some(MagnetisingLaw::Shape(LmShape {
            shape: Arc::new(shape),
            lm0_over_file: (lm0 - lls).max(1e-9) / n.lm_h,
            stator,
        }));
    }
}

/// The flux `psi` [Wb] with `psi = lm(psi) i` at the magnetising current `i` [A] (`lm0` the
/// law at zero flux): the secant method kept in the bracket `0 ..= 2 lm0 i` (bisection
/// where a step leaves it), to 1e-12 relative.
fn solve_flux(lm: &dyn Fn(f64) -> f64, lm0: f64, i: f64) -> f64 {
    if i <= 0.0 || lm0.is_nan() || lm0 <= 0.0 {
        return 0.0;
    }
    let g = |p: f64| p - lm(p) * i;
    let (mut lo, mut hi) = (0.0, 2.0 * lm0 * i);
    let (mut p0, mut p1) = (0.5 * lm0 * i, lm0 * i);
    let mut g0 = g(p0);
    for _ in 0..80 {
        let g1 = g(p1);
        if !g1.is_finite() {
            return f64::NAN;
        }
        if g1 > 0.0 {
            hi = p1;
        } else {
            lo = p1;
        }
        let mut p2 = if g1 != g0 {
            p1 - g1 * (p1 - p0) / (g1 - g0)
        } else {
            0.5 * (lo + hi)
        };
        if !(p2 > lo && p2 < hi) {
            p2 = 0.5 * (lo + hi);
        }
        let done = (p2 - p1).abs() <= 1e-12 * p2.abs().max(1e-30);
        (p0, g0, p1) = (p1, g1, p2);
        if done {
            break;
        }
    }
    p1
}

impl Contribution for LawOnLog {
    type Values = Vec<f64>;
    fn values(&self, v: &[f64]) -> Result<Vec<f64>, EffectValuesError> {
        if v.len() == self.law.params.len() {
            Ok(v.to_vec())
        } else {
            Err(EffectValuesError::Count {
                effect: self.law.id,
                expected: self.law.params.len(),
                got: v.len(),
            })
        }
    }
    fn contribute(&self, p: &Vec<f64>, d: &Prepared, n: &MachineConstants, t: &mut ModelTerms) {
        let at_t = |tt: f64| LawInputs {
            t_s: tt,
            ..LawInputs::default()
        };
        match self.law.acts_on {
            ActsOn::LoadTorque => t.add_sample_torque(LawTorque {
                law: Arc::clone(&self.law),
                values: p.clone(),
                t_s: Arc::from(d.t_s.as_slice()),
                theta: Arc::from(shaft_angle(d, n.np)),
            }),
            ActsOn::StatorResistance => t.scale_stator_resistance(
                d.t_s
                    .iter()
                    .map(|&tt| self.law.eval(p, &at_t(tt)) / n.rs_ohm),
            ),
            ActsOn::RotorResistance => {
                let f: Vec<f64> = d
                    .t_s
                    .iter()
                    .map(|&tt| self.law.eval(p, &at_t(tt)) / n.rr_ohm)
                    .collect();
                t.scale_resistances(f.iter().copied());
                t.scale_stator_resistance(f.iter().map(|x| 1.0 / x));
            }
            ActsOn::MagnetisingInductance | ActsOn::MagnetisingCurve => {
                self.magnetising(p, d, n, t)
            }
        }
    }
    fn describe(&self, p: &Vec<f64>, _d: &Prepared, _n: &MachineConstants) -> String {
        let values: Vec<String> = self
            .law
            .params
            .iter()
            .zip(p)
            .map(|(q, v)| {
                super::setup::with_unit(&format!("{} = {}", q.name, super::sig(*v)), q.unit)
            })
            .collect();
        if values.is_empty() {
            format!("the law of {} as given", self.law.acts_on)
        } else {
            values.join(", ")
        }
    }
}

/// The law's identity (for the tests).
#[cfg(test)]
fn id_of(e: &LawEffect) -> monitor_laws::EffectId {
    e.law.id
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_flux_solves_its_law() {
        let lm = |p: f64| 0.3 / (1.0 + (p / 1.0f64).powi(6));
        for i in [0.5, 2.0, 4.0, 8.0] {
            let p = solve_flux(&lm, 0.3, i);
            assert!((p - lm(p) * i).abs() < 1e-9, "{i}: {p}");
        }
        assert_eq!(solve_flux(&lm, 0.3, 0.0), 0.0);
    }

    #[test]
    fn a_phase_is_also_started_a_quarter_and_half_turn_away() {
        let f = monitor_laws::LawFile::parse(
            "[[law]]\nname = \"c\"\nacts_on = \"load_torque\"\nexpr = \"t0 + a * sin(theta + phi)\"\n[law.parameters]\nt0 = { start = 5.0, low = 0.0, high = 40.0 }\na = { start = 1.0, low = 0.0, high = 20.0 }\nphi = { start = 0.5, low = -3.1416, high = 3.1416, unit = \"rad\" }\n",
            std::path::Path::new("l.toml"),
        )
        .unwrap();
        let e = LawEffect::new(Arc::clone(&f.laws[0]));
        assert_eq!(id_of(&e).name(), "c");
        let alt = e.alt_starts(&[5.0, 1.0, 0.5]);
        assert_eq!(alt.len(), 3);
        for s in &alt {
            assert!(
                (-std::f64::consts::PI..=std::f64::consts::PI).contains(&s[2]) && s[2] != 0.5,
                "{s:?}"
            );
            assert_eq!(&s[..2], &[5.0, 1.0]);
        }
    }
}
