//! PNG plots of a run: one stacked panel per requested signal. Pure Rust:
//! plotters' bitmap backend with the font that `ivt-plot` embeds and
//! registers at run time (one font setup for the whole toolkit).

use crate::error::SimError;
use crate::record::{Panel, PlantSample};
use plotters::prelude::*;
use std::path::Path;

/// Draw the panels `plots` of the plant samples `series` into `path`.
///
/// # Errors
/// Drawing or encoding failures.
pub fn draw(
    path: &Path,
    title: &str,
    plots: &[Panel],
    series: &[PlantSample],
    omega0: f64,
) -> Result<(), SimError> {
    ivt_plot::ensure_font();
    let err = |e: String| SimError::Plot {
        path: path.to_path_buf(),
        msg: e,
    };
    let n = plots.len().max(1);
    let root = BitMapBackend::new(path, (1200, 220 * n as u32 + 40)).into_drawing_area();
    root.fill(&WHITE).map_err(|e| err(e.to_string()))?;
    let root = root
        .titled(title, ("sans-serif", 22))
        .map_err(|e| err(e.to_string()))?;
    let areas = root.split_evenly((n, 1));
    let t_end = series.last().map_or(1.0, |s| s.t).max(1e-9);
    for (area, &panel) in areas.iter().zip(plots) {
        let (label, scale) = panel.label();
        let pts: Vec<(f64, f64)> = series
            .iter()
            .filter(|s| panel.of(s).is_finite())
            .map(|s| (s.t, panel.of(s) * scale))
            .collect();
        let (mut lo, mut hi) = pts
            .iter()
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), p| {
                (a.min(p.1), b.max(p.1))
            });
        if !lo.is_finite() {
            (lo, hi) = (0.0, 1.0);
        }
        let pad = ((hi - lo) * 0.08).max(1e-6 * hi.abs().max(1.0));
        let mut chart = ChartBuilder::on(area)
            .margin(8)
            .x_label_area_size(28)
            .y_label_area_size(70)
            .caption(label, ("sans-serif", 16))
            .build_cartesian_2d(0.0..t_end, (lo - pad)..(hi + pad))
            .map_err(|e| err(e.to_string()))?;
        chart
            .configure_mesh()
            .x_desc("t [s]")
            .label_style(("sans-serif", 12))
            .draw()
            .map_err(|e| err(e.to_string()))?;
        if panel.is_speed() {
            let w0 = omega0 * scale;
            chart
                .draw_series(LineSeries::new([(0.0, w0), (t_end, w0)], RED.mix(0.6)))
                .map_err(|e| err(e.to_string()))?;
        }
        chart
            .draw_series(LineSeries::new(pts, &BLUE))
            .map_err(|e| err(e.to_string()))?;
    }
    root.present().map_err(|e| err(e.to_string()))?;
    Ok(())
}
