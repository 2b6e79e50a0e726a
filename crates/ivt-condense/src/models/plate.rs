//! A solid cantilever plate of linear tetrahedra (issue 42): a box
//! `L × W × H` meshed as `nx × ny × nz` hexahedra, each split into the six
//! tetrahedra around its main diagonal (Kuhn's split, the one of
//! scikit-fem's `MeshTet.init_tensor`), isotropic linear elasticity with the
//! consistent mass, clamped at x = 0. SI units throughout: the steel plate of
//! issue 42 has stiffness entries ~1e9 N/m and masses ~1e-3 kg.

use super::{from_triplets, SparseModel};
use faer::sparse::SparseColMat;
use ivt_hb::HbError;

/// The box and its material.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SolidProperties {
    /// Length (x, clamped at x = 0), width (y) and thickness (z) in m.
    pub size: [f64; 3],
    /// Young's modulus E in Pa.
    pub young: f64,
    /// Poisson's ratio ν.
    pub poisson: f64,
    /// Density ρ in kg/m³.
    pub density: f64,
}

impl Default for SolidProperties {
    /// Issue 42's steel plate: 1 × 0.2 × 0.02 m, E = 210 GPa, ν = 0.3,
    /// ρ = 7800 kg/m³.
    fn default() -> Self {
        Self {
            size: [1.0, 0.2, 0.02],
            young: 210e9,
            poisson: 0.3,
            density: 7800.0,
        }
    }
}

/// The meshed plate: `M`, `K` (`C` empty: [`Plate::with_rayleigh`] sets
/// it) on the DOFs `3·node + direction` of the free nodes (x > 0).
#[derive(Debug, Clone)]
pub struct Plate {
    /// `M`, `C`, `K`.
    pub model: SparseModel,
    /// The coordinates of each free node (DOFs `3i`, `3i + 1`, `3i + 2`:
    /// x, y, z displacements).
    pub nodes: Vec<[f64; 3]>,
    /// The vertical (z) DOF of the tip corner (L, W, H).
    pub tip: usize,
}

impl Plate {
    /// The plate with Rayleigh damping `C = alpha·M + beta·K`.
    ///
    /// # Errors
    /// [`HbError::InvalidInput`] for negative or non-finite coefficients.
    pub fn with_rayleigh(mut self, alpha: f64, beta: f64) -> Result<Self, HbError> {
        if !(alpha >= 0.0 && beta >= 0.0 && alpha.is_finite() && beta.is_finite()) {
            return Err(HbError::InvalidInput(
                "Rayleigh damping needs finite alpha, beta ≥ 0".into(),
            ));
        }
        let [m, _, k] = self.model.triplets();
        let c: Vec<(usize, usize, f64)> = m
            .iter()
            .map(|&(i, j, v)| (i, j, alpha * v))
            .chain(k.iter().map(|&(i, j, v)| (i, j, beta * v)))
            .collect();
        self.model.c = from_triplets(self.model.n_dof(), &c)?;
        Ok(self)
    }

    /// The DOF of direction `direction` (0 = x, 1 = y, 2 = z) at every free
    /// node where `pick(coordinates)` holds, in node order.
    pub fn dofs_where(&self, direction: usize, pick: impl Fn([f64; 3]) -> bool) -> Vec<usize> {
        (0..self.nodes.len())
            .filter(|&i| self.nodes.get(i).is_some_and(|&p| pick(p)))
            .map(|i| 3 * i + direction.min(2))
            .collect()
    }
}

/// The plate of `elements = [nx, ny, nz]` hexahedra (6 tetrahedra each).
///
/// # Errors
/// [`HbError::InvalidInput`] for a zero element count, non-positive sizes
/// or material constants, or ν outside (−1, ½).
pub fn plate(elements: [usize; 3], props: &SolidProperties) -> Result<Plate, HbError> {
    let SolidProperties {
        size,
        young,
        poisson,
        density,
    } = *props;
    let positive = size
        .iter()
        .chain([&young, &density])
        .all(|v| v.is_finite() && *v > 0.0);
    if elements.contains(&0) || !positive || !(poisson > -1.0 && poisson < 0.5) {
        return Err(HbError::InvalidInput(
            "plate: element counts ≥ 1, sizes, E, ρ > 0 and −1 < ν < ½".into(),
        ));
    }
    let [nx, ny, nz] = elements;
    let lambda = young * poisson / ((1.0 + poisson) * (1.0 - 2.0 * poisson));
    let mu = young / (2.0 * (1.0 + poisson));
    // Grid point (i, j, k); the free nodes are those with i ≥ 1.
    let coord = |i: usize, j: usize, k: usize| {
        [
            size[0] * i as f64 / nx as f64,
            size[1] * j as f64 / ny as f64,
            size[2] * k as f64 / nz as f64,
        ]
    };
    let node = |i: usize, j: usize, k: usize| -> Option<usize> {
        i.checked_sub(1).map(|i| (i * (ny + 1) + j) * (nz + 1) + k)
    };
    let mut nodes = Vec::with_capacity(nx * (ny + 1) * (nz + 1));
    for i in 1..=nx {
        for j in 0..=ny {
            for k in 0..=nz {
                nodes.push(coord(i, j, k));
            }
        }
    }
    // The six paths from corner (0,0,0) to (1,1,1) of a cube.
    const PATHS: [[usize; 3]; 6] = [
        [1, 2, 0],
        [1, 0, 2],
        [0, 1, 2],
        [2, 1, 0],
        [0, 2, 1],
        [2, 0, 1],
    ];
    let per_element = 6 * 144;
    let mut k_trip = Vec::with_capacity(nx * ny * nz * per_element);
    let mut m_trip = Vec::with_capacity(nx * ny * nz * per_element / 3);
    for i in 0..nx {
        for j in 0..ny {
            for k in 0..nz {
                for path in PATHS {
                    let mut corner = [i, j, k];
                    let mut tet = [(corner, None); 4];
                    tet[0] = (corner, node(i, j, k));
                    for (v, &axis) in path.iter().enumerate() {
                        if let Some(c) = corner.get_mut(axis) {
                            *c += 1;
                        }
                        let [a, b, c] = corner;
                        if let Some(slot) = tet.get_mut(v + 1) {
                            *slot = (corner, node(a, b, c));
                        }
                    }
                    let points = tet.map(|([a, b, c], _)| coord(a, b, c));
                    let dofs = tet.map(|(_, n)| n);
                    let Some((grad, volume)) = gradients(&points) else {
                        return Err(HbError::InvalidInput("plate: degenerate element".into()));
                    };
                    for (a, (da, ga)) in dofs.iter().zip(&grad).enumerate() {
                        for (b, (db, gb)) in dofs.iter().zip(&grad).enumerate() {
                            let (Some(na), Some(nb)) = (da, db) else {
                                continue;
                            };
                            let dot: f64 = ga.iter().zip(gb).map(|(x, y)| x * y).sum();
                            let mass = density * volume / 20.0 * if a == b { 2.0 } else { 1.0 };
                            for (p, gp) in ga.iter().enumerate() {
                                m_trip.push((3 * na + p, 3 * nb + p, mass));
                                for (q, gq) in gb.iter().enumerate() {
                                    // λ ∂_p φ_a ∂_q φ_b + μ ∂_q φ_a ∂_p φ_b + μ δ_pq ∇φ_a·∇φ_b.
                                    let gq_a = ga.get(q).copied().unwrap_or(0.0);
                                    let gp_b = gb.get(p).copied().unwrap_or(0.0);
                                    let diagonal = if p == q { mu * dot } else { 0.0 };
                                    let v =
                                        volume * (lambda * gp * gq + mu * gq_a * gp_b + diagonal);
                                    k_trip.push((3 * na + p, 3 * nb + q, v));
                                }
                            }
                        }
                    }
                }
            }
        }
    }
    let n = 3 * nodes.len();
    let m = from_triplets(n, &m_trip)?;
    let k = from_triplets(n, &k_trip)?;
    let c = SparseColMat::<usize, f64>::try_new_from_triplets(n, n, &[])
        .map_err(|e| HbError::InvalidInput(format!("sparse assembly failed: {e:?}")))?;
    let tip = node(nx, ny, nz).map_or(0, |t| 3 * t + 2);
    Ok(Plate {
        model: SparseModel { m, c, k },
        nodes,
        tip,
    })
}

/// The gradients of the four barycentric functions of a tetrahedron and its
/// volume; `None` for a degenerate one.
fn gradients(p: &[[f64; 3]; 4]) -> Option<([[f64; 3]; 4], f64)> {
    let [p0, p1, p2, p3] = p;
    let e = |a: &[f64; 3]| [a[0] - p0[0], a[1] - p0[1], a[2] - p0[2]];
    let (a, b, c) = (e(p1), e(p2), e(p3));
    let cross = |u: [f64; 3], v: [f64; 3]| {
        [
            u[1] * v[2] - u[2] * v[1],
            u[2] * v[0] - u[0] * v[2],
            u[0] * v[1] - u[1] * v[0],
        ]
    };
    let det: f64 = a.iter().zip(cross(b, c)).map(|(x, y)| x * y).sum();
    if det == 0.0 || !det.is_finite() {
        return None;
    }
    // Rows of the inverse Jacobian: ∇φ_1 = (b × c)/det, ∇φ_2 = (c × a)/det,
    // ∇φ_3 = (a × b)/det, ∇φ_0 = −(their sum).
    let g1 = cross(b, c).map(|v| v / det);
    let g2 = cross(c, a).map(|v| v / det);
    let g3 = cross(a, b).map(|v| v / det);
    let g0 = [
        -(g1[0] + g2[0] + g3[0]),
        -(g1[1] + g2[1] + g3[1]),
        -(g1[2] + g2[2] + g3[2]),
    ];
    Some(([g0, g1, g2, g3], det.abs() / 6.0))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Rigid motions cost no strain energy (K of the unclamped assembly
    /// annihilates them) and the mass is ρ·volume: checked on the clamped
    /// plate through a translation's reaction (K u = 0 at every DOF not
    /// touching the clamp) and the mass of one direction's DOFs.
    #[test]
    fn plate_energy_and_mass_are_consistent() {
        let props = SolidProperties::default();
        let p = plate([4, 2, 1], &props).unwrap();
        let n = p.model.n_dof();
        let k = p.model.k.to_dense();
        let m = p.model.m.to_dense();
        // A translation in y: K u vanishes at the nodes not adjacent to x = 0.
        let dx = props.size[0] / 4.0;
        for (i, node) in p.nodes.iter().enumerate() {
            if node[0] > 1.5 * dx {
                let f: f64 = (0..n / 3).map(|j| k[(3 * i + 1, 3 * j + 1)]).sum();
                assert!(f.abs() < 1e-6 * k[(3 * i + 1, 3 * i + 1)], "{f}");
            }
        }
        // The free nodes' mass in x: ρ·volume minus the clamped face's share.
        let total: f64 = (0..n / 3)
            .flat_map(|i| (0..n / 3).map(move |j| (i, j)))
            .map(|(i, j)| m[(3 * i, 3 * j)])
            .sum();
        let volume: f64 = props.size.iter().product();
        let full = props.density * volume;
        assert!(total < full && total > 0.8 * full, "{total} vs {full}");
        assert_eq!(p.tip, n - 1);
    }
}
