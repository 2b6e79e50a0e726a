//! `ivt kin ...`: kinematics and plant constants.

use super::{CliError, Output};
use clap::Subcommand;
use ivt_kin::plant::PlantParams;
use serde_json::json;

/// Kinematics subcommands.
#[derive(Subcommand)]
pub enum KinCommand {
    /// Derived constants of the printed plant (Table 1 → §4.1).
    Plant,
}

/// Run a kinematics subcommand.
///
/// # Errors
/// Bad arguments give [`CliError::Input`].
pub fn run(cmd: KinCommand) -> Result<Output, CliError> {
    match cmd {
        KinCommand::Plant => summary(),
    }
}

/// Summary of the printed plant: the derived constants of §4.1.
///
/// # Errors
/// Never fails today; the signature matches the other commands.
pub fn summary() -> Result<Output, CliError> {
    let p = PlantParams::printed();
    let json = json!({
        "j_a": p.j_a(), "j_b": p.j_b(), "j_c": p.j_c(), "j_d": p.j_d(),
        "motor_damping": p.motor_damping(), "motor_gain": p.motor_gain(),
        "load_gain": p.load_gain(), "r_max": p.r_max,
    });
    let human = format!(
        "IVT plant, Table 1 (thesis §4.1 values in brackets)\n\
         J_a = {:.6} kg·m² [0.0237]\nJ_b = {:.6} kg [2.1264]\nJ_c = {:.6} kg [0.3388]\n\
         F_m = {:.4}·f² [2.375]\nf1 = {:.4}·f·V_m [3.1667]\nf2 = {:.4}·f·T_U [40.5548]\n",
        p.j_a(),
        p.j_b(),
        p.j_c(),
        p.motor_damping(),
        p.motor_gain(),
        p.load_gain()
    );
    Ok(Output { json, human })
}
