//! The reduced model: the basis grown and certified ([`super::basis`],
//! [`super::certify`]), rewritten in Craig–Bampton form `[x_S; η]` (the
//! static modes scaled to unit displacement at `S`, then the rest of the
//! basis vanishing at `S`, rotated to the eigenvectors of its stiffness),
//! as a small [`Structure`] whose DOFs `0..s` are the nonlinear DOFs.

use super::basis::{KrylovBasis, Operators, Origin};
use super::certify::{distance, exact, grid, Modal, Point, Sample};
use super::{Reduction, ReductionOptions, CUTOFF, NESTED_MARGIN};
use crate::Structure;
use faer::{c64, Mat, MatRef, Side};
use ivt_hb::HbError;

/// Off-diagonal entries of the reduced matrices at most this part of the
/// geometric mean of their diagonal entries are rounding of structural
/// zeros (`ΨᵀKW = 0`, `WᵀKW` and `WᵀMW` diagonal) and dropped, so the
/// reduced structure keeps its arrow pattern.
const ZERO: f64 = 1e-13;

/// Ritz values that moved by at most this (relative) over the last block
/// count as converged modes.
const CONVERGED: f64 = 1e-8;

/// A structure reduced onto its nonlinear DOFs and a certified basis.
#[derive(Debug, Clone)]
pub struct ReducedModel {
    structure: Structure,
    /// The nested model (the basis without its last Krylov block) in the
    /// same coordinates: the multipliers' truncation estimate.
    coarse: Structure,
    load_cos: Vec<f64>,
    load_sin: Vec<f64>,
    dofs: Vec<usize>,
    /// `V G`, the reduced coordinates' shapes (`n × r`).
    shapes: Mat<f64>,
    report: Reduction,
}

impl ReducedModel {
    /// Reduces `M`, `C`, `K` (sparse, symmetric, `K` positive definite) with
    /// the nonlinear DOFs `dofs` and the load `F_cos cos θ + F_sin sin θ`
    /// (`load_sin` may be empty) for the band and harmonics of `opts`.
    ///
    /// # Errors
    /// [`HbError::InvalidInput`] for bad sizes, DOFs or options or a `K`
    /// that is not positive definite; [`HbError::Singular`] when an exact
    /// check meets a singular dynamic stiffness.
    pub fn new(
        ops: Operators<'_>,
        dofs: &[usize],
        load_cos: &[f64],
        load_sin: &[f64],
        opts: &ReductionOptions,
    ) -> Result<Self, HbError> {
        let clock = std::time::Instant::now();
        let n = ops.k.nrows();
        let (lo, hi) = (opts.band.0.min(opts.band.1), opts.band.0.max(opts.band.1));
        let valid = lo > 0.0 && hi.is_finite() && opts.tol > 0.0 && opts.tol.is_finite();
        let mut sorted = dofs.to_vec();
        sorted.sort_unstable();
        sorted.dedup();
        if !valid || opts.harmonics == 0 || opts.subharmonic == 0 {
            return Err(HbError::InvalidInput(
                "reduction: a positive finite band and tolerance, n ≥ 1, p ≥ 1".into(),
            ));
        }
        if dofs.is_empty() || sorted.len() != dofs.len() || sorted.last().is_some_and(|&d| d >= n) {
            return Err(HbError::InvalidInput(format!(
                "nonlinear DOFs must be distinct indices below n_dof = {n}"
            )));
        }
        let sin: Vec<f64> = if load_sin.is_empty() {
            vec![0.0; n]
        } else {
            load_sin.to_vec()
        };
        if load_cos.len() != n
            || sin.len() != n
            || !load_cos.iter().chain(&sin).all(|v| v.is_finite())
        {
            return Err(HbError::InvalidInput(format!(
                "load vectors must have n_dof = {n} finite entries"
            )));
        }
        let s = dofs.len();
        let mut basis = KrylovBasis::new(ops, dofs, &[load_cos, &sin])?;
        let loads = Mat::<f64>::from_fn(n, 2, |i, j| {
            if j == 0 {
                load_cos.get(i).copied().unwrap_or(0.0)
            } else {
                sin.get(i).copied().unwrap_or(0.0)
            }
        });
        let p = opts.subharmonic as f64;
        let cutoff = CUTOFF * opts.harmonics as f64 * hi / p;
        let points = grid((lo, hi), opts.harmonics, opts.subharmonic, opts.grid);
        let mut previous: Vec<f64> = Vec::new();
        let mut modes = 0;
        let target = opts.tol / NESTED_MARGIN;
        // Grow: the Ritz values past the cut-off, then the nested change
        // within the target.
        let mut nested = loop {
            let fine = modal(&basis, None, dofs, &loads)?;
            let theta = fine.ritz_values().to_vec();
            modes = converged(&theta, &previous, cutoff * cutoff).max(modes);
            previous = theta;
            let past = previous.last().is_some_and(|&t| t > cutoff * cutoff);
            let change = if past {
                nested_change(&basis, &fine, dofs, &loads, &points, opts)?
            } else {
                (f64::INFINITY, Vec::new())
            };
            if (past && change.0 <= target) || basis.size() >= opts.max_basis {
                break change;
            }
            if basis.grow() == 0 {
                break nested_change(&basis, &fine, dofs, &loads, &points, opts)?;
            }
        };
        // The certificate: exact solves at the top of the highest harmonic
        // and where the nested change is largest.
        let structure = Structure::new(ops.m, ops.c, ops.k)?;
        let complex_load: Vec<c64> = load_cos
            .iter()
            .zip(&sin)
            .map(|(c, s)| c64::new(*c, -s))
            .collect();
        let top = Point {
            omega: opts.harmonics as f64 * hi / p,
            harmonic: opts.harmonics,
            omega_f: hi,
            loaded: opts.harmonics == opts.subharmonic,
        };
        let chosen = choose_samples(top, &nested.1, opts.samples);
        let mut checks: Vec<(Point, Mat<c64>, f64)> = Vec::with_capacity(chosen.len());
        for point in chosen {
            let (reference, solve_error, full) =
                exact(&structure, dofs, &complex_load, point.omega)?;
            let fine = modal(&basis, None, dofs, &loads)?;
            let error = distance(&fine.receptances(point.omega), &reference, point.loaded);
            if error > opts.tol {
                // The exact solutions join the basis: the projection
                // interpolates the receptances there.
                let parts = Mat::<f64>::from_fn(n, 2 * (s + 1), |i, j| {
                    let z = full[(i, j / 2)];
                    if j % 2 == 0 {
                        z.re
                    } else {
                        z.im
                    }
                });
                basis.add(parts, Origin::Sample);
            }
            checks.push((point, reference, solve_error));
        }
        let fine = modal(&basis, None, dofs, &loads)?;
        if checks.iter().any(|(p, ..)| p.omega > 0.0) {
            nested = nested_change(&basis, &fine, dofs, &loads, &points, opts)?;
        }
        let sampled: Vec<Sample> = checks
            .iter()
            .map(|(point, reference, solve_error)| Sample {
                omega: point.omega,
                harmonic: point.harmonic,
                omega_f: point.omega_f,
                error: distance(&fine.receptances(point.omega), reference, point.loaded),
                solve_error: *solve_error,
            })
            .collect();
        let worst_sample = sampled.iter().map(|x| x.error).fold(0.0f64, f64::max);
        let first = fine
            .ritz_values()
            .first()
            .copied()
            .unwrap_or(0.0)
            .max(0.0)
            .sqrt();
        let report = Reduction {
            method: "krylov_static",
            n_dof: n,
            basis: basis.size(),
            blocks: basis.krylov_blocks(),
            modes,
            cutoff,
            first_frequency: first,
            error_estimate: worst_sample.max(nested.0),
            nested_change: nested.0,
            sampled,
            seconds: 0.0,
        };
        let all: Vec<usize> = (0..basis.size()).collect();
        let (fine_form, shapes) = craig_bampton(&basis, &all, dofs, &loads)?;
        let (coarse_form, _) = craig_bampton(&basis, &basis.without_last_block(), dofs, &loads)?;
        let report = Reduction {
            seconds: clock.elapsed().as_secs_f64(),
            ..report
        };
        Ok(Self {
            structure: fine_form.structure,
            coarse: coarse_form.structure,
            load_cos: fine_form.load_cos,
            load_sin: fine_form.load_sin,
            dofs: dofs.to_vec(),
            shapes,
            report,
        })
    }

    /// The reduced structure: DOFs `0..s` are the nonlinear DOFs.
    pub fn structure(&self) -> &Structure {
        &self.structure
    }

    /// The nested reduced structure (one Krylov block fewer), same
    /// coordinates.
    pub fn coarse_structure(&self) -> &Structure {
        &self.coarse
    }

    /// The reduced load `(F_cos, F_sin)`.
    pub fn load(&self) -> (&[f64], &[f64]) {
        (&self.load_cos, &self.load_sin)
    }

    /// The nonlinear DOFs of the whole structure (reduced DOF `a` is `dofs[a]`).
    pub fn dofs(&self) -> &[usize] {
        &self.dofs
    }

    /// What the reduction did and how good it is.
    pub fn report(&self) -> &Reduction {
        &self.report
    }

    /// DOFs of the whole structure.
    pub fn n_dof(&self) -> usize {
        self.shapes.nrows()
    }

    /// The coefficients of DOF `dof` of the whole structure from those of
    /// every reduced DOF (`coeffs[i]`, one series each): `x_dof = Σ_i
    /// V'_{dof,i} z_i`.
    pub fn expand(&self, dof: usize, coeffs: &[Vec<f64>]) -> Vec<f64> {
        let len = coeffs.first().map_or(0, Vec::len);
        let mut out = vec![0.0; len];
        if dof < self.shapes.nrows() {
            for (i, z) in coeffs.iter().enumerate().take(self.shapes.ncols()) {
                let w = self.shapes[(dof, i)];
                out.iter_mut().zip(z).for_each(|(o, v)| *o += w * v);
            }
        }
        out
    }
}

/// The modal model on `subset` (all of the basis for `None`).
fn modal(
    basis: &KrylovBasis<'_>,
    subset: Option<&[usize]>,
    dofs: &[usize],
    loads: &Mat<f64>,
) -> Result<Modal, HbError> {
    let all: Vec<usize>;
    let subset = match subset {
        Some(s) => s,
        None => {
            all = (0..basis.size()).collect();
            &all
        }
    };
    Modal::new(
        basis,
        subset,
        &basis.rows(dofs),
        &basis.project(loads.as_ref()),
    )
}

/// The change of the receptances from the nested basis (one Krylov block
/// fewer) at each grid point and at each resonance of the reduced model
/// inside a harmonic band (`√θ_j = h·ω_f/p`, where the quality factor
/// amplifies any error), with the largest.
fn nested_change(
    basis: &KrylovBasis<'_>,
    fine: &Modal,
    dofs: &[usize],
    loads: &Mat<f64>,
    grid_points: &[Point],
    opts: &ReductionOptions,
) -> Result<(f64, Vec<(Point, f64)>), HbError> {
    let coarse = modal(basis, Some(&basis.without_last_block()), dofs, loads)?;
    let (lo, hi) = (opts.band.0.min(opts.band.1), opts.band.0.max(opts.band.1));
    let p = opts.subharmonic as f64;
    let resonances = fine
        .ritz_values()
        .iter()
        .filter(|t| **t > 0.0)
        .flat_map(|t| {
            let w = t.sqrt();
            (1..=opts.harmonics).filter_map(move |h| {
                let omega_f = w * p / h as f64;
                (omega_f >= lo && omega_f <= hi).then_some(Point {
                    omega: w,
                    harmonic: h,
                    omega_f,
                    loaded: h == opts.subharmonic,
                })
            })
        });
    let changes: Vec<(Point, f64)> = grid_points
        .iter()
        .copied()
        .chain(resonances)
        .map(|pt| {
            let change = distance(
                &coarse.receptances(pt.omega),
                &fine.receptances(pt.omega),
                pt.loaded,
            );
            (pt, change)
        })
        .collect();
    let worst = changes.iter().map(|(_, c)| *c).fold(0.0f64, f64::max);
    Ok((worst, changes))
}

/// Ritz values below `limit` that moved by at most [`CONVERGED`] since
/// `previous` (matched in order).
fn converged(theta: &[f64], previous: &[f64], limit: f64) -> usize {
    theta
        .iter()
        .zip(previous)
        .take_while(|(t, _)| **t <= limit)
        .filter(|(t, q)| (**t - **q).abs() <= CONVERGED * t.abs())
        .count()
}

/// The samples: `top`, then the points of largest nested change at least
/// 2 % apart from those chosen.
fn choose_samples(top: Point, changes: &[(Point, f64)], count: usize) -> Vec<Point> {
    if count == 0 {
        return Vec::new();
    }
    let mut order: Vec<&(Point, f64)> = changes.iter().collect();
    order.sort_by(|a, b| b.1.total_cmp(&a.1));
    let mut chosen = vec![top];
    for (p, _) in order {
        if chosen.len() >= count {
            break;
        }
        if chosen
            .iter()
            .all(|q| (q.omega - p.omega).abs() > 0.02 * q.omega.max(p.omega))
        {
            chosen.push(*p);
        }
    }
    chosen
}

/// The Craig–Bampton form of one basis subset.
struct Form {
    structure: Structure,
    load_cos: Vec<f64>,
    load_sin: Vec<f64>,
}

/// The subset `subset` of the basis rewritten as `[Ψ | W]`, `Ψ` the static
/// modes with `Ψ_S = I`, `W_S = 0` with `WᵀMW = I`, `WᵀKW` diagonal; the
/// reduced structure and load, and (for the whole basis) the shapes `V G`.
fn craig_bampton(
    basis: &KrylovBasis<'_>,
    subset: &[usize],
    dofs: &[usize],
    loads: &Mat<f64>,
) -> Result<(Form, Mat<f64>), HbError> {
    let r = subset.len();
    let s = dofs.len();
    let pick = |a: &Mat<f64>| {
        Mat::<f64>::from_fn(r, r, |i, j| match (subset.get(i), subset.get(j)) {
            (Some(&p), Some(&q)) => a[(p, q)],
            _ => 0.0,
        })
    };
    let pick_rows = |a: &Mat<f64>| {
        Mat::<f64>::from_fn(r, a.ncols(), |i, j| {
            subset.get(i).map_or(0.0, |&p| a[(p, j)])
        })
    };
    let (t, cv) = (pick(basis.stiffness()), pick(basis.damping()));
    let all_rows = basis.rows(dofs);
    let vs = Mat::<f64>::from_fn(s, r, |a, j| {
        subset.get(j).map_or(0.0, |&q| all_rows[(a, q)])
    });
    let g = pick_rows(&basis.static_coordinates());
    // Ψ's coordinates g (V_S g)⁻¹.
    let at_s = &vs * &g;
    let inverse = ivt_num::lu::inverse(&row_major(at_s.as_ref()), s).ok_or_else(|| {
        HbError::InvalidInput("the static modes do not reach every nonlinear DOF".into())
    })?;
    let inverse = Mat::<f64>::from_fn(s, s, |i, j| inverse.get(i * s + j).copied().unwrap_or(0.0));
    let psi = &g * &inverse;
    // The null space of V_S: the r − s eigenvectors of V_SᵀV_S of least
    // eigenvalue (its other s are of order one: V_S has full row rank).
    let gram = vs.transpose() * &vs;
    let eig = gram
        .self_adjoint_eigen(Side::Lower)
        .map_err(|e| HbError::InvalidInput(format!("reduced eigenproblem failed: {e:?}")))?;
    let order = ascending(eig.S().column_vector().iter().copied().collect());
    let u = eig.U();
    let q2 = Mat::<f64>::from_fn(r, r - s, |i, j| order.get(j).map_or(0.0, |&c| u[(i, c)]));
    let inner = q2.transpose() * &t * &q2;
    let inner = symmetric(&inner);
    let eig = inner
        .self_adjoint_eigen(Side::Lower)
        .map_err(|e| HbError::InvalidInput(format!("reduced eigenproblem failed: {e:?}")))?;
    let order = ascending(eig.S().column_vector().iter().copied().collect());
    let z = eig.U();
    let z = Mat::<f64>::from_fn(r - s, r - s, |i, j| {
        order.get(j).map_or(0.0, |&c| z[(i, c)])
    });
    let w = &q2 * &z;
    let transform =
        Mat::<f64>::from_fn(r, r, |i, j| if j < s { psi[(i, j)] } else { w[(i, j - s)] });
    let k_r = symmetric(&(transform.transpose() * &t * &transform));
    let m_r = symmetric(&(transform.transpose() * &transform));
    let c_r = symmetric(&(transform.transpose() * &cv * &transform));
    let load = transform.transpose() * pick_rows(&basis.project(loads.as_ref()));
    let triplets = |a: &Mat<f64>, exact_w: Option<f64>| -> Vec<(usize, usize, f64)> {
        let mut out = Vec::new();
        for j in 0..r {
            for i in 0..r {
                let v = a[(i, j)];
                let v = match exact_w {
                    // WᵀMW = I exactly.
                    Some(one) if i >= s && j >= s => {
                        if i == j {
                            one
                        } else {
                            0.0
                        }
                    }
                    _ => v,
                };
                let scale = (a[(i, i)] * a[(j, j)]).abs().sqrt();
                if v != 0.0 && (i == j || v.abs() > ZERO * scale) {
                    out.push((i, j, v));
                }
            }
        }
        out
    };
    let structure = Structure::from_triplets(
        r,
        &triplets(&m_r, Some(1.0)),
        &triplets(&c_r, None),
        &triplets(&k_r, None),
    )?;
    let form = Form {
        structure,
        load_cos: (0..r).map(|i| load[(i, 0)]).collect(),
        load_sin: (0..r).map(|i| load[(i, 1)]).collect(),
    };
    // V G over the whole basis: zero rows for the vectors outside the subset.
    let full_g = Mat::<f64>::from_fn(basis.size(), r, |p, j| {
        subset
            .iter()
            .position(|&q| q == p)
            .map_or(0.0, |i| transform[(i, j)])
    });
    let shapes = if r == basis.size() {
        basis.combine(full_g.as_ref())
    } else {
        Mat::zeros(0, 0)
    };
    Ok((form, shapes))
}

/// Indices of `values` in increasing order.
fn ascending(values: Vec<f64>) -> Vec<usize> {
    let mut order: Vec<usize> = (0..values.len()).collect();
    order.sort_by(|&a, &b| {
        let (x, y) = (
            values.get(a).copied().unwrap_or(0.0),
            values.get(b).copied().unwrap_or(0.0),
        );
        x.total_cmp(&y)
    });
    order
}

/// `(A + Aᵀ)/2`.
fn symmetric(a: &Mat<f64>) -> Mat<f64> {
    Mat::<f64>::from_fn(a.nrows(), a.ncols(), |i, j| 0.5 * (a[(i, j)] + a[(j, i)]))
}

/// A dense matrix as a row-major vector.
fn row_major(a: MatRef<'_, f64>) -> Vec<f64> {
    (0..a.nrows())
        .flat_map(|i| (0..a.ncols()).map(move |j| a[(i, j)]))
        .collect()
}
