//! The peak `max_τ |x(τ)|` of a Fourier series `x = a0/2 + Σ a_k cos kτ + b_k
//! sin kτ` ([`crate::HbSolution::amplitude`]): the largest of equally spaced
//! samples, refined by Newton steps on `x′(τ) = 0`.

use crate::orbit::aft::{split_series, Aft};

/// `max_τ |x(τ)|` of the series `coeffs = [a0, a1..an, b1..bn]` as
/// [`HbSolution::amplitude`] finds it.
pub(crate) fn series_peak(coeffs: &[f64]) -> f64 {
    let Some((_, cos, sin)) = split_series(coeffs) else {
        return f64::NAN;
    };
    if cos.len() != sin.len() || !coeffs.iter().all(|c| c.is_finite()) {
        return f64::NAN;
    }
    // M = 4(n + 1) samples by one inverse real FFT (the thread's cached plan).
    let n = cos.len();
    let Ok(mut aft) = Aft::new(n, 2 * (n + 1)) else {
        return f64::NAN;
    };
    let mut samples = vec![0.0; aft.n_samples()];
    aft.synthesize(coeffs, &mut samples);
    refine_peak(coeffs, &samples)
}

/// `max_τ |x(τ)|` of the series `coeffs` from its `samples` at
/// `τ_i = 2πi/len`: the largest sample, then up to 8 Newton steps on
/// `x′(τ) = 0` from it (each at most one sample spacing), the largest `|x|`
/// visited. Never below the largest sample, never above the true maximum.
pub fn refine_peak(coeffs: &[f64], samples: &[f64]) -> f64 {
    let Some((at, best)) = samples.iter().map(|v| v.abs()).enumerate().fold(
        None,
        |acc: Option<(usize, f64)>, (i, v)| match acc {
            Some((_, b)) if b >= v => acc,
            _ => Some((i, v)),
        },
    ) else {
        return f64::NAN;
    };
    let h = std::f64::consts::TAU / samples.len() as f64;
    let mut tau = h * at as f64;
    let mut peak = best;
    for _ in 0..8 {
        let [x, d1, d2] = series_and_derivatives(coeffs, tau);
        peak = peak.max(x.abs());
        if d2 == 0.0 || !(d1 / d2).is_finite() {
            break;
        }
        let step = (d1 / d2).clamp(-h, h);
        tau -= step;
        if step.abs() <= 1e-15 * (1.0 + tau.abs()) {
            break;
        }
    }
    peak.max(series_and_derivatives(coeffs, tau)[0].abs())
}

/// `[x, x′, x″](τ)` of the series `coeffs` with one `sin_cos` (the powers of
/// `e^{jτ}` by complex multiplication).
fn series_and_derivatives(coeffs: &[f64], tau: f64) -> [f64; 3] {
    let Some((a0, cos, sin)) = split_series(coeffs) else {
        return [f64::NAN; 3];
    };
    let (sn, cs) = tau.sin_cos();
    let (mut zr, mut zi) = (cs, sn);
    let mut out = [0.5 * a0, 0.0, 0.0];
    for (k, (&a, &b)) in cos.iter().zip(sin).enumerate() {
        let k = (k + 1) as f64;
        // a cos kτ + b sin kτ = a·Re z^k + b·Im z^k; its τ-derivatives.
        let (c, s) = (zr, zi);
        out[0] += a * c + b * s;
        out[1] += k * (b * c - a * s);
        out[2] -= k * k * (a * c + b * s);
        (zr, zi) = (zr * cs - zi * sn, zr * sn + zi * cs);
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    /// max |x| by brute force, independent of Newton: direct evaluation at
    /// 10⁵ equally spaced τ, then at 2·10⁴ points within one spacing either
    /// side of the best; with the bound `½(Δ/2)²·Σ k²·hypot(a_k, b_k)` of the
    /// final spacing Δ on how far below the maximum the result can be.
    fn brute_force_max(coeffs: &[f64]) -> (f64, f64) {
        let x = |tau: f64| crate::orbit::aft::eval_series(coeffs, tau, 0).abs();
        let (m, zoom) = (100_000, 20_000);
        let h = std::f64::consts::TAU / m as f64;
        let (at, _) = (0..m)
            .map(|i| (i, x(h * i as f64)))
            .fold((0, -1.0), |a, b| if b.1 > a.1 { b } else { a });
        let step = 2.0 * h / zoom as f64;
        let max = (0..=zoom)
            .map(|i| x(h * at as f64 - h + step * i as f64))
            .fold(0.0, f64::max);
        let n = (coeffs.len() - 1) / 2;
        let curvature: f64 = (1..=n)
            .map(|k| (k * k) as f64 * coeffs[k].hypot(coeffs[n + k]))
            .sum();
        (max, 0.5 * (0.5 * step).powi(2) * curvature)
    }

    /// max |x| over 512 equally spaced τ: the amplitude orbits reported before.
    fn max_of_512(coeffs: &[f64]) -> f64 {
        (0..512)
            .map(|i| {
                let tau = std::f64::consts::TAU * i as f64 / 512.0;
                crate::orbit::aft::eval_series(coeffs, tau, 0).abs()
            })
            .fold(0.0, f64::max)
    }

    #[test]
    fn series_peak_of_one_harmonic_is_the_closed_form() {
        // a0/2 + a cos τ + b sin τ peaks at |a0/2| + hypot(a, b), at any phase.
        for (a0, a, b) in [
            (0.0, 1.0, 0.0),
            (0.0, 0.3, -0.7),
            (0.4, -0.123, 0.456),
            (-3.0, 1e-3, 2e-3),
        ] {
            let exact = (0.5f64 * a0).abs() + f64::hypot(a, b);
            let got = series_peak(&[a0, a, b]);
            assert!((got - exact).abs() <= 4e-16 * exact, "{got} vs {exact}");
        }
        assert_eq!(series_peak(&[0.0, 0.0, 0.0]), 0.0);
        assert_eq!(series_peak(&[-2.0]), 1.0);
        assert!(series_peak(&[]).is_nan() && series_peak(&[0.0, f64::NAN, 1.0]).is_nan());
    }

    #[test]
    fn series_peak_matches_a_brute_force_search_on_random_series() {
        // Series with k^-1.5-decaying random coefficients, n = 1..40: the peak
        // agrees with the brute-force maximum to rounding, and is never below
        // the 512-sample maximum the orbits reported before.
        let mut state = 0x2545_f491_4f6c_dd1du64;
        let mut uniform = move || {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            (state >> 11) as f64 / (1u64 << 53) as f64 * 2.0 - 1.0
        };
        let mut worst = 0.0f64;
        for n in [1usize, 2, 3, 5, 8, 13, 20, 29, 40] {
            for _ in 0..4 {
                let mut c = vec![uniform()];
                let k = |i: usize| ((i % n) + 1) as f64;
                c.extend((0..2 * n).map(|i| uniform() * k(i).powf(-1.5)));
                let (reference, bound) = brute_force_max(&c);
                let got = series_peak(&c);
                assert!(bound < 1e-15 * reference, "n = {n}: bound {bound}");
                assert!(got >= max_of_512(&c), "n = {n}: {got} below 512 samples");
                worst = worst.max((got - reference).abs() / reference);
            }
        }
        assert!(worst < 1e-14, "{worst}");
    }

    #[test]
    fn series_peak_of_the_fig28_orbit_matches_a_brute_force_search() {
        // Fig. 28's orbit (ω_f = 0.4, n = 20): the peak against the brute
        // force, and the AFT's own 2N = 128 samples refined by the same
        // Newton give it too.
        use crate::{Duffing, HbOptions, ModifiedIhb};
        let d = Duffing::new(0.02, 1.0, 1.0, 0.1);
        let mut solver = ModifiedIhb::new(&d, HbOptions::new(20, 64)).unwrap();
        let sol = solver.solve(0.4, None).unwrap();
        let (reference, bound) = brute_force_max(sol.dof(0));
        let got = sol.amplitude(0);
        assert!(bound < 1e-15 * reference, "{bound}");
        assert!(
            (got - reference).abs() < 1e-14 * reference,
            "{got} vs {reference}"
        );
        let mut aft = Aft::new(20, 64).unwrap();
        let mut samples = vec![0.0; 128];
        aft.synthesize(sol.dof(0), &mut samples);
        let from_aft = refine_peak(sol.dof(0), &samples);
        assert!((got - from_aft).abs() <= 1e-15 * got, "{got} vs {from_aft}");
        // The 512 samples reported before were low by 8.2e-6 relative
        // (0.11852299 against 0.11852397).
        let before = max_of_512(sol.dof(0));
        let low = (got - before) / got;
        assert!((low - 8.23e-6).abs() < 0.01e-6, "{got} {before} {low:e}");
    }
}
