//! `ivt sim SCENE.toml [--out DIR]` and the no-argument default run.

use super::{CliError, Output};
use clap::Args;
use ivt_sim::output::{run_and_write, write_all};
use ivt_sim::progress::Progress;
use ivt_sim::run::run_to;
use ivt_sim::scene::Scene;
use serde_json::json;
use std::path::{Path, PathBuf};

/// The default drive cycle (Fig. 51 shape), embedded so that `ivt` runs from any directory.
pub const DEFAULT_SCENE: &str = include_str!("../../scenes/drive.toml");

/// Arguments of `ivt sim`.
#[derive(Args)]
pub struct SimArgs {
    /// Scene file (TOML); see scenes/ and crates/ivt-sim/README.md.
    pub scene: PathBuf,
    /// Directory for the outputs the scene asks for.
    #[arg(long, default_value = "out")]
    pub out: PathBuf,
    /// Processor in the loop: run the controller in the QEMU firmware
    /// (`firmware/run-qemu.sh build` first; `$IVT_FW_ELF` overrides the image).
    #[arg(long)]
    pub pil: bool,
}

/// Run a scene file.
///
/// # Errors
/// Scene errors as [`CliError::Input`], run/output failures as [`CliError::Failed`].
pub fn run_file(args: &SimArgs, json: bool) -> Result<Output, CliError> {
    let scene = Scene::load(&args.scene).map_err(|e| CliError::Input(e.to_string()))?;
    run_scene(&scene, &args.out, json, args.pil)
}

/// `ivt` with no arguments: the default drive scene into `out/`.
///
/// # Errors
/// As [`run_file`].
pub fn run_default(json: bool) -> Result<Output, CliError> {
    let scene = Scene::parse(DEFAULT_SCENE, "scenes/drive.toml")
        .map_err(|e| CliError::Input(e.to_string()))?;
    run_scene(&scene, Path::new("out"), json, false)
}

fn run_scene(scene: &Scene, out: &Path, json: bool, pil: bool) -> Result<Output, CliError> {
    let mut bar = Progress::new(!json && scene.duration_s >= 5.0, &scene.name);
    let failed = |e: &dyn std::fmt::Display| CliError::Failed(e.to_string());
    let (result, paths) = if pil {
        let result =
            ivt_sim::pil::run_pil(scene, &mut |f| bar.update(f)).map_err(|e| failed(&e))?;
        bar.finish();
        let paths = write_all(out, scene, &result).map_err(|e| failed(&e))?;
        (result, paths)
    } else {
        // the MCAP log is written by a thread while the loop runs
        run_and_write(out, scene, |sink| {
            let r = run_to(scene, &mut |f| bar.update(f), sink);
            bar.finish();
            r
        })
        .map_err(|e| failed(&e))?
    };
    let outputs: Vec<String> = paths.iter().map(|p| p.display().to_string()).collect();
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
        s.law,
        s.settling_time_s.map_or("never".to_string(), |t| format!("{t:.2} s")),
        s.overshoot_pct,
        s.static_error_rad_s,
        s.static_error_rad_s * rpm,
        s.final_omega_a_rad_s * rpm,
        s.rms_control_effort_m_per_rad,
        s.max_abs_dr_dt_m_per_s,
        100.0 * s.saturated_fraction,
    );
    if outputs.is_empty() {
        human.push_str("no outputs requested\n");
    } else {
        human.push_str("wrote:\n");
        for p in &outputs {
            human.push_str(&format!("  {p}\n"));
        }
    }
    Ok(Output {
        json: json!({ "summary": s, "outputs": outputs }),
        human,
    })
}
