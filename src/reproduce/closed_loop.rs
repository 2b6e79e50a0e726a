//! §4.3–4.4 closed loop on the printed plant through the simulator (the same
//! `ivt-ctrl` controller the firmware runs): analogues of Figs. 43–45 and a
//! simulated Fig. 51 drive cycle, from the shipped scenes in `scenes/`.
//!
//! Analogues, not reproductions: the thesis's scene of §4.3 (T_U = 8 N·m,
//! V_m 8 → 7 V) leaves the feasible band of the printed plant (SPEC §5), so
//! the scenes keep the same shape inside the band; their gains come from the
//! simulator's gain study (crates/ivt-sim/README.md).

use super::{Context, ReproError};
use ivt_plot::{Figure, Series, Style};
use ivt_sim::run::Simulation;
use ivt_sim::scene::Scene;

const RAD_S_TO_RPM: f64 = 60.0 / (2.0 * std::f64::consts::PI);

/// (t, ω, ω_a, r, V_m, T_U) samples of a shipped scene, or why not.
fn simulate(name: &str, src: &str) -> Result<Vec<[f64; 6]>, String> {
    let scene = Scene::parse(src, name).map_err(|e| e.to_string())?;
    let res = Simulation::new(&scene).run().map_err(|e| e.to_string())?;
    res.channels
        .plot
        .ok_or_else(|| format!("{name}: the scene records no plot series"))
}

fn column(samples: &[[f64; 6]], j: usize, scale: f64) -> Vec<(f64, f64)> {
    samples.iter().map(|s| (s[0], s[j] * scale)).collect()
}

pub(crate) fn run(ctx: &mut Context) -> Result<(), ReproError> {
    ctx.step("closed loop: Figs. 43-45");
    let open = simulate(
        "scenes/voltage_step_open.toml",
        include_str!("../../scenes/voltage_step_open.toml"),
    );
    let delay_v = simulate(
        "scenes/voltage_step_delay.toml",
        include_str!("../../scenes/voltage_step_delay.toml"),
    );
    match (&open, &delay_v) {
        (Ok(a), Ok(b)) => {
            let (wa, wb) = (column(a, 2, RAD_S_TO_RPM), column(b, 2, RAD_S_TO_RPM));
            let v = column(b, 4, 10.0);
            ctx.line_figure(
                "Fig. 43",
                &Figure {
                    title: "Fig. 43 analogue: ω_a with and without the time-delay feedback after a V_m step",
                    x_label: "t [s]",
                    y_label: "ω_a [rpm]; V_m [V]×10",
                    series: vec![
                        Series { label: "open loop (u_ol only)", points: &wa, style: Style::Line },
                        Series { label: "time-delay feedback, Eq. 180", points: &wb, style: Style::Line },
                        Series { label: "V_m × 10", points: &v, style: Style::Dashed },
                    ],
                },
                "scenes voltage_step_open/voltage_step_delay: V_m 8.9 → 8.4 V inside the feasible band (the thesis's \
                 8 → 7 V at 8 N·m leaves it on the printed plant, SPEC §5)",
            )?;
        }
        (Err(e), _) | (_, Err(e)) => ctx.missing_figure("Fig. 43", "closed loop, V_m step", e),
    }
    let delay = simulate(
        "scenes/load_step_delay.toml",
        include_str!("../../scenes/load_step_delay.toml"),
    );
    let nodelay = simulate(
        "scenes/load_step_nodelay.toml",
        include_str!("../../scenes/load_step_nodelay.toml"),
    );
    match (&delay, &nodelay) {
        (Ok(a), Ok(b)) => {
            let (wa, wb) = (column(a, 2, RAD_S_TO_RPM), column(b, 2, RAD_S_TO_RPM));
            ctx.line_figure(
                "Fig. 44",
                &Figure {
                    title: "Fig. 44 analogue: ω_a for the feedback with and without time delay (T_U 6 → 8 N·m, V_m = 8.6 V)",
                    x_label: "t [s]",
                    y_label: "ω_a [rpm]",
                    series: vec![
                        Series { label: "with time delay, Eq. 180", points: &wa, style: Style::Line },
                        Series { label: "without time delay, Eq. 181", points: &wb, style: Style::Dashed },
                    ],
                },
                "scenes load_step_delay/load_step_nodelay, same gain k; the no-delay law keeps a static error in ω_a \
                 (it regulates the θ-mean of ω, not the time mean; crates/ivt-sim/README.md)",
            )?;
            let (ra, rb) = (column(a, 3, 1e3), column(b, 3, 1e3));
            ctx.line_figure(
                "Fig. 45",
                &Figure {
                    title: "Fig. 45 analogue: control variable r with and without time delay",
                    x_label: "t [s]",
                    y_label: "r [mm]",
                    series: vec![
                        Series { label: "with time delay, Eq. 180", points: &ra, style: Style::Line },
                        Series { label: "without time delay, Eq. 181", points: &rb, style: Style::Line },
                    ],
                },
                "both with the refitted feed-forward u_ol (REFIT), which steps r by the same amount at the load step; \
                 the delay law's feedback part is much smoother (ivt-sim test delay_law_is_smoother_than_no_delay_law)",
            )?;
        }
        (Err(e), _) | (_, Err(e)) => {
            ctx.missing_figure("Fig. 44", "closed loop, load step", e);
            ctx.missing_figure("Fig. 45", "closed loop, load step", e);
        }
    }
    ctx.step("closed loop: Fig. 51 drive cycle");
    match simulate("scenes/drive.toml", include_str!("../../scenes/drive.toml")) {
        Ok(s) => {
            let (w, r, t, v) = (
                column(&s, 2, RAD_S_TO_RPM),
                column(&s, 3, 5e3),
                column(&s, 5, 10.0),
                column(&s, 4, 10.0),
            );
            ctx.line_figure(
                "Fig. 51",
                &Figure {
                    title: "Fig. 51 (simulated): drive cycle on the printed plant, delay law",
                    x_label: "t [s]",
                    y_label: "ω_a [rpm]; r [mm]×5; T_U [N·m]×10; V_m [V]×10",
                    series: vec![
                        Series { label: "ω_a", points: &w, style: Style::Line },
                        Series { label: "r × 5 [mm]", points: &r, style: Style::Line },
                        Series { label: "T_U × 10", points: &t, style: Style::Dashed },
                        Series { label: "V_m × 10", points: &v, style: Style::Dashed },
                    ],
                },
                "scene drive.toml: the six stages of §4.4.3 (idle, start-up, flat, uphill, downhill, stop) inside the \
                 feasible band; the rig test itself (Fig. 51, ω_r = 60 rpm, Eq. 189) is measured data",
            )?;
        }
        Err(e) => ctx.missing_figure("Fig. 51", "drive cycle", &e),
    }
    Ok(())
}
