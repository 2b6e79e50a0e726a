//! `ivt ctrl ...`: run the real `ivt-ctrl` controller offline.
//!
//! `ivt ctrl replay LOG.csv` feeds a recorded pulse log (columns
//! `ticks[,vm,tu]`, one encoder pulse per row, optional header naming them
//! in any order, `#` comments) through the controller exactly as the firmware would, and
//! writes its outputs per pulse (SPEC §6).

use super::{CliError, Output};
use clap::{Args, Subcommand, ValueEnum};
use ivt_ctrl::{units, AnyController, Config, ControlOutput, Gains, LawKind, OpenLoopPreset};
use ivt_sim::scene::keys::typed;
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

/// One row of the log.
struct Row {
    ticks: u32,
    inputs: Option<(f32, f32)>,
}

/// Most pulses of one replayed log: about 3 h at 100 rpm and 1200 PPR, and
/// ~200 MB of JSON output.
const MAX_PULSES: usize = 1_000_000;

/// Refuse, by name and as typed, options that would make the replay
/// meaningless: a zero or non-finite timer frequency, decimation, stall
/// timeout or sample period, non-finite gains or set points, and any value
/// the controller's f32 cannot hold (`--k 1e300`).
fn check_args(a: &ReplayArgs) -> Result<(), CliError> {
    let positive = [
        ("--f-timer", a.f_timer),
        ("--omega0-rpm", a.omega0_rpm),
        ("--stall-timeout", a.stall_timeout),
        ("--prop-period", a.prop_period),
    ];
    let finite = [
        ("--k", a.k),
        ("--k2", a.k2),
        ("--k-prop", a.k_prop),
        ("--vm", a.vm),
        ("--tu", a.tu),
    ];
    for (name, v) in positive.iter().chain(&finite) {
        if !ivt_sim::scene::keys::fits_f32(*v) {
            return Err(CliError::Input(format!(
                "{name} = {} does not fit the controller's f32 (finite, |v| in [{:e}, {:e}] or 0)",
                typed(*v),
                f32::MIN_POSITIVE,
                f32::MAX
            )));
        }
    }
    for (name, v) in positive {
        if v <= 0.0 {
            return Err(CliError::Input(format!(
                "{name} must be > 0, got {}",
                typed(v)
            )));
        }
    }
    if a.decimation == 0 {
        return Err(CliError::Input("--decimation must be ≥ 1".into()));
    }
    Ok(())
}

/// Largest pulse log read \[bytes\]: [`MAX_PULSES`] rows of up to 64 bytes.
const MAX_LOG_BYTES: u64 = 64 * MAX_PULSES as u64;

/// Where each field is in a row: from the header by name (`ticks`, `vm` or
/// `v_m`, `tu` or `t_u`, in any order), or `ticks[,vm,tu]` by position in a
/// log without a header.
#[derive(Clone, Copy, Debug, PartialEq)]
struct Columns {
    ticks: usize,
    inputs: Option<(usize, usize)>,
    count: usize,
}

impl Columns {
    /// The documented order, for a log without a header.
    fn positional(count: usize) -> Option<Self> {
        match count {
            1 => Some(Self {
                ticks: 0,
                inputs: None,
                count,
            }),
            3 => Some(Self {
                ticks: 0,
                inputs: Some((1, 2)),
                count,
            }),
            _ => None,
        }
    }

    /// The columns a header names; every name must be known and given once,
    /// `ticks` is required, `vm` and `tu` come together.
    fn from_header(names: &[&str]) -> Result<Self, String> {
        let mut slots: [Option<usize>; 3] = [None; 3];
        for (i, name) in names.iter().enumerate() {
            let slot = match name.to_ascii_lowercase().as_str() {
                "ticks" => 0,
                "vm" | "v_m" => 1,
                "tu" | "t_u" => 2,
                _ => {
                    return Err(format!(
                        "unknown column {} (known: ticks, vm or v_m, tu or t_u)",
                        ivt_sim::input::excerpt(name)
                    ))
                }
            };
            match slots.get_mut(slot) {
                Some(s @ None) => *s = Some(i),
                _ => {
                    return Err(format!(
                        "column {} is given twice",
                        ivt_sim::input::excerpt(name)
                    ))
                }
            }
        }
        let [ticks, vm, tu] = slots;
        let ticks = ticks.ok_or("the header has no `ticks` column")?;
        let inputs = match (vm, tu) {
            (Some(v), Some(t)) => Some((v, t)),
            (None, None) => None,
            _ => return Err("the header names one of vm, tu without the other".into()),
        };
        Ok(Self {
            ticks,
            inputs,
            count: names.len(),
        })
    }
}

fn parse_log(text: &str) -> Result<Vec<Row>, CliError> {
    let mut rows = Vec::new();
    let mut columns: Option<Columns> = None;
    for (n, line) in text.lines().enumerate() {
        let line = line.trim();
        if line.is_empty() || line.starts_with('#') {
            continue;
        }
        let bad = |what: &str| {
            CliError::Input(format!(
                "line {}: {what}: {}",
                n + 1,
                ivt_sim::input::excerpt(line)
            ))
        };
        let cols: Vec<&str> = line.split(',').map(str::trim).collect();
        let first = cols.first().copied().unwrap_or("");
        let layout = match columns {
            Some(c) => c,
            None if first.parse::<f64>().is_err() => {
                // the header: the columns by name
                columns = Some(Columns::from_header(&cols).map_err(|e| bad(&e))?);
                continue;
            }
            None => {
                let c = Columns::positional(cols.len()).ok_or_else(|| {
                    bad("expected columns ticks[,vm,tu] (or a header naming them)")
                })?;
                columns = Some(c);
                c
            }
        };
        if cols.len() != layout.count {
            return Err(bad(&format!(
                "{} columns where the log has {}",
                cols.len(),
                layout.count
            )));
        }
        let field = |i: usize| cols.get(i).copied().unwrap_or("");
        let ticks: u64 = field(layout.ticks)
            .parse()
            .map_err(|_| bad("ticks is not an unsigned integer"))?;
        let ticks =
            u32::try_from(ticks).map_err(|_| bad("ticks exceeds u32 (log raw timer captures)"))?;
        let inputs = match layout.inputs {
            None => None,
            Some((v, t)) => {
                // Readings are passed through unchanged (NaN included): the
                // controller's own validation is what is being replayed.
                let v: f32 = field(v).parse().map_err(|_| bad("vm is not a number"))?;
                let t: f32 = field(t).parse().map_err(|_| bad("tu is not a number"))?;
                Some((v, t))
            }
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
    let text = ivt_sim::input::read_text_bounded(&a.log, MAX_LOG_BYTES)
        .map_err(|e| CliError::io(&a.log, e))?;
    let rows = parse_log(&text)?;
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
