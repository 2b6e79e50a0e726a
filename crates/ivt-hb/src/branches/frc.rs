//! Frequency-response curves (Fig. 29): the modified-IHB residual followed in ω_f by
//! pseudo-arclength continuation ([`ivt_path::continuation`], Eq. 68–77), with the
//! Floquet multipliers (Hsu, Eq. 80) and stability class at every point. Each
//! turn of the path is located as the points arrive, through the
//! [`Fold`] detector of an observer ([`crate::branches::events::observer`]): Newton on
//! the path engine's minimally extended system ([`crate::branches::events::locate_fold`],
//! the fold itself, not a bracket between two points), started from the path
//! point nearest the turn.

use crate::branches::events::{
    observe, observer, BifurcationKind, Detector, Fold, LocateOptions, PathOptions,
};
use crate::branches::family::{FamilyBranch, Frequency};
use crate::orbit::aft::Aft;
use crate::orbit::ihb::{HbError, HbOptions, HbSolution};
use crate::orbit::modified::ModifiedIhb;
use crate::problem::{AtFrequency, PeriodicProblem};
use crate::stability::{HsuSteps, StabilityKind};
use faer::c64;
use ivt_path::continuation::{ContinuationOptions, Corrector, Steps, Traced};
use ivt_path::events::{Event, TracedPoint};

/// Options of a frequency sweep.
#[derive(Debug, Clone, PartialEq)]
pub struct FrcOptions {
    /// Start frequency ω_f.
    pub from: f64,
    /// End frequency ω_f (may be below `from` for a downward sweep).
    pub to: f64,
    /// The path (λ bounds are set from `from`/`to`; its corrector
    /// [`Corrector::Newton`], the default: chord iterations on the exact
    /// Galerkin Jacobian, about 2–3 residuals per point; or
    /// [`Corrector::Broyden`], the thesis's Eq. 68–77) and the Hsu
    /// sub-intervals of each point's multipliers.
    pub path: PathOptions,
}

impl Default for FrcOptions {
    fn default() -> Self {
        Self {
            from: 0.2,
            to: 3.0,
            path: PathOptions {
                // The chord corrector converges in 2–3 iterations from the
                // second-order prediction, so the step is bounded by Δη ≤ 0.08
                // and the turn and correction tests: 94 points over 0.2–3.0 for
                // Fig. 29 (the Broyden corrector, 6–12 iterations near the peak
                // against the aim of 16: 96 points, the same folds to 1e-15;
                // 36 % more instructions per curve, measured).
                continuation: ContinuationOptions {
                    ds: 0.05,
                    ds_max: 0.08,
                    target_iter: 16,
                    // 3.5 calls of g per point instead of 7.2 on the chain of
                    // tests/corrector.rs.
                    second_order_predictor: true,
                    corrector: Corrector::Newton,
                    ..ContinuationOptions::default()
                },
                stability: HsuSteps::default(),
            },
        }
    }
}

impl FrcOptions {
    /// The default sweep from `from` to `to` with `corrector`.
    pub fn sweep(from: f64, to: f64, corrector: Corrector) -> Self {
        let mut sweep = Self {
            from,
            to,
            ..Self::default()
        };
        sweep.path.continuation.corrector = corrector;
        sweep
    }

    /// [`sweep`](Self::sweep) with `steps` overriding its continuation
    /// steps ([`Steps::on`]).
    ///
    /// # Errors
    /// The reason [`Steps::on`] gives for steps it refuses.
    pub fn stepped_sweep(
        from: f64,
        to: f64,
        corrector: Corrector,
        steps: &Steps,
    ) -> Result<Self, String> {
        let mut sweep = Self::sweep(from, to, corrector);
        sweep.path.continuation = steps.on(sweep.path.continuation)?;
        Ok(sweep)
    }
}

/// One point of the curve.
#[derive(Debug, Clone, PartialEq)]
pub struct FrcPoint {
    /// Excitation frequency ω_f.
    pub omega_f: f64,
    /// max |x_0(τ)| over the 2N AFT samples.
    pub amplitude: f64,
    /// Stability class from the Floquet multipliers.
    pub kind: StabilityKind,
    /// Floquet multipliers (Hsu), decreasing modulus.
    pub multipliers: Vec<c64>,
    /// Error estimate of the monodromy behind `multipliers` ([`crate::HsuEstimate::error`]):
    /// `None` for fixed Hsu steps.
    pub multiplier_error: Option<f64>,
    /// Fourier coefficients.
    pub coeffs: Vec<f64>,
}

impl FrcPoint {
    /// All multipliers inside the unit circle.
    pub fn stable(&self) -> bool {
        self.kind == StabilityKind::Stable
    }
}

/// A fold (turning point in ω_f) of the curve.
#[derive(Debug, Clone, PartialEq)]
pub struct FrcFold {
    /// Index of the path point nearest the turn.
    pub index: usize,
    /// ω_f at the fold.
    pub omega_f: f64,
    /// Amplitude of the fold orbit, as the curve's points measure it
    /// ([`FrcPoint::amplitude`]: max |x_0(τ)| over the 2N AFT samples).
    pub amplitude: f64,
    /// Fourier coefficients of the fold orbit.
    pub coeffs: Vec<f64>,
    /// `true` when Newton on the extended system converged; `false` leaves the
    /// parabola through the three points around the turn in `omega_f` and the
    /// nearest point's orbit in `coeffs` (accurate to the step, ~1e-3).
    pub located: bool,
}

/// A traced frequency-response curve (its events: the folds, turning points
/// in ω_f).
pub type Frc = Traced<FrcPoint, FrcFold>;

/// Traces the frequency-response curve of `problem` from `opts.from` to `opts.to`.
///
/// # Errors
/// [`HbError`] if the start point cannot be solved or the sizes are invalid.
pub fn frequency_response(
    problem: &dyn PeriodicProblem,
    hb: &HbOptions,
    opts: &FrcOptions,
) -> Result<Frc, HbError> {
    let problem = &problem;
    if !(opts.from.is_finite()
        && opts.to.is_finite()
        && opts.from > 0.0
        && opts.to > 0.0
        && opts.from != opts.to)
    {
        return Err(HbError::InvalidInput(
            "sweep bounds must be positive, finite and distinct".into(),
        ));
    }
    let at_start = AtFrequency::new(problem, opts.from);
    let start: HbSolution = ModifiedIhb::new(&at_start, hb.clone())?.solve(opts.from, None)?;
    let mut family = FamilyBranch::new(Frequency(problem), hb, opts.from)?;
    let mut x0 = start.coeffs.clone();
    x0.push(opts.from);
    let mut copts = opts.path.continuation.clone();
    copts.lambda_min = opts.from.min(opts.to);
    copts.lambda_max = opts.from.max(opts.to);
    let direction = if opts.to > opts.from { 1.0 } else { -1.0 };
    // Each point's multipliers and the fold detector's test as the point
    // arrives (an `EventObserver`): where the branch's last Galerkin assembly
    // is the point's (a Newton-corrected point, or every point without the
    // second-order predictor), its ∂g samples serve Hsu's level of the same
    // grid without another evaluation of g; a fold is located once the
    // point after its start has arrived, or from the last point when the
    // path ends there.
    let detectors: Vec<Box<dyn Detector<_, HbError>>> = vec![Box::new(Fold)];
    let locate = LocateOptions::fold();
    let mut observer = observer(&family, opts.from, opts.path.stability, &locate, detectors)?;
    let mut stepper = family.stepper(&x0, start.stats.iterations, direction, &copts)?;
    let (path, events) = observe(&mut stepper, &mut observer, |_, _| true)?;
    let trace = Traced {
        points: observer.into_points(),
        events,
        termination: path.termination,
    };
    // A fold that could not be located keeps the parabola's ω_f through the
    // three points around its turn (the stepper's estimate).
    let estimate = |index: usize| {
        path.events
            .iter()
            .find(|t| t.index == index)
            .map(|t| t.lambda)
    };
    assemble(&trace, hb, estimate)
}

/// The curve of an event trace in ω_f ([`crate::trace`] on a frequency
/// family): its points with their amplitudes, and its fold events as
/// [`FrcFold`]s (located, or the point before the turn when location failed).
///
/// # Errors
/// [`HbError`] if `hb`'s AFT sizes are invalid.
pub fn from_trace(trace: &crate::Trace, hb: &HbOptions) -> Result<Frc, HbError> {
    assemble(trace, hb, |_| None)
}

/// [`from_trace`], an unlocated fold at `estimate(index)` (ω_f), or at its
/// point's ω_f where that is `None`.
fn assemble<E>(
    trace: &Traced<TracedPoint, Event<E>>,
    hb: &HbOptions,
    estimate: impl Fn(usize) -> Option<f64>,
) -> Result<Frc, HbError> {
    let mut probe = AmplitudeProbe::new(hb)?;
    let points: Vec<FrcPoint> = trace
        .points
        .iter()
        .map(|p| FrcPoint {
            omega_f: p.lambda,
            amplitude: probe.of(&p.q),
            kind: p.kind,
            multipliers: p.multipliers.clone(),
            multiplier_error: p.multiplier_error,
            coeffs: p.q.clone(),
        })
        .collect();
    let folds = trace
        .events
        .iter()
        .filter(|e| e.kind == BifurcationKind::Fold)
        .filter_map(|e| {
            let near = points.get(e.index)?;
            let located = e.location.as_ref().ok().map(|b| (b.q.clone(), b.lambda));
            let omega = estimate(e.index).unwrap_or(near.omega_f);
            Some(probe.fold(e.index, located, near, omega))
        })
        .collect();
    Ok(Frc {
        points,
        events: folds,
        termination: trace.termination.clone(),
    })
}

/// `max_τ |x_0(τ)|` over the 2N AFT samples of a coefficient vector (DOF 0):
/// the `amplitude` of [`FrcPoint`] and [`FrcFold`] (and of the jobs' events).
pub struct AmplitudeProbe {
    aft: Aft,
    samples: Vec<f64>,
}

impl AmplitudeProbe {
    /// A probe for the coefficient vectors of `hb`'s harmonics.
    ///
    /// # Errors
    /// [`HbError`] if `hb`'s AFT sizes are invalid.
    pub fn new(hb: &HbOptions) -> Result<Self, HbError> {
        let aft = Aft::new(hb.harmonics, hb.n_half)?;
        Ok(Self {
            samples: vec![0.0; aft.n_samples()],
            aft,
        })
    }

    /// `max |x_0|` over the AFT samples of `q`.
    pub fn of(&mut self, q: &[f64]) -> f64 {
        let l = self.aft.coeff_len();
        self.aft
            .synthesize(q.get(..l).unwrap_or_default(), &mut self.samples);
        self.samples.iter().fold(0.0f64, |a, v| a.max(v.abs()))
    }

    /// The fold next to path point `near` (index `index`): the located orbit
    /// `(q, ω_f)`, or, when location failed, `near`'s orbit at `omega_estimate`.
    fn fold(
        &mut self,
        index: usize,
        located: Option<(Vec<f64>, f64)>,
        near: &FrcPoint,
        omega_estimate: f64,
    ) -> FrcFold {
        match located {
            Some((coeffs, omega_f)) => FrcFold {
                index,
                omega_f,
                amplitude: self.of(&coeffs),
                coeffs,
                located: true,
            },
            None => FrcFold {
                index,
                omega_f: omega_estimate,
                amplitude: near.amplitude,
                coeffs: near.coeffs.clone(),
                located: false,
            },
        }
    }
}
