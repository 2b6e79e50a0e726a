//! The isola search of the diagram: the folds of every branch followed in
//! the forcing scale, and deflated Newton at sample frequencies, for
//! branches no event leads to.

use super::*;
use ivt_hb::problem::boxed_family;

/// The largest step of a fold curve in the forcing scale (its crossings of
/// `s = 1` are solved there exactly; a Python `g` pays per residual).
const FOLD_CURVE_DS_MAX: f64 = 0.2;

/// `problem` with its excitation scaled by `scale` (the isola search's
/// second parameter).
struct ForcingScale<'a, P> {
    problem: &'a P,
    scale: f64,
}

impl<P: PeriodicProblem> PeriodicProblem for ForcingScale<'_, P> {
    fn n_dof(&self) -> usize {
        self.problem.n_dof()
    }
    fn mass(&self) -> &[f64] {
        self.problem.mass()
    }
    fn damping(&self) -> &[f64] {
        self.problem.damping()
    }
    fn stiffness(&self) -> &[f64] {
        self.problem.stiffness()
    }
    fn velocity_dependent(&self) -> bool {
        self.problem.velocity_dependent()
    }
    fn hysteretic(&self) -> bool {
        self.problem.hysteretic()
    }
    fn nonlinear(&self, x: &[f64], v: &[f64], theta: f64, out: &mut [f64]) {
        self.problem.nonlinear(x, v, theta, out)
    }
    fn nonlinear_samples(&self, x: &[f64], v: &[f64], theta: &[f64], out: &mut [f64]) {
        self.problem.nonlinear_samples(x, v, theta, out)
    }
    fn excitation(&self, theta: f64, out: &mut [f64]) {
        self.problem.excitation(theta, out);
        out.iter_mut().for_each(|f| *f *= self.scale);
    }
    fn nonlinear_jacobian(&self, x: &[f64], v: &[f64], theta: f64, dg: &mut [f64]) {
        self.problem.nonlinear_jacobian(x, v, theta, dg)
    }
    fn nonlinear_jacobian_samples(&self, x: &[f64], v: &[f64], theta: &[f64], dg: &mut [f64]) {
        self.problem.nonlinear_jacobian_samples(x, v, theta, dg)
    }
    fn frequency_dependent(&self) -> bool {
        self.problem.frequency_dependent()
    }
    fn nonlinear_samples_at(&self, x: &[f64], v: &[f64], th: &[f64], w: f64, out: &mut [f64]) {
        self.problem.nonlinear_samples_at(x, v, th, w, out)
    }
    fn nonlinear_jacobian_samples_at(
        &self,
        x: &[f64],
        v: &[f64],
        th: &[f64],
        w: f64,
        dg: &mut [f64],
    ) {
        self.problem.nonlinear_jacobian_samples_at(x, v, th, w, dg)
    }
    fn excitation_at(&self, theta: f64, omega_f: f64, out: &mut [f64]) {
        self.problem.excitation_at(theta, omega_f, out);
        out.iter_mut().for_each(|f| *f *= self.scale);
    }
}

impl<P: PeriodicProblem> Search<'_, P> {
    /// The folds of every period-one branch followed in the forcing scale
    /// both ways from 1 over `fold_scale`; a crossing of `s = 1` off the
    /// known branches starts a branch there.
    pub(super) fn fold_curves(&mut self) -> Result<(), HbError> {
        let Some((lo, hi)) = self.req.fold_scale else {
            return Ok(());
        };
        self.search.fold_scale = Some([lo, hi]);
        let problem = self.problem;
        let family = boxed_family(|scale: f64| -> Result<ForcingScale<'_, P>, HbError> {
            Ok(ForcingScale { problem, scale })
        });
        // Only the crossings of s = 1 are kept (each solved at s = 1 by
        // Newton): the curves are followed with long steps.
        let copts = ContinuationOptions {
            ds: 0.05,
            ds_max: FOLD_CURVE_DS_MAX,
            max_points: self.path.max_points,
            ..ContinuationOptions::default()
        };
        let folds: Vec<(usize, Bifurcation)> = self
            .located
            .iter()
            .enumerate()
            .filter(|(b, _)| matches!(self.states.get(*b), Some(Some((h, _))) if h.subharmonic == self.hb.subharmonic && h.harmonics == self.hb.harmonics))
            .flat_map(|(b, events)| {
                events
                    .iter()
                    .filter(|e| e.kind == BifurcationKind::Fold)
                    .filter_map(move |e| e.location.as_ref().ok().map(|l| (b, l.clone())))
            })
            .collect();
        for (b, fold) in folds {
            for (from, to) in [(lo, hi), (hi, lo)] {
                self.search.fold_curves += 1;
                let curve = match fold_curve(
                    &family,
                    &self.hb,
                    &fold.q,
                    fold.lambda,
                    1.0,
                    from,
                    to,
                    &[1.0],
                    &copts,
                ) {
                    Ok(c) => c,
                    Err(why) => {
                        self.search.failures.push(format!(
                            "fold curve from ω_f = {} on branch {b}: {why}",
                            fold.lambda
                        ));
                        continue;
                    }
                };
                for crossing in curve
                    .at
                    .iter()
                    .filter(|c| (c.omega - fold.lambda).abs() > 1e-6 * fold.lambda)
                {
                    let inside = (self.req.from.min(self.req.to)..=self.req.from.max(self.req.to))
                        .contains(&crossing.omega);
                    let mut x = crossing.coeffs.clone();
                    x.push(crossing.omega);
                    let h = self.req.step * norm2(&crossing.coeffs);
                    if !inside || self.known(&self.hb, &x, 0.25 * h) {
                        continue;
                    }
                    let origin = Origin {
                        kind: BifurcationKind::Fold,
                        omega: crossing.omega,
                        event: None,
                    };
                    if let Err(why) = self.branches_from_fold(
                        &crossing.coeffs,
                        crossing.omega,
                        &crossing.null_vector,
                        (Some(b), origin),
                    ) {
                        self.search
                            .failures
                            .push(format!("the fold at ω_f = {}: {why}", crossing.omega));
                    }
                }
            }
        }
        Ok(())
    }

    /// Deflated Newton at `samples` frequencies; each solution off the known
    /// branches is traced both ways.
    pub(super) fn deflation(&mut self) -> Result<(), HbError> {
        let n = self.req.samples;
        if n == 0 {
            return Ok(());
        }
        let (a, b) = (self.req.from, self.req.to);
        let omegas: Vec<f64> = (0..n)
            .map(|i| a + (b - a) * (i as f64 + 0.5) / n as f64)
            .collect();
        self.search.deflation_omegas = omegas.clone();
        self.search.deflation_exhausted = true;
        let opts = SearchOptions {
            max_amplitude: self.req.max_amplitude,
            amplitudes: self.req.amplitudes,
            stability_steps: crate::stability_steps(self.hb.harmonics),
            ..SearchOptions::default()
        };
        for omega in omegas {
            let found = match all_solutions(self.problem, &self.hb, omega, &opts) {
                Ok(f) => f,
                Err(why) => {
                    self.search
                        .failures
                        .push(format!("deflation at ω_f = {omega}: {why}"));
                    continue;
                }
            };
            self.search.deflation_solutions += found.solutions.len();
            self.search.deflation_exhausted &= found.report.exhausted;
            for s in found.solutions {
                let q = s.solution.coeffs;
                if self.on_branch_at(&q, omega) {
                    continue;
                }
                let mut x0 = q;
                x0.push(omega);
                let mut first: Option<usize> = None;
                for direction in [1.0, -1.0] {
                    if let Some(i) = first {
                        // The first half closed on itself: it is the whole branch.
                        if self
                            .branches
                            .get(i)
                            .is_some_and(|br| br.termination == Termination::Stopped)
                        {
                            break;
                        }
                    }
                    let traced = self.trace(Pending {
                        hb: self.hb.clone(),
                        x0: x0.clone(),
                        direction,
                        kind: BranchKind::Deflation,
                        parent: first,
                        origin: None,
                        level: 0,
                    });
                    match traced {
                        Ok(i) => first = first.or(i),
                        Err(why) => self
                            .search
                            .failures
                            .push(format!("the orbit found at ω_f = {omega}: {why}")),
                    }
                }
            }
        }
        Ok(())
    }
}
