//! `ivt.hb.elements`: ivt-hb's library of nonlinear elements ([`Law`]) from
//! Python. Each constructor returns an [`Elements`] holding one element; `+`
//! composes them, and the sum is passed as `g` to `solve`, `frc`,
//! `limit_cycle` or `backbone`: the forces and their exact Jacobians are then
//! evaluated in Rust, with no Python call in the loop.

use ivt_hb::{Element, Law};
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

    fn __repr__(&self) -> String {
        let parts: Vec<String> = self
            .list
            .iter()
            .map(|e| format!("{:?} on ({}, {:?})", e.law, e.a, e.b))
            .collect();
        format!("Elements([{}])", parts.join(", "))
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

/// Cubic spring F = k3·δ³.
#[pyfunction]
#[pyo3(signature = (k3, dof = 0, to = None))]
fn cubic_spring(
    k3: f64,
    #[pyo3(from_py_with = int64)] dof: i64,
    to: Option<i64>,
) -> PyResult<Elements> {
    element(Law::CubicSpring { k3 }, dof, to)
}

/// Quadratic damper F = c2·δ̇|δ̇|.
#[pyfunction]
#[pyo3(signature = (c2, dof = 0, to = None))]
fn quadratic_damper(
    c2: f64,
    #[pyo3(from_py_with = int64)] dof: i64,
    to: Option<i64>,
) -> PyResult<Elements> {
    element(Law::QuadraticDamper { c2 }, dof, to)
}

/// Cubic damper F = c3·δ̇³.
#[pyfunction]
#[pyo3(signature = (c3, dof = 0, to = None))]
fn cubic_damper(
    c3: f64,
    #[pyo3(from_py_with = int64)] dof: i64,
    to: Option<i64>,
) -> PyResult<Elements> {
    element(Law::CubicDamper { c3 }, dof, to)
}

/// Coulomb friction regularised by tanh: F = force·tanh(δ̇/v_reg) (v_reg > 0;
/// the sign function as v_reg → 0).
#[pyfunction]
#[pyo3(signature = (force, v_reg, dof = 0, to = None))]
fn coulomb(
    force: f64,
    v_reg: f64,
    #[pyo3(from_py_with = int64)] dof: i64,
    to: Option<i64>,
) -> PyResult<Elements> {
    element(Law::Coulomb { force, v_reg }, dof, to)
}

/// Clearance with penalty contact on both sides: F = k(δ − gap) for δ > gap,
/// k(δ + gap) for δ < −gap, 0 in between (gap = half the free play).
#[pyfunction]
#[pyo3(signature = (gap, k, dof = 0, to = None))]
fn clearance(
    gap: f64,
    k: f64,
    #[pyo3(from_py_with = int64)] dof: i64,
    to: Option<i64>,
) -> PyResult<Elements> {
    element(Law::Clearance { gap, k }, dof, to)
}

/// One-sided penalty contact: F = k(δ − gap) for δ > gap, else 0.
#[pyfunction]
#[pyo3(signature = (gap, k, dof = 0, to = None))]
fn unilateral(
    gap: f64,
    k: f64,
    #[pyo3(from_py_with = int64)] dof: i64,
    to: Option<i64>,
) -> PyResult<Elements> {
    element(Law::Unilateral { gap, k }, dof, to)
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
            unilateral
        ]
    );
    m.add_class::<Elements>()?;
    hb.add_submodule(&m)
}
