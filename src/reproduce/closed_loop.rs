//! §4.3–4.4 closed loop on the printed plant through the simulator (the same
//! `ivt-ctrl` controller the firmware runs): analogues of Figs. 43–45 and a
//! simulated Fig. 51 drive cycle, from the shipped scenes in `scenes/`.
//!
//! Analogues, not reproductions: the thesis's scene of §4.3 (T_U = 8 N·m,
//! V_m 8 → 7 V) leaves the feasible band of the printed plant (SPEC §5), so
//! the scenes keep the same shape inside the band; their gains come from the
//! simulator's gain study (docs/guide/src/controller/gains.md).

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

/// What a panel of two runs plots (Figs. 43–45): a `plant` field, its scale
/// to plot units, the axis label, the second run's line style, and whether
/// V_m × 10 of the second run is drawn too (dashed).
pub(super) struct RunPair {
    panel: Panel,
    scale: f64,
    y_label: &'static str,
    second_style: Style,
    v_m_of_second: bool,
}

/// Fig. 43: ω_a \[rpm\] of an open-loop and a feedback run after a V_m
/// step, with V_m × 10 of the feedback run.
pub(super) const FIG43: RunPair = RunPair {
    panel: Panel::OmegaA,
    scale: RAD_S_TO_RPM,
    y_label: "ω_a [rpm]; V_m [V]×10",
    second_style: Style::Line,
    v_m_of_second: true,
};

/// Fig. 44: ω_a \[rpm\] with the time-delay law (Eq. 180) and without it
/// (Eq. 181, dashed).
pub(super) const FIG44: RunPair = RunPair {
    panel: Panel::OmegaA,
    scale: RAD_S_TO_RPM,
    y_label: "ω_a [rpm]",
    second_style: Style::Dashed,
    v_m_of_second: false,
};

/// Fig. 45: the control variable r \[mm\] with and without time delay.
pub(super) const FIG45: RunPair = RunPair {
    panel: Panel::R,
    scale: 1e3,
    y_label: "r [mm]",
    second_style: Style::Line,
    v_m_of_second: false,
};

/// A panel of two runs, each as (legend label, samples), against t \[s\].
pub(super) fn run_pair_panel(
    ctx: &mut Context,
    what: &RunPair,
    id: &str,
    title: &str,
    first: (&str, &[PlantSample]),
    second: (&str, &[PlantSample]),
    note: &str,
) -> Result<(), ReproError> {
    let (y1, y2) = (
        column(first.1, what.panel, what.scale),
        column(second.1, what.panel, what.scale),
    );
    let v = if what.v_m_of_second {
        column(second.1, Panel::VM, 10.0)
    } else {
        Vec::new()
    };
    let mut curves = vec![
        (first.0, y1.as_slice(), Style::Line),
        (second.0, y2.as_slice(), what.second_style),
    ];
    if what.v_m_of_second {
        curves.push(("V_m × 10", v.as_slice(), Style::Dashed));
    }
    ctx.line_figure(
        id,
        &Figure {
            title,
            x_label: "t [s]",
            y_label: what.y_label,
            series: series(&curves),
        },
        note,
    )
}

pub(crate) fn run(ctx: &mut Context) -> Result<(), ReproError> {
    ctx.step("closed loop: Figs. 43-45");
    let open = shipped_scene!("voltage_step_open").map(|(_, s)| s);
    let delay_v = shipped_scene!("voltage_step_delay").map(|(_, s)| s);
    match (&open, &delay_v) {
        (Ok(a), Ok(b)) => run_pair_panel(
            ctx,
            &FIG43,
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
            run_pair_panel(
                ctx,
                &FIG44,
                "Fig. 44",
                "Fig. 44 analogue: ω_a for the feedback with and without time delay (T_U 6 → 8 N·m, V_m = 8.6 V)",
                ("with time delay, Eq. 180", a),
                ("without time delay, Eq. 181", b),
                "scenes load_step_delay/load_step_nodelay, same gain k; the no-delay law keeps a static error in ω_a \
                 (it regulates the θ-mean of ω, not the time mean; crates/ivt-sim/README.md)",
            )?;
            run_pair_panel(
                ctx,
                &FIG45,
                "Fig. 45",
                "Fig. 45 analogue: control variable r with and without time delay",
                ("with time delay, Eq. 180", a),
                ("without time delay, Eq. 181", b),
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
