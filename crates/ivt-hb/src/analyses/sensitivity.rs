//! How a located feature of a frequency-response curve moves with a
//! parameter `p` of a model family (issue 45 item 3): `dω/dp` and `dA/dp`
//! (`A` = max `|x_d|` of the orbit) of a fold, a period doubling, a
//! Neimark–Sacker point, a (symmetry-breaking) branch point, and an
//! amplitude peak, by the adjoint of the event's extended system.
//!
//! A located event solves an extended system `F(y; p) = 0`, `y = (q, ω)`
//! (the HB residual Eq. 61 with a test function that vanishes at the event:
//! the fold's Govaerts bordering, the bordered determinants of `Φ + I` and
//! `Φ⊙Φ − I` of the monodromy matrix (Eq. 80), the stationarity of the
//! amplitude along the curve). Along `p`, `F_y y' + F_p = 0`, so a linear
//! feature `φ(y)` moves by `dφ/dp = −ψᵀ F_p` with the adjoint `F_yᵀ ψ = ∇φ`:
//! one transposed solve per feature on the bordered LU
//! ([`ivt_num::BorderedLu`]) of the located point, and `F_p` by a central
//! difference of the residual and the test in `p` (exact for a parameter
//! the model is linear in, such as a force amplitude). For the fold the
//! test row is exact: `∂g/∂(q, ω) = −wᵀ J_(q, ω) v` with `w`, `v` from the
//! bordered solves ([`crate::Branch::jacobian_gradient`]); for the
//! multiplier events and the peak it is a central difference, as the
//! locators' ([`crate::branches::events`]; the multiplier events' with a wider step,
//! `CROSSING_FD_STEP`).
//!
//! A branch point of a forced curve persists in `p` only through a symmetry
//! (a pitchfork): with `v`, `w` the right and left null vectors of
//! `J = ∂R/∂q` there, `J v = 0` along `p` gives
//! `ω' = −(∇(wᵀJv)·q'_p + ∂_p wᵀJv) / (∇(wᵀJv)·q'_ω + ∂_ω wᵀJv)` with
//! `J q'_p = −R_p`, `J q'_ω = −R_ω` solved on the symmetric complement
//! (bordered by `v`, `w`): two solves.

mod peak;

use crate::branches::events::multipliers::{BorderedScalar, Monodromy, TestMatrix};
use crate::branches::events::neimark_sacker::compound_minus_identity;
use crate::branches::events::period_doubling::shifted_monodromy;
use crate::branches::events::{
    locate_fold, locate_multiplier_crossing, BifurcationError, BifurcationKind, LocateOptions,
};
use crate::branches::family::{Family, FamilyBranch, Frequency};
use crate::error::HbError;
use crate::orbit::ihb::HbOptions;
use crate::problem::BoxedFamily;
use ivt_num::{BorderedLu, LuWorkspace};
use ivt_path::branch::{path_lambda_step, Branch};
use ivt_path::events::extended::{
    border_null_vectors, extended_matrix, extended_newton, factored, null_vector,
};
use peak::{locate_peak, peak};

/// What is followed in `p`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Feature {
    /// A located event of the frequency response.
    Event(BifurcationKind),
    /// The peak of the amplitude along the curve (an extremum of `A` in
    /// arclength, away from folds).
    Peak,
}

impl Feature {
    /// The snake_case name of JSON and Python (`"fold"`, …, `"peak"`).
    pub fn name(self) -> &'static str {
        match self {
            Self::Event(BifurcationKind::Fold) => "fold",
            Self::Event(BifurcationKind::PeriodDoubling) => "period_doubling",
            Self::Event(BifurcationKind::NeimarkSacker) => "neimark_sacker",
            Self::Event(BifurcationKind::BranchPoint) => "branch_point",
            Self::Event(BifurcationKind::Crossing) => "crossing",
            Self::Peak => "peak",
        }
    }

    /// The feature named `name` ([`Self::name`]).
    ///
    /// # Errors
    /// [`HbError::InvalidInput`] naming the known features.
    pub fn from_name(name: &str) -> Result<Self, HbError> {
        [
            Self::Event(BifurcationKind::Fold),
            Self::Event(BifurcationKind::PeriodDoubling),
            Self::Event(BifurcationKind::NeimarkSacker),
            Self::Event(BifurcationKind::BranchPoint),
            Self::Peak,
        ]
        .into_iter()
        .find(|f| f.name() == name)
        .ok_or_else(|| {
            HbError::InvalidInput(format!(
                "unknown feature {name:?}: fold, period_doubling, neimark_sacker, branch_point or peak"
            ))
        })
    }

    /// The feature in words.
    pub fn words(self) -> &'static str {
        match self {
            Self::Event(kind) => kind.words(),
            Self::Peak => "amplitude peak",
        }
    }
}

/// The located feature and its derivatives in `p`.
#[derive(Debug, Clone, PartialEq)]
pub struct Sensitivity {
    /// What it is.
    pub feature: Feature,
    /// ω_f there.
    pub omega: f64,
    /// `A` = max over τ of `|x_d|` there.
    pub amplitude: f64,
    /// `dω_f/dp`.
    pub d_omega_dp: f64,
    /// `dA/dp`.
    pub d_amplitude_dp: f64,
    /// The orbit there.
    pub coeffs: Vec<f64>,
    /// Newton steps of the re-location from the given point.
    pub iterations: usize,
}

/// `A = max_τ |x_d(τ)|` of the orbit `q` (`n` harmonics) and its gradient
/// in `q` (envelope theorem: `±` the basis at the maximising τ).
pub fn amplitude_gradient(q: &[f64], n: usize, d: usize) -> Result<(f64, Vec<f64>), HbError> {
    let l = 2 * n + 1;
    let series = q
        .get(d * l..(d + 1) * l)
        .ok_or_else(|| HbError::InvalidInput(format!("no DOF {d} in the orbit")))?;
    let samples = 16 * l;
    let tau = 2.0 * std::f64::consts::PI;
    let mut best = (0.0f64, 0.0f64);
    for i in 0..samples {
        let t = tau * i as f64 / samples as f64;
        let x = crate::orbit::aft::eval_series(series, t, 0).abs();
        if x > best.0 {
            best = (x, t);
        }
    }
    // Newton on x'(τ) = 0 from the best sample.
    let mut t = best.1;
    for _ in 0..30 {
        let d1 = crate::orbit::aft::eval_series(series, t, 1);
        let d2 = crate::orbit::aft::eval_series(series, t, 2);
        if d2 == 0.0 {
            break;
        }
        let step = d1 / d2;
        t -= step;
        if step.abs() < 1e-15 {
            break;
        }
    }
    let x = crate::orbit::aft::eval_series(series, t, 0);
    if x.abs() < best.0 || !x.is_finite() {
        t = best.1;
    }
    let x = crate::orbit::aft::eval_series(series, t, 0);
    let sign = x.signum();
    let mut grad = vec![0.0; q.len()];
    if let Some(g) = grad.get_mut(d * l..(d + 1) * l) {
        if let Some(g0) = g.first_mut() {
            *g0 = 0.5 * sign;
        }
        for k in 1..=n {
            let (s, c) = (k as f64 * t).sin_cos();
            if let Some(a) = g.get_mut(k) {
                *a = sign * c;
            }
            if let Some(b) = g.get_mut(n + k) {
                *b = sign * s;
            }
        }
    }
    Ok((x.abs(), grad))
}

/// The relative step of the central differences of a multiplier event's
/// test row: the monodromy's rounding (~1e-11 of the bordered test) makes
/// the locators' 1e-6 err by ~1e-5 in `dω/dp`, 1e-4 by ~1e-6 (the period
/// doubling of `tests/sensitivity.rs`, measured).
const CROSSING_FD_STEP: f64 = 1e-4;

/// The step of the central difference in `p`: `1e-6·max(|p|, 1e-3)`.
fn p_step(p: f64) -> f64 {
    1e-6 * p.abs().max(1e-3)
}

/// The three branches at `p` and `p ± h`.
struct Triple<F: Family> {
    at: FamilyBranch<F>,
    plus: FamilyBranch<F>,
    minus: FamilyBranch<F>,
    h: f64,
}

impl<F: Family> Triple<F> {
    /// `∂R/∂p` at `(q, ω)` by the central difference.
    fn residual_p(&mut self, q: &[f64], omega: f64) -> Vec<f64> {
        let m = q.len();
        let (mut plus, mut minus) = (vec![0.0; m], vec![0.0; m]);
        self.plus.residual(q, omega, &mut plus);
        self.minus.residual(q, omega, &mut minus);
        plus.iter()
            .zip(&minus)
            .map(|(a, b)| (a - b) / (2.0 * self.h))
            .collect()
    }
}

/// The derivatives `−ψᵀF_p` of the features ω and `A` from the factored
/// Newton matrix `lu` of the extended system (`q`, then ω, then any
/// unfoldings) and `F_p` (`fp`).
fn adjoint_features(
    lu: &mut BorderedLu,
    m: usize,
    grad_a: &[f64],
    fp: &[f64],
) -> Result<(f64, f64), HbError> {
    let n = lu.dim();
    let mut e_omega = vec![0.0; n];
    if let Some(e) = e_omega.get_mut(m) {
        *e = 1.0;
    }
    let mut e_a = vec![0.0; n];
    e_a.iter_mut().zip(grad_a).for_each(|(e, g)| *e = *g);
    let mut out = [0.0; 2];
    for (o, rhs) in out.iter_mut().zip([&mut e_omega, &mut e_a]) {
        lu.solve_transpose(rhs)
            .map_err(|e| HbError::InvalidInput(format!("the event's extended system: {e}")))?;
        *o = -rhs.iter().zip(fp).map(|(a, b)| a * b).sum::<f64>();
    }
    Ok((out[0], out[1]))
}

/// A bifurcation error as an [`HbError`].
fn bifurcation_error(e: BifurcationError) -> HbError {
    match e {
        BifurcationError::Hb(h) => h,
        other => HbError::InvalidInput(other.to_string()),
    }
}

/// The sensitivity of `feature` located near the orbit `q0` at ω_f = `omega0`
/// on the frequency response of `family(p)` (planned with `hb`; the
/// amplitude of DOF `dof`): the feature is located again from the given
/// point (a fold, period doubling or Neimark–Sacker point by its locator,
/// the peak on its own extended system; a branch point is taken as given),
/// then differentiated (module docs).
///
/// # Errors
/// [`HbError::InvalidInput`] for sizes, a non-finite `p` or `family`'s
/// failure at `p`, `p ± h`; the locator's failure; a singular extended
/// system.
///
/// `family` is any `p ↦ problem` with its members boxed: `&boxed_family(f)`
/// ([`crate::problem::boxed_family`]), so this body is compiled once for
/// every model.
pub fn sensitivity(
    family: &BoxedFamily<'_, '_>,
    hb: &HbOptions,
    feature: Feature,
    (q0, omega0): (&[f64], f64),
    p: f64,
    dof: usize,
) -> Result<Sensitivity, HbError> {
    if !(p.is_finite() && omega0.is_finite() && omega0 > 0.0) {
        return Err(HbError::InvalidInput(format!(
            "p = {p} must be finite and ω_f = {omega0} finite and > 0"
        )));
    }
    let h = p_step(p);
    let (problem, plus, minus) = (family(p)?, family(p + h)?, family(p - h)?);
    let mut t = Triple {
        at: FamilyBranch::new(Frequency(&problem), hb, omega0)?,
        plus: FamilyBranch::new(Frequency(&plus), hb, omega0)?,
        minus: FamilyBranch::new(Frequency(&minus), hb, omega0)?,
        h,
    };
    let m = t.at.len();
    if q0.len() != m {
        return Err(HbError::InvalidInput(format!(
            "the feature's orbit must have {m} coefficients (the same n), got {}",
            q0.len()
        )));
    }
    let n = hb.harmonics;
    let opts = LocateOptions::default();
    let (q, omega, iterations, d_omega_dp, d_amplitude_dp, amplitude) =
        match feature {
            Feature::Event(BifurcationKind::Fold) => {
                let loc = locate_fold(&mut t.at, q0, omega0, &LocateOptions::fold())?;
                let (amplitude, grad) = amplitude_gradient(&loc.q, n, dof)?;
                let (dw, da) = fold(&mut t, &loc.q, loc.lambda, &grad)?;
                (loc.q, loc.lambda, loc.iterations, dw, da, amplitude)
            }
            Feature::Event(
                kind @ (BifurcationKind::PeriodDoubling | BifurcationKind::NeimarkSacker),
            ) => {
                let loc = locate_multiplier_crossing(&mut t.at, kind, q0, omega0, &opts)
                    .map_err(bifurcation_error)?;
                let (amplitude, grad) = amplitude_gradient(&loc.q, n, dof)?;
                let matrix: TestMatrix = if kind == BifurcationKind::PeriodDoubling {
                    shifted_monodromy
                } else {
                    compound_minus_identity
                };
                let rows = LocateOptions {
                    fd_step: CROSSING_FD_STEP,
                    ..opts
                };
                let (dw, da) = crossing(&mut t, matrix, (&loc.q, loc.lambda), &grad, &rows)?;
                (loc.q, loc.lambda, loc.iterations, dw, da, amplitude)
            }
            Feature::Event(BifurcationKind::BranchPoint) => {
                let (amplitude, grad) = amplitude_gradient(q0, n, dof)?;
                let (dw, da) = pitchfork(&mut t, q0, omega0, &grad, &opts)?;
                (q0.to_vec(), omega0, 0, dw, da, amplitude)
            }
            Feature::Event(BifurcationKind::Crossing) => return Err(HbError::InvalidInput(
                "a crossing of a set value is a requested point, not a feature that moves with p"
                    .into(),
            )),
            Feature::Peak => {
                let (q, omega, its) = locate_peak(&mut t.at, (q0, omega0), n, dof, &opts)?;
                let (amplitude, grad) = amplitude_gradient(&q, n, dof)?;
                let (dw, da) = peak(&mut t, (&q, omega), n, dof, &grad, &opts)?;
                (q, omega, its, dw, da, amplitude)
            }
        };
    Ok(Sensitivity {
        feature,
        omega,
        amplitude,
        d_omega_dp,
        d_amplitude_dp,
        coeffs: q,
        iterations,
    })
}

/// The fold's adjoint: the extended system `[R; g]` of Govaerts' bordering
/// with its exact test row `−wᵀJ_(q, ω)v`, `g_p = −wᵀJ_p v`.
fn fold<F: Family>(
    t: &mut Triple<F>,
    q: &[f64],
    omega: f64,
    grad_a: &[f64],
) -> Result<(f64, f64), HbError> {
    let m = q.len();
    let mut jac = vec![0.0; m * m];
    t.at.jacobian(q, omega, &mut jac);
    let seed: Vec<f64> = vec![1.0 / (m as f64).sqrt(); m];
    let (mut c, mut b) = (seed.clone(), seed);
    border_null_vectors(&jac, &mut c, &mut b).map_err(HbError::Solve)?;
    let mut border = BorderedLu::new(m, 1);
    if !factored(border.factor(&jac, &b, &c, &[0.0])) {
        return Err(HbError::InvalidInput(
            "the fold's bordered matrix is singular".into(),
        ));
    }
    let unit = |transpose: bool, lu: &mut BorderedLu| -> Vec<f64> {
        let mut rhs = vec![0.0; m + 1];
        if let Some(e) = rhs.last_mut() {
            *e = 1.0;
        }
        let solved = if transpose {
            lu.solve_transpose(&mut rhs)
        } else {
            lu.solve(&mut rhs)
        };
        if solved.is_err() {
            rhs.fill(f64::NAN);
        }
        rhs.truncate(m);
        rhs
    };
    let (v, w) = (unit(false, &mut border), unit(true, &mut border));
    let h_omega = path_lambda_step(omega);
    let mut r_omega = vec![0.0; m];
    t.at.residual_lambda(q, omega, h_omega, &mut r_omega);
    let mut g_q = vec![0.0; m];
    t.at.jacobian_gradient(q, omega, &w, &v, &mut g_q);
    g_q.iter_mut().for_each(|g| *g = -*g);
    let g_omega = -t.at.bilinear_lambda(q, omega, h_omega, &w, &v);
    let mut lu = BorderedLu::new(m, 1);
    lu.factor(&jac, &r_omega, &g_q, &[g_omega])
        .map_err(|e| HbError::InvalidInput(format!("the fold's extended system: {e}")))?;
    let mut fp = t.residual_p(q, omega);
    let g_p =
        -(t.plus.bilinear(q, omega, &w, &v) - t.minus.bilinear(q, omega, &w, &v)) / (2.0 * t.h);
    fp.push(g_p);
    adjoint_features(&mut lu, m, grad_a, &fp)
}

/// A scalar test `ψ(branch, q, ω)` of a located feature.
type ScalarTest<'a, F> = dyn FnMut(&mut FamilyBranch<F>, &[f64], f64) -> f64 + 'a;

/// The adjoint of a scalar test `ψ` at a located `(q, ω)` of `t.at`: the
/// Newton matrix `[[J, R_ω], [ψ_q, ψ_ω]]` by [`extended_matrix`],
/// `F_p = [R_p; ψ_p]` by central differences (`psi_p` the test's own).
fn scalar_adjoint<F: Family>(
    t: &mut Triple<F>,
    (q, omega): (&[f64], f64),
    test: &mut ScalarTest<'_, F>,
    psi_p: f64,
    grad_a: &[f64],
    opts: &LocateOptions,
) -> Result<(f64, f64), HbError> {
    let m = q.len();
    let matrix = extended_matrix(
        &mut t.at,
        (q, omega),
        &[],
        |br: &mut FamilyBranch<F>, q: &[f64], l: f64, out: &mut [f64]| {
            if let Some(o) = out.first_mut() {
                *o = test(br, q, l);
            }
        },
        opts,
    );
    let n = m + 1;
    let (top, bottom) = matrix.split_at(m * n);
    let mut lu = BorderedLu::new(m, 1);
    lu.factor_rows(top, bottom)
        .map_err(|e| HbError::InvalidInput(format!("the event's extended system: {e}")))?;
    let mut fp = t.residual_p(q, omega);
    fp.push(psi_p);
    adjoint_features(&mut lu, m, grad_a, &fp)
}

/// A multiplier crossing (period doubling, Neimark–Sacker): the bordered
/// test of `matrix(Φ)` with borders from its near-null vectors at the point.
fn crossing<F: Family>(
    t: &mut Triple<F>,
    matrix: TestMatrix,
    (q, omega): (&[f64], f64),
    grad_a: &[f64],
    opts: &LocateOptions,
) -> Result<(f64, f64), HbError> {
    let mut mono = Monodromy::new(&t.at, omega, opts.stability_steps)?;
    let dim = mono.dim;
    let mut a = Vec::new();
    let s = matrix(mono.eval(&t.at, q, omega), dim, &mut a);
    let (mut b, mut c) = (
        vec![1.0 / (s as f64).sqrt(); s],
        vec![1.0 / (s as f64).sqrt(); s],
    );
    border_null_vectors(&a, &mut c, &mut b).map_err(HbError::Solve)?;
    let mut bordered = BorderedScalar::new(b, c);
    let mut psi = move |br: &FamilyBranch<F>, mono: &mut Monodromy, q: &[f64], l: f64| {
        let mut a = Vec::new();
        matrix(mono.eval(br, q, l), dim, &mut a);
        bordered.eval(&a)
    };
    let mut mono_plus = Monodromy::new(&t.plus, omega, opts.stability_steps)?;
    let mut mono_minus = Monodromy::new(&t.minus, omega, opts.stability_steps)?;
    let psi_p = (psi(&t.plus, &mut mono_plus, q, omega) - psi(&t.minus, &mut mono_minus, q, omega))
        / (2.0 * t.h);
    let mut test = move |br: &mut FamilyBranch<F>, q: &[f64], l: f64| psi(br, &mut mono, q, l);
    scalar_adjoint(t, (q, omega), &mut test, psi_p, grad_a, opts)
}

/// The symmetric branch point's derivatives (module docs).
fn pitchfork<F: Family>(
    t: &mut Triple<F>,
    q: &[f64],
    omega: f64,
    grad_a: &[f64],
    opts: &LocateOptions,
) -> Result<(f64, f64), HbError> {
    let m = q.len();
    let mut jac = vec![0.0; m * m];
    t.at.jacobian(q, omega, &mut jac);
    let seed: Vec<f64> = (0..m).map(|i| 1.0 + 0.1 * (i as f64).sin()).collect();
    let (mut v, mut w) = (seed.clone(), seed);
    {
        let mut lu = LuWorkspace::new(m);
        lu.factor_row_major(&jac);
        if !null_vector(&mut lu, &mut v, false) || !null_vector(&mut lu, &mut w, true) {
            return Err(HbError::InvalidInput(
                "no null vector at the branch point".into(),
            ));
        }
    }
    let h_omega = path_lambda_step(omega);
    let mut r_omega = vec![0.0; m];
    t.at.residual_lambda(q, omega, h_omega, &mut r_omega);
    let r_p = t.residual_p(q, omega);
    let mut lu = BorderedLu::new(m, 1);
    if !factored(lu.factor(&jac, &w, &v, &[0.0])) {
        return Err(HbError::InvalidInput(
            "the branch point's bordered matrix is singular".into(),
        ));
    }
    let mut solve = |rhs: &[f64]| -> Result<Vec<f64>, HbError> {
        let mut x: Vec<f64> = rhs.iter().map(|r| -r).collect();
        x.push(0.0);
        lu.solve(&mut x).map_err(|e| {
            HbError::InvalidInput(format!("the branch point's bordered solve: {e}"))
        })?;
        x.truncate(m);
        Ok(x)
    };
    let (q_p, q_omega) = (solve(&r_p)?, solve(&r_omega)?);
    let mut grad = vec![0.0; m];
    t.at.jacobian_gradient(q, omega, &w, &v, &mut grad);
    let dot = |a: &[f64], b: &[f64]| a.iter().zip(b).map(|(x, y)| x * y).sum::<f64>();
    let b_omega = t.at.bilinear_lambda(q, omega, h_omega, &w, &v);
    let b_p =
        (t.plus.bilinear(q, omega, &w, &v) - t.minus.bilinear(q, omega, &w, &v)) / (2.0 * t.h);
    let denominator = dot(&grad, &q_omega) + b_omega;
    if denominator == 0.0 || !denominator.is_finite() {
        return Err(HbError::InvalidInput(format!(
            "the branch point at ω_f = {omega} is not a simple symmetric one: its test does not cross in ω_f ({})",
            opts.step_tol
        )));
    }
    let d_omega = -(dot(&grad, &q_p) + b_p) / denominator;
    let dq: Vec<f64> = q_p
        .iter()
        .zip(&q_omega)
        .map(|(a, b)| a + d_omega * b)
        .collect();
    Ok((d_omega, dot(grad_a, &dq)))
}
