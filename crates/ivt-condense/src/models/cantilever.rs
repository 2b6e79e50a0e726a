//! The benchmark beam of issue 28: an Euler–Bernoulli cantilever, clamped at
//! x = 0, of N equal Hermite-cubic elements with consistent mass.

use super::{from_triplets, SparseModel};
use ivt_hb::HbError;

/// The cantilever and the index of its tip displacement.
#[derive(Debug, Clone)]
pub struct Cantilever {
    /// `M`, `C = alpha·M + beta·K`, `K` on the DOFs `[w1, θ1, …, wN, θN]`.
    pub model: SparseModel,
    /// Index of the tip displacement `w_N` (`2N − 2`).
    pub tip: usize,
}

/// A uniform beam's properties.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BeamProperties {
    /// Length L.
    pub length: f64,
    /// Bending stiffness EI.
    pub ei: f64,
    /// Mass per length ρA.
    pub rho_a: f64,
    /// Rayleigh damping `C = alpha·M + beta·K`: α.
    pub alpha: f64,
    /// β.
    pub beta: f64,
}

impl Default for BeamProperties {
    /// Issue 28's beam: L = EI = ρA = 1, α = 0.07, β = 2e-4.
    fn default() -> Self {
        Self {
            length: 1.0,
            ei: 1.0,
            rho_a: 1.0,
            alpha: 0.07,
            beta: 2e-4,
        }
    }
}

/// The DOFs of element `e`'s end nodes `[w_e, θ_e, w_e+1, θ_e+1]` (node e
/// owns DOFs 2e − 2 and 2e − 1; node 0 is clamped: `None`).
pub fn element_dofs(e: usize) -> [Option<usize>; 4] {
    let left = (2 * e).checked_sub(2);
    [left, left.map(|d| d + 1), Some(2 * e), Some(2 * e + 1)]
}

/// Most elements of [`cantilever`]: 2·10⁵ DOF, a few MB of triplets (a
/// count such as 10⁹ is refused before anything is allocated).
pub const MAX_ELEMENTS: usize = 100_000;

/// The cantilever of `n_elements` Hermite-cubic elements with the
/// properties `beam`, clamped at x = 0.
///
/// Element matrices (h = L/N): `K_e = EI/h³ [[12, 6h, −12, 6h], [6h, 4h², −6h, 2h²],
/// [−12, −6h, 12, −6h], [6h, 2h², −6h, 4h²]]`, `M_e = ρA h/420 [[156, 22h, 54, −13h],
/// [22h, 4h², 13h, −3h²], [54, 13h, 156, −22h], [−13h, −3h², −22h, 4h²]]`.
/// `K_e` is formed from `1/h = N/L`: with L = EI = 1 its entries are
/// integers, stored exactly for every N ≤ 2^17 (the fine mesh's
/// ill-conditioning then comes from the dynamic stiffness alone, see
/// [`crate`]).
///
/// # Errors
/// [`HbError::InvalidInput`] for no elements or more than `MAX_ELEMENTS` (100 000),
/// non-positive / non-finite parameters.
pub fn cantilever(n_elements: usize, beam: &BeamProperties) -> Result<Cantilever, HbError> {
    if n_elements > MAX_ELEMENTS {
        return Err(HbError::InvalidInput(format!(
            "cantilever: n_elements = {n_elements} exceeds the limit of {MAX_ELEMENTS} elements"
        )));
    }
    let BeamProperties {
        length,
        ei,
        rho_a,
        alpha,
        beta,
    } = *beam;
    let positive = [length, ei, rho_a]
        .iter()
        .all(|v| v.is_finite() && *v > 0.0);
    let damping = [alpha, beta].iter().all(|v| v.is_finite() && *v >= 0.0);
    if n_elements == 0 || !positive || !damping {
        return Err(HbError::InvalidInput(
            "cantilever: n_elements ≥ 1, L, EI, ρA > 0 and α, β ≥ 0 finite".into(),
        ));
    }
    let inv_h = n_elements as f64 / length;
    let h = length / n_elements as f64;
    let s = ei * inv_h * inv_h * inv_h;
    let ke = [
        [
            12.0 * s,
            6.0 * ei * inv_h * inv_h,
            -12.0 * s,
            6.0 * ei * inv_h * inv_h,
        ],
        [
            6.0 * ei * inv_h * inv_h,
            4.0 * ei * inv_h,
            -6.0 * ei * inv_h * inv_h,
            2.0 * ei * inv_h,
        ],
        [
            -12.0 * s,
            -6.0 * ei * inv_h * inv_h,
            12.0 * s,
            -6.0 * ei * inv_h * inv_h,
        ],
        [
            6.0 * ei * inv_h * inv_h,
            2.0 * ei * inv_h,
            -6.0 * ei * inv_h * inv_h,
            4.0 * ei * inv_h,
        ],
    ];
    let mm = rho_a * h / 420.0;
    let me = [
        [156.0 * mm, 22.0 * h * mm, 54.0 * mm, -13.0 * h * mm],
        [
            22.0 * h * mm,
            4.0 * h * h * mm,
            13.0 * h * mm,
            -3.0 * h * h * mm,
        ],
        [54.0 * mm, 13.0 * h * mm, 156.0 * mm, -22.0 * h * mm],
        [
            -13.0 * h * mm,
            -3.0 * h * h * mm,
            -22.0 * h * mm,
            4.0 * h * h * mm,
        ],
    ];
    let n_dof = 2 * n_elements;
    let (mut m, mut c, mut k) = (Vec::new(), Vec::new(), Vec::new());
    for e in 0..n_elements {
        let dofs = element_dofs(e);
        for (ra, (me_row, ke_row)) in dofs.iter().zip(me.iter().zip(&ke)) {
            for (cb, (&mv, &kv)) in dofs.iter().zip(me_row.iter().zip(ke_row)) {
                if let (Some(i), Some(j)) = (*ra, *cb) {
                    m.push((i, j, mv));
                    k.push((i, j, kv));
                    c.push((i, j, alpha * mv + beta * kv));
                }
            }
        }
    }
    Ok(Cantilever {
        model: SparseModel {
            m: from_triplets(n_dof, &m)?,
            c: from_triplets(n_dof, &c)?,
            k: from_triplets(n_dof, &k)?,
        },
        tip: n_dof - 2,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use faer::linalg::solvers::Solve;
    use faer::Mat;

    #[test]
    fn first_frequency_converges_to_the_euler_bernoulli_value() {
        // Clamped–free beam: ω₁ = (1.8751041)² √(EI/(ρA L⁴)) = 3.5160153.
        // Hermite cubics converge as h⁴ from above: N = 10 within 1e-6.
        let props = BeamProperties {
            alpha: 0.0,
            beta: 0.0,
            ..BeamProperties::default()
        };
        let beam = cantilever(10, &props).unwrap();
        let (m, k) = (beam.model.m.to_dense(), beam.model.k.to_dense());
        let n = m.nrows();
        // Eigenvalues of M⁻¹K (dense; real and positive).
        let a = m.partial_piv_lu().solve(&k);
        let eig = a.eigenvalues().unwrap();
        let lowest = eig.iter().map(|z| z.re).fold(f64::INFINITY, f64::min);
        let w1 = lowest.sqrt();
        let exact = 1.875_104_068_711_961_f64.powi(2);
        assert!(w1 >= exact && w1 - exact < 1e-6 * exact, "{w1} vs {exact}");
        // Static tip stiffness 3EI/L³: K⁻¹ e_tip at the tip = 1/3.
        let mut e = Mat::<f64>::zeros(n, 1);
        e[(beam.tip, 0)] = 1.0;
        let x = k.partial_piv_lu().solve(&e);
        assert!((x[(beam.tip, 0)] - 1.0 / 3.0).abs() < 1e-12);
    }
}
