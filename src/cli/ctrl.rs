//! `ivt ctrl ...`: run the real `ivt-ctrl` controller offline.
//!
//! `ivt ctrl replay LOG.csv` feeds a recorded pulse log (columns
//! `ticks[,vm,tu]`, one encoder pulse per row, optional header naming them
//! in any order, `#` comments) through the controller exactly as the firmware would, and
//! writes its outputs per pulse (SPEC §6).

use super::{CliError, Output};
use clap::{Args, Subcommand, ValueEnum};
use ivt_ctrl::{units, AnyController, Config, ControlOutput, Gains, LawKind, OpenLoopPreset};
use ivt_sim::pulse_log::{parse_pulse_log, PulseRow, MAX_LOG_BYTES};
use serde_json::json;
use std::fmt::Write as _;
use std::path::PathBuf;

/// Controller subcommands.
#[derive(Subcommand)]
pub enum CtrlCommand {
    /// Replay a recorded pulse log through the controller.
    Replay(ReplayArgs),
}

/// Feedback law on the command line.
#[derive(Clone, Copy, Debug, ValueEnum)]
pub enum LawArg {
    /// Integral time-delay law, Eq. 180.
    Delay,
    /// No-delay law, Eq. 181.
    Nodelay,
    /// Proportional increment, Eq. 189.
    Prop,
    /// Open loop only, Eq. 160.
    Open,
}

impl From<LawArg> for LawKind {
    fn from(l: LawArg) -> Self {
        match l {
            LawArg::Delay => LawKind::Delay,
            LawArg::Nodelay => LawKind::NoDelay,
            LawArg::Prop => LawKind::Prop,
            LawArg::Open => LawKind::Open,
        }
    }
}

/// Open-loop coefficient set on the command line.
#[derive(Clone, Copy, Debug, Default, ValueEnum)]
pub enum OpenLoopArg {
    /// Refitted on the printed plant by `ivt ol fit` (SPEC §5, the default).
    #[default]
    Refit,
    /// Eq. 158–160 as printed.
    Thesis,
}

impl From<OpenLoopArg> for OpenLoopPreset {
    fn from(o: OpenLoopArg) -> Self {
        match o {
            OpenLoopArg::Refit => OpenLoopPreset::Refit,
            OpenLoopArg::Thesis => OpenLoopPreset::Thesis,
        }
    }
}

/// Arguments of `ivt ctrl replay`.
#[derive(Args)]
pub struct ReplayArgs {
    /// Pulse log: CSV with columns `ticks[,vm,tu]` (timer captures, V, N·m),
    /// by name when it has a header (`ticks`, `vm`/`v_m`, `tu`/`t_u` in any
    /// order), else in this order; at most 64 MB.
    pub log: PathBuf,
    /// Controller samples per revolution (see `--decimation`); supported:
    /// `ivt_ctrl::SUPPORTED_PPR` (16 … 4096; an unsupported value is refused
    /// with the list).
    #[arg(long, default_value_t = 1200)]
    pub ppr: usize,
    /// Encoder pulses per controller sample (encoder lines = ppr·decimation).
    #[arg(long, default_value_t = 1)]
    pub decimation: u16,
    /// Timer frequency of the ticks \[Hz\].
    #[arg(long, default_value_t = 1.0e6)]
    pub f_timer: f64,
    /// Target speed ω0 \[rpm\].
    #[arg(long, default_value_t = 100.0)]
    pub omega0_rpm: f64,
    /// Feedback law.
    #[arg(long, value_enum, default_value_t = LawArg::Delay)]
    pub law: LawArg,
    /// Gain k as printed in the thesis \[mm·rad⁻¹\] (§4.3; read as mm of r per
    /// rad of θ per rad/s, see ivt_ctrl::units).
    #[arg(long, default_value_t = 0.01)]
    pub k: f64,
    /// Gain k2 as printed in the thesis \[mm·rad⁻¹\].
    #[arg(long, default_value_t = 0.02)]
    pub k2: f64,
    /// Gain K of Eq. 189 \[deg of stepper per rpm\] (thesis: 50).
    #[arg(long, default_value_t = 50.0)]
    pub k_prop: f64,
    /// Sample period of Eq. 189 \[s\].
    #[arg(long, default_value_t = 0.1)]
    pub prop_period: f64,
    /// V_m \[V\] when the log has no vm column.
    #[arg(long, default_value_t = 8.0)]
    pub vm: f64,
    /// T_U \[N·m\] when the log has no tu column.
    #[arg(long, default_value_t = 8.0)]
    pub tu: f64,
    /// Open-loop law u_ol (Eq. 158–160 form): the refitted set or the printed one.
    #[arg(long, value_enum, default_value_t = OpenLoopArg::Refit)]
    pub open_loop: OpenLoopArg,
    /// Run the law without the open-loop feed-forward (r = r_d), as the
    /// driving test of §4.4.3 ran Eq. 189.
    #[arg(long)]
    pub no_feedforward: bool,
    /// Stall timeout \[s\].
    #[arg(long, default_value_t = 0.5)]
    pub stall_timeout: f64,
    /// Write the per-pulse CSV here (default: stdout without `--json`).
    #[arg(long)]
    pub out: Option<PathBuf>,
}

/// Run a controller subcommand.
///
/// # Errors
/// Unreadable or malformed logs, unsupported PPR: [`CliError::Input`];
/// an unwritable output file: [`CliError::Failed`].
pub fn run(cmd: CtrlCommand) -> Result<Output, CliError> {
    match cmd {
        CtrlCommand::Replay(a) => replay(&a),
    }
}

/// Refuse, by name and as typed, options that would make the replay
/// meaningless: each number outside its key's range in [`ivt_kin::params`]
/// (a zero timer frequency, stall timeout or sample period, any value the
/// controller's f32 cannot hold: `--k 1e300`), and a zero decimation.
fn check_args(a: &ReplayArgs) -> Result<(), CliError> {
    let keyed = [
        ("--f-timer", "encoder.f_timer_hz", a.f_timer),
        ("--omega0-rpm", "controller.omega0_rpm", a.omega0_rpm),
        (
            "--stall-timeout",
            "controller.stall_timeout_s",
            a.stall_timeout,
        ),
        ("--prop-period", "controller.prop_period_s", a.prop_period),
        ("--k", "controller.k_mm_per_rad", a.k),
        ("--k2", "controller.k2_mm_per_rad", a.k2),
        ("--k-prop", "controller.k_prop_deg_per_rpm", a.k_prop),
        ("--vm", "inputs.v_m[]", a.vm),
        ("--tu", "inputs.t_u[]", a.tu),
    ];
    for (flag, key, v) in keyed {
        super::check_flag(flag, key, v)?;
    }
    if a.decimation == 0 {
        return Err(CliError::Input("--decimation must be ≥ 1".into()));
    }
    Ok(())
}

/// The controller's outputs for every logged pulse, inputs replayed as
/// logged (`default_inputs` until the first logged reading).
fn simulate(
    mut c: AnyController,
    rows: &[PulseRow],
    default_inputs: (f32, f32),
) -> Vec<ControlOutput> {
    c.update_inputs(default_inputs.0, default_inputs.1);
    let mut last = None;
    rows.iter()
        .map(|row| {
            if let Some(inp) = row.inputs {
                // Compare bit patterns so NaN readings are replayed too.
                let key = (inp.0.to_bits(), inp.1.to_bits());
                if last != Some(key) {
                    last = Some(key);
                    c.update_inputs(inp.0, inp.1);
                }
            }
            c.on_pulse(row.ticks)
        })
        .collect()
}

fn replay(a: &ReplayArgs) -> Result<Output, CliError> {
    check_args(a)?;
    let text = ivt_sim::input::read_text_bounded(&a.log, MAX_LOG_BYTES)
        .map_err(|e| CliError::io(&a.log, e))?;
    let rows = parse_pulse_log(&text).map_err(|e| CliError::Input(e.to_string()))?;
    let config = Config {
        f_timer_hz: a.f_timer as f32,
        omega0: units::rpm_to_rad_s(a.omega0_rpm as f32),
        decimation: a.decimation,
        law: a.law.into(),
        gains: Gains {
            k_prop: units::prop_gain_from_deg_per_rpm(a.k_prop as f32),
            prop_period_s: a.prop_period as f32,
            ..Gains::from_thesis_mm_per_rad(a.k as f32, a.k2 as f32)
        },
        open_loop: OpenLoopPreset::from(a.open_loop).coeffs(),
        feedforward: !a.no_feedforward,
        stall_timeout_s: a.stall_timeout as f32,
        ..Config::default()
    };
    let controller =
        AnyController::new(a.ppr, config).map_err(|e| CliError::Input(format!("--ppr: {e}")))?;
    let outs = simulate(controller, &rows, (a.vm as f32, a.tu as f32));

    let mut csv = String::from(
        "ticks,omega,omega_a,omega_T,r_ol,r_d,r,stepper_target,saturated,ready,fault\n",
    );
    for (row, o) in rows.iter().zip(&outs) {
        let _ = writeln!(
            csv,
            "{},{},{},{},{},{},{},{},{},{},{}",
            row.ticks,
            o.omega,
            o.omega_a,
            o.omega_t,
            o.r_ol,
            o.r_d,
            o.r,
            o.stepper_target,
            u8::from(o.saturated),
            u8::from(o.ready),
            o.fault.code()
        );
    }
    let faults = outs.iter().filter(|o| o.fault.code() != 0).count();
    let last = outs.last().copied();
    let mut human = String::new();
    if let Some(path) = &a.out {
        super::write_atomic(path, csv.as_bytes())?;
        if let Some(o) = last {
            human = format!(
                "{} pulses, {faults} with a fault code; last: ω_a = {:.4} rad/s ({:.2} rpm), r = {:.6} m → {}\n",
                outs.len(),
                o.omega_a,
                units::rad_s_to_rpm(o.omega_a),
                o.r,
                path.display()
            );
        }
    } else {
        human = csv;
    }
    let col = |f: fn(&ControlOutput) -> f32| outs.iter().map(f).collect::<Vec<_>>();
    let json = json!({
        "ppr": a.ppr,
        "pulses": outs.len(),
        "omega": col(|o| o.omega),
        "omega_a": col(|o| o.omega_a),
        "omega_T": col(|o| o.omega_t),
        "r_ol": col(|o| o.r_ol),
        "r_d": col(|o| o.r_d),
        "r": col(|o| o.r),
        "stepper_target": outs.iter().map(|o| o.stepper_target).collect::<Vec<_>>(),
        "saturated": outs.iter().map(|o| o.saturated).collect::<Vec<_>>(),
        "ready": outs.iter().map(|o| o.ready).collect::<Vec<_>>(),
        "fault": outs.iter().map(|o| o.fault.code()).collect::<Vec<_>>(),
        "output": a.out.as_ref().map(|p| p.display().to_string()),
    });
    Ok(Output { json, human })
}
