//! How good the basis is: the reduced receptances at the nonlinear DOFs `S`
//! (and the reduced response to the load at its harmonic) on any subset of
//! the basis, their change from the nested basis one Krylov block smaller
//! on a grid of every harmonic band, and exact sparse solves of the whole
//! structure at sampled frequencies.
//!
//! The error measure at a frequency `w`: `max|ΔH_SS| / max|H_SS|` over the
//! entries, and at the load's harmonic also `max|Δu_S| / max|u_S|` (the
//! larger of the two): relative to the receptance matrix's size, so an
//! anti-resonance of one entry does not count as an infinite error.

use super::basis::KrylovBasis;
use crate::Structure;
use faer::linalg::solvers::Solve;
use faer::{c64, Mat, Side};
use ivt_hb::HbError;

/// One exact check of the reduced receptances.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct Sample {
    /// The frequency `w = h·ω_f/p` of the check, rad/s.
    pub omega: f64,
    /// Its harmonic `h`.
    pub harmonic: usize,
    /// The excitation frequency ω_f it belongs to.
    pub omega_f: f64,
    /// Relative error of the final reduced receptances there.
    pub error: f64,
    /// Relative error of the exact (refined) solve itself.
    pub solve_error: f64,
}

/// A frequency at which the receptances are compared.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Point {
    /// `w = h·ω_f/p`.
    pub omega: f64,
    /// `h`.
    pub harmonic: usize,
    /// ω_f.
    pub omega_f: f64,
    /// Whether the load acts at this harmonic (`h = p`).
    pub loaded: bool,
}

/// The grid of the nested estimate: `grid` excitation frequencies over the
/// band, harmonics `1..=n` (the static one is exact: `K⁻¹E_S` and `K⁻¹F`
/// are in every basis).
pub fn grid(band: (f64, f64), harmonics: usize, subharmonic: usize, grid: usize) -> Vec<Point> {
    let (lo, hi) = (band.0.min(band.1), band.0.max(band.1));
    let count = grid.max(2);
    let p = subharmonic.max(1);
    (1..=harmonics)
        .flat_map(|h| {
            (0..count).map(move |i| {
                let omega_f = lo + (hi - lo) * i as f64 / (count - 1) as f64;
                Point {
                    omega: h as f64 * omega_f / p as f64,
                    harmonic: h,
                    omega_f,
                    loaded: h == p,
                }
            })
        })
        .collect()
}

/// The reduced model on a subset of the basis in its modal form: the
/// eigenpairs `(θ_j, y_j)` of `VᵀKV`, the modal damping when `VᵀCV` is
/// diagonal in them (else the dense modal damping matrix), `V_S Y` and
/// `Yᵀ Vᵀ F`.
pub struct Modal {
    theta: Vec<f64>,
    damping: Damping,
    /// `V_S Y` (`s×r`).
    at_dofs: Mat<f64>,
    /// `Yᵀ Vᵀ F` (`r`), complex `F_cos − i F_sin`.
    load: Vec<c64>,
}

enum Damping {
    Diagonal(Vec<f64>),
    Dense(Mat<f64>),
}

/// Off-diagonal modal damping below this part of the diagonal's largest
/// counts as zero (rounding of the projections): proportional damping.
const DIAGONAL: f64 = 1e-12;

impl Modal {
    /// The model on the basis vectors `subset` of `basis`; `rows` = `V_S`
    /// (`s×r`), `load` = `Vᵀ[F_cos | F_sin]` (`r×2`).
    ///
    /// # Errors
    /// [`HbError::InvalidInput`] if the eigenproblem fails.
    pub fn new(
        basis: &KrylovBasis<'_>,
        subset: &[usize],
        rows: &Mat<f64>,
        load: &Mat<f64>,
    ) -> Result<Self, HbError> {
        let r = subset.len();
        let pick = |a: &Mat<f64>| {
            Mat::<f64>::from_fn(r, r, |i, j| match (subset.get(i), subset.get(j)) {
                (Some(&p), Some(&q)) => a[(p, q)],
                _ => 0.0,
            })
        };
        let (t, c) = (pick(basis.stiffness()), pick(basis.damping()));
        let eig = t
            .self_adjoint_eigen(Side::Lower)
            .map_err(|e| HbError::InvalidInput(format!("reduced eigenproblem failed: {e:?}")))?;
        let y = eig.U().to_owned();
        let theta: Vec<f64> = eig.S().column_vector().iter().copied().collect();
        let modal_c = y.transpose() * &c * &y;
        let largest = (0..r).fold(0.0f64, |m, i| m.max(modal_c[(i, i)].abs()));
        let diagonal = (0..r).all(|i| {
            (0..r).all(|j| {
                i == j || modal_c[(i, j)].abs() <= DIAGONAL * largest.max(f64::MIN_POSITIVE)
            })
        });
        let damping = if diagonal {
            Damping::Diagonal((0..r).map(|i| modal_c[(i, i)]).collect())
        } else {
            Damping::Dense(modal_c)
        };
        let sub_rows = Mat::<f64>::from_fn(rows.nrows(), r, |a, j| {
            subset.get(j).map_or(0.0, |&q| rows[(a, q)])
        });
        let at_dofs = &sub_rows * &y;
        let sub_load =
            Mat::<f64>::from_fn(r, 2, |i, j| subset.get(i).map_or(0.0, |&p| load[(p, j)]));
        let modal_load = y.transpose() * &sub_load;
        let load = (0..r)
            .map(|j| c64::new(modal_load[(j, 0)], -modal_load[(j, 1)]))
            .collect();
        Ok(Self {
            theta,
            damping,
            at_dofs,
            load,
        })
    }

    /// The Ritz values `θ_j = ω_j²`, increasing.
    pub fn ritz_values(&self) -> &[f64] {
        &self.theta
    }

    /// `[H_SS | u_S]` at `w` (`s×(s+1)`).
    pub fn receptances(&self, w: f64) -> Mat<c64> {
        let s = self.at_dofs.nrows();
        let r = self.theta.len();
        match &self.damping {
            Damping::Diagonal(d) => {
                let inv: Vec<c64> = self
                    .theta
                    .iter()
                    .zip(d)
                    .map(|(t, c)| c64::new(1.0, 0.0) / c64::new(t - w * w, w * c))
                    .collect();
                Mat::<c64>::from_fn(s, s + 1, |a, b| {
                    (0..r)
                        .map(|j| {
                            let right = if b < s {
                                c64::new(self.at_dofs[(b, j)], 0.0)
                            } else {
                                self.load.get(j).copied().unwrap_or_default()
                            };
                            inv.get(j).copied().unwrap_or_default() * self.at_dofs[(a, j)] * right
                        })
                        .sum()
                })
            }
            Damping::Dense(c) => {
                let d = Mat::<c64>::from_fn(r, r, |i, j| {
                    let diagonal = if i == j {
                        self.theta.get(i).copied().unwrap_or(0.0) - w * w
                    } else {
                        0.0
                    };
                    c64::new(diagonal, w * c[(i, j)])
                });
                let rhs = Mat::<c64>::from_fn(r, s + 1, |j, b| {
                    if b < s {
                        c64::new(self.at_dofs[(b, j)], 0.0)
                    } else {
                        self.load.get(j).copied().unwrap_or_default()
                    }
                });
                let x = d.partial_piv_lu().solve(&rhs);
                Mat::<c64>::from_fn(s, s + 1, |a, b| {
                    (0..r).map(|j| x[(j, b)] * self.at_dofs[(a, j)]).sum()
                })
            }
        }
    }
}

/// The relative distance of `a` from the reference `b` (both `[H | u]`):
/// the receptance part, and the load column where `loaded`.
pub fn distance(a: &Mat<c64>, b: &Mat<c64>, loaded: bool) -> f64 {
    let s = b.nrows();
    let part = |cols: std::ops::Range<usize>| {
        let (mut d, mut size) = (0.0f64, 0.0f64);
        for j in cols {
            for i in 0..s {
                d = d.max((a[(i, j)] - b[(i, j)]).norm());
                size = size.max(b[(i, j)].norm());
            }
        }
        if size > 0.0 {
            d / size
        } else if d == 0.0 {
            0.0
        } else {
            f64::INFINITY
        }
    };
    let receptance = part(0..s);
    let load = if loaded && s < b.ncols() {
        part(s..s + 1)
    } else {
        0.0
    };
    let worst = receptance.max(load);
    if worst.is_nan() {
        f64::INFINITY
    } else {
        worst
    }
}

/// The exact `[H_SS | u_S]` at `w` from the whole structure (refined sparse
/// LU), its solve error, and the full solutions `D(w)⁻¹[E_S | F]` (`n×(s+1)`).
///
/// # Errors
/// [`HbError::Singular`] when `D(w)` is singular.
pub fn exact(
    structure: &Structure,
    dofs: &[usize],
    load: &[c64],
    w: f64,
) -> Result<(Mat<c64>, f64, Mat<c64>), HbError> {
    let n = structure.n_dof();
    let s = dofs.len();
    let factored = structure.factor(w)?;
    let mut u = Mat::<c64>::zeros(n, s + 1);
    for (b, &d) in dofs.iter().enumerate() {
        if d < n {
            u[(d, b)] = c64::new(1.0, 0.0);
        }
    }
    for (i, f) in load.iter().enumerate().take(n) {
        u[(i, s)] = *f;
    }
    let error = structure.solve_refined(&factored, u.as_mut());
    if !error.is_finite() {
        return Err(HbError::Singular { omega: w });
    }
    let at_s = Mat::<c64>::from_fn(s, s + 1, |a, b| {
        dofs.get(a)
            .filter(|&&d| d < n)
            .map_or(c64::new(0.0, 0.0), |&d| u[(d, b)])
    });
    Ok((at_s, error, u))
}
