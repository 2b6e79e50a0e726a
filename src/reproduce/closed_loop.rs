//! §4.3–4.4 closed loop on the printed plant through the simulator (the same
//! `ivt-ctrl` controller the firmware runs): analogues of Figs. 43–45 and a
//! simulated Fig. 51 drive cycle, from the shipped scenes in `scenes/`.
//!
//! Analogues, not reproductions: the thesis's scene of §4.3 (T_U = 8 N·m,
//! V_m 8 → 7 V) leaves the feasible band of the printed plant (SPEC §5), so
//! the scenes keep the same shape inside the band; their gains come from the
//! simulator's gain study (crates/ivt-sim/README.md).

use super::{series, Context, ReproError};
use ivt_plot::{Figure, Style};
use ivt_sim::record::{Panel, PlantSample};
use ivt_sim::run::{Simulation, Summary};
use ivt_sim::scene::Scene;

pub(super) const RAD_S_TO_RPM: f64 = 60.0 / (2.0 * std::f64::consts::PI);

/// Run a scene: its summary and its plot samples of the plant, or why not.
pub(super) fn simulate(name: &str, src: &str) -> Result<(Summary, Vec<PlantSample>), String> {
    let scene = Scene::parse(src, name).map_err(|e| e.to_string())?;
    let res = Simulation::new(&scene).run().map_err(|e| e.to_string())?;
    let plot = res
        .channels
        .plot
        .ok_or_else(|| format!("{name}: the scene records no plot series"))?;
    Ok((res.summary, plot))
}

/// [`simulate`] a scene shipped in `scenes/` (compiled in, so the report
/// does not depend on the working directory).
macro_rules! shipped_scene {
    ($name:literal) => {
        super::closed_loop::simulate(
            concat!("scenes/", $name, ".toml"),
            include_str!(concat!("../../scenes/", $name, ".toml")),
        )
    };
}
pub(super) use shipped_scene;

/// One plot panel of the plant samples against t, scaled.
pub(super) fn column(samples: &[PlantSample], panel: Panel, scale: f64) -> Vec<(f64, f64)> {
    samples.iter().map(|s| (s.t, panel.of(s) * scale)).collect()
}

/// A Fig. 43 panel: ω_a \[rpm\] of an open-loop and a feedback run after a
/// V_m step, with V_m × 10 of the feedback run.
pub(super) fn fig43_panel(
    ctx: &mut Context,
    id: &str,
    title: &str,
    open: (&str, &[PlantSample]),
    feedback: (&str, &[PlantSample]),
    note: &str,
) -> Result<(), ReproError> {
    let (wo, wf) = (
        column(open.1, Panel::OmegaA, RAD_S_TO_RPM),
        column(feedback.1, Panel::OmegaA, RAD_S_TO_RPM),
    );
    let v = column(feedback.1, Panel::VM, 10.0);
    ctx.line_figure(
        id,
        &Figure {
            title,
            x_label: "t [s]",
            y_label: "ω_a [rpm]; V_m [V]×10",
            series: series(&[
                (open.0, &wo, Style::Line),
                (feedback.0, &wf, Style::Line),
                ("V_m × 10", &v, Style::Dashed),
            ]),
        },
        note,
    )
}

pub(crate) fn run(ctx: &mut Context) -> Result<(), ReproError> {
    ctx.step("closed loop: Figs. 43-45");
    let open = shipped_scene!("voltage_step_open").map(|(_, s)| s);
    let delay_v = shipped_scene!("voltage_step_delay").map(|(_, s)| s);
    match (&open, &delay_v) {
        (Ok(a), Ok(b)) => fig43_panel(
            ctx,
            "Fig. 43",
            "Fig. 43 analogue: ω_a with and without the time-delay feedback after a V_m step",
            ("open loop (u_ol only)", a),
            ("time-delay feedback, Eq. 180", b),
            "scenes voltage_step_open/voltage_step_delay: V_m 8.9 → 8.4 V inside the feasible band (the thesis's \
                 8 → 7 V at 8 N·m leaves it on the printed plant, SPEC §5)",
        )?,
        (Err(e), _) | (_, Err(e)) => ctx.missing_figure("Fig. 43", "closed loop, V_m step", e),
    }
    let delay = shipped_scene!("load_step_delay").map(|(_, s)| s);
    let nodelay = shipped_scene!("load_step_nodelay").map(|(_, s)| s);
    match (&delay, &nodelay) {
        (Ok(a), Ok(b)) => {
            let (wa, wb) = (
                column(a, Panel::OmegaA, RAD_S_TO_RPM),
                column(b, Panel::OmegaA, RAD_S_TO_RPM),
            );
            ctx.line_figure(
                "Fig. 44",
                &Figure {
                    title: "Fig. 44 analogue: ω_a for the feedback with and without time delay (T_U 6 → 8 N·m, V_m = 8.6 V)",
                    x_label: "t [s]",
                    y_label: "ω_a [rpm]",
                    series: series(&[("with time delay, Eq. 180", &wa, Style::Line), ("without time delay, Eq. 181", &wb, Style::Dashed)]),
                },
                "scenes load_step_delay/load_step_nodelay, same gain k; the no-delay law keeps a static error in ω_a \
                 (it regulates the θ-mean of ω, not the time mean; crates/ivt-sim/README.md)",
            )?;
            let (ra, rb) = (column(a, Panel::R, 1e3), column(b, Panel::R, 1e3));
            ctx.line_figure(
                "Fig. 45",
                &Figure {
                    title: "Fig. 45 analogue: control variable r with and without time delay",
                    x_label: "t [s]",
                    y_label: "r [mm]",
                    series: series(&[("with time delay, Eq. 180", &ra, Style::Line), ("without time delay, Eq. 181", &rb, Style::Line)]),
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
    match shipped_scene!("drive").map(|(_, s)| s) {
        Ok(s) => {
            let (w, r, t, v) = (
                column(&s, Panel::OmegaA, RAD_S_TO_RPM),
                column(&s, Panel::R, 5e3),
                column(&s, Panel::TU, 10.0),
                column(&s, Panel::VM, 10.0),
            );
            ctx.line_figure(
                "Fig. 51",
                &Figure {
                    title: "Fig. 51 (simulated): drive cycle on the printed plant, delay law",
                    x_label: "t [s]",
                    y_label: "ω_a [rpm]; r [mm]×5; T_U [N·m]×10; V_m [V]×10",
                    series: series(&[("ω_a", &w, Style::Line), ("r × 5 [mm]", &r, Style::Line), ("T_U × 10", &t, Style::Dashed), ("V_m × 10", &v, Style::Dashed)]),
                },
                "scene drive.toml: the six stages of §4.4.3 (idle, start-up, flat, uphill, downhill, stop) inside the \
                 feasible band; the rig test itself (Fig. 51, ω_r = 60 rpm, Eq. 189) is measured data",
            )?;
        }
        Err(e) => ctx.missing_figure("Fig. 51", "drive cycle", &e),
    }
    Ok(())
}
