//! `ivt rig commission`: the commissioning sequences of §4.4 (Fig. 47, 48,
//! 50, 51) on a rig (`--port DEV`: the firmware runs them, started by a
//! `Commission` request, its telemetry recorded) or against the simulated
//! rig (`--sim`, SIL; `--pil`: the QEMU firmware drives the sequence).
//! Either way the output is a commissioning recording (`ivt_sim::recording`).

use super::{CliError, Output};
use clap::{Args, ValueEnum};
use ivt_ctrl::commission::{Plan, Selection, SequenceName};
use ivt_kin::params::Typed;
use ivt_sim::commission::{run_sil, CommissionOptions, SensorModel};
use ivt_sim::scene::PlantSection;
use serde_json::json;
use std::path::PathBuf;
use std::time::Duration;

/// `--sequence`: one sequence, or all of them in order.
#[derive(Clone, Copy, Debug, ValueEnum)]
pub enum SequenceArg {
    /// sweep, hold, step, drive in order.
    All,
    /// Stepper-angle sweep with holds (Fig. 47).
    Sweep,
    /// Hold at θ_CT with every encoder edge logged (Fig. 48).
    Hold,
    /// θ_CT holds and the proportional-law step test (Fig. 50, Eq. 186–190).
    Step,
    /// The drive cycle (Fig. 51).
    Drive,
}

impl SequenceArg {
    fn selection(self) -> Selection {
        match self {
            Self::All => Selection::ALL,
            Self::Sweep => Selection::only(SequenceName::Sweep),
            Self::Hold => Selection::only(SequenceName::Hold),
            Self::Step => Selection::only(SequenceName::Step),
            Self::Drive => Selection::only(SequenceName::Drive),
        }
    }
}

/// `--sensors` of the simulated rig.
#[derive(Clone, Copy, Debug, ValueEnum)]
pub enum SensorsArg {
    /// Exact readings and edge times.
    Ideal,
    /// Noise, quantization and encoder jitter (the drive scene's sensors).
    Realistic,
}

/// Arguments of `ivt rig commission`.
#[derive(Args)]
pub struct CommissionArgs {
    /// Serial device of the rig (its USART1 adapter); or use --sim.
    #[arg(long, conflicts_with_all = ["sim", "pil", "plant_file", "sensors"], required_unless_present = "sim")]
    pub port: Option<String>,
    /// Run against the simulated rig instead of a port.
    #[arg(long)]
    pub sim: bool,
    /// With --sim: the QEMU firmware runs the controller and the sequence (PIL).
    #[arg(long, requires = "sim")]
    pub pil: bool,
    /// With --sim: the plant, a TOML file with a `[plant]` table (preset and
    /// overrides, as in a scene); default the printed plant.
    #[arg(long, requires = "sim")]
    pub plant_file: Option<PathBuf>,
    /// With --sim: ideal sensors or realistic ones.
    #[arg(long, value_enum, requires = "sim")]
    pub sensors: Option<SensorsArg>,
    /// Output MCAP recording.
    #[arg(long)]
    pub out: PathBuf,
    /// Which sequence to run.
    #[arg(long, value_enum, default_value = "all")]
    pub sequence: SequenceArg,
    /// With --sim: gain K of the proportional law Eq. 189 \[deg per rpm\].
    #[arg(long, default_value_t = 5.0)]
    pub k_prop: f64,
    /// With --sim: seed of the sensor noise.
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    /// With --port: baud rate.
    #[arg(long, default_value_t = 921_600)]
    pub baud: u32,
    /// With --port: timer rate of the firmware's timestamps in Hz.
    #[arg(long, default_value_t = 10.0e6)]
    pub f_timer_hz: f64,
}

/// Runs `ivt rig commission`.
///
/// # Errors
/// Bad arguments or plant file ([`CliError::Input`]), a failed run or port
/// ([`CliError::Failed`]).
pub fn commission_cmd(a: &CommissionArgs) -> Result<Output, CliError> {
    let selection = a.sequence.selection();
    let plan = Plan::default();
    if let Some(port) = &a.port {
        return on_rig(a, port, selection, &plan);
    }
    super::check_flag("--k-prop", "controller.k_prop_deg_per_rpm", a.k_prop)?;
    if a.k_prop <= 0.0 {
        return Err(CliError::Input(format!(
            "--k-prop = {} deg/rpm must be > 0 (the proportional law drives the stepper against the speed error)",
            Typed(a.k_prop)
        )));
    }
    let plant = match &a.plant_file {
        Some(p) => PlantSection::from_file(p)?,
        None => Default::default(),
    };
    let opts = CommissionOptions {
        plan,
        selection,
        plant,
        sensors: match a.sensors.unwrap_or(SensorsArg::Ideal) {
            SensorsArg::Ideal => SensorModel::Ideal,
            SensorsArg::Realistic => SensorModel::Realistic,
        },
        k_prop_deg_per_rpm: a.k_prop,
        seed: a.seed,
        ..CommissionOptions::default()
    };
    let s = if a.pil {
        ivt_sim::pil::run_pil_commission(&opts, &a.out)
    } else {
        run_sil(&opts, &a.out)
    }?;
    let human = format!(
        "{} stages, {} pulses over {:.2} s ({}) → {}\n",
        s.stages,
        s.pulses,
        s.duration_s,
        if a.pil { "PIL" } else { "SIL" },
        s.out.display()
    );
    Ok(Output {
        json: json!({
            "mode": if a.pil { "pil" } else { "sil" },
            "sequences": ivt_sim::commission::selected_names(selection),
            "stages": s.stages,
            "pulses": s.pulses,
            "duration_s": s.duration_s,
            "channels": s.channels,
            "out": s.out.display().to_string(),
        }),
        human,
    })
}

/// Starts the sequence on the rig and records its telemetry until the plan's
/// duration (at the firmware's r_max of the printed plant) has passed and
/// the port idles.
fn on_rig(
    a: &CommissionArgs,
    port: &str,
    selection: Selection,
    plan: &Plan,
) -> Result<Output, CliError> {
    super::check_flag("--f-timer-hz", "encoder.f_timer_hz", a.f_timer_hz)?;
    let mut dev = super::rig_port::open_port(port, a.baud)?;
    let mut frame = [0u8; ivt_wire::MAX_FRAME];
    let n = ivt_wire::Request::Commission {
        selection,
        plan: *plan,
    }
    .encode(&mut frame)
    .map_err(|e| CliError::Failed(e.to_string()))?;
    std::io::Write::write_all(&mut dev, frame.get(..n).unwrap_or(&[]))
        .map_err(|e| CliError::Io(format!("{port}: {e}")))?;
    super::note(&format!("commissioning started on {port}"));
    let total = plan.duration_s(selection, ivt_ctrl::Config::default().open_loop.r_max);
    // The rig sends a sample every 10 ms: the plan and one second more.
    let max_frames = (f64::from(total) * 100.0).ceil() as u64 + 100;
    let s = super::rig_port::record_live(
        dev,
        &a.out,
        a.f_timer_hz,
        Some(max_frames),
        Duration::from_secs(2),
    )?;
    let human = format!(
        "{} telemetry frames ({} bad) over {:.1} s of a {:.0} s plan → {}\n",
        s.frames,
        s.bad_frames,
        s.duration_s,
        total,
        s.out.display()
    );
    Ok(Output {
        json: json!({
            "mode": "rig",
            "sequences": ivt_sim::commission::selected_names(selection),
            "frames": s.frames,
            "bad_frames": s.bad_frames,
            "duration_s": s.duration_s,
            "plan_duration_s": total,
            "channels": s.channels,
            "out": s.out.display().to_string(),
        }),
        human,
    })
}
