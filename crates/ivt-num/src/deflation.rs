//! Deflated Newton (Farrell, Birkisson & Funke, SIAM J. Sci. Comput. 37
//! (2015); BifurcationKit's `DeflationOperator`): once roots `x₁…x_k` of
//! `F(x) = 0` are known, Newton is run on
//!
//! `G(x) = M(x) F(x)`,  `M(x) = Πᵢ (‖x − xᵢ‖⁻ᵖ/s⁻ᵖ + σ)`,
//!
//! whose only roots are the other roots of `F` (M blows up at each `xᵢ`).
//! The deflated step is the plain one `δ₀ = −F′⁻¹F` rescaled by
//! Sherman–Morrison, `δ = δ₀ / (1 − ∇ln M · δ₀)`, so one factorization per
//! step serves (the Jacobian of `G` is never assembled). A [`Solver`] of the
//! iteration core; the Newton system and workspace are those of
//! [`crate::newton()`].

use crate::iteration::{Progress, SolveError, Solver, Step};
use crate::newton::{run_newton, NewtonOptions, NewtonStats, NewtonSystem, NewtonWorkspace};
use crate::vector::norm2;

/// The deflation operator `M` of the known roots and the region searched.
#[derive(Debug, Clone, Copy)]
pub struct Deflation<'a> {
    /// The known roots `xᵢ`.
    pub roots: &'a [Vec<f64>],
    /// The power `p`.
    pub power: f64,
    /// The shift `σ` (M → σᵏ far from every root: plain Newton there).
    pub shift: f64,
    /// The scale `s` of the distances.
    pub scale: f64,
    /// An iterate with `|xᵢ| > bound` (or NaN) has left the region searched:
    /// the run has diverged.
    pub bound: f64,
}

impl Deflation<'_> {
    /// `∇ln M(x)` into `grad` (`x.len()` entries):
    /// `∂/∂x ln(‖d‖⁻ᵖ + σ) = −p‖d‖⁻ᵖ⁻² d/s² / (‖d‖⁻ᵖ + σ)` summed over the
    /// roots, `d = (x − xᵢ)/s`.
    pub fn log_gradient(&self, x: &[f64], grad: &mut [f64]) {
        let (p, sigma, s) = (self.power, self.shift, self.scale);
        grad.fill(0.0);
        for root in self.roots {
            let d2: f64 = x.iter().zip(root).map(|(a, b)| ((a - b) / s).powi(2)).sum();
            let dist = d2.sqrt().max(f64::MIN_POSITIVE);
            let mp = dist.powf(-p);
            let w = -p * mp / (dist * dist * (mp + sigma) * s * s);
            for ((g, a), b) in grad.iter_mut().zip(x).zip(root) {
                *g += w * (a - b);
            }
        }
    }
}

/// Deflated Newton on `sys` from `x` (overwritten by the last iterate):
/// full deflated steps (no line search), converged at `‖F‖₂ ≤ opts.ftol`,
/// at most `opts.max_iter` steps; the Jacobian's factorization as in
/// [`crate::newton()`] (`accept_near_singular` and `scale_rows` honoured, the other
/// line-search and step-test options unused).
///
/// # Errors
/// [`SolveError::SingularJacobian`] for a singular Jacobian or a non-finite
/// step, [`SolveError::NonFinite`] for a non-finite residual or deflation
/// factor, [`SolveError::NonConvergence`] after `max_iter` steps or when an
/// iterate leaves `deflation.bound`; the system's errors as
/// [`SolveError::Eval`].
pub fn deflated_newton<S: NewtonSystem + ?Sized>(
    sys: &mut S,
    x: &mut [f64],
    deflation: &Deflation<'_>,
    ws: &mut NewtonWorkspace,
    opts: &NewtonOptions,
) -> Result<NewtonStats, SolveError<S::Error>> {
    let n = x.len();
    if ws.dim() != n || ws.lu.borders() != 0 {
        *ws = NewtonWorkspace::new(n);
    }
    let mut history = std::mem::take(&mut ws.history);
    let mut solver = Deflated {
        sys,
        deflation,
        ws,
        opts,
        grad: vec![0.0; n],
        residual_evals: 0,
        jacobian_evals: 0,
    };
    let stats = run_newton(&mut solver, x, opts, &mut history, |s| {
        (s.residual_evals, s.jacobian_evals)
    });
    ws.history = history;
    stats
}

/// Deflated Newton as a [`Solver`]: the state between two steps of
/// [`deflated_newton`].
struct Deflated<'a, 'r, S: ?Sized> {
    sys: &'a mut S,
    deflation: &'a Deflation<'r>,
    ws: &'a mut NewtonWorkspace,
    /// `accept_near_singular` and `scale_rows` apply to the factorization.
    opts: &'a NewtonOptions,
    /// `∇ln M` at the iterate.
    grad: Vec<f64>,
    residual_evals: usize,
    jacobian_evals: usize,
}

impl<S: NewtonSystem + ?Sized> Solver for Deflated<'_, '_, S> {
    type Error = S::Error;

    fn start(&mut self, x: &mut [f64]) -> Result<f64, SolveError<S::Error>> {
        self.sys
            .residual(x, &mut self.ws.r)
            .map_err(SolveError::Eval)?;
        self.residual_evals += 1;
        Ok(norm2(&self.ws.r))
    }

    fn next_iter(&mut self, x: &mut [f64], at: Progress<'_>) -> Result<Step, SolveError<S::Error>> {
        let ws = &mut *self.ws;
        self.sys
            .jacobian(x, &mut ws.jac)
            .map_err(SolveError::Eval)?;
        self.jacobian_evals += 1;
        if !ws.newton_step(&[], self.opts) {
            return Err(at.singular());
        }
        self.deflation.log_gradient(x, &mut self.grad);
        let along: f64 = self.grad.iter().zip(&ws.dx).map(|(g, s)| g * s).sum();
        let factor = 1.0 / (1.0 - along);
        if !factor.is_finite() {
            return Err(at.non_finite());
        }
        for (xi, si) in x.iter_mut().zip(&ws.dx) {
            *xi += factor * si;
        }
        let bound = self.deflation.bound;
        if x.iter().any(|v| v.abs() > bound || v.is_nan()) {
            return Err(at.non_convergence());
        }
        self.sys.residual(x, &mut ws.r).map_err(SolveError::Eval)?;
        self.residual_evals += 1;
        Ok(Step::Moved {
            norm: norm2(&ws.r),
            converged: false,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `F(x) = (x − 1)(x − 2)(x + 3)`, roots 1, 2 and −3.
    struct Cubic;

    impl NewtonSystem for Cubic {
        type Error = ();
        fn residual(&mut self, x: &[f64], r: &mut [f64]) -> Result<(), ()> {
            r[0] = (x[0] - 1.0) * (x[0] - 2.0) * (x[0] + 3.0);
            Ok(())
        }
        fn jacobian(&mut self, x: &[f64], jac: &mut [f64]) -> Result<(), ()> {
            // d/dx (x³ − 7x + 6) = 3x² − 7.
            jac[0] = 3.0 * x[0] * x[0] - 7.0;
            Ok(())
        }
    }

    /// From x = 1.1 plain Newton (no known root) returns 1; deflated by the
    /// root 1 it reaches another root (2 or −3, to 1e-12); deflated by 1 and
    /// 2 it reaches −3; a bound of 1.5 stops the run that leaves it.
    #[test]
    fn deflation_reaches_the_other_roots() {
        let opts = NewtonOptions {
            ftol: 1e-12,
            max_iter: 60,
            ..NewtonOptions::default()
        };
        let mut ws = NewtonWorkspace::new(1);
        let run = |roots: &[Vec<f64>], bound: f64, ws: &mut NewtonWorkspace| {
            let deflation = Deflation {
                roots,
                power: 2.0,
                shift: 1.0,
                scale: 1.0,
                bound,
            };
            let mut x = [1.1];
            deflated_newton(&mut Cubic, &mut x, &deflation, ws, &opts).map(|_| x[0])
        };
        let plain = run(&[], 100.0, &mut ws).unwrap();
        assert!((plain - 1.0).abs() < 1e-12, "{plain}");
        let other = run(&[vec![1.0]], 100.0, &mut ws).unwrap();
        assert!(
            (other - 2.0).abs() < 1e-12 || (other + 3.0).abs() < 1e-12,
            "{other}"
        );
        let last = run(&[vec![1.0], vec![2.0]], 100.0, &mut ws).unwrap();
        assert!((last + 3.0).abs() < 1e-12, "{last}");
        let bounded = run(&[vec![1.0], vec![2.0]], 1.5, &mut ws);
        assert!(
            matches!(bounded, Err(SolveError::NonConvergence { .. })),
            "{bounded:?}"
        );
    }

    /// `∇ln M` against a central difference of `ln M` at a point off two
    /// roots in the plane.
    #[test]
    fn log_gradient_is_the_gradient_of_ln_m() {
        let roots = [vec![1.0, 0.5], vec![-0.3, 2.0]];
        let d = Deflation {
            roots: &roots,
            power: 2.0,
            shift: 0.7,
            scale: 1.3,
            bound: f64::INFINITY,
        };
        let ln_m = |x: &[f64]| -> f64 {
            roots
                .iter()
                .map(|r| {
                    let d2: f64 = x.iter().zip(r).map(|(a, b)| ((a - b) / 1.3).powi(2)).sum();
                    (d2.sqrt().powf(-2.0) + 0.7).ln()
                })
                .sum()
        };
        let x = [0.2, 0.9];
        let mut grad = [0.0; 2];
        d.log_gradient(&x, &mut grad);
        for k in 0..2 {
            let h = 1e-6;
            let (mut p, mut m) = (x, x);
            p[k] += h;
            m[k] -= h;
            let fd = (ln_m(&p) - ln_m(&m)) / (2.0 * h);
            assert!(
                (grad[k] - fd).abs() < 1e-8 * fd.abs().max(1.0),
                "{k}: {grad:?} {fd}"
            );
        }
    }
}
