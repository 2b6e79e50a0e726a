//! PNG heat map of a (V_m, T_U) grid (Fig. 42 analogue), drawn with plotters'
//! bitmap backend and an ab_glyph font loaded at run time (no system font
//! libraries at build time). Font: `$IVT_FONT`, else common DejaVu/Liberation paths.

use super::CliError;
use plotters::prelude::*;
use plotters::style::{register_font, FontStyle};

const FONT_PATHS: [&str; 4] = [
    "/usr/share/fonts/truetype/dejavu/DejaVuSans.ttf",
    "/usr/share/fonts/TTF/DejaVuSans.ttf",
    "/usr/share/fonts/truetype/liberation/LiberationSans-Regular.ttf",
    "/System/Library/Fonts/Supplemental/Arial.ttf",
];

fn load_font() -> Result<(), CliError> {
    let path = std::env::var("IVT_FONT")
        .ok()
        .or_else(|| {
            FONT_PATHS
                .iter()
                .find(|p| std::path::Path::new(p).exists())
                .map(|p| p.to_string())
        })
        .ok_or_else(|| {
            CliError::Input("no TTF font found for --plot; set IVT_FONT=/path/to/font.ttf".into())
        })?;
    let bytes =
        std::fs::read(&path).map_err(|e| CliError::Failed(format!("reading font {path}: {e}")))?;
    // plotters keeps registered fonts for the process lifetime.
    let bytes: &'static [u8] = Box::leak(bytes.into_boxed_slice());
    register_font("sans-serif", FontStyle::Normal, bytes)
        .map_err(|_| CliError::Failed(format!("{path} is not a usable TTF font")))
}

/// Colour for a max |multiplier|: blue (lo) → yellow (hi) over the data's
/// range below 1; ≥ 1 (unstable) red; failed/skipped grey.
fn colour(v: Option<f64>, lo: f64, hi: f64) -> RGBColor {
    match v {
        None => RGBColor(160, 160, 160),
        Some(m) if m >= 1.0 => RGBColor(200, 0, 0),
        Some(m) => {
            let t = ((m - lo) / (hi - lo).max(1e-12)).clamp(0.0, 1.0);
            RGBColor(
                (40.0 + 215.0 * t) as u8,
                (60.0 + 170.0 * t) as u8,
                (200.0 * (1.0 - t)) as u8,
            )
        }
    }
}

/// Draw cells `(v_m, t_u, value)` with cell size (dv, dt) to `path`.
///
/// # Errors
/// No font, or a drawing/encoding failure.
pub fn draw(
    path: &std::path::Path,
    title: &str,
    cells: &[(f64, f64, Option<f64>)],
    dv: f64,
    dt: f64,
) -> Result<(), CliError> {
    load_font()?;
    let stable = cells.iter().filter_map(|c| c.2).filter(|m| *m < 1.0);
    let (lo, hi) = stable.fold((f64::INFINITY, f64::NEG_INFINITY), |a, m| {
        (a.0.min(m), a.1.max(m))
    });
    let title = format!("{title}; blue {lo:.4} → yellow {hi:.4}, red ≥ 1");
    let fail = |e: String| CliError::Failed(format!("plot {}: {e}", path.display()));
    let (v0, v1) = cells
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |a, c| {
            (a.0.min(c.0), a.1.max(c.0))
        });
    let (t0, t1) = cells
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |a, c| {
            (a.0.min(c.1), a.1.max(c.1))
        });
    let root = BitMapBackend::new(path, (900, 600)).into_drawing_area();
    root.fill(&WHITE).map_err(|e| fail(e.to_string()))?;
    let mut chart = ChartBuilder::on(&root)
        .caption(&title, ("sans-serif", 16))
        .margin(15)
        .x_label_area_size(40)
        .y_label_area_size(50)
        .build_cartesian_2d(
            (v0 - dv / 2.0)..(v1 + dv / 2.0),
            (t0 - dt / 2.0)..(t1 + dt / 2.0),
        )
        .map_err(|e| fail(e.to_string()))?;
    chart
        .configure_mesh()
        .x_desc("V_m [V]")
        .y_desc("T_U [N·m]")
        .disable_mesh()
        .draw()
        .map_err(|e| fail(e.to_string()))?;
    chart
        .draw_series(cells.iter().map(|&(v, t, m)| {
            Rectangle::new(
                [(v - dv / 2.0, t - dt / 2.0), (v + dv / 2.0, t + dt / 2.0)],
                colour(m, lo, hi).filled(),
            )
        }))
        .map_err(|e| fail(e.to_string()))?;
    root.present().map_err(|e| fail(e.to_string()))?;
    Ok(())
}
