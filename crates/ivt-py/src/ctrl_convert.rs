//! What `ivt.ctrl` converts between Python and ivt-ctrl: the names of the
//! law, fault and open-loop region enums, the open-loop coefficients (a
//! preset name or a dict), encoder timestamps and per-pulse inputs from
//! arrays or sequences, and a [`ControlOutput`] as a dict or as columns.

use ivt_ctrl::open_loop::{POLY_T_TERMS, POLY_V_TERMS};
use ivt_ctrl::{ControlOutput, Fault, LawKind, OlRegion, OpenLoopCoeffs, OpenLoopPreset};
use ivt_kin::params::Typed;
use numpy::{PyArray1, PyArrayDescrMethods, PyArrayMethods, PyUntypedArray, PyUntypedArrayMethods};
use pyo3::exceptions::{PyTypeError, PyValueError};
use pyo3::prelude::*;
use pyo3::types::PyDict;

use crate::args::int;

pub(crate) fn law_kind(name: &str) -> PyResult<LawKind> {
    match name {
        "delay" => Ok(LawKind::Delay),
        "nodelay" => Ok(LawKind::NoDelay),
        "prop" => Ok(LawKind::Prop),
        "open" => Ok(LawKind::Open),
        other => Err(PyValueError::new_err(format!(
            "argument `law` = {other:?} must be one of 'delay', 'nodelay', 'prop', 'open'"
        ))),
    }
}

pub(crate) fn law_name(kind: LawKind) -> &'static str {
    match kind {
        LawKind::Delay => "delay",
        LawKind::NoDelay => "nodelay",
        LawKind::Prop => "prop",
        LawKind::Open => "open",
    }
}

/// Name of a fault code (the `Fault` enum of ivt-ctrl, lower case).
pub(crate) fn fault_name(f: Fault) -> &'static str {
    match f {
        Fault::None => "none",
        Fault::Stall => "stall",
        Fault::IntervalTooShort => "interval_too_short",
        Fault::InputInvalid => "input_invalid",
        Fault::Config => "config",
    }
}

pub(crate) fn region_name(r: OlRegion) -> &'static str {
    match r {
        OlRegion::Normal => "normal",
        OlRegion::OverDrive => "over_drive",
        OlRegion::UnderDrive => "under_drive",
    }
}

/// Open-loop coefficients from a preset name (`"refit"`, the default set
/// refitted on the printed plant, or `"thesis"`, Eq. 158–160 as printed) or a
/// dict with the fields of `OpenLoopCoeffs` (poly 3×5, boundary 3, r_max,
/// v_m_range 2, t_u_range 2; missing fields are taken from `"refit"`).
pub(crate) fn open_loop_from_py(ob: &Bound<'_, PyAny>) -> PyResult<OpenLoopCoeffs> {
    if let Ok(name) = ob.extract::<String>() {
        return OpenLoopPreset::from_name(&name)
            .map(OpenLoopPreset::coeffs)
            .ok_or_else(|| {
                PyValueError::new_err(format!(
                    "argument `open_loop` = {name:?}: known presets are 'refit' (the default) and 'thesis' (or pass a dict)"
                ))
            });
    }
    let d = ob.cast::<PyDict>().map_err(|_| {
        PyTypeError::new_err(
            "argument `open_loop` must be 'refit', 'thesis' or a dict of coefficients",
        )
    })?;
    let mut c = OpenLoopPreset::default().coeffs();
    for (key, value) in d.iter() {
        let key: String = key.extract()?;
        let bad = |what: &str| PyTypeError::new_err(format!("open_loop[{key:?}] must be {what}"));
        match key.as_str() {
            "poly" => {
                let (nv, nt) = (POLY_V_TERMS, POLY_T_TERMS);
                let shape = format!("at most {nv} rows (powers of V_m) of at most {nt} floats");
                let rows: Vec<Vec<f32>> = value.extract().map_err(|_| bad(&shape))?;
                if rows.len() > nv || rows.iter().any(|r| r.len() > nt) {
                    return Err(PyValueError::new_err(format!(
                        "open_loop[\"poly\"] must have {shape}"
                    )));
                }
                let mut poly = [[0.0f32; POLY_T_TERMS]; POLY_V_TERMS];
                for (dst, row) in poly.iter_mut().zip(&rows) {
                    for (d, v) in dst.iter_mut().zip(row) {
                        *d = *v;
                    }
                }
                c.poly = poly;
            }
            "boundary" => c.boundary = value.extract().map_err(|_| bad("3 floats"))?,
            "r_max" => c.r_max = value.extract().map_err(|_| bad("a float"))?,
            "v_m_range" => c.v_m_range = value.extract().map_err(|_| bad("2 floats"))?,
            "t_u_range" => c.t_u_range = value.extract().map_err(|_| bad("2 floats"))?,
            other => {
                return Err(PyTypeError::new_err(format!(
                    "unknown open_loop key {other:?} (poly, boundary, r_max, v_m_range, t_u_range)"
                )))
            }
        }
    }
    if !c.is_valid() {
        return Err(PyValueError::new_err(
            "argument `open_loop`: coefficients must be finite, ranges ordered, r_max > 0",
        ));
    }
    Ok(c)
}

pub(crate) fn open_loop_to_py<'py>(
    py: Python<'py>,
    c: &OpenLoopCoeffs,
) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    d.set_item("poly", c.poly.to_vec())?;
    d.set_item("boundary", c.boundary.to_vec())?;
    d.set_item("r_max", c.r_max)?;
    d.set_item("v_m_range", c.v_m_range.to_vec())?;
    d.set_item("t_u_range", c.t_u_range.to_vec())?;
    Ok(d)
}
/// One f32 signal of a [`ControlOutput`].
pub(crate) type Signal = fn(&ControlOutput) -> f32;

/// The f32 signals of a [`ControlOutput`] under their keys (those of `ivt
/// ctrl replay --json`, omega_T for ω_T), shared by the dict of one output and
/// the columns of many.
pub(crate) const SIGNALS: [(&str, Signal); 6] = [
    ("omega", |o| o.omega),
    ("omega_a", |o| o.omega_a),
    ("omega_T", |o| o.omega_t),
    ("r_ol", |o| o.r_ol),
    ("r_d", |o| o.r_d),
    ("r", |o| o.r),
];

/// Dict of one [`ControlOutput`]: the [`SIGNALS`], then the stepper target,
/// the flags, the fault (code and name) and the open-loop region.
pub(crate) fn output_dict<'py>(py: Python<'py>, o: &ControlOutput) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    for (key, signal) in SIGNALS {
        d.set_item(key, signal(o))?;
    }
    d.set_item("stepper_target", o.stepper_target)?;
    d.set_item("saturated", o.saturated)?;
    d.set_item("fault", o.fault.code())?;
    d.set_item("fault_name", fault_name(o.fault))?;
    d.set_item("ready", o.ready)?;
    d.set_item("inputs_clamped", o.inputs_clamped)?;
    d.set_item("ol_region", region_name(o.ol_region))?;
    Ok(d)
}

/// Timer timestamps as u32 from a uint32 array, an integer array, a float
/// array whose values are whole numbers, or a sequence of ints; each must
/// lie in [0, 2³²).
pub(crate) fn ticks_from_py(ob: &Bound<'_, PyAny>) -> PyResult<Vec<u32>> {
    if let Ok(a) = ob.cast::<PyArray1<u32>>() {
        return Ok(a.readonly().as_array().to_vec());
    }
    let ints: Vec<i128> = if let Ok(arr) = ob.cast::<PyUntypedArray>() {
        let kind = arr.dtype().kind();
        if kind == b'f' {
            return whole_ticks(ob);
        }
        if kind != b'i' && kind != b'u' {
            return Err(PyTypeError::new_err(format!(
                "argument `ticks` must hold integers (timer counts), got dtype kind {:?}",
                kind as char
            )));
        }
        let cast = arr.call_method1("astype", ("int64",))?;
        let a = cast
            .cast::<PyArray1<i64>>()
            .map_err(|_| PyValueError::new_err("argument `ticks` must be one-dimensional"))?;
        a.readonly()
            .as_array()
            .iter()
            .map(|&t| i128::from(t))
            .collect()
    } else {
        let items: Vec<Bound<'_, PyAny>> = ob.extract().map_err(|_| {
            PyTypeError::new_err("argument `ticks` must be an integer array or sequence of ints")
        })?;
        items
            .iter()
            .enumerate()
            .map(|(i, t)| {
                int(t).map_err(|e| {
                    let msg = format!("argument `ticks`[{i}]: {e}");
                    if e.is_instance_of::<PyTypeError>(ob.py()) {
                        PyTypeError::new_err(msg)
                    } else {
                        PyValueError::new_err(msg)
                    }
                })
            })
            .collect::<PyResult<_>>()?
    };
    ints.iter()
        .enumerate()
        .map(|(i, &t)| {
            u32::try_from(t).map_err(|_| {
                PyValueError::new_err(format!(
                    "argument `ticks`[{i}] = {t} is outside the u32 timer range [0, 2^32)"
                ))
            })
        })
        .collect()
}

/// Timer counts from a float array: each value must be a whole number in
/// [0, 2³²) (a float array of counts, as `numpy.loadtxt` returns).
pub(crate) fn whole_ticks(ob: &Bound<'_, PyAny>) -> PyResult<Vec<u32>> {
    let a = ob
        .extract::<numpy::PyArrayLike1<'_, f64, numpy::AllowTypeChange>>()
        .map_err(|_| PyValueError::new_err("argument `ticks` must be one-dimensional"))?;
    a.as_array()
        .iter()
        .enumerate()
        .map(|(i, &t)| {
            if t.fract() == 0.0 && (0.0..4_294_967_296.0).contains(&t) {
                Ok(t as u32)
            } else {
                Err(PyValueError::new_err(format!(
                    "argument `ticks`[{i}] = {} is not a whole timer count in [0, 2^32)",
                    Typed(t)
                )))
            }
        })
        .collect()
}

/// Optional per-pulse input (V_m or T_U): a float (held for every pulse) or
/// an array of floats with one entry per pulse, as float32.
pub(crate) fn inputs_from_py(
    name: &str,
    ob: Option<&Bound<'_, PyAny>>,
    n: usize,
) -> PyResult<Option<Vec<f32>>> {
    let Some(ob) = ob else { return Ok(None) };
    let v: Vec<f64> = if let Ok(x) = ob.extract::<f64>() {
        vec![x; n]
    } else if let Ok(a) = ob.extract::<numpy::PyArrayLike1<'_, f64, numpy::AllowTypeChange>>() {
        a.as_array().to_vec()
    } else {
        return Err(PyTypeError::new_err(format!(
            "argument `{name}` must be a float or a 1-D array of floats"
        )));
    };
    if v.len() != n {
        return Err(PyValueError::new_err(format!(
            "argument `{name}` has {} entries, `ticks` has {n}",
            v.len()
        )));
    }
    // Non-finite readings are passed through: the controller flags them
    // (Fault::InputInvalid), which is what a test of that path needs.
    Ok(Some(v.into_iter().map(|x| x as f32).collect()))
}
