//! A library of nonlinear elements for user models, composed without closures
//! into a [`PeriodicProblem`] with exact `∂g/∂x`, `∂g/∂ẋ`.
//!
//! Each element acts between DOF `a` and DOF `b` (or the ground, `b = None`) on
//! the relative displacement `δ = x_a − x_b` and velocity `δ̇ = v_a − v_b`; its
//! force `F(δ, δ̇)` is added to `g_a` and subtracted from `g_b`.
//!
//! The hysteretic [`Law::Jenkins`] depends on the history of δ: its force is
//! computed period by period over the AFT samples (`crate::problem::hysteresis`) by
//! [`PeriodicProblem::nonlinear_samples`] and
//! [`PeriodicProblem::nonlinear_jacobian_samples`]; a one-sample call
//! ([`PeriodicProblem::nonlinear`]) has no history and gives its virgin loading
//! curve `clamp(kδ, −F_s, F_s)`, so a time integration of an [`ElementProblem`]
//! with a Jenkins element does not model it.
//!
//! A sample slice of the wrong length (a caller's bug) gives NaN, not a panic.

use crate::problem::{matrix_getters, per_sample, PeriodicProblem};

/// The force law of one element.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Law {
    /// `k₃ δ³`.
    CubicSpring {
        /// Cubic stiffness k₃.
        k3: f64,
    },
    /// `c₂ δ̇ |δ̇|`.
    QuadraticDamper {
        /// Coefficient c₂.
        c2: f64,
    },
    /// `c₃ δ̇³`.
    CubicDamper {
        /// Coefficient c₃.
        c3: f64,
    },
    /// Coulomb friction regularised by `tanh`: `μN tanh(δ̇/v_reg)` (the sign
    /// function as `v_reg → 0`).
    Coulomb {
        /// Friction force μN.
        force: f64,
        /// Regularisation velocity (> 0).
        v_reg: f64,
    },
    /// Clearance with penalty contact on both sides: `k (δ − gap)` for
    /// `δ > gap`, `k (δ + gap)` for `δ < −gap`, zero in between.
    Clearance {
        /// Half the free play.
        gap: f64,
        /// Penalty stiffness.
        k: f64,
    },
    /// Unilateral (one-sided) spring: `k (δ − gap)` for `δ > gap`, else zero.
    Unilateral {
        /// Distance to the stop.
        gap: f64,
        /// Contact stiffness.
        k: f64,
    },
    /// Jenkins element: a spring `k` in series with a Coulomb slider of slip
    /// force `F_s`, `F = k(δ − z)` with the slider `z` moving only while
    /// `|F| = F_s` (hysteretic, see the module docs).
    Jenkins {
        /// Spring stiffness (> 0).
        k: f64,
        /// Slip force (> 0).
        slip_force: f64,
    },
}

impl Law {
    /// `(F, ∂F/∂δ, ∂F/∂δ̇)`.
    fn eval(self, d: f64, dv: f64) -> (f64, f64, f64) {
        match self {
            Law::CubicSpring { k3 } => (k3 * d * d * d, 3.0 * k3 * d * d, 0.0),
            Law::QuadraticDamper { c2 } => (c2 * dv * dv.abs(), 0.0, 2.0 * c2 * dv.abs()),
            Law::CubicDamper { c3 } => (c3 * dv * dv * dv, 0.0, 3.0 * c3 * dv * dv),
            Law::Coulomb { force, v_reg } => {
                let t = (dv / v_reg).tanh();
                (force * t, 0.0, force * (1.0 - t * t) / v_reg)
            }
            Law::Clearance { gap, k } => {
                let (push, push_x) = one_sided(d, gap, k);
                let (pull, pull_x) = one_sided(-d, gap, k);
                (push - pull, push_x + pull_x, 0.0)
            }
            Law::Unilateral { gap, k } => {
                let (f, fx) = one_sided(d, gap, k);
                (f, fx, 0.0)
            }
            Law::Jenkins { k, slip_force } => {
                // The virgin loading curve (no history at one sample).
                let f = k * d;
                if f.abs() < slip_force {
                    (f, k, 0.0)
                } else {
                    (slip_force.copysign(f), 0.0, 0.0)
                }
            }
        }
    }

    /// Whether the force depends on the history of δ ([`Law::Jenkins`]).
    fn hysteretic(self) -> bool {
        matches!(self, Law::Jenkins { .. })
    }

    /// Whether the force depends on δ̇.
    fn velocity_dependent(self) -> bool {
        matches!(
            self,
            Law::QuadraticDamper { .. } | Law::CubicDamper { .. } | Law::Coulomb { .. }
        )
    }
}

/// `(k (δ − gap), k)` beyond the gap, `(0, 0)` before it.
fn one_sided(d: f64, gap: f64, k: f64) -> (f64, f64) {
    if d > gap {
        (k * (d - gap), k)
    } else {
        (0.0, 0.0)
    }
}

/// One element: a law between DOF `a` and DOF `b` (or the ground).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Element {
    /// First DOF.
    pub a: usize,
    /// Second DOF, `None` for the ground.
    pub b: Option<usize>,
    /// Force law.
    pub law: Law,
}

/// The model DOFs `elements` act on (each `a` and `b`), sorted and without
/// repeats: the nonlinear DOFs a large model is condensed onto
/// (ivt-condense), so that an element's DOFs name model DOFs on the
/// condensed path as on a dense [`ElementProblem`].
#[must_use]
pub fn element_dofs(elements: &[Element]) -> Vec<usize> {
    let mut dofs: Vec<usize> = elements
        .iter()
        .flat_map(|e| [Some(e.a), e.b])
        .flatten()
        .collect();
    dofs.sort_unstable();
    dofs.dedup();
    dofs
}

/// `elements` on the sub-vector `x[dofs]` of the model's DOFs: each DOF
/// replaced by its position in `dofs` (how the condensed path's `g` sees
/// them).
///
/// # Errors
/// `(i, d)`: element `i` acts on model DOF `d`, which `dofs` lacks.
pub fn restrict_elements(
    elements: &[Element],
    dofs: &[usize],
) -> Result<Vec<Element>, (usize, usize)> {
    elements
        .iter()
        .enumerate()
        .map(|(i, e)| {
            let local = |d: usize| dofs.iter().position(|&x| x == d).ok_or((i, d));
            Ok(Element {
                a: local(e.a)?,
                b: e.b.map(local).transpose()?,
                law: e.law,
            })
        })
        .collect()
}

/// Harmonic forcing `amplitude·cos(θ + phase)` on one DOF.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Harmonic {
    /// DOF.
    pub dof: usize,
    /// Amplitude.
    pub amplitude: f64,
    /// Phase (rad).
    pub phase: f64,
}

/// `M ẍ + C ẋ + K x + Σ elements = Σ forcing` as a [`PeriodicProblem`].
#[derive(Debug, Clone, PartialEq)]
pub struct ElementProblem {
    n: usize,
    m: Vec<f64>,
    c: Vec<f64>,
    k: Vec<f64>,
    elements: Vec<Element>,
    forcing: Vec<Harmonic>,
}

impl ElementProblem {
    /// `[M, C, K]` row-major `n×n`, the elements and the forcing.
    ///
    /// # Errors
    /// A message naming the first bad input: matrix sizes, a DOF ≥ n, an element
    /// from a DOF to itself, non-finite or invalid parameters (`v_reg ≤ 0`, a
    /// negative gap or stiffness).
    pub fn new(
        n: usize,
        [m, c, k]: [Vec<f64>; 3],
        elements: Vec<Element>,
        forcing: Vec<Harmonic>,
    ) -> Result<Self, String> {
        if n == 0 || m.len() != n * n || c.len() != n * n || k.len() != n * n {
            return Err(format!("M, C, K must be {n}×{n} with n ≥ 1"));
        }
        if !m.iter().chain(&c).chain(&k).all(|v| v.is_finite()) {
            return Err("M, C, K must be finite".into());
        }
        for (i, e) in elements.iter().enumerate() {
            if e.a >= n || e.b.is_some_and(|b| b >= n || b == e.a) {
                return Err(format!("element {i}: DOFs must be < {n} and distinct"));
            }
            let ok = match e.law {
                Law::CubicSpring { k3 } => k3.is_finite(),
                Law::QuadraticDamper { c2 } => c2.is_finite(),
                Law::CubicDamper { c3 } => c3.is_finite(),
                Law::Coulomb { force, v_reg } => {
                    force.is_finite() && v_reg > 0.0 && v_reg.is_finite()
                }
                Law::Clearance { gap, k } | Law::Unilateral { gap, k } => {
                    gap >= 0.0 && gap.is_finite() && k >= 0.0 && k.is_finite()
                }
                Law::Jenkins { k, slip_force } => {
                    k > 0.0 && k.is_finite() && slip_force > 0.0 && slip_force.is_finite()
                }
            };
            if !ok {
                return Err(format!("element {i}: invalid parameters {:?}", e.law));
            }
        }
        for (i, h) in forcing.iter().enumerate() {
            if h.dof >= n || !(h.amplitude.is_finite() && h.phase.is_finite()) {
                return Err(format!("forcing {i}: DOF must be < {n}, values finite"));
            }
        }
        Ok(Self {
            n,
            m,
            c,
            k,
            elements,
            forcing,
        })
    }

    /// `x_a − x_b` of element `e` (NaN if `x` is short).
    fn relative(e: &Element, x: &[f64]) -> f64 {
        let at = |i: usize| x.get(i).copied().unwrap_or(f64::NAN);
        at(e.a) - e.b.map_or(0.0, at)
    }
}

/// `out[i] += v`, or all of `out` NaN if it has no entry `i` (a caller's size
/// bug: the DOFs of the elements and the forcing are `< n`, checked in
/// [`ElementProblem::new`]).
fn add_at(out: &mut [f64], i: usize, v: f64) {
    match out.get_mut(i) {
        Some(o) => *o += v,
        None => out.fill(f64::NAN),
    }
}

/// What [`ElementProblem::at_samples`] evaluates.
#[derive(Clone, Copy)]
enum Quantity {
    /// The forces `g`.
    Force,
    /// The Jacobian blocks `[∂g/∂x | ∂g/∂v]`.
    Tangent,
}

impl ElementProblem {
    /// Adds the forces of the elements for which `pick(law)` holds at one
    /// sample into `out` (zeroed first).
    fn forces(&self, x: &[f64], v: &[f64], out: &mut [f64], pick: impl Fn(Law) -> bool) {
        out.fill(0.0);
        for e in self.elements.iter().filter(|e| pick(e.law)) {
            let (f, _, _) = e.law.eval(Self::relative(e, x), Self::relative(e, v));
            add_at(out, e.a, f);
            if let Some(b) = e.b {
                add_at(out, b, -f);
            }
        }
    }

    /// Adds `∂F/∂δ = fx`, `∂F/∂δ̇ = fv` of element `e` to the blocks
    /// `[∂g/∂x | ∂g/∂v]` of one sample (`dg`, `2n²`).
    fn add_tangent(&self, e: &Element, fx: f64, fv: f64, dg: &mut [f64]) {
        let n = self.n;
        let (dg_dx, dg_dv) = dg.split_at_mut(n * n);
        // δ = x_a − x_b: ∂g_a/∂x_a = F', ∂g_a/∂x_b = −F', ∂g_b = −∂g_a.
        let mut add = |i: usize, j: usize, s: f64| {
            add_at(dg_dx, i * n + j, s * fx);
            add_at(dg_dv, i * n + j, s * fv);
        };
        add(e.a, e.a, 1.0);
        if let Some(b) = e.b {
            add(e.a, b, -1.0);
            add(b, e.a, -1.0);
            add(b, b, 1.0);
        }
    }

    /// The Jacobian blocks of the elements for which `pick(law)` holds at one
    /// sample into `dg` (zeroed first).
    fn tangents(&self, x: &[f64], v: &[f64], dg: &mut [f64], pick: impl Fn(Law) -> bool) {
        dg.fill(0.0);
        for e in self.elements.iter().filter(|e| pick(e.law)) {
            let (_, fx, fv) = e.law.eval(Self::relative(e, x), Self::relative(e, v));
            self.add_tangent(e, fx, fv, dg);
        }
    }

    /// Adds the hysteretic elements' forces (into `out`, `n` per sample) and
    /// local tangents (into `dg`, `2n²` per sample) over the periods of the
    /// sample-major `x` (periods split where θ restarts).
    fn add_hysteretic(
        &self,
        x: &[f64],
        theta: &[f64],
        mut out: Option<&mut [f64]>,
        mut dg: Option<&mut [f64]>,
    ) {
        let n = self.n;
        let ranges = crate::problem::hysteresis::period_ranges(theta);
        let mut delta = vec![0.0; theta.len()];
        let (mut force, mut tangent) = (vec![0.0; theta.len()], vec![0.0; theta.len()]);
        // n ≥ 1 (checked in `new`); x holds n values per sample.
        let x_ok = x.len() == n * theta.len();
        for e in self.elements.iter().filter(|e| e.law.hysteretic()) {
            let Law::Jenkins { k, slip_force } = e.law else {
                continue;
            };
            delta.fill(f64::NAN);
            if x_ok {
                for (d, xi) in delta.iter_mut().zip(x.chunks_exact(n)) {
                    *d = Self::relative(e, xi);
                }
            }
            for r in &ranges {
                let (Some(d), Some(f), Some(t)) = (
                    delta.get(r.clone()),
                    force.get_mut(r.clone()),
                    tangent.get_mut(r.clone()),
                ) else {
                    force.fill(f64::NAN);
                    continue;
                };
                crate::problem::hysteresis::jenkins_period(k, slip_force, d, f, t);
            }
            if let Some(out) = out.as_deref_mut() {
                for (o, f) in out.chunks_exact_mut(n).zip(&force) {
                    add_at(o, e.a, *f);
                    if let Some(b) = e.b {
                        add_at(o, b, -f);
                    }
                }
            }
            if let Some(dg) = dg.as_deref_mut() {
                let w = 2 * n * n;
                for (d, t) in dg.chunks_exact_mut(w).zip(&tangent) {
                    self.add_tangent(e, *t, 0.0, d);
                }
            }
        }
    }

    /// The forces (`n` per sample) or the Jacobian blocks (`2n²` per sample)
    /// of all elements at all samples into `out`: the memoryless laws sample
    /// by sample, the hysteretic ones over each period
    /// ([`Self::add_hysteretic`]).
    fn at_samples(&self, x: &[f64], v: &[f64], theta: &[f64], out: &mut [f64], what: Quantity) {
        let hysteresis = self.has_hysteresis();
        let memoryless = |law: Law| !(hysteresis && law.hysteretic());
        per_sample(self.n, x, v, theta, out, |x, v, _, o| match what {
            Quantity::Force => self.forces(x, v, o, memoryless),
            Quantity::Tangent => self.tangents(x, v, o, memoryless),
        });
        if hysteresis {
            match what {
                Quantity::Force => self.add_hysteretic(x, theta, Some(out), None),
                Quantity::Tangent => self.add_hysteretic(x, theta, None, Some(out)),
            }
        }
    }

    /// Whether any element is hysteretic.
    fn has_hysteresis(&self) -> bool {
        self.elements.iter().any(|e| e.law.hysteretic())
    }
}

impl PeriodicProblem for ElementProblem {
    matrix_getters!();
    fn nonlinear(&self, x: &[f64], v: &[f64], _theta: f64, out: &mut [f64]) {
        self.forces(x, v, out, |_| true);
    }
    fn nonlinear_samples(&self, x: &[f64], v: &[f64], theta: &[f64], out: &mut [f64]) {
        self.at_samples(x, v, theta, out, Quantity::Force);
    }
    fn excitation(&self, theta: f64, out: &mut [f64]) {
        out.fill(0.0);
        for h in &self.forcing {
            add_at(out, h.dof, h.amplitude * (theta + h.phase).cos());
        }
    }
    fn velocity_dependent(&self) -> bool {
        self.elements.iter().any(|e| e.law.velocity_dependent())
    }
    fn hysteretic(&self) -> bool {
        self.has_hysteresis()
    }
    fn nonlinear_jacobian(&self, x: &[f64], v: &[f64], _theta: f64, dg: &mut [f64]) {
        self.tangents(x, v, dg, |_| true);
    }
    fn nonlinear_jacobian_samples(&self, x: &[f64], v: &[f64], theta: &[f64], dg: &mut [f64]) {
        self.at_samples(x, v, theta, dg, Quantity::Tangent);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn elements_restricted_to_their_dofs_keep_their_order_and_laws() {
        let law = Law::CubicSpring { k3: 2.0 };
        let model = [
            Element { a: 7, b: None, law },
            Element {
                a: 3,
                b: Some(7),
                law,
            },
        ];
        let dofs = element_dofs(&model);
        assert_eq!(dofs, vec![3, 7]);
        let local = restrict_elements(&model, &dofs).unwrap();
        assert_eq!((local[0].a, local[0].b), (1, None));
        assert_eq!((local[1].a, local[1].b), (0, Some(1)));
        assert_eq!(local[1].law, law);
        // A DOF outside the list names the element and the model DOF.
        assert_eq!(restrict_elements(&model, &[7]), Err((1, 3)));
    }

    #[test]
    fn jacobian_matches_central_differences_for_every_law() {
        // Two DOFs, one element of each law between them and one from DOF 1 to
        // ground, at a state away from the kinks of the gap laws (between the
        // DOFs δ = 1.25 > gaps 0.2, 0.1; to ground δ = −0.35: clearance in
        // contact, unilateral spring open).
        let laws = [
            Law::CubicSpring { k3: 1.3 },
            Law::QuadraticDamper { c2: 0.7 },
            Law::CubicDamper { c3: 0.4 },
            Law::Coulomb {
                force: 0.3,
                v_reg: 0.5,
            },
            Law::Clearance { gap: 0.2, k: 50.0 },
            Law::Unilateral { gap: 0.1, k: 20.0 },
        ];
        let elements: Vec<Element> = laws
            .iter()
            .flat_map(|&law| {
                [
                    Element {
                        a: 0,
                        b: Some(1),
                        law,
                    },
                    Element { a: 1, b: None, law },
                ]
            })
            .collect();
        let eye = vec![1.0, 0.0, 0.0, 1.0];
        let p = ElementProblem::new(2, [eye.clone(), eye.clone(), eye], elements, vec![]).unwrap();
        let (x, v) = ([0.9, -0.35], [0.3, -0.4]);
        let mut dg = [0.0; 8];
        p.nonlinear_jacobian(&x, &v, 0.0, &mut dg);
        let (jx, jv) = dg.split_at(4);
        let h = 1e-6;
        let (mut gp, mut gm) = ([0.0; 2], [0.0; 2]);
        for j in 0..2 {
            for (jac, wrt_v) in [(&jx, false), (&jv, true)] {
                let (mut xp, mut vp, mut xm, mut vm) = (x, v, x, v);
                if wrt_v {
                    vp[j] += h;
                    vm[j] -= h;
                } else {
                    xp[j] += h;
                    xm[j] -= h;
                }
                p.nonlinear(&xp, &vp, 0.0, &mut gp);
                p.nonlinear(&xm, &vm, 0.0, &mut gm);
                for i in 0..2 {
                    let fd = (gp[i] - gm[i]) / (2.0 * h);
                    // Central differences of smooth pieces: error ~h² ≈ 1e-12
                    // times the third derivatives (≤ 100 here).
                    assert!(
                        (fd - jac[i * 2 + j]).abs() < 1e-7,
                        "{i},{j} v={wrt_v}: {fd} vs {}",
                        jac[i * 2 + j]
                    );
                }
            }
        }
    }

    #[test]
    fn invalid_elements_are_named() {
        let eye = vec![1.0];
        let bad = |law| {
            ElementProblem::new(
                1,
                [eye.clone(), eye.clone(), eye.clone()],
                vec![Element { a: 0, b: None, law }],
                vec![],
            )
        };
        assert!(bad(Law::Coulomb {
            force: 1.0,
            v_reg: 0.0
        })
        .unwrap_err()
        .contains("element 0"));
        assert!(bad(Law::Clearance { gap: -1.0, k: 1.0 }).is_err());
        let self_loop = Element {
            a: 0,
            b: Some(0),
            law: Law::CubicSpring { k3: 1.0 },
        };
        assert!(ElementProblem::new(
            1,
            [eye.clone(), eye.clone(), eye.clone()],
            vec![self_loop],
            vec![]
        )
        .is_err());
    }
}
