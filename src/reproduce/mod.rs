//! `ivt reproduce`: regenerate the thesis's computable results — figures
//! (PNG + CSV of the plotted data) and a table of every printed number the
//! toolkit can compute, each with a verdict — and write `REPRODUCTION.md`.
//!
//! One module per chapter; each appends [`Row`]s and figures to a
//! `Context`. The library APIs are called directly (never the CLI). A
//! chapter whose engine is not in this build reports its rows as
//! [`Verdict::NotComputable`] and its figures as missing, with the reason —
//! never a made-up number.

mod ch4_findings;
mod closed_loop;
mod closed_loop_ch4;
mod design;
mod design_maps;
mod design_refs;
mod gear_arcs;
mod hb;
mod kinematics;
mod report;
mod rig;
mod sthb;

use indicatif::{ProgressBar, ProgressStyle};
use ivt_plot::{Figure, HeatMap};
use ivt_sim::atomic::Staged;
use serde::Serialize;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

/// A curve's (x, y) points in plot units.
pub(crate) type Points = Vec<(f64, f64)>;

/// A series whose label and points the chapter owns (borrowed into
/// [`ivt_plot::Series`] when drawn).
pub(crate) type OwnedSeries = (String, Points, ivt_plot::Style);

/// A series as (label, points, style).
pub(crate) type SeriesSpec<'a> = (&'a str, &'a [(f64, f64)], ivt_plot::Style);

/// A figure's series from (label, points, style) triples.
pub(crate) fn series<'a>(list: &[SeriesSpec<'a>]) -> Vec<ivt_plot::Series<'a>> {
    list.iter()
        .map(|&(label, points, style)| ivt_plot::Series {
            label,
            points,
            style,
        })
        .collect()
}

/// Borrow owned series as the plot crate's [`ivt_plot::Series`].
pub(crate) fn borrow_series(data: &[OwnedSeries]) -> Vec<ivt_plot::Series<'_>> {
    let list: Vec<_> = data
        .iter()
        .map(|(label, points, style)| (label.as_str(), points.as_slice(), *style))
        .collect();
    series(&list)
}

/// How a thesis number compares with ours.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Verdict {
    /// Agrees to the digits the thesis prints.
    Reproduced,
    /// Disagrees; the row's note names the cause and its evidence.
    Differs,
    /// Cannot be computed from what is printed or built; the note says why.
    #[serde(rename = "not computable")]
    NotComputable,
}

impl Verdict {
    /// The word used in the report.
    pub fn as_str(self) -> &'static str {
        match self {
            Verdict::Reproduced => "reproduced",
            Verdict::Differs => "differs",
            Verdict::NotComputable => "not computable",
        }
    }
}

/// One row of the report table.
#[derive(Clone, Debug, Serialize)]
pub struct Row {
    /// Chapter/section id (e.g. `"kinematics"`).
    pub section: &'static str,
    /// What is compared, with its unit.
    pub quantity: String,
    /// The printed value with its source (Eq./Fig./§), or `—`.
    pub thesis: String,
    /// Our value, or `—`.
    pub ours: String,
    /// Absolute/relative difference in words, or `—`.
    pub difference: String,
    /// The verdict.
    pub verdict: Verdict,
    /// Cause and evidence for `differs`, reason for `not computable`, method otherwise.
    pub note: String,
    /// For `differs`: the test that demonstrates the cause (`file::name`).
    pub cause_test: Option<&'static str>,
}

/// Why a printed number differs from ours: the cause in words and the test
/// that demonstrates it (named in the row, so the claim can be checked).
#[derive(Clone, Copy, Debug)]
pub(crate) struct Cause<'a> {
    /// The cause with its evidence.
    pub why: &'a str,
    /// `file::test_name` of the demonstrating test.
    pub test: &'static str,
}

/// One figure: a PNG and the CSV of its data, or the reason it is missing.
#[derive(Clone, Debug, Serialize)]
pub struct FigureEntry {
    /// Thesis figure id, e.g. `"Fig. 24"`.
    pub id: String,
    /// Title drawn on the figure.
    pub title: String,
    /// The PNG, relative to the output directory (None if missing).
    pub png: Option<String>,
    /// The CSV of the plotted data, relative to the output directory.
    pub csv: Option<String>,
    /// What was computed and how it compares with the printed figure, or why it is missing.
    pub note: String,
}

/// Options of a reproduction run.
#[derive(Clone, Copy, Debug, Default)]
pub struct Options {
    /// Coarser grids and sweeps (for tests); the verdicts use the same numbers.
    pub quick: bool,
    /// Show an indicatif progress bar on stderr.
    pub progress: bool,
}

/// A failure that stops the whole run (I/O, drawing). Numerical failures of a
/// single result become rows with the error in the note instead.
#[derive(Debug, thiserror::Error)]
pub enum ReproError {
    /// Writing a file failed.
    #[error("cannot write {path}: {source}")]
    Io {
        /// The file.
        path: PathBuf,
        /// The OS error.
        source: std::io::Error,
    },
    /// A computation behind a figure failed (message of the library error).
    #[error("{0}")]
    Numeric(String),
    /// Drawing a figure failed.
    #[error(transparent)]
    Plot(#[from] ivt_plot::PlotError),
}

/// The finished run: where the report is, what it contains.
#[derive(Clone, Debug, Serialize)]
pub struct Report {
    /// Path of `REPRODUCTION.md`.
    pub report: PathBuf,
    /// Every figure (produced or missing).
    pub figures: Vec<FigureEntry>,
    /// Every table row.
    pub rows: Vec<Row>,
    /// Wall-clock time of the run \[s\].
    pub elapsed_s: f64,
}

/// What a chapter writes into.
pub(crate) struct Context {
    out: PathBuf,
    /// Every file of the run, under temporary names until the report is
    /// complete ([`ivt_sim::atomic::Staged`]): a failed run leaves none.
    staged: Staged,
    opts: Options,
    rows: Vec<Row>,
    figures: Vec<FigureEntry>,
    bar: ProgressBar,
    section: &'static str,
}

/// Format a number with `sig` significant digits, plain notation for
/// moderate magnitudes.
pub(crate) fn fmt_sig(x: f64, sig: usize) -> String {
    if !x.is_finite() {
        return format!("{x}");
    }
    if x == 0.0 {
        return "0".into();
    }
    let mag = x.abs().log10().floor() as i32;
    if !(-4..6).contains(&mag) {
        return format!("{:.*e}", sig.saturating_sub(1), x);
    }
    let decimals = (sig as i32 - 1 - mag).max(0) as usize;
    format!("{x:.decimals$}")
}

impl Context {
    fn new(out: &Path, staged: Staged, opts: Options, steps: u64) -> Self {
        let bar = if opts.progress {
            let b = ProgressBar::new(steps);
            if let Ok(style) =
                ProgressStyle::with_template("{elapsed:>4} [{bar:30}] {pos}/{len} {msg}")
            {
                b.set_style(style.progress_chars("=> "));
            }
            b
        } else {
            ProgressBar::hidden()
        };
        Self {
            out: out.to_path_buf(),
            staged,
            opts,
            rows: Vec::new(),
            figures: Vec::new(),
            bar,
            section: "",
        }
    }

    /// Whether the quick (test) grids are wanted.
    pub(crate) fn quick(&self) -> bool {
        self.opts.quick
    }

    /// Advance the progress bar by one step with a message.
    pub(crate) fn step(&self, msg: &str) {
        self.bar.set_message(msg.to_string());
        self.bar.inc(1);
    }

    /// Add a row in the current section.
    pub(crate) fn row(
        &mut self,
        quantity: impl Into<String>,
        thesis: impl Into<String>,
        ours: impl Into<String>,
        difference: impl Into<String>,
        verdict: Verdict,
        note: impl Into<String>,
    ) {
        self.rows.push(Row {
            section: self.section,
            quantity: quantity.into(),
            thesis: thesis.into(),
            ours: ours.into(),
            difference: difference.into(),
            verdict,
            note: note.into(),
            cause_test: None,
        });
    }

    /// A `differs` row with its cause and the test that demonstrates it.
    pub(crate) fn differs(
        &mut self,
        quantity: impl Into<String>,
        thesis: impl Into<String>,
        ours: impl Into<String>,
        difference: impl Into<String>,
        cause: Cause<'_>,
    ) {
        self.row(
            quantity,
            thesis,
            ours,
            difference,
            Verdict::Differs,
            format!("{} (demonstrated by `{}`)", cause.why, cause.test),
        );
        if let Some(r) = self.rows.last_mut() {
            r.cause_test = Some(cause.test);
        }
    }

    /// Compare a printed number with ours: `reproduced` if they agree to
    /// the printed digits (|ours − thesis| ≤ half a unit of the last printed
    /// digit, `half_ulp`), otherwise `differs` with the expected `cause`
    /// (`None` where agreement is expected: a difference then says that no
    /// cause is known, and the pinning test in tests/reproduce.rs fails).
    #[allow(clippy::too_many_arguments)]
    pub(crate) fn compare(
        &mut self,
        quantity: &str,
        thesis: f64,
        source: &str,
        ours: f64,
        half_ulp: f64,
        sig: usize,
        how: &str,
        cause: Option<Cause<'_>>,
    ) {
        let d = ours - thesis;
        let rel = if thesis != 0.0 {
            d / thesis.abs()
        } else {
            f64::NAN
        };
        let difference = if rel.is_finite() {
            format!("{} ({:+.2} %)", fmt_sig(d, 2), 100.0 * rel)
        } else {
            fmt_sig(d, 2)
        };
        let ok = ours.is_finite() && d.abs() <= half_ulp * (1.0 + 1e-9);
        let (thesis, ours) = (format!("{thesis} ({source})"), fmt_sig(ours, sig));
        if ok {
            self.row(quantity, thesis, ours, difference, Verdict::Reproduced, how);
        } else if let Some(cause) = cause {
            let why = format!("{}; {how}", cause.why);
            let cause = Cause {
                why: &why,
                test: cause.test,
            };
            self.differs(quantity, thesis, ours, difference, cause);
        } else {
            let note = format!("no cause identified; {how}");
            self.row(quantity, thesis, ours, difference, Verdict::Differs, note);
        }
    }

    /// A row that cannot be computed, with the reason.
    pub(crate) fn not_computable(&mut self, quantity: &str, thesis: &str, why: &str) {
        self.row(quantity, thesis, "—", "—", Verdict::NotComputable, why);
    }

    fn file_stem(id: &str) -> String {
        id.chars()
            .map(|c| {
                if c.is_ascii_alphanumeric() {
                    c.to_ascii_lowercase()
                } else {
                    '_'
                }
            })
            .collect::<String>()
            .split('_')
            .filter(|s| !s.is_empty())
            .collect::<Vec<_>>()
            .join("_")
    }

    /// Write `text` as `name` in the output directory (staged).
    fn write(&mut self, name: &str, text: &str) -> Result<(), ReproError> {
        let path = self.out.join(name);
        self.staged
            .write(&path, text.as_bytes())
            .map_err(|source| ReproError::Io { path, source })
    }

    /// The temporary path that becomes `name` in the output directory when
    /// the run completes.
    fn staging(&mut self, name: &str) -> Result<PathBuf, ReproError> {
        let path = self.out.join(name);
        self.staged
            .path(&path)
            .map_err(|source| ReproError::Io { path, source })
    }

    /// Draw a line figure and save its data as CSV (`series,x,y`, NaN rows
    /// mark curve breaks).
    pub(crate) fn line_figure(
        &mut self,
        id: &str,
        figure: &Figure<'_>,
        note: &str,
    ) -> Result<(), ReproError> {
        let (title, x_label, y_label) = (
            glyphs(figure.title),
            glyphs(figure.x_label),
            glyphs(figure.y_label),
        );
        let labels: Vec<String> = figure.series.iter().map(|s| glyphs(s.label)).collect();
        let drawable = Figure {
            title: &title,
            x_label: &x_label,
            y_label: &y_label,
            series: figure
                .series
                .iter()
                .zip(&labels)
                .map(|(s, l)| ivt_plot::Series { label: l, ..*s })
                .collect(),
        };
        let mut csv = format!(
            "series,{},{}\n",
            csv_quoted(figure.x_label),
            csv_quoted(figure.y_label)
        );
        for s in &figure.series {
            let label = csv_quoted(s.label);
            for &(x, y) in s.points {
                let _ = writeln!(csv, "{label},{x:e},{y:e}");
            }
        }
        self.save_figure(id, figure.title, note, &csv, |png| {
            ivt_plot::line_plot(png, &drawable)
        })
    }

    /// Draw a heat map and save its grid as CSV (`x,y,value`).
    pub(crate) fn heat_figure(
        &mut self,
        id: &str,
        map: &HeatMap<'_>,
        note: &str,
    ) -> Result<(), ReproError> {
        if map.values.len() != map.xs.len() * map.ys.len() {
            return Err(ReproError::Numeric(format!(
                "{id}: {} map values for a {}×{} grid",
                map.values.len(),
                map.xs.len(),
                map.ys.len()
            )));
        }
        let (title, x_label, y_label, value_label) = (
            glyphs(map.title),
            glyphs(map.x_label),
            glyphs(map.y_label),
            glyphs(map.value_label),
        );
        let drawable = HeatMap {
            title: &title,
            x_label: &x_label,
            y_label: &y_label,
            value_label: &value_label,
            ..*map
        };
        let mut csv = format!(
            "{},{},{}\n",
            csv_quoted(map.x_label),
            csv_quoted(map.y_label),
            csv_quoted(map.value_label)
        );
        // Row-major: one row of `xs.len()` values per y.
        for (&y, row) in map
            .ys
            .iter()
            .zip(map.values.chunks_exact(map.xs.len().max(1)))
        {
            for (&x, &v) in map.xs.iter().zip(row) {
                let _ = writeln!(csv, "{x:e},{y:e},{v:e}");
            }
        }
        self.save_figure(id, map.title, note, &csv, |png| {
            ivt_plot::heat_map(png, &drawable)
        })
    }

    /// The one way a drawn figure reaches the output: `draw` renders
    /// `<stem>.png` (staged), `csv` is written as `<stem>.csv`, and both are
    /// listed under `id` with `title` and `note`.
    fn save_figure(
        &mut self,
        id: &str,
        title: &str,
        note: &str,
        csv: &str,
        draw: impl FnOnce(&Path) -> Result<(), ivt_plot::PlotError>,
    ) -> Result<(), ReproError> {
        let stem = Self::file_stem(id);
        let (png, csv_name) = (format!("{stem}.png"), format!("{stem}.csv"));
        draw(&self.staging(&png)?).map_err(|e| e.for_path(&self.out.join(&png)))?;
        self.write(&csv_name, csv)?;
        self.figures.push(FigureEntry {
            id: id.to_string(),
            title: title.to_string(),
            png: Some(png),
            csv: Some(csv_name),
            note: note.to_string(),
        });
        Ok(())
    }

    /// A figure that cannot be drawn, with the reason.
    pub(crate) fn missing_figure(&mut self, id: &str, title: &str, why: &str) {
        self.figures.push(FigureEntry {
            id: id.to_string(),
            title: title.to_string(),
            png: None,
            csv: None,
            note: why.to_string(),
        });
    }
}

/// `s` as one quoted CSV field (a `"` inside becomes `'`).
fn csv_quoted(s: &str) -> String {
    format!("\"{}\"", s.replace('"', "'"))
}

/// Spell out the characters the embedded font subset lacks (combining
/// accents, §) so that labels never render as gaps.
fn glyphs(s: &str) -> String {
    s.replace("r̄", "r_bar")
        .replace("Γ̂", "Γ^")
        .replace('§', "Sec. ")
        .replace('‖', "|")
        .replace('\u{0304}', "_bar")
        .replace('\u{0302}', "^")
}

/// Run every chapter and write `out/REPRODUCTION.md`, the PNGs and CSVs.
///
/// # Errors
/// I/O or drawing failures; numerical failures become rows instead.
pub fn run(out: &Path, opts: Options) -> Result<Report, ReproError> {
    // `out` is created if needed, and removed again if the run fails or is
    // interrupted (the staged set of the one output writer).
    let staged = Staged::in_dir(out).map_err(|source| ReproError::Io {
        path: out.to_path_buf(),
        source,
    })?;
    run_in(out, staged, opts)
}

/// A chapter's entry point: appends its rows and figures to the context.
type Chapter = fn(&mut Context) -> Result<(), ReproError>;

/// The chapters in report order, each with its section id.
const CHAPTERS: &[(&str, Chapter)] = &[
    ("kinematics", kinematics::run),
    ("hb", hb::run),
    ("sthb", sthb::run),
    ("design", design::run),
    ("closed_loop", closed_loop::run),
    ("closed_loop/thesis-ch4", closed_loop_ch4::run),
    ("rig", rig::run),
];

/// Every chapter into the staged set of `out`, renamed into place once the
/// report is written.
fn run_in(out: &Path, staged: Staged, opts: Options) -> Result<Report, ReproError> {
    let start = std::time::Instant::now();
    let mut ctx = Context::new(out, staged, opts, 17);
    for &(section, chapter) in CHAPTERS {
        ctx.section = section;
        chapter(&mut ctx)?;
    }
    ctx.bar.finish_and_clear();
    let elapsed_s = start.elapsed().as_secs_f64();
    let report_path = out.join("REPRODUCTION.md");
    let text = report::markdown(&ctx.rows, &ctx.figures, elapsed_s, opts.quick);
    ctx.write("REPRODUCTION.md", &text)?;
    let Context {
        staged,
        figures,
        rows,
        ..
    } = ctx;
    staged.commit().map_err(|source| ReproError::Io {
        path: out.to_path_buf(),
        source,
    })?;
    Ok(Report {
        report: report_path,
        figures,
        rows,
        elapsed_s,
    })
}
