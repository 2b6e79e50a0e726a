//! `ivt sim SCENE.toml [--out DIR]` and the no-argument default run.

use super::{CliError, Output};
use clap::{Args, ValueEnum};
use ivt_sim::output::{run_and_write, write_outputs};
use ivt_sim::progress::Progress;
use ivt_sim::run::Simulation;
use ivt_sim::scene::Scene;
use ivt_sim::steady::{Route, SceneRun};
use serde_json::json;
use std::path::{Path, PathBuf};

/// The default drive cycle (Fig. 51 shape), embedded so that `ivt` runs from any directory.
pub const DEFAULT_SCENE: &str = include_str!("../../scenes/drive.toml");

/// Arguments of `ivt sim`.
#[derive(Args)]
pub struct SimArgs {
    /// Scene file (TOML); see scenes/ and the guide's Scenes chapter (docs/guide/src/controller/scenes.md).
    pub scene: PathBuf,
    /// Directory for the outputs the scene asks for.
    #[arg(long, default_value = "out")]
    pub out: PathBuf,
    /// Processor in the loop: run the controller in the QEMU firmware
    /// (`firmware/run-qemu.sh build` first; `$IVT_FW_ELF` overrides the image).
    #[arg(long)]
    pub pil: bool,
    /// Override the scene's `outputs.route`: answer a steady-state-only
    /// scene by the IHB steady state or force the time integration.
    #[arg(long, value_enum)]
    pub route: Option<RouteArg>,
    /// Work budget of a time integration: the most encoder pulses + sensor
    /// readings + fixed RK4 steps the run may meet. The scene's count is
    /// estimated before anything runs and a scene above the limit is refused
    /// with the estimate (the default, 1e9, is ~40 min of wall time).
    #[arg(long, default_value_t = ivt_sim::scene::DEFAULT_MAX_EVENTS)]
    pub max_events: f64,
}

/// `--route` on the command line.
#[derive(Clone, Copy, Debug, ValueEnum)]
#[value(rename_all = "snake_case")]
pub enum RouteArg {
    /// The periodic steady state by the modified IHB (no transient).
    IhbSteadyState,
    /// Closed-loop time integration.
    TimeIntegration,
}

impl From<RouteArg> for Route {
    fn from(r: RouteArg) -> Self {
        match r {
            RouteArg::IhbSteadyState => Route::IhbSteadyState,
            RouteArg::TimeIntegration => Route::TimeIntegration,
        }
    }
}

/// Run a scene file.
///
/// # Errors
/// Scene errors as [`CliError::Input`], unreadable scenes and unwritable
/// outputs as [`CliError::Io`], failed runs as [`CliError::Failed`].
pub fn run_file(args: &SimArgs, json: bool) -> Result<Output, CliError> {
    let scene = Scene::load(&args.scene)?;
    let route = if args.pil {
        if matches!(args.route, Some(RouteArg::IhbSteadyState)) {
            return Err(CliError::Input(
                "--pil runs the firmware in the loop: it needs --route time_integration".into(),
            ));
        }
        Some(Route::TimeIntegration)
    } else {
        args.route.map(Route::from)
    };
    super::check_flag("--max-events", "budget.max_events", args.max_events)?;
    run_scene(&scene, &args.out, json, args.pil, route, args.max_events)
}

/// `ivt` with no arguments: the default drive scene into `out/`.
///
/// # Errors
/// As [`run_file`].
pub fn run_default(json: bool) -> Result<Output, CliError> {
    let scene = Scene::parse(DEFAULT_SCENE, "scenes/drive.toml")?;
    let max_events = ivt_sim::scene::DEFAULT_MAX_EVENTS;
    run_scene(&scene, Path::new("out"), json, false, None, max_events)
}

fn run_scene(
    scene: &Scene,
    out: &Path,
    json: bool,
    pil: bool,
    route: Option<Route>,
    max_events: f64,
) -> Result<Output, CliError> {
    let mut bar = Progress::new(!json && scene.duration_s >= 5.0, &scene.name);
    let (answered, paths) = if pil {
        scene.check_events(max_events).map_err(CliError::Input)?;
        let r = ivt_sim::pil::run_pil(scene, &mut |f| bar.update(f))?;
        bar.finish();
        let mut answered = SceneRun::time_integration(scene, r);
        answered.route_reason = "processor in the loop".into();
        let paths = write_outputs(out, scene, &answered)?;
        (answered, paths)
    } else if !scene.outputs.steady_state && route != Some(Route::IhbSteadyState) {
        // A transient is asked for: the MCAP log is written by a thread while
        // the loop runs, the other files and the summary after it, all
        // renamed into place together.
        run_and_write(out, scene, |sink| {
            let r = Simulation::new(scene)
                .route(route)
                .max_events(max_events)
                .progress(&mut |f| bar.update(f))
                .sink(sink)
                .answer_by_time_integration();
            bar.finish();
            r
        })?
    } else {
        let answered = Simulation::new(scene)
            .route(route)
            .max_events(max_events)
            .progress(&mut |f| bar.update(f))
            .answer()?;
        bar.finish();
        let paths = write_outputs(out, scene, &answered)?;
        (answered, paths)
    };
    let summary = answered.summary_json(scene);
    let outputs: Vec<String> = paths.iter().map(|p| p.display().to_string()).collect();
    let route_line = format!(
        "route: {} ({})\n",
        answered.route.as_str(),
        answered.route_reason
    );
    let Some(result) = &answered.run else {
        let m = answered.steady.as_ref();
        let rpm = 60.0 / std::f64::consts::TAU;
        let mut human = format!("scene `{}`: {route_line}", scene.name);
        if let Some(m) = m {
            human.push_str(&format!(
                "steady state in {:.2} ms: ω_a {:.4} rpm (target {:.4}, error {:.2e} rad/s), ω ∈ [{:.4}, {:.4}] rpm, r = {:.6} mm, r̄ = {} mm, {}{}\n  method: {}\n",
                1e3 * answered.wall_time_s,
                m.omega_a_rad_s * rpm,
                m.omega0_rad_s * rpm,
                m.static_error_rad_s,
                m.omega_min_rad_s * rpm,
                m.omega_max_rad_s * rpm,
                1e3 * m.r_m,
                m.r_bar_m.map_or("—".into(), |r| format!("{:.6}", 1e3 * r)),
                m.verdict.unwrap_or("—"),
                m.max_abs_multiplier.map_or(String::new(), |x| format!(", delay loop max |multiplier| {x:.4}")),
                m.method,
            ));
        }
        for p in &outputs {
            human.push_str(&format!("wrote {p}\n"));
        }
        return Ok(Output {
            json: json!({ "summary": summary, "outputs": outputs }),
            human,
        });
    };
    let s = &result.summary;
    let rpm = 60.0 / std::f64::consts::TAU;
    let mut human = format!(
        "scene `{}`: {} s simulated in {:.3} s ({:.0}× real time), {} pulses, law {}\n\
         ω_a: settling {} , overshoot {:.2} %, static error {:.2e} rad/s ({:.4} rpm), final {:.3} rpm\n\
         r: RMS dr/dθ {:.3e} m/rad, max |dr/dt| {:.3e} m/s, saturated {:.1} % of pulses\n",
        s.scene,
        s.duration_s,
        s.wall_time_s,
        s.realtime_factor,
        s.pulses,
        s.law.name(),
        s.settling_time_s.map_or("never".to_string(), |t| format!("{t:.2} s")),
        s.overshoot_pct,
        s.static_error_rad_s,
        s.static_error_rad_s * rpm,
        s.final_omega_a_rad_s * rpm,
        s.rms_control_effort_m_per_rad,
        s.max_abs_dr_dt_m_per_s,
        100.0 * s.saturated_fraction,
    );
    human.push_str(&route_line);
    if let Some(m) = &answered.steady {
        human.push_str(&format!(
            "steady state (last revolution): ω_a {:.4} rpm, ω ∈ [{:.4}, {:.4}] rpm, r = {:.6} mm\n",
            m.omega_a_rad_s * rpm,
            m.omega_min_rad_s * rpm,
            m.omega_max_rad_s * rpm,
            1e3 * m.r_m
        ));
    }
    if outputs.is_empty() {
        human.push_str("no outputs requested\n");
    } else {
        human.push_str("wrote:\n");
        for p in &outputs {
            human.push_str(&format!("  {p}\n"));
        }
    }
    Ok(Output {
        json: json!({ "summary": summary, "outputs": outputs }),
        human,
    })
}
