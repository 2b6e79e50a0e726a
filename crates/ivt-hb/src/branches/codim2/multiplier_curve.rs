//! Period-doubling and Neimark–Sacker curves of a forced family in (ω, p)
//! (issue 27, item 1): how the point where a Floquet multiplier leaves the
//! unit circle at −1, or a complex pair leaves it at `e^{±iθ}`, moves with a
//! second parameter `p` of `family(p)`.
//!
//! Along such a curve the HB orbit solves `R(q, ω; p) = 0` (Eq. 61) and the
//! monodromy matrix Φ of its linearisation (Hsu's method, Eq. 80, Magnus-4
//! on the grid of the bifurcation locators) has the critical multiplier. The
//! critical eigenvector is an unknown — the standard augmented systems of
//! period-doubling and torus curves (Kuznetsov, *Elements of Applied
//! Bifurcation Theory*, §10.3; the PD/NS curves of cycles of AUTO and
//! MATCONT):
//!
//! - **Period doubling**: `R = 0`, `(Φ + I) v = 0`, `(vᵀv − 1)/2 = 0`, path
//!   vector `[q, ω, v, p]`.
//! - **Neimark–Sacker**: `Φ (v_r + i v_i) = e^{iθ} (v_r + i v_i)` in real
//!   form, `(Φ − cos θ I) v_r + sin θ v_i = 0` and
//!   `−sin θ v_r + (Φ − cos θ I) v_i = 0`, with `(|v_r|² + |v_i|² − 1)/2 = 0`
//!   and the phase `v_r⁰·v_i − v_i⁰·v_r = 0` (`Im ⟨v⁰, v⟩ = 0`, `v⁰` the
//!   start's eigenvector); path vector `[q, ω, θ, v_r, v_i, p]`.
//!
//! Each system has one equation fewer than unknowns and is followed by the
//! engine's pseudo-arclength continuation ([`ivt_path::continuation::Stepper`], Eq. 68–77)
//! with `p` as the path parameter (Φ's derivatives by the path's finite
//! differences). The point at each `p` of `at` is located as the points
//! arrive, solved at that `p` by Newton (the crossing of a set value, as on
//! every curve of [`super`]). On a Neimark–Sacker curve the strong
//! resonances 1:3 and 1:4 (θ = 2π/3, π/2) it crosses are located the same
//! way at fixed θ.
//! At the resonances 1:1 and 1:2 (θ = 0 or π) the NS curve ends on a fold or
//! a period-doubling curve: past them the path would run back along the
//! same curve on the conjugate pair, so it stops at the first point past
//! (θ leaves (0, π)) and the curve is then followed from the start the
//! other way. There the fixed-θ system is singular (every point of the fold
//! or PD curve solves it); as `p`, ω and `q` are even functions of θ − θ_e
//! on the curve, the end is extrapolated from the points at θ_e ± h and
//! θ_e ± 2h.

use super::{bounded, event_vector, follow_leg, path_interval, CurveSystem, Joined, Legs};
use crate::branches::events::{name_family_failures, BifurcationKind, LocateOptions, Unlocated};
use crate::error::HbError;
use crate::orbit::ihb::{HbOptions, HbResidual, HbSolution};
use crate::problem::{BoxedFamily, PeriodicProblem};
use crate::stability::floquet::{eigenvalues, monodromy_uniform, HsuRule};
use crate::stability::StabilityAnalyzer;
use ivt_num::vector::{dot, norm2};
use ivt_num::LuWorkspace;
use ivt_path::continuation::{ContinuationOptions, Termination};
use ivt_path::events::extended::null_vector;
use ivt_path::events::Crossing;
use ivt_path::PathError;
use std::f64::consts::{PI, TAU};

/// A located period doubling or Neimark–Sacker point of the FRC of
/// `family(p)` to start a curve from.
#[derive(Debug, Clone, PartialEq)]
pub struct CurveStart {
    /// [`BifurcationKind::PeriodDoubling`] or
    /// [`BifurcationKind::NeimarkSacker`].
    pub kind: BifurcationKind,
    /// Fourier coefficients of the orbit there.
    pub coeffs: Vec<f64>,
    /// Its excitation frequency ω_f.
    pub omega: f64,
    /// Its `p`.
    pub p: f64,
}

/// One point of a period-doubling or Neimark–Sacker curve.
#[derive(Debug, Clone, PartialEq)]
pub struct CurvePoint {
    /// Excitation frequency ω_f.
    pub omega: f64,
    /// The second parameter.
    pub p: f64,
    /// Fourier coefficients of the orbit.
    pub coeffs: Vec<f64>,
    /// Angle θ ∈ (0, π) of the critical multipliers `e^{±iθ}` (π for a
    /// period doubling).
    pub angle: f64,
}

/// A period-doubling or Neimark–Sacker curve in (ω, p).
#[derive(Debug, Clone, PartialEq)]
pub struct BifurcationCurve {
    /// What the curve's points are.
    pub kind: BifurcationKind,
    /// Points in path order.
    pub points: Vec<CurvePoint>,
    /// The point at each requested `p`, each time the curve crosses it, in
    /// path order.
    pub at: Vec<CurvePoint>,
    /// Strong resonances on a Neimark–Sacker curve, with their order: 1:1
    /// and 1:2 where the curve ends (θ = 0 on a fold curve, θ = π on a
    /// period-doubling curve), 1:3 and 1:4 where it crosses θ = 2π/3, π/2.
    pub resonances: Vec<(u32, CurvePoint)>,
    /// The `at` points and resonances the path passed but whose location
    /// failed, in path order, with the reason.
    pub unlocated: Vec<Unlocated<CurvePoint>>,
    /// Why tracing stopped.
    pub termination: Termination,
}

/// Follows the period doubling or Neimark–Sacker point `start` of the FRC of
/// `family(start.p)` in `p`, first towards `p_from` until `p` leaves
/// `[min(p_from, p_to), max(p_from, p_to)]` or the curve ends (a 1:1 or 1:2
/// resonance), then from the start towards `p_to` (`Legs`). Points are in
/// path order from the first leg's end (from the start when `p_to` is the
/// start); `termination` is that of the last path. The point at each `p` of `at`
/// and the strong resonances are located (module docs). `hb` must be the
/// options `start` was computed with.
///
/// # Errors
/// [`HbError::InvalidInput`] for sizes, bounds (`start.p` must lie in the
/// interval), a kind other than the two, or a start whose monodromy matrix
/// has no such multiplier near the unit circle; `family(start.p)`'s error;
/// the path's start failures as [`ivt_path::follow_residual`]'s. Later, a `p` where
/// `family` fails is a failed step, and an `at` point or resonance whose
/// location fails is reported in [`BifurcationCurve::unlocated`] (the curve
/// is kept).
///
/// `family` is any `p ↦ problem` with its members boxed: `&boxed_family(f)`
/// ([`crate::problem::boxed_family`]), so this body is compiled once for
/// every model.
pub fn bifurcation_curve(
    family: &BoxedFamily<'_, '_>,
    hb: &HbOptions,
    start: &CurveStart,
    p_from: f64,
    p_to: f64,
    at: &[f64],
    opts: &ContinuationOptions,
) -> Result<BifurcationCurve, HbError> {
    let p_start = start.p;
    let (lo, hi) = path_interval("bifurcation curve", start.omega, p_start, p_from, p_to)?;
    let ns = match start.kind {
        BifurcationKind::PeriodDoubling => false,
        BifurcationKind::NeimarkSacker => true,
        other => {
            return Err(HbError::InvalidInput(format!(
                "bifurcation_curve follows period doublings and Neimark–Sacker points, not {other:?} (fold_curve follows folds)"
            )))
        }
    };
    let mut sys = MultiplierSystem::new(&family, hb, p_start, ns)?;
    let m = sys.m;
    if start.coeffs.len() != m || start.coeffs.iter().any(|c| !c.is_finite()) {
        return Err(HbError::InvalidInput(format!(
            "the start must have {m} finite coefficients"
        )));
    }
    let x0 = sys.start_vector(&start.coeffs, start.omega, p_start)?;
    let copts = bounded(opts, (lo, hi));
    let theta_index = m + 1;
    let p_index = x0.len() - 1;
    // The events located as the points arrive (detector d is targets[d]).
    let scale = norm2(&start.coeffs);
    let targets = Target::list(at, ns);
    let watch: Vec<Crossing> = (targets.iter())
        .map(|t| match *t {
            Target::At(p) => Crossing::scaled(p_index, p, scale),
            Target::NearEnd { end, h, .. } => Crossing::scaled(theta_index, end + h, scale),
            Target::Strong(order) => Crossing::scaled(theta_index, TAU / f64::from(order), scale),
        })
        .collect();
    // A Neimark–Sacker path through θ = 0 or π (1:1, 1:2) continues on the
    // conjugate pair back along the same curve: it stops at the point past.
    let legs = Legs::follow((p_start, p_from, p_to), |direction| {
        let residual = |x: &[f64], r: &mut [f64]| sys.residual(x, r);
        follow_leg(residual, &x0, direction, &copts, (&watch, false), |pt| {
            !ns || pt.x.get(theta_index).is_none_or(|t| t.sin() > 0.0)
        })
    })?;
    let joined = legs.joined();
    let located_of = |d: usize| joined.of(d).filter_map(|b| sys.point(&event_vector(b)));
    let located = (targets.iter().enumerate())
        .filter(|(_, t)| matches!(t, Target::At(_)))
        .flat_map(|(d, _)| located_of(d))
        .collect();
    // An end at θ = 0 or π (reached: a point past it, θ within 0.5 of it):
    // the NS system degenerates there (every point of the fold or PD curve
    // solves it), and p, ω, q are even in θ − θ_e: Richardson from the
    // points at θ_e ± h and ± 2h (inside).
    let reached = |end: f64| {
        (joined.points.iter()).any(|pt| {
            (pt.x.get(theta_index)).is_some_and(|t| t.sin() <= 0.0 && (t - end).abs() < 0.5)
        })
    };
    let mut resonances = Vec::new();
    for (d, t) in targets.iter().enumerate() {
        match *t {
            Target::NearEnd {
                order,
                end,
                far: false,
                ..
            } if reached(end) => {
                // the target at 2h follows the one at h
                if let (Some(a), Some(b)) = (located_of(d).next(), located_of(d + 1).next()) {
                    resonances.push((order, richardson(&a, &b, end)));
                }
            }
            Target::Strong(order) => resonances.extend(located_of(d).map(|pt| (order, pt))),
            _ => {}
        }
    }
    // A failed `at` point, strong resonance or, where the curve reached its
    // end, one of the two points an end is extrapolated from.
    let mut unlocated = joined.unlocated(
        |x| sys.point(x),
        |d| match *targets.get(d)? {
            Target::At(p) => Some(("at", Some(p))),
            Target::NearEnd { order, end, .. } => {
                reached(end).then_some((resonance_name(order), None))
            }
            Target::Strong(order) => Some((resonance_name(order), None)),
        },
    );
    name_family_failures(&mut unlocated, |p, _| family(p).err());
    let Joined {
        points: mut path,
        termination,
        ..
    } = joined;
    // The points past a 1:1 or 1:2 end are not on the curve.
    path.retain(|pt| !ns || pt.x.get(theta_index).is_none_or(|t| t.sin() > 0.0));
    let points = path.iter().filter_map(|pt| sys.point(&pt.x)).collect();
    Ok(BifurcationCurve {
        kind: start.kind,
        points,
        at: located,
        resonances,
        unlocated,
        termination,
    })
}

/// What a detector of a period-doubling or Neimark–Sacker curve locates.
#[derive(Debug, Clone, Copy)]
enum Target {
    /// The point at p = the value.
    At(f64),
    /// θ = `end + h` near the 1:`order` end at θ = `end` (0 or π), one of
    /// the two points the end is extrapolated from (`far`: the one at 2h).
    NearEnd {
        order: u32,
        end: f64,
        h: f64,
        far: bool,
    },
    /// The strong resonance 1:`order` (3 or 4) at θ = 2π/order.
    Strong(u32),
}

impl Target {
    /// The `at` values of p, and on a Neimark–Sacker curve (`ns`) the points
    /// at θ_e ± h, ± 2h of the 1:1 and 1:2 ends (each pair h first) and the
    /// strong resonances 1:3, 1:4.
    fn list(at: &[f64], ns: bool) -> Vec<Self> {
        let mut out: Vec<Self> = at.iter().map(|&p| Self::At(p)).collect();
        if ns {
            let h = RESONANCE_STEP;
            for (order, end, h) in [(1, 0.0, h), (2, PI, -h)] {
                for (h, far) in [(h, false), (2.0 * h, true)] {
                    out.push(Self::NearEnd { order, end, h, far });
                }
            }
            out.extend([Self::Strong(3), Self::Strong(4)]);
        }
        out
    }
}

/// The JSON name of the strong resonance 1:`order`.
fn resonance_name(order: u32) -> &'static str {
    match order {
        1 => "resonance_1_1",
        2 => "resonance_1_2",
        3 => "resonance_1_3",
        _ => "resonance_1_4",
    }
}

/// The offset `h` of θ from a 1:1 or 1:2 end of the points its location
/// extrapolates from: the error of the extrapolation is O(h⁴), that of the
/// two points, solved where the system is singular as θ → θ_e, about
/// 1e-11/h (measured on the forced Van der Pol, tests/ns_curve.rs).
const RESONANCE_STEP: f64 = 5e-3;

/// The point at θ_e from the points `a` at θ_e ± h and `b` at θ_e ± 2h of a
/// curve even in θ − θ_e: `(4a − b)/3` (Richardson, error O(h⁴)).
fn richardson(a: &CurvePoint, b: &CurvePoint, theta: f64) -> CurvePoint {
    let mix = |x: f64, y: f64| (4.0 * x - y) / 3.0;
    CurvePoint {
        omega: mix(a.omega, b.omega),
        p: mix(a.p, b.p),
        coeffs: a
            .coeffs
            .iter()
            .zip(&b.coeffs)
            .map(|(x, y)| mix(*x, *y))
            .collect(),
        angle: theta,
    }
}

/// The monodromy matrix Φ of an HB orbit (Hsu, Magnus-4, the locators'
/// [`LocateOptions::stability_steps`]).
struct Monodromy {
    analyzer: StabilityAnalyzer,
    steps: usize,
    dim: usize,
    phi: Vec<f64>,
    orbit: HbSolution,
}

impl Monodromy {
    fn new<P: PeriodicProblem>(problem: &P, hb: &HbOptions) -> Result<Self, HbError> {
        let steps = LocateOptions::default().stability_steps;
        let dim = 2 * problem.n_dof();
        Ok(Self {
            analyzer: StabilityAnalyzer::new(problem, hb.harmonics, steps)?,
            steps,
            dim,
            phi: vec![0.0; dim * dim],
            orbit: HbSolution {
                coeffs: Vec::new(),
                omega_f: 1.0,
                harmonics: hb.harmonics,
                subharmonic: hb.subharmonic,
                stats: Default::default(),
            },
        })
    }

    /// Φ (row-major `dim×dim`) of the orbit `q` at ω_f.
    fn eval<P: PeriodicProblem>(&mut self, problem: &P, q: &[f64], omega: f64) -> &[f64] {
        self.orbit.coeffs.clear();
        self.orbit.coeffs.extend_from_slice(q);
        self.orbit.omega_f = omega;
        let theta = self.analyzer.theta_samples(problem, &self.orbit);
        let (d, s) = (self.dim, self.steps);
        monodromy_uniform(d, theta, s, TAU, HsuRule::Magnus4, &mut self.phi);
        &self.phi
    }
}

/// The PD or NS system of one family, planned at the last `p`.
struct MultiplierSystem<'f, F> {
    family: &'f F,
    hb: HbOptions,
    planned: f64,
    res: HbResidual,
    mono: Monodromy,
    /// Neimark–Sacker (else period doubling).
    ns: bool,
    /// Unknowns of `q`.
    m: usize,
    /// The start's eigenvector `[v_r⁰, v_i⁰]` (the NS phase condition).
    reference: Vec<f64>,
}

impl<'f, P: PeriodicProblem, F: Fn(f64) -> Result<P, HbError>> MultiplierSystem<'f, F> {
    fn new(family: &'f F, hb: &HbOptions, p: f64, ns: bool) -> Result<Self, HbError> {
        let problem = family(p)?;
        let res = HbResidual::new(&problem, hb)?;
        Ok(Self {
            family,
            hb: hb.clone(),
            planned: p,
            m: res.len(),
            res,
            mono: Monodromy::new(&problem, hb)?,
            ns,
            reference: Vec::new(),
        })
    }

    /// Plans the residual and the monodromy for `p`; `None` where the
    /// family fails.
    fn plan(&mut self, p: f64) -> Option<P> {
        let problem = (self.family)(p).ok()?;
        if p != self.planned {
            self.res = HbResidual::new(&problem, &self.hb).ok()?;
            self.mono = Monodromy::new(&problem, &self.hb).ok()?;
            self.planned = p;
        }
        Some(problem)
    }

    /// The path vector at the start: the critical multiplier of Φ (the real
    /// one nearest −1, or the upper one of the complex pair nearest the unit
    /// circle) and a unit eigenvector by inverse iteration.
    fn start_vector(&mut self, q: &[f64], omega: f64, p: f64) -> Result<Vec<f64>, HbError> {
        let problem = self
            .plan(p)
            .ok_or_else(|| HbError::InvalidInput("the family fails at the start's p".into()))?;
        let dim = self.mono.dim;
        let phi = self.mono.eval(&problem, q, omega).to_vec();
        let mu = eigenvalues(&phi, dim);
        let no_multiplier = |what: &str| {
            HbError::InvalidInput(format!(
                "the start's monodromy matrix has no {what} (multipliers {mu:?})"
            ))
        };
        let (theta, a) = if self.ns {
            let z = mu
                .iter()
                .filter(|z| z.im > 1e-9 && (z.norm() - 1.0).abs() < 1e-3)
                .min_by(|a, b| (a.norm() - 1.0).abs().total_cmp(&(b.norm() - 1.0).abs()))
                .ok_or_else(|| no_multiplier("complex pair on the unit circle"))?;
            let theta = z.arg();
            (Some(theta), eigen_matrix(&phi, dim, Some(theta)))
        } else {
            mu.iter()
                .filter(|z| z.im == 0.0 && (z.re + 1.0).abs() < 1e-3)
                .min_by(|a, b| (a.re + 1.0).abs().total_cmp(&(b.re + 1.0).abs()))
                .ok_or_else(|| no_multiplier("multiplier −1"))?;
            (None, eigen_matrix(&phi, dim, None))
        };
        let n = a.len().isqrt();
        let mut lu = LuWorkspace::new(n);
        // Singular to rounding at a located point: inverse iteration still
        // serves (its result is checked).
        lu.factor_row_major(&a);
        let mut v = vec![1.0 / (n as f64).sqrt(); n];
        if !null_vector(&mut lu, &mut v, false) {
            return Err(HbError::Path(PathError::SingularStart { lambda: p }));
        }
        self.reference = if self.ns { v.clone() } else { Vec::new() };
        let mut x = q.to_vec();
        x.push(omega);
        x.extend(theta);
        x.extend_from_slice(&v);
        x.push(p);
        Ok(x)
    }
}

impl<P: PeriodicProblem, F: Fn(f64) -> Result<P, HbError>> CurveSystem for MultiplierSystem<'_, F> {
    type Point = CurvePoint;

    /// The residual (module docs) at the path vector `x`; `None` if the
    /// sizes disagree or `p` cannot be planned.
    fn try_residual(&mut self, x: &[f64], r: &mut [f64]) -> Option<()> {
        let (q, rest) = x.split_at_checked(self.m)?;
        let (&omega, rest) = rest.split_first()?;
        let (&p, rest) = rest.split_last()?;
        let (r_orbit, r_eigen) = r.split_at_mut_checked(self.m)?;
        let problem = self.plan(p)?;
        self.res.eval(&problem, q, omega, 1.0, r_orbit);
        let d = self.mono.dim;
        let phi = self.mono.eval(&problem, q, omega);
        if !self.ns {
            let (r_v, [r_norm]) = r_eigen.split_at_mut_checked(d)? else {
                return None;
            };
            // (Φ + I) v.
            for ((ri, row), vi) in r_v.iter_mut().zip(phi.chunks_exact(d)).zip(rest) {
                *ri = dot(row, rest) + vi;
            }
            *r_norm = 0.5 * (dot(rest, rest) - 1.0);
            return (rest.len() == d).then_some(());
        }
        let (&theta, v) = rest.split_first()?;
        let (vr, vi) = v.split_at_checked(d)?;
        let (r_re, rest_r) = r_eigen.split_at_mut_checked(d)?;
        let (r_im, [r_norm, r_phase]) = rest_r.split_at_mut_checked(d)? else {
            return None;
        };
        let (s, c) = theta.sin_cos();
        // Φ v_r − c v_r + s v_i and Φ v_i − s v_r − c v_i.
        for (i, row) in phi.chunks_exact(d).enumerate() {
            let (a, b) = (*vr.get(i)?, *vi.get(i)?);
            *r_re.get_mut(i)? = dot(row, vr) - c * a + s * b;
            *r_im.get_mut(i)? = dot(row, vi) - s * a - c * b;
        }
        *r_norm = 0.5 * (dot(v, v) - 1.0);
        let (wr, wi) = self.reference.split_at_checked(d)?;
        *r_phase = dot(wr, vi) - dot(wi, vr);
        (vi.len() == d).then_some(())
    }

    /// The curve's point at the path vector `x` (`None` if `x` is short).
    fn point(&self, x: &[f64]) -> Option<CurvePoint> {
        let (q, rest) = x.split_at_checked(self.m)?;
        let (&omega, rest) = rest.split_first()?;
        let angle = if self.ns { *rest.first()? } else { PI };
        Some(CurvePoint {
            omega,
            p: *rest.last()?,
            coeffs: q.to_vec(),
            angle,
        })
    }
}

/// The real matrix whose null space holds the critical eigenvector:
/// `Φ + I` (`dim×dim`, period doubling, `theta` None) or
/// `[[Φ − cos θ I, sin θ I], [−sin θ I, Φ − cos θ I]]` (`2dim×2dim`, acting
/// on `[v_r; v_i]`).
fn eigen_matrix(phi: &[f64], dim: usize, theta: Option<f64>) -> Vec<f64> {
    let Some(theta) = theta else {
        let mut a = phi.to_vec();
        a.iter_mut().step_by(dim + 1).for_each(|e| *e += 1.0);
        return a;
    };
    let (s, c) = theta.sin_cos();
    let n = 2 * dim;
    let mut a = vec![0.0; n * n];
    for (i, row) in phi.chunks_exact(dim).enumerate() {
        for (j, &e) in row.iter().enumerate() {
            let diag = if i == j { c } else { 0.0 };
            let off = if i == j { s } else { 0.0 };
            for (r, col, val) in [
                (i, j, e - diag),
                (i + dim, j + dim, e - diag),
                (i, j + dim, off),
                (i + dim, j, -off),
            ] {
                if let Some(x) = a.get_mut(r * n + col) {
                    *x = val;
                }
            }
        }
    }
    a
}
