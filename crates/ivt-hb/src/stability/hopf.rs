//! Hopf points of the equilibria of an autonomous family (issue 27, item 2):
//! `M ẍ + C ẋ + K x + g(x, ẋ) = 0` at parameter p ([`crate::cycle_branch()`]
//! starts the limit cycles born there).
//!
//! An equilibrium solves `K x + g(x, 0) = 0` (Newton, [`ivt_num::newton()`]);
//! its linearisation in `y = (x, ẋ)` is
//!
//! `A = [[0, I], [−M⁻¹(K + ∂g/∂x), −M⁻¹(C + ∂g/∂v)]]`.
//!
//! The equilibria are followed over a grid of p; a Hopf point is where two
//! complex eigenvalues of `A` cross the imaginary axis (the count of complex
//! eigenvalues with positive real part changes by two), located by
//! bisection on that count to the rounding of p. Its first Lyapunov
//! coefficient (Kuznetsov, *Elements of Applied Bifurcation Theory*, Eq. 3.20)
//!
//! `l₁ = Re[⟨p, C(q,q,q̄)⟩ − 2⟨p, B(q, A⁻¹B(q,q̄))⟩ + ⟨p, B(q̄, (2iω − A)⁻¹B(q,q))⟩] / (2ω)`,
//!
//! with `A q = iω q`, `Aᵀ p = −iω p`, `⟨q, q⟩ = ⟨p, q⟩ = 1`, and `B`, `C` the
//! second and third derivatives of the vector field at the equilibrium (by
//! central differences of the field, polarised): `l₁ > 0` subcritical (an
//! unstable cycle on the side where the equilibrium is stable), `l₁ < 0`
//! supercritical.

use crate::error::HbError;
use crate::problem::PeriodicProblem;
use crate::stability::floquet::eigenvalues;
use ivt_num::{LuWorkspace, NewtonOptions, NewtonSystem, NewtonWorkspace};

mod search;
pub use search::{hopf_points, HopfSearch, Undecided, MAX_SAMPLES};

/// A Hopf point of the equilibria.
#[derive(Debug, Clone, PartialEq)]
pub struct HopfPoint {
    /// The parameter.
    pub p: f64,
    /// The frequency ω of the crossing eigenvalues ±iω.
    pub omega: f64,
    /// The first Lyapunov coefficient (> 0: subcritical, < 0: supercritical).
    pub lyapunov: f64,
    /// The equilibrium `x` (`n_dof`).
    pub equilibrium: Vec<f64>,
    /// `Re q`, `Im q` of the eigenvector `A q = iω q` in `y = (x, ẋ)`
    /// (`2·n_dof` each), `⟨q, q⟩ = 1`, turned so that `q` of DOF 0 is real.
    pub eigenvector: [Vec<f64>; 2],
}

impl HopfPoint {
    /// Whether the cycles born here are unstable (`l₁ > 0`).
    pub fn subcritical(&self) -> bool {
        self.lyapunov > 0.0
    }
}

/// The equilibrium of `problem` near `x` (overwritten).
///
/// # Errors
/// [`HbError::InvalidInput`] when Newton does not converge or `x` does not
/// hold `n_dof` entries, [`HbError::Size`] unless `K` is `n_dof×n_dof`.
pub fn equilibrium<P: PeriodicProblem>(problem: &P, x: &mut [f64]) -> Result<(), HbError> {
    let n = problem.n_dof();
    if x.len() != n {
        return Err(HbError::InvalidInput(format!(
            "the equilibrium has {n} entries"
        )));
    }
    let k = problem.stiffness().len();
    if k != n * n {
        return Err(HbError::Size {
            what: "K",
            expected: n * n,
            got: k,
        });
    }
    let opts = NewtonOptions {
        ftol: 1e-13,
        ..NewtonOptions::default()
    };
    ivt_num::newton(
        &mut Statics(problem),
        x,
        &mut NewtonWorkspace::new(n),
        &opts,
    )
    .map(|_| ())
    .map_err(|e| HbError::InvalidInput(format!("no equilibrium: {e}")))
}

/// `K x + g(x, 0)` and its Jacobian.
struct Statics<'a, P>(&'a P);

impl<P: PeriodicProblem> NewtonSystem for Statics<'_, P> {
    type Error = std::convert::Infallible;
    fn residual(&mut self, x: &[f64], r: &mut [f64]) -> Result<(), Self::Error> {
        let n = x.len();
        let zero = vec![0.0; n];
        self.0.nonlinear_samples(x, &zero, &[0.0], r);
        // `K` is `n×n` (checked by `Field::new` and the solvers' validation).
        for (ri, k_row) in r.iter_mut().zip(self.0.stiffness().chunks_exact(n.max(1))) {
            *ri += dot(k_row, x);
        }
        Ok(())
    }
    fn jacobian(&mut self, x: &[f64], jac: &mut [f64]) -> Result<(), Self::Error> {
        let n = x.len();
        let mut dg = vec![0.0; 2 * n * n];
        self.0
            .nonlinear_jacobian_samples(x, &vec![0.0; n], &[0.0], &mut dg);
        for ((j, d), k) in jac.iter_mut().zip(&dg).zip(self.0.stiffness()) {
            *j = k + d;
        }
        Ok(())
    }
}

/// The vector field `F(y)` of `problem` in `y = (x, ẋ)` and its linearisation.
pub(crate) struct Field<'a, P> {
    problem: &'a P,
    minv: Vec<f64>,
    n: usize,
}

impl<'a, P: PeriodicProblem> Field<'a, P> {
    pub(crate) fn new(problem: &'a P) -> Result<Self, HbError> {
        let n = problem.n_dof();
        if n == 0 {
            return Err(HbError::InvalidInput("n_dof must be positive".into()));
        }
        for (what, matrix) in [
            ("M", problem.mass()),
            ("C", problem.damping()),
            ("K", problem.stiffness()),
        ] {
            if matrix.len() != n * n {
                return Err(HbError::Size {
                    what,
                    expected: n * n,
                    got: matrix.len(),
                });
            }
        }
        let minv = ivt_num::lu::inverse(problem.mass(), n)
            .ok_or_else(|| HbError::InvalidInput("the mass matrix is singular".into()))?;
        Ok(Self { problem, minv, n })
    }

    /// `F(y) = [ẋ; −M⁻¹(C ẋ + K x + g(x, ẋ))]` (`y` holds `2n` entries; NaN
    /// if it does not).
    fn eval(&self, y: &[f64]) -> Vec<f64> {
        let n = self.n;
        let (Some(x), Some(v)) = (y.get(..n), y.get(n..)) else {
            return vec![f64::NAN; 2 * n];
        };
        if v.len() != n {
            return vec![f64::NAN; 2 * n];
        }
        let mut force = vec![0.0; n];
        self.problem.nonlinear_samples(x, v, &[0.0], &mut force);
        let (c, k) = (self.problem.damping(), self.problem.stiffness());
        // `n ≥ 1` and `C`, `K` are `n×n` (`Field::new`).
        let rows = c.chunks_exact(n).zip(k.chunks_exact(n));
        for (f, (c_row, k_row)) in force.iter_mut().zip(rows) {
            *f += dot(c_row, v) + dot(k_row, x);
        }
        let mut out = v.to_vec();
        out.extend(self.minv.chunks_exact(n).map(|row| -dot(row, &force)));
        out
    }

    /// The row-major `2n×2n` Jacobian `A` at the equilibrium `x`: the lower
    /// blocks are `−M⁻¹` times the columns of `K + ∂g/∂x` and `C + ∂g/∂v`.
    pub(crate) fn linearisation(&self, x: &[f64]) -> Vec<f64> {
        let n = self.n;
        let mut dg = vec![0.0; 2 * n * n];
        self.problem
            .nonlinear_jacobian_samples(x, &vec![0.0; n], &[0.0], &mut dg);
        let (dgx, dgv) = dg.split_at(n * n);
        let d = 2 * n;
        let mut a = vec![0.0; d * d];
        let mut col = vec![0.0; n];
        for (block, (linear, nonlinear)) in [
            (self.problem.stiffness(), dgx),
            (self.problem.damping(), dgv),
        ]
        .into_iter()
        .enumerate()
        {
            let sum: Vec<f64> = linear.iter().zip(nonlinear).map(|(l, g)| l + g).collect();
            for j in 0..n {
                // `n ≥ 1` (`Field::new`).
                let column: Vec<f64> = sum.iter().skip(j).step_by(n).copied().collect();
                ivt_num::vector::matvec(&self.minv, n, n, &column, &mut col);
                // Rows n + i, column block·n + j.
                let lower = a
                    .chunks_exact_mut(d)
                    .skip(n)
                    .map(|row| row.get_mut(block * n + j));
                for (entry, v) in lower.zip(&col) {
                    if let Some(entry) = entry {
                        *entry = -v;
                    }
                }
            }
        }
        // The identity in rows i < n, column n + i.
        for (i, row) in a.chunks_exact_mut(d).take(n).enumerate() {
            if let Some(entry) = row.get_mut(n + i) {
                *entry = 1.0;
            }
        }
        a
    }

    /// `B(u, u)` at `y0` (second central difference, step `h`).
    fn quadratic(&self, y0: &[f64], u: &[f64], h: f64) -> Vec<f64> {
        let (p, m, c) = (
            self.eval(&axpy(y0, h, u)),
            self.eval(&axpy(y0, -h, u)),
            self.eval(y0),
        );
        p.iter()
            .zip(&m)
            .zip(&c)
            .map(|((p, m), c)| (p - 2.0 * c + m) / (h * h))
            .collect()
    }

    /// `C(u, u, u)` at `y0` (third central difference, step `h`).
    fn cubic(&self, y0: &[f64], u: &[f64], h: f64) -> Vec<f64> {
        let f = |s: f64| self.eval(&axpy(y0, s * h, u));
        let (p2, p1, m1, m2) = (f(2.0), f(1.0), f(-1.0), f(-2.0));
        p2.iter()
            .zip(&p1)
            .zip(m1.iter().zip(&m2))
            .map(|((p2, p1), (m1, m2))| (p2 - 2.0 * p1 + 2.0 * m1 - m2) / (2.0 * h * h * h))
            .collect()
    }
}

/// `y + s u`.
fn axpy(y: &[f64], s: f64, u: &[f64]) -> Vec<f64> {
    y.iter().zip(u).map(|(a, b)| a + s * b).collect()
}

/// The number of eigenvalues of `a` (`dim×dim`) with positive real part,
/// real or complex: it changes by two where a complex pair crosses the
/// imaginary axis (a Hopf point), by one where a real eigenvalue crosses
/// zero, and not where a pair in the right half-plane turns real.
pub(crate) fn unstable(a: &[f64], dim: usize) -> usize {
    eigenvalues(a, dim).iter().filter(|l| l.re > 0.0).count()
}

/// The first Lyapunov coefficient and eigenvector at a Hopf point with
/// frequency `omega` of the equilibrium `x` of `field` (module docs).
pub(crate) fn lyapunov(
    field: &Field<'_, impl PeriodicProblem>,
    x: &[f64],
    omega: f64,
) -> Result<(f64, [Vec<f64>; 2]), HbError> {
    let d = 2 * field.n;
    let a = field.linearisation(x);
    // Aᵀ: entry k = (i, j) = (k / d, k % d) is A's (j, i) (`d ≥ 2`).
    let at: Vec<f64> = (0..d * d)
        .map(|k| a.get((k % d) * d + k / d).copied().unwrap_or(f64::NAN))
        .collect();
    let [qa, qb] = complex_null_vector(&a, d, omega)?;
    // ⟨q, q⟩ = 1 and q of DOF 0 real: multiply by e^{−iφ}, φ = arg q₀.
    let norm = (dot(&qa, &qa) + dot(&qb, &qb)).sqrt();
    let (Some(&qb0), Some(&qa0)) = (qb.first(), qa.first()) else {
        return Err(HbError::InvalidInput(
            "no eigenvector at the Hopf point".into(),
        ));
    };
    let phi = qb0.atan2(qa0);
    let (cs, sn) = (phi.cos() / norm, phi.sin() / norm);
    let q_re: Vec<f64> = qa.iter().zip(&qb).map(|(r, i)| cs * r + sn * i).collect();
    let q_im: Vec<f64> = qa.iter().zip(&qb).map(|(r, i)| cs * i - sn * r).collect();
    let [pa, pb] = complex_null_vector(&at, d, -omega)?;
    // p = s p₀ with ⟨p, q⟩ = s̄⟨p₀, q⟩ = 1.
    let (gr, gi) = inner(&pa, &pb, &q_re, &q_im);
    let den = gr * gr + gi * gi;
    let (sr, si) = (gr / den, gi / den); // s = conj(1/⟨p₀, q⟩) = ⟨p₀,q⟩/|⟨p₀,q⟩|²
    let p_re: Vec<f64> = pa.iter().zip(&pb).map(|(r, i)| sr * r - si * i).collect();
    let p_im: Vec<f64> = pa.iter().zip(&pb).map(|(r, i)| sr * i + si * r).collect();
    let mut y0 = x.to_vec();
    y0.extend(vec![0.0; field.n]);
    let h = 1e-3 * x.iter().fold(1.0f64, |m, v| m.max(v.abs()));
    let b = |u: &[f64]| field.quadratic(&y0, u, h);
    let c = |u: &[f64]| field.cubic(&y0, u, h);
    let (sum, diff) = (axpy(&q_re, 1.0, &q_im), axpy(&q_re, -1.0, &q_im));
    let (baa, bbb) = (b(&q_re), b(&q_im));
    // B(q, q̄) = B(a,a) + B(b,b); B(q, q) = B(a,a) − B(b,b) + 2i B(a,b),
    // B(a, b) = [B(a+b, a+b) − B(a−b, a−b)]/4.
    let b_qqbar = axpy(&baa, 1.0, &bbb);
    let bab: Vec<f64> = b(&sum)
        .iter()
        .zip(b(&diff))
        .map(|(s, d)| 0.25 * (s - d))
        .collect();
    let b_qq = [
        axpy(&baa, -1.0, &bbb),
        bab.iter().map(|v| 2.0 * v).collect(),
    ];
    // C(q, q, q̄) = C(a,a,a) + C(a,b,b) + i[C(a,a,b) + C(b,b,b)] with
    // C(a,a,b) = [c(a+b) − c(a−b) − 2c(b)]/6, C(a,b,b) = [c(a+b) + c(a−b) − 2c(a)]/6.
    let (caaa, cbbb, cs_, cd) = (c(&q_re), c(&q_im), c(&sum), c(&diff));
    let parts = || caaa.iter().zip(&cbbb).zip(cs_.iter().zip(&cd));
    let c_re: Vec<f64> = parts()
        .map(|((aaa, _), (s, d))| aaa + (s + d - 2.0 * aaa) / 6.0)
        .collect();
    let c_im: Vec<f64> = parts()
        .map(|((_, bbb), (s, d))| (s - d - 2.0 * bbb) / 6.0 + bbb)
        .collect();
    // A⁻¹ B(q, q̄) (real) and (2iω − A)⁻¹ B(q, q) (complex, as a real 2d system).
    let mut s1 = b_qqbar;
    solve(&a, d, &mut s1)?;
    // [[−A, −2ω I], [2ω I, −A]] (row-major 2d×2d).
    let big = real_form(&a, d, -1.0, -2.0 * omega);
    let [b_qq_re, b_qq_im] = &b_qq;
    let mut s2: Vec<f64> = b_qq_re.iter().chain(b_qq_im).copied().collect();
    solve(&big, 2 * d, &mut s2)?;
    // B(q, s1) = [B(q+s1) − B(q−s1)]/4 by parts (s1 real).
    let bpol = |u: &[f64], w: &[f64]| -> Vec<f64> {
        b(&axpy(u, 1.0, w))
            .iter()
            .zip(b(&axpy(u, -1.0, w)))
            .map(|(x, y)| 0.25 * (x - y))
            .collect()
    };
    let t2 = [bpol(&q_re, &s1), bpol(&q_im, &s1)];
    // B(q̄, s2) with q̄ = a − ib, s2 = u + iw: B(a,u) + B(b,w) + i[B(a,w) − B(b,u)].
    let (u, w) = s2.split_at(d);
    let (au, bw, aw, bu) = (
        bpol(&q_re, u),
        bpol(&q_im, w),
        bpol(&q_re, w),
        bpol(&q_im, u),
    );
    let t3 = [axpy(&au, 1.0, &bw), axpy(&aw, -1.0, &bu)];
    let ([t2_re, t2_im], [t3_re, t3_im]) = (&t2, &t3);
    let value = inner(&p_re, &p_im, &c_re, &c_im).0 - 2.0 * inner(&p_re, &p_im, t2_re, t2_im).0
        + inner(&p_re, &p_im, t3_re, t3_im).0;
    Ok((value / (2.0 * omega), [q_re, q_im]))
}

/// `Σ a_i b_i`.
fn dot(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(x, y)| x * y).sum()
}

/// `⟨p, z⟩ = p̄ᵀ z` of `p = pr + i pi`, `z = zr + i zi`: (re, im).
fn inner(pr: &[f64], pi: &[f64], zr: &[f64], zi: &[f64]) -> (f64, f64) {
    (dot(pr, zr) + dot(pi, zi), dot(pr, zi) - dot(pi, zr))
}

/// `b ← a⁻¹ b` (row-major `n×n`).
fn solve(a: &[f64], n: usize, b: &mut [f64]) -> Result<(), HbError> {
    let mut lu = LuWorkspace::new(n);
    if !lu.factor_row_major(a) {
        return Err(HbError::InvalidInput(
            "singular matrix in the Lyapunov coefficient".into(),
        ));
    }
    lu.solve(b);
    Ok(())
}

/// The row-major `2d×2d` real form `[[s·a, w I], [−w I, s·a]]` of the complex
/// matrix `s·a − i w I` (`a` row-major `d×d`; NaN where `a` is short).
fn real_form(a: &[f64], d: usize, s: f64, w: f64) -> Vec<f64> {
    (0..4 * d * d)
        .map(|k| {
            // `k < 4d²`, so `d ≥ 1` here.
            let (i, j) = (k / (2 * d), k % (2 * d));
            let (ii, jj) = (i % d, j % d);
            match (i < d, j < d) {
                (true, true) | (false, false) => {
                    s * a.get(ii * d + jj).copied().unwrap_or(f64::NAN)
                }
                (true, false) if ii == jj => w,
                (false, true) if ii == jj => -w,
                _ => 0.0,
            }
        })
        .collect()
}

/// A null vector `(Re, Im)` of `a − iω I` (`a` row-major `d×d`): the right
/// singular vector of the smallest singular value of the real form
/// `[[a, ω I], [−ω I, a]]`.
fn complex_null_vector(a: &[f64], d: usize, omega: f64) -> Result<[Vec<f64>; 2], HbError> {
    let form = real_form(a, d, 1.0, omega);
    let big = faer::Mat::<f64>::from_fn(2 * d, 2 * d, |i, j| {
        form.get(i * 2 * d + j).copied().unwrap_or(f64::NAN)
    });
    let svd = big
        .svd()
        .map_err(|_| HbError::InvalidInput("no eigenvector at the Hopf point".into()))?;
    let s = svd.S().column_vector();
    let k = (0..2 * d)
        .min_by(|&i, &j| s[i].total_cmp(&s[j]))
        .ok_or_else(|| HbError::InvalidInput("empty system".into()))?;
    let v = svd.V().col(k);
    Ok([
        (0..d).map(|i| v[i]).collect(),
        (0..d).map(|i| v[d + i]).collect(),
    ])
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::problem::matrix_getters;

    /// `ẍ − (μ + x² − x⁴)ẋ + x = 0` ([`crate::problem::bautin`] at ν = 1).
    fn family(mu: f64) -> Result<impl PeriodicProblem, HbError> {
        Ok(crate::problem::bautin(mu, 1.0))
    }

    #[test]
    fn subcritical_hopf_at_zero_with_the_closed_form_lyapunov_coefficient() {
        // ẍ + x = x²ẋ + …: averaging gives ṙ = r(μ/2 + r²/8), i.e. in the
        // normal form with ⟨q, q⟩ = 1 (r = √2|z|) Re c₁ = 1/4, ω = 1:
        // l₁ = 1/4 (the x⁴ẋ term is of fifth order and does not enter).
        let hopf = hopf_points(&family, &[0.0], -0.2, 0.1, 30).unwrap().points;
        assert_eq!(hopf.len(), 1);
        let h = &hopf[0];
        assert!(h.p.abs() < 1e-14, "{}", h.p);
        assert!((h.omega - 1.0).abs() < 1e-12, "{}", h.omega);
        assert!(h.subcritical());
        assert!((h.lyapunov - 0.25).abs() < 1e-5, "{}", h.lyapunov);
    }

    /// A linear oscillator whose mass "matrix" has two entries for one DOF.
    struct WrongMass {
        n: usize,
        m: Vec<f64>,
        c: Vec<f64>,
        k: Vec<f64>,
    }

    impl PeriodicProblem for WrongMass {
        matrix_getters!();
        fn nonlinear(&self, _x: &[f64], _v: &[f64], _theta: f64, out: &mut [f64]) {
            out.fill(0.0);
        }
    }

    #[test]
    fn a_mass_matrix_of_the_wrong_size_is_a_size_error() {
        let family = |_: f64| -> Result<_, HbError> {
            Ok(WrongMass {
                n: 1,
                m: vec![1.0, 0.0],
                c: vec![0.1],
                k: vec![1.0],
            })
        };
        let err = hopf_points(&family, &[0.0], -0.2, 0.1, 3).unwrap_err();
        assert_eq!(
            err,
            HbError::Size {
                what: "M",
                expected: 1,
                got: 2
            }
        );
        assert_eq!(err.kind(), "input");
        let mut problem = family(0.0).unwrap();
        problem.k.push(0.0);
        let err = equilibrium(&problem, &mut [0.0]).unwrap_err();
        assert_eq!(
            err,
            HbError::Size {
                what: "K",
                expected: 1,
                got: 2
            }
        );
    }
}
