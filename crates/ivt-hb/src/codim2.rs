//! Two-parameter continuation of the folds of frequency-response curves
//! (issue 27, item 1): how a fold moves with a second parameter `p` of a model
//! family `family(p)`, and where two folds meet (the cusp below which the jump
//! disappears).
//!
//! A fold of the FRC in ω is a point where the Galerkin Jacobian `Φ_q`
//! (Eq. 56) of the HB residual `R(q, ω; p)` (Eq. 61) is singular. The standard
//! extended system (Keller; the fold systems of AUTO and MATCONT)
//!
//! `R(q, ω; p) = 0`,  `Φ_q(q, ω; p) v = 0`,  `(vᵀv − 1)/2 = 0`
//!
//! (a unit null vector: a fixed normalisation `cᵀv = 1` lets `v` grow without
//! bound where it turns away from `c`, as it does through a cusp) has the unknowns `{q, v, ω}` and `p`; it is
//! followed by the engine's pseudo-arclength continuation
//! ([`Stepper`], Eq. 68–77) with `p` as the path parameter. A cusp is a
//! turning point of this curve in `p` (there the two folds of the FRC merge):
//! the path's fold detection brackets it and a second, short path with a
//! hundredth of the step through the bracket locates it (parabola through the
//! three points around the turn). The fold at each requested `p` is solved at
//! fixed `p` by Newton ([`ivt_num::newton()`]) from the bracketing points.
//!
//! Here the excitation may depend on `p` (a force amplitude): the residual is
//! planned anew when `p` changes. `family(p)` returns a `Result`, so a family
//! built from user callbacks can fail cleanly.

mod ns_points;
pub use ns_points::{neimark_sacker_points, NeimarkSackerPoint};

use crate::branch::ResidualBranch;
use crate::continuation::{BroydenCorrector, ContinuationOptions, Path, Stepper, Termination};
use crate::error::HbError;
use crate::galerkin::GalerkinJacobian;
use crate::ihb::{HbOptions, HbResidual};
use crate::problem::PeriodicProblem;
use ivt_num::vector::norm2;
use ivt_num::{LuWorkspace, NewtonOptions, NewtonSystem, NewtonWorkspace};

/// One fold on the curve.
#[derive(Debug, Clone, PartialEq)]
pub struct FoldPoint {
    /// Excitation frequency ω_f of the fold.
    pub omega: f64,
    /// The second parameter.
    pub p: f64,
    /// Fourier coefficients of the orbit at the fold.
    pub coeffs: Vec<f64>,
    /// The unit null vector of `Φ_q`.
    pub null_vector: Vec<f64>,
}

/// A fold curve in (ω, p).
#[derive(Debug, Clone, PartialEq)]
pub struct FoldCurve {
    /// Points in path order.
    pub points: Vec<FoldPoint>,
    /// The fold at each requested `p`, each time the curve crosses it, in
    /// path order.
    pub at: Vec<FoldPoint>,
    /// Cusps: turning points of the curve in `p`.
    pub cusps: Vec<FoldPoint>,
    /// Why tracing stopped.
    pub termination: Termination,
}

/// Follows the fold of the FRC of `family(p_start)` at `(start, omega)` (a
/// located fold: coefficients and ω_f) in `p`, first towards `p_from`, until `p`
/// leaves `[min(p_from, p_to), max(p_from, p_to)]`; the folds at each `p` of
/// `at` and the cusps are located (see the module docs).
///
/// # Errors
/// [`HbError::InvalidInput`] for sizes or bounds (`p_start` must lie in the
/// interval); `family(p_start)`'s error; the start's failures as
/// [`Stepper::new`]'s. Later, a `p` where `family` fails is a failed
/// step, and a failed location of an `at` point or cusp is left out (the
/// curve is kept).
#[allow(clippy::too_many_arguments)]
pub fn fold_curve<P, F>(
    family: F,
    hb: &HbOptions,
    start: &[f64],
    omega: f64,
    p_start: f64,
    p_from: f64,
    p_to: f64,
    at: &[f64],
    opts: &ContinuationOptions,
) -> Result<FoldCurve, HbError>
where
    P: PeriodicProblem,
    F: Fn(f64) -> Result<P, HbError>,
{
    let (lo, hi) = (p_from.min(p_to), p_from.max(p_to));
    if ![p_start, p_from, p_to, omega].iter().all(|v| v.is_finite())
        || lo == hi
        || !(lo..=hi).contains(&p_start)
        || omega <= 0.0
    {
        return Err(HbError::InvalidInput(
            "fold curve: finite p_from ≠ p_to with p_start between them, ω > 0".into(),
        ));
    }
    let mut sys = FoldSystem::new(&family, hb, p_start)?;
    let m = sys.m;
    if start.len() != m {
        return Err(HbError::InvalidInput(format!(
            "the start fold must have {m} coefficients"
        )));
    }
    let v0 = sys.null_vector(start, omega, p_start)?;
    let mut x0 = start.to_vec();
    x0.extend_from_slice(&v0);
    x0.extend([omega, p_start]);
    let mut copts = opts.clone();
    copts.lambda_min = lo;
    copts.lambda_max = hi;
    let direction = if p_from < p_start { -1.0 } else { 1.0 };
    let path = {
        let m_len = x0.len().saturating_sub(1);
        let mut residual_branch =
            ResidualBranch::new(m_len, |x: &[f64], r: &mut [f64]| sys.residual(x, r));
        let corrector = Box::new(BroydenCorrector::new(m_len, &copts.broyden, None));
        Stepper::new(&mut residual_branch, corrector, &x0, 0, direction, &copts)?.run(|_, _| true)
    };
    let cusps = path
        .folds
        .iter()
        .filter_map(|f| locate_cusp(&mut sys, &path, f.bracket, &copts))
        .collect();
    let mut located = Vec::new();
    for &p in at {
        for w in path.points.windows(2) {
            let (a, b) = (w[0].lambda(), w[1].lambda());
            if (a - p) * (b - p) <= 0.0 && a != b {
                if let Some(fp) = sys.solve_at(&w[0].x, &w[1].x, p) {
                    located.push(fp);
                }
            }
        }
    }
    let points = path.points.iter().map(|pt| sys.point(&pt.x)).collect();
    Ok(FoldCurve {
        points,
        at: located,
        cusps,
        termination: path.termination,
    })
}

/// The turning point in `p` near `path.points[bracket..bracket + 3]`: a
/// short path through the bracket with 1/100 of its spacing, and the vertex of
/// the parabola through the three points around its own turn.
fn locate_cusp<P: PeriodicProblem, F: Fn(f64) -> Result<P, HbError>>(
    sys: &mut FoldSystem<'_, F>,
    path: &Path,
    bracket: usize,
    opts: &ContinuationOptions,
) -> Option<FoldPoint> {
    let (a, b) = (path.points.get(bracket)?, path.points.get(bracket + 2)?);
    let span: f64 =
        a.x.iter()
            .zip(&b.x)
            .map(|(x, y)| (x - y).powi(2))
            .sum::<f64>()
            .sqrt();
    let ds = span / 200.0;
    let mut fine = opts.clone();
    fine.ds = ds;
    fine.ds_max = ds;
    fine.ds_min = ds * 1e-3;
    fine.max_points = 500;
    let dir = if a.dlambda < 0.0 { -1.0 } else { 1.0 };
    let mut turned = false;
    let local = {
        let m_len = a.x.len().saturating_sub(1);
        let mut residual_branch =
            ResidualBranch::new(m_len, |x: &[f64], r: &mut [f64]| sys.residual(x, r));
        let corrector = Box::new(BroydenCorrector::new(m_len, &fine.broyden, None));
        Stepper::new(&mut residual_branch, corrector, &a.x, 0, dir, &fine)
            .ok()?
            .run(|_, pt| {
                // Stop two points after the turn.
                let stop = turned;
                turned = turned || pt.dlambda * dir < 0.0;
                !stop
            })
    };
    let fold = local.folds.first()?;
    let mut x = local.points.get(fold.index)?.x.clone();
    if let Some(last) = x.last_mut() {
        *last = fold.lambda;
    }
    let mut point = sys.point(&x);
    point.p = fold.lambda;
    Some(point)
}

/// The fold system of one family, with the residual planned at the last `p`.
struct FoldSystem<'f, F> {
    family: &'f F,
    hb: HbOptions,
    /// `p` the residual and Jacobian scratch were planned for.
    planned: f64,
    res: HbResidual,
    galerkin: GalerkinJacobian,
    jac: Vec<f64>,
    /// Unknowns `m` of `q` (and of `v`).
    m: usize,
}

impl<'f, P: PeriodicProblem, F: Fn(f64) -> Result<P, HbError>> FoldSystem<'f, F> {
    fn new(family: &'f F, hb: &HbOptions, p: f64) -> Result<Self, HbError> {
        let res = HbResidual::new(&family(p)?, hb)?;
        let m = res.len();
        Ok(Self {
            family,
            hb: hb.clone(),
            planned: p,
            galerkin: GalerkinJacobian::new(&res),
            res,
            jac: vec![0.0; m * m],
            m,
        })
    }

    /// Plans the residual for `p` (the excitation may depend on it); `None`
    /// where the family fails.
    fn plan(&mut self, p: f64) -> Option<P> {
        let problem = (self.family)(p).ok()?;
        if p != self.planned {
            self.res = HbResidual::new(&problem, &self.hb).ok()?;
            self.planned = p;
        }
        Some(problem)
    }

    /// `[R; Φ_q v; (vᵀv − 1)/2]` at `x = [q, v, ω, p]` (NaN if `p` cannot be
    /// planned, which the path follower rejects).
    fn residual(&mut self, x: &[f64], r: &mut [f64]) {
        let m = self.m;
        let (q, rest) = x.split_at(m);
        let (v, wp) = rest.split_at(m);
        let (omega, p) = (wp[0], wp[1]);
        let Some(problem) = self.plan(p) else {
            r.fill(f64::NAN);
            return;
        };
        self.res.eval(&problem, q, omega, 1.0, &mut r[..m]);
        self.galerkin
            .assemble(&mut self.res, &problem, q, omega, 1.0, &mut self.jac);
        ivt_num::vector::matvec(&self.jac, m, m, v, &mut r[m..2 * m]);
        r[2 * m] = 0.5 * (ivt_num::vector::dot(v, v) - 1.0);
    }

    /// A unit null vector of `Φ_q` at a located fold, by two steps of inverse
    /// iteration.
    fn null_vector(&mut self, q: &[f64], omega: f64, p: f64) -> Result<Vec<f64>, HbError> {
        let problem = self
            .plan(p)
            .ok_or_else(|| HbError::InvalidInput("the family fails at p_start".into()))?;
        self.galerkin
            .assemble(&mut self.res, &problem, q, omega, 1.0, &mut self.jac);
        let mut lu = LuWorkspace::new(self.m);
        let mut v = vec![1.0; self.m];
        if lu.factor_row_major(&self.jac) {
            for _ in 0..2 {
                lu.solve(&mut v);
                let norm = norm2(&v);
                if !(norm.is_finite() && norm > 0.0) {
                    return Err(HbError::SingularStart { lambda: p });
                }
                v.iter_mut().for_each(|x| *x /= norm);
            }
        }
        Ok(v)
    }

    /// The fold at `x = [q, v, ω, p]`.
    fn point(&self, x: &[f64]) -> FoldPoint {
        let m = self.m;
        FoldPoint {
            omega: x[2 * m],
            p: x[2 * m + 1],
            coeffs: x[..m].to_vec(),
            null_vector: x[m..2 * m].to_vec(),
        }
    }

    /// The fold at fixed `p` from the linear interpolation of the path points
    /// `a`, `b` that bracket it (Newton on `{q, v, ω}`, central-difference
    /// Jacobian).
    fn solve_at(&mut self, a: &[f64], b: &[f64], p: f64) -> Option<FoldPoint> {
        let n = 2 * self.m + 1;
        let (pa, pb) = (a[n], b[n]);
        let t = (p - pa) / (pb - pa);
        let mut y: Vec<f64> = a[..n]
            .iter()
            .zip(&b[..n])
            .map(|(u, w)| u + t * (w - u))
            .collect();
        let scale = norm2(&a[..self.m]).max(f64::MIN_POSITIVE);
        let mut fixed = FixedP {
            sys: self,
            p,
            x: vec![0.0; n + 1],
            rp: vec![0.0; n],
            rm: vec![0.0; n],
        };
        let opts = NewtonOptions {
            ftol: 1e-12 * scale.max(1.0),
            ..NewtonOptions::default()
        };
        ivt_num::newton(&mut fixed, &mut y, &mut NewtonWorkspace::new(n), &opts).ok()?;
        y.push(p);
        Some(self.point(&y))
    }
}

/// The fold system at a fixed `p` as a square Newton system in `{q, v, ω}`.
struct FixedP<'s, 'f, F> {
    sys: &'s mut FoldSystem<'f, F>,
    p: f64,
    x: Vec<f64>,
    rp: Vec<f64>,
    rm: Vec<f64>,
}

impl<P: PeriodicProblem, F: Fn(f64) -> Result<P, HbError>> FixedP<'_, '_, F> {
    fn eval(&mut self, y: &[f64], out: Which) {
        let n = y.len();
        self.x[..n].copy_from_slice(y);
        self.x[n] = self.p;
        let r = match out {
            Which::Plus => &mut self.rp,
            Which::Minus => &mut self.rm,
        };
        self.sys.residual(&self.x, r);
    }
}

/// Which scratch residual [`FixedP::eval`] writes.
#[derive(Clone, Copy)]
enum Which {
    Plus,
    Minus,
}

impl<P: PeriodicProblem, F: Fn(f64) -> Result<P, HbError>> NewtonSystem for FixedP<'_, '_, F> {
    type Error = std::convert::Infallible;
    fn residual(&mut self, y: &[f64], r: &mut [f64]) -> Result<(), Self::Error> {
        self.eval(y, Which::Plus);
        r.copy_from_slice(&self.rp);
        Ok(())
    }
    fn jacobian(&mut self, y: &[f64], jac: &mut [f64]) -> Result<(), Self::Error> {
        let n = y.len();
        let mut yp = y.to_vec();
        for j in 0..n {
            let h = 1e-7 * y[j].abs().max(1e-3);
            yp[j] = y[j] + h;
            self.eval(&yp, Which::Plus);
            yp[j] = y[j] - h;
            self.eval(&yp, Which::Minus);
            yp[j] = y[j];
            for i in 0..n {
                jac[i * n + j] = (self.rp[i] - self.rm[i]) / (2.0 * h);
            }
        }
        Ok(())
    }
}
