//! Least-squares refit of the open-loop law (Eq. 158 form) and of the linear
//! boundary (Eq. 159 form) to IHB steady states, and the ω_a error of any law
//! of that form on the plant (open-loop θ-domain simulation, [`super::shooting`]).
//!
//! Coefficient layout matches `ivt_ctrl::OpenLoopCoeffs`: `poly[i][j]`
//! multiplies `V_m^i T_U^j` (i ≤ 2, j ≤ 4); `f_B = b0 V_m + b1 T_U + b2`,
//! `f_B > 0 → r_max` (Eq. 160), and the law is clamped to [0, r_max].

use super::shooting::{periodic_at_r, ShootingOptions};
use super::steady::{IhbOptions, IhbSolver};
use super::sweep::SweepPoint;
use super::{rad_s_to_rpm, IvtError, OperatingPoint};
use ivt_kin::plant::PlantParams;
use nalgebra::{DMatrix, DVector};

/// Which monomials V_m^i T_U^j the polynomial uses.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum PolyForm {
    /// The ten terms printed in Eq. 158.
    #[default]
    Eq158,
    /// All fifteen V_m^{0..2} T_U^{0..4} (same coefficient type, higher order).
    Full,
}

impl PolyForm {
    /// The (i, j) exponent pairs.
    pub fn terms(&self) -> Vec<(usize, usize)> {
        match self {
            Self::Eq158 => vec![
                (0, 4),
                (1, 3),
                (0, 3),
                (1, 2),
                (0, 2),
                (1, 1),
                (2, 0),
                (0, 1),
                (1, 0),
                (0, 0),
            ],
            Self::Full => (0..3).flat_map(|i| (0..5).map(move |j| (i, j))).collect(),
        }
    }
}

/// An open-loop law of the Eq. 158–160 form, in f64.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct OpenLoopLaw {
    /// `poly[i][j]` multiplies V_m^i T_U^j \[m\].
    pub poly: [[f64; 5]; 3],
    /// f_B = b0 V_m + b1 T_U + b2.
    pub boundary: [f64; 3],
    /// Saturation r_max \[m\].
    pub r_max: f64,
}

impl OpenLoopLaw {
    /// The printed law (Eq. 158, 159, r_max = 0.012 m), for comparison:
    /// the controller's [`ivt_ctrl::open_loop::THESIS`] preset, the one source.
    pub fn thesis() -> Self {
        Self::from_coeffs(&ivt_ctrl::open_loop::THESIS)
    }

    /// A law from the controller's f32 coefficient set. Each f32 is widened
    /// through its shortest round-trip decimal, so a printed coefficient
    /// (≤ 7 significant digits, e.g. 6.43e-3) becomes exactly the f64 of
    /// that decimal, not the f64 of its f32 rounding.
    pub fn from_coeffs(c: &ivt_ctrl::open_loop::OpenLoopCoeffs) -> Self {
        // An f32's Display output always parses as f64; were it not to, the
        // exact widening of the f32 is the same number to f32 precision.
        let widen = |x: f32| -> f64 { x.to_string().parse().unwrap_or(f64::from(x)) };
        Self {
            poly: c.poly.map(|row| row.map(widen)),
            boundary: c.boundary.map(widen),
            r_max: widen(c.r_max),
        }
    }

    /// r_f(V_m, T_U), Eq. 158 form (unclamped).
    pub fn r_f(&self, v: f64, t: f64) -> f64 {
        let mut s = 0.0;
        for (i, row) in self.poly.iter().enumerate() {
            for (j, c) in row.iter().enumerate() {
                s += c * v.powi(i as i32) * t.powi(j as i32);
            }
        }
        s
    }

    /// u_ol, Eq. 160, clamped to [0, r_max] (never extrapolated).
    pub fn u_ol(&self, v: f64, t: f64) -> f64 {
        let fb = self.boundary[0] * v + self.boundary[1] * t + self.boundary[2];
        if fb > 0.0 {
            self.r_max
        } else {
            self.r_f(v, t).clamp(0.0, self.r_max)
        }
    }
}

/// Result of a polynomial refit.
#[derive(Clone, Debug, PartialEq)]
pub struct PolyFit {
    /// The fitted law (with the boundary filled in by [`fit_boundary`] or the caller).
    pub poly: [[f64; 5]; 3],
    /// Points used (feasible ones).
    pub points: usize,
    /// RMS of r_f − r̄ over those points \[m\].
    pub rms_r: f64,
    /// Max |r_f − r̄| \[m\].
    pub max_r: f64,
}

/// Fit `form` to the feasible points (0 ≤ r̄ ≤ r_max) of a sweep by linear least
/// squares (SVD).
///
/// # Errors
/// [`IvtError::EmptyGrid`] when fewer feasible points than terms.
pub fn fit_polynomial(
    points: &[SweepPoint],
    r_max: f64,
    form: PolyForm,
) -> Result<PolyFit, IvtError> {
    let data: Vec<(f64, f64, f64)> = points
        .iter()
        .filter_map(|p| p.result.as_ref().ok().map(|s| (p.op.v_m, p.op.t_u, s.r)))
        .filter(|(_, _, r)| (0.0..=r_max).contains(r))
        .collect();
    let terms = form.terms();
    if data.len() < terms.len() {
        return Err(IvtError::EmptyGrid(
            "fewer feasible points than polynomial terms",
        ));
    }
    let a = DMatrix::from_row_iterator(
        data.len(),
        terms.len(),
        data.iter().flat_map(|&(v, t, _)| {
            terms
                .iter()
                .map(move |&(i, j)| v.powi(i as i32) * t.powi(j as i32))
        }),
    );
    let b = DVector::from_iterator(data.len(), data.iter().map(|d| d.2));
    let x = a
        .clone()
        .svd(true, true)
        .solve(&b, 1e-14)
        .map_err(|_| IvtError::EmptyGrid("least-squares solve failed"))?;
    let mut poly = [[0.0; 5]; 3];
    for (&(i, j), &xc) in terms.iter().zip(x.iter()) {
        // V_m^i T_U^j with i < 3, j < 5 (PolyForm::terms)
        if let Some(slot) = poly.get_mut(i).and_then(|row| row.get_mut(j)) {
            *slot = xc;
        }
    }
    let res = &a * &x - &b;
    Ok(PolyFit {
        poly,
        points: data.len(),
        rms_r: (res.norm_squared() / data.len() as f64).sqrt(),
        max_r: res.amax(),
    })
}

/// V_m where r̄(V_m, T_U) = `r_target` (secant on IHB solves; r̄ is nearly
/// linear in V_m).
///
/// # Errors
/// Solver failures or no convergence.
pub fn voltage_for_r(
    plant: &PlantParams,
    t_u: f64,
    omega0: f64,
    r_target: f64,
    opts: IhbOptions,
) -> Result<f64, IvtError> {
    let mut solver = IhbSolver::new(opts)?;
    let mut r_of = |v: f64| -> Result<f64, IvtError> {
        Ok(solver
            .solve(
                plant,
                &OperatingPoint {
                    v_m: v,
                    t_u,
                    omega0,
                },
                None,
            )?
            .r)
    };
    let (mut v0, mut v1) = (8.0, 10.0);
    let (mut f0, mut f1) = (r_of(v0)? - r_target, r_of(v1)? - r_target);
    let mut history = Vec::new();
    for _ in 0..30 {
        let v2 = v1 - f1 * (v1 - v0) / (f1 - f0);
        (v0, f0) = (v1, f1);
        v1 = v2;
        f1 = r_of(v1)? - r_target;
        history.push(f1.abs());
        if f1.abs() < 1e-12 {
            return Ok(v1);
        }
    }
    Err(IvtError::NoConvergence {
        method: "boundary voltage (secant)",
        iterations: 30,
        history,
    })
}

/// Straight line V_m = α T_U + β through the points where r̄ = `r_target`
/// at each T_U (Eq. 159 for r_target = r_max). Returns (α, β, max |V − line|).
///
/// # Errors
/// Solver failures, or fewer than two T_U values.
pub fn fit_boundary(
    plant: &PlantParams,
    t_values: &[f64],
    omega0: f64,
    r_target: f64,
    opts: IhbOptions,
) -> Result<(f64, f64, f64), IvtError> {
    if t_values.len() < 2 {
        return Err(IvtError::EmptyGrid("need at least two T_U values"));
    }
    let v: Vec<f64> = t_values
        .iter()
        .map(|&t| voltage_for_r(plant, t, omega0, r_target, opts))
        .collect::<Result<_, _>>()?;
    let n = v.len() as f64;
    let (st, sv) = (t_values.iter().sum::<f64>(), v.iter().sum::<f64>());
    let stt: f64 = t_values.iter().map(|t| t * t).sum();
    let stv: f64 = t_values.iter().zip(&v).map(|(t, v)| t * v).sum();
    let alpha = (n * stv - st * sv) / (n * stt - st * st);
    let beta = (sv - alpha * st) / n;
    let err = t_values
        .iter()
        .zip(&v)
        .map(|(t, v)| (v - alpha * t - beta).abs())
        .fold(0.0, f64::max);
    Ok((alpha, beta, err))
}

/// ω_a error of a law at grid points (open-loop periodic orbit at r = u_ol).
///
/// A point where u_ol is so large that the motion started at ω(0) = ω0 stalls
/// (Eq. 162 reaches ω = 0, [`IvtError::Stall`]) stops the IVT: it counts with
/// ω_a = 0, an error of −ω0, and in [`LawError::stalled`].
#[derive(Clone, Debug, PartialEq)]
pub struct LawError {
    /// (V_m, T_U, u_ol, ω_a − ω0 \[rpm\]) per evaluated point.
    pub points: Vec<(f64, f64, f64, f64)>,
    /// How many of those points stall (ω_a = 0).
    pub stalled: usize,
    /// Max |ω_a − ω0| \[rpm\] over points whose r̄ is feasible.
    pub max_abs_rpm: f64,
    /// RMS of ω_a − ω0 \[rpm\] over those points.
    pub rms_rpm: f64,
}

/// Simulate `law` open loop at each feasible sweep point and measure ω_a − ω0.
///
/// # Errors
/// No convergence at some point.
pub fn law_error(
    plant: &PlantParams,
    law: &OpenLoopLaw,
    points: &[SweepPoint],
) -> Result<LawError, IvtError> {
    let opts = ShootingOptions::default();
    let mut out = Vec::new();
    let mut stalled = 0;
    for p in points {
        let Ok(s) = p.result.as_ref() else { continue };
        if !(0.0..=plant.r_max).contains(&s.r) {
            continue;
        }
        let r = law.u_ol(p.op.v_m, p.op.t_u);
        let omega_a = match periodic_at_r(plant, p.op.v_m, p.op.t_u, r, p.op.omega0, &opts) {
            Ok(o) => o.omega_a(),
            Err(IvtError::Stall { .. }) => {
                stalled += 1;
                0.0
            }
            Err(e) => return Err(e),
        };
        out.push((p.op.v_m, p.op.t_u, r, rad_s_to_rpm(omega_a - p.op.omega0)));
    }
    let n = out.len().max(1) as f64;
    Ok(LawError {
        stalled,
        max_abs_rpm: out.iter().map(|p| p.3.abs()).fold(0.0, f64::max),
        rms_rpm: (out.iter().map(|p| p.3 * p.3).sum::<f64>() / n).sqrt(),
        points: out,
    })
}

/// Rust source with `pub const <name>: OpenLoopCoeffs` for `ivt-ctrl`
/// (`crates/ivt-ctrl/src/open_loop/refit.rs`), f32 literals.
pub fn emit_rust(law: &OpenLoopLaw, name: &str, header: &str) -> String {
    let mut s = String::new();
    for line in header.lines() {
        s.push_str("//! ");
        s.push_str(line);
        s.push('\n');
    }
    s.push_str("\nuse super::OpenLoopCoeffs;\n\n");
    s.push_str(
        "/// Refitted open-loop law (generated by `ivt ol fit --emit-rust`; do not edit).\n",
    );
    s.push_str(&format!(
        "pub const {name}: OpenLoopCoeffs = OpenLoopCoeffs {{\n    poly: [\n"
    ));
    for row in &law.poly {
        let cells: Vec<String> = row.iter().map(|c| format!("{:e}", *c as f32)).collect();
        s.push_str(&format!("        [{}],\n", cells.join(", ")));
    }
    s.push_str("    ],\n");
    let b: Vec<String> = law
        .boundary
        .iter()
        .map(|c| format!("{:e}", *c as f32))
        .collect();
    s.push_str(&format!("    boundary: [{}],\n", b.join(", ")));
    s.push_str(&format!("    r_max: {:e},\n", law.r_max as f32));
    s.push_str("    v_m_range: [2.0, 12.0],\n    t_u_range: [1.5, 9.0],\n};\n");
    s
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The thesis law widened from the controller's f32 preset is exactly
    /// the printed decimals of Eq. 158–159 and r_max = 0.012 m (§4.2.1).
    #[test]
    fn thesis_law_is_the_printed_decimals() {
        let law = OpenLoopLaw::thesis();
        assert_eq!(
            law.poly,
            [
                [6.43e-3, -1.17e-2, 4.6e-3, -6.65e-4, 3.2e-5],
                [8.85e-3, -3.23e-3, 4.7e-4, -2.3e-5, 0.0],
                [-2.1e-5, 0.0, 0.0, 0.0, 0.0],
            ]
        );
        assert_eq!(law.boundary, [1.0, -1.579, -0.632]);
        assert_eq!(law.r_max, 0.012);
    }
}
