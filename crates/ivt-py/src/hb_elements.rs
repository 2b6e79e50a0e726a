//! `ivt.hb.elements`: ivt-hb's library of nonlinear elements ([`Law`]) from
//! Python. Each constructor returns an [`Elements`] holding one element; `+`
//! composes them, and the sum is passed as `g` to `solve`, `frc`,
//! `limit_cycle` or `backbone`: the forces are evaluated in Rust, with no
//! Python call in the loop.

use ivt_hb::{element_dofs, restrict_elements, Element, Law};
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;

use crate::args::{count, int64};

/// A sum of nonlinear elements, usable as `g`: each acts on the relative
/// displacement δ = x[dof] − x[to] and velocity δ̇ (x[to] = 0 for the ground,
/// `to=None`), adding its force F(δ, δ̇) to g[dof] and −F to g[to].
#[pyclass(module = "ivt.hb.elements", frozen)]
pub(crate) struct Elements {
    list: Vec<Element>,
}

impl Elements {
    /// The elements in the order they were added.
    pub(crate) fn list(&self) -> &[Element] {
        &self.list
    }
}

#[pymethods]
impl Elements {
    /// The composition of both element lists.
    fn __add__(&self, other: &Bound<'_, Elements>) -> Elements {
        let mut list = self.list.clone();
        list.extend_from_slice(other.get().list());
        Elements { list }
    }

    fn __len__(&self) -> usize {
        self.list.len()
    }

    /// The model DOFs the elements act on (each `dof` and `to`), sorted and
    /// without repeats: the nonlinear DOFs a large model is condensed onto
    /// ([`ivt_hb::element_dofs`]).
    #[getter]
    fn dofs(&self) -> Vec<usize> {
        element_dofs(&self.list)
    }

    /// The same elements on the sub-vector `x[dofs]` of the model's DOFs:
    /// each DOF replaced by its position in `dofs` (how the condensed path
    /// sees them, [`ivt_hb::restrict_elements`]). ValueError naming the
    /// element whose DOF `dofs` lacks.
    fn restricted(&self, dofs: Vec<usize>) -> PyResult<Elements> {
        restrict_elements(&self.list, &dofs)
            .map(|list| Elements { list })
            .map_err(|(i, d)| {
                let text = self.list.get(i).map(call_text).unwrap_or_default();
                PyValueError::new_err(format!(
                    "element {i} ({text}) acts on model DOF {d}, which is not among the nonlinear DOFs {dofs:?}"
                ))
            })
    }

    fn __repr__(&self) -> String {
        let parts: Vec<String> = self.list.iter().map(call_text).collect();
        format!("Elements([{}])", parts.join(", "))
    }

    /// The elements as constructor calls, `[(name, params, dof, to), ...]`
    /// (`ivt.hb` pickles an `Elements` as these calls; the floats round-trip
    /// exactly).
    #[allow(clippy::type_complexity)]
    fn _state(&self) -> Vec<(&'static str, Vec<f64>, usize, Option<usize>)> {
        self.list
            .iter()
            .map(|e| {
                let (name, params) = law_call(&e.law);
                (name, params.iter().map(|p| p.1).collect(), e.a, e.b)
            })
            .collect()
    }
}

/// The element as the Python call that builds it, e.g.
/// `cubic_spring(k3=0.5, dof=0, to=None)` (not the Debug text of [`Law`]).
fn call_text(e: &Element) -> String {
    let (name, params) = law_call(&e.law);
    let params: Vec<String> = params.iter().map(|(p, v)| format!("{p}={v}")).collect();
    let to = e.b.map_or_else(|| "None".to_string(), |b| b.to_string());
    format!("{name}({}, dof={}, to={to})", params.join(", "), e.a)
}

/// The constructor of `law` and its parameters in the constructor's order.
fn law_call(law: &Law) -> (&'static str, Vec<(&'static str, f64)>) {
    match *law {
        Law::CubicSpring { k3 } => ("cubic_spring", vec![("k3", k3)]),
        Law::QuadraticDamper { c2 } => ("quadratic_damper", vec![("c2", c2)]),
        Law::CubicDamper { c3 } => ("cubic_damper", vec![("c3", c3)]),
        Law::Coulomb { force, v_reg } => ("coulomb", vec![("force", force), ("v_reg", v_reg)]),
        Law::Clearance { gap, k } => ("clearance", vec![("gap", gap), ("k", k)]),
        Law::Unilateral { gap, k } => ("unilateral", vec![("gap", gap), ("k", k)]),
        Law::Jenkins { k, slip_force } => ("jenkins", vec![("k", k), ("slip_force", slip_force)]),
    }
}

/// One element of law `law` between DOF `dof` and DOF `to` (None: ground).
/// The DOFs (< n_dof, `dof != to`) and the law's parameters (finite,
/// v_reg > 0, gap >= 0, k >= 0) are checked by ivt-hb when the system is built.
fn element(law: Law, dof: i64, to: Option<i64>) -> PyResult<Elements> {
    Ok(Elements {
        list: vec![Element {
            a: count("dof", dof)?,
            b: to.map(|b| count("to", b)).transpose()?,
            law,
        }],
    })
}

/// A `#[pyfunction]` `name(params..., dof=0, to=None)` returning the one
/// element of law `Law::$law { params }`.
macro_rules! element_fn {
    ($(#[$doc:meta])* fn $name:ident($($p:ident),+) => $law:ident) => {
        $(#[$doc])*
        #[pyfunction]
        #[pyo3(signature = ($($p,)+ dof = 0, to = None))]
        fn $name($($p: f64,)+ #[pyo3(from_py_with = int64)] dof: i64, to: Option<i64>) -> PyResult<Elements> {
            element(Law::$law { $($p),+ }, dof, to)
        }
    };
}

element_fn! {
    /// Cubic spring F = k3·δ³.
    fn cubic_spring(k3) => CubicSpring
}
element_fn! {
    /// Quadratic damper F = c2·δ̇|δ̇|.
    fn quadratic_damper(c2) => QuadraticDamper
}
element_fn! {
    /// Cubic damper F = c3·δ̇³.
    fn cubic_damper(c3) => CubicDamper
}
element_fn! {
    /// Coulomb friction regularised by tanh: F = force·tanh(δ̇/v_reg) (v_reg > 0;
    /// the sign function as v_reg → 0).
    fn coulomb(force, v_reg) => Coulomb
}
element_fn! {
    /// Clearance with penalty contact on both sides: F = k(δ − gap) for δ > gap,
    /// k(δ + gap) for δ < −gap, 0 in between (gap = half the free play).
    fn clearance(gap, k) => Clearance
}
element_fn! {
    /// One-sided penalty contact: F = k(δ − gap) for δ > gap, else 0.
    fn unilateral(gap, k) => Unilateral
}
element_fn! {
    /// Jenkins element: a spring k in series with a Coulomb slider of slip
    /// force `slip_force` (both > 0), F = k(δ − z) with the slider z moving
    /// only while |F| = slip_force. Hysteretic: the force over a period is
    /// computed from the period's history (the play operator, two passes to
    /// the periodic state); Jacobians use the local tangent (k in stick, 0 in
    /// slip), so folds and multipliers with it are approximate.
    fn jenkins(k, slip_force) => Jenkins
}

/// Register `ivt._ivt.hb.elements` under the `hb` module.
pub fn register(hb: &Bound<'_, PyModule>) -> PyResult<()> {
    let m = PyModule::new(hb.py(), "elements")?;
    add_functions!(
        &m,
        [
            cubic_spring,
            quadratic_damper,
            cubic_damper,
            coulomb,
            clearance,
            unilateral,
            jenkins
        ]
    );
    m.add_class::<Elements>()?;
    hb.add_submodule(&m)
}
