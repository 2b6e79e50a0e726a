//! The general periodic problem (issue 3, item 1): `n_dof` second-order ODEs
//!
//! `M ẍ + C ẋ + K x + g(x, ẋ, θ) = f(θ)`,  θ = ω_f t,
//!
//! solved for periodic responses of period `p·2π/ω_f` (Eq. 52: τ = ωt with
//! `ω = ω_f/p`, so θ = pτ). The user gives `M`, `C`, `K` (row-major `n_dof×n_dof`),
//! the nonlinear/parametric part `g` in the time domain, the excitation `f`, and
//! optionally the derivatives of `g` (default: central differences). `g` and `f`
//! may also read ω_f ([`PeriodicProblem::frequency_dependent`], [`AtFrequency`]).
//!
//! Slice lengths are the callers' contract; a slice of the wrong length in the
//! default methods and helpers here is not a panic: the output is NaN, which the
//! solvers report as [`crate::HbError::NonFinite`].

pub mod elements;
mod general;
mod hysteresis;
pub mod ode;
mod omega;
mod oscillators;
use crate::HbError;
pub use general::{GeneralProblem, Nonlinearity, WithJacobian};
pub use omega::{AtFrequency, Excitation, FrequencyExcitation, REFERENCE_FREQUENCY};
pub use oscillators::{bautin, Duffing, MathieuDuffing, Oscillator};

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

/// `n_dof`, `mass`, `damping`, `stiffness` and `velocity_dependent` of a
/// problem that wraps another, read from the inner problem `$inner` (`$s`
/// stands for `self`).
macro_rules! forward_matrices {
    (|$s:ident| $inner:expr) => {
        fn n_dof(&self) -> usize {
            let $s = self;
            $inner.n_dof()
        }
        fn mass(&self) -> &[f64] {
            let $s = self;
            $inner.mass()
        }
        fn damping(&self) -> &[f64] {
            let $s = self;
            $inner.damping()
        }
        fn stiffness(&self) -> &[f64] {
            let $s = self;
            $inner.stiffness()
        }
        fn velocity_dependent(&self) -> bool {
            let $s = self;
            $inner.velocity_dependent()
        }
        fn hysteretic(&self) -> bool {
            let $s = self;
            $inner.hysteretic()
        }
    };
}
use forward_matrices;

/// `velocity_dependent() = false` and a `nonlinear_jacobian` that writes `∂g/∂x`
/// by `$body` (`$s` stands for `self`) and zeroes `∂g/∂v`: the trait items of a
/// force that depends on displacement and phase only (exported for the
/// problems of the crates built on this one, e.g. ivt-sthb's modal string).
#[macro_export]
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
pub use displacement_jacobian;

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
    /// Whether `g` has a memory along the trajectory (the Jenkins element,
    /// whose samples are taken period by period): a quasi-periodic torus
    /// ([`crate::branches::torus`]) refuses such a `g`. Default: `false`.
    fn hysteretic(&self) -> bool {
        false
    }
    /// `∂g/∂x` and `∂g/∂v` at one sample into `dg` as the row-major blocks
    /// `[∂g/∂x | ∂g/∂v]` (`2·n_dof²`, one sample of
    /// [`Self::nonlinear_jacobian_samples`]). Default: central differences with
    /// the step `1e-6·max(|x_j|, 1)` (one sample carries no orbit scale; the
    /// engine's assemblies call [`Self::nonlinear_jacobian_samples`]). NaN in
    /// `dg` unless `x`, `v` hold `n_dof` and `dg` `2·n_dof²` entries.
    fn nonlinear_jacobian(&self, x: &[f64], v: &[f64], theta: f64, dg: &mut [f64]) {
        let n = self.n_dof();
        if x.len() != n || v.len() != n || dg.len() != 2 * n * n {
            return dg.fill(f64::NAN);
        }
        let (dg_dx, dg_dv) = dg.split_at_mut(n * n);
        let mut xp = x.to_vec();
        let mut vp = v.to_vec();
        let mut gp = vec![0.0; n];
        let mut gm = vec![0.0; n];
        for j in 0..n {
            // Column j of each block: entries j, j + n, … (`n ≥ 1` in this loop).
            let column = dg_dx.iter_mut().skip(j).step_by(n);
            let at_x = |xp: &[f64], g: &mut [f64]| self.nonlinear(xp, v, theta, g);
            difference_column(&mut xp, j, at_x, (&mut gp, &mut gm), column);
            let column = dg_dv.iter_mut().skip(j).step_by(n);
            let at_v = |vp: &[f64], g: &mut [f64]| self.nonlinear(x, vp, theta, g);
            difference_column(&mut vp, j, at_v, (&mut gp, &mut gm), column);
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

/// Central difference of `g` in entry `j` of `point` (step `1e-6·max(|u_j|, 1)`)
/// into `column` (`g(u + h e_j) − g(u − h e_j)) / 2h` by `eval(point, g)`, with
/// `(g₊, g₋)` as scratch; `point` is restored.
fn difference_column<'a>(
    point: &mut [f64],
    j: usize,
    mut eval: impl FnMut(&[f64], &mut [f64]),
    (gp, gm): (&mut [f64], &mut [f64]),
    column: impl Iterator<Item = &'a mut f64>,
) {
    let Some(u) = point.get(j).copied() else {
        return column.for_each(|d| *d = f64::NAN);
    };
    let h = 1e-6 * u.abs().max(1.0);
    for (sign, g) in [(1.0, &mut *gp), (-1.0, &mut *gm)] {
        if let Some(p) = point.get_mut(j) {
            *p = u + sign * h;
        }
        eval(point, g);
    }
    if let Some(p) = point.get_mut(j) {
        *p = u;
    }
    for (d, (a, b)) in column.zip(gp.iter().zip(gm.iter())) {
        *d = (a - b) / (2.0 * h);
    }
}

/// Calls a one-sample function `f(x_i, v_i, θ_i, out_i)` on each of
/// `theta.len()` sample-major samples: `x`, `v` hold `n` entries per sample and
/// `out` an equal share per sample (`n` for `g`; `2n²` for the Jacobian blocks
/// `[∂g/∂x | ∂g/∂v]`, the layout of
/// [`PeriodicProblem::nonlinear_jacobian_samples`]). The default way to
/// evaluate all AFT samples. `out` is NaN (and `f` not called) if `n` is zero,
/// `x` or `v` holds fewer than `n` entries per sample, or `out` fewer than one
/// per sample.
pub fn per_sample(
    n: usize,
    x: &[f64],
    v: &[f64],
    theta: &[f64],
    out: &mut [f64],
    mut f: impl FnMut(&[f64], &[f64], f64, &mut [f64]),
) {
    let ns = theta.len();
    if ns == 0 {
        return;
    }
    let width = out.len() / ns;
    if n == 0 || width == 0 || x.len() < n * ns || v.len() < n * ns {
        return out.fill(f64::NAN);
    }
    let samples = x.chunks_exact(n).zip(v.chunks_exact(n)).zip(theta);
    for (((x, v), &th), out) in samples.zip(out.chunks_exact_mut(width)) {
        f(x, v, th, out);
    }
}

/// Zeroes the `∂g/∂v` block of every sample's `[∂g/∂x | ∂g/∂v]` in `dg`: the
/// velocity Jacobian of a force declared independent of `v`.
fn zero_velocity_blocks(n: usize, dg: &mut [f64]) {
    let n2 = n * n;
    if n2 == 0 {
        return;
    }
    for block in dg.chunks_mut(2 * n2) {
        block.iter_mut().skip(n2).for_each(|d| *d = 0.0);
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
    if n == 0 || ns == 0 {
        return;
    }
    let (Some(x), Some(v)) = (x.get(..n * ns), v.get(..n * ns)) else {
        return dg.fill(f64::NAN);
    };
    if dg.len() < 2 * n * n * ns {
        return dg.fill(f64::NAN);
    }
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
                xs.extend_from_slice(x);
                vs.extend_from_slice(v);
                let moved = if wrt_v { &mut vs } else { &mut xs };
                for m in moved.iter_mut().skip(start + j).step_by(n) {
                    *m += sign * h;
                }
                thetas.extend_from_slice(theta);
            }
        }
    }
    let mut g = vec![0.0; copies * n * ns];
    eval(&xs, &vs, &thetas, &mut g);
    // `n, ns ≥ 1`: every chunk size below is positive.
    let copy = n * ns;
    for (pair, (g_pm, &h)) in g.chunks_exact(2 * copy).zip(&steps).enumerate() {
        let (wrt_v, j) = (pair >= n, pair % n);
        let (gp, gm) = g_pm.split_at(copy);
        let block = if wrt_v { n * n } else { 0 };
        let samples = gp.chunks_exact(n).zip(gm.chunks_exact(n));
        for (sample, (gp, gm)) in dg.chunks_exact_mut(2 * n * n).zip(samples) {
            // Column j of the block: rows r at `block + r·n + j`.
            let column = sample.iter_mut().skip(block + j).step_by(n);
            for (d, (a, b)) in column.zip(gp.iter().zip(gm)) {
                *d = (a - b) / (2.0 * h);
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
        max(&mut u.iter().skip(j).step_by(n.max(1))),
        max(&mut u.iter()),
        1.0,
    ]
    .into_iter()
    .find(|s| *s > 0.0 && s.is_finite())
    .unwrap_or(1.0)
}

/// `impl PeriodicProblem for` a pointer to a problem: every method forwards to
/// the problem pointed to, the ones it overrides included.
macro_rules! forward_pointer {
    ($ptr:ty) => {
        impl<P: PeriodicProblem + ?Sized> PeriodicProblem for $ptr {
            forward_matrices!(|s| (**s));
            fn nonlinear(&self, x: &[f64], v: &[f64], theta: f64, out: &mut [f64]) {
                (**self).nonlinear(x, v, theta, out)
            }
            fn nonlinear_samples(&self, x: &[f64], v: &[f64], theta: &[f64], out: &mut [f64]) {
                (**self).nonlinear_samples(x, v, theta, out)
            }
            fn excitation(&self, theta: f64, out: &mut [f64]) {
                (**self).excitation(theta, out)
            }
            fn nonlinear_jacobian(&self, x: &[f64], v: &[f64], theta: f64, dg: &mut [f64]) {
                (**self).nonlinear_jacobian(x, v, theta, dg)
            }
            fn nonlinear_jacobian_samples(
                &self,
                x: &[f64],
                v: &[f64],
                theta: &[f64],
                dg: &mut [f64],
            ) {
                (**self).nonlinear_jacobian_samples(x, v, theta, dg)
            }
            fn frequency_dependent(&self) -> bool {
                (**self).frequency_dependent()
            }
            fn nonlinear_samples_at(
                &self,
                x: &[f64],
                v: &[f64],
                th: &[f64],
                w: f64,
                out: &mut [f64],
            ) {
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
    };
}
// A borrowed problem is a problem (lets solvers borrow problems that are not
// `Clone`, e.g. `GeneralProblem` with closures); `&dyn PeriodicProblem` lets
// every model share one compiled engine.
forward_pointer!(&P);
// A boxed problem is a problem: a family whose members are `BoxedProblem`s
// shares one compiled engine whatever its members' type.
forward_pointer!(Box<P>);

/// A problem of any type behind one pointer type. The jobs take
/// `&dyn PeriodicProblem` and families of `BoxedProblem`s, so that the engine
/// is compiled once for every model rather than once per model type (each
/// closure is a type of its own); one virtual call per residual evaluation
/// (`g` at all samples at once) is the price.
pub type BoxedProblem<'a> = Box<dyn PeriodicProblem + 'a>;

/// A family `p ↦ problem` with its members boxed, as the engine's and the
/// jobs' bodies take it: a family function is then compiled once, not once
/// per family type in every caller ([`BoxedProblem`]).
pub type BoxedFamily<'f, 'p> = dyn Fn(f64) -> Result<BoxedProblem<'p>, HbError> + 'f;

/// `family` with its members boxed ([`BoxedFamily`]).
pub fn boxed_family<'p, P: PeriodicProblem + 'p>(
    family: impl Fn(f64) -> Result<P, HbError>,
) -> impl Fn(f64) -> Result<BoxedProblem<'p>, HbError> {
    move |p| family(p).map(|m| Box::new(m) as BoxedProblem<'p>)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `g = x₀³ + x₀x₁ + v₁` on two DOFs, without an analytic Jacobian.
    struct Cubic {
        n: usize,
        m: Vec<f64>,
        c: Vec<f64>,
        k: Vec<f64>,
    }

    impl PeriodicProblem for Cubic {
        matrix_getters!();
        fn nonlinear(&self, x: &[f64], v: &[f64], _theta: f64, out: &mut [f64]) {
            out[0] = x[0].powi(3) + x[0] * x[1] + v[1];
            out[1] = 0.0;
        }
    }

    fn cubic() -> Cubic {
        let eye = vec![1.0, 0.0, 0.0, 1.0];
        Cubic {
            n: 2,
            m: eye.clone(),
            c: vec![0.0; 4],
            k: eye,
        }
    }

    #[test]
    fn default_jacobian_is_the_closed_form_and_nan_for_wrong_sizes() {
        let p = cubic();
        let (x, v) = ([0.5, 2.0], [0.0, 1.0]);
        let mut dg = [0.0; 8];
        p.nonlinear_jacobian(&x, &v, 0.0, &mut dg);
        // ∂g₀/∂x = (3x₀² + x₁, x₀) = (2.75, 0.5), ∂g₀/∂v = (0, 1); row 1 zero.
        let exact = [2.75, 0.5, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0];
        for (a, b) in dg.iter().zip(exact) {
            assert!((a - b).abs() < 1e-8, "{dg:?}");
        }
        let mut short = [0.0; 7];
        p.nonlinear_jacobian(&x, &v, 0.0, &mut short);
        assert!(short.iter().all(|d| d.is_nan()));
        p.nonlinear_jacobian(&x[..1], &v, 0.0, &mut dg);
        assert!(dg.iter().all(|d| d.is_nan()));
    }

    #[test]
    fn per_sample_and_central_differences_of_short_states_give_nan() {
        let p = cubic();
        let theta = [0.0, 1.0];
        // Two samples need 4 entries of x and v.
        let (x, v) = ([0.5, 2.0, 0.1], [0.0; 4]);
        let mut g = [0.0; 4];
        p.nonlinear_samples(&x, &v, &theta, &mut g);
        assert!(g.iter().all(|e| e.is_nan()));
        let mut dg = [0.0; 16];
        central_difference_samples(&p, &x, &v, &theta, &mut dg);
        assert!(dg.iter().all(|e| e.is_nan()));
        let mut out = [0.0; 2];
        per_sample(0, &[], &[], &theta, &mut out, |_, _, _, _| {});
        assert!(out.iter().all(|e| e.is_nan()));
        // The right sizes: one call per sample.
        per_sample(
            1,
            &[3.0, 4.0],
            &[0.0; 2],
            &theta,
            &mut out,
            |x, _, th, o| o[0] = x[0] + th,
        );
        assert_eq!(out, [3.0, 5.0]);
    }

    #[test]
    fn one_dof_models_without_a_state_give_nan() {
        let mut out = [0.0];
        Duffing::fig28().nonlinear(&[], &[], 0.0, &mut out);
        assert!(out[0].is_nan());
        MathieuDuffing::thesis(1.0).nonlinear(&[], &[], 0.0, &mut out);
        assert!(out[0].is_nan());
    }
}
