//! `ivt kin ...`: kinematics of the GIVT, SGIVT and its variant, noncircular
//! gears and plant constants (thesis Chapter 2, §4.1, §4.4.2).

use super::{CliError, Output};
use clap::{Subcommand, ValueEnum};
use ivt_kin::arcs::{fit_arcs, Arc, ArcOptions, GearProfile, Member};
use ivt_kin::givt::{DirectionMode, DirectionModule, GivtGeometry, MAX_CORNERS};
use ivt_kin::ncg::{
    fourier_coefficient, fourier_coefficient_eq38, pitch_profile, GearRatio, GivtNcg, PitchPoint,
    SgivtNcg, SmoothNcg, EQ42_PRINTED,
};
use ivt_kin::params::Typed;
use ivt_kin::plant::PlantParams;
use ivt_kin::sgivt::{output_ripple, SgivtGeometry, R_AVG_SLOPE_PRINTED_PER_DEG};
use ivt_kin::units::{deg_to_rad, m_to_inch, rad_to_deg};
use ivt_kin::KinError;
use serde_json::{json, Value};
use std::fmt::Write as _;

/// Kinematics subcommands.
#[derive(Subcommand)]
pub enum KinCommand {
    /// Derived constants of the printed plant (Table 1 → §4.1).
    Plant,
    /// SGIVT prototype: crank length and average ratio for a stepper angle
    /// (Eq. 35, 185, §4.4.2), and the instantaneous ratio over θ_in.
    SgivtRatio {
        /// Stepper angle θ_CT in degrees (0..=3600).
        #[arg(long, default_value_t = 3600.0)]
        theta_ct: f64,
        /// Samples of R(θ_in) over one revolution (0 = none).
        #[arg(long, default_value_t = 0)]
        points: usize,
    },
    /// GIVT: module ratio Eq. 9, final ratio Eq. 10, its average and reduced ratio.
    GivtRatio {
        /// Eccentricity r in mm.
        #[arg(long, default_value_t = 10.0)]
        r_mm: f64,
        /// l1 in mm (not printed in the thesis; illustrative default).
        #[arg(long, default_value_t = 50.0)]
        l1_mm: f64,
        /// Output-gear radius in mm (not printed in the thesis; illustrative default).
        #[arg(long, default_value_t = 15.0)]
        r_output_mm: f64,
        /// Samples of R(θ) over one period π/2 (0 = none).
        #[arg(long, default_value_t = 0)]
        points: usize,
    },
    /// Pitch profiles of NG1/NG2 by integrating Eq. 17/41, with closure checks.
    PitchProfile {
        /// Which gear pair.
        #[arg(long, value_enum, default_value_t = Design::Sgivt)]
        design: Design,
        /// Points over one NG2 revolution (both ends included).
        #[arg(long, default_value_t = 361)]
        points: usize,
    },
    /// Tangent circular-arc approximation of both pitch profiles (§2.2.4).
    Arcs {
        /// Which gear pair.
        #[arg(long, value_enum, default_value_t = Design::Sgivt)]
        design: Design,
        /// Largest radial deviation / theoretical radius away from corners.
        #[arg(long, default_value_t = 0.01)]
        tolerance: f64,
        /// Half-width of the rounded window around each corner, degrees of the gear's own angle.
        #[arg(long, default_value_t = 2.0)]
        corner_deg: f64,
    },
    /// Fourier coefficients of Eq. 38 (exact and by quadrature) against the printed Eq. 42.
    FourierFit {
        /// Number of harmonics cos(4kθ) to list (≥ 4).
        #[arg(long, default_value_t = 6)]
        harmonics: u32,
    },
    /// Direction control module Eq. 18–19: forward and reverse ratios.
    Direction {
        /// Sun-gear radius (any unit; only the ratio to the planet matters).
        #[arg(long, default_value_t = 1.0)]
        r_sun: f64,
        /// Planet-gear radius (same unit as --r-sun).
        #[arg(long, default_value_t = 1.0)]
        r_planet: f64,
    },
}

/// A noncircular gear pair of the thesis.
#[derive(Clone, Copy, ValueEnum)]
pub enum Design {
    /// SGIVT, Eq. 38, D = 5.25 in.
    Sgivt,
    /// SGIVT with the smooth printed series Eq. 42, D = 5.25 in.
    SgivtSmooth,
    /// GIVT, Eq. 13 with r_o = 10 mm, D = 10 mm (illustrative l1, r_output).
    Givt,
}

impl Design {
    fn name(self) -> &'static str {
        match self {
            Design::Sgivt => "sgivt",
            Design::SgivtSmooth => "sgivt-smooth",
            Design::Givt => "givt",
        }
    }
}

/// Most `--points` of a sampled curve: 100 000 points are ~10 MB of JSON and
/// a second of work; beyond that the output is neither readable nor useful.
const MAX_POINTS: usize = 100_000;

/// `--points` in `min..=`[`MAX_POINTS`], checked before anything is allocated.
fn check_points(points: usize, min: usize) -> Result<(), CliError> {
    if (min..=MAX_POINTS).contains(&points) {
        Ok(())
    } else {
        Err(CliError::Input(format!(
            "--points must be in {min}..={MAX_POINTS} (the JSON of more is tens of MB), got {points}"
        )))
    }
}

fn kin_err(e: KinError) -> CliError {
    CliError::Input(e.to_string())
}

/// Run a kinematics subcommand.
///
/// # Errors
/// Out-of-domain arguments give [`CliError::Input`].
pub fn run(cmd: KinCommand) -> Result<Output, CliError> {
    match cmd {
        KinCommand::Plant => summary(),
        KinCommand::SgivtRatio { theta_ct, points } => sgivt_ratio(theta_ct, points),
        KinCommand::GivtRatio {
            r_mm,
            l1_mm,
            r_output_mm,
            points,
        } => givt_ratio(r_mm, l1_mm, r_output_mm, points),
        KinCommand::PitchProfile { design, points } => {
            with_design(design, |g, d| profile(design, g, d, points))
        }
        KinCommand::Arcs {
            design,
            tolerance,
            corner_deg,
        } => with_design(design, |g, d| arcs(design, g, d, tolerance, corner_deg)),
        KinCommand::FourierFit { harmonics } => fourier(harmonics),
        KinCommand::Direction { r_sun, r_planet } => direction(r_sun, r_planet),
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

fn sgivt_ratio(theta_ct_deg: f64, points: usize) -> Result<Output, CliError> {
    check_points(points, 0)?;
    super::check_flag("--theta-ct", "kin.theta_ct_deg", theta_ct_deg)?;
    let g = SgivtGeometry::prototype();
    let th = deg_to_rad(theta_ct_deg);
    let e = g.crank_length(th).map_err(kin_err)?;
    let r_avg = g.average_ratio(e).map_err(kin_err)?;
    let samples: Vec<Value> = (0..points)
        .map(|k| {
            let t = 2.0 * std::f64::consts::PI * k as f64 / points as f64;
            g.ratio(t, e)
                .map(|r| json!({"theta_in": t, "ratio": r}))
                .map_err(kin_err)
        })
        .collect::<Result<_, _>>()?;
    let json = json!({
        "theta_ct_deg": theta_ct_deg,
        "e": e,
        "e_inch": m_to_inch(e),
        "r_og": g.r_og,
        "ratio_min": e / g.r_og / std::f64::consts::SQRT_2,
        "ratio_max": e / g.r_og,
        "r_avg": r_avg,
        "r_avg_printed": R_AVG_SLOPE_PRINTED_PER_DEG * theta_ct_deg,
        "samples": samples,
    });
    let human = format!(
        "SGIVT prototype at θ_CT = {theta_ct_deg}°\n\
         crank length e = {:.6} in (Eq. 185: 7π/51840·θ_CT)\n\
         ratio Eq. 35 over θ_in: {:.6} .. {:.6}\n\
         R_avg = {:.6} (printed approximation 7θ_CT/27492 = {:.6})\n",
        m_to_inch(e),
        e / g.r_og / std::f64::consts::SQRT_2,
        e / g.r_og,
        r_avg,
        R_AVG_SLOPE_PRINTED_PER_DEG * theta_ct_deg
    );
    Ok(Output { json, human })
}

fn givt_ratio(r_mm: f64, l1_mm: f64, r_output_mm: f64, points: usize) -> Result<Output, CliError> {
    check_points(points, 0)?;
    super::check_flag("--r-mm", "kin.givt_r_mm", r_mm)?;
    super::check_flag("--l1-mm", "kin.givt_l1_mm", l1_mm)?;
    super::check_flag("--r-output-mm", "kin.givt_r_output_mm", r_output_mm)?;
    if r_mm >= l1_mm {
        return Err(CliError::Input(format!(
            "--r-mm = {} mm is out of domain: must be < --l1-mm = {} mm (Eq. 8 divides by |l1 − r|)",
            Typed(r_mm),
            Typed(l1_mm)
        )));
    }
    let g = GivtGeometry {
        l1: l1_mm * 1e-3,
        r_output: r_output_mm * 1e-3,
        ..GivtGeometry::illustrative()
    };
    let r = r_mm * 1e-3;
    let avg = g.average_module_ratio(r).map_err(kin_err)?;
    let mut c = [0.0; MAX_CORNERS];
    let nc = g.module_corners(r, &mut c).map_err(kin_err)?;
    let corners = c.get(..nc).unwrap_or(&c);
    let period = ivt_kin::givt::MODULE_PERIOD;
    let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
    let n_scan = points.max(2048);
    for k in 0..n_scan {
        let v = g
            .module_ratio(period * k as f64 / n_scan as f64, r)
            .map_err(kin_err)?;
        lo = lo.min(v);
        hi = hi.max(v);
    }
    // Fig. 10: with the noncircular gears designed for r_o = 10 mm, the
    // output/NG1 ratio is constant at r = r_o and varies slightly elsewhere.
    let ncg = GivtNcg::new(g, 0.010).map_err(kin_err)?;
    let (mut nlo, mut nhi, mut nsum) = (f64::INFINITY, f64::NEG_INFINITY, 0.0);
    for k in 0..n_scan {
        let v = ncg
            .output_to_ng1(period / 3.0 * k as f64 / n_scan as f64, r)
            .map_err(kin_err)?;
        nlo = nlo.min(v);
        nhi = nhi.max(v);
        nsum += v;
    }
    let nmean = nsum / n_scan as f64;
    let samples: Vec<Value> = (0..points)
        .map(|k| {
            let t = period * k as f64 / points as f64;
            Ok(json!({
                "theta": t,
                "r1": g.single_ratio(t, r).map_err(kin_err)?,
                "module_ratio": g.module_ratio(t, r).map_err(kin_err)?,
                "final_ratio": g.final_ratio(t, r).map_err(kin_err)?,
            }))
        })
        .collect::<Result<_, CliError>>()?;
    let json = json!({
        "r": r, "l1": g.l1, "r_output": g.r_output,
        "average_module_ratio": avg,
        "average_final_ratio": g.crank_to_input() * avg,
        "reduced_ratio_min": if avg > 0.0 { lo / avg } else { f64::NAN },
        "reduced_ratio_max": if avg > 0.0 { hi / avg } else { f64::NAN },
        "corners": corners,
        "with_ncg_r_o": 0.010,
        "with_ncg_reduced_min": nlo / nmean,
        "with_ncg_reduced_max": nhi / nmean,
        "samples": samples,
    });
    let human = format!(
        "GIVT, r = {r_mm} mm (l1 = {l1_mm} mm, r_output = {r_output_mm} mm: illustrative, not printed)\n\
         average R (Eq. 9) = {avg:.6}, average F = 3R (Eq. 10) = {:.6}\n\
         reduced ratio range {:.4} .. {:.4}; corners at {:?} deg\n\
         with noncircular gears designed for r_o = 10 mm (Eq. 13): ω_out/ω_NG1 varies {:.4} .. {:.4} of its mean\n",
        3.0 * avg,
        lo / avg,
        hi / avg,
        corners.iter().map(|x| rad_to_deg(*x)).collect::<Vec<_>>(),
        nlo / nmean,
        nhi / nmean
    );
    Ok(Output { json, human })
}

/// Run `f` with the gear ratio and centre distance of a design.
fn with_design(
    design: Design,
    f: impl FnOnce(&dyn GearRatio, f64) -> Result<Output, CliError>,
) -> Result<Output, CliError> {
    let d_sgivt = SgivtGeometry::prototype().ncg_centre_distance;
    match design {
        Design::Sgivt => f(&SgivtNcg, d_sgivt),
        Design::SgivtSmooth => f(&SmoothNcg::PRINTED, d_sgivt),
        Design::Givt => {
            let g = GivtNcg::new(GivtGeometry::illustrative(), 0.010).map_err(kin_err)?;
            f(&g, 0.010)
        }
    }
}

fn profile(design: Design, g: &dyn GearRatio, d: f64, points: usize) -> Result<Output, CliError> {
    check_points(points, 2)?;
    let mut pts = vec![PitchPoint::default(); points];
    let c = pitch_profile(g, d, &mut pts).map_err(kin_err)?;
    let json = json!({
        "design": design.name(),
        "centre_distance": d,
        "centre_distance_inch": m_to_inch(d),
        "closure_error": c.closure_error,
        "max_centre_distance_error": c.max_centre_distance_error,
        "r_driven_min": c.r_driven_range.0, "r_driven_max": c.r_driven_range.1,
        "r_driving_min": c.r_driving_range.0, "r_driving_max": c.r_driving_range.1,
        "points": pts.iter().map(|p| json!({
            "theta_driven": p.theta_driven, "r_driven": p.r_driven,
            "theta_driving": p.theta_driving, "r_driving": p.r_driving,
        })).collect::<Vec<_>>(),
    });
    let human = format!(
        "pitch profiles, design {} (D = {:.4} mm), {points} points over one NG2 revolution\n\
         closure error φ(2π) − 2π·turns = {:.3e} rad\n\
         NG2 radius {:.4} .. {:.4} mm; NG1 radius {:.4} .. {:.4} mm\n\
         (use --json for the points)\n",
        design.name(),
        d * 1e3,
        c.closure_error,
        c.r_driven_range.0 * 1e3,
        c.r_driven_range.1 * 1e3,
        c.r_driving_range.0 * 1e3,
        c.r_driving_range.1 * 1e3,
    );
    Ok(Output { json, human })
}

fn arcs(
    design: Design,
    g: &dyn GearRatio,
    d: f64,
    tolerance: f64,
    corner_deg: f64,
) -> Result<Output, CliError> {
    super::check_flag("--tolerance", "kin.arc_tolerance", tolerance)?;
    super::check_flag("--corner-deg", "kin.arc_corner_deg", corner_deg)?;
    let opts = ArcOptions {
        tolerance,
        corner_half_width: deg_to_rad(corner_deg),
        ..ArcOptions::default()
    };
    let mut obj = serde_json::Map::new();
    obj.insert("design".into(), json!(design.name()));
    obj.insert("centre_distance".into(), json!(d));
    obj.insert("tolerance".into(), json!(tolerance));
    obj.insert("corner_half_width_deg".into(), json!(corner_deg));
    let mut human = format!(
        "circular-arc approximation, design {} (D = {:.4} mm), tolerance {:.2} %, corner window ±{corner_deg}°\n",
        design.name(),
        d * 1e3,
        tolerance * 100.0
    );
    for (key, member) in [("driven", Member::Driven), ("driving", Member::Driving)] {
        let mut buf = vec![Arc::default(); 1 << 16];
        let prof = GearProfile {
            gear: g,
            centre_distance: d,
            member,
        };
        let fit = fit_arcs(&prof, &opts, &mut buf).map_err(kin_err)?;
        let list: Vec<Value> = buf
            .iter()
            .take(fit.count)
            .map(|a| {
                json!({
                    "start": a.start, "end": a.end(), "center": a.center(),
                    "radius": a.radius(), "heading": a.heading, "curvature": a.curvature,
                    "length": a.length, "sweep": a.sweep(), "fillet": a.fillet,
                })
            })
            .collect();
        obj.insert(
            key.into(),
            json!({
                "count": fit.count, "corners": fit.corners,
                "max_deviation": fit.max_deviation,
                "max_corner_deviation": fit.max_corner_deviation,
                "arcs": list,
            }),
        );
        let _ = writeln!(
            human,
            "{key:>8} ({}): {} arcs, {} corners, max deviation {:.3} % (corners {:.3} %)",
            if key == "driven" { "NG2" } else { "NG1" },
            fit.count,
            fit.corners,
            fit.max_deviation * 100.0,
            fit.max_corner_deviation * 100.0
        );
    }
    Ok(Output {
        json: Value::Object(obj),
        human,
    })
}

fn fourier(harmonics: u32) -> Result<Output, CliError> {
    if !(4..=64).contains(&harmonics) {
        return Err(CliError::Input("--harmonics must be in 4..=64".into()));
    }
    let mut rows = Vec::new();
    let mut human = String::from(
        "Fourier coefficients of Eq. 38 in 1 + Σ a_k cos(4kθ) vs the printed Eq. 42\n\
          k   exact 2(-1)^(k+1)/(16k²-1)   quadrature           printed    printed/exact\n",
    );
    for k in 0..=harmonics {
        let exact = fourier_coefficient_eq38(k);
        let numeric = fourier_coefficient(&SgivtNcg, k).map_err(kin_err)?;
        let printed = match k {
            0 => Some(1.0),
            1..=4 => EQ42_PRINTED.get(k as usize - 1).copied(),
            _ => None,
        };
        rows.push(json!({
            "k": k, "exact": exact, "numeric": numeric, "printed": printed,
            "printed_over_exact": printed.map(|p| p / exact),
        }));
        let _ = writeln!(
            human,
            "{k:>3}   {exact:>+24.10}   {numeric:>+18.12}   {:>9}   {}",
            printed.map_or("-".into(), |p| format!("{p:+}")),
            printed.map_or("-".into(), |p| format!("{:.4}", p / exact)),
        );
    }
    human.push_str(
        "The printed coefficients are 0.9 × the Fourier coefficients (to the printed digits),\n\
         not the Fourier coefficients themselves.\n",
    );
    let ripple_printed = output_ripple(&SmoothNcg::PRINTED, 100_000).map_err(kin_err)?;
    let ripple_fourier = output_ripple(&SmoothNcg::fourier(), 100_000).map_err(kin_err)?;
    let _ = writeln!(
        human,
        "output/engine ratio R/R_smooth (Eq. 37) relative to its mean: printed {:.4} .. {:.4}, \
         Fourier {:.4} .. {:.4}",
        ripple_printed.0, ripple_printed.1, ripple_fourier.0, ripple_fourier.1
    );
    Ok(Output {
        json: json!({
            "coefficients": rows,
            "ripple_printed": [ripple_printed.0, ripple_printed.1],
            "ripple_fourier": [ripple_fourier.0, ripple_fourier.1],
        }),
        human,
    })
}

fn direction(r_sun: f64, r_planet: f64) -> Result<Output, CliError> {
    super::check_flag("--r-sun", "kin.r_sun", r_sun)?;
    super::check_flag("--r-planet", "kin.r_planet", r_planet)?;
    let m = DirectionModule { r_sun, r_planet };
    let f = m.speeds(DirectionMode::Forward, 1.0).map_err(kin_err)?;
    let r = m.speeds(DirectionMode::Reverse, 1.0).map_err(kin_err)?;
    let json = json!({
        "r_sun": r_sun, "r_planet": r_planet,
        "forward_ratio": f.omega_carrier1,
        "forward_sun_speed_ratio": f.omega_sun,
        "reverse_ratio": r.omega_carrier1,
        "reverse_ring1_speed_ratio": r.omega_rg1,
        "forward_ratio_printed": m.forward_ratio_printed(),
        "reverse_ratio_printed": m.reverse_ratio_printed(),
    });
    let human = format!(
        "direction module (Eq. 18–19), r_sun = {r_sun}, r_planet = {r_planet}\n\
         forward (ring 1 held): ω_carrier1/ω_rg2 = {:+.6}  [printed form: {:+.6}]\n\
         reverse (suns held):   ω_carrier1/ω_rg2 = {:+.6}  [printed form: {:+.6}]\n",
        f.omega_carrier1,
        m.forward_ratio_printed(),
        r.omega_carrier1,
        m.reverse_ratio_printed()
    );
    Ok(Output { json, human })
}
