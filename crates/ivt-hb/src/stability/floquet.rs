//! Floquet multipliers of `V' = Θ(τ) V`, `Θ` 2π-periodic (or any period), by Hsu's
//! method (Eq. 80): the transformation (monodromy) matrix is a product of matrix
//! exponentials over `N_Q` sub-intervals.
//!
//! Eq. 80 freezes Θ at one point per sub-interval (first order in Δτ, rule
//! [`HsuRule::Left`]). The default [`HsuRule::Magnus4`] uses the fourth-order Magnus
//! step `Ω = (h/6)(Θ₀ + 4Θ_½ + Θ₁) − (h²/12)[Θ₀, Θ₁]` on the same uniform grid,
//! which reaches 1e-9 agreement with Hill's method at a few thousand steps.
//!
//! Slice lengths are the callers' contract; a slice too short in a release build
//! is not a panic: the result is NaN, which the stability checks report as
//! [`crate::HbError::NonFiniteMultipliers`].

use faer::c64;
use ivt_num::small::{matmul, matmul_n};

/// Quadrature rule of one Hsu sub-interval.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum HsuRule {
    /// Θ frozen at the end of each sub-interval, literally Eq. 80 (order 1).
    Left,
    /// Θ frozen at the midpoint (order 2).
    Midpoint,
    /// Fourth-order Magnus step with Θ at both ends and the midpoint (default).
    #[default]
    Magnus4,
}

/// Scratch entries [`expm`] needs for a `dim×dim` matrix.
pub fn expm_scratch_len(dim: usize) -> usize {
    5 * dim * dim
}

/// `‖a/2^s‖₁` bound of [`expm`]'s scaling: the degree-12 Taylor remainder is
/// then below `θ¹³/13! · e^θ ≈ 3e-18`, under the rounding of the sum.
const EXPM_THETA: f64 = 0.25;

/// `1/k!` as `(1/(k−1)!)/k`, the rounding of a running division.
const fn inverse_factorial(k: usize) -> f64 {
    if k == 0 {
        1.0
    } else {
        inverse_factorial(k - 1) / k as f64
    }
}

/// Taylor coefficients 1/k! of [`expm`]'s degree-12 polynomial.
const EXPM_TAYLOR: [f64; 13] = [
    inverse_factorial(0),
    inverse_factorial(1),
    inverse_factorial(2),
    inverse_factorial(3),
    inverse_factorial(4),
    inverse_factorial(5),
    inverse_factorial(6),
    inverse_factorial(7),
    inverse_factorial(8),
    inverse_factorial(9),
    inverse_factorial(10),
    inverse_factorial(11),
    inverse_factorial(12),
];

/// Calls `$f::<N>(args)` with the compile-time size `N = $dim` for sizes
/// 1–8 (here the state sizes `2·n_dof` of systems up to 4 DOF, in
/// `stability.rs` the DOF count: every loop over the size is then unrolled
/// and free of bounds checks), `N = 0` (the size read at run time) beyond.
macro_rules! by_size {
    ($dim:expr, $f:ident($($arg:expr),* $(,)?)) => {
        match $dim {
            1 => $f::<1>($($arg),*),
            2 => $f::<2>($($arg),*),
            3 => $f::<3>($($arg),*),
            4 => $f::<4>($($arg),*),
            5 => $f::<5>($($arg),*),
            6 => $f::<6>($($arg),*),
            7 => $f::<7>($($arg),*),
            8 => $f::<8>($($arg),*),
            _ => $f::<0>($($arg),*),
        }
    };
}
pub(crate) use by_size;

/// `c = a·b` of `dim×dim` matrices with the size `N` known at compile time
/// ([`matmul_n`]), or read from `dim` for `N = 0` ([`matmul`]).
fn product<const N: usize>(a: &[f64], b: &[f64], dim: usize, c: &mut [f64]) {
    if N == 0 {
        matmul(a, b, dim, c);
    } else {
        matmul_n::<N>(a, b, c);
    }
}

/// `out = exp(a)` for a small dense row-major `dim×dim` matrix: scaling and
/// squaring to `‖a/2^s‖₁ ≤ 1/4` and the degree-12 Taylor polynomial evaluated
/// by Paterson–Stockmeyer, `p = B₀ + A⁴(B₁ + A⁴B₂)` with `Bᵢ` in `I, A, A², A³`
/// (five products of `dim×dim` matrices instead of twelve; the one-step
/// exponential of every Hsu sub-interval). `scratch` needs
/// [`expm_scratch_len`] entries; nothing is allocated.
///
/// If `scratch` is shorter than [`expm_scratch_len`]`(dim)` (for `dim > 2`)
/// or `a` shorter than `dim²`, `out` is NaN.
pub fn expm(a: &[f64], dim: usize, out: &mut [f64], scratch: &mut [f64]) {
    if dim == 0 {
        return;
    }
    if dim == 2 {
        expm2(a, out);
        return;
    }
    by_size!(dim, expm_sized(a, dim, out, scratch));
}

/// [`expm`] (Taylor) with the size `N` known at compile time, or read from
/// `dim` for `N = 0`.
fn expm_sized<const N: usize>(a: &[f64], dim: usize, out: &mut [f64], scratch: &mut [f64]) {
    let dim = if N == 0 { dim } else { N };
    let d2 = dim * dim;
    let Some(out) = out.get_mut(..d2) else {
        return out.fill(f64::NAN);
    };
    let (Some(a), Some(scratch), true) = (a.get(..d2), scratch.get_mut(..5 * d2), dim > 0) else {
        return out.fill(f64::NAN);
    };
    let norm1 = (0..dim)
        .map(|j| a.iter().skip(j).step_by(dim).map(|x| x.abs()).sum::<f64>())
        .fold(0.0, f64::max);
    let s = if norm1 > EXPM_THETA {
        (norm1 / EXPM_THETA).log2().ceil() as i32
    } else {
        0
    };
    let scale = 0.5f64.powi(s);
    let (a1, rest) = scratch.split_at_mut(d2);
    let (a2, rest) = rest.split_at_mut(d2);
    let (a3, rest) = rest.split_at_mut(d2);
    let (a4, tmp) = rest.split_at_mut(d2);
    a1.iter_mut().zip(a).for_each(|(x, y)| *x = y * scale);
    product::<N>(a1, a1, dim, a2);
    product::<N>(a2, a1, dim, a3);
    product::<N>(a2, a2, dim, a4);
    let [c0, c1, c2, c3, c4, c5, c6, c7, c8, c9, c10, c11, c12] = EXPM_TAYLOR;
    // B_i = c[4i] I + c[4i+1] A + c[4i+2] A² + c[4i+3] A³ (B₂ adds c[12] A⁴).
    let block = |[ci, ci1, ci2, ci3]: [f64; 4], a4_coeff: Option<f64>, b: &mut [f64]| {
        let powers = a1.iter().zip(a2.iter()).zip(a3.iter()).zip(a4.iter());
        for (v, (((x1, x2), x3), x4)) in b.iter_mut().zip(powers) {
            *v = ci1 * x1 + ci2 * x2 + ci3 * x3;
            if let Some(c) = a4_coeff {
                *v += c * x4;
            }
        }
        b.iter_mut().step_by(dim + 1).for_each(|v| *v += ci);
    };
    // out = B₂; tmp = A⁴ B₂ + B₁; out = A⁴ tmp + B₀.
    block([c8, c9, c10, c11], Some(c12), out);
    product::<N>(a4, out, dim, tmp);
    block([c4, c5, c6, c7], None, out);
    tmp.iter_mut().zip(out.iter()).for_each(|(t, b)| *t += b);
    product::<N>(a4, tmp, dim, out);
    block([c0, c1, c2, c3], None, tmp);
    out.iter_mut().zip(tmp.iter()).for_each(|(o, b)| *o += b);
    for _ in 0..s {
        product::<N>(out, out, dim, tmp);
        out.copy_from_slice(tmp);
    }
}

/// Closed-form exponential of a 2×2 matrix: with `μ = tr/2` and `δ² = μ² − det`,
/// `exp(A) = e^μ [cosh δ · I + (sinh δ/δ)(A − μI)]` (δ imaginary → cos/sin).
/// `out` is NaN if `a` has fewer than 4 entries.
pub fn expm2(a: &[f64], out: &mut [f64]) {
    let Some(out) = out.first_chunk_mut::<4>() else {
        return out.fill(f64::NAN);
    };
    let Some(&[a0, a1, a2, a3]) = a.first_chunk::<4>() else {
        return out.fill(f64::NAN);
    };
    let mu = 0.5 * (a0 + a3);
    let det = a0 * a3 - a1 * a2;
    let d2 = mu * mu - det;
    let (c, s) = if d2.abs() < 1e-8 {
        // Series to O(d2³): cosh δ = 1 + d2/2 + d2²/24, sinh δ/δ = 1 + d2/6 + d2²/120.
        (
            1.0 + d2 / 2.0 + d2 * d2 / 24.0,
            1.0 + d2 / 6.0 + d2 * d2 / 120.0,
        )
    } else if d2 > 0.0 {
        let d = d2.sqrt();
        (d.cosh(), d.sinh() / d)
    } else {
        let d = (-d2).sqrt();
        (d.cos(), d.sin() / d)
    };
    let e = mu.exp();
    *out = [
        e * (c + s * (a0 - mu)),
        e * s * a1,
        e * s * a2,
        e * (c + s * (a3 - mu)),
    ];
}

/// Monodromy matrix (Eq. 80) from Θ sampled on a uniform grid: `theta` holds
/// `2·steps` row-major `dim×dim` samples at `τ_j = j·period/(2·steps)`,
/// `j = 0..2·steps−1` (the sample at τ = period is the one at 0). One Hsu step spans
/// two grid intervals. Result in `q` (`dim²`; NaN if `theta` is short).
pub fn monodromy_uniform(
    dim: usize,
    theta: &[f64],
    steps: usize,
    period: f64,
    rule: HsuRule,
    q: &mut [f64],
) {
    monodromy_strided(dim, theta, 2 * steps, 1, period, rule, q);
}

/// [`monodromy_uniform`] on every `stride`-th of `samples` uniform Θ samples
/// (`samples / (2·stride)` steps): with `stride = 2`, the monodromy of half the
/// steps from the same samples, the coarse member of a Richardson error
/// estimate ([`crate::AdaptiveHsu`]).
pub(crate) fn monodromy_strided(
    dim: usize,
    theta: &[f64],
    samples: usize,
    stride: usize,
    period: f64,
    rule: HsuRule,
    q: &mut [f64],
) {
    let grid = ThetaGrid {
        dim,
        theta,
        samples,
        stride,
        period,
    };
    by_size!(dim, monodromy_sized(grid, rule, q));
}

/// The uniform Θ samples [`monodromy_strided`] reads: `samples` row-major
/// `dim×dim` matrices over one `period`, every `stride`-th of them used.
#[derive(Clone, Copy)]
struct ThetaGrid<'a> {
    dim: usize,
    theta: &'a [f64],
    samples: usize,
    stride: usize,
    period: f64,
}

/// [`monodromy_strided`] with the size `N` known at compile time, or read
/// from `grid.dim` for `N = 0`.
fn monodromy_sized<const N: usize>(grid: ThetaGrid<'_>, rule: HsuRule, q: &mut [f64]) {
    let ThetaGrid {
        dim,
        theta,
        samples,
        stride,
        period,
    } = grid;
    let dim = if N == 0 { dim } else { N };
    let d2 = dim * dim;
    let steps = samples / (2 * stride);
    debug_assert!(theta.len() >= samples * d2 && steps * 2 * stride == samples);
    let h = period / steps as f64;
    // One buffer cut into slices of the exact lengths (known at compile time
    // for N ≥ 1, so that the loops below unroll).
    let mut work = vec![0.0; 3 * d2 + dim + expm_scratch_len(dim)];
    let (omega, rest) = work.split_at_mut(d2);
    let (step, rest) = rest.split_at_mut(d2);
    let (prod, rest) = rest.split_at_mut(d2);
    let (comm, scratch) = rest.split_at_mut(dim);
    let Some(q) = q.get_mut(..d2) else {
        return q.fill(f64::NAN);
    };
    q.fill(0.0);
    q.iter_mut().step_by(dim + 1).for_each(|v| *v = 1.0);
    let at = |j: usize| {
        let j = (j * stride) % samples.max(1);
        theta.get(j * d2..(j + 1) * d2)
    };
    for s in 0..steps {
        let (Some(t0), Some(th), Some(t1)) = (at(2 * s), at(2 * s + 1), at(2 * s + 2)) else {
            return q.fill(f64::NAN);
        };
        match rule {
            HsuRule::Left => omega.iter_mut().zip(t1).for_each(|(o, t)| *o = h * t),
            HsuRule::Midpoint => omega.iter_mut().zip(th).for_each(|(o, t)| *o = h * t),
            HsuRule::Magnus4 => {
                for (o, ((x0, xh), x1)) in omega.iter_mut().zip(t0.iter().zip(th).zip(t1)) {
                    *o = h / 6.0 * (x0 + 4.0 * xh + x1);
                }
                // − (h²/12) [Θ₀, Θ₁], row i: Σ_l Θ₀[i][l] Θ₁[l][:] − Θ₁[i][l] Θ₀[l][:].
                let c = h * h / 12.0;
                let rows = t0.chunks_exact(dim).zip(t1.chunks_exact(dim));
                for (o_row, (t0_row, t1_row)) in omega.chunks_exact_mut(dim).zip(rows.clone()) {
                    comm.fill(0.0);
                    for ((a0, a1), (r0, r1)) in t0_row.iter().zip(t1_row).zip(rows.clone()) {
                        for ((s, x1), x0) in comm.iter_mut().zip(r1).zip(r0) {
                            *s += a0 * x1 - a1 * x0;
                        }
                    }
                    for (o, s) in o_row.iter_mut().zip(comm.iter()) {
                        *o -= c * s;
                    }
                }
            }
        }
        if dim == 2 {
            expm2(omega, step);
        } else {
            expm_sized::<N>(omega, dim, step, scratch);
        }
        // Later sub-intervals multiply from the left.
        product::<N>(step, q, dim, prod);
        q.copy_from_slice(prod);
    }
}

/// Monodromy matrix with Θ given as a function `theta(τ, out)`; samples it on the
/// uniform grid of [`monodromy_uniform`].
pub fn monodromy_hsu<F: FnMut(f64, &mut [f64])>(
    dim: usize,
    period: f64,
    steps: usize,
    rule: HsuRule,
    mut theta: F,
) -> Vec<f64> {
    let d2 = dim * dim;
    let m = 2 * steps;
    let mut samples = vec![0.0; m * d2];
    for (j, sample) in samples.chunks_exact_mut(d2.max(1)).enumerate() {
        theta(j as f64 * period / m as f64, sample);
    }
    let mut q = vec![0.0; d2];
    monodromy_uniform(dim, &samples, steps, period, rule, &mut q);
    q
}

/// Eigenvalues of a real row-major `dim×dim` matrix (faer), i.e. the Floquet
/// multipliers when applied to the monodromy matrix. Sorted by decreasing modulus.
/// NaN if `a` has fewer than `dim²` entries or the eigensolver fails.
pub fn eigenvalues(a: &[f64], dim: usize) -> Vec<c64> {
    if a.len() < dim * dim {
        return vec![c64::new(f64::NAN, f64::NAN); dim];
    }
    if let (2, Some(&[a0, a1, a2, a3])) = (dim, a.first_chunk::<4>()) {
        // Closed form for the single-DOF case (the FRC hot path): λ² − tr λ + det = 0.
        let (tr, det) = (a0 + a3, a0 * a3 - a1 * a2);
        let disc = 0.25 * tr * tr - det;
        let mut ev = if disc >= 0.0 {
            let r = disc.sqrt();
            // Avoid cancellation: larger root first, smaller from the product.
            let l1 = 0.5 * tr + r.copysign(tr);
            let l2 = if l1 != 0.0 {
                det / l1
            } else {
                0.5 * tr - r.copysign(tr)
            };
            vec![c64::new(l1, 0.0), c64::new(l2, 0.0)]
        } else {
            let i = (-disc).sqrt();
            vec![c64::new(0.5 * tr, i), c64::new(0.5 * tr, -i)]
        };
        sort_by_modulus(&mut ev);
        return ev;
    }
    let mat = faer::Mat::<f64>::from_fn(dim, dim, |i, j| {
        a.get(i * dim + j).copied().unwrap_or(f64::NAN)
    });
    let mut ev = mat
        .eigenvalues()
        .unwrap_or_else(|_| vec![c64::new(f64::NAN, f64::NAN); dim]);
    sort_by_modulus(&mut ev);
    ev
}

/// Relative difference below which two moduli count as equal in
/// [`sort_by_modulus`]. The two members of a conjugate pair have equal moduli up
/// to the eigensolver's rounding (a few ε), and no multiplier of this crate is
/// more accurate than 1e-10 (Hsu, Hill and the monodromy integrations are
/// 1e-12…1e-6 accurate), so moduli within 1e-10 are equal to every method's
/// accuracy: ordering them by imaginary part gives the same order for the same
/// multipliers computed by different methods.
pub const MODULUS_TIE: f64 = 1e-10;

/// Sorts complex numbers by decreasing modulus; each run of neighbours whose
/// moduli agree within [`MODULUS_TIE`] (relative) is then ordered by increasing
/// imaginary part, so a conjugate pair comes out as (a − ib, a + ib) whatever
/// its rounding.
pub fn sort_by_modulus(v: &mut [c64]) {
    v.sort_by(|a, b| b.norm().total_cmp(&a.norm()));
    for run in v.chunk_by_mut(|a, b| a.norm() - b.norm() <= MODULUS_TIE * a.norm()) {
        run.sort_by(|a, b| a.im.total_cmp(&b.im));
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn taylor_coefficients_are_the_running_division_and_one_over_k_factorial() {
        let mut running = 1.0;
        let mut factorial = 1.0;
        for (k, &c) in EXPM_TAYLOR.iter().enumerate() {
            if k > 0 {
                running /= k as f64;
                factorial *= k as f64;
            }
            assert_eq!(c.to_bits(), running.to_bits(), "k = {k}");
            assert!((c * factorial - 1.0).abs() < 1e-15, "k = {k}");
        }
    }

    #[test]
    fn expm_of_rotation_generator() {
        // exp([[0, t], [−t, 0]]) = [[cos t, sin t], [−sin t, cos t]], t = 3.
        let a = [0.0, 3.0, -3.0, 0.0];
        let mut out = [0.0; 4];
        let mut scratch = [0.0; 8];
        expm(&a, 2, &mut out, &mut scratch);
        let want = [3f64.cos(), 3f64.sin(), -3f64.sin(), 3f64.cos()];
        for (o, w) in out.iter().zip(want) {
            assert!((o - w).abs() < 1e-14, "{o} vs {w}");
        }
    }

    #[test]
    fn modulus_ties_are_ordered_by_imaginary_part() {
        // A conjugate pair whose moduli differ in the last bits, a real
        // multiplier between two runs, and a second pair 2e-6 apart in angle.
        let pair = c64::new(0.3, 0.4);
        let nudged = c64::new(0.3 * (1.0 + 4.0 * f64::EPSILON), -0.4);
        let mut v = [
            c64::new(0.1, 0.0),
            pair,
            c64::new(0.2, 1e-6),
            nudged,
            c64::new(0.9, 0.0),
            c64::new(0.2, -1e-6 * (1.0 + 1e-6)),
        ];
        sort_by_modulus(&mut v);
        assert_eq!(v[0], c64::new(0.9, 0.0));
        assert_eq!((v[1], v[2]), (nudged, pair), "{v:?}");
        assert_eq!(v[5], c64::new(0.1, 0.0));
        // 0.2 ± 1e-6 i: moduli equal within 1e-10, so −i first.
        assert!(v[3].im < 0.0 && v[4].im > 0.0, "{v:?}");
    }

    #[test]
    fn expm_matches_nalgebra_pade_for_sizes_3_to_8_and_10() {
        // nalgebra's exp (Padé with its own scaling) is an independent method.
        // Entries from a fixed LCG; norms 1e-4…20 cover no scaling (a Hsu step at
        // high ω_f) to seven squarings (ω_f = 0.2 with few steps). Sizes 3–8 run
        // the compile-time sizes of `by_size!`, 10 the size read at run time.
        let mut seed = 0x2545_f491_4f6c_dd1du64;
        let mut next = || {
            seed = seed
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (seed >> 11) as f64 / (1u64 << 53) as f64 * 2.0 - 1.0
        };
        let mut worst = 0.0f64;
        for dim in (3..=8).chain([10]) {
            for norm in [1e-4, 0.03, 0.2, 0.9, 4.0, 20.0] {
                let mut a: Vec<f64> = (0..dim * dim).map(|_| next()).collect();
                let n1 = (0..dim)
                    .map(|j| (0..dim).map(|i| a[i * dim + j].abs()).sum::<f64>())
                    .fold(0.0, f64::max);
                a.iter_mut().for_each(|v| *v *= norm / n1);
                let mut out = vec![0.0; dim * dim];
                let mut scratch = vec![0.0; expm_scratch_len(dim)];
                expm(&a, dim, &mut out, &mut scratch);
                let want = nalgebra::DMatrix::from_row_slice(dim, dim, &a).exp();
                let scale = want.norm();
                let err = (0..dim * dim)
                    .map(|k| (out[k] - want[(k / dim, k % dim)]).powi(2))
                    .sum::<f64>()
                    .sqrt()
                    / scale;
                worst = worst.max(err);
                assert!(
                    err < 1e-13,
                    "dim {dim}, ‖a‖₁ = {norm}: relative error {err:e}"
                );
            }
        }
        eprintln!("expm vs nalgebra: worst relative error {worst:.1e}");
    }

    /// A constant Θ makes every Magnus-4 step exact: the monodromy over 2π is
    /// `exp(2πΘ)` (nalgebra's Padé, independent), for the compile-time size 4
    /// and the run-time size 10 of `by_size!`, by both step counts of a
    /// Richardson pair.
    #[test]
    fn constant_theta_monodromy_is_the_exponential_for_every_size_path() {
        for dim in [4, 10] {
            let d2 = dim * dim;
            let theta: Vec<f64> = (0..d2)
                .map(|k| 0.3 * ((k * 37 % 11) as f64 / 11.0 - 0.5))
                .collect();
            let period = 2.0 * std::f64::consts::PI;
            let want = (nalgebra::DMatrix::from_row_slice(dim, dim, &theta) * period).exp();
            let samples: Vec<f64> = (0..64).flat_map(|_| theta.iter().copied()).collect();
            for stride in [1, 2] {
                let mut q = vec![0.0; d2];
                monodromy_strided(dim, &samples, 64, stride, period, HsuRule::Magnus4, &mut q);
                let scale = want.norm();
                let err = (0..d2)
                    .map(|k| (q[k] - want[(k / dim, k % dim)]).powi(2))
                    .sum::<f64>()
                    .sqrt();
                assert!(err <= 1e-12 * scale, "dim {dim}, stride {stride}: {err:e}");
            }
        }
    }

    #[test]
    fn closed_form_2x2_matches_taylor_path() {
        // Compare expm2 with the generic path by embedding in a 3×3 block-diagonal.
        for a in [
            [0.3, 1.2, -0.7, -0.1],
            [0.5, 0.2, 0.1, 0.4],
            [1e-5, 1.0, 0.0, 1e-5],
        ] {
            let mut out2 = [0.0; 4];
            expm2(&a, &mut out2);
            let big = [a[0], a[1], 0.0, a[2], a[3], 0.0, 0.0, 0.0, 0.2];
            let mut out3 = [0.0; 9];
            let mut scratch = [0.0; 45];
            expm(&big, 3, &mut out3, &mut scratch);
            for (x, y) in out2.iter().zip([out3[0], out3[1], out3[3], out3[4]]) {
                assert!((x - y).abs() < 1e-14, "{a:?}: {out2:?} vs {out3:?}");
            }
        }
    }

    #[test]
    fn closed_form_2x2_matches_the_rotation_and_boost() {
        // [[0, w], [−w, 0]] is a rotation by w (d2 = −w²), [[0, w], [w, 0]] a
        // boost (d2 = w²): exp is [[cos w, sin w], [−sin w, cos w]] and
        // [[cosh w, sinh w], [sinh w, cosh w]]; w = 1e-9 takes the series
        // branch (|d2| < 1e-8), the others cos/sin and cosh/sinh.
        for w in [1e-9f64, 1e-4, 0.1, 0.5, 0.9, 0.999_999, 1.0, 1.01, 3.0] {
            let (c, s) = (w.cos(), w.sin());
            let mut out = [0.0; 4];
            expm2(&[0.0, w, -w, 0.0], &mut out);
            for (got, want) in out.iter().zip([c, s, -s, c]) {
                assert!(
                    (got - want).abs() <= 4e-16 * want.abs().max(1e-300),
                    "rotation {w}: {out:?}"
                );
            }
            expm2(&[0.0, w, w, 0.0], &mut out);
            for (got, want) in out.iter().zip([w.cosh(), w.sinh(), w.sinh(), w.cosh()]) {
                assert!(
                    (got - want).abs() <= 4e-16 * want.abs(),
                    "boost {w}: {out:?}"
                );
            }
        }
    }

    #[test]
    fn mathieu_free_oscillator_multipliers() {
        // Θ constant [[0,1],[−ω0², −2ζω0]]: multipliers exp(2π λ), λ the eigenvalues.
        let (w0, z) = (1.3f64, 0.05);
        let q = monodromy_hsu(
            2,
            2.0 * std::f64::consts::PI,
            64,
            HsuRule::Magnus4,
            |_, o| {
                o.copy_from_slice(&[0.0, 1.0, -w0 * w0, -2.0 * z * w0]);
            },
        );
        let mu = eigenvalues(&q, 2);
        let re = -z * w0;
        let im = w0 * (1.0 - z * z).sqrt();
        let tp = 2.0 * std::f64::consts::PI;
        let want = c64::new(
            (re * tp).exp() * (im * tp).cos(),
            (re * tp).exp() * (im * tp).sin(),
        );
        let hit = mu.iter().any(|m| (m - want).norm() < 1e-12);
        assert!(hit, "{mu:?} vs {want:?}");
    }
}
