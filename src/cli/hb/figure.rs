//! The pictures `ivt hb ... --plot FILE.png` draws of a job's result, the
//! same as `ivt.plot`'s in Python: a response curve (amplitude against ω)
//! with its unstable stretches dashed and its events marked and labelled, a
//! two-parameter curve with its special points, a branch of limit cycles
//! with its Hopf points and folds, a backbone, the orbits found at one
//! frequency, a limit cycle's phase portrait. Each is drawn by `ivt-plot`
//! through the one output writer ([`super::super::write_figure`]).

use super::CliError;
use ivt_hb::orbit::aft::eval_series;
use ivt_hb::BifurcationKind;
use ivt_jobs::{
    AllSolutionsResult, BackboneCurve, Cycle, CycleBranchResult, FoldCurveResult, FrcCurve,
};
use ivt_plot::Style;
use std::f64::consts::PI;
use std::path::Path;

/// The (x, y) points of a series; a NaN point breaks the curve.
type Points = Vec<(f64, f64)>;

/// A figure with owned data: title, axis labels and the series in drawing
/// order.
pub(crate) struct Picture {
    title: String,
    x_label: &'static str,
    y_label: &'static str,
    series: Vec<(String, Points, Style)>,
}

impl Picture {
    pub(crate) fn new(
        title: impl Into<String>,
        x_label: &'static str,
        y_label: &'static str,
    ) -> Self {
        Self {
            title: title.into(),
            x_label,
            y_label,
            series: Vec::new(),
        }
    }

    /// Add a series unless it has no finite point.
    pub(crate) fn with(
        mut self,
        label: impl Into<String>,
        points: Vec<(f64, f64)>,
        style: Style,
    ) -> Self {
        if points.iter().any(|p| p.0.is_finite() && p.1.is_finite()) {
            self.series.push((label.into(), points, style));
        }
        self
    }

    /// Add one [`Style::Events`] series per label, in order of first
    /// appearance: one marker per event, the label beside it.
    fn with_events(mut self, events: &[(String, (f64, f64))]) -> Self {
        let mut labels: Vec<&String> = Vec::new();
        for (label, _) in events {
            if !labels.contains(&label) {
                labels.push(label);
            }
        }
        for label in labels {
            let at = events
                .iter()
                .filter(|(l, _)| l == label)
                .map(|&(_, p)| p)
                .collect();
            self = self.with(label.clone(), at, Style::Events);
        }
        self
    }

    /// Draw into the PNG at `path` (staged, renamed when complete).
    pub(crate) fn draw(&self, path: &Path) -> Result<(), CliError> {
        let figure = ivt_plot::Figure {
            title: &self.title,
            x_label: self.x_label,
            y_label: self.y_label,
            series: self
                .series
                .iter()
                .map(|(label, points, style)| ivt_plot::Series {
                    label,
                    points,
                    style: *style,
                })
                .collect(),
        };
        super::super::write_figure(path, |tmp| ivt_plot::line_plot(tmp, &figure))
    }
}

/// The points of a curve `(x, y, stable)` in path order as two NaN-broken
/// series: the dashed one holds exactly the unstable points, one piece per
/// run of them; the solid one holds the stable runs, each extended by the
/// segment to the neighbouring unstable point on either side, so that the
/// curve stays connected (the change of stability lies on that segment, at
/// the event marked there).
pub(super) fn stability_runs(points: &[(f64, f64, bool)]) -> (Points, Points) {
    let gap = (f64::NAN, f64::NAN);
    let (mut solid, mut dashed) = (Vec::new(), Vec::new());
    let mut previous: Option<(f64, f64, bool)> = None;
    for &(x, y, stable) in points {
        match previous {
            Some((px, py, was)) if was != stable => {
                if stable {
                    // unstable → stable: the solid run starts at the last
                    // unstable point.
                    dashed.push(gap);
                    solid.push((px, py));
                    solid.push((x, y));
                } else {
                    // stable → unstable: the solid run ends at this point.
                    solid.push((x, y));
                    solid.push(gap);
                    dashed.push((x, y));
                }
            }
            _ if stable => solid.push((x, y)),
            _ => dashed.push((x, y)),
        }
        previous = Some((x, y, stable));
    }
    (solid, dashed)
}

/// The label of an event on a response curve or a branch.
fn event_label(kind: BifurcationKind) -> &'static str {
    match kind {
        BifurcationKind::Fold => "fold",
        BifurcationKind::PeriodDoubling => "PD",
        BifurcationKind::NeimarkSacker => "NS",
        BifurcationKind::BranchPoint => "BP",
        BifurcationKind::Crossing => "at",
    }
}

/// A response curve: `points` `(ω, amplitude, stable)` solid where stable
/// and dashed where not, `events` marked.
pub(crate) fn response(
    title: impl Into<String>,
    y_label: &'static str,
    points: &[(f64, f64, bool)],
    events: &[(String, (f64, f64))],
) -> Picture {
    let (solid, dashed) = stability_runs(points);
    Picture::new(title, "ω", y_label)
        .with("stable", solid, Style::Line)
        .with("unstable", dashed, Style::Dashed)
        .with_events(events)
}

/// A job's frequency-response curve (`duffing-frc`, `switch`, the future
/// model-file `frc`) with its events (`bifurcations`: the folds among them).
pub(super) fn frc<F>(title: impl Into<String>, curve: &FrcCurve<F>) -> Picture {
    let points: Vec<_> = curve
        .points
        .iter()
        .map(|p| (p.omega, p.amplitude, p.stable))
        .collect();
    let events: Vec<_> = curve
        .bifurcations
        .iter()
        .filter_map(|e| Some((event_label(e.kind).to_owned(), (e.omega?, e.amplitude?))))
        .collect();
    response(title, "max |x|", &points, &events)
}

/// A two-parameter curve in (ω, p) with its special points (cusps,
/// resonances) labelled and the points located at the requested p marked.
pub(super) fn curve2(
    title: impl Into<String>,
    p_label: &'static str,
    curve: &FoldCurveResult,
) -> Picture {
    let line = curve.points.iter().map(|q| (q.omega, q.p)).collect();
    let at = curve.at.iter().map(|q| (q.omega, q.p)).collect();
    let special: Vec<_> = curve
        .special
        .iter()
        .map(|s| {
            let kind = serde_json::to_value(s.kind)
                .ok()
                .and_then(|v| v.as_str().map(special_label))
                .unwrap_or_default();
            (kind, (s.point.omega, s.point.p))
        })
        .collect();
    let name = match curve.kind {
        BifurcationKind::Fold => "fold curve",
        BifurcationKind::PeriodDoubling => "period-doubling curve",
        BifurcationKind::NeimarkSacker => "Neimark–Sacker curve",
        BifurcationKind::BranchPoint => "branch-point curve",
        BifurcationKind::Crossing => "curve",
    };
    Picture::new(title, "ω", p_label)
        .with(name, line, Style::Line)
        .with("located at the requested p", at, Style::Markers)
        .with_events(&special)
}

/// `cusp`, `1:1` … `1:4` from the JSON word of a special point's kind.
fn special_label(word: &str) -> String {
    word.strip_prefix("resonance_")
        .map_or_else(|| word.to_owned(), |r| r.replace('_', ":"))
}

/// A branch of limit cycles: amplitude against the parameter, unstable
/// cycles dashed, the cycles solved at the requested p as dots, the Hopf
/// points (amplitude 0) and the folds marked.
pub(super) fn cycles(
    title: impl Into<String>,
    p_label: &'static str,
    branch: &CycleBranchResult,
) -> Picture {
    let points: Vec<_> = branch
        .points
        .iter()
        .map(|c| (c.p, c.amplitude, c.stable))
        .collect();
    let (solid, dashed) = stability_runs(&points);
    let mut events: Vec<_> = branch
        .hopf
        .iter()
        .map(|h| ("Hopf".to_owned(), (h.p, 0.0)))
        .collect();
    events.extend(
        branch
            .bifurcations
            .iter()
            .map(|f| (event_label(f.kind).to_owned(), (f.p, f.amplitude))),
    );
    let at = branch.at.iter().map(|c| (c.p, c.amplitude)).collect();
    Picture::new(title, p_label, "max |x|")
        .with("stable cycles", solid, Style::Line)
        .with("unstable cycles", dashed, Style::Dashed)
        .with("cycles at the requested p", at, Style::Markers)
        .with_events(&events)
}

/// A backbone: ω against max |x| of its points (`peak`, the measure of a
/// response curve's amplitude).
pub(super) fn backbone(title: impl Into<String>, curve: &BackboneCurve) -> Picture {
    let line = curve.points.iter().map(|p| (p.omega, p.peak)).collect();
    Picture::new(title, "ω", "max |x|").with("backbone", line, Style::Line)
}

/// The orbits found at one frequency `omega`: their amplitudes, stable and
/// unstable ones in two colours.
pub(super) fn solutions(title: impl Into<String>, omega: f64, all: &AllSolutionsResult) -> Picture {
    let pick = |stable: bool| {
        all.solutions
            .iter()
            .filter(|s| s.stable == stable)
            .map(|s| (omega, s.amplitude))
            .collect()
    };
    Picture::new(title, "ω", "max |x|")
        .with("stable", pick(true), Style::Markers)
        .with("unstable", pick(false), Style::Markers)
}

/// The phase portrait (x, dx/dt) of DOF 0 of a limit cycle of `harmonics`
/// harmonics over one period.
pub(super) fn phase_portrait(title: impl Into<String>, cycle: &Cycle, harmonics: usize) -> Picture {
    let dof0 = cycle.coeffs.0.get(..2 * harmonics + 1).unwrap_or_default();
    let orbit = (0..=800)
        .map(|j| {
            let tau = 2.0 * PI * f64::from(j) / 800.0;
            (
                eval_series(dof0, tau, 0),
                eval_series(dof0, tau, 1) * cycle.omega,
            )
        })
        .collect();
    Picture::new(title, "x", "dx/dt").with("limit cycle", orbit, Style::Line)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn finite(v: &[(f64, f64)]) -> Vec<(f64, f64)> {
        v.iter().copied().filter(|p| p.0.is_finite()).collect()
    }

    /// Stable, stable, unstable, unstable, stable: the dashed series is
    /// exactly the two unstable points; the solid one joins both stable
    /// runs to them (one break between).
    #[test]
    fn dashed_runs_are_exactly_the_unstable_points() {
        let pts = [
            (0.0, 0.0, true),
            (1.0, 1.0, true),
            (2.0, 2.0, false),
            (3.0, 3.0, false),
            (4.0, 4.0, true),
        ];
        let (solid, dashed) = stability_runs(&pts);
        assert_eq!(finite(&dashed), [(2.0, 2.0), (3.0, 3.0)]);
        assert_eq!(
            finite(&solid),
            [(0.0, 0.0), (1.0, 1.0), (2.0, 2.0), (3.0, 3.0), (4.0, 4.0)]
        );
        assert_eq!(solid.iter().filter(|p| p.0.is_nan()).count(), 1);
        // Two unstable runs are two dashed pieces.
        let two = [(0.0, 0.0, false), (1.0, 1.0, true), (2.0, 2.0, false)];
        let (_, dashed) = stability_runs(&two);
        assert_eq!(dashed.iter().filter(|p| p.0.is_nan()).count(), 1);
        assert_eq!(finite(&dashed), [(0.0, 0.0), (2.0, 2.0)]);
    }

    #[test]
    fn special_points_are_labelled_by_their_resonance() {
        assert_eq!(special_label("cusp"), "cusp");
        assert_eq!(special_label("resonance_1_3"), "1:3");
    }

    /// The Duffing FRC of Fig. 29 (n = 8): its dashed series is exactly
    /// the unstable points, and each of its two folds is one marker at the
    /// located fold (ω_f, amplitude).
    #[test]
    fn duffing_frc_picture_dashes_the_unstable_points_and_marks_both_folds() {
        use ivt_jobs::{self as jobs, FrcRequest};
        let d = ivt_hb::Duffing::new(0.02, 1.0, 1.0, 0.1);
        let hb = ivt_hb::HbOptions::new(8, 32);
        let curve = jobs::frc(&d, &hb, &FrcRequest::default()).unwrap();
        let pic = frc("t", &curve);
        let series = |label: &str| {
            pic.series
                .iter()
                .find(|s| s.0 == label)
                .map(|s| (s.1.clone(), s.2))
                .unwrap()
        };
        let unstable: Vec<_> = curve
            .points
            .iter()
            .filter(|p| !p.stable)
            .map(|p| (p.omega, p.amplitude))
            .collect();
        assert!(unstable.len() > 3);
        let (dashed, style) = series("unstable");
        assert_eq!(style, Style::Dashed);
        assert_eq!(finite(&dashed), unstable);
        let (folds, style) = series("fold");
        assert_eq!(style, Style::Events);
        let located: Vec<_> = curve.folds.iter().map(|f| (f.omega, f.amplitude)).collect();
        assert_eq!(folds, located);
        assert_eq!(folds.len(), 2);
    }

    /// One Events series per kind, one marker per event.
    #[test]
    fn events_are_grouped_by_label() {
        let events = [
            ("fold".to_owned(), (1.0, 2.0)),
            ("NS".to_owned(), (1.5, 2.5)),
            ("fold".to_owned(), (2.0, 3.0)),
        ];
        let p = Picture::new("t", "x", "y").with_events(&events);
        let got: Vec<_> = p
            .series
            .iter()
            .map(|(l, pts, s)| (l.as_str(), pts.len(), *s))
            .collect();
        assert_eq!(got, [("fold", 2, Style::Events), ("NS", 1, Style::Events)]);
    }
}
