//! The predictor of a continuation step (Eq. 71): from the point `x` along
//! its unit direction `d` (the secant of the Broyden corrector, the tangent
//! of the exact ones), `x + Δη d`, with the second-order term `½Δη² κ` of
//! [`super::ContinuationOptions::second_order_predictor`], `κ` the curvature
//! of the last two directions.

use ivt_num::vector::norm2;

/// `x + step·d + ½ step² κ` into `out` (the curvature term only where it moves
/// the prediction by at most a quarter of the step: a turn sharper than the
/// step is not extrapolated), λ (the last entry) set to `landing` if given.
pub(crate) fn predict(
    x: &[f64],
    direction: &[f64],
    step: f64,
    curvature: Option<&[f64]>,
    landing: Option<f64>,
    out: &mut [f64],
) {
    for (p, (xi, di)) in out.iter_mut().zip(x.iter().zip(direction)) {
        *p = xi + di * step;
    }
    if let Some(c) = curvature.filter(|c| 0.5 * step * norm2(c) <= 0.25) {
        for (p, ci) in out.iter_mut().zip(c) {
            *p += 0.5 * step * step * ci;
        }
    }
    if let (Some(l), Some(last)) = (landing, out.last_mut()) {
        *last = l;
    }
}

/// `‖a − b‖₂`.
pub(crate) fn distance(a: &[f64], b: &[f64]) -> f64 {
    a.iter()
        .zip(b)
        .map(|(u, v)| (u - v) * (u - v))
        .sum::<f64>()
        .sqrt()
}

/// The curvature vector `(d₁ − d₀)/‖x₁ − x₀‖` of the path between two
/// consecutive points and their unit directions into `out`; `false` for
/// coincident points.
pub(crate) fn curvature_between(
    x0: &[f64],
    x1: &[f64],
    d0: &[f64],
    d1: &[f64],
    out: &mut [f64],
) -> bool {
    let ds = distance(x1, x0);
    if !(ds > 0.0 && ds.is_finite()) {
        return false;
    }
    for ((o, a), b) in out.iter_mut().zip(d0).zip(d1) {
        *o = (b - a) / ds;
    }
    true
}

#[cfg(test)]
mod tests {
    use super::*;

    /// On the unit circle the second-order prediction from the tangent and
    /// the curvature of two tangents is off the circle by O(Δη³), the linear
    /// one by O(Δη²).
    #[test]
    fn second_order_term_follows_the_circle() {
        let at = |s: f64| [s.cos(), s.sin()];
        let tangent = |s: f64| [-s.sin(), s.cos()];
        let (h, step) = (0.01, 0.1);
        let mut kappa = [0.0; 2];
        assert!(curvature_between(
            &at(-h),
            &at(0.0),
            &tangent(-h),
            &tangent(0.0),
            &mut kappa
        ));
        let (mut linear, mut curved) = ([0.0; 2], [0.0; 2]);
        predict(&at(0.0), &tangent(0.0), step, None, None, &mut linear);
        predict(
            &at(0.0),
            &tangent(0.0),
            step,
            Some(&kappa),
            None,
            &mut curved,
        );
        let off = |p: [f64; 2]| (norm2(&p) - 1.0).abs();
        assert!(off(linear) > 4e-3, "{linear:?}");
        assert!(off(curved) < 1e-4, "{curved:?}");
        predict(&at(0.0), &tangent(0.0), step, None, Some(0.25), &mut linear);
        assert_eq!(linear[1], 0.25);
    }
}
