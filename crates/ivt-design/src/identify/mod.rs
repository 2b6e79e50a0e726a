//! Plant identification from a rig's own recording (§4.4 closed into a loop):
//! the coefficients of Eq. 151 by equation error, with 95 % intervals, and
//! the rig tests of §4.4.2–4.4.3 (Fig. 47, 48, 50) from the same data.
//!
//! # What is identifiable, and why
//! Eq. 151 is linear in its eight coefficients J_a, J_b, J_c, J_d,
//! k_t k_e/R_a (`motor_damping`), k_t/R_a (`motor_gain`), 2√2/(π r_u)
//! (`load_gain`) and the gravity gain g — and homogeneous: multiplying all
//! eight by one factor leaves every trajectory unchanged. From V_m, T_U and
//! the motion alone only their ratios are identifiable; the absolute scale
//! comes from the one coefficient that is known, the gravity term
//! g·(sin θ + cos θ)·r of the printed G (g = 9.8 m/s², not a property of
//! the rig). Its once-per-revolution torque (≤ g·√2·r_max ≈ 0.17 N·m) is
//! what fixes the units of all the others, so a recording needs holds at
//! r > 0 (the stepper sweep) and the interval widths say how well it did.
//! With the mass-weighted G = m_r g (sin θ + cos θ) the gravity gain is
//! itself unknown and the scale is not identifiable: [`identify`] refuses.
//! Of the motor only the two combinations k_t/R_a and k_t k_e/R_a enter
//! Eq. 151, hence k_e = damping/gain but not k_t or R_a alone; J_b and J_c
//! multiply r², at most 1–2 % of J, and come with wide intervals.
//!
//! # The armature inductance
//! Eq. 151 takes L_a = 0 (Eq. 138). With L_a > 0 (Eq. 137) the rows use the
//! motor's inputs lagged by τ_e = L_a/R_a ([`windows`]), which is exact; but
//! L_a itself is not identifiable from V_m, T_U and the motion (to first
//! order in τ_e it only shifts J_d by −τ_e k_t k_e/R_a), so τ_e is taken
//! from the nominal plant: the rig's L_a and R_a as measured on the motor.
//! Left at 0 on a rig with L_a = 1 mH, J_d comes out −0.008 kg·m²
//! (`tests/rig_identify_checks.rs`).
//!
//! # What the data must show
//! [`identify`] refuses instead of returning a confident wrong plant:
//! - the equation residual must be of the size of the noise the recording
//!   implies, measured as the difference between the two halves of its
//!   edges and readings over the same windows (model errors and stuck or
//!   miscalibrated sensors are common to both halves, noise is not): above
//!   [`CONSISTENCY_LIMIT`] times that, [`IdentifyError::Inconsistent`];
//! - every coefficient that fixes the plant (J_a, J_d, the motor's two, the
//!   load gain) must be excited by its regressor: its 95 % interval must
//!   exclude 0, else [`IdentifyError::NotIdentifiable`] naming it;
//! - the plant they give must be physical ([`PlantParams::validate`]).
//!
//! What is doubtful but usable is listed in [`Identification::warnings`]:
//! J_b or J_c not determined (their nominal values kept), a residual
//! beyond [`CONSISTENCY_WARN`] times the noise, a sensor that reads one value
//! through every stage.
//!
//! # What the rows assume
//! Eq. 151 holds (G in its printed form, no friction beyond the motor's
//! k_t k_e/R_a, τ_e from the nominal plant), r is constant over a window,
//! V_m and T_U are constant over one encoder interval, and so is θ̇ (with
//! L_a > 0: the lagged motor speed is a line over it). The θ-integrals of f
//! and f² are exact ([`windows::f_integrals`]): the motor's work per window
//! is ~250× the gravity work that fixes the scale, so a quadrature error of
//! 1e-5 of it is a bias of the size of the intervals (a midpoint rule gave
//! J_d +1 %). What is left, measured with the simulator's exact edge times:
//! J_d −0.09 % (L_a = 0) and +0.06 % (L_a = 1 mH), against 95 % intervals of
//! ±0.4–0.5 % with ideal sensors (measured, not asserted).
//!
//! The estimator is in [`windows`] (Eq. 151 in its energy form over windows
//! of θ, no θ̈), [`regression`] (instrumental variables: regressors from
//! every other encoder edge and reading, instruments from the other half,
//! so that measurement noise does not shrink the estimates; Newey–West 95 %
//! intervals) and [`steady`] (Fig. 47/48/50).

pub mod regression;
pub mod steady;
pub mod windows;

use ivt_kin::plant::{GravityModel, PlantParams};
use nalgebra::{DMatrix, DVector};
use std::f64::consts::{PI, SQRT_2, TAU};

pub use steady::{HoldPoint, SweepAnalysis};

/// Time after each stage start left out of the windows \[s\]: the ramp of
/// the inputs and the stepper move (Eq. 151 has no ṙ term), and the span
/// the smoothing of the readings must not reach across.
pub const SETTLE_S: f64 = 0.5;

/// Half-width of the local straight-line smoothing of the V_m and T_U
/// readings within a stage \[s\]. Reading noise is noise in the regressors
/// of the equation error and shrinks every estimate towards zero along the
/// weakly determined scale (errors in variables); the sequences hold V_m and
/// T_U constant (or ramp them) within a stage, so a local line loses nothing.
pub const SMOOTH_HALF_S: f64 = 0.25;

/// Largest ratio of the equation residual to the noise the two halves of
/// the recording imply that [`identify`] accepts. Measured on simulated
/// commissioning runs: 0.92–1.28 for runs that follow Eq. 151 or Eq. 137
/// (ideal or realistic sensors, L_a 0 or 1 mH), 87 with V_m and T_U stuck.
pub const CONSISTENCY_LIMIT: f64 = 3.0;

/// Ratio of the residual to the noise above which [`identify`] warns.
pub const CONSISTENCY_WARN: f64 = 1.5;

/// Range of θ at the first pulse \[rad\] (the encoder's zero is anywhere
/// on one turn; a θ0 of 1e20 would leave no significant digit for the pulses).
pub const THETA0_RANGE: [f64; 2] = [-TAU, TAU];

/// Why a recording gives no estimate.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum IdentifyError {
    /// The recording's arrays are inconsistent (named field, reason).
    #[error("recording: `{field}` {why}")]
    Recording {
        /// The offending field.
        field: &'static str,
        /// What is wrong.
        why: String,
    },
    /// The data do not determine the parameters of a fit.
    #[error("{what} is not identifiable from this recording: {why}")]
    NotIdentifiable {
        /// Which fit.
        what: String,
        /// Why not.
        why: String,
    },
    /// The data contradict the model: the residual is far above the noise.
    #[error("the recording is not consistent with Eq. 151: {why}")]
    Inconsistent {
        /// The numbers, and what may cause it.
        why: String,
    },
}

/// A stage of a commissioning sequence (`/sequence` of the recording).
#[derive(Clone, Debug, PartialEq)]
pub struct Stage {
    /// Start time \[s\].
    pub t: f64,
    /// Sequence name: `sweep`, `hold`, `step` or `drive`.
    pub name: String,
    /// The stepper angle the stage moves to \[deg\].
    pub theta_ct_deg: f64,
}

/// A commissioning recording as arrays (what `ivt rig identify` reads from
/// the MCAP channels).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Recording {
    /// Encoder pulses per revolution of θ.
    pub ppr: usize,
    /// θ at the first pulse \[rad\] (0: the encoder is zeroed at θ = 0).
    pub theta0: f64,
    /// Time of every encoder edge, consecutive pulses \[s\].
    pub pulse_t: Vec<f64>,
    /// Sensor samples (t \[s\], V_m \[V\], T_U \[N·m\]), by time.
    pub sensors: Vec<[f64; 3]>,
    /// Eccentricity samples (t \[s\], r \[m\]) from the stepper position
    /// (Eq. 185), by time; r holds until the next sample.
    pub eccentricity: Vec<(f64, f64)>,
    /// Stage starts, by time.
    pub stages: Vec<Stage>,
}

impl Recording {
    /// Angle per pulse 2π/PPR.
    pub fn dtheta(&self) -> f64 {
        TAU / self.ppr as f64
    }

    /// θ at pulse k.
    pub fn theta_of(&self, k: usize) -> f64 {
        self.theta0 + self.dtheta() * k as f64
    }

    /// r at time t (the last sample at or before t).
    pub fn eccentricity_at(&self, t: f64) -> Option<f64> {
        let k = self.eccentricity.partition_point(|s| s.0 <= t);
        self.eccentricity.get(k.checked_sub(1)?).map(|s| s.1)
    }

    /// True if a sample in (ta, tb] changes r.
    pub fn eccentricity_changes_in(&self, ta: f64, tb: f64) -> bool {
        let Some(r) = self.eccentricity_at(ta) else {
            return true;
        };
        let lo = self.eccentricity.partition_point(|s| s.0 <= ta);
        let hi = self.eccentricity.partition_point(|s| s.0 <= tb);
        self.eccentricity
            .get(lo..hi)
            .is_none_or(|s| s.iter().any(|x| x.1 != r))
    }

    /// (V_m, T_U) at time t, linear between sensor samples (None outside).
    pub fn inputs_at(&self, t: f64) -> Option<(f64, f64)> {
        let k = self.sensors.partition_point(|s| s[0] <= t);
        let hi = self.sensors.get(k)?;
        let lo = self.sensors.get(k.checked_sub(1)?)?;
        let w = (t - lo[0]) / (hi[0] - lo[0]);
        Some((lo[1] + w * (hi[1] - lo[1]), lo[2] + w * (hi[2] - lo[2])))
    }

    /// Start of the stage that holds t (−∞ before the first, or without stages).
    pub fn stage_start(&self, t: f64) -> f64 {
        let k = self.stages.partition_point(|s| s.t <= t);
        k.checked_sub(1)
            .and_then(|k| self.stages.get(k))
            .map_or(f64::NEG_INFINITY, |s| s.t)
    }

    /// End of the stage that holds t (the next start, +∞ for the last).
    pub fn stage_end(&self, t: f64) -> f64 {
        let k = self.stages.partition_point(|s| s.t <= t);
        self.stages.get(k).map_or(f64::INFINITY, |s| s.t)
    }

    /// True if t is at least [`SETTLE_S`] past the start of its stage.
    pub fn settled(&self, t: f64) -> bool {
        t - self.stage_start(t) >= SETTLE_S
    }

    /// This recording with every settled reading replaced by the value at
    /// its time of a straight line fitted to the settled readings of the
    /// same stage within ±[`SMOOTH_HALF_S`].
    pub fn with_smoothed_inputs(&self) -> Self {
        let mut out = self.clone();
        for (i, slot) in out.sensors.iter_mut().enumerate() {
            let Some(&[ti, ..]) = self.sensors.get(i) else {
                continue;
            };
            if !self.settled(ti) {
                continue;
            }
            let from = (ti - SMOOTH_HALF_S).max(self.stage_start(ti) + SETTLE_S);
            let to = (ti + SMOOTH_HALF_S).min(self.stage_end(ti));
            let lo = self.sensors.partition_point(|s| s[0] < from);
            let hi = self.sensors.partition_point(|s| s[0] < to);
            let Some(near) = self.sensors.get(lo..hi) else {
                continue;
            };
            if let (Some(v), Some(t)) = (line_at(near, 1, ti), line_at(near, 2, ti)) {
                *slot = [ti, v, t];
            }
        }
        out
    }

    /// Every second encoder edge and sensor reading, from `parity` (0 or 1):
    /// half of the data, its noise independent of the other half's (the
    /// instruments of [`identify`]). None for an odd PPR.
    pub fn half(&self, parity: usize) -> Option<Self> {
        if !self.ppr.is_multiple_of(2) || parity > 1 {
            return None;
        }
        Some(Self {
            ppr: self.ppr / 2,
            theta0: self.theta0 + self.dtheta() * parity as f64,
            pulse_t: self
                .pulse_t
                .iter()
                .skip(parity)
                .step_by(2)
                .copied()
                .collect(),
            sensors: self
                .sensors
                .iter()
                .skip(parity)
                .step_by(2)
                .copied()
                .collect(),
            eccentricity: self.eccentricity.clone(),
            stages: self.stages.clone(),
        })
    }

    /// Checks: PPR > 0, increasing finite pulse times, sorted finite samples.
    fn validate(&self) -> Result<(), IdentifyError> {
        let bad = |field, why: &str| IdentifyError::Recording {
            field,
            why: why.to_string(),
        };
        if self.ppr == 0 {
            return Err(bad("ppr", "must be > 0"));
        }
        let [lo, hi] = THETA0_RANGE;
        if !(lo..=hi).contains(&self.theta0) {
            return Err(IdentifyError::Recording {
                field: "theta0",
                why: format!("= {:e} rad is outside [−2π, 2π] rad", self.theta0),
            });
        }
        let increasing = |v: &[f64]| {
            v.iter().all(|x| x.is_finite()) && v.iter().zip(v.iter().skip(1)).all(|(a, b)| a <= b)
        };
        if !increasing(&self.pulse_t) {
            return Err(bad("pulse_t", "must be finite and non-decreasing"));
        }
        if !increasing(&self.sensors.iter().map(|s| s[0]).collect::<Vec<_>>())
            || self
                .sensors
                .iter()
                .any(|s| !(s[1].is_finite() && s[2].is_finite()))
        {
            return Err(bad("sensors", "must be finite and sorted by time"));
        }
        if !increasing(&self.eccentricity.iter().map(|s| s.0).collect::<Vec<_>>())
            || self.eccentricity.iter().any(|s| !s.1.is_finite())
        {
            return Err(bad("eccentricity", "must be finite and sorted by time"));
        }
        Ok(())
    }
}

/// Column `col` of `samples` fitted by a straight line in time, at t.
fn line_at(samples: &[[f64; 3]], col: usize, t: f64) -> Option<f64> {
    let n = samples.len() as f64;
    if n < 3.0 {
        return None;
    }
    let mean = |f: &dyn Fn(&[f64; 3]) -> f64| samples.iter().map(f).sum::<f64>() / n;
    let tm = mean(&|s| s[0]);
    let ym = mean(&|s| s.get(col).copied().unwrap_or(f64::NAN));
    let stt = mean(&|s| (s[0] - tm) * (s[0] - tm));
    let sty = mean(&|s| (s[0] - tm) * (s.get(col).copied().unwrap_or(f64::NAN) - ym));
    let slope = if stt > 0.0 { sty / stt } else { 0.0 };
    Some(ym + slope * (t - tm))
}

/// One identified coefficient: estimate and 95 % interval.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Estimate {
    /// The estimate.
    pub value: f64,
    /// 95 % interval \[lo, hi\].
    pub ci95: [f64; 2],
}

/// The names of [`Identification::estimates`], those of `ivt.kin.Plant.summary()`.
pub const NAMES: [&str; 7] = [
    "j_a",
    "j_b",
    "j_c",
    "j_d",
    "motor_damping",
    "motor_gain",
    "load_gain",
];

/// What a recording says about the plant.
#[derive(Clone, Debug, PartialEq)]
pub struct Identification {
    /// J_a, J_b, J_c, J_d, k_t k_e/R_a, k_t/R_a, 2√2/(π r_u), in [`NAMES`] order.
    pub estimates: [Estimate; 7],
    /// RMS residual of the window equations \[J\] (energy per window).
    pub residual_rms: f64,
    /// Window equations used.
    pub windows: usize,
    /// 1/condition number of the column-scaled regression.
    pub inverse_condition: f64,
    /// RMS of the equation noise the recording implies \[J\]: the RMS
    /// difference of the residuals of its two halves over the same
    /// windows, over √2.
    pub noise_rms: f64,
    /// RMS of the gravity work per window \[J\]: what fixes the scale.
    pub gravity_rms: f64,
    /// The electrical time constant L_a/R_a assumed \[s\] (the nominal
    /// plant's; 0: Eq. 138).
    pub lag_s: f64,
    /// What is doubtful but did not refuse the fit, one sentence each.
    pub warnings: Vec<String>,
    /// Fig. 47 and Fig. 50 (None without a stepper sweep in the recording).
    pub sweep: Option<SweepAnalysis>,
    /// Fig. 48's phase average (None without a `hold` stage).
    pub phase_average: Option<Vec<(f64, f64)>>,
}

impl Identification {
    /// The estimate named `name` (one of [`NAMES`]).
    pub fn get(&self, name: &str) -> Option<Estimate> {
        let k = NAMES.iter().position(|n| *n == name)?;
        self.estimates.get(k).copied()
    }

    /// The identified plant as Table 1 parameters, starting from `nominal`:
    /// k_e = damping/gain and k_t = gain·R_a (R_a kept: only k_t/R_a is
    /// identifiable); the parts of J_a scaled together to the identified
    /// J_a; J_N1 = J_d; m_r and m_dr scaled to J_b; r_u = 2√2/(π·load gain)
    /// and J_U from J_c at that r_u. J_b and J_c whose intervals include 0
    /// keep their nominal values.
    pub fn plant(&self, nominal: &PlantParams) -> PlantParams {
        let v = |k: usize| self.estimates.get(k).map_or(f64::NAN, |e| e.value);
        let significant = |k: usize| {
            self.estimates
                .get(k)
                .is_some_and(|e| e.ci95[0] > 0.0 && e.value > 0.0)
        };
        let mut p = *nominal;
        let (j_a, j_b, j_c, j_d) = (v(0), v(1), v(2), v(3));
        let (damping, gain, load) = (v(4), v(5), v(6));
        p.k_e = damping / gain;
        p.k_t = gain * nominal.r_a;
        let s = j_a / nominal.j_a();
        for x in [
            &mut p.j_n2,
            &mut p.j_carrier,
            &mut p.j_inshaft,
            &mut p.j_crk,
            &mut p.j_ring,
        ] {
            *x *= s;
        }
        p.j_n1 = j_d;
        if significant(1) {
            let s = j_b / nominal.j_b();
            p.m_r *= s;
            p.m_dr *= s;
        }
        p.r_u = 2.0 * SQRT_2 / (PI * load);
        p.j_u = if significant(2) {
            j_c * PI * PI * p.r_u * p.r_u / 8.0
        } else {
            nominal.j_c() * PI * PI * p.r_u * p.r_u / 8.0
        };
        p
    }
}

/// Identify Eq. 151's coefficients from a recording; `nominal` gives the
/// gravity gain (which must be the printed, known g), the motor's
/// electrical time constant L_a/R_a (Eq. 137, not identifiable; see the
/// module docs) and the starting point of [`Identification::plant`].
///
/// # Errors
/// [`IdentifyError::Recording`] for inconsistent arrays,
/// [`IdentifyError::NotIdentifiable`] when the windows do not excite a
/// coefficient (collinear regressors, or a 95 % interval that includes 0),
/// the gravity gain is unknown (G = m_r g) or the plant is not physical,
/// [`IdentifyError::Inconsistent`] when the residual exceeds
/// [`CONSISTENCY_LIMIT`] times the noise the recording implies.
pub fn identify(rec: &Recording, nominal: &PlantParams) -> Result<Identification, IdentifyError> {
    rec.validate()?;
    if nominal.gravity != GravityModel::Printed {
        return Err(IdentifyError::NotIdentifiable {
            what: "the scale of Eq. 151".into(),
            why: "with G = m_r g (sin θ + cos θ) no coefficient is known (see identify's docs)"
                .into(),
        });
    }
    let lag_s = nominal.l_a / nominal.r_a;
    // Regressors from one half of the edges and readings, instruments from
    // the other (regression::instrumental_variables), window by window.
    let halves = [rec.half(0), rec.half(1)];
    let [Some(h0), Some(h1)] = halves else {
        return Err(IdentifyError::Recording {
            field: "ppr",
            why: format!("= {} must be even (the two halves of the edges)", rec.ppr),
        });
    };
    let (rx, rz) = (
        windows::rows(&h0.with_smoothed_inputs(), lag_s),
        windows::rows(&h1.with_smoothed_inputs(), lag_s),
    );
    let by_key: std::collections::BTreeMap<i64, windows::Row> =
        rz.into_iter().map(|r| (r.key, r)).collect();
    let pairs: Vec<(windows::Row, windows::Row)> = rx
        .into_iter()
        .filter_map(|r| by_key.get(&r.key).map(|z| (r, *z)))
        .collect();
    let g = nominal.gravity_gain();
    let column = |i: usize, j: usize, second: bool| {
        pairs
            .get(i)
            .and_then(|(x, z)| if second { z } else { x }.x.get(j).copied())
            .unwrap_or(f64::NAN)
    };
    let x = DMatrix::from_fn(pairs.len(), windows::UNKNOWNS, |i, j| column(i, j, false));
    let z = DMatrix::from_fn(pairs.len(), windows::UNKNOWNS, |i, j| column(i, j, true));
    let y = DVector::from_iterator(pairs.len(), pairs.iter().map(|(r, _)| g * r.gravity));
    // Rows share smoothed readings over 2·SMOOTH_HALF_S: the HAC lag spans that.
    let span = match (pairs.first(), pairs.last()) {
        (Some(a), Some(b)) if pairs.len() > 1 => (b.0.t - a.0.t) / (pairs.len() - 1) as f64,
        _ => f64::INFINITY,
    };
    let lag = (2.0 * SMOOTH_HALF_S / span).ceil().clamp(1.0, 1e4) as usize + 2;
    let fit = regression::instrumental_variables(&x, &z, &y, lag, "Eq. 151")?;
    let mut estimates = [Estimate {
        value: f64::NAN,
        ci95: [f64::NAN; 2],
    }; 7];
    for ((e, v), h) in estimates.iter_mut().zip(&fit.params).zip(&fit.half_width) {
        *e = Estimate {
            value: *v,
            ci95: [v - h, v + h],
        };
    }
    let checks = Checks {
        noise_rms: noise_rms(&pairs, &fit.params, g),
        residual_rms: fit.residual_rms,
        gravity_rms: (y.norm_squared() / y.len().max(1) as f64).sqrt(),
    };
    let mut warnings = stuck_sensors(rec);
    checks.consistent(&mut warnings)?;
    checks.excited(&estimates, &mut warnings)?;
    let rec = &rec.with_smoothed_inputs();
    let at = |k: usize| estimates.get(k).map_or(f64::NAN, |e| e.value);
    let motor = steady::Motor {
        gain: at(5),
        damping: at(4),
        lag_s,
    };
    let sweep = steady::sweep_analysis(rec, motor)?;
    let id = Identification {
        estimates,
        residual_rms: fit.residual_rms,
        windows: fit.rows,
        inverse_condition: fit.inverse_condition,
        noise_rms: checks.noise_rms,
        gravity_rms: checks.gravity_rms,
        lag_s,
        warnings,
        sweep,
        phase_average: steady::phase_average(rec),
    };
    id.plant(nominal)
        .validate()
        .map_err(|e| IdentifyError::NotIdentifiable {
            what: "a physical plant".into(),
            why: format!("the identified {e}"),
        })?;
    Ok(id)
}

/// The RMS equation noise the two halves imply at the estimate `p`: the
/// residuals of a window from either half differ by their noise only (a
/// model error or a sensor's error is common to both), so the RMS of the
/// difference over √2 is the noise of one.
fn noise_rms(pairs: &[(windows::Row, windows::Row)], p: &[f64], g: f64) -> f64 {
    let residual =
        |r: &windows::Row| g * r.gravity - r.x.iter().zip(p).map(|(x, p)| x * p).sum::<f64>();
    let sum: f64 = pairs
        .iter()
        .map(|(x, z)| (residual(x) - residual(z)).powi(2))
        .sum();
    (sum / (2.0 * pairs.len().max(1) as f64)).sqrt()
}

/// A sensor that reads one value through every stage of a recording with
/// more than one: one warning per such channel.
fn stuck_sensors(rec: &Recording) -> Vec<String> {
    let mut out = Vec::new();
    if rec.stages.len() < 2 || rec.sensors.len() < 2 {
        return out;
    }
    for (col, name, unit) in [(1, "V_m", "V"), (2, "T_U", "N·m")] {
        let value = |s: &[f64; 3]| s.get(col).copied().unwrap_or(f64::NAN);
        let first = rec.sensors.first().map_or(f64::NAN, value);
        if rec.sensors.iter().all(|s| value(s) == first) {
            out.push(format!(
                "{name} reads {} {unit} in all {} readings over {} stages (a stuck sensor?)",
                // readings are f32 on the rig: its shortest digits
                first as f32,
                rec.sensors.len(),
                rec.stages.len()
            ));
        }
    }
    out
}

/// The numbers the consistency and excitation checks compare.
struct Checks {
    noise_rms: f64,
    residual_rms: f64,
    gravity_rms: f64,
}

/// The coefficients that fix the identified plant (J_b and J_c do not: a
/// J_b or J_c not determined keeps its nominal value).
const REQUIRED: [&str; 5] = ["j_a", "j_d", "motor_damping", "motor_gain", "load_gain"];

impl Checks {
    /// Residual against noise: refuse above [`CONSISTENCY_LIMIT`], warn
    /// above [`CONSISTENCY_WARN`]; the warnings so far (stuck sensors) name
    /// a likely cause.
    fn consistent(&self, warnings: &mut Vec<String>) -> Result<(), IdentifyError> {
        let ratio = if self.residual_rms == 0.0 {
            0.0
        } else {
            self.residual_rms / self.noise_rms
        };
        let text = format!(
            "the equation residual ({:.3e} J RMS per window) is {ratio:.2}× the noise the two halves \
             of the recording imply ({:.3e} J)",
            self.residual_rms, self.noise_rms
        );
        if ratio.is_nan() || ratio > CONSISTENCY_LIMIT {
            let cause = if warnings.is_empty() {
                "a sensor that is stuck or off scale, L_a other than the nominal plant's, or \
                 dynamics outside Eq. 151"
                    .to_string()
            } else {
                warnings.join("; ")
            };
            return Err(IdentifyError::Inconsistent {
                why: format!("{text}, above the limit {CONSISTENCY_LIMIT}× ({cause})"),
            });
        }
        if ratio > CONSISTENCY_WARN {
            warnings.push(format!(
                "{text}: model error beyond the noise, the intervals may be too narrow"
            ));
        }
        Ok(())
    }

    /// Each coefficient of [`REQUIRED`] with a 95 % interval above 0;
    /// J_b, J_c whose interval includes 0 are warned about.
    fn excited(
        &self,
        estimates: &[Estimate; 7],
        warnings: &mut Vec<String>,
    ) -> Result<(), IdentifyError> {
        for (name, e) in NAMES.iter().zip(estimates) {
            let [lo, hi] = e.ci95;
            if lo > 0.0 {
                continue;
            }
            let interval = format!(
                "{} = {:.4e}, 95 % interval [{lo:.4e}, {hi:.4e}]",
                name, e.value
            );
            if REQUIRED.contains(name) {
                let why = if hi < 0.0 {
                    let hint = if *name == "j_d" {
                        " (an armature inductance left out biases J_d by −L_a k_t k_e/R_a²: \
                         is the nominal plant's L_a the rig's?)"
                    } else {
                        ""
                    };
                    format!("{interval} lies below 0: not physical{hint}")
                } else {
                    format!(
                        "{interval} includes 0 (the gravity work that fixes the scale of Eq. 151 \
                         is {:.3e} J RMS per window against a residual of {:.3e} J)",
                        self.gravity_rms, self.residual_rms
                    )
                };
                return Err(IdentifyError::NotIdentifiable {
                    what: (*name).to_string(),
                    why,
                });
            }
            warnings.push(format!(
                "{interval} includes 0: not determined, its nominal value kept"
            ));
        }
        Ok(())
    }
}
