//! The variables a law is a function of, and their values where it is evaluated.

use serde::Serialize;

/// A variable a law is a function of (`ActsOn::variables`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Variable {
    /// `t`: time [s].
    T,
    /// `w`: the shaft's mechanical speed [rad/s].
    W,
    /// `theta`: the shaft's mechanical angle [rad].
    Theta,
    /// `psi_m`: the magnetising flux linkage, peak [Wb].
    PsiM,
}

impl Variable {
    /// Every variable.
    pub const ALL: [Variable; 4] = [Variable::T, Variable::W, Variable::Theta, Variable::PsiM];

    /// The name an expression uses.
    pub fn name(self) -> &'static str {
        match self {
            Variable::T => "t",
            Variable::W => "w",
            Variable::Theta => "theta",
            Variable::PsiM => "psi_m",
        }
    }

    /// Its unit.
    pub fn unit(self) -> &'static str {
        match self {
            Variable::T => "s",
            Variable::W => "rad/s",
            Variable::Theta => "rad",
            Variable::PsiM => "Wb",
        }
    }

    /// Its value in `x`.
    #[inline(always)]
    pub fn of(self, x: &LawInputs) -> f64 {
        match self {
            Variable::T => x.t_s,
            Variable::W => x.w_rad_s,
            Variable::Theta => x.theta_rad,
            Variable::PsiM => x.psi_m_wb,
        }
    }
}

/// Where a law is evaluated: the values of its variables ([`Variable`]); a law reads only
/// those of its [`ActsOn::variables`].
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct LawInputs {
    /// Time [s] (in the analysis: the log's time; in the simulator: the run's).
    pub t_s: f64,
    /// The shaft's mechanical speed [rad/s].
    pub w_rad_s: f64,
    /// The shaft's mechanical angle [rad].
    pub theta_rad: f64,
    /// The magnetising flux linkage, peak [Wb].
    pub psi_m_wb: f64,
}
