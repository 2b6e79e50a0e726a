//! `ivt.kin` continued: the GIVT (§2.1) and SGIVT (§2.2) mechanisms, the
//! noncircular-gear pitch profiles (Eq. 13–17, 38–42) and unit helpers.

use crate::args::{check_arg, count, int};
use crate::fields::{self, Field};
use crate::vectorize::{map, map1, map2};
use ivt_kin::givt::{DirectionMode, DirectionModule, GivtGeometry};
use ivt_kin::ncg::{self, GearRatio, GivtNcg, PitchPoint, SgivtNcg, SmoothNcg};
use ivt_kin::params::Typed;
use ivt_kin::sgivt::{self, SgivtGeometry};
use ivt_kin::{units, KinError};
use numpy::ndarray::Array1;
use numpy::IntoPyArray;
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use pyo3::types::PyDict;

fn kin_err(e: KinError) -> PyErr {
    PyValueError::new_err(e.to_string())
}

/// A frozen geometry class `$ty` wrapping `geometry: $geom` (its fields in
/// `fields`) with its `#[pymethods]`: the constructor (`reference()` with
/// keyword overrides, then `check`), `params()` (the fields as a dict),
/// `__repr__` (the fields that differ from `reference()`), the `items` as
/// written; for each `fn name(a, b);` under `pairs`, a method broadcasting the
/// pair `self.geometry.name(a, b)` (see [`map2`]); then one method per
/// `fn name(a[, b]);` entry that broadcasts the fallible
/// `self.geometry.name(a[, b])` over numpy array-likes like a ufunc (scalar in
/// → float out), raising the Rust error with the flat index.
macro_rules! geometry_class {
    (
        $(#[$cdoc:meta])*
        $ty:ident($geom:ty, $what:literal, $fields:expr, $reference:path, $check:expr) {
            $($items:tt)*
        }
        $(pairs { $( $(#[$pdoc:meta])* fn $pair:ident($pa:ident, $pb:ident); )* })?
        $( $(#[$doc:meta])* fn $name:ident($a:ident $(, $b:ident)?); )*
    ) => {
        $(#[$cdoc])*
        #[pyclass(module = "ivt.kin", frozen)]
        pub struct $ty {
            geometry: $geom,
        }

        #[pymethods]
        impl $ty {
            #[new]
            #[pyo3(signature = (**overrides))]
            fn new(overrides: Option<&Bound<'_, PyDict>>) -> PyResult<Self> {
                let mut geometry = $reference();
                fields::apply($what, $fields, &mut geometry, overrides, |_, _, _| Ok(false))?;
                ($check)(&geometry)?;
                Ok(Self { geometry })
            }

            /// The dimensions as a dict (constructor keywords).
            fn params<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
                fields::to_dict(py, $fields, &self.geometry)
            }

            fn __repr__(&self) -> String {
                let changed = fields::changed($fields, &self.geometry, &$reference());
                format!("{}({})", stringify!($ty), changed.join(", "))
            }

            $($items)*
            $($(
                $(#[$pdoc])*
                fn $pair<'py>(
                    &self,
                    py: Python<'py>,
                    $pa: &Bound<'py, PyAny>,
                    $pb: &Bound<'py, PyAny>,
                ) -> PyResult<(Bound<'py, PyAny>, Bound<'py, PyAny>)> {
                    let g = self.geometry;
                    map2(py, [(stringify!($pa), $pa), (stringify!($pb), $pb)], |[$pa, $pb]| {
                        g.$pair($pa, $pb)
                    })
                }
            )*)?
            $(
                $(#[$doc])*
                fn $name<'py>(
                    &self,
                    py: Python<'py>,
                    $a: &Bound<'py, PyAny>,
                    $($b: &Bound<'py, PyAny>,)?
                ) -> PyResult<Bound<'py, PyAny>> {
                    let g = self.geometry;
                    let [y] = map(py, [(stringify!($a), $a) $(, (stringify!($b), $b))?], |[$a $(, $b)?]| {
                        g.$name($a $(, $b)?).map(|v| [v])
                    })?;
                    Ok(y)
                }
            )*
        }
    };
}

const GIVT_FIELDS: &[Field<GivtGeometry>] = fields::field_table![
    GivtGeometry; l1, r_output, r_sun, r_planet, r_crk, control_to_ring
];

geometry_class! {
    /// The crank-slider GIVT of §2.1 (Eq. 1–10), SI units.
    ///
    /// `Givt()` uses ivt-kin's illustrative dimensions (l1 = 50 mm, r_output =
    /// 15 mm: **not printed in the thesis**); keywords override them. Ratio
    /// methods broadcast over numpy arrays; θ must be finite and 0 ≤ r < l1,
    /// else `ValueError` with the Rust message.
    Givt(GivtGeometry, "GIVT", GIVT_FIELDS, GivtGeometry::illustrative, |g: &GivtGeometry| {
        g.validate().map_err(kin_err)
    }) {
    /// Corners (kinks) of R(θ, r) in one period [rad].
    fn module_corners(&self, r: f64) -> PyResult<Vec<f64>> {
        let mut buf = [0.0; ivt_kin::givt::MAX_CORNERS];
        let n = self.geometry.module_corners(r, &mut buf).map_err(kin_err)?;
        Ok(buf.iter().take(n).copied().collect())
    }

    /// ω_crk/ω_in at zero control speed: 2(r_sun + r_planet)/r_sun (3 in the design).
    #[getter]
    fn crank_to_input(&self) -> f64 {
        self.geometry.crank_to_input()
    }
}
pairs {
    /// Sun-gear speeds (ω_sA, ω_sB) for input ω_in and control ω_c1, Eq. 1–2.
    fn sun_speeds(omega_in, omega_c1);
    /// Crank rotation and translation (ω_crk, v_crk) from the sun speeds, Eq. 3–4.
    fn crank_motion(omega_sa, omega_sb);
}
    /// Single crank-slider ratio R1(θ, r), Eq. 8.
    fn single_ratio(theta, r);
    /// Module ratio R(θ, r): max over the four phases, Eq. 9.
    fn module_ratio(theta, r);
    /// dR/dθ of the module ratio (the value of the piece starting at a corner).
    fn module_ratio_derivative(theta, r);
    /// Final ratio F = 3R, Eq. 10 (crank_to_input × module ratio).
    fn final_ratio(theta, r);
    /// Reduced ratio R(θ, r)/R̄(r) (§2.1.5); r = 0 is an error (zero mean).
    fn reduced_ratio(theta, r);
    /// Average module ratio R̄(r) over a period (adaptive quadrature between corners).
    fn average_module_ratio(r);
    /// Average final ratio 3R̄(r).
    fn average_final_ratio(r);
}

const SGIVT_FIELDS: &[Field<SgivtGeometry>] = fields::field_table![
    SgivtGeometry; d_sg, d_pg, d_acg, d_esg, d_erg, d_ecg, r_cg, r_og, stepper_to_acg,
    ncg_centre_distance, theta_ct_max
];

/// Every SGIVT dimension must be finite and > 0.
fn sgivt_positive(geometry: &SgivtGeometry) -> PyResult<()> {
    for (name, get, _) in SGIVT_FIELDS {
        let v = get(geometry);
        if !(v.is_finite() && v > 0.0) {
            return Err(PyValueError::new_err(format!(
                "SGIVT parameter `{name}` = {} must be finite and > 0",
                Typed(v)
            )));
        }
    }
    Ok(())
}

geometry_class! {
    /// The scotch-yoke SGIVT prototype of §2.2 and §4.4.2, SI units.
    ///
    /// `Sgivt()` is the printed prototype (gear diameters in inches converted to
    /// metres); keywords override dimensions (each finite and > 0). Methods
    /// broadcast over numpy arrays; out-of-domain inputs raise `ValueError`.
    Sgivt(SgivtGeometry, "SGIVT", SGIVT_FIELDS, SgivtGeometry::prototype, sgivt_positive) {
    /// v_CRK/ω_CT = 7 r_CG/288 [m/rad] through the gear chain, Eq. 184.
    #[getter]
    fn crank_length_per_stepper_rad(&self) -> f64 {
        self.geometry.crank_length_per_stepper_rad()
    }
}
    /// Crank length e [m] for a stepper angle θ_CT [rad] ∈ [0, theta_ct_max], Eq. 182–185.
    fn crank_length(theta_ct);
    /// Stepper angle θ_CT [rad] for a crank length e [m] (inverse of crank_length).
    fn stepper_angle(e);
    /// Instantaneous ratio ω_out/ω_in at input angle θ_in and crank length e, Eq. 35.
    fn ratio(theta_in, e);
    /// Average ratio over a revolution for crank length e.
    fn average_ratio(e);
    /// Average ratio for a stepper angle θ_CT [rad] (§4.4.2: ≈ 7 θ_CT[deg]/27492).
    fn average_ratio_from_stepper(theta_ct);
}

/// Pitch profiles of a noncircular gear pair by integrating Eq. 17/41.
///
/// design: "sgivt" (Eq. 38, D = 5.25 in), "sgivt-smooth" (Eq. 42 as printed,
/// D = 5.25 in) or "givt" (Eq. 13 with r_o = 10 mm, D = 10 mm, illustrative
/// GIVT dimensions) — the designs of `ivt kin pitch-profile`. Returns a dict
/// with arrays theta_driven, r_driven, theta_driving, r_driving (points over
/// one NG2 revolution, both ends included) and the checks closure_error,
/// max_centre_distance_error, r_driven_min/max, r_driving_min/max,
/// centre_distance (the keys of `ivt kin pitch-profile --json`).
#[pyfunction]
#[pyo3(signature = (design = "sgivt", points = 361))]
fn pitch_profile<'py>(
    py: Python<'py>,
    design: &str,
    #[pyo3(from_py_with = int)] points: i128,
) -> PyResult<Bound<'py, PyDict>> {
    let points: usize = count("points", points)?;
    if !(2..=1_000_000).contains(&points) {
        return Err(PyValueError::new_err(format!(
            "argument `points` = {points} must be in 2..=1000000"
        )));
    }
    let d_sgivt = SgivtGeometry::prototype().ncg_centre_distance;
    let mut pts = vec![PitchPoint::default(); points];
    let pts_mut = &mut pts;
    let (check, d) = match design {
        "sgivt" => (
            py.detach(|| ncg::pitch_profile(&SgivtNcg, d_sgivt, pts_mut)),
            d_sgivt,
        ),
        "sgivt-smooth" => (
            py.detach(|| ncg::pitch_profile(&SmoothNcg::PRINTED, d_sgivt, pts_mut)),
            d_sgivt,
        ),
        "givt" => {
            let g = GivtNcg::new(GivtGeometry::illustrative(), 0.010).map_err(kin_err)?;
            (py.detach(|| ncg::pitch_profile(&g, 0.010, pts_mut)), 0.010)
        }
        other => {
            return Err(PyValueError::new_err(format!(
                "argument `design` = {other:?} must be 'sgivt', 'sgivt-smooth' or 'givt'"
            )))
        }
    };
    let c = check.map_err(kin_err)?;
    let col = |f: fn(&PitchPoint) -> f64| Array1::from_iter(pts.iter().map(f)).into_pyarray(py);
    let out = PyDict::new(py);
    out.set_item("design", design)?;
    out.set_item("centre_distance", d)?;
    out.set_item("closure_error", c.closure_error)?;
    out.set_item("max_centre_distance_error", c.max_centre_distance_error)?;
    out.set_item("r_driven_min", c.r_driven_range.0)?;
    out.set_item("r_driven_max", c.r_driven_range.1)?;
    out.set_item("r_driving_min", c.r_driving_range.0)?;
    out.set_item("r_driving_max", c.r_driving_range.1)?;
    out.set_item("theta_driven", col(|p| p.theta_driven))?;
    out.set_item("r_driven", col(|p| p.r_driven))?;
    out.set_item("theta_driving", col(|p| p.theta_driving))?;
    out.set_item("r_driving", col(|p| p.r_driving))?;
    Ok(out)
}

/// Exact Fourier coefficient a_k of Eq. 38 in R_n = 1 + Σ a_k cos(4kθ):
/// 2(−1)^(k+1)/(16k² − 1) (k ≥ 1; a_0 = 1).
#[pyfunction]
fn fourier_coefficient_eq38(#[pyo3(from_py_with = int)] k: i128) -> PyResult<f64> {
    Ok(ncg::fourier_coefficient_eq38(count("k", k)?))
}

/// Ratio of the SGIVT noncircular pair, Eq. 38 (= f(θ) of Eq. 43), or the
/// printed smooth series Eq. 42 with `smooth=True`, over θ₂ [rad].
#[pyfunction]
#[pyo3(signature = (theta, smooth = false))]
fn ncg_ratio<'py>(
    py: Python<'py>,
    theta: &Bound<'py, PyAny>,
    smooth: bool,
) -> PyResult<Bound<'py, PyAny>> {
    if smooth {
        map1(py, [("theta", theta)], |[t]| SmoothNcg::PRINTED.ratio(t))
    } else {
        map1(py, [("theta", theta)], |[t]| SgivtNcg.ratio(t))
    }
}

/// Forward and reverse speed ratios ω_carrier1/ω_rg2 of the direction module,
/// Eq. 18–19 (as derived, and as printed): dict with forward_ratio,
/// reverse_ratio, forward_ratio_printed, reverse_ratio_printed (keys of
/// `ivt kin direction --json`) and the mode speeds for ω_rg2 = 1.
#[pyfunction]
#[pyo3(signature = (r_sun = 1.0, r_planet = 1.0))]
fn direction<'py>(py: Python<'py>, r_sun: f64, r_planet: f64) -> PyResult<Bound<'py, PyDict>> {
    check_arg("r_sun", "kin.r_sun", r_sun)?;
    check_arg("r_planet", "kin.r_planet", r_planet)?;
    let m = DirectionModule { r_sun, r_planet };
    let fwd = m.speeds(DirectionMode::Forward, 1.0).map_err(kin_err)?;
    let rev = m.speeds(DirectionMode::Reverse, 1.0).map_err(kin_err)?;
    let d = PyDict::new(py);
    d.set_item("forward_ratio", m.forward_ratio())?;
    d.set_item("reverse_ratio", m.reverse_ratio())?;
    d.set_item("forward_ratio_printed", m.forward_ratio_printed())?;
    d.set_item("reverse_ratio_printed", m.reverse_ratio_printed())?;
    for (key, s) in [("forward_speeds", fwd), ("reverse_speeds", rev)] {
        let e = PyDict::new(py);
        e.set_item("omega_sun", s.omega_sun)?;
        e.set_item("omega_rg1", s.omega_rg1)?;
        e.set_item("omega_carrier1", s.omega_carrier1)?;
        d.set_item(key, e)?;
    }
    Ok(d)
}

/// max(|sin θ|, |cos θ|): the rectified shape of the four yoke phases (§2.2.3).
#[pyfunction]
fn rectified_shape<'py>(py: Python<'py>, theta: &Bound<'py, PyAny>) -> PyResult<Bound<'py, PyAny>> {
    map1(py, [("theta", theta)], |[t]| sgivt::rectified_shape(t))
}

macro_rules! unit_fn {
    ($name:ident, $arg:ident, $doc:literal) => {
        #[doc = $doc]
        #[pyfunction]
        fn $name<'py>(py: Python<'py>, $arg: &Bound<'py, PyAny>) -> PyResult<Bound<'py, PyAny>> {
            map1(py, [(stringify!($arg), $arg)], |[v]| units::$name(v))
        }
    };
}
unit_fn!(inch_to_m, inch, "Inches → metres.");
unit_fn!(m_to_inch, m, "Metres → inches.");
unit_fn!(deg_to_rad, deg, "Degrees → radians.");
unit_fn!(rad_to_deg, rad, "Radians → degrees.");
unit_fn!(rpm_to_rad_s, rpm, "Revolutions per minute → rad/s.");
unit_fn!(rad_s_to_rpm, rad_s, "rad/s → revolutions per minute.");

/// Add the gear functions and classes to `ivt._ivt.kin`.
pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<Givt>()?;
    m.add_class::<Sgivt>()?;
    add_functions!(
        m,
        [
            pitch_profile,
            fourier_coefficient_eq38,
            ncg_ratio,
            direction,
            rectified_shape,
            inch_to_m,
            m_to_inch,
            deg_to_rad,
            rad_to_deg,
            rpm_to_rad_s,
            rad_s_to_rpm
        ]
    );
    m.add("EQ42_PRINTED", ncg::EQ42_PRINTED.to_vec())?;
    m.add(
        "R_AVG_SLOPE_PRINTED_PER_DEG",
        sgivt::R_AVG_SLOPE_PRINTED_PER_DEG,
    )?;
    m.add("GIVT_MODULE_PERIOD", ivt_kin::givt::MODULE_PERIOD)?;
    Ok(())
}
