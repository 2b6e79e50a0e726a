//! Two routes to a scene's answer (SPEC §3: "no transient where only a steady
//! state is asked — then it uses the HB solution"; thesis §4.2.1: the
//! periodic steady state is what the design needs, and harmonic balance
//! reaches it without integrating the start-up).
//!
//! - [`Route::IhbSteadyState`]: the scene asks only for steady-state metrics
//!   (`outputs.steady_state = true`, no channels, plots, MCAP or CSV) at
//!   constant inputs, with a law whose equilibrium is the periodic orbit at
//!   constant r (`delay`, `open`, `none`), and with no random disturbances
//!   ([`Scene::ihb_route_blocker`]). Then:
//!   1. the modified IHB (Eq. 152–157, the thesis's n = 7) gives r̄ for ω0,
//!      polished by shooting in θ (Eq. 162, ~1e-12), and the verdict
//!      under-drive / feasible / over-drive;
//!   2. the r the loop holds: r̄ for the delay law inside the band (Eq. 180
//!      is at rest when ω_a = ω0 and ω = ω_T), the bound 0 or r_max outside it
//!      (anti-windup), u_ol(V_m, T_U) of the controller's own f32 law for
//!      `open`, the scheduled r for `none` — each rounded to the stepper's
//!      step, as the simulated stepper holds it;
//!   3. the periodic orbit at that r (the polished one inside the band,
//!      shooting at fixed r outside), which gives the mean speed;
//!   4. ω at the encoder pulse angles θ_k = 2πk/PPR by one RK6 revolution of
//!      that orbit. (The truncated IHB series itself converges only like 1/n
//!      at the kinks of ω(θ) at the gear corners: min/max ω were 8e-5
//!      relative off at n = 63 and 4e-5 at n = 127, and n = 127 cost more
//!      than the 20 s time integration — so the series gives r̄, and one
//!      revolution of the ODE gives the samples.)
//!
//!   For the delay law inside the band the route also checks that the loop
//!   reaches that orbit: the max |Floquet multiplier| of the linearized delay
//!   system (Eq. 174–179, `ivt_design::delay`) for the scene's gains. If it
//!   is ≥ 1, `"auto"` falls back to time integration. The check assumes an
//!   ideal actuator: a stepper rate limit can still turn a linearly stable
//!   loop into a limit cycle (the guide's gains chapter: k2 = 4 at the shipped point).
//! - [`Route::TimeIntegration`]: the closed-loop simulation ([`Simulation::run`]).
//!   If the scene asks for steady-state metrics, they are measured on the
//!   last revolution of θ (per-pulse plant and control samples are recorded
//!   for that and decimated back to what the scene asked for).

use crate::error::SimError;
use crate::record::Channel;
use crate::run::{RunResult, Simulation};
use crate::scene::{ChannelSpec, Law, Scene};
use ivt_ctrl::{ActuatorMap, OpenLoopPreset};
use ivt_design::delay::{delay_stability_about, steady_orbit, DelayOptions, FeedbackGains};
use ivt_design::shooting::{omega_at_angles, periodic_at_r, ShootingOptions};
use ivt_design::steady::{IhbOptions, IhbSolver};
use ivt_design::{OperatingPoint, Verdict};
use serde::Serialize;
use std::time::Instant;

pub use crate::scene::Route;

/// Steady-state metrics of a scene at its constant inputs.
#[derive(Clone, Debug, Serialize, PartialEq)]
pub struct SteadyMetrics {
    /// Target ω0 \[rad/s\].
    pub omega0_rad_s: f64,
    /// Mean speed of the periodic state, ω_a = 2π/T (the time mean of ω over
    /// a revolution, §4.3) \[rad/s\].
    pub omega_a_rad_s: f64,
    /// ω_a − ω0 \[rad/s\].
    pub static_error_rad_s: f64,
    /// Smallest ω at the encoder pulse angles over a revolution \[rad/s\].
    pub omega_min_rad_s: f64,
    /// Largest ω at the encoder pulse angles over a revolution \[rad/s\].
    pub omega_max_rad_s: f64,
    /// Eccentricity held (time-integration route: mean over the last
    /// revolution) \[m\].
    pub r_m: f64,
    /// Unconstrained r̄ for ω0 (IHB route only: the IHB value polished by
    /// shooting) \[m\].
    pub r_bar_m: Option<f64>,
    /// `"under-drive"`, `"feasible"` or `"over-drive"` for ω0 (IHB: from r̄;
    /// time integration: from the delay law's saturation; None otherwise).
    pub verdict: Option<&'static str>,
    /// `verdict == "feasible"`.
    pub feasible: Option<bool>,
    /// Delay law inside the band, IHB route: max |Floquet multiplier| of the
    /// linearized delay loop (Eq. 179) for the scene's gains (< 1: the loop
    /// reaches this orbit).
    pub max_abs_multiplier: Option<f64>,
    /// How the numbers were obtained.
    pub method: String,
}

/// A scene's answer: the route taken, why, and its results.
#[derive(Clone, Debug)]
pub struct SceneRun {
    /// Route taken.
    pub route: Route,
    /// Why this route (one line).
    pub route_reason: String,
    /// Steady-state metrics (if the scene asked for them).
    pub steady: Option<SteadyMetrics>,
    /// The time integration (time route only).
    pub run: Option<RunResult>,
    /// Wall-clock time of the whole answer \[s\].
    pub wall_time_s: f64,
}

impl Simulation<'_> {
    /// Answer the scene by the route its `outputs.route` asks for, or the
    /// one forced by [`Simulation::route`] (e.g. the CLI's `--route`).
    /// `"auto"` takes the IHB route when [`Scene::ihb_route_blocker`] finds
    /// nothing in the way and the delay loop is stable there.
    ///
    /// # Errors
    /// A forced IHB route on a scene that cannot take it, or a failure of
    /// the route taken.
    pub fn answer(self) -> Result<SceneRun, SimError> {
        answer(self.scene, self.route, self.progress, self.max_events)
    }

    /// The time integration ([`Simulation::run`]) as the scene's answer,
    /// without steady-state metrics: the route reason is `"forced"` when
    /// [`Simulation::route`] forced it, else as
    /// [`SceneRun::time_integration`] gives it.
    ///
    /// # Errors
    /// As [`Simulation::run`].
    pub fn answer_by_time_integration(self) -> Result<SceneRun, SimError> {
        let (scene, forced) = (self.scene, self.route.is_some());
        let mut answer = SceneRun::time_integration(scene, self.run()?);
        if forced {
            answer.route_reason = "forced".into();
        }
        Ok(answer)
    }
}

fn answer(
    scene: &Scene,
    force: Option<Route>,
    progress: Option<&mut dyn FnMut(f64)>,
    max_events: f64,
) -> Result<SceneRun, SimError> {
    let wall = Instant::now();
    let asked = force.or_else(|| scene.outputs.route.forced());
    let blocker = scene.ihb_route_blocker();
    let (route, mut reason) = match (asked, blocker) {
        (Some(Route::TimeIntegration), _) => (Route::TimeIntegration, "forced".to_string()),
        (Some(Route::IhbSteadyState), Some(why)) => {
            return Err(SimError::Scene(format!(
                "route \"ihb_steady_state\" is not possible: {why}"
            )))
        }
        (Some(Route::IhbSteadyState), None) => (Route::IhbSteadyState, "forced".to_string()),
        (None, Some(why)) => (Route::TimeIntegration, why),
        (None, None) => (
            Route::IhbSteadyState,
            "only steady-state metrics at constant inputs are asked".to_string(),
        ),
    };
    if route == Route::IhbSteadyState {
        let steady = ihb_steady_state(scene)?;
        let unstable = steady.max_abs_multiplier.filter(|&m| m >= 1.0);
        match unstable {
            Some(m) if asked.is_none() => {
                reason = format!(
                    "the delay loop is unstable at this point (max |multiplier| = {m:.4} ≥ 1): the IHB orbit is not what it reaches"
                );
            }
            _ => {
                return Ok(SceneRun {
                    route,
                    route_reason: reason,
                    steady: Some(steady),
                    run: None,
                    wall_time_s: wall.elapsed().as_secs_f64(),
                })
            }
        }
    }
    let (result, steady) = time_route(scene, progress, max_events)?;
    Ok(SceneRun {
        route: Route::TimeIntegration,
        route_reason: reason,
        steady,
        run: Some(result),
        wall_time_s: wall.elapsed().as_secs_f64(),
    })
}

impl SceneRun {
    /// The answer of a time integration `run` of `scene` without
    /// steady-state metrics: why it was not the IHB route is the scene's
    /// [`Scene::ihb_route_blocker`], or `"forced"` when nothing blocks it.
    #[must_use]
    pub fn time_integration(scene: &Scene, run: RunResult) -> Self {
        Self {
            route: Route::TimeIntegration,
            route_reason: scene.ihb_route_blocker().unwrap_or_else(|| "forced".into()),
            steady: None,
            wall_time_s: run.summary.wall_time_s,
            run: Some(run),
        }
    }

    /// The summary JSON: the time integration's [`crate::run::Summary`]
    /// fields (time route), plus `route`, `route_reason`, `steady_state` and
    /// `wall_time_s` (the whole answer).
    #[must_use]
    pub fn summary_json(&self, scene: &Scene) -> serde_json::Value {
        let mut v = match &self.run {
            Some(r) => serde_json::to_value(&r.summary).unwrap_or_default(),
            None => serde_json::json!({
                "scene": scene.name,
                "law": scene.controller.law,
                "ppr": scene.encoder.ppr,
                "omega0_rad_s": scene.omega0_rad_s(),
            }),
        };
        if let Some(m) = v.as_object_mut() {
            m.insert("route".into(), self.route.as_str().into());
            m.insert("route_reason".into(), self.route_reason.clone().into());
            m.insert(
                "steady_state".into(),
                serde_json::to_value(&self.steady).unwrap_or_default(),
            );
            m.insert("wall_time_s".into(), self.wall_time_s.into());
        }
        v
    }
}

/// The IHB route (module doc). The scene must pass
/// [`Scene::ihb_route_blocker`].
///
/// # Errors
/// An IHB or shooting solve that does not converge (with its residual
/// history), a stall, or a plant the solver refuses.
pub fn ihb_steady_state(scene: &Scene) -> Result<SteadyMetrics, SimError> {
    if let Some(why) = scene.ihb_route_blocker() {
        return Err(SimError::Scene(why));
    }
    let params = scene
        .plant_params()
        .map_err(|e| SimError::Scene(e.to_string()))?;
    let c = &scene.controller;
    let (Some(&[_, v_m]), Some(&[_, t_u])) = (scene.inputs.v_m.first(), scene.inputs.t_u.first())
    else {
        return Err(SimError::Scene(
            "inputs.v_m and inputs.t_u need a knot".into(),
        ));
    };
    let op = OperatingPoint {
        v_m,
        t_u,
        omega0: scene.omega0_rad_s(),
    };
    let ihb = IhbSolver::new(IhbOptions::default())?.solve(&params, &op, None)?;
    // Polish r̄ by shooting (the n = 7 IHB r̄ is ~1e-3 relative off: ω̄ has
    // kinks) so that points near a band edge are classified on the right
    // side; if the orbit at ω0 cannot be followed (a stall far outside the
    // band), the IHB value decides.
    let exact = steady_orbit(&params, &op, Some(ihb.r), &DelayOptions::default()).ok();
    let r_bar = exact.as_ref().map_or(ihb.r, |o| o.r);
    let verdict = Verdict::classify(r_bar, params.r_max);
    let map = ActuatorMap::sgivt(scene.stepper.steps_per_rev as f32);
    let on_step = |r: f64| f64::from(map.steps(r as f32)) / f64::from(map.steps_per_metre);
    let n = IhbOptions::default().harmonics;
    let (held, what) = match c.law {
        Law::Delay => match verdict {
            Verdict::Feasible => (None, "Eq. 180 holds ω_a = ω0 with r = r̄".to_string()),
            Verdict::UnderDrive => (
                Some(on_step(0.0)),
                "delay law saturated at r = 0 (anti-windup)".into(),
            ),
            Verdict::OverDrive => (
                Some(on_step(params.r_max)),
                "delay law saturated at r = r_max (anti-windup)".into(),
            ),
        },
        Law::Open => {
            let preset = OpenLoopPreset::from(c.open_loop);
            let mut coeffs = preset.coeffs();
            coeffs.r_max = params.r_max as f32;
            let u = if c.feedforward {
                coeffs.evaluate(op.v_m as f32, op.t_u as f32).r_ol
            } else {
                0.0
            };
            (
                Some(on_step(f64::from(u))),
                format!("r = u_ol(V_m, T_U) of the \"{}\" law (the controller's f32 value, on the stepper's step)", preset.name()),
            )
        }
        _ => (
            Some(c.r_schedule.first().map_or(0.0, |k| k[1])),
            "r from the schedule".into(),
        ),
    };
    let shooting = ShootingOptions::default();
    let orbit = match (held, exact) {
        (None, Some(o)) => o,
        (None, None) => steady_orbit(&params, &op, Some(ihb.r), &DelayOptions::default())?,
        (Some(r), _) => periodic_at_r(&params, op.v_m, op.t_u, r, op.omega0, &shooting)?,
    };
    let max_abs_multiplier = if held.is_none() && c.law == Law::Delay {
        let gains = FeedbackGains::from_thesis_mm_per_rad(c.k_mm_per_rad, c.k2_mm_per_rad);
        let s = delay_stability_about(&params, &op, gains, &orbit, &DelayOptions::default())?;
        Some(s.max_abs_multiplier)
    } else {
        None
    };
    let omega = omega_at_angles(
        &params,
        op.v_m,
        op.t_u,
        orbit.r,
        orbit.omega_start,
        scene.encoder.ppr,
        shooting.steps_per_segment,
    )?;
    let (lo, hi) = omega
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), &w| {
            (lo.min(w), hi.max(w))
        });
    let omega_a = orbit.omega_a();
    Ok(SteadyMetrics {
        omega0_rad_s: op.omega0,
        omega_a_rad_s: omega_a,
        static_error_rad_s: omega_a - op.omega0,
        omega_min_rad_s: lo,
        omega_max_rad_s: hi,
        r_m: orbit.r,
        r_bar_m: Some(r_bar),
        verdict: Some(verdict.as_str()),
        feasible: Some(verdict == Verdict::Feasible),
        max_abs_multiplier,
        method: format!(
            "modified IHB (n = {n}, {} iterations, residual {:.1e}): r̄ = {:.6e} m, polished by shooting in θ to {:.6e} m for the verdict; {what}; the periodic orbit at that r sampled at the {} pulse angles by RK6",
            ihb.iterations, ihb.residual_norm, ihb.r, r_bar, scene.encoder.ppr
        ),
    })
}

/// The time route; with `steady_state` asked, per-pulse plant and control
/// samples are recorded for the last-revolution metrics and then decimated
/// back to the channels the scene asked for (every n-th pulse from the
/// first, as [`crate::run`] records them).
fn time_route(
    scene: &Scene,
    progress: Option<&mut dyn FnMut(f64)>,
    max_events: f64,
) -> Result<(RunResult, Option<SteadyMetrics>), SimError> {
    let run = |s: &Scene, progress: Option<&mut dyn FnMut(f64)>| match progress {
        Some(p) => Simulation::new(s).max_events(max_events).progress(p).run(),
        None => Simulation::new(s).max_events(max_events).run(),
    };
    if !scene.outputs.steady_state {
        return Ok((run(scene, progress)?, None));
    }
    let (every_plant, every_control) = (
        scene.outputs.every(Channel::Plant),
        scene.outputs.every(Channel::Control),
    );
    let mut s = scene.clone();
    s.outputs
        .channels
        .retain(|c| !matches!(c.name, Channel::Plant | Channel::Control));
    for name in [Channel::Plant, Channel::Control] {
        s.outputs.channels.push(ChannelSpec { name, every: 1 });
    }
    let mut result = run(&s, progress)?;
    let steady = last_revolution(scene, &result);
    let ch = &mut result.channels;
    ch.plant = ch.plant.take().and_then(|v| decimate(v, every_plant));
    ch.control = ch.control.take().and_then(|v| decimate(v, every_control));
    Ok((result, steady))
}

fn decimate<T>(v: Vec<T>, every: Option<usize>) -> Option<Vec<T>> {
    let e = every?;
    Some(v.into_iter().step_by(e.max(1)).collect())
}

/// Steady-state metrics on the last revolution of a run with per-pulse
/// plant and control samples (None if it had less than one revolution).
fn last_revolution(scene: &Scene, result: &RunResult) -> Option<SteadyMetrics> {
    let ppr = scene.encoder.ppr;
    let plant = result.channels.plant.as_ref()?;
    let control = result.channels.control.as_ref();
    let last = plant.last()?;
    if plant.len() < ppr + 1 || !last.omega_a.is_finite() {
        return None;
    }
    let rev = plant.get(plant.len() - ppr..)?;
    let (lo, hi) = rev
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), p| {
            (lo.min(p.omega), hi.max(p.omega))
        });
    let r_m = rev.iter().map(|p| p.r).sum::<f64>() / ppr as f64;
    let r_max = scene.plant_params().ok()?.r_max;
    let verdict = match (scene.controller.law, control.and_then(|c| c.last())) {
        (Law::Delay, Some(c)) if c.out.saturated && c.out.r <= 0.0 => Some(Verdict::UnderDrive),
        (Law::Delay, Some(c)) if c.out.saturated && f64::from(c.out.r) >= r_max * (1.0 - 1e-6) => {
            Some(Verdict::OverDrive)
        }
        (Law::Delay, Some(_)) => Some(Verdict::Feasible),
        _ => None,
    };
    let omega0 = scene.omega0_rad_s();
    Some(SteadyMetrics {
        omega0_rad_s: omega0,
        omega_a_rad_s: last.omega_a,
        static_error_rad_s: last.omega_a - omega0,
        omega_min_rad_s: lo,
        omega_max_rad_s: hi,
        r_m,
        r_bar_m: None,
        verdict: verdict.map(|v| v.as_str()),
        feasible: verdict.map(|v| v == Verdict::Feasible),
        max_abs_multiplier: None,
        method: format!(
            "closed-loop time integration for {} s; metrics over the last revolution ({ppr} pulses)",
            scene.duration_s
        ),
    })
}
