//! The quasi-periodic response born at a Neimark–Sacker point (issue 45
//! item 1): the torus branch ([`ivt_hb::branches::torus`]) started at a located point of
//! `frc(..., events=True)` and continued in ω_f to `omega_to`, each point
//! read (rotation number, mean and maximum `|x|`, their error estimates, the
//! normal exponent of a one-DOF torus) and the torus solved exactly at each
//! ω_f of `at` (with its Poincaré section).

use super::{all_finite, finite, finite_list, path_steps, Array, Steps};
use ivt_hb::branches::events::LocateOptions;
use ivt_hb::branches::family::{Family, Frequency};
use ivt_hb::branches::torus::measure::{section, WIDER};
use ivt_hb::branches::torus::{
    torus_start, NeimarkSackerStart, TorusBranch, TorusHarmonics, TorusMeasures, TorusOptions,
    Truncation,
};
use ivt_hb::orbit::ihb::HbOptions;
use ivt_hb::problem::PeriodicProblem;
use ivt_hb::HbError;
use ivt_hb::{c64, Corrector};
use ivt_path::branch::Branch;
use ivt_path::continuation::{
    correct_at_fixed_lambda, ContinuationOptions, NewtonCorrector, Step, Stepper, Termination,
};
use serde::Serialize;
use std::time::Instant;

/// The Neimark–Sacker point, the end of the branch and the tori to solve.
#[derive(Debug, Clone, PartialEq)]
pub struct TorusRequest {
    /// ω_f of the located Neimark–Sacker point.
    pub omega: f64,
    /// Its orbit (`n_dof` blocks of `2n + 1`, the `n` of the HB options).
    pub coeffs: Vec<f64>,
    /// Its Floquet multipliers (the critical pair on the unit circle).
    pub multipliers: Vec<c64>,
    /// The branch is continued to this ω_f.
    pub omega_to: f64,
    /// ω_f at which the torus is solved and returned with its section.
    pub at: Vec<f64>,
    /// Harmonics and grid of the torus.
    pub torus: TorusOptions,
    /// The first torus's distance from the orbit along the critical
    /// direction, relative to the orbit's ‖coefficients‖₂.
    pub step: f64,
    /// The path's steps and most points (by default Δη from 0.01 up to 0.05,
    /// 400 points: [`TORUS_STEPS`]).
    pub steps: Steps,
    /// The DOF whose `|x|` is measured.
    pub amplitude_dof: usize,
    /// Estimate the errors of every path point too (one Newton step in a
    /// truncation 4 orders wider per point); the `at` tori always are.
    pub estimate_points: bool,
    /// The `at` tori are solved again in wider truncations until their
    /// error estimate is at most this …
    pub tol: f64,
    /// … or the estimate's truncation would exceed this many unknowns.
    pub max_unknowns: usize,
    /// Points of each `at` torus's Poincaré section.
    pub section_points: usize,
}

/// The torus path's own first step, largest step and most points.
pub const TORUS_STEPS: (f64, f64, usize) = (0.01, 0.05, 400);

impl Default for TorusRequest {
    /// No start (`coeffs` empty): a request is completed by the caller.
    fn default() -> Self {
        Self {
            omega: f64::NAN,
            coeffs: Vec::new(),
            multipliers: Vec::new(),
            omega_to: f64::NAN,
            at: Vec::new(),
            torus: TorusOptions::default(),
            step: 0.02,
            steps: Steps::default(),
            amplitude_dof: 0,
            estimate_points: false,
            tol: 1e-7,
            max_unknowns: 3000,
            section_points: 200,
        }
    }
}

impl TorusRequest {
    /// # Errors
    /// [`HbError::InvalidInput`] for non-finite or non-positive frequencies,
    /// `omega_to` equal to the start's, non-finite coefficients, multipliers
    /// or `at`, a `step` outside (0, 1] or non-positive steps.
    pub fn validate(&self) -> Result<(), HbError> {
        all_finite(&[("omega", self.omega), ("omega_to", self.omega_to)])?;
        if !(self.omega > 0.0 && self.omega_to > 0.0 && self.omega != self.omega_to) {
            return Err(HbError::InvalidInput(format!(
                "the start's ω_f = {:?} and `omega_to` = {:?} must be > 0 and distinct",
                self.omega, self.omega_to
            )));
        }
        finite_list("coeffs", &self.coeffs)?;
        finite_list("at", &self.at)?;
        let parts: Vec<f64> = self.multipliers.iter().flat_map(|z| [z.re, z.im]).collect();
        finite_list("multipliers", &parts)?;
        let step = finite("step", self.step)?;
        if !(step > 0.0 && step <= 1.0) {
            return Err(HbError::InvalidInput(format!(
                "`step` = {step:?} must be in (0, 1]"
            )));
        }
        self.path()?;
        if self.tol.is_nan() || self.tol < 0.0 {
            return Err(HbError::InvalidInput(format!(
                "`tol` = {:?} must be ≥ 0",
                self.tol
            )));
        }
        Ok(())
    }

    /// [`TORUS_STEPS`] with the request's `steps`.
    ///
    /// # Errors
    /// [`HbError::InvalidInput`] for steps [`Steps::on`] refuses.
    pub fn path(&self) -> Result<ContinuationOptions, HbError> {
        path_steps(&self.steps, TORUS_STEPS)
    }
}

/// One torus of the branch.
#[derive(Debug, Clone, Serialize)]
pub struct TorusPoint {
    /// ω_f.
    pub omega: f64,
    /// `Ω/(ω_f/p)` reduced to `[0, ½]`: the turn of the stroboscopic map.
    pub rotation_number: f64,
    /// Ω of the torus's own harmonics (`ν_k = k₁ω_f/p + k₂Ω`).
    pub second_frequency: f64,
    /// Mean of `|x_d|` over the torus.
    pub amplitude_mean: f64,
    /// Maximum of `|x_d|` over the torus.
    pub amplitude_max: f64,
    /// The largest of the three errors below (`None` when not estimated).
    pub error_estimate: Option<f64>,
    /// The estimated errors of `rotation_number`, `amplitude_mean`,
    /// `amplitude_max` (their change to a truncation 4 orders wider).
    pub errors: Option<TorusMeasures>,
    /// The normal Lyapunov exponent (one DOF; `None` otherwise).
    pub normal_exponent: Option<f64>,
    /// `normal_exponent < 0` (one DOF; `None`: not computed).
    pub stable: Option<bool>,
    /// The torus's coefficients (`n_dof` blocks `[a₀, a_k.., b_k..]` over
    /// the branch's `harmonics`, or this point's own).
    pub coeffs: Array<f64>,
    /// The truncation of `coeffs`.
    pub truncation: Truncation,
    /// `[k₁, k₂]` of the coefficient pairs when they differ from the
    /// branch's (an `at` torus solved in a wider truncation).
    pub harmonics: Option<Vec<[i64; 2]>>,
    /// The Poincaré section `θ₁ = 0` of the measured DOF (only for `at`).
    pub section: Option<Section>,
}

/// A Poincaré section: `x` and `v` of one DOF at the forcing phase 0.
#[derive(Debug, Clone, Serialize)]
pub struct Section {
    /// Displacements.
    pub x: Array<f64>,
    /// Velocities.
    pub v: Array<f64>,
}

/// The torus branch: the keys of `ivt hb torus --json` and of
/// `ivt.hb.torus_branch`.
#[derive(Debug, Clone, Serialize)]
pub struct TorusCurve {
    /// ω_f of the Neimark–Sacker point.
    pub start_omega: f64,
    /// The angle φ of its multipliers `e^{±iφ}`.
    pub angle: f64,
    /// Ω at the Neimark–Sacker point.
    pub start_second_frequency: f64,
    /// The kept harmonics.
    pub truncation: Truncation,
    /// `[k₁, k₂]` of each coefficient pair, in order.
    pub harmonics: Vec<[i64; 2]>,
    /// The grid.
    pub samples: [usize; 2],
    /// The tori in path order.
    pub points: Vec<TorusPoint>,
    /// The torus at each ω_f of `at` (each crossing), with its section.
    pub at: Vec<TorusPoint>,
    /// Why the path stopped.
    pub termination: Termination,
    /// Wall time.
    pub time_s: f64,
}

/// The torus branch of `problem`'s frequency response from the
/// Neimark–Sacker point of `req` (its orbit planned with `hb`).
///
/// # Errors
/// [`TorusRequest::validate`]'s; [`torus_start`]'s; an input error when the
/// torus leaves the Neimark–Sacker point on the side away from `omega_to`;
/// the path's start.
pub fn torus(
    problem: &dyn PeriodicProblem,
    hb: &HbOptions,
    req: &TorusRequest,
) -> Result<TorusCurve, HbError> {
    let problem = &problem;
    let family = Frequency(problem);
    req.validate()?;
    let t0 = Instant::now();
    let ns = NeimarkSackerStart {
        coeffs: &req.coeffs,
        harmonics: hb.harmonics,
        lambda: req.omega,
        multipliers: &req.multipliers,
    };
    let options = TorusOptions {
        subharmonic: hb.subharmonic,
        ..req.torus
    };
    let start = torus_start(family, &ns, &options, req.step, &LocateOptions::default())?;
    let (mut branch, first) = (start.branch, start.first);
    let lambda1 = first.last().copied().unwrap_or(f64::NAN);
    if (lambda1 - req.omega) * (req.omega_to - req.omega) < 0.0 {
        return Err(HbError::InvalidInput(format!(
            "the torus leaves the Neimark–Sacker point at ω_f = {:?} towards ω_f = {lambda1:?}: \
             `omega_to` = {:?} must lie on that side",
            req.omega, req.omega_to
        )));
    }
    let mut copts = req.path()?;
    copts.corrector = Corrector::Newton;
    copts.lambda_min = lambda1.min(req.omega_to);
    copts.lambda_max = lambda1.max(req.omega_to);
    let (path, termination) = follow(&mut branch, &first, req.omega_to - lambda1, &copts)?;
    let mut points = Vec::with_capacity(path.len());
    for x in &path {
        points.push(read_point(&mut branch, x, req, req.estimate_points, false)?);
    }
    let at = solve_at(problem, &mut branch, &path, req, &copts)?;
    Ok(TorusCurve {
        start_omega: req.omega,
        angle: start.angle,
        start_second_frequency: start.omega2,
        truncation: options.truncation,
        harmonics: branch.harmonics().iter().map(|(a, b)| [a, b]).collect(),
        samples: {
            let (n1, n2) = options.grid();
            [n1, n2]
        },
        points,
        at,
        termination,
        time_s: t0.elapsed().as_secs_f64(),
    })
}

/// The path of `branch` from `first` (corrected at its λ first) in the
/// direction of `sign`, its phase condition moved to each accepted torus:
/// the states `[coefficients, Ω, λ]` and why it stopped.
///
/// # Errors
/// The start's ([`correct_at_fixed_lambda`], [`Stepper::new`]).
pub fn follow<F: Family>(
    branch: &mut TorusBranch<F>,
    first: &[f64],
    sign: f64,
    copts: &ContinuationOptions,
) -> Result<(Vec<Vec<f64>>, Termination), HbError> {
    let m = branch.len();
    let mut x0 = first.to_vec();
    correct_at_fixed_lambda(branch, &mut x0, copts)?;
    let corrector = Box::new(NewtonCorrector::new(m, copts));
    let mut stepper = Stepper::new(branch, corrector, &x0, 0, sign, copts)?;
    let mut path = Vec::new();
    let termination = loop {
        match stepper.next() {
            Step::Point(p) => {
                let coeffs = p.x.get(..m - 1).unwrap_or_default().to_vec();
                path.push(p.x);
                // The phase condition against the newest torus (it holds
                // there exactly: ⟨∂X/∂θ₂, X⟩ = 0 for any torus).
                if stepper.branch().set_reference(&coeffs).is_err() {
                    break Termination::Stopped;
                }
            }
            Step::Stop(t) => break t,
        }
    };
    Ok((path, termination))
}

/// The point of the state `x` (`[coefficients, Ω, λ]`), with its section
/// when `with_section`.
fn read_point<F: Family>(
    branch: &mut TorusBranch<F>,
    x: &[f64],
    req: &TorusRequest,
    estimate: bool,
    with_section: bool,
) -> Result<TorusPoint, HbError> {
    let Some((&lambda, q)) = x.split_last() else {
        return Err(HbError::InvalidInput("empty torus state".into()));
    };
    let reading = branch.read(q, lambda, req.amplitude_dof, estimate)?;
    let (omega1, omega2) = branch.frequencies_at(q, lambda);
    let section = with_section.then(|| {
        let dof = branch.dof_coeffs(q, req.amplitude_dof);
        let (x, v) = section(
            branch.harmonics(),
            dof,
            (omega1, omega2),
            req.section_points,
        );
        Section {
            x: Array(x),
            v: Array(v),
        }
    });
    let m = reading.measures;
    Ok(TorusPoint {
        omega: branch.family().at(lambda).1,
        rotation_number: m.rotation_number,
        second_frequency: omega2,
        amplitude_mean: m.amplitude_mean,
        amplitude_max: m.amplitude_max,
        error_estimate: reading
            .errors
            .map(|e| e.rotation_number.max(e.amplitude_mean).max(e.amplitude_max)),
        errors: reading.errors,
        normal_exponent: reading.normal_exponent,
        stable: reading.normal_exponent.map(|s| s < 0.0),
        coeffs: Array(
            q.get(..q.len().saturating_sub(1))
                .unwrap_or_default()
                .to_vec(),
        ),
        truncation: branch.options().truncation,
        harmonics: with_section.then(|| branch.harmonics().iter().map(|(a, b)| [a, b]).collect()),
        section,
    })
}

/// The torus at each λ of `req.at` crossed by `path` (each crossing): the
/// state interpolated between the two points around it, corrected at that
/// λ by Newton, refined ([`refined`]) and read with its section.
fn solve_at<P: PeriodicProblem>(
    problem: &P,
    branch: &mut TorusBranch<Frequency<'_, P>>,
    path: &[Vec<f64>],
    req: &TorusRequest,
    copts: &ContinuationOptions,
) -> Result<Vec<TorusPoint>, HbError> {
    let m = branch.len();
    let mut out = Vec::new();
    for &target in &req.at {
        for w in path.windows(2) {
            let [a, b] = w else { continue };
            let (la, lb) = (
                a.get(m).copied().unwrap_or(f64::NAN),
                b.get(m).copied().unwrap_or(f64::NAN),
            );
            let first = path.first().is_some_and(|p| std::ptr::eq(a, p));
            let inside =
                (la - target) * (lb - target) < 0.0 || lb == target || (first && la == target);
            if !inside || la == lb {
                continue;
            }
            let t = (target - la) / (lb - la);
            let mut x: Vec<f64> = a.iter().zip(b).map(|(u, v)| u + t * (v - u)).collect();
            if let Some(l) = x.last_mut() {
                *l = target;
            }
            branch.set_reference(a.get(..m - 1).unwrap_or_default())?;
            correct_at_fixed_lambda(branch, &mut x, copts)?;
            out.push(refined(problem, branch, x, req, copts)?);
        }
    }
    Ok(out)
}

/// The torus `x` (`[coefficients, Ω, λ]`) of `branch`, solved again in
/// wider truncations ([`Truncation::grown`]: along the axes whose edge
/// harmonics are not small; Newton at fixed λ from the narrower torus)
/// while its error estimate exceeds `req.tol` and the estimate's
/// truncation fits `req.max_unknowns`; read with its section.
fn refined<P: PeriodicProblem>(
    problem: &P,
    branch: &mut TorusBranch<Frequency<'_, P>>,
    x: Vec<f64>,
    req: &TorusRequest,
    copts: &ContinuationOptions,
) -> Result<TorusPoint, HbError> {
    let mut best = read_point(branch, &x, req, true, true)?;
    let nd = branch.n_dof();
    let fits = |t: Truncation| {
        TorusHarmonics::new(t.widened(WIDER)).is_ok_and(|h| nd * h.coeff_len() < req.max_unknowns)
    };
    let mut x = x;
    let mut harmonics = branch.harmonics().clone();
    let lambda = x.last().copied().unwrap_or(f64::NAN);
    while best.error_estimate.is_some_and(|e| e > req.tol) {
        let m = branch_len(&harmonics, nd);
        let coeffs = x.get(..m - 1).unwrap_or_default();
        let truncation = harmonics.truncation().grown(&harmonics, coeffs);
        if !fits(truncation) {
            break;
        }
        let options = TorusOptions {
            truncation,
            samples: (0, 0),
            ..*branch.options()
        };
        let mut wide = TorusBranch::planned(Frequency(problem), &options, lambda)?;
        let mut y = wide.embed(&harmonics, coeffs);
        wide.set_reference(&y)?;
        y.extend(x.get(m - 1..).unwrap_or_default());
        correct_at_fixed_lambda(&mut wide, &mut y, copts)?;
        best = read_point(&mut wide, &y, req, true, true)?;
        harmonics = wide.harmonics().clone();
        x = y;
    }
    Ok(best)
}

/// Unknowns of a torus of `nd` DOFs over `harmonics` (Ω included).
fn branch_len(harmonics: &TorusHarmonics, nd: usize) -> usize {
    nd * harmonics.coeff_len() + 1
}
