//! A component of the path vector crossing a set value: the point of a
//! two-parameter curve at a requested `p` (its `at` points), or where the
//! multiplier angle θ of a Neimark–Sacker curve passes a strong resonance.
//! The test function is the component minus the value; the locator is Newton
//! on `R(q, λ) = 0` closed by the border row `x[index] = value`
//! ([`ivt_num::newton_bordered`] on [`BranchWithLambda`]),
//! started from the linear interpolation of the two path points that bracket
//! the value. Located as the points arrive, like every event: no search of
//! the finished path.

use super::detector::{Bifurcation, BifurcationKind, Detector, PathSoFar, Start};
use super::extended::{finish, BranchWithLambda};
use crate::branch::Branch;
use crate::error::PathError;
use ivt_num::{newton_bordered, Border, NewtonOptions, NewtonWorkspace};

/// The event "component `index` of `x = (q, λ)` equals `value`" on any
/// [`Branch`], located by Newton with `newton`'s options (the caller's
/// tolerances: its residual's scale and noise floor).
#[derive(Debug, Clone, PartialEq)]
pub struct Crossing {
    index: usize,
    value: f64,
    newton: NewtonOptions,
}

impl Crossing {
    /// The crossing of `value` by component `index` of the path vector
    /// (`index = m` is λ itself).
    pub fn new(index: usize, value: f64, newton: NewtonOptions) -> Self {
        Self {
            index,
            value,
            newton,
        }
    }

    /// The crossing located to the scale of its residual: converged at
    /// ‖R‖ ≤ 1e-12·max(1, `scale`) or a full step below 1e-10 relative
    /// (1e-12 absolute); below 1e-9·max(1, `scale`) a rise of ‖R‖ is noise
    /// (a residual through a monodromy matrix has a noise floor near 1e-11).
    pub fn scaled(index: usize, value: f64, scale: f64) -> Self {
        let newton = NewtonOptions {
            ftol: 1e-12 * scale.max(1.0),
            rtol: 1e-10,
            atol: 1e-12,
            accept_below: 1e-9 * scale.max(1.0),
            ..NewtonOptions::default()
        };
        Self::new(index, value, newton)
    }

    /// The component watched.
    pub fn index(&self) -> usize {
        self.index
    }

    /// The value it is located at.
    pub fn value(&self) -> f64 {
        self.value
    }
}

impl<B: Branch, E: From<PathError>> Detector<B, E> for Crossing {
    fn kind(&self) -> BifurcationKind {
        BifurcationKind::Crossing
    }

    /// `x[index] − value` at point `k`; a point exactly at the value counts
    /// as above it, so a path through it reports it once (a path that starts
    /// there reports it when it moves below).
    fn test(&mut self, _branch: &mut B, path: &PathSoFar, k: usize) -> f64 {
        let d = (path.points.get(k))
            .and_then(|p| p.x.get(self.index))
            .map_or(f64::NAN, |x| x - self.value);
        if d == 0.0 {
            f64::MIN_POSITIVE
        } else {
            d
        }
    }

    /// Newton from the interpolation of the bracketing points, `x[index]`
    /// fixed at the value (exactly, in the result).
    ///
    /// # Errors
    /// [`PathError::InvalidInput`] if the bracket is not on the path;
    /// [`PathError::Solve`] if Newton fails.
    fn locate(&mut self, at: Start<'_, B>) -> Result<Bifurcation, E> {
        let points = &at.path.points;
        let bracket = (points.get(at.index), points.get(at.index + 1));
        let (Some(a), Some(b)) = bracket else {
            return Err(
                PathError::InvalidInput(format!("no bracket at point {}", at.index)).into(),
            );
        };
        let (va, vb) = match (a.x.get(self.index), b.x.get(self.index)) {
            (Some(&va), Some(&vb)) if va != vb && a.x.len() == b.x.len() => (va, vb),
            _ => {
                return Err(PathError::InvalidInput(format!(
                    "component {} does not change between points {} and {}",
                    self.index,
                    at.index,
                    at.index + 1
                ))
                .into())
            }
        };
        let t = (self.value - va) / (vb - va);
        let mut x: Vec<f64> = a.x.iter().zip(&b.x).map(|(u, w)| u + t * (w - u)).collect();
        let n = x.len();
        let mut row = vec![0.0; n];
        if let (Some(c), Some(e)) = (row.get_mut(self.index), x.get_mut(self.index)) {
            (*c, *e) = (1.0, self.value);
        }
        let border = Border {
            rows: &row,
            values: &[self.value],
            origin: &[],
        };
        let branch = at.branch;
        let mut system = BranchWithLambda::new(&mut *branch, at.opts);
        let mut ws = NewtonWorkspace::bordered(n, 1);
        let stats = newton_bordered(&mut system, border, &mut x, &mut ws, &self.newton)
            .map_err(PathError::Solve)?;
        if let Some(e) = x.get_mut(self.index) {
            *e = self.value;
        }
        let lambda = x.pop().unwrap_or(f64::NAN);
        Ok(finish(
            branch,
            BifurcationKind::Crossing,
            (x, lambda),
            Vec::new(),
            Vec::new(),
            stats.iterations,
        ))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::continuation::ContinuationOptions;
    use crate::events::{observe_residual, EventObserver, Fold, LocateOptions};

    type Found = Vec<(BifurcationKind, usize, Vec<f64>, f64)>;

    /// The unit circle `(u − 2)² + λ² = 1` by its residual from `(u, λ) =
    /// (2.6, 0.8)` towards increasing λ, watched for `u = 2.5`, `λ = 0.8`
    /// (the start: counted when the path moves below it) and folds: `(kind,
    /// detector, q, λ)` of each event in path order.
    fn circle_events(max_points: usize) -> Found {
        let opts = ContinuationOptions {
            ds: 0.07,
            ds_max: 0.07,
            max_points,
            lambda_min: -2.0,
            lambda_max: 2.0,
            ..Default::default()
        };
        let newton = NewtonOptions {
            ftol: 1e-14,
            ..NewtonOptions::default()
        };
        let detectors: Vec<Box<dyn Detector<_, PathError>>> = vec![
            Box::new(Crossing::new(0, 2.5, newton)),
            Box::new(Crossing::new(1, 0.8, newton)),
            Box::new(Fold),
        ];
        let mut observer = EventObserver::new(&LocateOptions::default(), detectors);
        let residual = |x: &[f64], r: &mut [f64]| r[0] = (x[0] - 2.0).powi(2) + x[1] * x[1] - 1.0;
        let (_, events) =
            observe_residual(residual, &[2.6, 0.8], 1.0, &opts, &mut observer, |_| true).unwrap();
        (events.into_iter())
            .map(|e| {
                let b = e
                    .location
                    .unwrap_or_else(|err| panic!("{:?} {}: {err:?}", e.kind, e.index));
                (e.kind, e.detector, b.q, b.lambda)
            })
            .collect()
    }

    #[test]
    fn crossings_of_a_circle_are_located_where_the_closed_form_puts_them() {
        // Nearly once round the circle (2π/0.07 ≈ 90 steps): up over the fold at
        // λ = 1, down over the fold at λ = −1 and back up.
        let found = circle_events(85);
        let s = 0.75f64.sqrt();
        let crossings_of_u: Vec<f64> = (found.iter())
            .filter(|(_, d, _, _)| *d == 0)
            .map(|(_, _, q, l)| {
                assert_eq!(q[0], 2.5, "the fixed component is exact");
                *l
            })
            .collect();
        // u = 2.5 at λ = +√0.75 (on the way up) and −√0.75 (on the way back).
        assert_eq!(crossings_of_u.len(), 2, "{found:?}");
        assert!((crossings_of_u[0] - s).abs() < 1e-12, "{found:?}");
        assert!((crossings_of_u[1] + s).abs() < 1e-12, "{found:?}");
        // λ = 0.8: the start is not reported (the path moves up from it),
        // the far side (u = 1.4) is, once, on the way down.
        let at_08: Vec<&Vec<f64>> = (found.iter())
            .filter(|(_, d, _, _)| *d == 1)
            .map(|(_, _, q, _)| q)
            .collect();
        assert_eq!(at_08.len(), 1, "{found:?}");
        assert!((at_08[0][0] - 1.4).abs() < 1e-12, "{found:?}");
        // Both folds, λ = ±1.
        let folds: Vec<f64> = (found.iter())
            .filter(|(k, _, _, _)| *k == BifurcationKind::Fold)
            .map(|(_, _, _, l)| *l)
            .collect();
        assert_eq!(folds.len(), 2, "{found:?}");
        assert!((folds[0] - 1.0).abs() < 1e-10 && (folds[1] + 1.0).abs() < 1e-10);
    }
}
