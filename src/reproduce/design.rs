//! §4.2–4.3 on the printed plant (Eq. 151 + Table 1, ω0 = 100 rpm): IVT
//! steady state r̄ (Fig. 39), the open-loop law refit against Eq. 158/159
//! (Fig. 38), Γ̂ of §4.2.2 (Fig. 40), and the stability of the time-delay
//! loop (Fig. 42 and its two example multipliers).

use super::{borrow_series, fmt_sig, Context, OwnedSeries, ReproError, Verdict};
use ivt_design::delay::{delay_stability, DelayOptions, FeedbackGains};
use ivt_design::fit::{self, OpenLoopLaw, PolyForm};
use ivt_design::gains::stability_map;
use ivt_design::shooting::{periodic_at_r, shoot_steady_state, ShootingOptions};
use ivt_design::steady::{solve_steady_state, IhbOptions};
use ivt_design::sweep::{self, range, Grid, SweepPoint};
use ivt_design::{averaged_r, rad_s_to_rpm, thesis_omega0, OperatingPoint};
use ivt_kin::plant::PlantParams;
use ivt_kin::variant::{f_on_segment, segment_of};
use ivt_num::{ExplicitRk, RK4};
use ivt_plot::{Figure, HeatMap, Style};
use std::f64::consts::{PI, SQRT_2};

const SPEC5: &str = "SPEC §5: the printed u_ol (Eq. 158) does not hold 100 rpm on the printed \
plant (Eq. 151 + Table 1); 100 rpm needs V_m in the band [7.87, 7.87 + 0.154 T_U] V";

pub(crate) fn run(ctx: &mut Context) -> Result<(), ReproError> {
    let plant = PlantParams::printed();
    ctx.step("design: steady state at (6 V, 6 N·m)");
    steady_row_and_fig39(ctx, &plant)?;
    ctx.step("design: IHB sweep and refit (Eq. 158/159)");
    // The sweep is cheap (~0.3 s); the feasible band is narrow, so the refit
    // needs the full thesis grid even in --quick.
    let grid = Grid::thesis();
    match sweep::sweep(&plant, &grid, IhbOptions::default(), || ()) {
        Ok(pts) => {
            let law = refit_rows(ctx, &plant, &grid, &pts);
            figs_38_40(ctx, &plant, &grid, &pts, law.as_ref())?;
        }
        Err(e) => {
            let why = format!("IHB sweep failed: {e}");
            ctx.not_computable("Eq. 158 coefficients", "Eq. 158", &why);
            ctx.not_computable("Eq. 159 coefficients", "Eq. 159", &why);
            ctx.missing_figure("Fig. 38", "values of r̄", &why);
            ctx.missing_figure("Fig. 40", "boundary Γ̂ = 0", &why);
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
    stability(ctx, &plant, &map_grid)?;
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
            dw[0] = plant
                .terms_with_f(th, f, f_theta, r, v, t)
                .acceleration(w[0], r)
                / w[0];
        };
        rk.step(&mut rhs, th, h, &mut w);
        out.push((th + h, w[0]));
    }
    out
}

fn steady_row_and_fig39(ctx: &mut Context, plant: &PlantParams) -> Result<(), ReproError> {
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
            let evidence = format!(
                "{SPEC5}. Evidence: modified IHB (n = 31) r̄ = {} m, shooting (RK6 + Newton) r̄ = {} m, \
                 averaged power balance {} m — all < 0 (under-drive). Holding r = 0.0067 m instead, the \
                 periodic orbit has ω_a = {} rpm, not 100",
                fmt_sig(s.r, 5),
                fmt_sig(o.r, 6),
                fmt_sig(averaged_r(plant, &op), 3),
                at_thesis_r
                    .as_ref()
                    .map_or("?".into(), |p| fmt_sig(rad_s_to_rpm(p.omega_a()), 4))
            );
            ctx.compare(
                "r̄ at (6 V, 6 N·m) [m]",
                0.0067,
                "Fig. 39, §4.2.1",
                o.r,
                5e-5,
                5,
                "shooting",
                &evidence,
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
            "Fig. 39",
            "steady-state ω at (6 V, 6 N·m)",
            "steady-state solvers failed",
        );
        return Ok(());
    }
    let series = borrow_series(&series_data);
    ctx.line_figure(
        "Fig. 39",
        &Figure {
            title: "Fig. 39: steady-state ω at V_m = 6 V, T_U = 6 N·m, IHB vs Runge–Kutta (printed plant)",
            x_label: "θ [deg]",
            y_label: "ω [rpm]",
            series,
        },
        &format!("{SPEC5}: at 6 V the 100-rpm orbit needs r̄ < 0 (unconstrained, shown); the dashed curve holds the thesis's r̄ = 0.0067 m"),
    )
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

fn refit_rows(
    ctx: &mut Context,
    plant: &PlantParams,
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
    let evidence = format!(
        "{SPEC5}. Evidence (open-loop periodic orbits by shooting at the {} feasible grid points): \
         printed law ω_a error {}; refit ω_a error {}; refit error in r: RMS {:.2e} m, max {:.2e} m",
        pf.points,
        err_thesis.as_ref().map_or_else(|e| e.to_string(), |e| format!("max {:.2} rpm, RMS {:.2} rpm", e.max_abs_rpm, e.rms_rpm)),
        match &err_refit {
            Some(Ok(e)) => format!("max {:.3} rpm, RMS {:.3} rpm", e.max_abs_rpm, e.rms_rpm),
            Some(Err(e)) => e.to_string(),
            None => "—".into(),
        },
        pf.rms_r,
        pf.max_r
    );
    ctx.row(
        "Eq. 158 coefficients (u_ol = Σ c_ij V_m^i T_U^j) [m]",
        format!("{} (Eq. 158)", poly_str(&thesis.poly)),
        poly_str(&pf.poly),
        "every coefficient (different sign pattern)",
        Verdict::Differs,
        evidence,
    );
    match boundary {
        Ok((a, b, dev)) => ctx.row(
            "Eq. 159 coefficients (boundary r̄ = r_max: V_m = α T_U + β)",
            "α = 1.579, β = 0.632 V (Eq. 159)",
            format!("α = {}, β = {} V", fmt_sig(a, 4), fmt_sig(b, 5)),
            format!("α {:+.3}, β {:+.3} V", a - 1.579, b - 0.632),
            Verdict::Differs,
            format!(
                "{SPEC5}: on the printed plant the feasible band is only {:.3} T_U V wide above the \
                 under-drive edge; exact boundary points by IHB + secant, line max deviation {:.1e} V",
                a, dev
            ),
        ),
        Err(e) => ctx.not_computable("Eq. 159 coefficients", "Eq. 159", &e.to_string()),
    }
    law
}

fn gamma_hat(plant: &PlantParams, law: &OpenLoopLaw, v: f64, t: f64) -> f64 {
    // §4.2.2, the equation after Eq. 170: Γ̂ = −9.8√2 r_f + (k_t/R_a V_m − 2√2 T_U r_f/(π r_u))/√2.
    let rf = law.r_f(v, t);
    -9.8 * SQRT_2 * rf + (plant.motor_gain() * v - plant.load_gain() * t * rf) / SQRT_2
}

fn figs_38_40(
    ctx: &mut Context,
    plant: &PlantParams,
    grid: &Grid,
    pts: &[SweepPoint],
    law: Option<&OpenLoopLaw>,
) -> Result<(), ReproError> {
    let values: Vec<f64> = pts
        .iter()
        .map(|p| p.result.as_ref().map_or(f64::NAN, |s| 1e3 * s.r))
        .collect();
    // Grid order: rows of T_U, V_m fastest (as the sweep returns them).
    ctx.heat_figure(
        "Fig. 38(a)",
        &HeatMap {
            title: "Fig. 38(a): r̄ for ω_a = 100 rpm (IHB)",
            x_label: "V_m [V]",
            y_label: "T_U [N·m]",
            value_label: "r̄ [mm]",
            xs: &grid.v_m,
            ys: &grid.t_u,
            values: &values,
        },
        &format!("{SPEC5}; r̄ < 0: under-drive, r̄ > 12 mm: over-drive"),
    )?;
    let t_line = [1.5, 9.0];
    let printed: Vec<(f64, f64)> = t_line.iter().map(|&t| (t, 1.579 * t + 0.632)).collect();
    let mut series_data: Vec<OwnedSeries> =
        vec![("f_B = 0 printed (Eq. 159)".into(), printed, Style::Dashed)];
    if let Some(l) = law {
        let ours: Vec<(f64, f64)> = t_line
            .iter()
            .map(|&t| (t, -l.boundary[1] * t - l.boundary[2]))
            .collect();
        series_data.push((
            "r̄ = r_max, refit on the printed plant".into(),
            ours,
            Style::Line,
        ));
    }
    let series = borrow_series(&series_data);
    ctx.line_figure(
        "Fig. 38(b)",
        &Figure {
            title: "Fig. 38(b): boundary r̄ = 0.012 m of the open-loop law",
            x_label: "T_U [N·m]",
            y_label: "V_m [V]",
            series,
        },
        SPEC5,
    )?;

    // Fig. 40: Γ̂ = 0 against f_B = 0, for the printed and the refitted r_f.
    let mut series_data: Vec<OwnedSeries> = Vec::new();
    let laws: Vec<(&str, OpenLoopLaw)> =
        std::iter::once(("printed r_f (Eq. 158)", OpenLoopLaw::thesis()))
            .chain(law.map(|l| ("refit r_f", *l)))
            .collect();
    let ts: Vec<f64> = (0..=30).map(|i| 1.5 + 7.5 * i as f64 / 30.0).collect();
    for (name, l) in &laws {
        let zero: Vec<(f64, f64)> = ts
            .iter()
            .map(|&t| (t, bisect_v(|v| gamma_hat(plant, l, v, t), 2.0, 12.0)))
            .collect();
        series_data.push((format!("Γ̂ = 0, {name}"), zero, Style::Line));
        series_data.push((
            format!("f_B = 0, {name}"),
            t_line
                .iter()
                .map(|&tt| (tt, -l.boundary[1] * tt - l.boundary[2]))
                .collect(),
            Style::Dashed,
        ));
    }
    let series = borrow_series(&series_data);
    ctx.line_figure(
        "Fig. 40",
        &Figure {
            title: "Fig. 40: boundary Γ̂ = 0 (§4.2.2) compared with f_B = 0",
            x_label: "T_U [N·m]",
            y_label: "V_m [V]",
            series,
        },
        &format!(
            "Γ̂ from the closed form after Eq. 170 with the printed plant constants. Γ̂ = 0 is drawn only \
             where Γ̂ changes sign in V_m ∈ [2, 12] V; over the grid Γ̂ ranges {}. The thesis draws Γ̂ = 0 \
             inside the grid: with the printed constants Γ̂ stays positive there (SPEC §5: the printed \
             law matches no parameter set in the text)",
            laws.iter()
                .map(|(name, l)| {
                    let vals = grid.t_u.iter().flat_map(|&t| grid.v_m.iter().map(move |&v| (v, t)));
                    let (lo, hi) = vals.fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), (v, t)| {
                        let g = gamma_hat(plant, l, v, t);
                        (a.min(g), b.max(g))
                    });
                    format!("{lo:.3} … {hi:.3} ({name})")
                })
                .collect::<Vec<_>>()
                .join(", ")
        ),
    )?;
    Ok(())
}

/// Root of g on [a, b] by bisection, NaN if g does not change sign.
fn bisect_v(g: impl Fn(f64) -> f64, mut a: f64, mut b: f64) -> f64 {
    let (mut ga, gb) = (g(a), g(b));
    if !(ga.is_finite() && gb.is_finite()) || ga * gb > 0.0 {
        return f64::NAN;
    }
    for _ in 0..60 {
        let m = 0.5 * (a + b);
        let gm = g(m);
        if gm * ga <= 0.0 {
            b = m;
        } else {
            a = m;
            ga = gm;
        }
    }
    0.5 * (a + b)
}

fn stability(ctx: &mut Context, plant: &PlantParams, grid: &Grid) -> Result<(), ReproError> {
    let opts = DelayOptions::default();
    let op = OperatingPoint::at_100_rpm(7.0, 2.0);
    for (k, k2, thesis) in [(0.01, 0.02, 0.7776), (0.06, 0.12, 0.4871)] {
        let q = format!("Fig. 42 multiplier (k = {k}, k2 = {k2})");
        let ctrl_reading = delay_stability(
            plant,
            &op,
            FeedbackGains::from_thesis_mm_per_rad(k, k2),
            &opts,
        );
        let si_reading = delay_stability(plant, &op, FeedbackGains { k, k2 }, &opts);
        match (&ctrl_reading, &si_reading) {
            (Ok(a), Ok(b)) => {
                let why = format!(
                    "two causes, both evidenced: (1) SPEC §5 — (7 V, 2 N·m) is under-drive on the printed plant \
                     (r̄ = {} m < 0), so the linearization is about a different orbit than the thesis's; (2) the gain \
                     unit mm·rad⁻¹ is ambiguous (SPEC §5): ours reads k_SI = 1e-3·k (ivt-ctrl); reading the printed \
                     numbers as SI gives {} instead. Chebyshev Tau order N = {}",
                    fmt_sig(a.orbit.r, 4),
                    fmt_sig(b.max_abs_multiplier, 5),
                    opts.chebyshev_order
                );
                ctx.compare(
                    &q,
                    thesis,
                    "§4.3, V_m = 7 V, T_U = 2 N·m",
                    a.max_abs_multiplier,
                    5e-5,
                    5,
                    "max |multiplier| without the structural one",
                    &why,
                );
            }
            (Err(e), _) | (_, Err(e)) => {
                ctx.not_computable(&q, &format!("{thesis} (§4.3)"), &e.to_string())
            }
        }
    }
    let ops: Vec<OperatingPoint> = grid
        .t_u
        .iter()
        .flat_map(|&t| {
            grid.v_m.iter().map(move |&v| OperatingPoint {
                v_m: v,
                t_u: t,
                omega0: grid.omega0,
            })
        })
        .collect();
    match stability_map(
        plant,
        &ops,
        FeedbackGains::from_thesis_mm_per_rad(0.01, 0.02),
        &opts,
    ) {
        Ok(map) => {
            let values: Vec<f64> = map
                .iter()
                .map(|(_, r)| r.as_ref().map_or(f64::NAN, |v| *v))
                .collect();
            let worst = values
                .iter()
                .copied()
                .filter(|v| v.is_finite())
                .fold(0.0f64, f64::max);
            ctx.heat_figure(
                "Fig. 42",
                &HeatMap {
                    title: "Fig. 42: k = 0.01, k2 = 0.02 mm/rad",
                    x_label: "V_m [V]",
                    y_label: "T_U [N·m]",
                    value_label: "max |multiplier|",
                    xs: &grid.v_m,
                    ys: &grid.t_u,
                    values: &values,
                },
                &format!(
                    "linearized about the unconstrained 100-rpm orbit at every grid point (as the thesis); \
                     worst {worst:.5} (< 1: stable everywhere, as the thesis finds, but slow — SPEC §5)"
                ),
            )?;
        }
        Err(e) => ctx.missing_figure("Fig. 42", "stability map", &e.to_string()),
    }
    Ok(())
}
