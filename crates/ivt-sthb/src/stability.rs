//! Stability of periodic responses of the string (Eq. 126–131), fixed–fixed
//! or with the spring boundary (the Tau constraint eliminated, see
//! `Linearization`).
//!
//! The linearization `γ̇ = A(t) γ`, `A = [[0, E], [(G2 + S(t))/ω², −c_d/ω E]]`
//! (Eq. 127), takes `S(t) = ∂ℒ/∂Q` from the same spectrum `Ŝ_p` that builds the
//! STHB Jacobian (Eq. 129: `∂ℒ/∂Q = Φ̂ᵀ S_T`), so no modal ODE is derived.
//!
//! * [`hill`] — eigenvalues of the truncated Hill matrix `A_𝒯 − D` (Eq. 130–131)
//!   in the fundamental strip. With the period normalized to `2π` the exponents
//!   repeat with period `j` (not `2πj` as printed under Eq. 131), so the strip is
//!   `Im λ ∈ (−½, ½]` and the multipliers are `exp(2πλ)`.
//! * [`monodromy`] — RK4 over one period of the same `A(t)`; `O(N³)` per step,
//!   cheap enough for every continuation point, with Hill to confirm.

use std::f64::consts::PI;

use faer::Mat;
use ivt_num::{ExplicitRk, RK4};
use realfft::num_complex::Complex;
use realfft::RealFftPlanner;

use super::toeplitz::{add_real_toeplitz, BlockLayout, PeriodicSpectrum};
use super::StringHb;
use ivt_hb::HbError;

/// The stability classes of the engine ([`ivt_hb::stability::classify`]): the
/// unstable kinds name the multiplier that left the unit circle (fold +1,
/// period doubling −1, Neimark–Sacker complex pair).
pub use ivt_hb::stability::StabilityKind;

/// Which method produced a verdict.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "snake_case")]
pub enum StabilityMethod {
    /// Eigenvalues of the Hill matrix (Eq. 130–131).
    Hill,
    /// Eigenvalues of the RK4 monodromy matrix.
    Monodromy,
    /// Eigenvalues of the RK4 monodromy matrix with half the step
    /// ([`monodromy_refined`]): the confirmation where Hill's matrix exceeds
    /// [`HILL_MAX_DIM`].
    MonodromyRefined,
}

/// Stability verdict of one periodic response.
#[derive(Clone, Debug, PartialEq)]
pub struct Stability {
    /// Classification.
    pub kind: StabilityKind,
    /// Floquet multipliers, decreasing modulus (monodromy: all `2N`; Hill:
    /// `exp(2πλ)` of the exponents in the fundamental strip).
    pub multipliers: Vec<Complex<f64>>,
    /// Method used.
    pub method: StabilityMethod,
}

impl Stability {
    /// `true` for [`StabilityKind::Stable`].
    pub fn is_stable(&self) -> bool {
        self.kind == StabilityKind::Stable
    }

    /// The multiplier of largest modulus.
    pub fn critical(&self) -> Complex<f64> {
        // Never empty (`from_multipliers` refuses that); NaN if it were.
        self.multipliers
            .first()
            .copied()
            .unwrap_or(Complex::new(f64::NAN, f64::NAN))
    }

    /// Classifies by the leading multiplier of `multipliers` (non-empty,
    /// decreasing modulus).
    fn from_multipliers(
        multipliers: Vec<Complex<f64>>,
        method: StabilityMethod,
    ) -> Result<Self, HbError> {
        let Some(critical) = multipliers.get(..1) else {
            return Err(HbError::Eigen("no Floquet multiplier".into()));
        };
        Ok(Self {
            kind: ivt_hb::stability::classify(critical),
            multipliers,
            method,
        })
    }
}

/// The linearization about a response in second-order form
/// `γ̈ = −(c_d/ω) γ̇ + (S̃(t) − K̃) γ / ω²` (Eq. 127), `N` coordinates.
///
/// Fixed–fixed: `K̃ = diag(n²π²)`, `S̃ = S = ∂ℒ/∂Q` (Eq. 129). Spring (Tau,
/// Eq. 133–136): the boundary row is algebraic and constant in time, so
/// `q_{N+1} = cᵀq` eliminates it exactly; the rows then read
/// `ω² M q̈ + ω c_d M q̇ + K q − ℒ(q, cᵀq) = f` with `M = I + e cᵀ`, hence
/// `K̃ = M⁻¹K`, `S̃ = M⁻¹(S_{:,1..N} + S_{:,N+1} cᵀ)`, the damping staying
/// `c_d/ω` because `C = c_d M`. `M⁻¹ = I − e cᵀ/(1 + cᵀe)` (Sherman–Morrison).
struct Linearization {
    /// `K̃`, row-major `N × N`.
    stiffness: Vec<f64>,
    /// Spectrum of `S̃(t)`, `N × N`.
    s: PeriodicSpectrum,
}

impl Linearization {
    fn of(hb: &StringHb) -> Result<Self, HbError> {
        let n = hb.params().modes;
        let spec = hb.s_spectrum();
        let mut stiffness = vec![0.0; n * n];
        for (i, k) in stiffness.iter_mut().step_by(n + 1).enumerate() {
            *k = ((i + 1) as f64 * PI).powi(2);
        }
        let Some((e, c)) = hb.tau_coupling() else {
            return Ok(Self {
                stiffness,
                s: spec.clone(),
            });
        };
        if e.len() != n || c.len() != n {
            return Err(HbError::InvalidInput(format!(
                "spring boundary: Tau coupling vectors of {} and {} entries for {n} modes",
                e.len(),
                c.len()
            )));
        }
        let denom = 1.0 + c.iter().zip(&e).map(|(a, b)| a * b).sum::<f64>();
        if denom.abs() < 1e-12 {
            return Err(HbError::InvalidInput(
                "spring boundary: singular Tau mass matrix (1 + cᵀe = 0)".into(),
            ));
        }
        // M⁻¹ X = X − e (cᵀX)/(1 + cᵀe), applied column by column.
        let apply_minv = |col: &mut dyn FnMut(usize) -> Complex<f64>, out: &mut [Complex<f64>]| {
            let mut ctx = Complex::new(0.0, 0.0);
            for (i, (o, ci)) in out.iter_mut().zip(&c).enumerate() {
                *o = col(i);
                ctx += *o * ci;
            }
            for (o, ei) in out.iter_mut().zip(&e) {
                *o -= ctx * (ei / denom);
            }
        };
        let mut col = vec![Complex::new(0.0, 0.0); n];
        let mut k_new = vec![0.0; n * n];
        let nan = Complex::new(f64::NAN, f64::NAN);
        for j in 0..n {
            let k_col = |i: usize| stiffness.get(i * n + j).copied().unwrap_or(f64::NAN);
            apply_minv(&mut |i| Complex::new(k_col(i), 0.0), &mut col);
            for (k, x) in k_new.iter_mut().skip(j).step_by(n).zip(&col) {
                *k = x.re;
            }
        }
        let mut s = PeriodicSpectrum::zeros(n, n, spec.ms, spec.p_max);
        for p in 0..=spec.p_max {
            let at =
                |i: usize, j: usize| spec.data.get(spec.index(p, i, j)).copied().unwrap_or(nan);
            for (j, &cj) in c.iter().enumerate() {
                apply_minv(&mut |i| at(i, j) + at(i, n) * cj, &mut col);
                for (i, x) in col.iter().enumerate() {
                    let k = s.index(p, i, j);
                    if let Some(y) = s.data.get_mut(k) {
                        *y = *x;
                    }
                }
            }
        }
        Ok(Self {
            stiffness: k_new,
            s,
        })
    }
}

/// Hill exponents `λ` in the fundamental strip `Im λ ∈ (−½, ½]` at the response
/// whose Jacobian was evaluated last (after [`StringHb::solve`] or
/// [`StringHb::linearize`]).
///
/// # Errors
/// [`HbError::InvalidInput`] if the spring's Tau mass matrix is singular,
/// [`HbError::Eigen`] if the eigenvalue iteration fails.
pub fn hill_exponents(hb: &StringHb, omega: f64) -> Result<Vec<Complex<f64>>, HbError> {
    let lin = Linearization::of(hb)?;
    let (n, m, cd) = (hb.params().modes, hb.params().harmonics, hb.params().cd);
    let blk = 2 * n;
    let dim = blk * (2 * m + 1);
    let mut h = Mat::<f64>::zeros(dim, dim);
    for g in 0..2 * m + 1 {
        let o = g * blk;
        for i in 0..n {
            h[(o + i, o + n + i)] = 1.0;
            for (j, kij) in lin.stiffness.iter().skip(i * n).take(n).enumerate() {
                h[(o + n + i, o + j)] = -kij / (omega * omega);
            }
            h[(o + n + i, o + n + i)] = -cd / omega;
        }
        if g > 0 && g % 2 == 0 {
            // −D: d/dt (c cos kt + s sin kt) = k s cos kt − k c sin kt.
            let k = (g / 2) as f64;
            let oc = (g - 1) * blk;
            for i in 0..blk {
                h[(oc + i, o + i)] -= k;
                h[(o + i, oc + i)] += k;
            }
        }
    }
    let layout = BlockLayout {
        row_block: blk,
        row_off: n,
        col_block: blk,
        col_off: 0,
    };
    add_real_toeplitz(
        &lin.s,
        m,
        1.0 / (omega * omega),
        layout,
        h.as_mut(),
        &mut Vec::new(),
    );
    let ev = h
        .eigenvalues()
        .map_err(|e| HbError::Eigen(format!("{e:?}")))?;
    let mut strip: Vec<Complex<f64>> = ev
        .into_iter()
        .map(|z| Complex::new(z.re, z.im))
        .filter(|z| z.im > -0.5 - 1e-9 && z.im <= 0.5 + 1e-9)
        .collect();
    strip.sort_by(|a, b| b.re.total_cmp(&a.re));
    Ok(strip)
}

/// Hill's-method verdict (Eq. 126–131).
///
/// # Errors
/// As [`hill_exponents`].
pub fn hill(hb: &StringHb, omega: f64) -> Result<Stability, HbError> {
    let ex = hill_exponents(hb, omega)?;
    if ex.is_empty() {
        return Err(HbError::Eigen("no Hill exponent in the strip".into()));
    }
    // A real exponent (Im λ = 0) gives a positive multiplier, Im λ = ±½ a negative one;
    // snap those so the classification does not hinge on rounding. The exponents
    // are sorted by decreasing real part, so the multipliers by decreasing modulus.
    let multipliers = ex
        .iter()
        .map(|&lambda| {
            let mu = (lambda * (2.0 * PI)).exp();
            let frac = lambda.im.abs();
            if frac < 1e-6 || (0.5 - frac).abs() < 1e-6 {
                Complex::new(mu.re, 0.0)
            } else {
                mu
            }
        })
        .collect();
    Stability::from_multipliers(multipliers, StabilityMethod::Hill)
}

/// `S(t)[idx, idx]` from its spectrum at time `t` (row-major `k × k`,
/// `k = idx.len()`, into `out`).
fn s_at(s: &PeriodicSpectrum, t: f64, idx: &[usize], out: &mut [f64]) {
    let entries = |p: usize| {
        idx.iter().flat_map(move |&i| {
            idx.iter().map(move |&j| {
                s.data
                    .get(s.index(p, i, j))
                    .copied()
                    .unwrap_or(Complex::new(f64::NAN, f64::NAN))
            })
        })
    };
    for (o, z) in out.iter_mut().zip(entries(0)) {
        *o = z.re;
    }
    let base = Complex::from_polar(1.0, t);
    let mut rot = Complex::new(1.0, 0.0);
    for p in 1..=s.p_max {
        rot *= base;
        let w = if 2 * p == s.ms { 1.0 } else { 2.0 };
        let e = rot * w;
        for (o, z) in out.iter_mut().zip(entries(p)) {
            *o += (z * e).re;
        }
    }
}

/// `S(t)[idx, idx]` on the `2·steps + 1` RK4 nodes `t = node·π/steps` (the
/// last one `t = 2π`, equal to the first) by one inverse real FFT of length
/// `2·steps` per entry: the same trigonometric sums as [`s_at`] (whose
/// weights it keeps: 2, or 1 at `p = M_s/2`) in `O(steps log steps)` instead
/// of `O(steps · p_max)`. Calls `put(node, i, j, value)`; `false` (nothing
/// done) when `p_max ≥ steps`, where the grid cannot carry the harmonics.
fn s_on_grid(
    s: &PeriodicSpectrum,
    steps: usize,
    idx: &[usize],
    mut put: impl FnMut(usize, usize, usize, f64),
) -> bool {
    if s.p_max >= steps {
        return false;
    }
    let len = 2 * steps;
    let ifft = RealFftPlanner::<f64>::new().plan_fft_inverse(len);
    let (mut spec, mut out) = (ifft.make_input_vec(), ifft.make_output_vec());
    let mut scratch = ifft.make_scratch_vec();
    let nan = Complex::new(f64::NAN, f64::NAN);
    for (i, &fi) in idx.iter().enumerate() {
        for (j, &fj) in idx.iter().enumerate() {
            let at = |p: usize| s.data.get(s.index(p, fi, fj)).copied().unwrap_or(nan);
            spec.fill(Complex::new(0.0, 0.0));
            if let Some(x0) = spec.first_mut() {
                *x0 = Complex::new(at(0).re, 0.0);
            }
            for (p, x) in spec.iter_mut().enumerate().take(s.p_max + 1).skip(1) {
                // The FFT doubles every bin below len/2; s_at's Nyquist bin has weight 1.
                let w = if 2 * p == s.ms { 0.5 } else { 1.0 };
                *x = at(p) * w;
            }
            if ifft
                .process_with_scratch(&mut spec, &mut out, &mut scratch)
                .is_err()
            {
                return false;
            }
            for (node, v) in out.iter().chain(out.first()).enumerate() {
                put(node, i, j, *v);
            }
        }
    }
    true
}

/// Monodromy matrix (`2N × 2N`, column-major) of Eq. 126 by RK4 with `steps`
/// steps per period.
///
/// # Errors
/// As [`hill_exponents`].
pub fn monodromy_matrix(hb: &StringHb, omega: f64, steps: usize) -> Result<Mat<f64>, HbError> {
    let lin = Linearization::of(hb)?;
    let all: Vec<usize> = (0..hb.params().modes).collect();
    Ok(block_monodromy(hb, &lin, omega, steps, &all))
}

/// The monodromy (`2k × 2k`, state `[x_idx; v_idx]`) of the linearization
/// restricted to the coordinates `idx` (`k = idx.len()`): the whole of it when
/// the other coordinates do not couple to these ([`parity_blocks`]).
fn block_monodromy(
    hb: &StringHb,
    lin: &Linearization,
    omega: f64,
    steps: usize,
    idx: &[usize],
) -> Mat<f64> {
    let (full, cd) = (hb.params().modes, hb.params().cd);
    let n = idx.len();
    if n == 0 {
        return Mat::zeros(0, 0);
    }
    let s = &lin.s;
    let d = 2 * n;
    let h = 2.0 * PI / steps as f64;
    let w2 = 1.0 / (omega * omega);
    // B(t) = (S̃(t) − K̃)/ω² at the 2·steps + 1 half-step nodes, stored
    // column-major so that B x is a sum of columns (vectorized axpys).
    let mut b = vec![0.0; (2 * steps + 1) * n * n];
    // K̃_ij of the block's coordinates (NaN marks an index slip).
    let stiffness = |i: usize, j: usize| {
        let (Some(fi), Some(fj)) = (idx.get(i), idx.get(j)) else {
            return f64::NAN;
        };
        lin.stiffness
            .get(fi * full + fj)
            .copied()
            .unwrap_or(f64::NAN)
    };
    // Column-major entry (i, j) of node `node` (every index < b.len()).
    let put = |b: &mut [f64], node: usize, i: usize, j: usize, v: f64| {
        if let Some(x) = b.get_mut(node * n * n + j * n + i) {
            *x = (v - stiffness(i, j)) * w2;
        }
    };
    if !s_on_grid(s, steps, idx, |node, i, j, v| put(&mut b, node, i, j, v)) {
        let mut row_major = vec![0.0; n * n];
        for node in 0..=2 * steps {
            s_at(s, node as f64 * 0.5 * h, idx, &mut row_major);
            for (e, v) in row_major.iter().enumerate() {
                put(&mut b, node, e / n, e % n, *v);
            }
        }
    }
    let damp = cd / omega;
    // Y = [X; V] column by column; f(Y) = [V; B X − damp V].
    let mut y = vec![0.0; d * d];
    y.iter_mut().step_by(d + 1).for_each(|v| *v = 1.0);
    let f = |bn: &[f64], y: &[f64], out: &mut [f64]| {
        for (yc, oc) in y.chunks_exact(d).zip(out.chunks_exact_mut(d)) {
            let (x, v) = yc.split_at(n);
            let (ox, ov) = oc.split_at_mut(n);
            ox.copy_from_slice(v);
            for (o, vi) in ov.iter_mut().zip(v) {
                *o = -damp * vi;
            }
            for (xj, bcol) in x.iter().zip(bn.chunks_exact(n)) {
                for (o, bij) in ov.iter_mut().zip(bcol) {
                    *o += bij * xj;
                }
            }
        }
    };
    // Stage times are multiples of h/2: the node index of B.
    let mut rhs = |t: f64, y: &[f64], out: &mut [f64]| {
        let k = (2.0 * t / h).round() as usize;
        match b.get(k * n * n..(k + 1) * n * n) {
            Some(bn) => f(bn, y, out),
            None => out.fill(f64::NAN),
        }
    };
    ExplicitRk::with_dim(&RK4, d * d).fixed_steps(&mut rhs, 0.0, h, steps, &mut y);
    Mat::from_fn(d, d, |i, j| y.get(j * d + i).copied().unwrap_or(f64::NAN))
}

/// The odd and the even sine modes (0-based indices even, odd) when the
/// linearization does not couple them: the fixed–fixed string at a response
/// of its invariant subspace (`sthb::reduced`), whose `S(t)` then has
/// `S_ij = 0` for `i + j` odd (the reflection `x → 1 − x`; entries up to
/// 1e-12 of the largest, rounding, are taken as zero). `None` otherwise.
fn parity_blocks(hb: &StringHb, lin: &Linearization) -> Option<[Vec<usize>; 2]> {
    let n = hb.params().modes;
    if hb.tau_coupling().is_some() || n < 2 {
        return None;
    }
    let s = &lin.s;
    let (mut cross, mut largest) = (0.0f64, 0.0f64);
    for (e, z) in s.data.iter().enumerate() {
        let (i, j) = ((e / s.cols) % s.rows, e % s.cols);
        if (i + j) % 2 == 1 {
            cross = cross.max(z.norm());
        }
        largest = largest.max(z.norm());
    }
    (cross <= 1e-12 * largest).then(|| [(0..n).step_by(2).collect(), (1..n).step_by(2).collect()])
}

/// RK4 steps that keep `h ρ ≤ 0.3` for the fastest mode (`ρ² ≈ (N²π² + ‖S‖)/ω²`).
pub fn default_steps(hb: &StringHb, omega: f64) -> usize {
    let s = hb.s_spectrum();
    let bound: f64 = s.data.iter().map(|z| 2.0 * z.norm()).sum::<f64>() / (s.rows.max(1) as f64);
    let n = hb.params().modes as f64;
    let rho = ((n * n * PI * PI + bound) / (omega * omega)).sqrt();
    ((2.0 * PI * rho / 0.3).ceil() as usize).clamp(64, 100_000)
}

/// Floquet multipliers of the RK4 monodromy ([`monodromy_matrix`]; split into
/// the odd- and the even-mode blocks where those decouple, a quarter of the
/// work), largest modulus first.
///
/// # Errors
/// As [`monodromy_matrix`], or [`HbError::Eigen`].
pub fn monodromy_multipliers(hb: &StringHb, omega: f64) -> Result<Vec<Complex<f64>>, HbError> {
    multipliers_with_steps(hb, omega, default_steps(hb, omega))
}

/// Floquet multipliers of the RK4 monodromy with `steps` steps, largest modulus first.
fn multipliers_with_steps(
    hb: &StringHb,
    omega: f64,
    steps: usize,
) -> Result<Vec<Complex<f64>>, HbError> {
    let lin = Linearization::of(hb)?;
    let blocks =
        parity_blocks(hb, &lin).map_or_else(|| vec![(0..hb.params().modes).collect()], Vec::from);
    let mut mu: Vec<Complex<f64>> = Vec::with_capacity(2 * hb.params().modes);
    for idx in &blocks {
        let phi = block_monodromy(hb, &lin, omega, steps, idx);
        let ev = phi
            .eigenvalues()
            .map_err(|e| HbError::Eigen(format!("{e:?}")))?;
        mu.extend(ev.into_iter().map(|z| Complex::new(z.re, z.im)));
    }
    mu.sort_by(|a, b| b.norm().total_cmp(&a.norm()));
    Ok(mu)
}

/// Monodromy verdict.
///
/// # Errors
/// As [`monodromy_multipliers`].
pub fn monodromy(hb: &StringHb, omega: f64) -> Result<Stability, HbError> {
    Stability::from_multipliers(
        monodromy_multipliers(hb, omega)?,
        StabilityMethod::Monodromy,
    )
}

/// Largest Hill matrix, `2N(2M + 1)`, whose dense eigenproblem ([`hill`]) a
/// curve solves to confirm a verdict: 780 (`N = 10`, `M = 19`) takes ~0.3 s,
/// the cost growing as the cube (`N = 20`, `M = 39`: 3160, a minute per call
/// on the loaded machine, measured, not asserted).
pub const HILL_MAX_DIM: usize = 800;

/// `2N(2M + 1)`, the order of the Hill matrix of Eq. 130.
pub fn hill_dim(hb: &StringHb) -> usize {
    2 * hb.params().modes * (2 * hb.params().harmonics + 1)
}

/// Verdict of the RK4 monodromy with twice [`default_steps`] (halved step),
/// the confirmation of `coarse` (the [`monodromy`] verdict at the same point)
/// where the Hill matrix is larger than [`HILL_MAX_DIM`]. RK4's error in `μ`
/// falls 16× with the halved step, so `| |μ_h| − |μ_{h/2}| |` of the critical
/// multiplier, returned with the verdict, is about 15/16 of the coarse error
/// and bounds the refined one (Richardson).
///
/// # Errors
/// As [`monodromy_multipliers`].
pub fn monodromy_refined(
    hb: &StringHb,
    omega: f64,
    coarse: &Stability,
) -> Result<(Stability, f64), HbError> {
    let fine = multipliers_with_steps(hb, omega, 2 * default_steps(hb, omega))?;
    let fine = Stability::from_multipliers(fine, StabilityMethod::MonodromyRefined)?;
    let error = (coarse.critical().norm() - fine.critical().norm()).abs();
    Ok((fine, error))
}
