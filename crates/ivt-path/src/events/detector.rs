//! What every event shares: its kind, its located result, the options of the
//! locators, and the [`Detector`] trait an event implements — a test function
//! evaluated at each accepted path point and a locator (Newton on a minimally
//! extended system, Govaerts' bordering) started where the test changes sign.

use crate::branch::Branch;
use crate::continuation::PathPoint;
use crate::error::PathError;
use crate::multipliers::StabilityKind;
use faer::c64;
use ivt_num::vector::norm2;

/// The kind of a located bifurcation (in the order the [`Observer`]s
/// report events found between the same two points).
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, serde::Serialize)]
#[serde(rename_all = "snake_case")]
pub enum BifurcationKind {
    /// A turning point in λ (a real multiplier through +1), located by
    /// [`crate::events::locate_fold`].
    Fold,
    /// A real Floquet multiplier through −1.
    PeriodDoubling,
    /// A complex pair of multipliers through the unit circle.
    NeimarkSacker,
    /// Two branches cross (rank loss of `[∂R/∂q, ∂R/∂λ]`).
    BranchPoint,
    /// A component of the path vector crosses a set value (not a
    /// bifurcation: a requested point, [`crate::events::Crossing`]).
    Crossing,
}

impl BifurcationKind {
    /// The kind in words, for messages ("period doubling").
    pub fn words(self) -> &'static str {
        match self {
            Self::Fold => "fold",
            Self::PeriodDoubling => "period doubling",
            Self::NeimarkSacker => "Neimark–Sacker point",
            Self::BranchPoint => "branch point",
            Self::Crossing => "crossing of a set value",
        }
    }
}

/// Options of the event locators (Newton on the extended systems) and of the
/// multipliers reported at a located event.
#[derive(Debug, Clone, PartialEq)]
pub struct LocateOptions {
    /// Hsu sub-intervals of the monodromy matrix (Magnus4; > harmonics).
    pub stability_steps: usize,
    /// Stop when the Newton step is below this, relative to ‖q‖∞ and |λ|.
    pub step_tol: f64,
    /// Also stop when the step is below this (relative) and the residual no
    /// longer falls by 4× per step: the noise floor of the finite differences
    /// (e.g. a user `g` without analytic Jacobian).
    pub noise_tol: f64,
    /// Maximum Newton steps.
    pub max_iter: usize,
    /// Relative central-difference step for `∂R/∂λ` and the test functions.
    pub fd_step: f64,
}

/// The fold locator's step tolerance: its extended system has the analytic
/// gradient `−wᵀ J_q v` (Govaerts), so it converges below the 1e-11 of the
/// differenced test functions of the other events.
pub(crate) const FOLD_STEP_TOL: f64 = 1e-12;

impl Default for LocateOptions {
    /// The options of period doubling, Neimark–Sacker and branch points.
    fn default() -> Self {
        Self {
            stability_steps: 2048,
            step_tol: 1e-11,
            noise_tol: 1e-8,
            max_iter: 30,
            fd_step: 1e-6,
        }
    }
}

impl LocateOptions {
    /// The options of a fold located on its own ([`crate::events::locate_fold`]):
    /// step tolerance 1e-12, 25 Newton steps.
    pub fn fold() -> Self {
        Self {
            step_tol: FOLD_STEP_TOL,
            max_iter: 25,
            ..Self::default()
        }
    }
}

/// One point of the traced branch.
#[derive(Debug, Clone, PartialEq)]
pub struct TracedPoint {
    /// Fourier coefficients.
    pub q: Vec<f64>,
    /// Parameter λ.
    pub lambda: f64,
    /// Floquet multipliers (Hsu), decreasing modulus.
    pub multipliers: Vec<c64>,
    /// Error estimate of their monodromy (ivt-hb's `HsuEstimate::error`):
    /// `None` for fixed Hsu steps.
    pub multiplier_error: Option<f64>,
    /// Stability class.
    pub kind: StabilityKind,
}

/// A located bifurcation.
#[derive(Debug, Clone, PartialEq)]
pub struct Bifurcation {
    /// What it is.
    pub kind: BifurcationKind,
    /// The orbit at the bifurcation.
    pub q: Vec<f64>,
    /// The parameter at the bifurcation.
    pub lambda: f64,
    /// Floquet multipliers there (Hsu), decreasing modulus.
    pub multipliers: Vec<c64>,
    /// Branch point only: an orthonormal basis of the null space of
    /// `[∂R/∂q, ∂R/∂λ]` (two vectors of `m + 1` entries); empty otherwise.
    pub null_vectors: Vec<Vec<f64>>,
    /// Newton steps taken.
    pub iterations: usize,
    /// ‖R(q, λ)‖₂ at the result.
    pub residual_norm: f64,
}

impl Bifurcation {
    /// Branch point: the unit direction of the null space orthogonal to
    /// `tangent` (the tangent of the branch that was followed, `m + 1`
    /// entries): the initial direction of the other branch. `None` for other
    /// kinds.
    pub fn second_direction(&self, tangent: &[f64]) -> Option<Vec<f64>> {
        let [v1, v2] = self.null_vectors.as_slice() else {
            return None;
        };
        let (a, b) = (dot(tangent, v1), dot(tangent, v2));
        // In span{v1, v2} the direction orthogonal to (a, b) is (−b, a).
        let mut d: Vec<f64> = v1.iter().zip(v2).map(|(x, y)| -b * x + a * y).collect();
        let n = norm2(&d);
        if n == 0.0 || !n.is_finite() {
            return None;
        }
        d.iter_mut().for_each(|x| *x /= n);
        Some(d)
    }
}

/// `aᵀb`.
pub fn dot(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(x, y)| x * y).sum()
}

/// An event between points `index` and `index + 1` of a traced path; `E`
/// is the detector's location error.
#[derive(Debug, Clone, PartialEq)]
pub struct Event<E> {
    /// What changed.
    pub kind: BifurcationKind,
    /// The point before the change (the Newton start).
    pub index: usize,
    /// Which detector found it: its position in the observer's list.
    pub detector: usize,
    /// The located bifurcation, or why it could not be located.
    pub location: Result<Bifurcation, E>,
}

/// An event the path passed (its test changed sign between two points) but
/// that could not be located: none is dropped. What was sought, the path
/// point the locator started from (as the caller reports points), and why.
#[derive(Debug, Clone, PartialEq)]
pub struct Unlocated<T> {
    /// What was sought, in the caller's words: `"at"` (with the value in
    /// `value`), `"fold"`, `"cusp"`, a resonance (`"resonance_1_3"`, …).
    pub what: &'static str,
    /// The requested value of an `at` point (`None` otherwise).
    pub value: Option<f64>,
    /// The path point the locator started from.
    pub near: T,
    /// The locator's failure in words, followed by any cause the caller
    /// adds ([`Unlocated::add_cause`]).
    pub reason: String,
}

impl<T> Unlocated<T> {
    /// Appends `cause` to the reason (`"{reason}; {cause}"`): what the
    /// caller knows of the failure beyond the locator's words.
    pub fn add_cause(&mut self, cause: impl std::fmt::Display) {
        self.reason = format!("{}; {cause}", self.reason);
    }
}

/// Watches a path of a [`Branch`] as its points arrive (as BifurcationKit's
/// event detection does): called once per accepted point, in path order, it
/// returns the events that point completes, already located; when the path
/// ends, [`Observer::finish`] locates the events still waiting for a point.
pub trait Observer<B: Branch> {
    /// The failure that ends the observation, and the location error its
    /// events carry.
    type Error;

    /// Takes the newest accepted `point` of the path followed on `branch`.
    ///
    /// # Errors
    /// A failure that ends the observation (e.g. the point's multipliers);
    /// an event that cannot be located is not one, it carries its error in
    /// [`Event::location`].
    fn on_point(
        &mut self,
        branch: &mut B,
        point: &PathPoint,
    ) -> Result<Vec<Event<Self::Error>>, Self::Error>;

    /// The path has ended: the events bracketed but not yet located (their
    /// start is the last point, no point after it will come), located from
    /// the points there are. Default: none.
    ///
    /// # Errors
    /// As [`Observer::on_point`].
    fn finish(&mut self, _branch: &mut B) -> Result<Vec<Event<Self::Error>>, Self::Error> {
        Ok(Vec::new())
    }
}

/// The path as far as it has arrived, as the detectors see it: each accepted
/// point (from the continuation driver) with its multipliers (from the
/// [`PointMultipliers`](crate::events::PointMultipliers) of the observer,
/// if it has one), in path order.
#[derive(Debug, Clone, Default)]
pub struct PathSoFar {
    /// The driver's points `{q, λ}` with their secant λ component and
    /// branch-point sign.
    pub points: Vec<PathPoint>,
    /// The same points with their multipliers.
    pub traced: Vec<TracedPoint>,
}

impl PathSoFar {
    /// Number of points that have arrived.
    pub fn len(&self) -> usize {
        self.points.len()
    }

    /// True before the first point.
    pub fn is_empty(&self) -> bool {
        self.points.is_empty()
    }

    /// Point `k` split into `(q, λ)`, or `None` past the end.
    pub fn q_lambda(&self, k: usize) -> Option<(&[f64], f64)> {
        let x = &self.points.get(k)?.x;
        let (lambda, q) = x.split_last()?;
        Some((q, *lambda))
    }

    /// The multipliers of point `k`, or `None` past the end.
    pub fn multipliers(&self, k: usize) -> Option<&[c64]> {
        self.traced.get(k).map(|p| p.multipliers.as_slice())
    }

    /// Unit secant from point `k` to point `k + 1`, `None` past the end or
    /// for two equal points.
    pub fn secant(&self, k: usize) -> Option<Vec<f64>> {
        let (a, b) = (self.points.get(k)?, self.points.get(k + 1)?);
        let mut t: Vec<f64> = b.x.iter().zip(&a.x).map(|(p, q)| p - q).collect();
        let n = norm2(&t);
        if n == 0.0 || !n.is_finite() {
            return None;
        }
        t.iter_mut().for_each(|v| *v /= n);
        Some(t)
    }
}

/// One kind of event on a [`Branch`]: a test function evaluated
/// at every accepted point, whose sign change between two consecutive points
/// brackets the event, and the locator started there; `E` is its location
/// error. Adding an event is one file implementing this trait; an
/// [`EventObserver`](crate::events::EventObserver) runs every detector as
/// the points arrive. The fold needs the branch alone; ivt-hb's events of
/// the Floquet multipliers implement it for its `FamilyBranch` only.
pub trait Detector<B: Branch, E> {
    /// The kind located.
    fn kind(&self) -> BifurcationKind;

    /// The test function at point `k` of `path` (`k` < `path.len()`; it may
    /// use the points before and, for `k = 0`, the point after). Called once
    /// per point; a zero or NaN never brackets an event.
    fn test(&mut self, branch: &mut B, path: &PathSoFar, k: usize) -> f64;

    /// The sign changed between the two newest points: the index of the
    /// locator's start, or `None` when this is no event of the kind (yet).
    /// Default: the older of the two points.
    fn start(&self, path: &PathSoFar) -> Option<usize> {
        path.len().checked_sub(2)
    }

    /// Locates the event from the start point `at.index`.
    ///
    /// # Errors
    /// Sizes, a singular extended system or non-convergence of its Newton
    /// iteration (with the residual history); per kind as documented there.
    fn locate(&mut self, at: Start<'_, B>) -> Result<Bifurcation, E>;
}

/// Where a locator starts: the branch, the path so far, the index of the
/// start point (`index` < `path.len()`: the point after it, when the path
/// has one, has arrived) and the options.
pub struct Start<'a, B: Branch> {
    /// The branch followed.
    pub branch: &'a mut B,
    /// The path so far.
    pub path: &'a PathSoFar,
    /// The start point.
    pub index: usize,
    /// The locator's options.
    pub opts: &'a LocateOptions,
}

impl<'a, B: Branch> Start<'a, B> {
    /// The start point `(q, λ)`.
    ///
    /// # Errors
    /// [`PathError::InvalidInput`] if `index` is past the path.
    pub fn point(&self) -> Result<(&'a [f64], f64), PathError> {
        let path: &'a PathSoFar = self.path;
        path.q_lambda(self.index)
            .ok_or_else(|| PathError::InvalidInput(format!("no path point {}", self.index)))
    }
}
