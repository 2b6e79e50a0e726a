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
    ($n:literal $(, $field:ident)?) => {
        fn n_dof(&self) -> usize {
            $n
        }
        matrix_getters!(@mck $($field)?);
    };
    (@mck $($field:ident)?) => {
        fn mass(&self) -> &[f64] {
            &self$(.$field)?.m
        }
        fn damping(&self) -> &[f64] {
            &self$(.$field)?.c
        }
        fn stiffness(&self) -> &[f64] {
            &self$(.$field)?.k
        }
    };
}
pub(crate) use matrix_getters;

/// `velocity_dependent() = false` and a `nonlinear_jacobian` that writes `∂g/∂x`
/// by `$body` (`$s` stands for `self`) and zeroes `∂g/∂v`: the trait items of a
/// force that depends on displacement and phase only.
macro_rules! displacement_jacobian {
    (|$s:ident, $x:ident, $theta:ident, $dg_dx:ident| $body:expr) => {
        fn velocity_dependent(&self) -> bool {
            false
        }
        fn nonlinear_jacobian(&self, $x: &[f64], _v: &[f64], $theta: f64, dg: &mut [f64]) {
            let $s = self;
            let ($dg_dx, dg_dv) = dg.split_at_mut(dg.len() / 2);
            $body;
            dg_dv.fill(0.0);
        }
    };
}
pub(crate) use displacement_jacobian;

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
        per_sample(self.n_dof(), x, v, theta, out, |x, v, th, out| {
            self.nonlinear(x, v, th, out)
        });
    }
    /// External excitation `f(θ)` (right-hand side). Default: none.
    fn excitation(&self, _theta: f64, out: &mut [f64]) {
        out.fill(0.0);
    }
    /// Whether `g` depends on `v` (saves one inverse FFT per DOF when not).
    fn velocity_dependent(&self) -> bool {
        true
    }
    /// `∂g/∂x` and `∂g/∂v` at one sample into `dg` as the row-major blocks
    /// `[∂g/∂x | ∂g/∂v]` (`2·n_dof²`, one sample of
    /// [`Self::nonlinear_jacobian_samples`]). Default: central differences with
    /// the step `1e-6·max(|x_j|, 1)` (one sample carries no orbit scale; the
    /// engine's assemblies call [`Self::nonlinear_jacobian_samples`]).
    fn nonlinear_jacobian(&self, x: &[f64], v: &[f64], theta: f64, dg: &mut [f64]) {
        let n = self.n_dof();
        let (dg_dx, dg_dv) = dg.split_at_mut(n * n);
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
    /// `∂g/∂x` and `∂g/∂v` at `theta.len()` samples at once: `x`, `v` sample-major as
    /// in [`Self::nonlinear_samples`]; `dg` holds per sample the row-major blocks
    /// `[∂g/∂x | ∂g/∂v]` (`2·n_dof²` per sample). The Galerkin Jacobian (Eq. 56),
    /// the stability matrix Θ (Eq. 79) and the fold locator call this once per
    /// assembly. Default: [`Self::nonlinear_jacobian`] per sample (right for an
    /// analytic Jacobian; a problem without one should use
    /// [`central_difference_samples`], as [`GeneralProblem`] does).
    fn nonlinear_jacobian_samples(&self, x: &[f64], v: &[f64], theta: &[f64], dg: &mut [f64]) {
        per_sample(self.n_dof(), x, v, theta, dg, |x, v, th, dg| {
            self.nonlinear_jacobian(x, v, th, dg)
        });
    }
}

/// Calls a one-sample function `f(x_i, v_i, θ_i, out_i)` on each of
/// `theta.len()` sample-major samples: `x`, `v` hold `n` entries per sample and
/// `out` an equal share per sample (`n` for `g`; `2n²` for the Jacobian blocks
/// `[∂g/∂x | ∂g/∂v]`, the layout of
/// [`PeriodicProblem::nonlinear_jacobian_samples`]). The default way to
/// evaluate all AFT samples.
pub fn per_sample(
    n: usize,
    x: &[f64],
    v: &[f64],
    theta: &[f64],
    out: &mut [f64],
    mut f: impl FnMut(&[f64], &[f64], f64, &mut [f64]),
) {
    let width = out.len() / theta.len().max(1);
    for (i, &th) in theta.iter().enumerate() {
        let s = i * n..(i + 1) * n;
        f(
            &x[s.clone()],
            &v[s],
            th,
            &mut out[i * width..(i + 1) * width],
        );
    }
}

/// Zeroes the `∂g/∂v` block of every sample's `[∂g/∂x | ∂g/∂v]` in `dg`: the
/// velocity Jacobian of a force declared independent of `v`.
fn zero_velocity_blocks(n: usize, dg: &mut [f64]) {
    let n2 = n * n;
    for block in dg.chunks_mut(2 * n2) {
        block[n2..].fill(0.0);
    }
}

/// Relative step of [`central_difference_samples`]: central differences err by
/// O(h²) in truncation and O(ε/h) in rounding, both ≈ 1e-11…1e-10 here.
const FD_STEP: f64 = 1e-6;

/// `∂g/∂x`, `∂g/∂v` at all samples (layout of
/// [`PeriodicProblem::nonlinear_jacobian_samples`]) by central differences of
/// [`PeriodicProblem::nonlinear_samples`]: the `2·n_dof` perturbed copies of the
/// samples (`4·n_dof` with velocity dependence; each DOF stepped up and down)
/// are stacked into one call, so a vectorized `g` is called once per Jacobian
/// whatever the number of DOFs and samples (`g` acts sample by sample, so
/// stacking changes nothing else). DOF j is stepped by `1e-6·max_i |x_ij|`
/// (`v` likewise), relative to the orbit's own scale: an orbit of micrometres
/// is differenced like one of metres, where a floor of 1 would step by its
/// whole amplitude. Allocates its scratch.
pub fn central_difference_samples<P: PeriodicProblem + ?Sized>(
    problem: &P,
    x: &[f64],
    v: &[f64],
    theta: &[f64],
    dg: &mut [f64],
) {
    let n = problem.n_dof();
    let ns = theta.len();
    let with_v = problem.velocity_dependent();
    // Perturbation k = (wrt_v, j, sign): x₀⁺, x₀⁻, x₁⁺, …, then v₀⁺, … .
    let wrt: &[bool] = if with_v { &[false, true] } else { &[false] };
    let copies = 2 * n * wrt.len();
    let (mut xs, mut vs) = (
        Vec::with_capacity(copies * n * ns),
        Vec::with_capacity(copies * n * ns),
    );
    let mut thetas = Vec::with_capacity(copies * ns);
    let mut steps = Vec::with_capacity(copies / 2);
    for &wrt_v in wrt {
        let base = if wrt_v { v } else { x };
        for j in 0..n {
            let h = FD_STEP * orbit_scale(base, n, j);
            steps.push(h);
            for sign in [1.0, -1.0] {
                let start = if wrt_v { vs.len() } else { xs.len() };
                xs.extend_from_slice(&x[..n * ns]);
                vs.extend_from_slice(&v[..n * ns]);
                let moved = if wrt_v { &mut vs } else { &mut xs };
                for m in moved[start..].iter_mut().skip(j).step_by(n) {
                    *m += sign * h;
                }
                thetas.extend_from_slice(theta);
            }
        }
    }
    let mut g = vec![0.0; copies * n * ns];
    problem.nonlinear_samples(&xs, &vs, &thetas, &mut g);
    let copy = n * ns;
    for (pair, &h) in steps.iter().enumerate() {
        let (wrt_v, j) = (pair >= n, pair % n);
        let (gp, gm) = (&g[2 * pair * copy..], &g[(2 * pair + 1) * copy..]);
        let block = if wrt_v { n * n } else { 0 };
        for i in 0..ns {
            for r in 0..n {
                dg[2 * i * n * n + block + r * n + j] = (gp[i * n + r] - gm[i * n + r]) / (2.0 * h);
            }
        }
    }
    if !with_v {
        zero_velocity_blocks(n, dg);
    }
}

/// `max_i |u_ij|` of DOF j over the samples; that of all DOFs if DOF j is
/// identically zero, and 1 if everything is.
fn orbit_scale(u: &[f64], n: usize, j: usize) -> f64 {
    let max = |it: &mut dyn Iterator<Item = &f64>| it.fold(0.0f64, |a, b| a.max(b.abs()));
    [
        max(&mut u.iter().skip(j).step_by(n)),
        max(&mut u.iter()),
        1.0,
    ]
    .into_iter()
    .find(|s| *s > 0.0 && s.is_finite())
    .unwrap_or(1.0)
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
        0.5 * self.linear.c[0]
    }
    /// Linear stiffness α.
    pub fn alpha(&self) -> f64 {
        self.linear.k[0]
    }
    /// Whether all parameters are finite.
    pub fn is_finite(&self) -> bool {
        [self.linear.c[0], self.linear.k[0], self.eps, self.force]
            .iter()
            .all(|v| v.is_finite())
    }
}

impl PeriodicProblem for Duffing {
    matrix_getters!(1, linear);
    fn nonlinear(&self, x: &[f64], _v: &[f64], _theta: f64, out: &mut [f64]) {
        out[0] = self.eps * x[0] * x[0] * x[0];
    }
    fn excitation(&self, theta: f64, out: &mut [f64]) {
        out[0] = self.force * theta.cos();
    }
    displacement_jacobian!(|s, x, _theta, dg_dx| dg_dx[0] = 3.0 * s.eps * x[0] * x[0]);
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
    fn nonlinear(&self, x: &[f64], _v: &[f64], theta: f64, out: &mut [f64]) {
        out[0] = -self.beta * theta.sin() * x[0] + self.gamma * x[0] * x[0] * x[0];
    }
    displacement_jacobian!(|s, x, theta, dg_dx| {
        dg_dx[0] = -s.beta * theta.sin() + 3.0 * s.gamma * x[0] * x[0]
    });
}

/// The force `g(x, v, θ)` of a [`GeneralProblem`]: any closure
/// `Fn(&[f64], &[f64], f64, &mut [f64])` (one sample per call), or a type that
/// also evaluates all AFT samples in one call (e.g. one call into an interpreter),
/// and optionally its analytic Jacobian ([`Self::jacobian_samples`];
/// [`WithJacobian`] pairs a closure with one).
pub trait Nonlinearity {
    /// `g` at one sample (see [`PeriodicProblem::nonlinear`]).
    fn eval(&self, x: &[f64], v: &[f64], theta: f64, out: &mut [f64]);
    /// `g` at `theta.len()` samples, sample-major (see
    /// [`PeriodicProblem::nonlinear_samples`]). Default: [`Self::eval`] per sample.
    fn eval_samples(&self, x: &[f64], v: &[f64], theta: &[f64], out: &mut [f64]) {
        let n = x.len() / theta.len().max(1);
        per_sample(n, x, v, theta, out, |x, v, th, out| {
            self.eval(x, v, th, out)
        });
    }
    /// The analytic `∂g/∂x`, `∂g/∂v` at `theta.len()` samples into `dg` (layout of
    /// [`PeriodicProblem::nonlinear_jacobian_samples`]: per sample the row-major
    /// blocks `[∂g/∂x | ∂g/∂v]`, `2·n_dof²`); returns whether it wrote them.
    /// Default: `false`, and [`GeneralProblem`] differences [`Self::eval_samples`]
    /// ([`central_difference_samples`]: one call per Jacobian on the 2·n_dof
    /// perturbed copies of the samples, 4·n_dof with velocity dependence)
    /// instead.
    fn jacobian_samples(&self, _x: &[f64], _v: &[f64], _theta: &[f64], _dg: &mut [f64]) -> bool {
        false
    }
}

/// A [`Nonlinearity`] `g` with its analytic Jacobian `jacobian(x, v, θ, dg)`
/// at one sample (`dg`: the blocks `[∂g/∂x | ∂g/∂v]`, `2·n_dof²`), so that the
/// Galerkin Jacobian (Eq. 56) and the stability matrix (Eq. 79) call no
/// differences of `g` ([`GeneralProblem::with_jacobian`]).
pub struct WithJacobian<G, J> {
    g: G,
    jacobian: J,
}

impl<G, J> Nonlinearity for WithJacobian<G, J>
where
    G: Nonlinearity,
    J: Fn(&[f64], &[f64], f64, &mut [f64]),
{
    fn eval(&self, x: &[f64], v: &[f64], theta: f64, out: &mut [f64]) {
        self.g.eval(x, v, theta, out)
    }
    fn eval_samples(&self, x: &[f64], v: &[f64], theta: &[f64], out: &mut [f64]) {
        self.g.eval_samples(x, v, theta, out)
    }
    fn jacobian_samples(&self, x: &[f64], v: &[f64], theta: &[f64], dg: &mut [f64]) -> bool {
        let n = x.len() / theta.len().max(1);
        per_sample(n, x, v, theta, dg, &self.jacobian);
        true
    }
}

impl<G: Fn(&[f64], &[f64], f64, &mut [f64])> Nonlinearity for G {
    fn eval(&self, x: &[f64], v: &[f64], theta: f64, out: &mut [f64]) {
        self(x, v, theta, out)
    }
}

/// A general multi-DOF problem built from matrices, a [`Nonlinearity`] (e.g. a
/// closure) and an excitation closure, for users who do not want to implement the
/// trait. Its `∂g` are the nonlinearity's analytic Jacobian when it has one
/// ([`Nonlinearity::jacobian_samples`], [`Self::with_jacobian`]), else central
/// differences over all samples at once with steps relative to the orbit
/// ([`central_difference_samples`]).
pub struct GeneralProblem<G, F> {
    n: usize,
    m: Vec<f64>,
    c: Vec<f64>,
    k: Vec<f64>,
    g: G,
    f: F,
    velocity_dependent: bool,
}

impl<G, F> GeneralProblem<G, F>
where
    G: Nonlinearity,
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
        Self {
            n,
            m,
            c,
            k,
            g,
            f,
            velocity_dependent: true,
        }
    }

    /// Declares whether `g` reads `v` (default `true`; `false` saves an inverse FFT
    /// per DOF in the residual and the `v` differences of the Jacobian).
    pub fn with_velocity_dependent(mut self, velocity_dependent: bool) -> Self {
        self.velocity_dependent = velocity_dependent;
        self
    }

    /// The nonlinearity `g`.
    pub fn nonlinearity(&self) -> &G {
        &self.g
    }

    /// The same problem with the analytic Jacobian `jacobian(x, v, θ, dg)` of `g`
    /// at one sample (`dg`: row-major `[∂g/∂x | ∂g/∂v]`, `2·n_dof²`; the `∂g/∂v`
    /// block is ignored, taken as zero, when `g` is declared velocity
    /// independent): every Jacobian assembly then calls it instead of
    /// differencing `g`.
    pub fn with_jacobian<J>(self, jacobian: J) -> GeneralProblem<WithJacobian<G, J>, F>
    where
        J: Fn(&[f64], &[f64], f64, &mut [f64]),
    {
        GeneralProblem {
            n: self.n,
            m: self.m,
            c: self.c,
            k: self.k,
            g: WithJacobian {
                g: self.g,
                jacobian,
            },
            f: self.f,
            velocity_dependent: self.velocity_dependent,
        }
    }
}

impl<G, F> PeriodicProblem for GeneralProblem<G, F>
where
    G: Nonlinearity,
    F: Fn(f64, &mut [f64]),
{
    matrix_getters!();
    fn nonlinear(&self, x: &[f64], v: &[f64], theta: f64, out: &mut [f64]) {
        self.g.eval(x, v, theta, out)
    }
    fn nonlinear_samples(&self, x: &[f64], v: &[f64], theta: &[f64], out: &mut [f64]) {
        self.g.eval_samples(x, v, theta, out)
    }
    fn excitation(&self, theta: f64, out: &mut [f64]) {
        (self.f)(theta, out)
    }
    fn velocity_dependent(&self) -> bool {
        self.velocity_dependent
    }
    fn nonlinear_jacobian_samples(&self, x: &[f64], v: &[f64], theta: &[f64], dg: &mut [f64]) {
        if !self.g.jacobian_samples(x, v, theta, dg) {
            return central_difference_samples(self, x, v, theta, dg);
        }
        if !self.velocity_dependent {
            zero_velocity_blocks(self.n, dg);
        }
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
    fn nonlinear_jacobian(&self, x: &[f64], v: &[f64], theta: f64, dg: &mut [f64]) {
        (**self).nonlinear_jacobian(x, v, theta, dg)
    }
    fn nonlinear_jacobian_samples(&self, x: &[f64], v: &[f64], theta: &[f64], dg: &mut [f64]) {
        (**self).nonlinear_jacobian_samples(x, v, theta, dg)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{GalerkinJacobian, HbOptions, HbResidual};
    use std::cell::Cell;

    /// A 2-DOF chain with a coupled, velocity-dependent `g`:
    /// g₀ = ½x₀³ + 0.1x₀²v₁, g₁ = 0.2(x₁ − x₀)³.
    fn chain_g(x: &[f64], v: &[f64], out: &mut [f64]) {
        out[0] = 0.5 * x[0].powi(3) + 0.1 * x[0] * x[0] * v[1];
        out[1] = 0.2 * (x[1] - x[0]).powi(3);
    }

    /// Its `[∂g/∂x | ∂g/∂v]`, row-major 2×2 blocks.
    fn chain_jacobian(x: &[f64], v: &[f64], dg: &mut [f64]) {
        let d = 0.6 * (x[1] - x[0]).powi(2);
        let dx = [1.5 * x[0] * x[0] + 0.2 * x[0] * v[1], 0.0, -d, d];
        let dv = [0.0, 0.1 * x[0] * x[0], 0.0, 0.0];
        dg[..4].copy_from_slice(&dx);
        dg[4..].copy_from_slice(&dv);
    }

    /// The Galerkin Jacobian Φ_q (Eq. 56) of `problem` at a two-harmonic orbit,
    /// and the number of one-sample `g` calls `calls` counted while assembling it.
    fn galerkin<P: PeriodicProblem>(problem: &P, calls: &Cell<usize>) -> (Vec<f64>, usize) {
        let opts = HbOptions::new(5, 16);
        let mut res = HbResidual::new(problem, &opts).unwrap();
        let l = 2 * 5 + 1;
        let mut q = vec![0.0; 2 * l];
        // DOF 0: 0.8cos τ + 0.3 sin 2τ + 0.1; DOF 1: 0.5 sin τ − 0.2cos 3τ.
        (q[0], q[1], q[5 + 2]) = (0.2, 0.8, 0.3);
        (q[l + 5 + 1], q[l + 3]) = (0.5, -0.2);
        let mut jac = vec![0.0; q.len() * q.len()];
        calls.set(0);
        GalerkinJacobian::new(&res).assemble(&mut res, problem, &q, 1.3, 1.0, &mut jac);
        (jac, calls.get())
    }

    #[test]
    fn analytic_jacobian_gives_the_differenced_galerkin_jacobian_without_calling_g() {
        let calls = Cell::new(0);
        let g = |x: &[f64], v: &[f64], _th: f64, out: &mut [f64]| {
            calls.set(calls.get() + 1);
            chain_g(x, v, out);
        };
        let mck = || {
            (
                vec![1.0, 0.0, 0.0, 1.0],
                vec![0.02, 0.0, 0.0, 0.02],
                vec![2.0, -1.0, -1.0, 2.0],
            )
        };
        let (m, c, k) = mck();
        let differenced =
            GeneralProblem::new(2, m, c, k, g, |_: f64, out: &mut [f64]| out.fill(0.0));
        let (m, c, k) = mck();
        let analytic = GeneralProblem::new(2, m, c, k, g, |_: f64, out: &mut [f64]| out.fill(0.0))
            .with_jacobian(|x: &[f64], v: &[f64], _th: f64, dg: &mut [f64]| {
                chain_jacobian(x, v, dg)
            });
        let (jac_fd, calls_fd) = galerkin(&differenced, &calls);
        let (jac_an, calls_an) = galerkin(&analytic, &calls);
        // Central differences with steps 1e-6 of the orbit's scale err by
        // ~1e-10 relative (FD_STEP): 1e-8 of the largest entry bounds it.
        let scale = jac_an.iter().fold(0.0f64, |a, b| a.max(b.abs()));
        let err = jac_fd
            .iter()
            .zip(&jac_an)
            .fold(0.0f64, |a, (f, e)| a.max((f - e).abs()));
        assert!(
            err <= 1e-8 * scale,
            "max |Φ_fd − Φ_analytic| = {err:e}, scale {scale}"
        );
        // The 2N = 32 samples, differenced in 4·n_dof = 8 evaluations of all samples.
        assert_eq!(calls_fd, 8 * 32);
        assert_eq!(calls_an, 0);
    }

    #[test]
    fn analytic_velocity_block_is_ignored_for_a_velocity_independent_g() {
        let g = |x: &[f64], _v: &[f64], _th: f64, out: &mut [f64]| chain_g(x, &[0.0; 2], out);
        let problem = GeneralProblem::new(
            2,
            vec![1.0, 0.0, 0.0, 1.0],
            vec![0.0; 4],
            vec![0.0; 4],
            g,
            |_: f64, out: &mut [f64]| out.fill(0.0),
        )
        .with_velocity_dependent(false)
        .with_jacobian(|x: &[f64], _v: &[f64], _th: f64, dg: &mut [f64]| dg.fill(x[0]));
        let (x, v) = ([0.5, 1.0, -2.0, 3.0], [7.0; 4]);
        let mut dg = [f64::NAN; 16];
        problem.nonlinear_jacobian_samples(&x, &v, &[0.0, 1.0], &mut dg);
        assert_eq!(&dg[..8], &[0.5, 0.5, 0.5, 0.5, 0.0, 0.0, 0.0, 0.0]);
        assert_eq!(&dg[8..], &[-2.0, -2.0, -2.0, -2.0, 0.0, 0.0, 0.0, 0.0]);
    }
}
