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
use crate::error::HbError;
use faer::{c64, Mat};

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
    /// Per harmonic: `U_h = D_h⁻¹ [e_S | F_h]` (`n×(s+1)`).
    pub responses: Vec<Mat<c64>>,
    /// Largest estimated relative error of the refined solves.
    pub solve_error: f64,
    /// The static harmonic's share of `solve_error` (reused with it).
    static_error: f64,
}

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
            responses: Vec::with_capacity(harmonics + 1),
            solve_error: 0.0,
            static_error: 0.0,
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
            out.receptance.push(part.receptance);
            out.response.push(part.response);
            out.d_receptance.push(part.d_receptance);
            out.d_response.push(part.d_response);
            out.responses.push(part.responses);
        }
        Ok(out)
    }
}

impl Receptances {
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
            responses: take(&mut self.responses)?,
            error: self.static_error,
        })
    }
}

/// One harmonic's share of [`Receptances`].
struct Harmonic {
    receptance: Mat<c64>,
    response: Mat<c64>,
    d_receptance: Mat<c64>,
    d_response: Mat<c64>,
    responses: Mat<c64>,
    error: f64,
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
    let error = structure.solve_refined(&factored, u.subcols_mut(0, solved));
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
    // ∂H_SS/∂ω_f = −Wᵀ D′ U_S, ∂u_S/∂ω_f = −Wᵀ D′ u with W = D⁻ᵀ e_S.
    let (d_receptance, d_response) = if dw == 0.0 {
        (Mat::zeros(s, s), Mat::zeros(s, 1))
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
        let mut du = Mat::<c64>::zeros(n, s + 1);
        structure.apply_derivative(w, u.as_ref(), du.as_mut());
        let mut prod = wt.transpose() * &du;
        prod.col_iter_mut()
            .for_each(|c| c.iter_mut().for_each(|z| *z *= -dw));
        (prod.subcols(0, s).to_owned(), prod.subcols(s, 1).to_owned())
    };
    Ok(Harmonic {
        receptance,
        response,
        d_receptance,
        d_response,
        responses: u,
        error,
    })
}
