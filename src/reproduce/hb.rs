//! §3.2: Duffing (Fig. 28 against RK4, Fig. 29 FRC, the IHB timings of
//! §3.2.3) and Mathieu–Duffing (A0 and β1/β2/β4 of §3.2.5, Figs. 30–33).

use super::{fmt_sig, series, Cause, Context, ReproError, Verdict};
use ivt_hb::branches::mathieu::THESIS_A0;
use ivt_hb::orbit::aft::eval_series;
use ivt_hb::problem::ode::{first_order, rk4};
use ivt_hb::{
    frequency_response, period_doubling_cascade, CascadeOptions, ClassicIhb, Duffing, FrcOptions,
    HbOptions, MathieuDuffing, ModifiedIhb,
};
use ivt_plot::{Figure, Style};
use std::f64::consts::PI;
use std::time::Instant;

/// The test behind the A0 row's note.
const A0_TEST: &str = "src/reproduce/hb.rs::a0_differs_in_a8_sign_and_b3";

/// The test ruling out β, n and truncation as the cause of A0's b3.
const A0_RULED_OUT: &str = "src/reproduce/hb.rs::a0_b3_is_not_beta_n_or_truncation";

/// The test ruling out one-parameter slips, the classic IHB and sign flips.
const A0_SLIPS: &str = "tests/a0_causes.rs::a0_b3_is_not_a_parameter_slip_or_the_classic_ihb";

/// The test ruling out collocation and the literal Eq. 83 residual.
const A0_COLLOCATION: &str = "tests/a0_causes.rs::a0_b3_is_not_collocation_or_the_literal_eq83";

/// Fig. 28 forcing frequency (n = 20, N = 64, ξ = 0.02, α = 1, ε = 1, F = 0.1).
const OMEGA_F: f64 = 0.4;

pub(crate) fn run(ctx: &mut Context) -> Result<(), ReproError> {
    ctx.step("hb: Duffing, timings, FRC");
    duffing(ctx)?;
    ctx.step("hb: Mathieu–Duffing cascade");
    mathieu(ctx)?;
    Ok(())
}

fn median_time(mut f: impl FnMut() -> bool, reps: usize) -> Option<f64> {
    let mut t: Vec<f64> = Vec::with_capacity(reps);
    for _ in 0..reps {
        let s = Instant::now();
        if !f() {
            return None;
        }
        t.push(s.elapsed().as_secs_f64());
    }
    t.sort_by(f64::total_cmp);
    t.get(t.len() / 2).copied()
}

fn duffing(ctx: &mut Context) -> Result<(), ReproError> {
    let problem = Duffing::fig28();
    let opts = HbOptions::new(20, 64);
    // Timings of §3.2.3: one solve from the default start, setup included.
    let reps = if ctx.quick() { 3 } else { 11 };
    // One timed solve with either solver type (same problem, options, start).
    macro_rules! timed {
        ($solver:ident) => {
            median_time(
                || {
                    $solver::new(problem.clone(), opts.clone())
                        .and_then(|mut s| s.solve(OMEGA_F, None))
                        .is_ok()
                },
                reps,
            )
        };
    }
    let (t_mod, t_cls) = (timed!(ModifiedIhb), timed!(ClassicIhb));
    let ratio = match (t_cls, t_mod) {
        (Some(c), Some(m)) => format!("{:.0}", c / m),
        _ => "?".into(),
    };
    for (q, thesis, ours) in [
        ("IHB time, classic [s]", 0.25, t_cls),
        ("IHB time, modified [s]", 0.003, t_mod),
    ] {
        match ours {
            Some(t) => ctx.row(
                q,
                format!("{thesis} s (§3.2.3, Duffing n = 20, N = 64)"),
                format!("{} s", fmt_sig(t, 3)),
                format!("×{:.3}", t / thesis),
                Verdict::NotComputable,
                format!(
                    "a wall-clock time is not comparable: the thesis's machine and language are not stated (ours, \
                     measured, not asserted: Rust release build, median of {reps} solves). The thesis's claim is \
                     the ratio classic/modified ≈ 83; ours is {ratio}"
                ),
            ),
            None => ctx.not_computable(q, &format!("{thesis} s"), "the solver failed at the Fig. 28 parameters"),
        }
    }

    // Fig. 28: modified IHB vs RK4 (150 forcing periods from rest, then one period).
    let sol =
        ModifiedIhb::new(problem.clone(), opts.clone()).and_then(|mut s| s.solve(OMEGA_F, None));
    match sol {
        Ok(sol) => {
            let period = 2.0 * PI / OMEGA_F;
            let per = 4096;
            let dt = period / per as f64;
            let mut y = [0.0, 0.0];
            let periods = if ctx.quick() { 100 } else { 150 };
            rk4(
                first_order(&problem, OMEGA_F),
                0.0,
                &mut y,
                dt,
                periods * per,
            );
            let mut rk = Vec::new();
            let mut t = periods as f64 * period;
            let mut max_diff: f64 = 0.0;
            for j in 0..=64 {
                let tt = j as f64 * period / 64.0;
                let hb = eval_series(&sol.coeffs, OMEGA_F * tt, 0);
                max_diff = max_diff.max((hb - y[0]).abs());
                rk.push((tt, y[0]));
                rk4(first_order(&problem, OMEGA_F), t, &mut y, dt, per / 64);
                t += dt * (per / 64) as f64;
            }
            let hb: Vec<(f64, f64)> = (0..=400)
                .map(|j| {
                    let tt = j as f64 * period / 400.0;
                    (tt, eval_series(&sol.coeffs, OMEGA_F * tt, 0))
                })
                .collect();
            ctx.line_figure(
                "Fig. 28",
                &Figure {
                    title: "Fig. 28: Duffing, n = 20, N = 64, ξ = 0.02, α = 1, ε = 1, ω_f = 0.4, F = 0.1",
                    x_label: "t [s]",
                    y_label: "x [-]",
                    series: series(&[("modified IHB", &hb, Style::Line), ("Runge–Kutta (RK4, 150 periods from rest)", &rk, Style::Markers)]),
                },
                &format!(
                    "max |x_IHB − x_RK| over 65 points = {max_diff:.1e}; IHB residual {:.1e} in {} Broyden iterations",
                    sol.stats.residual_norm, sol.stats.iterations
                ),
            )?;
        }
        Err(e) => ctx.missing_figure("Fig. 28", "Duffing solution", &e.to_string()),
    }

    // Fig. 29: FRC with stability.
    match frequency_response(&problem, &opts, &FrcOptions::default()) {
        Ok(frc) => {
            let nan = (f64::NAN, f64::NAN);
            let stable: Vec<(f64, f64)> = frc
                .points
                .iter()
                .map(|p| {
                    if p.stable() {
                        (p.omega_f, p.amplitude)
                    } else {
                        nan
                    }
                })
                .collect();
            let unstable: Vec<(f64, f64)> = frc
                .points
                .iter()
                .map(|p| {
                    if p.stable() {
                        nan
                    } else {
                        (p.omega_f, p.amplitude)
                    }
                })
                .collect();
            let folds: Vec<String> = frc
                .events
                .iter()
                .map(|f| format!("{:.4}", f.omega_f))
                .collect();
            ctx.line_figure(
                "Fig. 29",
                &Figure {
                    title: "Fig. 29: Duffing amplitude–frequency response (n = 20, N = 64) with stability",
                    x_label: "ω_f [rad/s]",
                    y_label: "amplitude max |x| [-]",
                    series: series(&[("stable", &stable, Style::Line), ("unstable (Hsu multipliers)", &unstable, Style::Markers)]),
                },
                &format!(
                    "pseudo-arclength continuation, {} points; folds at ω_f = {}; the stability flag switches at the folds",
                    frc.points.len(),
                    folds.join(", ")
                ),
            )?;
        }
        Err(e) => ctx.missing_figure("Fig. 29", "Duffing FRC", &e.to_string()),
    }
    Ok(())
}

/// RK4 of Eq. 81 with Ω = 2 (period π): discard `transient` periods, then
/// return the stroboscopic samples x(kπ) of `keep` periods and the phase
/// portrait of the last `portrait` periods, and the final state.
fn mathieu_rk(
    beta: f64,
    y0: [f64; 2],
    transient: usize,
    keep: usize,
    portrait: usize,
) -> (Vec<f64>, Vec<(f64, f64)>, [f64; 2]) {
    let problem = MathieuDuffing::thesis(beta);
    let per = 256;
    let dt = PI / per as f64;
    let mut y = y0;
    let mut t = 0.0;
    rk4(first_order(&problem, 2.0), t, &mut y, dt, transient * per);
    t += transient as f64 * PI;
    let mut strobe = Vec::new();
    let mut phase = Vec::new();
    for k in 0..keep {
        strobe.push(y[0]);
        for _ in 0..per / 8 {
            if k + portrait >= keep {
                phase.push((y[0], y[1]));
            }
            rk4(first_order(&problem, 2.0), t, &mut y, dt, 8);
            t += 8.0 * dt;
        }
    }
    (strobe, phase, y)
}

fn mathieu(ctx: &mut Context) -> Result<(), ReproError> {
    // A0 (§3.2.5): period-1 at β0 = 3.6 with n = 9, solved by the modified IHB
    // from the printed coefficients.
    let a0 = ModifiedIhb::new(MathieuDuffing::thesis(3.6), HbOptions::new(9, 64))
        .and_then(|mut s| s.solve(2.0, Some(&THESIS_A0)));
    match &a0 {
        Ok(sol) => {
            let diff = sol
                .coeffs
                .iter()
                .zip(THESIS_A0)
                .map(|(a, b)| (a - b).abs())
                .fold(0.0, f64::max);
            let ours: Vec<String> = sol.coeffs.iter().map(|c| format!("{c:.4}")).collect();
            let verdict = if diff <= 5e-5 * (1.0 + 1e-9) {
                Verdict::Reproduced
            } else {
                Verdict::Differs
            };
            ctx.row(
                "A0 (§3.2.5, period-1 coefficients at β0 = 3.6, n = 9)",
                "{0.7881 −1.3956 0.2686 0.1121 −0.0260 0.0026 −0.0008 −0.0001 −0.0001 0 1.9884 −0.1693 0.0471 −0.0175 −0.0042 0.0021 −0.0003 0 0} (§3.2.5; printed \"=0.0001\" read as −0.0001)",
                format!("{{{}}}", ours.join(" ")),
                format!("max |Δ| = {diff:.1e}"),
                verdict,
                if verdict == Verdict::Reproduced {
                    "modified IHB from the printed A0, converged: every coefficient agrees to the printed 4 decimals".to_string()
                } else {
                    let names: Vec<String> = (0..=9).map(|k| format!("a{k}")).chain((1..=9).map(|k| format!("b{k}"))).collect();
                    let off: Vec<String> = sol
                        .coeffs
                        .iter()
                        .zip(THESIS_A0)
                        .zip(&names)
                        .filter(|((a, b), _)| (**a - *b).abs() > 5e-5)
                        .map(|((a, b), n)| format!("{n}: printed {b}, ours {a:.5}"))
                        .collect();
                    format!(
                        "modified IHB (n = 9, N = 64) from the printed A0 converges (residual {:.1e}) to a solution that \
                         differs beyond half a printed unit only in {}. a8: the printed \"=0.0001\" is a garbled sign, \
                         and read as +0.0001 it agrees; b3: ours is 0.04718 also when stopped at the thesis's residual \
                         tolerance 1e-6, for AFT sizes N = 10…64 and with n = 20 harmonics; a β off 3.6 that gives \
                         0.0471 moves a1 off its printed digits (db3/dβ ≈ −0.28, da1/dβ ≈ 1.7), and truncating instead \
                         of rounding would print a0 = 0.7880, not 0.7881: all ruled out (`{A0_RULED_OUT}`); so are a slip \
                         in ξ̂, α̂, γ or Ω (no value that prints b3 = 0.0471 keeps the other 18 printed digits), the classic \
                         IHB's Galerkin integrals (the same b3) and a flipped damping or forcing sign (`{A0_SLIPS}`), and \
                         collocation at the 2n + 1 = 19 points (b3 = 0.04718 again) or Eq. 83 taken literally (damping on \
                         u: another solution) (`{A0_COLLOCATION}`); what \
                         remains, a slip in the last printed digit, no computation can show (demonstrated by `{A0_TEST}`)",
                        sol.stats.residual_norm,
                        off.join("; ")
                    )
                },
            );
            if verdict == Verdict::Differs {
                if let Some(r) = ctx.rows.last_mut() {
                    r.cause_test = Some(A0_TEST);
                }
            }
        }
        Err(e) => ctx.not_computable("A0 (§3.2.5)", "§3.2.5", &e.to_string()),
    }

    let cascade = period_doubling_cascade(&CascadeOptions::default());
    let betas: Vec<f64> = match &cascade {
        Ok(pds) => {
            for (pd, (name, thesis)) in
                pds.iter()
                    .zip([("β1", 4.825), ("β2", 5.194), ("β4", 5.253)])
            {
                ctx.compare(
                    &format!("{name} (period {} → {})", pd.period, 2 * pd.period),
                    thesis,
                    "§3.2.5",
                    pd.beta,
                    5e-4,
                    6,
                    &format!(
                        "continuation in β with Hsu multipliers, μ = −1 located on its extended system (μ = {:.8}), n = 12·period",
                        pd.multiplier.re
                    ),
                    Some(Cause {
                        why: "the thesis located β by stepping the controlled amplitude on a 0.0005/0.0001 grid, \
                              which resolves β only to a few 1e-3; ours is the converged crossing (unchanged to 1e-6 \
                              from n = 12 to 20) and agrees with RK4 time integration on either side of β1",
                        test: "crates/ivt-hb/tests/mathieu.rs::cascade_matches_thesis_and_is_converged_in_n",
                    }),
                );
            }
            pds.iter().map(|p| p.beta).collect()
        }
        Err(e) => {
            for q in ["β1", "β2", "β4"] {
                ctx.not_computable(q, "§3.2.5", &e.to_string());
            }
            Vec::new()
        }
    };

    // Figs. 30–32: phase portraits of the attractors at the thesis's β, by RK4
    // from the period-1 orbit's initial state.
    let y0 = match &a0 {
        Ok(sol) => [
            eval_series(&sol.coeffs, 0.0, 0),
            2.0 * eval_series(&sol.coeffs, 0.0, 1),
        ],
        Err(_) => [1.0, 0.0],
    };
    let transient = if ctx.quick() { 600 } else { 2000 };
    for (id, beta, expect) in [
        ("Fig. 30", 4.1906, 1),
        ("Fig. 31", 4.8390, 2),
        ("Fig. 32", 5.2508, 4),
    ] {
        let (strobe, phase, _) = mathieu_rk(beta, y0, transient, 16, 4);
        let first8 = strobe
            .get(..8)
            .ok_or_else(|| ReproError::Numeric(format!("{id}: fewer than 8 strobe points")))?;
        let distinct = distinct_count(first8, 1e-3);
        let title = format!(
            "{id}: Mathieu–Duffing attractor at β = {beta} (RK4, ξ̂ = 0.125, α̂ = 1, Ω = 2, γ = 1)"
        );
        ctx.line_figure(
            id,
            &Figure {
                title: &title,
                x_label: "u [-]",
                y_label: "du/dt [1/s]",
                series: series(&[("last 4 forcing periods", &phase, Style::Line)]),
            },
            &format!(
                "period of the attractor from the stroboscopic samples u(kπ): {distinct} (thesis: period {expect}); \
                 drawn from time integration after {transient} forcing periods"
            ),
        )?;
    }

    // Fig. 33: bifurcation diagram, stroboscopic samples over β.
    let nb = if ctx.quick() { 60 } else { 240 };
    let mut diagram = Vec::new();
    let mut y = y0;
    for i in 0..nb {
        let beta = 3.6 + (5.3 - 3.6) * i as f64 / (nb - 1) as f64;
        let (strobe, _, end) = mathieu_rk(beta, y, if ctx.quick() { 300 } else { 800 }, 16, 0);
        // Continue from the attractor just found (an upward sweep in β).
        y = end;
        diagram.extend(strobe.iter().map(|&x| (beta, x)));
    }
    let marks: Vec<(f64, f64)> = {
        let (lo, hi) = diagram
            .iter()
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), p| {
                (a.min(p.1), b.max(p.1))
            });
        betas
            .iter()
            .flat_map(|&b| [(b, lo), (b, hi), (f64::NAN, f64::NAN)])
            .collect()
    };
    ctx.line_figure(
        "Fig. 33",
        &Figure {
            title: "Fig. 33: Mathieu–Duffing bifurcation diagram (stroboscopic u(kπ) by RK4)",
            x_label: "β [-]",
            y_label: "u(kπ) [-]",
            series: series(&[("RK4 attractor samples", &diagram, Style::Markers), ("β1, β2, β4 from HB + Hsu", &marks, Style::Dashed)]),
        },
        "each β continues from the previous attractor; the dashed lines are the HB period-doubling points",
    )?;
    Ok(())
}

fn distinct_count(xs: &[f64], tol: f64) -> usize {
    let mut seen: Vec<f64> = Vec::new();
    for &x in xs {
        if !seen.iter().any(|s| (s - x).abs() < tol) {
            seen.push(x);
        }
    }
    seen.len()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn a0_with(tol: f64, n_half: usize) -> Vec<f64> {
        let opts = HbOptions::new(9, n_half).with_tol(tol);
        ModifiedIhb::new(MathieuDuffing::thesis(3.6), opts)
            .and_then(|mut s| s.solve(2.0, Some(&THESIS_A0)))
            .unwrap()
            .coeffs
    }

    /// A0 row: converged from the printed vector, only a8 (index 8) and b3
    /// (index 12) leave half a printed unit. a8 = +0.00013 agrees with the
    /// garbled "=0.0001" read as +0.0001. b3 = 0.04718 rounds to 0.0472 under
    /// the thesis's residual tolerance 1e-6 as well as at 1e-10, and for every
    /// AFT size N = 10…64: neither explains the printed 0.0471.
    #[test]
    fn a0_differs_in_a8_sign_and_b3() {
        for (tol, n_half) in [
            (1e-10, 64),
            (1e-6, 64),
            (1e-10, 10),
            (1e-10, 16),
            (1e-10, 32),
        ] {
            let c = a0_with(tol, n_half);
            let off: Vec<usize> = c
                .iter()
                .zip(THESIS_A0)
                .enumerate()
                .filter(|(_, (a, b))| (**a - b).abs() > 5e-5)
                .map(|(i, _)| i)
                .collect();
            assert_eq!(off, [8, 12], "tol {tol:e}, N {n_half}");
            assert!((c[8] - 1e-4).abs() < 5e-5, "a8 = {}", c[8]);
            assert!((c[12] - 0.04718).abs() < 1e-5, "b3 = {}", c[12]);
        }
    }

    /// What does not explain the printed b3 = 0.0471 (ours 0.047179):
    /// - β: a β that brings b3 within half a unit of 0.0471 moves a1 beyond
    ///   half a unit of the printed −1.3956 (b3 and a1 move together);
    /// - n: with n = 20 harmonics b3 is still 0.04718 (to 1e-5);
    /// - truncating instead of rounding: a0 = 0.78806 would print 0.7880,
    ///   not 0.7881, while b3 would print 0.0471.
    #[test]
    fn a0_b3_is_not_beta_n_or_truncation() {
        let solve = |beta: f64, n: usize| {
            let mut start = vec![0.0; 2 * n + 1];
            start[..=9].copy_from_slice(&THESIS_A0[..=9]);
            start[n + 1..=n + 9].copy_from_slice(&THESIS_A0[10..]);
            let c = ModifiedIhb::new(MathieuDuffing::thesis(beta), HbOptions::new(n, 64))
                .and_then(|mut s| s.solve(2.0, Some(&start)))
                .unwrap()
                .coeffs;
            (c[0], c[1], c[n + 3])
        };
        for i in 0..=200 {
            let beta = 3.59 + 1e-4 * i as f64;
            let (_, a1, b3) = solve(beta, 9);
            if (b3 - 0.0471).abs() <= 5e-5 {
                assert!(
                    (a1 - THESIS_A0[1]).abs() > 5e-5,
                    "β = {beta}: a1 {a1}, b3 {b3}"
                );
            }
        }
        let (_, _, b3) = solve(3.6, 20);
        assert!((b3 - 0.04718).abs() < 1e-5, "n = 20: b3 = {b3}");
        let (a0, _, b3) = solve(3.6, 9);
        let trunc = |x: f64| (x * 1e4).trunc() / 1e4;
        assert_eq!(trunc(b3), 0.0471);
        assert!((trunc(a0) - 0.7880).abs() < 1e-12 && (THESIS_A0[0] - 0.7881).abs() < 1e-12);
    }
}
