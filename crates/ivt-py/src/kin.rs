//! `ivt.kin`: kinematics of the SGIVT variant (§2.3) and the plant
//! coefficients of Eq. 151, vectorized over numpy arrays.

use crate::args::check_arg;
use crate::fields::{self, Field};
use crate::vectorize::{map, map1, map2};
use ivt_kin::plant::{GravityModel, PlantParams};
use ivt_kin::variant;
use pyo3::exceptions::{PyFileNotFoundError, PyTypeError, PyValueError};
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyTuple};

/// Output gear radius r_u of the printed plant (Table 1), the default of the
/// speed functions.
const R_U_PRINTED: f64 = PlantParams::printed().r_u;

/// Noncircular-gear speed ratio f(θ) = π/(2√2)·max(|sin θ|, |cos θ|), Eq. 43.
///
/// theta: angle of the driven noncircular gear [rad], float or array.
/// Returns a float for scalar input, else an array of the broadcast shape.
#[pyfunction]
fn f<'py>(py: Python<'py>, theta: &Bound<'py, PyAny>) -> PyResult<Bound<'py, PyAny>> {
    map1(py, [("theta", theta)], |[t]| variant::f(t))
}

/// df/dθ, Eq. 139 (discontinuous at θ = π/4 + kπ/2; there the value of the
/// segment that starts at the corner is returned).
///
/// theta: angle of the driven noncircular gear [rad], float or array.
#[pyfunction]
fn f_theta<'py>(py: Python<'py>, theta: &Bound<'py, PyAny>) -> PyResult<Bound<'py, PyAny>> {
    map1(py, [("theta", theta)], |[t]| variant::f_theta(t))
}

/// Exact mean of f² over a period, (π²/8)(1/2 + 1/π) ≈ 1.0095 (SPEC §5).
#[pyfunction]
fn mean_f_squared() -> f64 {
    variant::mean_f_squared()
}

/// Ring-gear speeds (ω_r1, ω_r2) of the input-control module, Eq. 44:
/// ω_ri = (2(d_S + d_P)ω ± d_S ω_c)/(d_S + 2 d_P).
///
/// omega: carrier-side input speed [rad/s]; omega_c: control speed [rad/s];
/// d_s, d_p: sun and planet diameters (only their ratio matters).
#[pyfunction]
#[pyo3(signature = (omega, omega_c, d_s = 1.0, d_p = 1.0))]
fn ring_speeds<'py>(
    omega: &Bound<'py, PyAny>,
    omega_c: &Bound<'py, PyAny>,
    d_s: f64,
    d_p: f64,
) -> PyResult<(Bound<'py, PyAny>, Bound<'py, PyAny>)> {
    if !(d_s.is_finite() && d_p.is_finite() && d_s + 2.0 * d_p != 0.0) {
        return Err(PyValueError::new_err(format!(
            "arguments `d_s` = {d_s}, `d_p` = {d_p} must be finite with d_s + 2 d_p != 0"
        )));
    }
    map2(
        omega.py(),
        [("omega", omega), ("omega_c", omega_c)],
        |[w, wc]| variant::ring_speeds(w, wc, d_s, d_p),
    )
}

/// Driver speeds (v_d1, v_d2) = (ω r sin θ, ω r cos θ) [m/s], Eq. 45–46.
#[pyfunction]
fn driver_speeds<'py>(
    py: Python<'py>,
    theta: &Bound<'py, PyAny>,
    omega: &Bound<'py, PyAny>,
    r: &Bound<'py, PyAny>,
) -> PyResult<(Bound<'py, PyAny>, Bound<'py, PyAny>)> {
    map2(
        py,
        [("theta", theta), ("omega", omega), ("r", r)],
        |[t, w, r]| variant::driver_speeds(t, w, r),
    )
}

/// Output-shaft speed ω_U = max(|v_d1|, |v_d2|)/r_u [rad/s], Eq. 47.
///
/// r_u defaults to the printed output gear radius (Table 1, 0.0222 m).
#[pyfunction]
#[pyo3(signature = (theta, omega, r, r_u = R_U_PRINTED))]
fn output_speed<'py>(
    py: Python<'py>,
    theta: &Bound<'py, PyAny>,
    omega: &Bound<'py, PyAny>,
    r: &Bound<'py, PyAny>,
    r_u: f64,
) -> PyResult<Bound<'py, PyAny>> {
    check_arg("r_u", "plant.r_u", r_u)?;
    map1(
        py,
        [("theta", theta), ("omega", omega), ("r", r)],
        |[t, w, r]| variant::output_speed(t, w, r, r_u),
    )
}

/// The constant output-to-motor speed ratio ω_U/ω_m = 2√2 r/(π r_u), Eq. 47.
#[pyfunction]
#[pyo3(signature = (r, r_u = R_U_PRINTED))]
fn output_to_motor_ratio<'py>(r: &Bound<'py, PyAny>, r_u: f64) -> PyResult<Bound<'py, PyAny>> {
    check_arg("r_u", "plant.r_u", r_u)?;
    map1(r.py(), [("r", r)], |[r]| {
        variant::output_to_motor_ratio(r, r_u)
    })
}

/// The numeric Table 1 parameters by their Rust (and Python) names.
const FIELDS: &[Field<PlantParams>] = fields::field_table![
    PlantParams; r_a, k_e, k_t, l_a, j_n1, j_n2, j_inshaft, j_carrier, j_ring, j_crk, m_r, m_dr,
    j_u, r_u, g, sun_to_planet, r_max
];

fn gravity_name(g: GravityModel) -> &'static str {
    match g {
        GravityModel::Printed => "printed",
        GravityModel::RollerMass => "roller_mass",
    }
}

/// Apply keyword overrides to `params` and validate the result.
fn apply_overrides(
    params: &mut PlantParams,
    overrides: Option<&Bound<'_, PyDict>>,
) -> PyResult<()> {
    fields::apply("plant", FIELDS, params, overrides, |p, key, value| {
        if key != "gravity" {
            return Ok(false);
        }
        let name: String = value.extract().map_err(|_| {
            PyTypeError::new_err("argument `gravity` must be 'printed' or 'roller_mass'")
        })?;
        p.gravity = match name.as_str() {
            "printed" => GravityModel::Printed,
            "roller_mass" => GravityModel::RollerMass,
            other => {
                return Err(PyValueError::new_err(format!(
                    "argument `gravity` = {other:?} must be 'printed' or 'roller_mass'"
                )))
            }
        };
        Ok(true)
    })?;
    // the keywords are the fields' names: each checked under its own key
    params
        .validate()
        .map_err(|e| PyValueError::new_err(format!("argument `{}` {}", e.name, e.refused)))
}

/// The parameters of a plant file (a `[plant]` table: preset + overrides,
/// as in scenes; what `ivt rig identify --out` writes), read by ivt-sim's
/// one parser.
///
/// # Errors
/// `FileNotFoundError` for a missing file; `ValueError` for a path that is
/// not a regular file (saying what it is: a FIFO, a device, a directory),
/// one over the size budget, or an invalid file (one line: file, line,
/// column, key). The file is opened by ivt-sim's one input opener
/// ([`ivt_sim::input`]).
pub fn plant_from_file(path: &std::path::Path) -> PyResult<PlantParams> {
    let section = ivt_sim::scene::PlantSection::from_file(path).map_err(|e| {
        if e.unreadable && !path.try_exists().unwrap_or(true) {
            PyFileNotFoundError::new_err(format!("plant file {}", e.message))
        } else {
            PyValueError::new_err(e.message)
        }
    })?;
    section
        .params()
        .map_err(|e| PyValueError::new_err(format!("{}: {e}", path.display())))
}

/// The IVT plant of Eq. 151 with the Table 1 parameters.
///
/// `Plant()` is the printed plant; keyword arguments override parameters by
/// name (SI units), e.g. `Plant(r_a=0.3, gravity="roller_mass")`. Invalid
/// values raise `ValueError` naming the parameter, unknown names `TypeError`.
#[pyclass(name = "Plant", module = "ivt.kin", frozen)]
#[derive(Clone)]
pub struct Plant {
    /// The wrapped Rust parameters.
    pub params: PlantParams,
}

/// `#[pymethods] impl Plant`: the `items` as written, then one read-only
/// property per `name;` entry returning `self.params.name()`.
macro_rules! plant_methods {
    ({ $($items:tt)* } $( $(#[$doc:meta])* $name:ident; )*) => {
        #[pymethods]
        impl Plant {
            $($items)*
            $(
                $(#[$doc])*
                #[getter]
                fn $name(&self) -> f64 {
                    self.params.$name()
                }
            )*
        }
    };
}

plant_methods! {
{
    #[new]
    #[pyo3(signature = (**overrides))]
    fn new(overrides: Option<&Bound<'_, PyDict>>) -> PyResult<Self> {
        let mut params = PlantParams::printed();
        apply_overrides(&mut params, overrides)?;
        Ok(Self { params })
    }

    /// The plant of a plant file: its `[plant]` table (preset + overrides),
    /// e.g. written by `ivt rig identify --out` (same file as `--plant-file`).
    #[staticmethod]
    fn from_file(path: std::path::PathBuf) -> PyResult<Self> {
        Ok(Self {
            params: plant_from_file(&path)?,
        })
    }

    /// A copy with some parameters changed (same keywords as the constructor).
    #[pyo3(signature = (**overrides))]
    fn replace(&self, overrides: Option<&Bound<'_, PyDict>>) -> PyResult<Self> {
        let mut params = self.params;
        apply_overrides(&mut params, overrides)?;
        Ok(Self { params })
    }

    /// All parameters as a dict (keys are the constructor keywords).
    fn params<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let d = fields::to_dict(py, FIELDS, &self.params)?;
        d.set_item("gravity", gravity_name(self.params.gravity))?;
        Ok(d)
    }

    /// Derived constants of §4.1: the keys of `ivt kin plant --json`.
    fn summary<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let p = &self.params;
        let d = PyDict::new(py);
        d.set_item("j_a", p.j_a())?;
        d.set_item("j_b", p.j_b())?;
        d.set_item("j_c", p.j_c())?;
        d.set_item("j_d", p.j_d())?;
        d.set_item("motor_damping", p.motor_damping())?;
        d.set_item("motor_gain", p.motor_gain())?;
        d.set_item("load_gain", p.load_gain())?;
        d.set_item("r_max", p.r_max)?;
        Ok(d)
    }

    /// Largest eccentricity r_max [m] (§4.2.1: 0.012).
    #[getter]
    fn r_max(&self) -> f64 {
        self.params.r_max
    }

    /// Coefficients of Eq. 151 at (θ, r) for inputs (V_m, T_U), broadcast
    /// over arrays: a dict with keys f, f_theta, j, j_theta, j_r, j_theta_r,
    /// g, f_m, f1, f2.
    fn terms<'py>(
        &self,
        theta: &Bound<'py, PyAny>,
        r: &Bound<'py, PyAny>,
        v_m: &Bound<'py, PyAny>,
        t_u: &Bound<'py, PyAny>,
    ) -> PyResult<Bound<'py, PyDict>> {
        let (py, p) = (theta.py(), self.params);
        let outs = map(
            py,
            [("theta", theta), ("r", r), ("v_m", v_m), ("t_u", t_u)],
            |[th, r, vm, tu]| {
                let t = p.terms(th, r, vm, tu);
                Ok::<_, std::convert::Infallible>([
                    t.f,
                    t.f_theta,
                    t.j,
                    t.j_theta,
                    t.j_r,
                    t.j_theta_r,
                    t.g,
                    t.f_m,
                    t.f1,
                    t.f2,
                ])
            },
        )?;
        let names = [
            "f",
            "f_theta",
            "j",
            "j_theta",
            "j_r",
            "j_theta_r",
            "g",
            "f_m",
            "f1",
            "f2",
        ];
        let d = PyDict::new(py);
        for (name, v) in names.iter().zip(outs) {
            d.set_item(name, v)?;
        }
        Ok(d)
    }

    /// θ̈ of Eq. 151 at (θ, ω = θ̇) with eccentricity r and inputs (V_m, T_U),
    /// broadcast over arrays.
    fn acceleration<'py>(
        &self,
        py: Python<'py>,
        theta: &Bound<'py, PyAny>,
        omega: &Bound<'py, PyAny>,
        r: &Bound<'py, PyAny>,
        v_m: &Bound<'py, PyAny>,
        t_u: &Bound<'py, PyAny>,
    ) -> PyResult<Bound<'py, PyAny>> {
        let p = self.params;
        map1(
            py,
            [
                ("theta", theta),
                ("omega", omega),
                ("r", r),
                ("v_m", v_m),
                ("t_u", t_u),
            ],
            |[th, w, r, vm, tu]| p.acceleration(th, w, r, vm, tu),
        )
    }

    fn __repr__(&self) -> String {
        let printed = PlantParams::printed();
        let changed: Vec<String> = fields::changed(FIELDS, &self.params, &printed)
            .into_iter()
            .chain(
                (self.params.gravity != printed.gravity)
                    .then(|| format!("gravity={:?}", gravity_name(self.params.gravity))),
            )
            .collect();
        format!("Plant({})", changed.join(", "))
    }

    fn __eq__(&self, other: &Bound<'_, PyAny>) -> bool {
        other
            .cast::<Plant>()
            .is_ok_and(|o| o.get().params == self.params)
    }

    /// Pickle support (for dask workers in other processes): rebuilt from
    /// `params()` by the constructor.
    fn __reduce__<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyTuple>> {
        let rebuild = py.import("ivt.kin")?.getattr("_plant_from_params")?;
        let args = PyTuple::new(py, [self.params(py)?])?;
        PyTuple::new(py, [rebuild, args.into_any()])
    }
}
    /// J_a [kg·m²] (§4.1; thesis 0.0237).
    j_a;
    /// J_b = m_r + m_dr [kg] (§4.1; thesis 2.1264).
    j_b;
    /// J_c = J_U·8/(π² r_u²) [kg] (§4.1; thesis 0.3388).
    j_c;
    /// J_d = J_N1 [kg·m²] (§4.1).
    j_d;
    /// k_t k_e/R_a: F_m = this·f² (thesis 2.375).
    motor_damping;
    /// k_t/R_a: f1 = this·f·V_m (thesis 3.1667).
    motor_gain;
    /// 2√2/(π r_u): f2 = this·f·T_U (thesis 40.5548).
    load_gain;
    /// Coefficient of (sin θ + cos θ) in G: g, or m_r·g with gravity="roller_mass".
    gravity_gain;
}

/// Register `ivt._ivt.kin`.
pub fn register(parent: &Bound<'_, PyModule>) -> PyResult<()> {
    let m = PyModule::new(parent.py(), "kin")?;
    add_functions!(
        &m,
        [
            f,
            f_theta,
            mean_f_squared,
            ring_speeds,
            driver_speeds,
            output_speed,
            output_to_motor_ratio
        ]
    );
    m.add_class::<Plant>()?;
    m.add("NCG_AMPLITUDE", ivt_kin::NCG_AMPLITUDE)?;
    crate::gears::register(&m)?;
    parent.add_submodule(&m)
}
