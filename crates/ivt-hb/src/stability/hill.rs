//! Hill's method for `V' = Θ(τ) V`, Θ 2π-periodic with Fourier blocks
//! `Θ(τ) = Σ_k Θ̂_k e^{ikτ}`.
//!
//! With `V = e^{λτ} Σ_{k=−H..H} c_k e^{ikτ}` the exponents λ are the eigenvalues of the
//! block-Toeplitz Hill matrix `𝓗_{kj} = Θ̂_{k−j} − i k δ_{kj} I` (faer). Every exponent
//! appears shifted by all integers `i m`; the fundamental ones are those whose
//! eigenvectors are most centred in the harmonic index (the weighted mean index of
//! `|c_k|²` closest to 0). Multipliers are `μ = exp(2πλ)`.

use crate::error::HbError;
use faer::c64;
use realfft::RealFftPlanner;

/// Result of Hill's method.
#[derive(Debug, Clone, PartialEq)]
pub struct HillResult {
    /// The `dim` fundamental characteristic exponents λ.
    pub exponents: Vec<c64>,
    /// Floquet multipliers `exp(2πλ)`, sorted by decreasing modulus.
    pub multipliers: Vec<c64>,
}

/// Fourier blocks `Θ̂_k`, `k = −K..K`, of a real periodic matrix sampled on a uniform
/// grid: `samples` holds `m` row-major `dim×dim` matrices at `τ_j = 2πj/m`.
/// Output layout: block `k` at `(k+K)·dim²`.
///
/// # Errors
/// [`HbError::InvalidInput`] unless `m > 2K`, `dim ≥ 1` and `samples` holds
/// `m·dim²` entries.
pub fn fourier_blocks(
    dim: usize,
    samples: &[f64],
    m: usize,
    kmax: usize,
) -> Result<Vec<c64>, HbError> {
    let d2 = dim * dim;
    if m <= 2 * kmax || d2 == 0 || samples.len() != m * d2 {
        return Err(HbError::InvalidInput(format!(
            "Fourier blocks need m > 2K samples of dim² = {d2} ≥ 1 entries \
             (got m = {m}, K = {kmax}, {} entries)",
            samples.len()
        )));
    }
    let mut planner = RealFftPlanner::<f64>::new();
    let fft = planner.plan_fft_forward(m);
    let mut input = vec![0.0; m];
    let mut spec = fft.make_output_vec();
    let mut out = vec![c64::new(0.0, 0.0); (2 * kmax + 1) * d2];
    // Block k = 0 is out[K·d2..]: the negative blocks before it, in reverse.
    let (negative, non_negative) = out.split_at_mut(kmax * d2);
    for e in 0..d2 {
        for (x, s) in input.iter_mut().zip(samples.iter().skip(e).step_by(d2)) {
            *x = *s;
        }
        fft.process(&mut input, &mut spec)
            .map_err(|err| HbError::InvalidInput(format!("Fourier blocks: {err}")))?;
        // Real Θ: Θ̂_{−k} = conj Θ̂_k.
        let plus = non_negative.iter_mut().skip(e).step_by(d2);
        let minus = negative.iter_mut().rev().skip(d2 - 1 - e).step_by(d2);
        for (x, plus) in spec.iter().zip(plus).take(kmax + 1) {
            let v = x / m as f64;
            *plus = c64::new(v.re, v.im);
        }
        for (x, minus) in spec.iter().skip(1).zip(minus).take(kmax) {
            let v = x / m as f64;
            *minus = c64::new(v.re, -v.im);
        }
    }
    Ok(out)
}

/// Hill exponents and multipliers from the Fourier blocks `theta_hat` (`k = −K..K`,
/// layout of [`fourier_blocks`]) with `h` harmonics in the perturbation (matrix size
/// `(2h+1)·dim`). Blocks with `|k| > K` are taken as zero, so choose `K ≥ 2h` when Θ
/// has that many harmonics.
///
/// # Errors
/// [`HbError::InvalidInput`] on inconsistent sizes, [`HbError::Eigen`] on
/// eigen-solver failure.
pub fn hill_multipliers(dim: usize, theta_hat: &[c64], h: usize) -> Result<HillResult, HbError> {
    let d2 = dim * dim;
    if d2 == 0 || !theta_hat.len().is_multiple_of(d2) || (theta_hat.len() / d2).is_multiple_of(2) {
        return Err(HbError::InvalidInput(format!(
            "Fourier blocks hold {} entries, expected (2K+1)·dim² = {}",
            theta_hat.len(),
            d2 * (2 * h + 1)
        )));
    }
    let kmax = (theta_hat.len() / d2 - 1) / 2;
    let nb = 2 * h + 1;
    let size = nb * dim;
    let hill = faer::Mat::<c64>::from_fn(size, size, |r, c| {
        let (kb, i) = (r / dim, r % dim);
        let (jb, j) = (c / dim, c % dim);
        let diff = kb as i64 - jb as i64;
        let mut v = if diff.unsigned_abs() as usize <= kmax {
            // < (2K+1)·d2 = theta_hat.len() (checked above).
            theta_hat
                .get(((diff + kmax as i64) as usize) * d2 + i * dim + j)
                .copied()
                .unwrap_or(c64::new(f64::NAN, f64::NAN))
        } else {
            c64::new(0.0, 0.0)
        };
        if r == c {
            v.im -= kb as f64 - h as f64;
        }
        v
    });
    let eig = hill
        .eigen()
        .map_err(|e| HbError::Eigen(format!("Hill matrix: {e:?}")))?;
    let s = eig.S();
    let u = eig.U();
    let mut scored: Vec<(f64, c64)> = (0..size)
        .map(|col| {
            let (mut w, mut wk) = (0.0, 0.0);
            for r in 0..size {
                let p = u[(r, col)].norm_sqr();
                w += p;
                wk += p * ((r / dim) as f64 - h as f64);
            }
            ((wk / w).abs(), s[col])
        })
        .collect();
    scored.sort_by(|a, b| a.0.total_cmp(&b.0));
    let exponents: Vec<c64> = scored.iter().take(dim).map(|x| x.1).collect();
    let tp = 2.0 * std::f64::consts::PI;
    let mut multipliers: Vec<c64> = exponents
        .iter()
        .map(|l| c64::from_polar((l.re * tp).exp(), l.im * tp))
        .collect();
    crate::stability::floquet::sort_by_modulus(&mut multipliers);
    Ok(HillResult {
        exponents,
        multipliers,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::stability::floquet::{eigenvalues, monodromy_hsu, HsuRule};

    #[test]
    fn damped_mathieu_hill_agrees_with_hsu() {
        // x'' + 0.2 x' + (1.1 + 0.4 cos τ) x = 0 as V' = Θ V.
        let theta =
            |t: f64, o: &mut [f64]| o.copy_from_slice(&[0.0, 1.0, -(1.1 + 0.4 * t.cos()), -0.2]);
        let q = monodromy_hsu(2, 2.0 * std::f64::consts::PI, 2048, HsuRule::Magnus4, theta);
        let hsu = eigenvalues(&q, 2);
        let m = 64;
        let mut samples = vec![0.0; m * 4];
        for j in 0..m {
            theta(
                2.0 * std::f64::consts::PI * j as f64 / m as f64,
                &mut samples[j * 4..j * 4 + 4],
            );
        }
        let blocks = fourier_blocks(2, &samples, m, 4).unwrap();
        // Θ̂_{−k} = conj Θ̂_k: Θ̂_{±1} of entry (1, 0) is −0.4/2 (the cos τ term).
        assert!((blocks[3 * 4 + 2].re + 0.2).abs() < 1e-14 && blocks[3 * 4 + 2].im.abs() < 1e-14);
        assert!((blocks[5 * 4 + 2].re + 0.2).abs() < 1e-14);
        for (kind, m, kmax, len) in [
            ("m ≤ 2K", 8, 4, 32),
            ("short", 64, 4, 255),
            ("dim 0", 64, 4, 0),
        ] {
            let dim = if kind == "dim 0" { 0 } else { 2 };
            let r = fourier_blocks(dim, &vec![0.0; len], m, kmax);
            assert!(matches!(r, Err(HbError::InvalidInput(_))), "{kind}");
        }
        let hill = hill_multipliers(2, &blocks, 16).unwrap();
        for (a, b) in hsu.iter().zip(&hill.multipliers) {
            assert!((a - b).norm() < 1e-9, "{hsu:?} vs {:?}", hill.multipliers);
        }
    }
}
