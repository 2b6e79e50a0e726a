//! `ivt.ctrl`: the rig controller of `ivt-ctrl` (f32, the code the firmware
//! runs), driven from Python pulse by pulse or over whole arrays of encoder
//! timestamps (GIL released).

use ivt_ctrl::{
    units, AnyController, Config, ControlOutput, Fault, Gains, OpenLoopPreset, SUPPORTED_PPR,
};
use numpy::ndarray::Array1;
use numpy::IntoPyArray;
use pyo3::exceptions::{PyTypeError, PyValueError};
use pyo3::prelude::*;
use pyo3::types::PyDict;

use crate::args::{check_arg, count, int, opt_int};
use crate::ctrl_convert::{
    fault_name, inputs_from_py, law_kind, law_name, open_loop_from_py, open_loop_to_py,
    output_dict, region_name, ticks_from_py, SIGNALS,
};

/// One keyword override of [`Config`]: its Python name and how to apply it.
type Override = (&'static str, Box<dyn Fn(&mut Config)>);

/// The rig controller of ivt-ctrl (Eq. 158–160 open loop, Eq. 180/181/189
/// feedback, angle-sampled averaging, stepper output), single precision as on
/// the MCU.
///
/// Every keyword defaults to `ivt-ctrl`'s `Config::default()` (the thesis
/// setup: 100 rpm, 1 MHz timer, Eq. 180 with k = 0.01, k2 = 0.02 mm·rad⁻¹ read
/// as SI 1e-5, 2e-5 m·s/rad², the open-loop law refitted on the printed
/// plant (`open_loop="refit"`; `"thesis"` selects Eq. 158–160 as printed),
/// 3200 steps/rev).
/// Gains are SI; `thesis_gains(k, k2)` converts the printed mm·rad⁻¹ values.
/// `ppr` must be one of `SUPPORTED_PPR`. An invalid setting raises
/// `ValueError` naming the keyword.
#[pyclass(name = "Controller", module = "ivt.ctrl")]
pub struct Controller {
    inner: Box<AnyController>,
    ppr: usize,
    config: Config,
}

#[pymethods]
impl Controller {
    #[new]
    #[pyo3(signature = (
        ppr = 1200, *, f_timer_hz = None, omega0 = None, omega0_rpm = None, decimation = None,
        law = None, k = None, k2 = None, k_prop = None, prop_period_s = None, open_loop = None,
        feedforward = None, steps_per_metre = None, offset_steps = None, stepper_max_speed = None,
        stepper_accel = None, stall_timeout_s = None, omega_max = None, safe_r = None,
        v_m_valid = None, t_u_valid = None, initial_inputs = None
    ))]
    #[allow(clippy::too_many_arguments)]
    fn new(
        #[pyo3(from_py_with = int)] ppr: i128,
        f_timer_hz: Option<f64>,
        omega0: Option<f64>,
        omega0_rpm: Option<f64>,
        #[pyo3(from_py_with = opt_int)] decimation: Option<i128>,
        law: Option<&str>,
        k: Option<f64>,
        k2: Option<f64>,
        k_prop: Option<f64>,
        prop_period_s: Option<f64>,
        open_loop: Option<&Bound<'_, PyAny>>,
        feedforward: Option<bool>,
        steps_per_metre: Option<f32>,
        #[pyo3(from_py_with = opt_int)] offset_steps: Option<i128>,
        stepper_max_speed: Option<f64>,
        stepper_accel: Option<f64>,
        stall_timeout_s: Option<f64>,
        omega_max: Option<f32>,
        safe_r: Option<f32>,
        v_m_valid: Option<[f32; 2]>,
        t_u_valid: Option<[f32; 2]>,
        initial_inputs: Option<[f32; 2]>,
    ) -> PyResult<Self> {
        let ppr: usize = count("ppr", ppr)?;
        let decimation: Option<u16> = decimation.map(|d| count("decimation", d)).transpose()?;
        let offset_steps: Option<i32> =
            offset_steps.map(|o| count("offset_steps", o)).transpose()?;
        if !SUPPORTED_PPR.contains(&ppr) {
            return Err(PyValueError::new_err(format!(
                "argument `ppr` = {ppr} has no compiled controller (supported: {SUPPORTED_PPR:?})"
            )));
        }
        if omega0.is_some() && omega0_rpm.is_some() {
            return Err(PyTypeError::new_err(
                "give `omega0` [rad/s] or `omega0_rpm`, not both",
            ));
        }
        // each float that sets a quantity of ivt_kin::params, checked
        // through its key as typed, then held as the controller's f32
        let keyed = |name: &'static str, key: &str, v: Option<f64>| -> PyResult<Option<f32>> {
            v.map(|v| check_arg(name, key, v).map(|()| v as f32))
                .transpose()
        };
        let f_timer_hz = keyed("f_timer_hz", "encoder.f_timer_hz", f_timer_hz)?;
        let omega0 = keyed("omega0", "controller.omega0", omega0)?;
        let omega0_rpm = keyed("omega0_rpm", "controller.omega0_rpm", omega0_rpm)?;
        let k = keyed("k", "controller.k_si", k)?;
        let k2 = keyed("k2", "controller.k2_si", k2)?;
        let k_prop = keyed("k_prop", "controller.k_prop_si", k_prop)?;
        let prop_period_s = keyed("prop_period_s", "controller.prop_period_s", prop_period_s)?;
        let stepper_max_speed = keyed("stepper_max_speed", "stepper.max_speed", stepper_max_speed)?;
        let stepper_accel = keyed("stepper_accel", "stepper.accel", stepper_accel)?;
        let stall_timeout_s = keyed(
            "stall_timeout_s",
            "controller.stall_timeout_s",
            stall_timeout_s,
        )?;
        let mut overrides: Vec<Override> = Vec::new();
        macro_rules! set {
            ($opt:expr, $name:literal, |$c:ident, $v:ident| $body:expr) => {
                if let Some($v) = $opt {
                    overrides.push(($name, Box::new(move |$c: &mut Config| $body)));
                }
            };
        }
        set!(f_timer_hz, "f_timer_hz", |c, v| c.f_timer_hz = v);
        set!(omega0, "omega0", |c, v| c.omega0 = v);
        set!(omega0_rpm, "omega0_rpm", |c, v| c.omega0 =
            units::rpm_to_rad_s(v));
        set!(decimation, "decimation", |c, v| c.decimation = v);
        if let Some(name) = law {
            let kind = law_kind(name)?;
            overrides.push(("law", Box::new(move |c: &mut Config| c.law = kind)));
        }
        set!(k, "k", |c, v| c.gains.k = v);
        set!(k2, "k2", |c, v| c.gains.k2 = v);
        set!(k_prop, "k_prop", |c, v| c.gains.k_prop = v);
        set!(prop_period_s, "prop_period_s", |c, v| c
            .gains
            .prop_period_s =
            v);
        if let Some(ob) = open_loop {
            let coeffs = open_loop_from_py(ob)?;
            overrides.push((
                "open_loop",
                Box::new(move |c: &mut Config| c.open_loop = coeffs),
            ));
        }
        set!(feedforward, "feedforward", |c, v| c.feedforward = v);
        set!(steps_per_metre, "steps_per_metre", |c, v| c
            .actuator
            .steps_per_metre =
            v);
        set!(offset_steps, "offset_steps", |c, v| c
            .actuator
            .offset_steps = v);
        set!(stepper_max_speed, "stepper_max_speed", |c, v| c
            .stepper
            .max_speed =
            v);
        set!(stepper_accel, "stepper_accel", |c, v| c.stepper.accel = v);
        set!(stall_timeout_s, "stall_timeout_s", |c, v| c
            .stall_timeout_s =
            v);
        set!(omega_max, "omega_max", |c, v| c.omega_max = v);
        set!(safe_r, "safe_r", |c, v| c.safe_r = v);
        set!(v_m_valid, "v_m_valid", |c, v| c.v_m_valid = v);
        set!(t_u_valid, "t_u_valid", |c, v| c.t_u_valid = v);
        set!(initial_inputs, "initial_inputs", |c, v| c.initial_inputs =
            v);

        let mut config = Config::default();
        for (_, apply) in &overrides {
            apply(&mut config);
        }
        let inner = Box::new(
            AnyController::new(ppr, config)
                .map_err(|e| PyValueError::new_err(format!("argument `ppr`: {e}")))?,
        );
        if inner.output().fault == Fault::Config {
            // ivt-ctrl reports an invalid Config as a whole (permanent safe
            // state); name the keyword(s) that alone make the default invalid.
            let culprits: Vec<&str> = overrides
                .iter()
                .filter(|(_, apply)| {
                    let mut c = Config::default();
                    apply(&mut c);
                    AnyController::new(ppr, c).is_ok_and(|x| x.output().fault == Fault::Config)
                })
                .map(|(name, _)| *name)
                .collect();
            let which = if culprits.is_empty() {
                "the combination of the given keywords".to_string()
            } else {
                culprits
                    .iter()
                    .map(|n| format!("`{n}`"))
                    .collect::<Vec<_>>()
                    .join(", ")
            };
            return Err(PyValueError::new_err(format!(
                "invalid controller configuration ({which}): values must be finite, rates, \
                 periods and limits > 0, ranges ordered, decimation >= 1"
            )));
        }
        Ok(Self { inner, ppr, config })
    }

    /// Encoder samples per revolution of θ (the const generic of ivt-ctrl).
    #[getter]
    fn ppr(&self) -> usize {
        self.ppr
    }

    /// r_max of the open-loop coefficient set [m].
    #[getter]
    fn r_max(&self) -> f32 {
        self.inner.r_max()
    }

    /// The configuration in effect, as a dict (SI units).
    fn config<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let c = &self.config;
        let d = PyDict::new(py);
        d.set_item("ppr", self.ppr)?;
        d.set_item("f_timer_hz", c.f_timer_hz)?;
        d.set_item("omega0", c.omega0)?;
        d.set_item("decimation", c.decimation)?;
        d.set_item("law", law_name(c.law))?;
        d.set_item("k", c.gains.k)?;
        d.set_item("k2", c.gains.k2)?;
        d.set_item("k_prop", c.gains.k_prop)?;
        d.set_item("prop_period_s", c.gains.prop_period_s)?;
        d.set_item("open_loop", open_loop_to_py(py, &c.open_loop)?)?;
        d.set_item("feedforward", c.feedforward)?;
        d.set_item("steps_per_metre", c.actuator.steps_per_metre)?;
        d.set_item("offset_steps", c.actuator.offset_steps)?;
        d.set_item("stepper_max_speed", c.stepper.max_speed)?;
        d.set_item("stepper_accel", c.stepper.accel)?;
        d.set_item("stall_timeout_s", c.stall_timeout_s)?;
        d.set_item("omega_max", c.omega_max)?;
        d.set_item("safe_r", c.safe_r)?;
        d.set_item("v_m_valid", c.v_m_valid.to_vec())?;
        d.set_item("t_u_valid", c.t_u_valid.to_vec())?;
        d.set_item("initial_inputs", c.initial_inputs.to_vec())?;
        Ok(d)
    }

    /// One encoder pulse with its timer timestamp (0 ≤ ticks < 2³², wrapping
    /// is the timer's). Returns the output dict: omega, omega_a, omega_T,
    /// r_ol, r_d, r, stepper_target, saturated, fault (code), fault_name,
    /// ready, inputs_clamped, ol_region.
    fn on_pulse<'py>(
        &mut self,
        py: Python<'py>,
        #[pyo3(from_py_with = int)] ticks: i128,
    ) -> PyResult<Bound<'py, PyDict>> {
        let o = self.inner.on_pulse(count("ticks", ticks)?);
        output_dict(py, &o)
    }

    /// Slow readings: motor voltage V_m [V] and brake torque T_U [N·m].
    /// Invalid readings are ignored by the controller and flagged
    /// (fault 3, input_invalid); returns the output dict.
    fn update_inputs<'py>(
        &mut self,
        py: Python<'py>,
        v_m: f32,
        t_u: f32,
    ) -> PyResult<Bound<'py, PyDict>> {
        self.inner.update_inputs(v_m, t_u);
        output_dict(py, &self.inner.output())
    }

    /// Step-generator tick at timer count `now`: dict with step, forward,
    /// position, next_step_at, moving, fault, fault_name.
    fn step_tick<'py>(
        &mut self,
        py: Python<'py>,
        #[pyo3(from_py_with = int)] now: i128,
    ) -> PyResult<Bound<'py, PyDict>> {
        let s = self.inner.step_tick(count("now", now)?);
        let d = PyDict::new(py);
        d.set_item("step", s.step)?;
        d.set_item("forward", s.forward)?;
        d.set_item("position", s.position)?;
        d.set_item("next_step_at", s.next_step_at)?;
        d.set_item("moving", s.moving)?;
        d.set_item("fault", s.fault.code())?;
        d.set_item("fault_name", fault_name(s.fault))?;
        Ok(d)
    }

    /// The output of the most recent call.
    fn output<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        output_dict(py, &self.inner.output())
    }

    /// Feed a whole array of encoder timestamps (one `on_pulse` each, with
    /// `update_inputs(v_m[i], t_u[i])` before pulse i when the arrays are
    /// given), the GIL released. Returns a dict of arrays with one entry per
    /// pulse: the keys of `ivt ctrl replay --json` (omega, omega_a, omega_T,
    /// r_ol, r_d, r, fault) plus stepper_target, saturated, ready.
    #[pyo3(signature = (ticks, v_m = None, t_u = None))]
    fn on_pulses<'py>(
        &mut self,
        py: Python<'py>,
        ticks: &Bound<'py, PyAny>,
        v_m: Option<&Bound<'py, PyAny>>,
        t_u: Option<&Bound<'py, PyAny>>,
    ) -> PyResult<Bound<'py, PyDict>> {
        let ticks = ticks_from_py(ticks)?;
        let n = ticks.len();
        let v_m = inputs_from_py("v_m", v_m, n)?;
        let t_u = inputs_from_py("t_u", t_u, n)?;
        if v_m.is_some() != t_u.is_some() {
            return Err(PyTypeError::new_err(
                "give both `v_m` and `t_u`, or neither",
            ));
        }
        let inputs = v_m.zip(t_u);
        let inner = &mut self.inner;
        // `inputs_from_py` checked that both input columns have one entry per tick.
        let outs: Vec<ControlOutput> = py.detach(|| match &inputs {
            Some((v, tu)) => ticks
                .iter()
                .zip(v.iter().zip(tu))
                .map(|(&t, (&v, &tu))| {
                    inner.update_inputs(v, tu);
                    inner.on_pulse(t)
                })
                .collect(),
            None => ticks.iter().map(|&t| inner.on_pulse(t)).collect(),
        });
        let d = PyDict::new(py);
        for (key, signal) in SIGNALS {
            d.set_item(
                key,
                Array1::from_iter(outs.iter().map(signal)).into_pyarray(py),
            )?;
        }
        d.set_item(
            "fault",
            Array1::from_iter(outs.iter().map(|o| o.fault.code())).into_pyarray(py),
        )?;
        d.set_item(
            "stepper_target",
            Array1::from_iter(outs.iter().map(|o| o.stepper_target)).into_pyarray(py),
        )?;
        d.set_item(
            "saturated",
            Array1::from_iter(outs.iter().map(|o| o.saturated)).into_pyarray(py),
        )?;
        d.set_item(
            "ready",
            Array1::from_iter(outs.iter().map(|o| o.ready)).into_pyarray(py),
        )?;
        Ok(d)
    }

    fn __repr__(&self) -> String {
        format!(
            "Controller(ppr={}, law={:?}, omega0={} rad/s)",
            self.ppr,
            law_name(self.config.law),
            self.config.omega0
        )
    }
}

/// Gains (k, k2) in SI [m·s/rad²] from the thesis's printed mm·rad⁻¹ values
/// (e.g. 0.01, 0.02 for Eq. 180); the interpretation is ivt-ctrl's
/// `units::gain_from_mm_per_rad`.
#[pyfunction]
fn thesis_gains(k: f32, k2: f32) -> (f32, f32) {
    let g = Gains::from_thesis_mm_per_rad(k, k2);
    (g.k, g.k2)
}

/// The open-loop coefficient preset `name` ("refit" or "thesis") as a dict, the form
/// `Controller(open_loop=...)` accepts.
#[pyfunction]
fn open_loop_preset<'py>(
    py: Python<'py>,
    name: &Bound<'py, PyAny>,
) -> PyResult<Bound<'py, PyDict>> {
    open_loop_to_py(py, &open_loop_from_py(name)?)
}

/// Evaluate an open-loop law (Eq. 158–160) like the controller does:
/// dict with r_ol [m], ol_region, inputs_clamped, and the raw polynomial r_f
/// and boundary f_B. `open_loop` defaults to the controller's default set
/// ("refit").
#[pyfunction]
#[pyo3(signature = (v_m, t_u, open_loop = None))]
fn open_loop_eval<'py>(
    py: Python<'py>,
    v_m: f32,
    t_u: f32,
    open_loop: Option<&Bound<'py, PyAny>>,
) -> PyResult<Bound<'py, PyDict>> {
    let c = match open_loop {
        Some(ob) => open_loop_from_py(ob)?,
        None => OpenLoopPreset::default().coeffs(),
    };
    let v = c.evaluate(v_m, t_u);
    let d = PyDict::new(py);
    d.set_item("r_ol", v.r_ol)?;
    d.set_item("ol_region", region_name(v.region))?;
    d.set_item("inputs_clamped", v.inputs_clamped)?;
    d.set_item("r_f", c.r_f(v_m, t_u))?;
    d.set_item("f_b", c.f_b(v_m, t_u))?;
    Ok(d)
}

/// Register `ivt._ivt.ctrl`.
pub fn register(parent: &Bound<'_, PyModule>) -> PyResult<()> {
    let py = parent.py();
    let m = PyModule::new(py, "ctrl")?;
    m.add_class::<Controller>()?;
    add_functions!(&m, [thesis_gains, open_loop_preset, open_loop_eval]);
    m.add("SUPPORTED_PPR", SUPPORTED_PPR.to_vec())?;
    let faults = PyDict::new(py);
    for f in [
        Fault::None,
        Fault::Stall,
        Fault::IntervalTooShort,
        Fault::InputInvalid,
        Fault::Config,
    ] {
        faults.set_item(f.code(), fault_name(f))?;
    }
    m.add("FAULTS", faults)?;
    parent.add_submodule(&m)
}
