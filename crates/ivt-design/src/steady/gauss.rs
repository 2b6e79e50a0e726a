//! Gauss–Legendre quadrature nodes for the piecewise quadrature of the IHB
//! residual integral ([`super::Quadrature::PiecewiseGauss`]).

use core::f64::consts::PI;

/// Gauss–Legendre nodes and weights on [−1, 1] (Newton on P_m from the
/// Chebyshev-like initial guesses; Abramowitz–Stegun 25.4.29), nodes
/// increasing.
pub(crate) fn gauss_legendre(m: usize) -> (Vec<f64>, Vec<f64>) {
    let mut x = vec![0.0; m];
    let mut w = vec![0.0; m];
    // Guess i lies near cos(π(i + ¾)/(m + ½)), decreasing in i: stored from the end.
    for (i, (xi, wi)) in x.iter_mut().rev().zip(w.iter_mut().rev()).enumerate() {
        let mut z = (PI * (i as f64 + 0.75) / (m as f64 + 0.5)).cos();
        let mut dp = 1.0;
        for _ in 0..100 {
            let (mut p0, mut p1) = (1.0, z);
            for k in 2..=m {
                let p2 = ((2 * k - 1) as f64 * z * p1 - (k - 1) as f64 * p0) / k as f64;
                p0 = p1;
                p1 = p2;
            }
            let pm = if m == 0 { 1.0 } else { p1 };
            let pm1 = if m <= 1 { 1.0 } else { p0 };
            dp = m as f64 * (z * pm - pm1) / (z * z - 1.0);
            let dz = pm / dp;
            z -= dz;
            if dz.abs() < 1e-16 {
                break;
            }
        }
        *xi = z;
        *wi = 2.0 / ((1.0 - z * z) * dp * dp);
    }
    (x, w)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Five nodes integrate x⁸ exactly (degree ≤ 2·5 − 1): ∫₋₁¹ x⁸ = 2/9;
    /// weights sum to 2; nodes increase and are symmetric.
    #[test]
    fn five_nodes_are_exact_to_degree_nine() {
        let (x, w) = gauss_legendre(5);
        let q: f64 = x.iter().zip(&w).map(|(x, w)| w * x.powi(8)).sum();
        assert!((q - 2.0 / 9.0).abs() < 1e-15, "{q}");
        assert!((w.iter().sum::<f64>() - 2.0).abs() < 1e-15);
        assert!(x.windows(2).all(|p| p[0] < p[1]));
        assert!((x[0] + x[4]).abs() < 1e-15 && x[2].abs() < 1e-15);
    }
}
