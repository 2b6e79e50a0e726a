//! The general periodic problem (issue 3, item 1): `n_dof` second-order ODEs
//!
//! `M ẍ + C ẋ + K x + g(x, ẋ, θ) = f(θ)`,  θ = ω_f t,
//!
//! solved for periodic responses of period `p·2π/ω_f` (Eq. 52: τ = ωt with
//! `ω = ω_f/p`, so θ = pτ). The user gives `M`, `C`, `K` (row-major `n_dof×n_dof`),
//! the nonlinear/parametric part `g` in the time domain, the excitation `f`, and
//! optionally the derivatives of `g` (default: central differences).

/// `n_dof` (the field `n`, or a literal), `mass`, `damping`, `stiffness` of a
/// problem that stores the row-major matrices `m`, `c`, `k` as fields.
macro_rules! matrix_getters {
    () => {
        fn n_dof(&self) -> usize {
            self.n
        }
        matrix_getters!(@mck);
    };
    ($n:literal) => {
        fn n_dof(&self) -> usize {
            $n
        }
        matrix_getters!(@mck);
    };
    (@mck) => {
        fn mass(&self) -> &[f64] {
            &self.m
        }
        fn damping(&self) -> &[f64] {
            &self.c
        }
        fn stiffness(&self) -> &[f64] {
            &self.k
        }
    };
}
pub(crate) use matrix_getters;

/// A periodically forced second-order system (see the module docs).
pub trait PeriodicProblem {
    /// Number of degrees of freedom.
    fn n_dof(&self) -> usize;
    /// Mass matrix `M` (row-major, must be invertible for stability analysis).
    fn mass(&self) -> &[f64];
    /// Damping matrix `C`.
    fn damping(&self) -> &[f64];
    /// Stiffness matrix `K`.
    fn stiffness(&self) -> &[f64];
    /// Nonlinear and parametric forces `g(x, v, θ)` with `v = dx/dt` (physical
    /// time) and θ the excitation phase; written into `out` (`n_dof`).
    fn nonlinear(&self, x: &[f64], v: &[f64], theta: f64, out: &mut [f64]);
    /// `g` at `theta.len()` samples at once: `x`, `v` and `out` sample-major
    /// (`samples×n_dof`, row-major), `theta` one phase per sample. The HB residual
    /// calls this once per evaluation. Default: one [`Self::nonlinear`] call per
    /// sample; override to vectorise (e.g. one call into an interpreter).
    fn nonlinear_samples(&self, x: &[f64], v: &[f64], theta: &[f64], out: &mut [f64]) {
        let n = self.n_dof();
        for (i, &th) in theta.iter().enumerate() {
            let s = i * n..(i + 1) * n;
            self.nonlinear(&x[s.clone()], &v[s.clone()], th, &mut out[s]);
        }
    }
    /// External excitation `f(θ)` (right-hand side). Default: none.
    fn excitation(&self, _theta: f64, out: &mut [f64]) {
        out.fill(0.0);
    }
    /// Whether `g` depends on `v` (saves one inverse FFT per DOF when not).
    fn velocity_dependent(&self) -> bool {
        true
    }
    /// `∂g/∂x` and `∂g/∂v` (row-major `n_dof×n_dof`). Default: central differences
    /// with a relative step of 1e-6 (allocates; not used in the modified IHB loop).
    fn nonlinear_jacobian(
        &self,
        x: &[f64],
        v: &[f64],
        theta: f64,
        dg_dx: &mut [f64],
        dg_dv: &mut [f64],
    ) {
        let n = self.n_dof();
        let mut xp = x.to_vec();
        let mut vp = v.to_vec();
        let mut gp = vec![0.0; n];
        let mut gm = vec![0.0; n];
        for j in 0..n {
            let h = 1e-6 * x[j].abs().max(1.0);
            xp[j] = x[j] + h;
            self.nonlinear(&xp, v, theta, &mut gp);
            xp[j] = x[j] - h;
            self.nonlinear(&xp, v, theta, &mut gm);
            xp[j] = x[j];
            for i in 0..n {
                dg_dx[i * n + j] = (gp[i] - gm[i]) / (2.0 * h);
            }
            let h = 1e-6 * v[j].abs().max(1.0);
            vp[j] = v[j] + h;
            self.nonlinear(x, &vp, theta, &mut gp);
            vp[j] = v[j] - h;
            self.nonlinear(x, &vp, theta, &mut gm);
            vp[j] = v[j];
            for i in 0..n {
                dg_dv[i * n + j] = (gp[i] - gm[i]) / (2.0 * h);
            }
        }
    }
}

/// Duffing's equation Eq. 49: `ü + 2ξ u̇ + α u + ε u³ = F cos(ω_f t)`.
#[derive(Debug, Clone, PartialEq)]
pub struct Duffing {
    m: [f64; 1],
    c: [f64; 1],
    k: [f64; 1],
    /// Nonlinear stiffness ε.
    pub eps: f64,
    /// Forcing amplitude F.
    pub force: f64,
}

impl Duffing {
    /// Duffing oscillator with damping ratio ξ, stiffness α, nonlinearity ε, force F.
    pub fn new(xi: f64, alpha: f64, eps: f64, force: f64) -> Self {
        Self {
            m: [1.0],
            c: [2.0 * xi],
            k: [alpha],
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
        0.5 * self.c[0]
    }
    /// Linear stiffness α.
    pub fn alpha(&self) -> f64 {
        self.k[0]
    }
    /// Whether all parameters are finite.
    pub fn is_finite(&self) -> bool {
        [self.c[0], self.k[0], self.eps, self.force]
            .iter()
            .all(|v| v.is_finite())
    }
}

impl PeriodicProblem for Duffing {
    matrix_getters!(1);
    fn nonlinear(&self, x: &[f64], _v: &[f64], _theta: f64, out: &mut [f64]) {
        out[0] = self.eps * x[0] * x[0] * x[0];
    }
    fn excitation(&self, theta: f64, out: &mut [f64]) {
        out[0] = self.force * theta.cos();
    }
    fn velocity_dependent(&self) -> bool {
        false
    }
    fn nonlinear_jacobian(
        &self,
        x: &[f64],
        _v: &[f64],
        _theta: f64,
        dg_dx: &mut [f64],
        dg_dv: &mut [f64],
    ) {
        dg_dx[0] = 3.0 * self.eps * x[0] * x[0];
        dg_dv[0] = 0.0;
    }
}

/// Mathieu–Duffing equation Eq. 81: `ü + 2ξ̂ u̇ − (α̂ + β sin Ωt) u + γ u³ = 0`
/// (θ = Ωt is the excitation phase, so ω_f = Ω).
#[derive(Debug, Clone, PartialEq)]
pub struct MathieuDuffing {
    m: [f64; 1],
    c: [f64; 1],
    k: [f64; 1],
    /// Parametric amplitude β.
    pub beta: f64,
    /// Cubic stiffness γ.
    pub gamma: f64,
}

impl MathieuDuffing {
    /// With damping ratio ξ̂, stiffness α̂ (enters as −α̂), β and γ.
    pub fn new(xi: f64, alpha: f64, beta: f64, gamma: f64) -> Self {
        Self {
            m: [1.0],
            c: [2.0 * xi],
            k: [-alpha],
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
    matrix_getters!(1);
    fn nonlinear(&self, x: &[f64], _v: &[f64], theta: f64, out: &mut [f64]) {
        out[0] = -self.beta * theta.sin() * x[0] + self.gamma * x[0] * x[0] * x[0];
    }
    fn velocity_dependent(&self) -> bool {
        false
    }
    fn nonlinear_jacobian(
        &self,
        x: &[f64],
        _v: &[f64],
        theta: f64,
        dg_dx: &mut [f64],
        dg_dv: &mut [f64],
    ) {
        dg_dx[0] = -self.beta * theta.sin() + 3.0 * self.gamma * x[0] * x[0];
        dg_dv[0] = 0.0;
    }
}

/// A general multi-DOF problem built from matrices and closures (for users who do
/// not want to implement the trait).
pub struct GeneralProblem<G, F> {
    n: usize,
    m: Vec<f64>,
    c: Vec<f64>,
    k: Vec<f64>,
    g: G,
    f: F,
}

impl<G, F> GeneralProblem<G, F>
where
    G: Fn(&[f64], &[f64], f64, &mut [f64]),
    F: Fn(f64, &mut [f64]),
{
    /// `M`, `C`, `K` row-major `n×n`; `g(x, v, θ, out)`, `f(θ, out)`.
    ///
    /// # Panics
    /// If a matrix is not `n×n`.
    pub fn new(n: usize, m: Vec<f64>, c: Vec<f64>, k: Vec<f64>, g: G, f: F) -> Self {
        assert!(
            m.len() == n * n && c.len() == n * n && k.len() == n * n,
            "M, C, K must be n×n"
        );
        Self { n, m, c, k, g, f }
    }
}

impl<G, F> PeriodicProblem for GeneralProblem<G, F>
where
    G: Fn(&[f64], &[f64], f64, &mut [f64]),
    F: Fn(f64, &mut [f64]),
{
    matrix_getters!();
    fn nonlinear(&self, x: &[f64], v: &[f64], theta: f64, out: &mut [f64]) {
        (self.g)(x, v, theta, out)
    }
    fn excitation(&self, theta: f64, out: &mut [f64]) {
        (self.f)(theta, out)
    }
}

/// A borrowed problem is a problem (lets solvers borrow problems that are not
/// `Clone`, e.g. [`GeneralProblem`] with closures).
impl<P: PeriodicProblem + ?Sized> PeriodicProblem for &P {
    fn n_dof(&self) -> usize {
        (**self).n_dof()
    }
    fn mass(&self) -> &[f64] {
        (**self).mass()
    }
    fn damping(&self) -> &[f64] {
        (**self).damping()
    }
    fn stiffness(&self) -> &[f64] {
        (**self).stiffness()
    }
    fn nonlinear(&self, x: &[f64], v: &[f64], theta: f64, out: &mut [f64]) {
        (**self).nonlinear(x, v, theta, out)
    }
    fn nonlinear_samples(&self, x: &[f64], v: &[f64], theta: &[f64], out: &mut [f64]) {
        (**self).nonlinear_samples(x, v, theta, out)
    }
    fn excitation(&self, theta: f64, out: &mut [f64]) {
        (**self).excitation(theta, out)
    }
    fn velocity_dependent(&self) -> bool {
        (**self).velocity_dependent()
    }
    fn nonlinear_jacobian(
        &self,
        x: &[f64],
        v: &[f64],
        theta: f64,
        dg_dx: &mut [f64],
        dg_dv: &mut [f64],
    ) {
        (**self).nonlinear_jacobian(x, v, theta, dg_dx, dg_dv)
    }
}
