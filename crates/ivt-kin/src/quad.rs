//! Adaptive Simpson quadrature (no allocation, bounded recursion) for the
//! averages and angle maps of the gear designs. Integrands must be smooth on
//! `[a, b]`: callers split at the corners (kinks) of the ratio first.

/// Result of an adaptive integration.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct Quad {
    /// The integral.
    pub value: f64,
    /// Whether every panel met its share of the tolerance before the depth limit.
    pub converged: bool,
}

/// Deepest bisection level; 2^-40 of the interval is far below f64 resolution
/// of any angle we integrate over.
const MAX_DEPTH: u32 = 40;

/// ∫_a^b g by adaptive Simpson with Richardson correction, absolute tolerance `tol`.
pub(crate) fn simpson<G: Fn(f64) -> f64>(g: &G, a: f64, b: f64, tol: f64) -> Quad {
    if a == b {
        return Quad {
            value: 0.0,
            converged: true,
        };
    }
    let (fa, fb, m) = (g(a), g(b), 0.5 * (a + b));
    let fm = g(m);
    let whole = (b - a) / 6.0 * (fa + 4.0 * fm + fb);
    let mut converged = true;
    let value = step(g, a, b, fa, fm, fb, whole, tol, MAX_DEPTH, &mut converged);
    Quad { value, converged }
}

#[allow(clippy::too_many_arguments)]
fn step<G: Fn(f64) -> f64>(
    g: &G,
    a: f64,
    b: f64,
    fa: f64,
    fm: f64,
    fb: f64,
    whole: f64,
    tol: f64,
    depth: u32,
    converged: &mut bool,
) -> f64 {
    let m = 0.5 * (a + b);
    let (lm, rm) = (0.5 * (a + m), 0.5 * (m + b));
    let (flm, frm) = (g(lm), g(rm));
    let left = (m - a) / 6.0 * (fa + 4.0 * flm + fm);
    let right = (b - m) / 6.0 * (fm + 4.0 * frm + fb);
    let delta = left + right - whole;
    if delta.abs() <= 15.0 * tol {
        return left + right + delta / 15.0;
    }
    if depth == 0 {
        *converged = false;
        return left + right + delta / 15.0;
    }
    step(g, a, m, fa, flm, fm, left, 0.5 * tol, depth - 1, converged)
        + step(g, m, b, fm, frm, fb, right, 0.5 * tol, depth - 1, converged)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn integrates_smooth_functions_to_tolerance() {
        let q = simpson(&|x: f64| libm::sin(x), 0.0, core::f64::consts::PI, 1e-12);
        assert!(q.converged && (q.value - 2.0).abs() < 1e-11);
        let q = simpson(&|x: f64| libm::exp(x), 0.0, 1.0, 1e-13);
        assert!((q.value - (core::f64::consts::E - 1.0)).abs() < 1e-12);
    }
}
