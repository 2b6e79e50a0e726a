//! `ivt rig identify run.mcap [--out plant.toml]`: the plant's identifiable
//! coefficients from a commissioning recording (equation error on Eq. 151,
//! `ivt_design::identify`), their 95 % intervals, the fit residual, the §4.4
//! figures from the data, and a plant file (`[plant]` table: preset +
//! overrides) for `--plant-file`, scenes and `ivt.kin.Plant.from_file`.

use super::commissioning::{self, crank_m_per_deg};
use super::{CliError, Output};
use clap::Args;
use ivt_design::identify::{self, Identification, SweepAnalysis, NAMES};
use ivt_kin::plant::PlantParams;
use ivt_kin::sgivt::R_AVG_SLOPE_PRINTED_PER_DEG;
use ivt_plot::{Figure, Series, Style};
use ivt_sim::atomic::Staged;
use ivt_sim::scene::PlantSection;
use serde_json::{json, Map, Value};
use std::f64::consts::{PI, SQRT_2};
use std::path::{Path, PathBuf};

/// Arguments of `ivt rig identify`.
#[derive(Args)]
pub struct IdentifyArgs {
    /// The commissioning recording (MCAP: /pulses, /sensors, /stepper, /sequence, metadata `ivt`).
    pub recording: PathBuf,
    /// Write the identified plant file (a `[plant]` table) here.
    #[arg(long)]
    pub out: Option<PathBuf>,
    /// Directory of the figures (default: beside --out, else beside the recording).
    #[arg(long)]
    pub figures: Option<PathBuf>,
}

/// Run `ivt rig identify`.
///
/// # Errors
/// An unreadable, truncated or corrupt recording (with the byte offset),
/// data that do not identify the plant, or an unwritable output.
pub fn run(a: &IdentifyArgs) -> Result<Output, CliError> {
    let rec = commissioning::read(&a.recording).map_err(|e| match e {
        commissioning::ReadError::Io(m) => CliError::Io(m),
        other => CliError::Input(other.to_string()),
    })?;
    let nominal = commissioning::nominal_params(&rec).map_err(CliError::Input)?;
    let id = identify::identify(&rec.recording, &nominal).map_err(|e| {
        let text = format!("{}: {e}", a.recording.display());
        match e {
            identify::IdentifyError::Recording { .. } => CliError::Input(text),
            _ => CliError::Unidentifiable(text),
        }
    })?;
    let plant = id.plant(&nominal);
    let section = PlantSection::from_params(rec.nominal.preset, &plant);
    let dir = a.figures.clone().unwrap_or_else(|| {
        let beside = a.out.as_deref().unwrap_or(&a.recording);
        beside
            .parent()
            .map_or_else(|| PathBuf::from("."), Path::to_path_buf)
    });
    // The plant file and the figures are one set: all of them or none.
    let mut staged = Staged::in_dir(&dir).map_err(|e| CliError::io(&dir, e))?;
    if let Some(out) = &a.out {
        // The recording's path as a quoted, escaped string: a newline in it
        // cannot start a line of the plant file.
        let text = format!(
            "# Identified by `ivt rig identify {:?}` (equation error on Eq. 151, {} windows).\n{}",
            a.recording.display().to_string(),
            id.windows,
            section.to_toml()
        );
        staged
            .write(out, text.as_bytes())
            .map_err(|e| CliError::io(out, e))?;
    }
    let figures = draw_figures(&mut staged, &dir, &id, &plant)?;
    staged.commit().map_err(|e| CliError::io(&dir, e))?;
    let mut out = report(a, &id, &plant, &section, &figures);
    if let Some(obj) = out.json.as_object_mut() {
        obj.insert(
            "recording".into(),
            json!({"frame_version": rec.frame_version, "ppr": rec.recording.ppr,
                   "f_timer_hz": rec.f_timer_hz, "steps_per_rev": rec.steps_per_rev,
                   "edges": rec.recording.pulse_t.len()}),
        );
    }
    Ok(out)
}

/// The JSON object and the human text.
fn report(
    a: &IdentifyArgs,
    id: &Identification,
    plant: &PlantParams,
    section: &PlantSection,
    figures: &[PathBuf],
) -> Output {
    let mut summary = Map::new();
    let mut ci95 = Map::new();
    for (name, e) in NAMES.iter().zip(&id.estimates) {
        summary.insert(name.to_string(), json!(e.value));
        ci95.insert(name.to_string(), json!(e.ci95));
    }
    summary.insert("r_max".into(), json!(plant.r_max));
    let sweep = id.sweep.as_ref().map(|s| sweep_json(s, plant));
    let mut human = format!("model: {}\nidentified (95 % interval):\n", model(id, plant));
    for (name, e) in NAMES.iter().zip(&id.estimates) {
        human.push_str(&format!(
            "  {name:<14} {:>12.6e}  [{:.6e}, {:.6e}]\n",
            e.value, e.ci95[0], e.ci95[1]
        ));
    }
    human.push_str(&format!(
        "residual RMS {:.3e} J over {} windows\n",
        id.residual_rms, id.windows
    ));
    if let Some(s) = &id.sweep {
        human.push_str(&format!(
            "R_avg slope {:.4e}/deg (Eq. 185 with r_OG = r_u: {:.4e}); K2·T_out {:.4} rpm/deg, K = {:.1} deg/rpm\n",
            s.r_avg_line.slope,
            eq185_slope(plant),
            s.k2_t_out,
            s.k
        ));
    }
    if let Some(out) = &a.out {
        human.push_str(&format!("plant file → {}\n", out.display()));
    }
    for w in &id.warnings {
        human.push_str(&format!("warning: {w}\n"));
    }
    Output {
        json: json!({
            "summary": summary,
            "ci95": ci95,
            "plant_file": a.out.as_ref().map(|p| p.display().to_string()),
            "plant": section.to_toml(),
            "figures": figures.iter().map(|p| p.display().to_string()).collect::<Vec<_>>(),
            "residual_rms": id.residual_rms,
            "noise_rms": id.noise_rms,
            "gravity_rms": id.gravity_rms,
            "model": model(id, plant),
            "l_a": plant.l_a,
            "warnings": id.warnings,
            "windows": id.windows,
            "inverse_condition": id.inverse_condition,
            "sweep": sweep,
        }),
        human,
    }
}

/// The model fitted, with its assumption on L_a stated.
fn model(id: &Identification, plant: &PlantParams) -> String {
    if id.lag_s > 0.0 {
        format!(
            "Eq. 137 with L_a = {} H from the nominal plant (τ_e = L_a/R_a = {:.3e} s; L_a is not identifiable from the motion)",
            plant.l_a, id.lag_s
        )
    } else {
        "Eq. 151, L_a = 0 as the nominal plant (Eq. 138; a rig with L_a > 0 needs it in the plant metadata)".into()
    }
}

/// Eq. 185's average-ratio slope with the output radius r_u of `plant` in
/// place of r_OG: (2√2/π)(7π/51840)/r_u \[1/deg\] (7/27492 at r_u = 1.5″).
pub fn eq185_slope(plant: &PlantParams) -> f64 {
    2.0 * SQRT_2 / PI * crank_m_per_deg() / plant.r_u
}

fn sweep_json(s: &SweepAnalysis, plant: &PlantParams) -> Value {
    let holds: Vec<Value> = s
        .holds
        .iter()
        .map(|h| {
            json!({"theta_ct_deg": h.theta_ct_deg, "r": h.r, "v_m": h.v_m, "t_u": h.t_u,
                   "omega_m_rpm": h.omega_m * 60.0 / (2.0 * PI), "r_avg": h.r_avg,
                   "revolutions": h.revolutions})
        })
        .collect();
    let l = &s.r_avg_line;
    json!({
        "r_avg_slope_per_deg": l.slope,
        "r_avg_slope_ci95": [l.slope - l.slope_half_width, l.slope + l.slope_half_width],
        "r_avg_intercept": l.intercept,
        "eq185_slope_per_deg": eq185_slope(plant),
        "eq185_printed_per_deg": R_AVG_SLOPE_PRINTED_PER_DEG,
        "k2_t_out_rpm_per_deg": s.k2_t_out,
        "k2_t_out_ci95": [s.k2_t_out - s.omega_line.slope_half_width, s.k2_t_out + s.omega_line.slope_half_width],
        "k_deg_per_rpm": s.k,
        "omega_intercept_rpm": s.omega_line.intercept,
        "holds": holds,
    })
}

/// Fig. 47, 48 and 50 from the data, as far as the recording has them,
/// staged in `staged`.
fn draw_figures(
    staged: &mut Staged,
    dir: &Path,
    id: &Identification,
    plant: &PlantParams,
) -> Result<Vec<PathBuf>, CliError> {
    let mut out = Vec::new();
    if let Some(s) = &id.sweep {
        let measured: Vec<(f64, f64)> = s
            .holds
            .iter()
            .filter_map(|h| h.r_avg.map(|r| (h.theta_ct_deg, r)))
            .collect();
        let span = |pts: &[(f64, f64)]| {
            let lo = pts.iter().map(|p| p.0).fold(f64::INFINITY, f64::min);
            let hi = pts.iter().map(|p| p.0).fold(f64::NEG_INFINITY, f64::max);
            (lo, hi)
        };
        let (lo, hi) = span(&measured);
        let line = |a: f64, b: f64| vec![(lo, a + b * lo), (hi, a + b * hi)];
        let fitted = line(s.r_avg_line.intercept, s.r_avg_line.slope);
        let eq185 = line(0.0, eq185_slope(plant));
        let printed = line(0.0, R_AVG_SLOPE_PRINTED_PER_DEG);
        out.push(plot(
            staged,
            dir,
            "fig47_average_ratio.png",
            &Figure {
                title: "Average speed ratio against the stepper angle (Fig. 47)",
                x_label: "θ_CT [deg]",
                y_label: "R_avg = T_in / T_out",
                series: vec![
                    Series {
                        label: "holds (data)",
                        points: &measured,
                        style: Style::Markers,
                    },
                    Series {
                        label: "fitted line",
                        points: &fitted,
                        style: Style::Line,
                    },
                    Series {
                        label: "Eq. 185 with r_u",
                        points: &eq185,
                        style: Style::Dashed,
                    },
                    Series {
                        label: "7/27492 per degree",
                        points: &printed,
                        style: Style::Dashed,
                    },
                ],
            },
        )?);
        let speed: Vec<(f64, f64)> = s
            .holds
            .iter()
            .map(|h| (h.theta_ct_deg, h.omega_m * 60.0 / (2.0 * PI)))
            .collect();
        let (lo, hi) = span(&speed);
        let fit = vec![
            (lo, s.omega_line.intercept + s.omega_line.slope * lo),
            (hi, s.omega_line.intercept + s.omega_line.slope * hi),
        ];
        let title = format!(
            "Motor speed against the stepper angle (Fig. 50): K2·T_out = {:.4} rpm/deg, K = {:.1} deg/rpm",
            s.k2_t_out, s.k
        );
        out.push(plot(
            staged,
            dir,
            "fig50_motor_speed.png",
            &Figure {
                title: &title,
                x_label: "θ_CT [deg]",
                y_label: "ω_m [rpm]",
                series: vec![
                    Series {
                        label: "holds (data)",
                        points: &speed,
                        style: Style::Markers,
                    },
                    Series {
                        label: "fitted line",
                        points: &fit,
                        style: Style::Line,
                    },
                ],
            },
        )?);
    }
    if let Some(p) = &id.phase_average {
        out.push(plot(
            staged,
            dir,
            "fig48_speed_over_theta_in.png",
            &Figure {
                title: "Speed of NG2 over θ_in, phase-averaged over the hold (Fig. 48)",
                x_label: "θ_in [deg]",
                y_label: "ω / mean ω",
                series: vec![Series {
                    label: "data",
                    points: p,
                    style: Style::Line,
                }],
            },
        )?);
    }
    Ok(out)
}

/// Draw one figure into its staged temporary file.
fn plot(
    staged: &mut Staged,
    dir: &Path,
    name: &str,
    fig: &Figure<'_>,
) -> Result<PathBuf, CliError> {
    let path = dir.join(name);
    let tmp = staged.path(&path).map_err(|e| CliError::io(&path, e))?;
    ivt_plot::line_plot(&tmp, fig).map_err(|e| CliError::Failed(e.for_path(&path).to_string()))?;
    Ok(path)
}
