//! The model file of `ivt hb frc MODEL.toml` and `ivt hb solve MODEL.toml`:
//! a user's `M ẍ + C ẋ + K x + Σ elements = F cos(θ + φ)` (θ = ω_f t) as an
//! [`ElementProblem`], with the harmonic-balance options and the range of
//! `ivt.hb.frc` / `ivt.hb.solve` (the same defaults, the same job).
//!
//! ```toml
//! [model]                      # M, C, K: rows of numbers, a number (one
//! m = [[1, 0], [0, 1]]         # DOF) or a Matrix Market file relative to
//! c = "c.mtx"                  # this file
//! k = [[2, -1], [-1, 2]]
//! [[element]]                  # ivt.hb.elements: law, its parameters, dof, to
//! law = "cubic_spring"
//! k3 = 0.5
//! dof = 0
//! [forcing]                    # F_j cos(θ + φ_j); none: unforced
//! amplitude = [0.1, 0]
//! [range]                      # ω_f of `frc` (--from/--to override)
//! from = 0.5
//! to = 2.5
//! [options]                    # n, samples, tol, rtol, max_iter, events, method
//! n = 20
//! ```
//!
//! Every table refuses unknown keys; every error names its key (and the
//! position in the file) and the value.

use super::matrix_market::{self, ReadError};
use crate::cli::CliError;
use ivt_hb::{Element, ElementProblem, Harmonic, HbOptions, Law};
use ivt_jobs::Method;
use ivt_sim::scene::locate::Doc;
use serde::Deserialize;
use std::path::{Path, PathBuf};

/// Largest model file \[bytes\]: 1 MiB (the scene budget); large matrices
/// belong in Matrix Market files ([`matrix_market::MAX_BYTES`]).
const MAX_FILE_BYTES: u64 = ivt_sim::input::MAX_SCENE_BYTES;

/// The file as written.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct ModelFile {
    model: Matrices,
    #[serde(default)]
    element: Vec<ElementEntry>,
    forcing: Option<Forcing>,
    range: Option<Range>,
    #[serde(default)]
    options: Options,
}

/// `[model]`.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct Matrices {
    m: MatrixEntry,
    c: MatrixEntry,
    k: MatrixEntry,
}

/// One of M, C, K.
#[derive(Deserialize)]
#[serde(
    untagged,
    expecting = "a matrix: rows of numbers, a number (one DOF), or the path of a Matrix Market file"
)]
enum MatrixEntry {
    Scalar(f64),
    Rows(Vec<Vec<f64>>),
    File(PathBuf),
}

/// The laws of `ivt.hb.elements`, by their Python names.
#[derive(Deserialize, Clone, Copy, Debug)]
#[serde(rename_all = "snake_case")]
enum LawName {
    CubicSpring,
    QuadraticDamper,
    CubicDamper,
    Coulomb,
    Clearance,
    Unilateral,
    Jenkins,
}

/// `[[element]]`: a law with its parameters (the keywords of
/// `ivt.hb.elements.<law>`), between DOF `dof` and DOF `to` (absent: ground).
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct ElementEntry {
    law: LawName,
    dof: usize,
    to: Option<usize>,
    k3: Option<f64>,
    c2: Option<f64>,
    c3: Option<f64>,
    force: Option<f64>,
    v_reg: Option<f64>,
    gap: Option<f64>,
    k: Option<f64>,
    slip_force: Option<f64>,
}

/// `[forcing]`: `amplitude[j]·cos(θ + phase[j])` on DOF j.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct Forcing {
    amplitude: Vec<f64>,
    phase: Option<Vec<f64>>,
}

/// `[range]`: the ω_f interval of `frc`.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct Range {
    from: Option<f64>,
    to: Option<f64>,
}

/// `[options]`, with `ivt.hb.frc`'s and `ivt.hb.solve`'s defaults.
#[derive(Deserialize)]
#[serde(deny_unknown_fields, default)]
struct Options {
    n: usize,
    samples: usize,
    tol: f64,
    rtol: f64,
    max_iter: usize,
    events: bool,
    method: MethodName,
}

impl Default for Options {
    fn default() -> Self {
        Self {
            n: 20,
            samples: 64,
            tol: 0.0,
            rtol: 1e-9,
            max_iter: 100,
            events: true,
            method: MethodName::Modified,
        }
    }
}

/// `options.method` of `solve`.
#[derive(Deserialize, Clone, Copy)]
#[serde(rename_all = "snake_case")]
enum MethodName {
    Modified,
    Classic,
}

/// A model read and checked: the problem, its options, the file's range and
/// the jobs' switches.
pub struct Model {
    /// The system.
    pub problem: ElementProblem,
    /// Harmonics, samples and tolerances.
    pub options: HbOptions,
    /// `[range] from`, `to`.
    pub range: (Option<f64>, Option<f64>),
    /// `options.events` (frc).
    pub events: bool,
    /// `options.method` (solve).
    pub method: Method,
}

/// A check that failed: the key and what is wrong with its value.
struct Invalid {
    key: String,
    message: String,
}

fn invalid(key: impl Into<String>, message: impl Into<String>) -> Invalid {
    Invalid {
        key: key.into(),
        message: message.into(),
    }
}

/// The model in the file `path`.
///
/// # Errors
/// [`CliError::Io`] when the file or a Matrix Market file it names cannot be
/// read (within their size budgets); [`CliError::Input`] naming the position,
/// the key and the value for anything the file gets wrong.
pub fn load(path: &Path) -> Result<Model, CliError> {
    let src = ivt_sim::input::read_text_bounded(path, MAX_FILE_BYTES)
        .map_err(|e| CliError::io(path, e))?;
    let origin = path.display().to_string();
    let doc = Doc::new(&src);
    let at = |span: Option<std::ops::Range<usize>>| doc.at(&origin, span);
    let file: ModelFile = toml::from_str(&src).map_err(|e| {
        // The value as written, unless the message shows it already.
        let got = e
            .span()
            .and_then(|s| src.get(s))
            .filter(|v| !e.message().contains(v.trim()))
            .map(|v| format!(" (got {})", ivt_sim::input::excerpt(v.trim())))
            .unwrap_or_default();
        CliError::Input(format!("{}{got}", doc.serde_error(&origin, &e)))
    })?;
    let base = path.parent().unwrap_or(Path::new("."));
    let [m, c, k] = [
        ("m", &file.model.m),
        ("c", &file.model.c),
        ("k", &file.model.k),
    ]
    .map(|(name, entry)| matrix(&format!("model.{name}"), entry, base));
    let mut mats = Vec::with_capacity(3);
    for r in [m, c, k] {
        match r {
            Ok(v) => mats.push(v),
            Err(Loaded::Io(e)) => return Err(e),
            Err(Loaded::Invalid(e)) => {
                return Err(CliError::Input(format!(
                    "{}: `{}`{}",
                    at(doc.span_of(&e.key)),
                    e.key,
                    e.message
                )))
            }
        }
    }
    build(file, mats).map_err(|e| {
        CliError::Input(format!(
            "{}: `{}`{}",
            at(doc.span_of(&e.key)),
            e.key,
            e.message
        ))
    })
}

/// A matrix that could not be had.
enum Loaded {
    Io(CliError),
    Invalid(Invalid),
}

/// `(n, row-major entries)` of one matrix entry.
fn matrix(key: &str, entry: &MatrixEntry, base: &Path) -> Result<(usize, Vec<f64>), Loaded> {
    let bad = |m: String| Loaded::Invalid(invalid(key, m));
    match entry {
        MatrixEntry::Scalar(v) => finite_entries(key, vec![*v]).map(|a| (1, a)),
        MatrixEntry::Rows(rows) => {
            let n = rows.len();
            if n == 0 || n > matrix_market::MAX_DOFS {
                return Err(bad(format!(
                    " has {n} rows; a model has 1 to {} DOFs",
                    matrix_market::MAX_DOFS
                )));
            }
            if let Some((i, r)) = rows.iter().enumerate().find(|(_, r)| r.len() != n) {
                return Err(bad(format!(
                    " row {i} has {} entries; a {n}×{n} matrix needs {n}",
                    r.len()
                )));
            }
            finite_entries(key, rows.concat()).map(|a| (n, a))
        }
        MatrixEntry::File(p) => {
            let full = base.join(p);
            matrix_market::read(&full).map_err(|e| match e {
                ReadError::Io(e) => Loaded::Io(CliError::Io(format!(
                    "`{key}` = {:?}: {}: {e}",
                    p.display().to_string(),
                    full.display()
                ))),
                ReadError::Format(e) => bad(format!(
                    " = {:?}: {}: {e}",
                    p.display().to_string(),
                    full.display()
                )),
            })
        }
    }
}

/// `a` unless an entry is not finite (TOML has `inf` and `nan`).
fn finite_entries(key: &str, a: Vec<f64>) -> Result<Vec<f64>, Loaded> {
    match a.iter().position(|v| !v.is_finite()) {
        Some(i) => Err(Loaded::Invalid(invalid(
            key,
            format!(
                " has a non-finite entry {} (at {i}, row-major)",
                a.get(i).copied().unwrap_or(f64::NAN)
            ),
        ))),
        None => Ok(a),
    }
}

/// The checked model from the parsed file and its matrices.
fn build(file: ModelFile, mats: Vec<(usize, Vec<f64>)>) -> Result<Model, Invalid> {
    let [(n, m), (nc, c), (nk, k)]: [(usize, Vec<f64>); 3] = mats
        .try_into()
        .map_err(|_| invalid("model", ": M, C and K are needed"))?;
    if nc != n || nk != n {
        return Err(invalid(
            "model",
            format!(": M, C, K must have one size, got {n}, {nc}, {nk}"),
        ));
    }
    let elements = file
        .element
        .iter()
        .enumerate()
        .map(|(i, e)| element(i, e, n))
        .collect::<Result<Vec<_>, _>>()?;
    let forcing = match &file.forcing {
        Some(f) => harmonics(f, n)?,
        None => Vec::new(),
    };
    let options = options(&file.options)?;
    let range = file.range.as_ref().map_or((None, None), |r| (r.from, r.to));
    for (key, v) in [("range.from", range.0), ("range.to", range.1)] {
        if let Some(v) = v {
            if !(v.is_finite() && v > 0.0) {
                return Err(invalid(key, format!(" = {v:?}: must be finite and > 0")));
            }
        }
    }
    let problem = ElementProblem::new(n, [m, c, k], elements, forcing)
        .map_err(|e| invalid("model", format!(": {e}")))?;
    Ok(Model {
        problem,
        options,
        range,
        events: file.options.events,
        method: match file.options.method {
            MethodName::Modified => Method::Modified,
            MethodName::Classic => Method::Classic,
        },
    })
}

/// Element `i` of the file, its DOFs < n and its law's parameters (and no
/// other) given and valid.
fn element(i: usize, e: &ElementEntry, n: usize) -> Result<Element, Invalid> {
    let key = |k: &str| format!("element[{i}].{k}");
    if e.dof >= n {
        return Err(invalid(
            key("dof"),
            format!(" = {}: must be < {n} (the model's DOFs)", e.dof),
        ));
    }
    if let Some(to) = e.to {
        if to >= n || to == e.dof {
            return Err(invalid(
                key("to"),
                format!(
                    " = {to}: must be < {n} and differ from `dof` = {} (leave it out for the ground)",
                    e.dof
                ),
            ));
        }
    }
    let given = [
        ("k3", e.k3),
        ("c2", e.c2),
        ("c3", e.c3),
        ("force", e.force),
        ("v_reg", e.v_reg),
        ("gap", e.gap),
        ("k", e.k),
        ("slip_force", e.slip_force),
    ];
    let wants: &[&str] = match e.law {
        LawName::CubicSpring => &["k3"],
        LawName::QuadraticDamper => &["c2"],
        LawName::CubicDamper => &["c3"],
        LawName::Coulomb => &["force", "v_reg"],
        LawName::Clearance | LawName::Unilateral => &["gap", "k"],
        LawName::Jenkins => &["k", "slip_force"],
    };
    let law_name = format!("{:?}", e.law);
    for (name, v) in given {
        match (wants.contains(&name), v) {
            (false, Some(v)) => {
                return Err(invalid(
                    key(name),
                    format!(
                        " = {v}: law `{}` takes {} only",
                        snake(&law_name),
                        wants.join(", ")
                    ),
                ))
            }
            (true, None) => {
                return Err(invalid(
                    format!("element[{i}]"),
                    format!(": law `{}` needs `{name}`", snake(&law_name)),
                ))
            }
            (true, Some(v)) if !v.is_finite() => {
                return Err(invalid(key(name), format!(" = {v:?}: must be finite")))
            }
            _ => {}
        }
    }
    let p = |v: Option<f64>| v.unwrap_or(f64::NAN);
    let law = match e.law {
        LawName::CubicSpring => Law::CubicSpring { k3: p(e.k3) },
        LawName::QuadraticDamper => Law::QuadraticDamper { c2: p(e.c2) },
        LawName::CubicDamper => Law::CubicDamper { c3: p(e.c3) },
        LawName::Coulomb => Law::Coulomb {
            force: p(e.force),
            v_reg: p(e.v_reg),
        },
        LawName::Clearance => Law::Clearance {
            gap: p(e.gap),
            k: p(e.k),
        },
        LawName::Unilateral => Law::Unilateral {
            gap: p(e.gap),
            k: p(e.k),
        },
        LawName::Jenkins => Law::Jenkins {
            k: p(e.k),
            slip_force: p(e.slip_force),
        },
    };
    // (key, value, holds, the rule) of the laws with a sign condition.
    let rules = match law {
        Law::Coulomb { v_reg, .. } => vec![("v_reg", v_reg, v_reg > 0.0, "> 0")],
        Law::Clearance { gap, k } | Law::Unilateral { gap, k } => {
            vec![("gap", gap, gap >= 0.0, ">= 0"), ("k", k, k >= 0.0, ">= 0")]
        }
        Law::Jenkins { k, slip_force } => vec![
            ("k", k, k > 0.0, "> 0"),
            ("slip_force", slip_force, slip_force > 0.0, "> 0"),
        ],
        _ => Vec::new(),
    };
    if let Some((name, v, _, rule)) = rules.into_iter().find(|r| !r.2) {
        return Err(invalid(key(name), format!(" = {v:?}: must be {rule}")));
    }
    Ok(Element {
        a: e.dof,
        b: e.to,
        law,
    })
}

/// `CubicSpring` → `cubic_spring`.
fn snake(camel: &str) -> String {
    let mut out = String::new();
    for (i, ch) in camel.chars().enumerate() {
        if ch.is_ascii_uppercase() && i > 0 {
            out.push('_');
        }
        out.push(ch.to_ascii_lowercase());
    }
    out
}

/// The forcing as one harmonic per DOF.
fn harmonics(f: &Forcing, n: usize) -> Result<Vec<Harmonic>, Invalid> {
    let lengths = [
        ("forcing.amplitude", Some(f.amplitude.len())),
        ("forcing.phase", f.phase.as_ref().map(Vec::len)),
    ];
    for (key, len) in lengths {
        if let Some(len) = len.filter(|&l| l != n) {
            return Err(invalid(
                key,
                format!(" has {len} entries; the model has {n} DOFs"),
            ));
        }
    }
    let phase = f.phase.clone().unwrap_or_else(|| vec![0.0; n]);
    f.amplitude
        .iter()
        .zip(&phase)
        .enumerate()
        .map(|(dof, (&amplitude, &phase))| {
            for (key, v) in [("forcing.amplitude", amplitude), ("forcing.phase", phase)] {
                if !v.is_finite() {
                    return Err(invalid(
                        format!("{key}[{dof}]"),
                        format!(" = {v:?}: must be finite"),
                    ));
                }
            }
            Ok(Harmonic {
                dof,
                amplitude,
                phase,
            })
        })
        .collect()
}

/// The harmonic-balance options as `ivt.hb.frc`/`solve` build them from the
/// same keywords (`HbOptions::new(n, samples)`, then the tolerances).
fn options(o: &Options) -> Result<HbOptions, Invalid> {
    if o.n == 0 {
        return Err(invalid("options.n", " = 0: must be >= 1 (harmonics)"));
    }
    if let Some(why) = ivt_hb::limits::unknowns_error(1, o.n) {
        return Err(invalid("options.n", format!(" = {}: {why}", o.n)));
    }
    if let Some(why) = ivt_hb::limits::samples_error(o.samples) {
        return Err(invalid(
            "options.samples",
            format!(" = {}: {why}", o.samples),
        ));
    }
    if o.samples <= o.n {
        return Err(invalid(
            "options.samples",
            format!(
                " = {}: must exceed `options.n` = {} (2N > 2n AFT samples)",
                o.samples, o.n
            ),
        ));
    }
    for (key, v) in [("options.tol", o.tol), ("options.rtol", o.rtol)] {
        if !(v.is_finite() && v >= 0.0) {
            return Err(invalid(key, format!(" = {v:?}: must be finite and >= 0")));
        }
    }
    if o.tol + o.rtol <= 0.0 {
        return Err(invalid(
            "options.rtol",
            " = 0: `options.tol` and `options.rtol` must not both be 0",
        ));
    }
    if o.max_iter == 0 {
        return Err(invalid("options.max_iter", " = 0: must be >= 1"));
    }
    Ok(HbOptions::new(o.n, o.samples)
        .with_subharmonic(1)
        .with_tolerances(o.rtol, o.tol)
        .with_max_iter(o.max_iter))
}
