//! The Floquet multipliers of a branch's orbits (Hsu's method, Eq. 78–80):
//! [`Multipliers`], the [`PointMultipliers`] that gives each accepted path
//! point its multipliers as it arrives (the period-doubling and
//! Neimark–Sacker tests read them), and the monodromy matrix Φ at any `(q, λ)` with the locator of
//! a multiplier crossing: Newton on `R = 0` and the bordered test function of
//! a matrix built from Φ that turns singular at the crossing (`Φ + I`,
//! `Φ⊙Φ − I`).

use super::BifurcationError;
use crate::branches::family::{Family, FamilyBranch};
use crate::orbit::ihb::HbError;
use crate::stability::floquet::{eigenvalues, monodromy_uniform, HsuRule};
use crate::stability::{AdaptiveHsu, StabilityAnalyzer};
use faer::c64;
use ivt_num::BorderedLu;
use ivt_path::continuation::PathPoint;
use ivt_path::events::extended::{
    border_null_vectors, check_start, extended_newton, factored, finish,
};
use ivt_path::events::{
    Bifurcation, BifurcationKind, LocateOptions, PointMultipliers, TracedPoint,
};
use ivt_path::PathError;

/// The observer of the multipliers along a path: Hsu's monodromy of each
/// accepted point, its steps chosen per point ([`AdaptiveHsu`]).
pub struct Multipliers {
    hsu: AdaptiveHsu,
}

impl Multipliers {
    /// The observer computing each point's monodromy with `hsu`.
    pub fn new(hsu: AdaptiveHsu) -> Self {
        Self { hsu }
    }
}

impl<F: Family, E: From<HbError>> PointMultipliers<FamilyBranch<F>, E> for Multipliers {
    /// Hsu's monodromy of the point: where the branch's last Galerkin
    /// assembly is the point's, Hsu takes its `∂g` samples
    /// ([`FamilyBranch::jacobian_samples_at`]).
    ///
    /// # Errors
    /// As [`AdaptiveHsu::floquet_with_samples`]; [`HbError::InvalidInput`]
    /// for an empty point.
    fn at(&mut self, branch: &FamilyBranch<F>, point: &PathPoint) -> Result<TracedPoint, E> {
        let Some((&lambda, q)) = point.x.split_last() else {
            return Err(HbError::InvalidInput("empty path point".into()).into());
        };
        let (problem, sol) = branch.solution(q, lambda);
        let known = branch.jacobian_samples_at(&point.x);
        let fl = self.hsu.floquet_with_samples(&problem, &sol, known)?;
        Ok(TracedPoint {
            q: q.to_vec(),
            lambda,
            multipliers: fl.floquet.multipliers,
            multiplier_error: fl.error,
            kind: fl.floquet.kind,
        })
    }
}

/// The monodromy matrix Φ of the orbit `q` at λ (Hsu, Magnus4, `steps` steps).
pub(crate) struct Monodromy {
    analyzer: StabilityAnalyzer,
    steps: usize,
    pub(crate) dim: usize,
    phi: Vec<f64>,
}

impl Monodromy {
    /// Plans Φ of `branch`'s orbits at `lambda`.
    ///
    /// # Errors
    /// As [`StabilityAnalyzer::new`].
    pub(crate) fn new<F: Family>(
        branch: &FamilyBranch<F>,
        lambda: f64,
        steps: usize,
    ) -> Result<Self, HbError> {
        let problem = branch.family().at(lambda).0;
        let analyzer = StabilityAnalyzer::new(&problem, branch.options().harmonics, steps)?;
        let dim = 2 * crate::PeriodicProblem::n_dof(&problem);
        Ok(Self {
            analyzer,
            steps,
            dim,
            phi: vec![0.0; dim * dim],
        })
    }

    /// Φ (row-major `dim × dim`) of the orbit `q` at λ.
    pub(crate) fn eval<F: Family>(
        &mut self,
        branch: &FamilyBranch<F>,
        q: &[f64],
        lambda: f64,
    ) -> &[f64] {
        let (problem, sol) = branch.solution(q, lambda);
        let theta = self.analyzer.theta_samples(&problem, &sol);
        let period = 2.0 * std::f64::consts::PI;
        monodromy_uniform(
            self.dim,
            theta,
            self.steps,
            period,
            HsuRule::Magnus4,
            &mut self.phi,
        );
        &self.phi
    }

    /// The multipliers (eigenvalues of Φ) of the orbit `q` at λ.
    pub(crate) fn multipliers<F: Family>(
        &mut self,
        branch: &FamilyBranch<F>,
        q: &[f64],
        lambda: f64,
    ) -> Vec<c64> {
        let dim = self.dim;
        eigenvalues(self.eval(branch, q, lambda), dim)
    }
}

/// A matrix built from Φ (`dim × dim`, row-major) into `a` that is singular
/// exactly at a multiplier crossing; returns its size.
pub(crate) type TestMatrix = fn(phi: &[f64], dim: usize, a: &mut Vec<f64>) -> usize;

/// `g` of `[[A, b], [cᵀ, 0]] [v; g] = [0; 1]` for fixed borders `b`, `c`: the
/// bordered LU and the right-hand side are kept across the calls of the
/// finite-difference loop of [`extended_newton`].
pub(crate) struct BorderedScalar {
    b: Vec<f64>,
    c: Vec<f64>,
    lu: BorderedLu,
    rhs: Vec<f64>,
}

impl BorderedScalar {
    pub(crate) fn new(b: Vec<f64>, c: Vec<f64>) -> Self {
        let s = b.len();
        Self {
            b,
            c,
            lu: BorderedLu::new(s, 1),
            rhs: vec![0.0; s + 1],
        }
    }

    /// `g` for the `s×s` row-major `a` (NaN if singular).
    pub(crate) fn eval(&mut self, a: &[f64]) -> f64 {
        // Near-singular pivots are accepted (the solve is checked instead).
        if !factored(self.lu.factor(a, &self.b, &self.c, &[0.0])) {
            return f64::NAN;
        }
        self.rhs.fill(0.0);
        if let Some(last) = self.rhs.last_mut() {
            *last = 1.0;
        }
        match (self.lu.solve(&mut self.rhs), self.rhs.last()) {
            (Ok(()), Some(&g)) if self.rhs.iter().all(|v| v.is_finite()) => g,
            _ => f64::NAN,
        }
    }
}

/// Locates the multiplier crossing of kind `kind` whose test matrix is
/// `matrix` nearest the converged orbit `(q0, λ0)` of `branch`: borders from
/// the near-null vectors of the test matrix at the start, then
/// [`extended_newton`] on `[R; g] = 0`; the multipliers at the result.
///
/// # Errors
/// [`BifurcationError::Hb`] for sizes, a singular bordered or extended system
/// (with the history), non-convergence.
pub(crate) fn locate_crossing<F: Family>(
    branch: &mut FamilyBranch<F>,
    (kind, matrix): (BifurcationKind, TestMatrix),
    q0: &[f64],
    lambda0: f64,
    opts: &LocateOptions,
) -> Result<Bifurcation, BifurcationError> {
    check_start(branch, q0, lambda0)?;
    let mut mono = Monodromy::new(branch, lambda0, opts.stability_steps)?;
    let dim = mono.dim;
    let mut a = Vec::new();
    let s = matrix(mono.eval(branch, q0, lambda0), dim, &mut a);
    let (mut b, mut c) = (
        vec![1.0 / (s as f64).sqrt(); s],
        vec![1.0 / (s as f64).sqrt(); s],
    );
    border_null_vectors(&a, &mut c, &mut b).map_err(PathError::from)?;
    let mut bordered = BorderedScalar::new(b, c);
    let (q, lambda, iterations) = extended_newton(
        branch,
        (q0, lambda0),
        &[],
        |br: &mut FamilyBranch<F>, q: &[f64], l: f64, out: &mut [f64]| {
            matrix(mono.eval(br, q, l), dim, &mut a);
            if let Some(g) = out.first_mut() {
                *g = bordered.eval(&a);
            }
        },
        opts,
    )?;
    let mut mono = Monodromy::new(branch, lambda, opts.stability_steps)?;
    let multipliers = mono.multipliers(branch, &q, lambda);
    Ok(finish(
        branch,
        kind,
        (q, lambda),
        multipliers,
        Vec::new(),
        iterations,
    ))
}
