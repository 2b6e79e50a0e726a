//! `ivt ctrl ...`: run the real `ivt-ctrl` controller offline.
//!
//! `ivt ctrl replay LOG.csv` feeds a recorded pulse log (columns
//! `ticks[,vm,tu]`, one encoder pulse per row, optional header and `#`
//! comments) through the controller exactly as the firmware would, and
//! writes its outputs per pulse (SPEC §6).

use super::{CliError, Output};
use clap::{Args, Subcommand, ValueEnum};
use ivt_ctrl::{units, AnyController, Config, ControlOutput, Gains, LawKind, OpenLoopPreset};
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
    /// Pulse log: CSV with columns `ticks[,vm,tu]` (timer captures, V, N·m).
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
    pub f_timer: f32,
    /// Target speed ω0 \[rpm\].
    #[arg(long, default_value_t = 100.0)]
    pub omega0_rpm: f32,
    /// Feedback law.
    #[arg(long, value_enum, default_value_t = LawArg::Delay)]
    pub law: LawArg,
    /// Gain k as printed in the thesis \[mm·rad⁻¹\] (§4.3; read as mm of r per
    /// rad of θ per rad/s, see ivt_ctrl::units).
    #[arg(long, default_value_t = 0.01)]
    pub k: f32,
    /// Gain k2 as printed in the thesis \[mm·rad⁻¹\].
    #[arg(long, default_value_t = 0.02)]
    pub k2: f32,
    /// Gain K of Eq. 189 \[deg of stepper per rpm\] (thesis: 50).
    #[arg(long, default_value_t = 50.0)]
    pub k_prop: f32,
    /// Sample period of Eq. 189 \[s\].
    #[arg(long, default_value_t = 0.1)]
    pub prop_period: f32,
    /// V_m \[V\] when the log has no vm column.
    #[arg(long, default_value_t = 8.0)]
    pub vm: f32,
    /// T_U \[N·m\] when the log has no tu column.
    #[arg(long, default_value_t = 8.0)]
    pub tu: f32,
    /// Open-loop law u_ol (Eq. 158–160 form): the refitted set or the printed one.
    #[arg(long, value_enum, default_value_t = OpenLoopArg::Refit)]
    pub open_loop: OpenLoopArg,
    /// Run the law without the open-loop feed-forward (r = r_d), as the
    /// driving test of §4.4.3 ran Eq. 189.
    #[arg(long)]
    pub no_feedforward: bool,
    /// Stall timeout \[s\].
    #[arg(long, default_value_t = 0.5)]
    pub stall_timeout: f32,
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

/// One row of the log.
struct Row {
    ticks: u32,
    inputs: Option<(f32, f32)>,
}

/// Most pulses of one replayed log: about 3 h at 100 rpm and 1200 PPR, and
/// ~200 MB of JSON output.
const MAX_PULSES: usize = 1_000_000;

/// Refuse, by name, options that would make the replay meaningless: a zero
/// or non-finite timer frequency, decimation, stall timeout or sample
/// period, and non-finite gains or set points.
fn check_args(a: &ReplayArgs) -> Result<(), CliError> {
    let positive = [
        ("--f-timer", a.f_timer),
        ("--omega0-rpm", a.omega0_rpm),
        ("--stall-timeout", a.stall_timeout),
        ("--prop-period", a.prop_period),
    ];
    for (name, v) in positive {
        if !(v.is_finite() && v > 0.0) {
            return Err(CliError::Input(format!(
                "{name} must be finite and > 0, got {v}"
            )));
        }
    }
    let finite = [
        ("--k", a.k),
        ("--k2", a.k2),
        ("--k-prop", a.k_prop),
        ("--vm", a.vm),
        ("--tu", a.tu),
    ];
    for (name, v) in finite {
        if !v.is_finite() {
            return Err(CliError::Input(format!("{name} must be finite, got {v}")));
        }
    }
    if a.decimation == 0 {
        return Err(CliError::Input("--decimation must be ≥ 1".into()));
    }
    Ok(())
}

fn parse_log(text: &str) -> Result<Vec<Row>, CliError> {
    let mut rows = Vec::new();
    for (n, line) in text.lines().enumerate() {
        let line = line.trim();
        if line.is_empty() || line.starts_with('#') {
            continue;
        }
        let cols: Vec<&str> = line.split(',').map(str::trim).collect();
        let first = cols.first().copied().unwrap_or("");
        if rows.is_empty() && first.parse::<f64>().is_err() {
            continue; // header
        }
        let bad = |what: &str| CliError::Input(format!("line {}: {what}: {line:?}", n + 1));
        let ticks: u64 = first
            .parse()
            .map_err(|_| bad("ticks is not an unsigned integer"))?;
        let ticks =
            u32::try_from(ticks).map_err(|_| bad("ticks exceeds u32 (log raw timer captures)"))?;
        let inputs = match cols.as_slice() {
            [_] => None,
            [_, v, t] => {
                // Readings are passed through unchanged (NaN included): the
                // controller's own validation is what is being replayed.
                let v: f32 = v.parse().map_err(|_| bad("vm is not a number"))?;
                let t: f32 = t.parse().map_err(|_| bad("tu is not a number"))?;
                Some((v, t))
            }
            _ => return Err(bad("expected columns ticks[,vm,tu]")),
        };
        if rows.len() == MAX_PULSES {
            return Err(CliError::Input(format!(
                "the log has more than {MAX_PULSES} pulses (the JSON of more is hundreds of MB); split it"
            )));
        }
        rows.push(Row { ticks, inputs });
    }
    if rows.is_empty() {
        return Err(CliError::Input("the log has no pulses".into()));
    }
    Ok(rows)
}

/// The controller's outputs for every logged pulse, inputs replayed as
/// logged (`default_inputs` until the first logged reading).
fn simulate(mut c: AnyController, rows: &[Row], default_inputs: (f32, f32)) -> Vec<ControlOutput> {
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
    let text = std::fs::read_to_string(&a.log).map_err(|e| CliError::io(&a.log, e))?;
    let rows = parse_log(&text)?;
    let config = Config {
        f_timer_hz: a.f_timer,
        omega0: units::rpm_to_rad_s(a.omega0_rpm),
        decimation: a.decimation,
        law: a.law.into(),
        gains: Gains {
            k_prop: units::prop_gain_from_deg_per_rpm(a.k_prop),
            prop_period_s: a.prop_period,
            ..Gains::from_thesis_mm_per_rad(a.k, a.k2)
        },
        open_loop: OpenLoopPreset::from(a.open_loop).coeffs(),
        feedforward: !a.no_feedforward,
        stall_timeout_s: a.stall_timeout,
        ..Config::default()
    };
    let controller =
        AnyController::new(a.ppr, config).map_err(|e| CliError::Input(format!("--ppr: {e}")))?;
    let outs = simulate(controller, &rows, (a.vm, a.tu));

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
