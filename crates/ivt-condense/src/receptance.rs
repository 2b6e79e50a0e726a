//! The linear structure seen from its nonlinear DOFs `S` at one excitation
//! frequency, harmonic by harmonic (Krack & Gross, *Harmonic Balance for
//! Nonlinear Vibration Problems*, §3.3; NLvib `HB_residual.m` keeps the same
//! per-harmonic dynamic stiffness): with `D_h = K − (hω)²M + ihωC` and the
//! responses `U_h = D_h⁻¹ [e_S | F_h]`,
//!
//! `X_S = u_S − H_SS G`, `u = D_h⁻¹ F_h`, `H = D_h⁻¹`,
//!
//! exact for harmonic balance since the linear DOFs decouple per harmonic
//! (the receptance form of the condensed equation: its residual is a
//! displacement, bounded at resonances of `H` and at anti-resonances, where
//! the dynamic-stiffness form `H_SS⁻¹` blows up);
//! any DOF is recovered as `X_j = U_F,j − U_S,j G`. The ω-derivatives come
//! from `∂H/∂ω = −H D′ H` with transposed solves (no second factorization).

use super::dynamic::Structure;
use faer::{c64, Mat};
use ivt_hb::HbError;

/// `H_SS`, `u_S`, their ω_f-derivatives and the responses `U_h` for
/// `h = 0..=n` at one ω_f.
#[derive(Debug)]
pub struct Receptances {
    /// ω_f they belong to.
    pub omega_f: f64,
    /// Per harmonic: the receptance `H_SS` (`s×s`).
    pub receptance: Vec<Mat<c64>>,
    /// Per harmonic: the linear response `u_S` to the load (`s×1`).
    pub response: Vec<Mat<c64>>,
    /// `∂H_SS/∂ω_f`.
    pub d_receptance: Vec<Mat<c64>>,
    /// `∂u_S/∂ω_f`.
    pub d_response: Vec<Mat<c64>>,
    /// `∂²H_SS/∂ω_f²` (from one plain solve: the Taylor model's last term).
    d2_receptance: Vec<Mat<c64>>,
    /// `∂²u_S/∂ω_f²`.
    d2_response: Vec<Mat<c64>>,
    /// Per harmonic: `U_h = D_h⁻¹ [e_S | F_h]` (`n×(s+1)`); empty for a
    /// Taylor model of them at a nearby ω_f.
    pub responses: Vec<Mat<c64>>,
    /// Largest estimated relative error of the refined solves (for a Taylor
    /// model: plus the model's estimated error).
    pub solve_error: f64,
    /// The static harmonic's share of `solve_error` (reused with it).
    static_error: f64,
    /// Largest relative error of the plain LU solves (the second
    /// derivatives' error).
    plain_error: f64,
}

/// Largest estimated relative error a Taylor model ([`Receptances::taylor`])
/// may add: the refined solves' own level.
pub(crate) const MODEL_TOLERANCE: f64 = 4.0 * f64::EPSILON;

/// Where the receptances act: the nonlinear DOFs, the load vector and its
/// harmonic.
#[derive(Debug, Clone)]
pub struct Coupling {
    /// The nonlinear DOFs `S`, in the order of the local problem's DOFs.
    pub dofs: Vec<usize>,
    /// The complex load `F_cos − i F_sin` (`n_dof`) at harmonic `p`.
    pub load: Vec<c64>,
    /// Harmonic of τ the load acts at (the sub-harmonic order p).
    pub load_harmonic: usize,
}

impl Coupling {
    /// Whether the load has a non-zero entry off the nonlinear DOFs.
    fn load_outside_dofs(&self) -> bool {
        self.load
            .iter()
            .enumerate()
            .any(|(i, f)| *f != c64::new(0.0, 0.0) && !self.dofs.contains(&i))
    }
}

impl Receptances {
    /// The condensed data of `structure` at ω_f for harmonics `0..=n`
    /// (response frequency ω = ω_f/p).
    ///
    /// # Errors
    /// [`HbError::Singular`] when a `D_h` is singular.
    pub fn new(
        structure: &Structure,
        coupling: &Coupling,
        harmonics: usize,
        omega_f: f64,
    ) -> Result<Self, HbError> {
        Self::reusing(structure, coupling, harmonics, omega_f, None)
    }

    /// [`Self::new`], the static harmonic (`h = 0`, `D(0) = K`: the same at
    /// every ω_f) taken from `previous` when it has one for this load.
    ///
    /// # Errors
    /// As [`Self::new`].
    pub fn reusing(
        structure: &Structure,
        coupling: &Coupling,
        harmonics: usize,
        omega_f: f64,
        previous: Option<Self>,
    ) -> Result<Self, HbError> {
        // The static column carries the load only at a static load.
        let reusable = coupling.load_harmonic != 0;
        let mut previous = previous.filter(|_| reusable);
        let p = coupling.load_harmonic as f64;
        let mut out = Self {
            omega_f,
            receptance: Vec::with_capacity(harmonics + 1),
            response: Vec::with_capacity(harmonics + 1),
            d_receptance: Vec::with_capacity(harmonics + 1),
            d_response: Vec::with_capacity(harmonics + 1),
            d2_receptance: Vec::with_capacity(harmonics + 1),
            d2_response: Vec::with_capacity(harmonics + 1),
            responses: Vec::with_capacity(harmonics + 1),
            solve_error: 0.0,
            static_error: 0.0,
            plain_error: 0.0,
        };
        for h in 0..=harmonics {
            let w = h as f64 * omega_f / p;
            let reused = previous
                .as_mut()
                .filter(|_| h == 0)
                .and_then(Self::take_static);
            let part = match reused {
                Some(part) => part,
                None => harmonic(structure, coupling, h, w, h as f64 / p)?,
            };
            if h == 0 {
                out.static_error = part.error;
            }
            out.solve_error = out.solve_error.max(part.error);
            out.plain_error = out.plain_error.max(part.plain_error);
            out.receptance.push(part.receptance);
            out.response.push(part.response);
            out.d_receptance.push(part.d_receptance);
            out.d_response.push(part.d_response);
            out.d2_receptance.push(part.d2_receptance);
            out.d2_response.push(part.d2_response);
            out.responses.push(part.responses);
        }
        Ok(out)
    }
}

impl Receptances {
    /// The second-order Taylor model of these (exact) receptances at ω_f,
    /// `H(ω₀ + δ) ≈ H + δH′ + δ²/2 H″` (and `u_S` alike; `H′` ≈ `H′ + δH″`),
    /// or `None` when its estimated error exceeds [`MODEL_TOLERANCE`] or
    /// these are a model themselves. The corrector's last iterates move ω_f
    /// by 1e-8 or less (N = 500 beam): the model serves them without a
    /// factorization.
    ///
    /// The error estimate: near the pole `p` nearest to ω₀ the receptance is
    /// `a/(ω − p)` plus a slowly varying part, whose Taylor terms shrink by
    /// `r = |δ|/|ω₀ − p|`; both `|H′|/|H|` and `|H″|/(2|H′|)` equal
    /// `1/|ω₀ − p|` for a simple pole, and the larger, doubled, gives `r`.
    /// The remainder after the δ² term is then `r³/(1 − r)` relative, plus
    /// the δ² term times the plain solve's error (`plain_error`),
    /// added to `solve_error`. Responses `U_h` are not modelled (empty).
    pub(crate) fn taylor(&self, omega_f: f64) -> Option<Self> {
        if self.responses.is_empty() || !omega_f.is_finite() {
            return None;
        }
        let delta = omega_f - self.omega_f;
        // Largest |entry|, column by column (no allocation: this runs at
        // every corrector iterate that asks for the model).
        let size = |m: &Mat<c64>| {
            m.col_iter()
                .map(|c| c.iter().fold(0.0f64, |a, z| a.max(z.norm())))
                .fold(0.0f64, f64::max)
        };
        let mut inverse_radius = 0.0f64;
        let mut second = 0.0f64;
        let families = [
            (&self.receptance, &self.d_receptance, &self.d2_receptance),
            (&self.response, &self.d_response, &self.d2_response),
        ];
        for (value, first, curvature) in families {
            for ((v, d1), d2) in value.iter().zip(first).zip(curvature) {
                let (a, b, c) = (size(v), size(d1), size(d2));
                let ratio = |num: f64, den: f64| if num == 0.0 { 0.0 } else { num / den };
                inverse_radius = inverse_radius.max(ratio(b, a)).max(ratio(c, 2.0 * b));
                second = second.max(ratio(c, 2.0 * a));
            }
        }
        let r = 2.0 * delta.abs() * inverse_radius;
        let error = r.powi(3) / (1.0 - r) + second * delta * delta * self.plain_error;
        if !(r < 1.0 && error <= MODEL_TOLERANCE) {
            return None;
        }
        let model = |v: &[Mat<c64>], d1: &[Mat<c64>], d2: &[Mat<c64>], order: usize| {
            v.iter()
                .zip(d1)
                .zip(d2)
                .map(|((v, d1), d2)| match order {
                    0 => Mat::<c64>::from_fn(v.nrows(), v.ncols(), |i, j| {
                        v[(i, j)] + delta * d1[(i, j)] + 0.5 * delta * delta * d2[(i, j)]
                    }),
                    _ => Mat::<c64>::from_fn(v.nrows(), v.ncols(), |i, j| {
                        d1[(i, j)] + delta * d2[(i, j)]
                    }),
                })
                .collect::<Vec<_>>()
        };
        let (h, dh, d2h) = (&self.receptance, &self.d_receptance, &self.d2_receptance);
        let (u, du, d2u) = (&self.response, &self.d_response, &self.d2_response);
        Some(Self {
            omega_f,
            receptance: model(h, dh, d2h, 0),
            response: model(u, du, d2u, 0),
            d_receptance: model(h, dh, d2h, 1),
            d_response: model(u, du, d2u, 1),
            d2_receptance: d2h.clone(),
            d2_response: d2u.clone(),
            responses: Vec::new(),
            solve_error: self.solve_error + error,
            static_error: self.static_error,
            plain_error: self.plain_error,
        })
    }

    /// Largest relative change of `H_SS` over the harmonics from the
    /// rounding of the stored `M` and `C` ([`Structure::data_error`]; asked
    /// per point, not per corrector step).
    pub fn data_error(&self, structure: &Structure, coupling: &Coupling) -> f64 {
        let (s, p) = (coupling.dofs.len(), coupling.load_harmonic as f64);
        self.responses
            .iter()
            .enumerate()
            .map(|(h, u)| {
                let w = h as f64 * self.omega_f / p;
                structure.data_error(w, u.subcols(0, s), &coupling.dofs)
            })
            .fold(0.0, f64::max)
    }

    /// The static harmonic's share, moved out (`None` if there is none).
    fn take_static(&mut self) -> Option<Harmonic> {
        let take = |v: &mut Vec<Mat<c64>>| (!v.is_empty()).then(|| v.swap_remove(0));
        Some(Harmonic {
            receptance: take(&mut self.receptance)?,
            response: take(&mut self.response)?,
            d_receptance: take(&mut self.d_receptance)?,
            d_response: take(&mut self.d_response)?,
            d2_receptance: take(&mut self.d2_receptance)?,
            d2_response: take(&mut self.d2_response)?,
            responses: take(&mut self.responses)?,
            error: self.static_error,
            // D(0) = K needs no ω-derivative: no plain solve was used.
            plain_error: 0.0,
        })
    }
}

/// One harmonic's share of [`Receptances`].
struct Harmonic {
    receptance: Mat<c64>,
    response: Mat<c64>,
    d_receptance: Mat<c64>,
    d_response: Mat<c64>,
    d2_receptance: Mat<c64>,
    d2_response: Mat<c64>,
    responses: Mat<c64>,
    error: f64,
    plain_error: f64,
}

/// The condensed data of harmonic `h` at `w = hω`; `dw` = ∂w/∂ω_f.
fn harmonic(
    structure: &Structure,
    coupling: &Coupling,
    h: usize,
    w: f64,
    dw: f64,
) -> Result<Harmonic, HbError> {
    let n = structure.n_dof();
    let s = coupling.dofs.len();
    let factored = structure.factor(w)?;
    // The load column needs a solve of its own only at the load's harmonic
    // and only when the load reaches beyond `S`; otherwise it is zero or the
    // combination `U_S F_S` of the columns solved anyway (the beam and the
    // disk are loaded at their nonlinear DOF: half the solves).
    let loaded = h == coupling.load_harmonic;
    let own_load = loaded && coupling.load_outside_dofs();
    let mut u = Mat::<c64>::zeros(n, s + 1);
    for (b, &d) in coupling.dofs.iter().enumerate() {
        u[(d, b)] = c64::new(1.0, 0.0);
    }
    if own_load {
        for (i, f) in coupling.load.iter().enumerate() {
            u[(i, s)] = *f;
        }
    }
    let solved = if own_load { s + 1 } else { s };
    let refined = structure.refine(&factored, u.subcols_mut(0, solved));
    let error = refined.error;
    if !error.is_finite() {
        return Err(HbError::Singular { omega: w });
    }
    if loaded && !own_load {
        for (b, &d) in coupling.dofs.iter().enumerate() {
            let f = coupling.load.get(d).copied().unwrap_or_default();
            for i in 0..n {
                let v = u[(i, b)] * f;
                u[(i, s)] += v;
            }
        }
    }
    let at = |a: usize, b: usize| {
        coupling
            .dofs
            .get(a)
            .filter(|&&d| d < u.nrows() && b < u.ncols())
            .map_or(c64::new(0.0, 0.0), |&d| u[(d, b)])
    };
    let receptance = Mat::<c64>::from_fn(s, s, at);
    let response = Mat::<c64>::from_fn(s, 1, |a, _| at(a, s));
    // ∂H_SS/∂ω_f = −Wᵀ D′ U_S, ∂u_S/∂ω_f = −Wᵀ D′ u with W = D⁻ᵀ e_S;
    // ∂²/∂ω_f² = 2 Wᵀ (D′ Z + M U) with Z = D⁻¹ D′ U (∂²D/∂w² = −2M).
    let zero = || (Mat::zeros(s, s), Mat::zeros(s, 1));
    let ((d_receptance, d_response), (d2_receptance, d2_response)) = if dw == 0.0 {
        (zero(), zero())
    } else {
        // A symmetric D: W = D⁻¹ e_S, the columns already solved.
        let wt = if structure.is_symmetric() {
            u.subcols(0, s).to_owned()
        } else {
            let mut wt = Mat::<c64>::zeros(n, s);
            for (a, &d) in coupling.dofs.iter().enumerate() {
                wt[(d, a)] = c64::new(1.0, 0.0);
            }
            structure.solve_transpose(&factored, wt.as_mut());
            wt
        };
        // Past the load's harmonic the load column is zero, and so are its
        // products.
        let columns = if loaded { s + 1 } else { s };
        let mut du = Mat::<c64>::zeros(n, s + 1);
        structure.apply_derivative(w, u.subcols(0, columns), du.subcols_mut(0, columns));
        let mut z = du.clone();
        structure.solve_plain(&factored, z.subcols_mut(0, columns));
        let mut second = Mat::<c64>::zeros(n, s + 1);
        let (z_used, u_used) = (z.subcols(0, columns), u.subcols(0, columns));
        structure.apply_derivative(w, z_used, second.subcols_mut(0, columns));
        structure.add_mass(u_used, second.subcols_mut(0, columns));
        let split = |prod: Mat<c64>, scale: f64| {
            let scaled = Mat::<c64>::from_fn(s, s + 1, |i, j| prod[(i, j)] * scale);
            (
                scaled.subcols(0, s).to_owned(),
                scaled.subcols(s, 1).to_owned(),
            )
        };
        (
            split(wt.transpose() * &du, -dw),
            split(wt.transpose() * &second, 2.0 * dw * dw),
        )
    };
    Ok(Harmonic {
        receptance,
        response,
        d_receptance,
        d_response,
        d2_receptance,
        d2_response,
        responses: u,
        error,
        plain_error: refined.plain_error,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::models::{cantilever, BeamProperties};

    /// The N = 50 cantilever seen from its tip, loaded there.
    fn tip() -> (Structure, Coupling) {
        let beam = cantilever(50, &BeamProperties::default()).unwrap();
        let s = &beam.model;
        let structure = Structure::new(s.m.as_ref(), s.c.as_ref(), s.k.as_ref()).unwrap();
        let mut load = vec![c64::new(0.0, 0.0); s.n_dof()];
        load[beam.tip] = c64::new(0.005, 0.0);
        let dofs = vec![beam.tip];
        let coupling = Coupling {
            dofs,
            load,
            load_harmonic: 1,
        };
        (structure, coupling)
    }

    /// Largest `|a − b|` over the harmonics' matrices, relative to `max|b|`.
    fn distance(a: &[Mat<c64>], b: &[Mat<c64>]) -> f64 {
        let mut worst = (0.0f64, 0.0f64);
        for (x, y) in a.iter().zip(b) {
            for j in 0..y.ncols() {
                for i in 0..y.nrows() {
                    worst.0 = worst.0.max((x[(i, j)] - y[(i, j)]).norm());
                    worst.1 = worst.1.max(y[(i, j)].norm());
                }
            }
        }
        worst.0 / worst.1
    }

    /// Next to the first resonance (ω₁ = 3.516): the model 1e-8 away equals
    /// a fresh exact evaluation there within the errors both report; 1e-3
    /// away (r ≈ 0.06) it declines.
    #[test]
    fn the_taylor_model_equals_an_exact_evaluation_within_its_estimate() {
        let (structure, coupling) = tip();
        let w0 = 3.5;
        let base = Receptances::new(&structure, &coupling, 7, w0).unwrap();
        assert!(base.taylor(w0 + 1e-3).is_none());
        for delta in [1e-8, -3e-8] {
            let model = base.taylor(w0 + delta).unwrap();
            let exact = Receptances::new(&structure, &coupling, 7, w0 + delta).unwrap();
            let bound = model.solve_error + exact.solve_error;
            assert!(model.responses.is_empty());
            assert!(
                model.solve_error < 10.0 * f64::EPSILON,
                "{}",
                model.solve_error
            );
            for (a, b) in [
                (&model.receptance, &exact.receptance),
                (&model.response, &exact.response),
            ] {
                let d = distance(a, b);
                assert!(d <= bound, "δ = {delta:e}: {d:e} > {bound:e}");
            }
            // The derivatives to first order: δ·|H″|/|H′| ~ 1e-6 relative.
            let d = distance(&model.d_receptance, &exact.d_receptance);
            assert!(d < 1e-8, "δ = {delta:e}: derivative off by {d:e}");
            // Without the model the change is far above the bound.
            let still = distance(&base.receptance, &exact.receptance);
            assert!(still > 1e3 * bound, "{still:e}");
            assert!(model.taylor(w0).is_none(), "a model is not re-expanded");
        }
    }
}
