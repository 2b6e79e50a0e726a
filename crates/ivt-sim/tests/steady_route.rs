//! The steady-state route of scenes (issue 7, build item 7): a scene that
//! asks only for steady-state metrics at constant inputs is answered by the
//! IHB periodic steady state; forcing the time integration on the same scene
//! must give the same numbers (an independent method: the closed loop from
//! rest through the real controller, measured on its last revolution).
//! Timing belongs to `benches/steady_route.rs`.
// A test may unwrap (the package's panic lints guard library code).
#![allow(clippy::unwrap_used)]

use ivt_sim::record::Channel;
use ivt_sim::run::Simulation;
use ivt_sim::scene::Law;
use ivt_sim::scene::{ChannelSpec, Scene};
use ivt_sim::steady::{Route, SceneRun, SteadyMetrics};
use std::path::PathBuf;

fn scene(name: &str) -> Scene {
    let p = PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("../../scenes")
        .join(format!("{name}.toml"));
    Scene::load(&p).unwrap()
}

fn answer(s: &Scene, force: Option<Route>) -> SceneRun {
    Simulation::new(s).route(force).answer().unwrap()
}

/// Both routes on `s`; returns (IHB metrics, time-route metrics).
fn both(s: &Scene) -> (SteadyMetrics, SteadyMetrics) {
    let ihb = answer(s, None);
    assert_eq!(ihb.route, Route::IhbSteadyState, "{}", ihb.route_reason);
    assert!(ihb.run.is_none(), "the IHB route integrated a transient");
    let time = answer(s, Some(Route::TimeIntegration));
    assert_eq!(time.route, Route::TimeIntegration);
    let (a, b) = (ihb.steady.unwrap(), time.steady.unwrap());
    eprintln!("{}:\n  IHB  {a:?}\n  time {b:?}", s.name);
    (a, b)
}

fn rel(a: f64, b: f64) -> f64 {
    (a - b).abs() / b.abs()
}

/// r of one stepper step of the SGIVT map at 3200 steps/rev (Eq. 185):
/// 7π/51840 in/deg · 360/3200 deg = 1.2118e-6 m.
const STEP_M: f64 = 7.0 * std::f64::consts::PI / 51840.0 * 0.0254 * 360.0 / 3200.0;

/// The shipped scene (V_m = 8.4 V, T_U = 6 N·m, Eq. 180, inside the band).
/// Tolerances:
/// - ω_a: the IHB orbit has ω_a = ω0 exactly (Eq. 152); the loop holds it to
///   the integral's dither over ±1 stepper step (≈ 1.6e-4 rad/s per step,
///   crates/ivt-sim/tests/closed_loop.rs) → 2e-4 rad/s.
/// - r: the mean of that dither is within one step of r̄.
/// - min/max ω: the stepper dither (≈ 1.5e-5 relative); both routes sample
///   ω at the same pulse angles → 1e-4 relative.
#[test]
fn ihb_route_agrees_with_time_integration_inside_the_band() {
    let s = scene("steady_state");
    let (a, b) = both(&s);
    assert_eq!(a.verdict, Some("feasible"));
    assert_eq!(b.verdict, Some("feasible"));
    assert_eq!(a.static_error_rad_s, 0.0);
    assert!(b.static_error_rad_s.abs() < 2e-4, "{b:?}");
    assert!((a.r_m - b.r_m).abs() < STEP_M, "r {} vs {}", a.r_m, b.r_m);
    assert!(rel(a.omega_min_rad_s, b.omega_min_rad_s) < 1e-4);
    assert!(rel(a.omega_max_rad_s, b.omega_max_rad_s) < 1e-4);
    // The gains of the scene are stable there (§4.3): the loop reaches the orbit.
    let m = a.max_abs_multiplier.unwrap();
    assert!(m < 1.0, "max |multiplier| {m}");
}

/// Outside the band (the thesis's 7 V at 8 N·m, under-drive): the delay law
/// saturates at r = 0 and the plant runs at its free speed there. No dither
/// now (r = 0 exactly), so the two routes agree to the integrators'
/// accuracy: ω_a to 1e-6 relative (time route: the integrator error ~1e-9 and
/// one revolution of exact pulse times; IHB route: shooting to 1e-13), and
/// min/max, sampled at the same pulse angles, to 1e-6.
#[test]
fn ihb_route_agrees_with_time_integration_when_saturated() {
    let mut s = scene("steady_state");
    s.inputs.v_m = vec![[0.0, 7.0]];
    s.inputs.t_u = vec![[0.0, 8.0]];
    s.duration_s = 10.0;
    let (a, b) = both(&s);
    assert_eq!(a.verdict, Some("under-drive"));
    assert_eq!(b.verdict, Some("under-drive"));
    assert!(a.r_bar_m.unwrap() < 0.0 && a.r_m == 0.0 && b.r_m == 0.0);
    // SPEC §5: the no-load speed at 7 V is ≈ 89 rpm.
    let rpm = a.omega_a_rad_s * 30.0 / std::f64::consts::PI;
    assert!((rpm - 89.0).abs() < 1.0, "{rpm} rpm");
    assert!(rel(a.omega_a_rad_s, b.omega_a_rad_s) < 1e-6);
    assert!(rel(a.omega_min_rad_s, b.omega_min_rad_s) < 1e-6);
    assert!(rel(a.omega_max_rad_s, b.omega_max_rad_s) < 1e-6);
    assert!(a.max_abs_multiplier.is_none());
}

/// The open law with the refitted u_ol: r = u_ol on the stepper's step, and
/// the mean speed is ω0 up to the fit error of the law (≤ 0.114 rpm over the
/// grid, refit.rs header) — here both routes agree on it to 1e-6.
#[test]
fn ihb_route_agrees_with_time_integration_open_loop() {
    let mut s = scene("steady_state");
    s.controller.law = Law::Open;
    s.duration_s = 10.0;
    let (a, b) = both(&s);
    // Both hold u_ol on the same stepper step (steps/steps_per_metre vs
    // position·r_per_step: equal up to one f64 rounding).
    assert!((a.r_m - b.r_m).abs() < 1e-15, "r {} vs {}", a.r_m, b.r_m);
    assert!(rel(a.omega_a_rad_s, b.omega_a_rad_s) < 1e-6);
    assert!(rel(a.omega_min_rad_s, b.omega_min_rad_s) < 1e-4);
    assert!(rel(a.omega_max_rad_s, b.omega_max_rad_s) < 1e-4);
    let fit_err_rpm = a.static_error_rad_s.abs() * 30.0 / std::f64::consts::PI;
    assert!(fit_err_rpm < 0.114, "{fit_err_rpm} rpm");
}

/// Anything beyond steady-state metrics sends the scene to the time
/// integration, with the reason in the summary; forcing the IHB route then
/// is an error naming the key.
#[test]
fn scenes_that_need_a_transient_take_the_time_route() {
    let mut s = scene("steady_state");
    s.duration_s = 2.0;
    s.outputs.channels.push(ChannelSpec {
        name: Channel::Plant,
        every: 100,
    });
    let r = answer(&s, None);
    assert_eq!(r.route, Route::TimeIntegration);
    assert!(r.route_reason.contains("channels"), "{}", r.route_reason);
    // the per-pulse recording for the steady metrics is decimated back
    let n = r
        .run
        .as_ref()
        .unwrap()
        .channels
        .plant
        .as_ref()
        .unwrap()
        .len();
    let pulses = r.run.as_ref().unwrap().summary.pulses as usize;
    assert_eq!(n, pulses.div_ceil(100));
    assert!(r.run.as_ref().unwrap().channels.control.is_none());
    let j = r.summary_json(&s);
    assert_eq!(j["route"], "time_integration");
    assert!(j["steady_state"]["omega_a_rad_s"].is_number());

    let mut n = scene("steady_state");
    n.controller.law = Law::NoDelay;
    assert!(Simulation::new(&n)
        .route(Some(Route::IhbSteadyState))
        .answer()
        .is_err());
    let mut ramp = scene("steady_state");
    ramp.inputs.v_m = vec![[0.0, 8.4], [1.0, 8.5]];
    assert!(ramp.ihb_route_blocker().unwrap().contains("constant"));

    let src = std::fs::read_to_string(
        PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../scenes/steady_state.toml"),
    )
    .unwrap()
    .replace(
        "route = \"auto\"",
        "route = \"ihb_steady_state\"\nmcap = true",
    );
    let e = Scene::parse(&src, "s.toml").unwrap_err().message;
    assert!(e.contains("outputs.route") && e.contains("MCAP"), "{e}");
    let e = Scene::parse(
        &src.replace("route = \"ihb_steady_state\"", "route = \"fast\""),
        "s.toml",
    )
    .unwrap_err()
    .message;
    assert!(e.contains("outputs.route"), "{e}");
}

/// The summary JSON of the IHB route says which route was taken and carries
/// the metrics; nothing else was computed.
#[test]
fn ihb_summary_names_the_route() {
    let s = scene("steady_state");
    let r = answer(&s, None);
    let j = r.summary_json(&s);
    assert_eq!(j["route"], "ihb_steady_state");
    assert_eq!(j["steady_state"]["verdict"], "feasible");
    assert!(j["steady_state"]["r_bar_m"].as_f64().unwrap() > 0.0);
    assert!(j.get("pulses").is_none());
}

/// With gains whose linearized delay loop is unstable there (k = 20,
/// k2 = 1 mm·rad⁻¹: max |multiplier| 1.73 at 8.4 V / 6 N·m), "auto" does not
/// report the IHB orbit the loop would never reach: it falls back to the
/// time integration and says why; forcing the IHB route still answers, with
/// the multiplier in the metrics.
#[test]
fn unstable_gains_fall_back_to_time_integration() {
    let mut s = scene("steady_state");
    s.controller.k_mm_per_rad = 20.0;
    s.duration_s = 2.0;
    let r = answer(&s, None);
    assert_eq!(r.route, Route::TimeIntegration);
    assert!(r.route_reason.contains("unstable"), "{}", r.route_reason);
    let forced = answer(&s, Some(Route::IhbSteadyState));
    let m = forced.steady.unwrap().max_abs_multiplier.unwrap();
    assert!(m > 1.0, "{m}");
}
