//! The general periodic problem (issue 3, item 1): `n_dof` second-order ODEs
//!
//! `M ẍ + C ẋ + K x + g(x, ẋ, θ) = f(θ)`,  θ = ω_f t,
//!
//! solved for periodic responses of period `p·2π/ω_f` (Eq. 52: τ = ωt with
//! `ω = ω_f/p`, so θ = pτ). The user gives `M`, `C`, `K` (row-major `n_dof×n_dof`),
//! the nonlinear/parametric part `g` in the time domain, the excitation `f`, and
//! optionally the derivatives of `g` (default: central differences). `g` and `f`
//! may also read ω_f ([`PeriodicProblem::frequency_dependent`], [`AtFrequency`]).

mod general;
mod omega;
pub use general::{GeneralProblem, Nonlinearity, WithJacobian};
pub use omega::{AtFrequency, Excitation, FrequencyExcitation, REFERENCE_FREQUENCY};

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
    /// Whether `g` or `f` read the excitation frequency ω_f (a rotating
    /// unbalance `m e ω_f² cos θ`, a law written in τ-derivatives): then the
    /// `_at` hooks below are the model, and solvers see it bound to one ω_f
    /// ([`AtFrequency`], which the frequency family [`crate::Frequency`] builds
    /// at every ω_f, so that `∂R/∂ω_f` includes their ω-dependence). Default:
    /// `false`.
    fn frequency_dependent(&self) -> bool {
        false
    }
    /// `g(x, v, θ, ω_f)` at all samples (layout of [`Self::nonlinear_samples`]).
    /// Default: ignores ω_f.
    fn nonlinear_samples_at(
        &self,
        x: &[f64],
        v: &[f64],
        theta: &[f64],
        _omega_f: f64,
        out: &mut [f64],
    ) {
        self.nonlinear_samples(x, v, theta, out)
    }
    /// `[∂g/∂x | ∂g/∂v]` of `g(·, ω_f)` at all samples (layout of
    /// [`Self::nonlinear_jacobian_samples`]). Default: ignores ω_f.
    fn nonlinear_jacobian_samples_at(
        &self,
        x: &[f64],
        v: &[f64],
        theta: &[f64],
        _omega_f: f64,
        dg: &mut [f64],
    ) {
        self.nonlinear_jacobian_samples(x, v, theta, dg)
    }
    /// The excitation `f(θ, ω_f)`. Default: ignores ω_f.
    fn excitation_at(&self, theta: f64, _omega_f: f64, out: &mut [f64]) {
        self.excitation(theta, out)
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
    let (n, with_v) = (problem.n_dof(), problem.velocity_dependent());
    central_differences(
        n,
        with_v,
        |x, v, th, g| problem.nonlinear_samples(x, v, th, g),
        x,
        v,
        theta,
        dg,
    )
}

/// [`central_difference_samples`] of any `g` evaluated on all samples by
/// `eval(x, v, θ, out)` (`n` DOFs; `v` differenced if `with_v`).
pub(crate) fn central_differences(
    n: usize,
    with_v: bool,
    eval: impl FnOnce(&[f64], &[f64], &[f64], &mut [f64]),
    x: &[f64],
    v: &[f64],
    theta: &[f64],
    dg: &mut [f64],
) {
    let ns = theta.len();
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
    eval(&xs, &vs, &thetas, &mut g);
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
    fn frequency_dependent(&self) -> bool {
        (**self).frequency_dependent()
    }
    fn nonlinear_samples_at(&self, x: &[f64], v: &[f64], th: &[f64], w: f64, out: &mut [f64]) {
        (**self).nonlinear_samples_at(x, v, th, w, out)
    }
    fn nonlinear_jacobian_samples_at(
        &self,
        x: &[f64],
        v: &[f64],
        th: &[f64],
        w: f64,
        dg: &mut [f64],
    ) {
        (**self).nonlinear_jacobian_samples_at(x, v, th, w, dg)
    }
    fn excitation_at(&self, theta: f64, omega_f: f64, out: &mut [f64]) {
        (**self).excitation_at(theta, omega_f, out)
    }
}
