//! The machine's circuit under a hypothesis, and the 3 x 3 algebra of the residuals.

use super::*;
use crate::{FaultTarget, MachineParameter};

/// The machine's circuit parameters under a hypothesis.
#[derive(Debug, Clone, Copy)]
pub(super) struct Circuit {
    pub(super) rs: f32,
    pub(super) rr: f32,
    pub(super) ls: f32,
    pub(super) lr: f32,
    pub(super) lm: f32,
    pub(super) np: f32,
    pub(super) b_total: f32,
}

/// A symmetric 3 x 3 matrix (covariance or weight of [`ParityResiduals`]).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub(super) struct Sym3 {
    pub(super) xx: f32,
    pub(super) xy: f32,
    pub(super) xz: f32,
    pub(super) yy: f32,
    pub(super) yz: f32,
    pub(super) zz: f32,
}

impl Sym3 {
    /// The weight of the two voltage residuals alone, the torque balance left out (the load
    /// as an unknown input): the inverse of the d-q block of this weight's covariance, with
    /// zero weight on `e_T`; `None` when a matrix is singular.
    pub(super) fn voltage_only(&self) -> Option<Self> {
        let mut s = self.inverse()?;
        s.xz = 0.0;
        s.yz = 0.0;
        s.zz = 1.0;
        let mut w = s.inverse()?;
        w.xz = 0.0;
        w.yz = 0.0;
        w.zz = 0.0;
        Some(w)
    }

    /// `diag(1/s^2)`: the weight of independent spreads `s`.
    pub(super) fn diagonal_weight(s: &ParityResiduals) -> Self {
        let [a, b, c] = s.to_array();
        Sym3 {
            xx: 1.0 / (a * a),
            yy: 1.0 / (b * b),
            zz: 1.0 / (c * c),
            ..Sym3::default()
        }
    }

    /// Adds the outer product `d d^T`.
    pub(super) fn add_outer(&mut self, d: &ParityResiduals) {
        let [x, y, z] = d.to_array();
        self.xx += x * x;
        self.xy += x * y;
        self.xz += x * z;
        self.yy += y * y;
        self.yz += y * z;
        self.zz += z * z;
    }

    /// The inverse (adjugate over determinant); `None` when the determinant is not
    /// positive or anything is not finite.
    pub(super) fn inverse(&self) -> Option<Self> {
        let m = self;
        let c_xx = m.yy * m.zz - m.yz * m.yz;
        let c_xy = m.xz * m.yz - m.xy * m.zz;
        let c_xz = m.xy * m.yz - m.xz * m.yy;
        let det = m.xx * c_xx + m.xy * c_xy + m.xz * c_xz;
        if !(det > 0.0 && det.is_finite()) {
            return None;
        }
        let inv = Sym3 {
            xx: c_xx / det,
            xy: c_xy / det,
            xz: c_xz / det,
            yy: (m.xx * m.zz - m.xz * m.xz) / det,
            yz: (m.xy * m.xz - m.xx * m.yz) / det,
            zz: (m.xx * m.yy - m.xy * m.xy) / det,
        };
        let all = [inv.xx, inv.xy, inv.xz, inv.yy, inv.yz, inv.zz];
        all.iter().all(|v| v.is_finite()).then_some(inv)
    }

    /// `d^T M d`.
    pub(super) fn quadratic(&self, d: &ParityResiduals) -> f32 {
        let [x, y, z] = d.to_array();
        self.xx * x * x
            + self.yy * y * y
            + self.zz * z * z
            + 2.0 * (self.xy * x * y + self.xz * x * z + self.yz * y * z)
    }
}

impl Circuit {
    /// This circuit with parameter `j` (0 Rs, 1 Rr, 2 the stator leakage, 3 the rotor
    /// leakage, 4 Lm with the leakages kept) [`NAMEPLATE_UNCERTAINTY`] larger.
    pub(super) fn nameplate_off(mut self, j: usize) -> Self {
        let mut f = [1.0f32; 5];
        if let Some(x) = f.get_mut(j) {
            *x += NAMEPLATE_UNCERTAINTY;
        }
        let [rs, rr, lls, llr, lm] = f;
        let (l_s, l_r) = (self.ls - self.lm, self.lr - self.lm);
        self.rs *= rs;
        self.rr *= rr;
        self.lm *= lm;
        self.ls = l_s * lls + self.lm;
        self.lr = l_r * llr + self.lm;
        self
    }

    /// The circuit with parameter fault `f` of factor `k` (the parameter its
    /// [`Fault::target`] names; a sensor fault leaves it alone). The `ls` and `lr` faults scale
    /// the leakage inductances ([`Fault::Ls`]: the paper's simulator PSIM's Ls and Lr are the
    /// leakages); on a side
    /// without leakage (a Gamma-model machine) they scale Lm, as the simulator does.
    pub(super) fn with(mut self, f: Fault, k: f32, m: &MotorModel) -> Self {
        let (lls, llr) = (m.lls_h(), m.llr_h());
        let tiny = 1e-9 * m.lm_h;
        let FaultTarget::Parameter(p) = f.target() else {
            return self;
        };
        match p {
            MachineParameter::Rs => self.rs *= k,
            MachineParameter::Rr => self.rr *= k,
            MachineParameter::StatorLeakage | MachineParameter::RotorLeakage => {
                let (l_side, side_is_s) = if p == MachineParameter::StatorLeakage {
                    (lls, true)
                } else {
                    (llr, false)
                };
                if l_side <= tiny {
                    self.lm = m.lm_h * k;
                    self.ls = lls + self.lm;
                    self.lr = llr + self.lm;
                } else if side_is_s {
                    self.ls = lls * k + m.lm_h;
                } else {
                    self.lr = llr * k + m.lm_h;
                }
            }
            MachineParameter::MachineFriction => self.b_total = m.b_nms * k + m.bl_nms,
            MachineParameter::LoadFriction => self.b_total = m.b_nms + m.bl_nms * k,
        }
        self
    }
}
