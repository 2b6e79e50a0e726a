//! The one-DOF oscillators of the thesis as [`PeriodicProblem`]s: Duffing's
//! equation (Eq. 49) and the Mathieu–Duffing equation (Eq. 81); and the
//! self-excited oscillators of the limit-cycle examples (Van der Pol,
//! Rayleigh).

use super::{displacement_jacobian, matrix_getters, GeneralProblem, PeriodicProblem};
use crate::error::HbError;

/// `out[0] = law(x[0])` of a one-DOF force; NaN in `out` if `x` is empty.
#[inline]
fn one_dof(x: &[f64], out: &mut [f64], law: impl FnOnce(f64) -> f64) {
    match (x.first(), out.first_mut()) {
        (Some(&u), Some(o)) => *o = law(u),
        _ => out.fill(f64::NAN),
    }
}

/// The linear part `ü + 2ξ u̇ + k u` of a one-DOF oscillator with unit mass.
#[derive(Debug, Clone, PartialEq)]
struct UnitMass {
    m: [f64; 1],
    c: [f64; 1],
    k: [f64; 1],
}

impl UnitMass {
    /// Damping ratio ξ and stiffness `k`.
    fn new(xi: f64, k: f64) -> Self {
        Self {
            m: [1.0],
            c: [2.0 * xi],
            k: [k],
        }
    }
}

/// Duffing's equation Eq. 49: `ü + 2ξ u̇ + α u + ε u³ = F cos(ω_f t)`.
#[derive(Debug, Clone, PartialEq)]
pub struct Duffing {
    linear: UnitMass,
    /// Nonlinear stiffness ε.
    pub eps: f64,
    /// Forcing amplitude F.
    pub force: f64,
}

impl Duffing {
    /// Duffing oscillator with damping ratio ξ, stiffness α, nonlinearity ε, force F.
    pub fn new(xi: f64, alpha: f64, eps: f64, force: f64) -> Self {
        Self {
            linear: UnitMass::new(xi, alpha),
            eps,
            force,
        }
    }
    /// The parameters of Fig. 28/29: ξ = 0.02, α = 1, ε = 1, F = 0.1.
    pub fn fig28() -> Self {
        Self::new(0.02, 1.0, 1.0, 0.1)
    }
    /// Damping ratio ξ.
    pub fn xi(&self) -> f64 {
        let [c] = self.linear.c;
        0.5 * c
    }
    /// Linear stiffness α.
    pub fn alpha(&self) -> f64 {
        let [k] = self.linear.k;
        k
    }
    /// Whether all parameters are finite.
    pub fn is_finite(&self) -> bool {
        [self.xi(), self.alpha(), self.eps, self.force]
            .iter()
            .all(|v| v.is_finite())
    }
}

impl PeriodicProblem for Duffing {
    matrix_getters!(1, linear);
    #[inline]
    fn nonlinear(&self, x: &[f64], _v: &[f64], _theta: f64, out: &mut [f64]) {
        one_dof(x, out, |u| self.eps * u * u * u);
    }
    fn excitation(&self, theta: f64, out: &mut [f64]) {
        if let Some(o) = out.first_mut() {
            *o = self.force * theta.cos();
        }
    }
    displacement_jacobian!(|s, x, _theta, dg_dx| one_dof(x, dg_dx, |u| 3.0 * s.eps * u * u));
}

/// Mathieu–Duffing equation Eq. 81: `ü + 2ξ̂ u̇ − (α̂ + β sin Ωt) u + γ u³ = 0`
/// (θ = Ωt is the excitation phase, so ω_f = Ω).
#[derive(Debug, Clone, PartialEq)]
pub struct MathieuDuffing {
    linear: UnitMass,
    /// Parametric amplitude β.
    pub beta: f64,
    /// Cubic stiffness γ.
    pub gamma: f64,
}

impl MathieuDuffing {
    /// With damping ratio ξ̂, stiffness α̂ (enters as −α̂), β and γ.
    pub fn new(xi: f64, alpha: f64, beta: f64, gamma: f64) -> Self {
        Self {
            linear: UnitMass::new(xi, -alpha),
            beta,
            gamma,
        }
    }
    /// The thesis case §3.2.5: ξ̂ = 0.125, α̂ = 1, γ = 1 (Ω = 2 is the frequency).
    pub fn thesis(beta: f64) -> Self {
        Self::new(0.125, 1.0, beta, 1.0)
    }
}

impl PeriodicProblem for MathieuDuffing {
    matrix_getters!(1, linear);
    #[inline]
    fn nonlinear(&self, x: &[f64], _v: &[f64], theta: f64, out: &mut [f64]) {
        one_dof(x, out, |u| {
            -self.beta * theta.sin() * u + self.gamma * u * u * u
        });
    }
    displacement_jacobian!(|s, x, theta, dg_dx| {
        one_dof(x, dg_dx, |u| -s.beta * theta.sin() + 3.0 * s.gamma * u * u)
    });
}

/// A self-excited oscillator of one DOF, `ẍ + x = μ h(x, ẋ)`, written as
/// `M = 1`, `C = −μ`, `K = 1` and the rest in `g` (the CLI's `ivt hb
/// limit-cycle --model`; Python builds the same system from `m, c, k, g`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Oscillator {
    /// Van der Pol `ẍ − μ(1 − x²)ẋ + x = 0`: `g = μ x² ẋ`.
    VanDerPol,
    /// Rayleigh `ẍ − μ(ẋ − ẋ³/3) + x = 0`: `g = μ ẋ³/3`.
    Rayleigh,
}

impl std::str::FromStr for Oscillator {
    type Err = HbError;

    /// `"van-der-pol"` or `"rayleigh"`.
    fn from_str(s: &str) -> Result<Self, HbError> {
        match s {
            "van-der-pol" => Ok(Self::VanDerPol),
            "rayleigh" => Ok(Self::Rayleigh),
            other => Err(HbError::InvalidInput(format!(
                "`model` = {other:?} must be 'van-der-pol' or 'rayleigh'"
            ))),
        }
    }
}

impl Oscillator {
    /// The oscillator with parameter `mu` as a periodic problem (unforced).
    pub fn problem(self, mu: f64) -> impl PeriodicProblem {
        self_excited(mu, move |x, v| match self {
            Self::VanDerPol => mu * x * x * v,
            Self::Rayleigh => mu * v * v * v / 3.0,
        })
    }
}

/// `ẍ − (μ + νx² − x⁴)ẋ + x = 0` as `M = 1`, `C = −μ`, `K = 1`,
/// `g = −(νx² − x⁴)ẋ`: the one-DOF oscillator with a Hopf point at μ = 0
/// (subcritical for ν > 0: averaging gives `ṙ = r(μ/2 + νr²/8 − r⁴/16)`)
/// and a fold of limit cycles near μ = −ν²/8, meeting at the Bautin point
/// μ = ν = 0 — the family of the cycle-fold and Hopf examples.
pub fn bautin(mu: f64, nu: f64) -> impl PeriodicProblem {
    self_excited(mu, move |x, v| -(nu * x * x - x.powi(4)) * v)
}

/// `ẍ − μẋ + x + g(x, ẋ) = 0` unforced, as `M = 1`, `C = −μ`, `K = 1`.
fn self_excited(mu: f64, g: impl Fn(f64, f64) -> f64) -> impl PeriodicProblem {
    GeneralProblem::new(
        1,
        vec![1.0],
        vec![-mu],
        vec![1.0],
        move |x: &[f64], v: &[f64], _theta: f64, out: &mut [f64]| {
            if let (Some(out), Some(&x), Some(&v)) = (out.first_mut(), x.first(), v.first()) {
                *out = g(x, v);
            }
        },
        |_theta: f64, out: &mut [f64]| out.fill(0.0),
    )
}
