#![doc = include_str!("../README.md")]

use plotters::coord::types::RangedCoordf64;
use plotters::coord::Shift;
use plotters::element::DashedPathElement;
use plotters::prelude::*;
use plotters::style::{register_font, FontStyle};
use std::path::{Path, PathBuf};
use std::sync::Once;

static FONT: &[u8] = include_bytes!("../assets/DejaVuSans-subset.ttf");
static REGISTER: Once = Once::new();

/// Register the embedded font under the family name `"sans-serif"` (once per
/// process). Called by every drawing function; public for callers that draw
/// with plotters directly.
pub fn ensure_font() {
    REGISTER.call_once(|| {
        // The embedded font is checked by this crate's tests; a failure here
        // would only lose text, never the figure.
        let _ = register_font("sans-serif", FontStyle::Normal, FONT);
    });
}

/// A drawing failure, with the file it was for.
#[derive(Debug, thiserror::Error)]
#[error("cannot draw {path}: {msg}")]
pub struct PlotError {
    /// The PNG being written.
    pub path: PathBuf,
    /// What plotters or the encoder reported.
    pub msg: String,
}

impl PlotError {
    /// The same failure, naming `path` (the target of a figure that was drawn
    /// into a staged temporary file).
    #[must_use]
    pub fn for_path(self, path: &Path) -> Self {
        Self {
            path: path.to_path_buf(),
            msg: self.msg,
        }
    }
}

/// How a series is drawn.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Style {
    /// Solid line through the points (NaN points break it).
    Line,
    /// Dashed line (NaN points break it).
    Dashed,
    /// A small filled circle at each point.
    Markers,
    /// A triangle at each point with the series' label written beside it:
    /// the events of a curve (folds, bifurcations, special points), one
    /// marker each. The label is on the plot, not in the legend.
    Events,
}

/// One curve of a [`Figure`].
#[derive(Clone, Copy, Debug)]
pub struct Series<'a> {
    /// Legend text (empty: no legend entry).
    pub label: &'a str,
    /// The (x, y) points in plot units.
    pub points: &'a [(f64, f64)],
    /// How it is drawn.
    pub style: Style,
}

/// A titled x–y figure.
#[derive(Clone, Debug)]
pub struct Figure<'a> {
    /// Title above the plot.
    pub title: &'a str,
    /// x-axis label with unit, e.g. `"ω [rad/s]"`.
    pub x_label: &'a str,
    /// y-axis label with unit.
    pub y_label: &'a str,
    /// Curves, drawn in order with the palette colours.
    pub series: Vec<Series<'a>>,
}

/// The palette, chosen to stay distinguishable in print.
const PALETTE: [RGBColor; 6] = [
    RGBColor(31, 119, 180),
    RGBColor(214, 39, 40),
    RGBColor(44, 160, 44),
    RGBColor(255, 127, 14),
    RGBColor(148, 103, 189),
    RGBColor(23, 190, 207),
];

/// Width and height of every figure in pixels.
const SIZE: (u32, u32) = (1000, 640);

fn finite_range(values: impl Iterator<Item = f64>) -> (f64, f64) {
    let (lo, hi) = values
        .filter(|v| v.is_finite())
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), v| {
            (a.min(v), b.max(v))
        });
    if !lo.is_finite() {
        return (0.0, 1.0);
    }
    // One value (or a span below round-off of it): ±5 % of it, so that the
    // axis still shows where it is.
    let scale = hi.abs().max(lo.abs());
    let pad = if hi - lo > 1e-9 * scale {
        (hi - lo) * 0.05
    } else if scale > 0.0 {
        0.05 * scale
    } else {
        0.05
    };
    (lo - pad, hi + pad)
}

/// A chart on a bitmap with f64 axes.
type Chart<'r, 'p> =
    ChartContext<'r, BitMapBackend<'p>, Cartesian2d<RangedCoordf64, RangedCoordf64>>;

/// The frame every figure kind shares: caption, margins, axis ranges and
/// labelled axes.
struct Frame<'a> {
    title: &'a str,
    caption_px: u32,
    y_label_area: u32,
    x: (f64, f64),
    y: (f64, f64),
    x_label: &'a str,
    y_label: &'a str,
    /// Draw the mesh (grid) lines.
    grid: bool,
}

impl Frame<'_> {
    /// Builds the chart on `root` and draws its axes.
    fn draw<'r, 'p>(
        &self,
        root: &'r DrawingArea<BitMapBackend<'p>, Shift>,
        err: impl Fn(&dyn std::fmt::Display) -> PlotError,
    ) -> Result<Chart<'r, 'p>, PlotError> {
        let mut chart = ChartBuilder::on(root)
            .caption(self.title, ("sans-serif", self.caption_px))
            .margin(12)
            .x_label_area_size(48)
            .y_label_area_size(self.y_label_area)
            .build_cartesian_2d(self.x.0..self.x.1, self.y.0..self.y.1)
            .map_err(|e| err(&e))?;
        let mut mesh = chart.configure_mesh();
        if !self.grid {
            mesh.disable_mesh();
        }
        mesh.x_desc(self.x_label)
            .y_desc(self.y_label)
            .label_style(("sans-serif", 15))
            .draw()
            .map_err(|e| err(&e))?;
        Ok(chart)
    }
}

/// Split a point list at non-finite points into drawable pieces.
fn pieces(points: &[(f64, f64)]) -> impl Iterator<Item = &[(f64, f64)]> {
    points
        .split(|p| !(p.0.is_finite() && p.1.is_finite()))
        .filter(|s| !s.is_empty())
}

/// Draw `figure` into the PNG at `path`.
///
/// # Errors
/// Drawing or encoding failures, as a [`PlotError`] naming the file.
pub fn line_plot(path: &Path, figure: &Figure<'_>) -> Result<(), PlotError> {
    ensure_font();
    let err = |e: &dyn std::fmt::Display| PlotError {
        path: path.to_path_buf(),
        msg: e.to_string(),
    };
    let all = || figure.series.iter().flat_map(|s| s.points.iter());
    let root = BitMapBackend::new(path, SIZE).into_drawing_area();
    root.fill(&WHITE).map_err(|e| err(&e))?;
    let mut chart = Frame {
        title: figure.title,
        caption_px: 24,
        y_label_area: 80,
        x: finite_range(all().map(|p| p.0)),
        y: finite_range(all().map(|p| p.1)),
        x_label: figure.x_label,
        y_label: figure.y_label,
        grid: true,
    }
    .draw(&root, err)?;
    let mut legend = false;
    for (series, &color) in figure.series.iter().zip(PALETTE.iter().cycle()) {
        let mut first = true;
        for piece in pieces(series.points) {
            let anno = match series.style {
                Style::Line => chart.draw_series(LineSeries::new(
                    piece.iter().copied(),
                    color.stroke_width(2),
                )),
                Style::Dashed => chart.draw_series(DashedLineSeries::new(
                    piece.iter().copied(),
                    8,
                    6,
                    color.stroke_width(2),
                )),
                Style::Markers => {
                    chart.draw_series(piece.iter().map(|&p| Circle::new(p, 3, color.filled())))
                }
                Style::Events => chart.draw_series(piece.iter().map(|&p| {
                    EmptyElement::at(p)
                        + TriangleMarker::new((0, 0), 7, color.filled())
                        + Text::new(
                            series.label.to_owned(),
                            (9, -20),
                            ("sans-serif", 16).into_font().color(&color),
                        )
                })),
            }
            .map_err(|e| err(&e))?;
            if first && !series.label.is_empty() && series.style != Style::Events {
                // The legend's sample: a short solid or dashed line, or the marker.
                let anno = anno.label(series.label);
                let line = move |x: i32, y: i32| vec![(x, y), (x + 20, y)];
                match series.style {
                    Style::Dashed => anno.legend(move |(x, y)| {
                        DashedPathElement::new(line(x, y), 6, 4, color.stroke_width(2))
                    }),
                    Style::Markers => {
                        anno.legend(move |(x, y)| Circle::new((x + 10, y), 3, color.filled()))
                    }
                    Style::Line | Style::Events => anno
                        .legend(move |(x, y)| PathElement::new(line(x, y), color.stroke_width(2))),
                };
                legend = true;
            }
            first = false;
        }
    }
    if legend {
        chart
            .configure_series_labels()
            .background_style(WHITE.mix(0.85))
            .border_style(BLACK)
            .label_font(("sans-serif", 15))
            .draw()
            .map_err(|e| err(&e))?;
    }
    root.present().map_err(|e| err(&e))
}

/// A value on a grid: `values[j * xs.len() + i]` belongs to `(xs[i], ys[j])`.
#[derive(Clone, Debug)]
pub struct HeatMap<'a> {
    /// Title above the plot.
    pub title: &'a str,
    /// x-axis label with unit.
    pub x_label: &'a str,
    /// y-axis label with unit.
    pub y_label: &'a str,
    /// What the colour means, with unit (shown in the title line).
    pub value_label: &'a str,
    /// Grid abscissae, increasing.
    pub xs: &'a [f64],
    /// Grid ordinates, increasing.
    pub ys: &'a [f64],
    /// Row-major values; NaN cells are drawn grey (e.g. infeasible points).
    pub values: &'a [f64],
}

/// Draw a [`HeatMap`] into the PNG at `path`, cells coloured from blue (low)
/// to red (high) over the finite values' range.
///
/// # Errors
/// A size mismatch between the grid and the values, or drawing failures.
pub fn heat_map(path: &Path, map: &HeatMap<'_>) -> Result<(), PlotError> {
    ensure_font();
    let err = |e: &dyn std::fmt::Display| PlotError {
        path: path.to_path_buf(),
        msg: e.to_string(),
    };
    let (nx, ny) = (map.xs.len(), map.ys.len());
    if nx == 0 || ny == 0 || map.values.len() != nx * ny {
        return Err(err(&format!(
            "grid {nx}×{ny} does not match {} values",
            map.values.len()
        )));
    }
    let (hx, hy) = (half_widths(map.xs), half_widths(map.ys));
    // Outer edges of the first and last cells (the grid is not empty).
    let span = |v: &[f64], h: &[f64]| match (v.first(), v.last(), h.first(), h.last()) {
        (Some(v0), Some(v1), Some(h0), Some(h1)) => (v0 - h0, v1 + h1),
        _ => (0.0, 1.0),
    };
    let (lo, hi) = finite_range(map.values.iter().copied());
    let title = format!(
        "{} — colour: {} ({:.4} … {:.4})",
        map.title, map.value_label, lo, hi
    );
    let root = BitMapBackend::new(path, SIZE).into_drawing_area();
    root.fill(&WHITE).map_err(|e| err(&e))?;
    let mut chart = Frame {
        title: &title,
        caption_px: 20,
        y_label_area: 70,
        x: span(map.xs, &hx),
        y: span(map.ys, &hy),
        x_label: map.x_label,
        y_label: map.y_label,
        grid: false,
    }
    .draw(&root, err)?;
    let columns = || map.xs.iter().zip(&hx);
    let rows = map.values.chunks_exact(nx).zip(map.ys.iter().zip(&hy));
    let cells = rows.flat_map(|(row, y)| row.iter().zip(columns()).map(move |(v, x)| (*v, x, y)));
    chart
        .draw_series(cells.map(|(v, (&x, &hx), (&y, &hy))| {
            let color = if v.is_finite() {
                let s = ((v - lo) / (hi - lo)).clamp(0.0, 1.0);
                RGBColor((255.0 * s) as u8, 60, (255.0 * (1.0 - s)) as u8)
            } else {
                RGBColor(200, 200, 200)
            };
            Rectangle::new([(x - hx, y - hy), (x + hx, y + hy)], color.filled())
        }))
        .map_err(|e| err(&e))?;
    root.present().map_err(|e| err(&e))
}

/// Half the width of each grid cell centred on `v[k]`: half the gap to the
/// next abscissa, the last cell as wide as the one before it, and a single
/// cell of width 1.
fn half_widths(v: &[f64]) -> Vec<f64> {
    let gaps = v.iter().zip(v.iter().skip(1)).map(|(a, b)| 0.5 * (b - a));
    let last = gaps.clone().next_back().unwrap_or(0.5);
    gaps.chain(std::iter::once(last)).collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Cells centred on 0, 1, 3: half-widths ½, 1 and (like the one before) 1;
    /// one abscissa alone gets ½.
    #[test]
    fn cell_half_widths() {
        assert_eq!(half_widths(&[0.0, 1.0, 3.0]), [0.5, 1.0, 1.0]);
        assert_eq!(half_widths(&[5.0]), [0.5]);
    }

    /// 5 % margins; one value alone gets ±5 % of itself (±0.05 for zero).
    #[test]
    fn axis_ranges_have_margins_even_for_one_value() {
        let close =
            |a: (f64, f64), b: (f64, f64)| (a.0 - b.0).abs() < 1e-12 && (a.1 - b.1).abs() < 1e-12;
        assert!(close(finite_range([0.0, 10.0].into_iter()), (-0.5, 10.5)));
        assert!(close(
            finite_range([1.4, 1.4, f64::NAN].into_iter()),
            (1.33, 1.47)
        ));
        assert!(close(finite_range([0.0].into_iter()), (-0.05, 0.05)));
        assert_eq!(finite_range([f64::NAN].into_iter()), (0.0, 1.0));
    }

    fn png_ok(path: &Path) -> bool {
        let bytes = std::fs::read(path).unwrap_or_default();
        bytes.len() > 1000 && bytes.starts_with(&[0x89, b'P', b'N', b'G'])
    }

    #[test]
    fn draws_lines_markers_and_breaks() {
        let dir = std::env::temp_dir().join(format!("ivt-plot-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let a: Vec<(f64, f64)> = (0..50)
            .map(|k| (k as f64, (k as f64 * 0.2).sin()))
            .collect();
        let b = [
            (0.0, 0.0),
            (1.0, 1.0),
            (f64::NAN, f64::NAN),
            (2.0, 0.5),
            (3.0, 0.2),
        ];
        let fig = Figure {
            title: "test ω",
            x_label: "θ [rad]",
            y_label: "ω [rad/s]",
            series: vec![
                Series {
                    label: "sin",
                    points: &a,
                    style: Style::Line,
                },
                Series {
                    label: "broken",
                    points: &b,
                    style: Style::Dashed,
                },
                Series {
                    label: "",
                    points: &b,
                    style: Style::Markers,
                },
                Series {
                    label: "fold",
                    points: &b[..2],
                    style: Style::Events,
                },
            ],
        };
        let path = dir.join("lines.png");
        line_plot(&path, &fig).unwrap();
        assert!(png_ok(&path));
        assert_eq!(pieces(&b).count(), 2);
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn heat_map_checks_sizes() {
        let dir = std::env::temp_dir().join(format!("ivt-plot-h-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let xs = [1.0, 2.0, 3.0];
        let ys = [0.5, 1.0];
        let values = [0.1, 0.2, 0.3, f64::NAN, 0.5, 0.6];
        let map = HeatMap {
            title: "t",
            x_label: "V_m [V]",
            y_label: "T_U [N·m]",
            value_label: "|μ|",
            xs: &xs,
            ys: &ys,
            values: &values,
        };
        let path = dir.join("heat.png");
        heat_map(&path, &map).unwrap();
        assert!(png_ok(&path));
        let bad = HeatMap {
            values: &values[..5],
            ..map
        };
        assert!(heat_map(&dir.join("bad.png"), &bad).is_err());
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
