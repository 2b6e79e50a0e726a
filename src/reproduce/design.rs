//! §4.2–4.3 on both plant presets (ω0 = 100 rpm): IVT steady state r̄
//! (Fig. 39), the open-loop law refit against Eq. 158/159 (Fig. 38), Γ̂ of
//! §4.2.2 (Fig. 40), and the stability of the time-delay loop (Fig. 42 and
//! its two example multipliers). `printed` is Table 1 (SPEC §5: Chapter 4
//! does not reproduce on it); `thesis-ch4` divides k_t and k_e by 10.

use super::design_maps::{figs_38_40, stability};
use super::design_refs::{fig_id, BAND_TEST, SPEC5};
use super::{borrow_series, fmt_sig, Cause, Context, OwnedSeries, ReproError};
use ivt_design::fit::{self, OpenLoopLaw, PolyForm};
use ivt_design::shooting::{periodic_at_r, shoot_steady_state, ShootingOptions};
use ivt_design::steady::{solve_steady_state, IhbOptions};
use ivt_design::sweep::{self, range, Grid, SweepPoint};
use ivt_design::{averaged_r, rad_s_to_rpm, thesis_omega0, OperatingPoint};
use ivt_kin::plant::{PlantParams, PlantPreset};
use ivt_kin::variant::{f_on_segment, segment_of};
use ivt_num::{ExplicitRk, RK4};
use ivt_plot::{Figure, Style};
use std::f64::consts::PI;

/// The test showing how far Eq. 158's printed digits can represent a fit.
const DIGITS_TEST: &str = "src/reproduce/design.rs::printed_digits_limit_eq158";

/// Report section of a preset.
fn section(preset: PlantPreset) -> &'static str {
    match preset {
        PlantPreset::Printed => "design/printed",
        PlantPreset::ThesisCh4 => "design/thesis-ch4",
    }
}

pub(crate) fn run(ctx: &mut Context) -> Result<(), ReproError> {
    for preset in PlantPreset::ALL {
        ctx.section = section(preset);
        run_plant(ctx, preset)?;
    }
    ctx.section = "design";
    super::ch4_findings::run(ctx);
    Ok(())
}

fn run_plant(ctx: &mut Context, preset: PlantPreset) -> Result<(), ReproError> {
    let plant = preset.params();
    ctx.step("design: steady state at (6 V, 6 N·m)");
    steady_row_and_fig39(ctx, &plant, preset)?;
    ctx.step("design: IHB sweep and refit (Eq. 158/159)");
    // The sweep is cheap (~0.3 s); the feasible band is narrow, so the refit
    // needs the full thesis grid even in --quick.
    let grid = Grid::thesis();
    match sweep::sweep(&plant, &grid, IhbOptions::default(), || ()) {
        Ok(pts) => {
            let law = refit_rows(ctx, &plant, preset, &grid, &pts);
            figs_38_40(ctx, &plant, preset, &grid, &pts, law.as_ref())?;
        }
        Err(e) => {
            let why = format!("IHB sweep failed: {e}");
            ctx.not_computable("Eq. 158 coefficients", "Eq. 158", &why);
            ctx.not_computable("Eq. 159 coefficients", "Eq. 159", &why);
            ctx.missing_figure(&fig_id("Fig. 38", preset), "values of r̄", &why);
            ctx.missing_figure(&fig_id("Fig. 40", preset), "boundary Γ̂ = 0", &why);
        }
    }
    ctx.step("design: delay-loop stability (Fig. 42)");
    // The stability map costs ~20 ms per point: --quick uses a coarser grid.
    let map_grid = if ctx.quick() {
        Grid {
            v_m: range(2.0, 1.2, 12.0),
            t_u: range(1.5, 1.5, 9.0),
            omega0: thesis_omega0(),
        }
    } else {
        grid
    };
    stability(ctx, &plant, preset, &map_grid)?;
    Ok(())
}

/// θ-domain RK4 of Eq. 151 at constant r, steps landing on the gear
/// corners θ = π/4 + kπ/2 (8·m steps per revolution): an independent check
/// of the IHB orbit for Fig. 39.
fn rk4_orbit(
    plant: &PlantParams,
    v: f64,
    t: f64,
    r: f64,
    omega_start: f64,
    steps: usize,
) -> Vec<(f64, f64)> {
    let h = 2.0 * PI / steps as f64;
    let mut rk = ExplicitRk::<4, [f64; 1]>::new(&RK4);
    let mut w = [omega_start];
    let mut out = vec![(0.0, w[0])];
    for i in 0..steps {
        // The analytic branch of the step's own gear segment, so that f_θ's
        // jump at a corner (a step end) never sits inside a step.
        let th = i as f64 * h;
        let seg = segment_of(th + 0.5 * h);
        let mut rhs = |th: f64, w: &[f64], dw: &mut [f64]| {
            let (f, f_theta) = f_on_segment(th, seg);
            let terms = plant.terms_with_f(th, f, f_theta, r, v, t);
            // The state is the single ω.
            for (dw, &w) in dw.iter_mut().zip(w) {
                *dw = terms.acceleration(w, r) / w;
            }
        };
        rk.step(&mut rhs, th, h, &mut w);
        out.push((th + h, w[0]));
    }
    out
}

fn steady_row_and_fig39(
    ctx: &mut Context,
    plant: &PlantParams,
    preset: PlantPreset,
) -> Result<(), ReproError> {
    let op = OperatingPoint::at_100_rpm(6.0, 6.0);
    // n = 31: the orbit has four humps per revolution plus corners, so n = 7
    // keeps only the 4th harmonic (design README: r̄ error 1.8e-5 at n = 31).
    let ihb = solve_steady_state(
        plant,
        &op,
        IhbOptions {
            harmonics: 31,
            ..Default::default()
        },
    );
    let shoot = shoot_steady_state(plant, &op, None, &ShootingOptions::default());
    let at_thesis_r = periodic_at_r(
        plant,
        6.0,
        6.0,
        0.0067,
        op.omega0,
        &ShootingOptions::default(),
    );
    match (&ihb, &shoot) {
        (Ok(s), Ok(o)) => {
            let ihb_vs_shooting = format!(
                "modified IHB (n = 31) r̄ = {} m, shooting (RK6 + Newton) r̄ = {} m, averaged power balance {} m",
                fmt_sig(s.r, 5),
                fmt_sig(o.r, 6),
                fmt_sig(averaged_r(plant, &op), 3),
            );
            let why = match preset {
                PlantPreset::Printed => format!(
                    "{SPEC5}. Evidence: {ihb_vs_shooting} — all < 0 (under-drive). Holding r = 0.0067 m instead, \
                     the periodic orbit has ω_a = {} rpm, not 100",
                    at_thesis_r
                        .as_ref()
                        .map_or("?".into(), |p| fmt_sig(rad_s_to_rpm(p.omega_a()), 4))
                ),
                _ => format!(
                    "{ihb_vs_shooting}: 1.2 % above the printed value, which is this r̄ truncated to two digits \
                     (0.00678 → 0.0067) or the result of constants slightly off the inferred thesis-ch4 set; \
                     Eq. 158 itself gives 0.00744 here"
                ),
            };
            let test = match preset {
                PlantPreset::Printed => BAND_TEST,
                _ => "tests/ch4_plant.rs::thesis_ch4_r_bar_matches_the_audit_values",
            };
            ctx.compare(
                "r̄ at (6 V, 6 N·m) [m]",
                0.0067,
                "Fig. 39, §4.2.1",
                o.r,
                5e-5,
                5,
                "shooting",
                Some(Cause { why: &why, test }),
            );
        }
        _ => {
            let e = ihb
                .as_ref()
                .err()
                .map(|e| e.to_string())
                .or(shoot.as_ref().err().map(|e| e.to_string()));
            ctx.not_computable(
                "r̄ at (6 V, 6 N·m) [m]",
                "0.0067 (Fig. 39)",
                &e.unwrap_or_default(),
            );
        }
    }
    r_bar_vs_eq158_rows(ctx, plant, preset);
    // Fig. 39: ω over one revolution, IHB vs an independent RK4 in θ.
    let mut series_data: Vec<OwnedSeries> = Vec::new();
    let deg = 180.0 / PI;
    let to_rpm = |pts: Vec<(f64, f64)>| -> Vec<(f64, f64)> {
        pts.into_iter()
            .map(|(t, w)| (t * deg, rad_s_to_rpm(w)))
            .collect()
    };
    if let (Ok(s), Ok(o)) = (&ihb, &shoot) {
        let ihb_pts: Vec<(f64, f64)> = (0..=180)
            .map(|i| {
                let th = 2.0 * PI * i as f64 / 180.0;
                (th, s.omega_at_theta(th))
            })
            .collect();
        series_data.push((
            format!("modified IHB (n = 31), r̄ = {:.4} m", s.r),
            to_rpm(ihb_pts),
            Style::Line,
        ));
        let rk = rk4_orbit(plant, 6.0, 6.0, o.r, o.omega_start, 2048);
        let rk: Vec<(f64, f64)> = rk.into_iter().step_by(16).collect();
        series_data.push((
            "RK4 in θ from the shooting ω(0)".into(),
            to_rpm(rk),
            Style::Markers,
        ));
    }
    if let Ok(p) = &at_thesis_r {
        let rk = rk4_orbit(plant, 6.0, 6.0, 0.0067, p.omega_start, 2048);
        series_data.push((
            format!(
                "r = 0.0067 m (thesis r̄): ω_a = {:.1} rpm",
                rad_s_to_rpm(p.omega_a())
            ),
            to_rpm(rk),
            Style::Dashed,
        ));
    }
    if series_data.is_empty() {
        ctx.missing_figure(
            &fig_id("Fig. 39", preset),
            "steady-state ω at (6 V, 6 N·m)",
            "steady-state solvers failed",
        );
        return Ok(());
    }
    let series = borrow_series(&series_data);
    let title = format!(
        "Fig. 39: steady-state ω at V_m = 6 V, T_U = 6 N·m, IHB vs Runge–Kutta ({} plant)",
        preset.name()
    );
    let note = match preset {
        PlantPreset::Printed => format!("{SPEC5}: at 6 V the 100-rpm orbit needs r̄ < 0 (unconstrained, shown); the dashed curve holds the thesis's r̄ = 0.0067 m"),
        _ => "k_t, k_e ÷ 10: r̄ = 0.00678 m, the orbit of the thesis's Fig. 39; the dashed curve holds the printed r̄ = 0.0067 m".to_string(),
    };
    ctx.line_figure(
        &fig_id("Fig. 39", preset),
        &Figure {
            title: &title,
            x_label: "θ [deg]",
            y_label: "ω [rpm]",
            series,
        },
        &note,
    )
}

/// r̄ by shooting at the two points the thesis evaluates Eq. 158 at
/// (§4.3's Fig. 42 example and Figs. 44–45), against the printed r_f there.
fn r_bar_vs_eq158_rows(ctx: &mut Context, plant: &PlantParams, preset: PlantPreset) {
    let thesis = OpenLoopLaw::thesis();
    for (v, t) in [(7.0, 2.0), (8.0, 8.0)] {
        let q = format!("r̄ at ({v} V, {t} N·m) vs the printed r_f of Eq. 158 [m]");
        let r_f = thesis.r_f(v, t);
        let shot = shoot_steady_state(
            plant,
            &OperatingPoint::at_100_rpm(v, t),
            None,
            &ShootingOptions::default(),
        );
        let Ok(o) = shot else {
            ctx.not_computable(&q, "Eq. 158", &format!("{:?}", shot.err()));
            continue;
        };
        let (why, test) = match preset {
            PlantPreset::Printed => (
                format!("{SPEC5}: r̄ = {} m on the printed plant", fmt_sig(o.r, 4)),
                BAND_TEST,
            ),
            _ => (
                "Eq. 158 is a fit whose printed 2–3 significant digits alone limit it to ~0.8 mm RMS over the grid \
                 (rounding the exact least-squares fit to the printed digits); the printed law is 0.42 mm RMS from \
                 r̄ on thesis-ch4"
                    .to_string(),
                DIGITS_TEST,
            ),
        };
        ctx.compare(
            &q,
            fmt_sig(r_f, 3).parse().unwrap_or(r_f),
            "Eq. 158 at this point, 3 significant digits",
            o.r,
            if r_f > 0.01 { 5e-5 } else { 5e-6 },
            5,
            "shooting",
            Some(Cause { why: &why, test }),
        );
    }
}

fn poly_str(p: &[[f64; 5]; 3]) -> String {
    let mut terms = Vec::new();
    for (i, row) in p.iter().enumerate() {
        for (j, &c) in row.iter().enumerate() {
            if c != 0.0 {
                terms.push(format!("V^{i}T^{j}: {}", fmt_sig(c, 4)));
            }
        }
    }
    terms.join(", ")
}

/// RMS and max of |printed r_f − r̄| over the feasible sweep points [m].
fn printed_r_f_error(pts: &[SweepPoint], r_max: f64) -> (f64, f64) {
    let thesis = OpenLoopLaw::thesis();
    let d: Vec<f64> = pts
        .iter()
        .filter_map(|p| p.result.as_ref().ok().map(|s| (p.op, s.r)))
        .filter(|(_, r)| (0.0..=r_max).contains(r))
        .map(|(op, r)| thesis.r_f(op.v_m, op.t_u) - r)
        .collect();
    let n = d.len().max(1) as f64;
    let rms = (d.iter().map(|x| x * x).sum::<f64>() / n).sqrt();
    (rms, d.iter().fold(0.0f64, |m, x| m.max(x.abs())))
}

/// Max |V_m| distance over T_U ∈ [1.5, 9] N·m between two lines V = α T + β.
fn line_gap(a: (f64, f64), b: (f64, f64)) -> f64 {
    [1.5, 9.0]
        .iter()
        .map(|t| ((a.0 - b.0) * t + a.1 - b.1).abs())
        .fold(0.0, f64::max)
}

fn refit_rows(
    ctx: &mut Context,
    plant: &PlantParams,
    preset: PlantPreset,
    grid: &Grid,
    pts: &[SweepPoint],
) -> Option<OpenLoopLaw> {
    let thesis = OpenLoopLaw::thesis();
    let pf = match fit::fit_polynomial(pts, plant.r_max, PolyForm::Eq158) {
        Ok(pf) => pf,
        Err(e) => {
            let why = format!("refit failed: {e}");
            ctx.not_computable("Eq. 158 coefficients", "Eq. 158", &why);
            ctx.not_computable("Eq. 159 coefficients", "Eq. 159", &why);
            return None;
        }
    };
    let boundary = fit::fit_boundary(
        plant,
        &grid.t_u,
        grid.omega0,
        plant.r_max,
        IhbOptions::default(),
    );
    let law = boundary.as_ref().ok().map(|&(a, b, _)| OpenLoopLaw {
        poly: pf.poly,
        boundary: [1.0, -a, -b],
        r_max: plant.r_max,
    });
    let err_thesis = fit::law_error(plant, &thesis, pts);
    let err_refit = law.as_ref().map(|l| fit::law_error(plant, l, pts));
    let (rms_printed, max_printed) = printed_r_f_error(pts, plant.r_max);
    let evidence = format!(
        "open-loop periodic orbits by shooting at the {} feasible grid points: printed law ω_a error {}; \
         refit ω_a error {}. In r: the Eq. 158-form least-squares refit is RMS {:.2e} m, max {:.2e} m from r̄; \
         the printed coefficients RMS {:.2e} m, max {:.2e} m",
        pf.points,
        err_thesis.as_ref().map_or_else(
            |e| e.to_string(),
            |e| format!(
                "max {:.2} rpm, RMS {:.2} rpm ({} points stall from ω0)",
                e.max_abs_rpm, e.rms_rpm, e.stalled
            )
        ),
        match &err_refit {
            Some(Ok(e)) => format!("max {:.3} rpm, RMS {:.3} rpm", e.max_abs_rpm, e.rms_rpm),
            Some(Err(e)) => e.to_string(),
            None => "—".into(),
        },
        pf.rms_r,
        pf.max_r,
        rms_printed,
        max_printed
    );
    let (why, test, difference) = match preset {
        PlantPreset::Printed => (
            format!("{SPEC5}. Evidence: {evidence}"),
            BAND_TEST,
            "every coefficient (different sign pattern)",
        ),
        _ => (
            format!(
                "same sign pattern, magnitudes within a factor 3 (V² term excepted): the printed digits cannot pin a \
                 fit of this form — the exact refit rounded to the printed significant digits is ~0.8 mm RMS from r̄, \
                 more than the printed law. Evidence: {evidence}"
            ),
            DIGITS_TEST,
            "every coefficient (same sign pattern)",
        ),
    };
    ctx.differs(
        "Eq. 158 coefficients (u_ol = Σ c_ij V_m^i T_U^j) [m]",
        format!("{} (Eq. 158)", poly_str(&thesis.poly)),
        poly_str(&pf.poly),
        difference,
        Cause { why: &why, test },
    );
    match boundary {
        Ok((a, b, dev)) => {
            let gap = line_gap((a, b), (1.579, 0.632));
            let why = match preset {
                PlantPreset::Printed => format!(
                    "{SPEC5}: on the printed plant the feasible band is only {a:.3} T_U V wide above the \
                     under-drive edge; exact boundary points by IHB + secant, line max deviation {dev:.1e} V"
                ),
                _ => format!(
                    "the two lines are at most {gap:.2} V apart over T_U ∈ [1.5, 9] N·m, about half the 0.4 V step of \
                     the grid a boundary read from Fig. 38's points is resolved to; ours from exact boundary points \
                     (IHB + secant, line max deviation {dev:.1e} V)"
                ),
            };
            let test = match preset {
                PlantPreset::Printed => BAND_TEST,
                _ => "src/reproduce/design.rs::eq159_is_the_thesis_ch4_boundary_to_the_grid_step",
            };
            ctx.differs(
                "Eq. 159 coefficients (boundary r̄ = r_max: V_m = α T_U + β)",
                "α = 1.579, β = 0.632 V (Eq. 159)",
                format!("α = {}, β = {} V", fmt_sig(a, 4), fmt_sig(b, 5)),
                format!(
                    "α {:+.3}, β {:+.3} V; lines ≤ {gap:.2} V apart",
                    a - 1.579,
                    b - 0.632
                ),
                Cause { why: &why, test },
            );
        }
        Err(e) => ctx.not_computable("Eq. 159 coefficients", "Eq. 159", &e.to_string()),
    }
    law
}

#[cfg(test)]
mod tests {
    use super::super::design_maps::{bisect_v, gamma_hat};
    use super::*;

    fn sweep_on(preset: PlantPreset) -> Vec<SweepPoint> {
        sweep::sweep(
            &preset.params(),
            &Grid::thesis(),
            IhbOptions::default(),
            || (),
        )
        .unwrap()
    }

    /// Round to `sig` significant digits.
    fn round_sig(x: f64, sig: i32) -> f64 {
        if x == 0.0 {
            return 0.0;
        }
        let scale = 10f64.powi(sig - 1 - x.abs().log10().floor() as i32);
        (x * scale).round() / scale
    }

    /// RMS of r_f − r̄ of a law over the feasible points.
    fn rms(poly: &[[f64; 5]; 3], pts: &[SweepPoint]) -> f64 {
        let law = OpenLoopLaw {
            poly: *poly,
            ..OpenLoopLaw::thesis()
        };
        let d: Vec<f64> = pts
            .iter()
            .filter_map(|p| p.result.as_ref().ok().map(|s| (p.op, s.r)))
            .filter(|(_, r)| (0.0..=0.012).contains(r))
            .map(|(op, r)| law.r_f(op.v_m, op.t_u) - r)
            .collect();
        (d.iter().map(|x| x * x).sum::<f64>() / d.len() as f64).sqrt()
    }

    /// On thesis-ch4 the exact Eq. 158-form fit is 0.06 mm RMS from r̄, the
    /// printed law 0.42 mm, and the exact fit rounded to the printed numbers
    /// of significant digits 0.8 mm: the printed digits, not the plant, limit
    /// Eq. 158. On the printed plant the printed law is far off (> 5 mm).
    #[test]
    fn printed_digits_limit_eq158() {
        let pts = sweep_on(PlantPreset::ThesisCh4);
        let fit = fit::fit_polynomial(&pts, 0.012, PolyForm::Eq158).unwrap();
        assert!(fit.rms_r < 7e-5, "{}", fit.rms_r);
        let printed = rms(&OpenLoopLaw::thesis().poly, &pts);
        assert!((printed - 4.2e-4).abs() < 0.2e-4, "{printed}");
        // Significant digits of the printed coefficients (Eq. 158).
        let sig = [[3, 3, 2, 3, 2], [3, 3, 2, 2, 0], [2, 0, 0, 0, 0]];
        let mut rounded = fit.poly;
        for (row, digits) in rounded.iter_mut().zip(sig) {
            for (c, d) in row.iter_mut().zip(digits) {
                *c = if d == 0 { 0.0 } else { round_sig(*c, d) };
            }
        }
        let r = rms(&rounded, &pts);
        assert!(r > printed && r > 6e-4, "rounded refit {r}");
        let (printed_rms, _) = printed_r_f_error(&sweep_on(PlantPreset::Printed), 0.012);
        assert!(printed_rms > 5e-3, "{printed_rms}");
    }

    /// Eq. 159 lies within 0.25 V of the thesis-ch4 boundary r̄ = r_max over
    /// the grid's T_U (the grid step in V_m is 0.4 V), and > 3 V from the
    /// printed plant's.
    #[test]
    fn eq159_is_the_thesis_ch4_boundary_to_the_grid_step() {
        let grid = Grid::thesis();
        let gap = |preset: PlantPreset| {
            let (a, b, _) = fit::fit_boundary(
                &preset.params(),
                &grid.t_u,
                grid.omega0,
                0.012,
                IhbOptions::default(),
            )
            .unwrap();
            line_gap((a, b), (1.579, 0.632))
        };
        let ch4 = gap(PlantPreset::ThesisCh4);
        assert!(ch4 < 0.25, "{ch4}");
        assert!(gap(PlantPreset::Printed) > 3.0);
    }

    /// Γ̂ = 0 (printed r_f) appears inside the grid on thesis-ch4 only.
    #[test]
    fn gamma_hat_crosses_only_on_thesis_ch4() {
        let law = OpenLoopLaw::thesis();
        let crosses = |p: &PlantParams| {
            Grid::thesis()
                .t_u
                .iter()
                .filter(|&&t| bisect_v(|v| gamma_hat(p, &law, v, t), 2.0, 12.0).is_finite())
                .count()
        };
        assert!(crosses(&PlantParams::thesis_ch4()) > 0);
        assert_eq!(crosses(&PlantParams::printed()), 0);
    }
}
