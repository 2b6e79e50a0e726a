//! A point of a two-parameter curve with one component of its path vector
//! held fixed: the fold, period doubling or Neimark–Sacker point at a given
//! `p` (the `at` points), or at a given multiplier angle θ (a strong
//! resonance of a Neimark–Sacker curve). The curve's extended system has one
//! equation fewer than unknowns; fixing a component makes it square, and it
//! is solved by Newton ([`ivt_num::newton()`]) with a central-difference
//! Jacobian from the linear interpolation of the two path points that
//! bracket the value.

use ivt_num::{NewtonOptions, NewtonSystem, NewtonWorkspace};
use ivt_path::continuation::PathPoint;

/// The extended system of a curve: `n − 1` equations in the path vector `x`
/// of `n` entries (`p` last).
pub(crate) trait CurveSystem {
    /// What a point of the curve reports.
    type Point;

    /// The residual at `x` into `r` (`n − 1` entries); `None` where it
    /// cannot be evaluated (sizes disagree or the family fails at that `p`).
    fn try_residual(&mut self, x: &[f64], r: &mut [f64]) -> Option<()>;

    /// The curve's point at the path vector `x` (`None` if `x` is short).
    fn point(&self, x: &[f64]) -> Option<Self::Point>;

    /// [`Self::try_residual`], NaN where it cannot be evaluated (a failed
    /// step to the path).
    fn residual(&mut self, x: &[f64], r: &mut [f64]) {
        if self.try_residual(x, r).is_none() {
            r.fill(f64::NAN);
        }
    }
}

/// The point of `sys` at each crossing of component `index` of `path` with
/// a value of `values` ([`super::crossings`]), solved there by
/// [`solve_fixed`]; crossings whose solve fails are left out.
pub(crate) fn solve_crossings<S: CurveSystem>(
    sys: &mut S,
    path: &[PathPoint],
    values: &[f64],
    index: usize,
    scale: f64,
) -> Vec<S::Point> {
    super::crossings(path, values, index)
        .filter_map(|(a, b, v)| {
            let x = solve_fixed(sys, (a, b), index, v, scale)?;
            sys.point(&x)
        })
        .collect()
}

/// The point of `sys` with `x[index] = value`, from the path points `a` and
/// `b` whose components `index` bracket `value`; Newton stops when
/// ‖residual‖ ≤ 1e-12·max(1, `scale`) or a full step is below 1e-10
/// relative (1e-12 absolute). `None` if the sizes disagree, the
/// bracket is empty or Newton fails.
pub(crate) fn solve_fixed<S: CurveSystem>(
    sys: &mut S,
    (a, b): (&[f64], &[f64]),
    index: usize,
    value: f64,
    scale: f64,
) -> Option<Vec<f64>> {
    let n = a.len();
    let (va, vb) = (*a.get(index)?, *b.get(index)?);
    if b.len() != n || va == vb || n < 2 {
        return None;
    }
    let t = (value - va) / (vb - va);
    let mut y: Vec<f64> = a
        .iter()
        .zip(b)
        .enumerate()
        .filter(|(i, _)| *i != index)
        .map(|(_, (u, w))| u + t * (w - u))
        .collect();
    let mut fixed = Fixed {
        sys,
        index,
        value,
        x: vec![0.0; n],
        rp: vec![0.0; n - 1],
        rm: vec![0.0; n - 1],
    };
    // A monodromy-based residual has a noise floor near 1e-11: below 1e-9
    // a rise is noise, and a full step below 1e-10 relative converges.
    let opts = NewtonOptions {
        ftol: 1e-12 * scale.max(1.0),
        rtol: 1e-10,
        atol: 1e-12,
        accept_below: 1e-9 * scale.max(1.0),
        ..NewtonOptions::default()
    };
    ivt_num::newton(&mut fixed, &mut y, &mut NewtonWorkspace::new(n - 1), &opts).ok()?;
    fixed.embed(&y);
    Some(fixed.x)
}

/// The curve system with `x[index] = value` as a square Newton system in the
/// other components.
struct Fixed<'s, S> {
    sys: &'s mut S,
    index: usize,
    value: f64,
    /// The full path vector of the last evaluation.
    x: Vec<f64>,
    rp: Vec<f64>,
    rm: Vec<f64>,
}

/// Which scratch residual [`Fixed::eval`] writes.
#[derive(Clone, Copy)]
enum Which {
    Plus,
    Minus,
}

impl<S: CurveSystem> Fixed<'_, S> {
    /// `x` from the free components `y` and the fixed one.
    fn embed(&mut self, y: &[f64]) {
        let (head, tail) = y.split_at(self.index.min(y.len()));
        self.x.clear();
        self.x.extend_from_slice(head);
        self.x.push(self.value);
        self.x.extend_from_slice(tail);
    }

    fn eval(&mut self, y: &[f64], out: Which) {
        self.embed(y);
        let r = match out {
            Which::Plus => &mut self.rp,
            Which::Minus => &mut self.rm,
        };
        self.sys.residual(&self.x, r);
    }
}

impl<S: CurveSystem> NewtonSystem for Fixed<'_, S> {
    type Error = std::convert::Infallible;
    fn residual(&mut self, y: &[f64], r: &mut [f64]) -> Result<(), Self::Error> {
        self.eval(y, Which::Plus);
        r.copy_from_slice(&self.rp);
        Ok(())
    }
    fn jacobian(&mut self, y: &[f64], jac: &mut [f64]) -> Result<(), Self::Error> {
        let n = y.len();
        let mut yp = y.to_vec();
        for (j, &yj) in y.iter().enumerate() {
            let h = 1e-7 * yj.abs().max(1e-3);
            if let Some(e) = yp.get_mut(j) {
                *e = yj + h;
            }
            self.eval(&yp, Which::Plus);
            if let Some(e) = yp.get_mut(j) {
                *e = yj - h;
            }
            self.eval(&yp, Which::Minus);
            if let Some(e) = yp.get_mut(j) {
                *e = yj;
            }
            // Column j of the row-major n×n Jacobian.
            for ((row, p), m) in jac.chunks_exact_mut(n).zip(&self.rp).zip(&self.rm) {
                if let Some(e) = row.get_mut(j) {
                    *e = (p - m) / (2.0 * h);
                }
            }
        }
        Ok(())
    }
}
