//! Every periodic solution at one excitation frequency by deflated Newton
//! (Farrell, Birkisson & Funke, SIAM J. Sci. Comput. 37 (2015); BifurcationKit's
//! `DeflationOperator`): once solutions `q₁…q_k` of the HB residual `R(q) = 0`
//! (Eq. 61) are known, Newton is run on
//!
//! `G(q) = M(q) R(q)`,  `M(q) = Π_i (‖q − q_i‖⁻ᵖ/s⁻ᵖ + σ)`,
//!
//! whose only roots are the other roots of `R` (M blows up at each `q_i`). The
//! deflated Newton step is the plain one `δ₀ = −Φ_q⁻¹R` (Φ_q the Galerkin
//! Jacobian, Eq. 56) rescaled by Sherman–Morrison,
//! `δ = δ₀ / (1 − ∇ln M · δ₀)`, so no second factorisation is needed. Each root
//! found is polished by undeflated Newton and its Floquet multipliers (Hsu,
//! Eq. 80) are computed.
//!
//! The search is bounded, and the result says how: a fixed set of starts (the
//! linear solution, Eq. 59, and its shape scaled to amplitudes spread
//! geometrically up to `max_amplitude` at four phases), from each start deflated
//! runs until one fails (k = 1 consecutive failure per start), at most
//! `max_iter` Newton steps per run, and iterates leaving the box
//! `‖q‖∞ ≤ max_amplitude` abandoned. "Exhausted" means every start's last run
//! found nothing new within these bounds, not a proof; the report states the
//! bound ([`SearchReport::bound`]).
//!
//! Each Newton matrix is factored with its rows scaled to unit ∞-norm
//! (harmonic h of the linear part grows as h²ω², so at large ω_f the
//! unscaled matrix looks singular to the pivot test while its rows are
//! well separated). When the linear part itself is singular at a harmonic
//! (an undamped resonance, h·ω_f a natural frequency) and nothing is found,
//! the search says so ([`HbError::InvalidInput`] naming the harmonic): there
//! is no isolated orbit — none if the load excites that harmonic, a continuum
//! if it does not. For an autonomous problem (no excitation, `g` independent
//! of θ) every time shift of an orbit is an orbit: copies that differ by a
//! shift (and the symmetric copies that are half-period shifts) are merged
//! into one ([`SearchReport::copies_merged`]).

use crate::error::HbError;
use crate::orbit::classic::Galerkin;
use crate::orbit::galerkin::GalerkinJacobian;
use crate::orbit::ihb::{HbOptions, HbResidual, HbSolution};
use crate::problem::PeriodicProblem;
use crate::stability::floquet::HsuRule;
use crate::stability::{StabilityAnalyzer, StabilityKind};
use crate::BroydenStats;
use faer::c64;
use ivt_num::vector::norm2;
use ivt_num::{
    deflated_newton, newton, Deflation, LuWorkspace, NewtonOptions, NewtonWorkspace, SolveError,
};

/// Bounds of the search.
#[derive(Debug, Clone, PartialEq)]
pub struct SearchOptions {
    /// Largest `‖q‖∞` searched (the box; also the scale `s` of the distances).
    pub max_amplitude: f64,
    /// Start amplitudes per phase, spread geometrically from
    /// `max_amplitude/100` to `max_amplitude/2` (default 6).
    pub amplitudes: usize,
    /// Newton steps per deflated run (default 60).
    pub max_iter: usize,
    /// Power `p` of the deflation (default 2).
    pub power: f64,
    /// Shift `σ` of the deflation (default 1).
    pub shift: f64,
    /// Hsu sub-intervals of the stability analysis (> harmonics; default 512).
    pub stability_steps: usize,
}

impl Default for SearchOptions {
    fn default() -> Self {
        Self {
            max_amplitude: 10.0,
            amplitudes: 6,
            max_iter: 60,
            power: 2.0,
            shift: 1.0,
            stability_steps: 512,
        }
    }
}

/// One solution with its stability.
#[derive(Debug, Clone, PartialEq)]
pub struct FoundSolution {
    /// The orbit.
    pub solution: HbSolution,
    /// Floquet multipliers (Hsu), decreasing modulus.
    pub multipliers: Vec<c64>,
    /// Their verdict.
    pub kind: StabilityKind,
}

/// How the search was bounded and how it ended.
#[derive(Debug, Clone, PartialEq)]
pub struct SearchReport {
    /// Starts tried.
    pub starts: usize,
    /// Deflated Newton runs (successful and failed).
    pub runs: usize,
    /// The box `‖q‖∞ ≤ max_amplitude`.
    pub max_amplitude: f64,
    /// Newton steps allowed per run.
    pub max_iter: usize,
    /// Whether every start's last run failed to find a new solution (the search
    /// found nothing more within its bounds).
    pub exhausted: bool,
    /// Failed runs that end the search from one start (k = 1).
    pub failures_per_start: usize,
    /// Orbits dropped as time-shifted copies of another (autonomous
    /// problems only).
    pub copies_merged: usize,
    /// The bound `exhausted` refers to, in words: the start set, the
    /// failures per start, the Newton steps per run and the box.
    pub bound: String,
}

/// Every solution found, by increasing `‖q‖₂`, and the search's bounds.
#[derive(Debug, Clone, PartialEq)]
pub struct AllSolutions {
    /// The solutions.
    pub solutions: Vec<FoundSolution>,
    /// The search.
    pub report: SearchReport,
}

/// Most solutions kept (a guard against a continuum of solutions, e.g. an
/// unforced conservative problem).
const MAX_SOLUTIONS: usize = 64;

/// Most start amplitudes per harmonic (`SearchOptions::amplitudes`): the
/// starts are listed before the search, each is one deflated Newton run.
pub const MAX_AMPLITUDES: usize = 1000;

/// All periodic solutions of `problem` at `omega_f` that deflated Newton finds
/// within `opts` (see the module docs).
///
/// # Errors
/// [`HbError::InvalidInput`] for a bad frequency or bounds (`amplitudes`
/// above [`MAX_AMPLITUDES`]), the AFT's size errors; [`HbError::Interrupted`]
/// when cancelled ([`ivt_num::cancel`]).
pub fn all_solutions(
    problem: &dyn PeriodicProblem,
    hb: &HbOptions,
    omega_f: f64,
    opts: &SearchOptions,
) -> Result<AllSolutions, HbError> {
    let problem = &problem;
    crate::orbit::ihb::validate_omega(omega_f)?;
    if opts.amplitudes > MAX_AMPLITUDES {
        return Err(HbError::InvalidInput(format!(
            "amplitudes = {} exceeds the limit of {MAX_AMPLITUDES} start amplitudes",
            opts.amplitudes
        )));
    }
    if !(opts.max_amplitude.is_finite()
        && opts.max_amplitude > 0.0
        && opts.amplitudes > 0
        && opts.max_iter > 0
        && opts.power > 0.0
        && opts.shift > 0.0)
    {
        return Err(HbError::InvalidInput(
            "search bounds: max_amplitude > 0 finite, amplitudes ≥ 1, max_iter ≥ 1, power > 0, shift > 0".into(),
        ));
    }
    let mut newton = Deflated::new(problem, hb, omega_f, opts)?;
    let starts = newton.starts()?;
    let mut known: Vec<Vec<f64>> = Vec::new();
    let mut runs = 0;
    let mut exhausted = true;
    let token = ivt_num::cancel::Token::now();
    'starts: for start in &starts {
        loop {
            if token.cancelled() {
                return Err(HbError::Interrupted);
            }
            if known.len() >= MAX_SOLUTIONS {
                exhausted = false;
                break 'starts;
            }
            runs += 1;
            match newton.run(start, &known) {
                Some(q) => known.push(q),
                None => break,
            }
        }
    }
    if known.is_empty() {
        if let Some(why) = newton.singular_linear_part() {
            return Err(HbError::InvalidInput(why));
        }
    }
    let found = known.len();
    let known = if crate::branches::autonomous::require_autonomous(problem, "").is_ok() {
        merge_time_shifts(known, hb.harmonics)
    } else {
        known
    };
    let copies_merged = found - known.len();
    let mut analyzer = StabilityAnalyzer::new(problem, hb.harmonics, opts.stability_steps)?;
    let mut solutions: Vec<FoundSolution> = known
        .into_iter()
        .map(|coeffs| {
            let solution = HbSolution {
                coeffs,
                omega_f,
                harmonics: hb.harmonics,
                subharmonic: hb.subharmonic,
                stats: BroydenStats::default(),
            };
            let floquet = analyzer.hsu(problem, &solution, HsuRule::Magnus4);
            FoundSolution {
                solution,
                multipliers: floquet.multipliers,
                kind: floquet.kind,
            }
        })
        .collect();
    solutions.sort_by(|a, b| norm2(&a.solution.coeffs).total_cmp(&norm2(&b.solution.coeffs)));
    Ok(AllSolutions {
        solutions,
        report: SearchReport {
            starts: starts.len(),
            runs,
            max_amplitude: opts.max_amplitude,
            max_iter: opts.max_iter,
            exhausted,
            failures_per_start: 1,
            copies_merged,
            bound: format!(
                "deflated Newton from {} starts (the linear solution if it lies in the box, \
                 then its shape at {} amplitudes from {} to {} at 4 phases each) until 1 \
                 failed run per start; at most {} Newton steps per run; the box max \
                 |coefficient| ≤ {}",
                starts.len(),
                opts.amplitudes,
                opts.max_amplitude / 100.0,
                opts.max_amplitude / 2.0,
                opts.max_iter,
                opts.max_amplitude
            ),
        },
    })
}

/// `known` without the orbits that are time shifts of an earlier one
/// (`n_dof` blocks of `2n + 1` coefficients each; the shift is found from
/// the largest harmonic of the earlier orbit and checked on every
/// coefficient, relative 1e-6).
fn merge_time_shifts(known: Vec<Vec<f64>>, n: usize) -> Vec<Vec<f64>> {
    let l = 2 * n + 1;
    let mut kept: Vec<Vec<f64>> = Vec::new();
    for q in known {
        if !kept.iter().any(|k| is_time_shift(k, &q, n, l)) {
            kept.push(q);
        }
    }
    kept
}

/// Whether `q` is `p` shifted in time (module docs).
fn is_time_shift(p: &[f64], q: &[f64], n: usize, l: usize) -> bool {
    if p.len() != q.len() || l == 0 {
        return false;
    }
    let scale = p.iter().chain(q).fold(0.0f64, |a, v| a.max(v.abs()));
    let close = |a: &[f64]| {
        a.iter()
            .zip(q)
            .all(|(x, y)| (x - y).abs() <= 1e-6 * scale.max(f64::MIN_POSITIVE))
    };
    // The harmonic (DOF, h) of p with the largest amplitude fixes the shift
    // up to multiples of 2π/h.
    let amp = |c: &[f64], d: usize, h: usize| {
        let (a, b) = (
            c.get(d * l + h).copied().unwrap_or(0.0),
            c.get(d * l + n + h).copied().unwrap_or(0.0),
        );
        (a, b)
    };
    let Some((d, h)) = (0..p.len() / l)
        .flat_map(|d| (1..=n).map(move |h| (d, h)))
        .max_by(|&(d1, h1), &(d2, h2)| {
            let (a1, b1) = amp(p, d1, h1);
            let (a2, b2) = amp(p, d2, h2);
            a1.hypot(b1).total_cmp(&a2.hypot(b2))
        })
    else {
        return close(p);
    };
    let (pa, pb) = amp(p, d, h);
    let (qa, qb) = amp(q, d, h);
    if pa.hypot(pb) == 0.0 {
        return close(p);
    }
    // u(τ + φ): (a, b) of harmonic h turns by −hφ in the (a, b) plane
    // ([`crate::orbit::aft::shift_time`]), i.e. arg(a + ib) decreases by hφ.
    let turn = pb.atan2(pa) - qb.atan2(qa);
    let hf = h as f64;
    (0..h).any(|k| {
        let phi = (turn + 2.0 * std::f64::consts::PI * k as f64) / hf;
        let mut shifted = p.to_vec();
        for block in shifted.chunks_exact_mut(l) {
            crate::orbit::aft::shift_time(block, phi);
        }
        close(&shifted)
    })
}

/// The deflated Newton iteration on one problem at one frequency.
struct Deflated<'p, P> {
    problem: &'p P,
    res: HbResidual,
    galerkin: GalerkinJacobian,
    lu: LuWorkspace,
    jac: Vec<f64>,
    r: Vec<f64>,
    omega_f: f64,
    tol: f64,
    opts: SearchOptions,
    newton: NewtonWorkspace,
}

impl<'p, P: PeriodicProblem> Deflated<'p, P> {
    fn new(
        problem: &'p P,
        hb: &HbOptions,
        omega_f: f64,
        opts: &SearchOptions,
    ) -> Result<Self, HbError> {
        let res = HbResidual::new(problem, hb)?;
        let m = res.len();
        let mut r = vec![0.0; m];
        // Tolerance from the forcing (or, unforced, from a unit first harmonic).
        let mut unit = vec![0.0; m];
        if let Some(a1) = unit.get_mut(1) {
            *a1 = 1.0;
        }
        let tol = hb.residual_tol(res.force_scale(problem, &unit, omega_f, &mut r));
        Ok(Self {
            galerkin: GalerkinJacobian::new(&res),
            lu: LuWorkspace::new(m),
            jac: vec![0.0; m * m],
            r,
            problem,
            res,
            omega_f,
            tol,
            opts: opts.clone(),
            newton: NewtonWorkspace::new(m),
        })
    }

    /// The linear solution (Eq. 59) and its shape at `amplitudes` amplitudes and
    /// four phases (a unit cosine on DOF 0 if the linear solution vanishes).
    fn starts(&mut self) -> Result<Vec<Vec<f64>>, HbError> {
        let m = self.res.len();
        let n = self.res.harmonics();
        let l = 2 * n + 1;
        self.res.linear_matrix(
            self.problem,
            self.omega_f / self.res.subharmonic() as f64,
            &mut self.jac,
        );
        let mut linear = self.res.excitation().to_vec();
        let solvable = self.factor_scaled(&mut linear);
        if solvable {
            self.lu.solve(&mut linear);
        }
        let size = linear.iter().fold(0.0f64, |a, v| a.max(v.abs()));
        let mut starts = Vec::new();
        if solvable && size > 0.0 && size.is_finite() && size <= self.opts.max_amplitude {
            starts.push(linear.clone());
        }
        let shape: Vec<f64> = if solvable && size > 0.0 && size.is_finite() {
            linear.iter().map(|v| v / size).collect()
        } else {
            let mut unit = vec![0.0; m];
            if let Some(a1) = unit.get_mut(1) {
                *a1 = 1.0;
            }
            unit
        };
        let k = self.opts.amplitudes;
        let (lo, hi) = (
            self.opts.max_amplitude / 100.0,
            self.opts.max_amplitude / 2.0,
        );
        for i in 0..k {
            let amp = if k == 1 {
                hi
            } else {
                lo * (hi / lo).powf(i as f64 / (k - 1) as f64)
            };
            for quarter in 0..4 {
                // Rotate every harmonic h by h·quarter·π/2 (a time shift of the
                // shape; for a forced problem a different orbit).
                let mut q: Vec<f64> = shape.iter().map(|v| amp * v).collect();
                for block in q.chunks_exact_mut(l) {
                    crate::orbit::aft::shift_time(
                        block,
                        quarter as f64 * std::f64::consts::FRAC_PI_2,
                    );
                }
                starts.push(q);
            }
        }
        Ok(starts)
    }

    /// Factor `self.jac` with each row (and the entry of `rhs` on it) scaled
    /// to unit ∞-norm (module docs); false if it is singular even so.
    fn factor_scaled(&mut self, rhs: &mut [f64]) -> bool {
        let m = self.res.len();
        for (row, b) in self.jac.chunks_exact_mut(m.max(1)).zip(rhs.iter_mut()) {
            let size = row.iter().fold(0.0f64, |a, v| a.max(v.abs()));
            if size > 0.0 && size.is_finite() {
                row.iter_mut().for_each(|v| *v /= size);
                *b /= size;
            }
        }
        self.lu.factor_row_major(&self.jac)
    }

    /// Why the linear part `L(ω_f)` (Eq. 59) has no unique solution: the
    /// first harmonic h whose block is singular (module docs); `None` if
    /// every block is regular.
    fn singular_linear_part(&mut self) -> Option<String> {
        let m = self.res.len();
        let n = self.res.harmonics();
        let l = 2 * n + 1;
        let omega = self.omega_f / self.res.subharmonic() as f64;
        self.res.linear_matrix(self.problem, omega, &mut self.jac);
        let n_dof = m / l;
        for h in 0..=n {
            let rows: Vec<usize> = (0..n_dof)
                .flat_map(|d| {
                    let cos = d * l + h;
                    if h == 0 {
                        vec![cos]
                    } else {
                        vec![cos, cos + n]
                    }
                })
                .collect();
            let k = rows.len();
            let mut block: Vec<f64> = rows
                .iter()
                .flat_map(|&i| rows.iter().map(move |&j| (i, j)))
                .map(|(i, j)| self.jac.get(i * m + j).copied().unwrap_or(f64::NAN))
                .collect();
            for row in block.chunks_exact_mut(k.max(1)) {
                let size = row.iter().fold(0.0f64, |a, v| a.max(v.abs()));
                if size > 0.0 && size.is_finite() {
                    row.iter_mut().for_each(|v| *v /= size);
                }
            }
            if !LuWorkspace::new(k).factor_row_major(&block) {
                return Some(format!(
                    "no isolated periodic orbit at ω_f = {:?}: the linear part is singular at \
                     harmonic {h} (h·ω = {:?} is an undamped natural frequency, or K is \
                     singular at h = 0): none exists if the load excites it, a continuum if \
                     not; add damping or move ω_f",
                    self.omega_f,
                    h as f64 * omega
                ));
            }
        }
        None
    }

    /// ‖R(q)‖₂ into `self.r`.
    fn residual(&mut self, q: &[f64]) -> f64 {
        self.res
            .eval(self.problem, q, self.omega_f, 1.0, &mut self.r);
        norm2(&self.r)
    }

    /// One deflated run from `start` (at most `max_iter` steps, iterates
    /// leaving the box abandoned): a new root polished by plain Newton, or
    /// `None` if the run fails within its bounds or only finds a known root.
    fn run(&mut self, start: &[f64], known: &[Vec<f64>]) -> Option<Vec<f64>> {
        let mut q = start.to_vec();
        let box_size = self.opts.max_amplitude;
        let mut sys = Galerkin {
            problem: self.problem,
            res: &mut self.res,
            galerkin: &mut self.galerkin,
            omega_f: self.omega_f,
        };
        let deflation = Deflation {
            roots: known,
            power: self.opts.power,
            shift: self.opts.shift,
            scale: box_size,
            bound: box_size,
        };
        let run = NewtonOptions {
            ftol: self.tol,
            max_iter: self.opts.max_iter,
            scale_rows: true,
            ..NewtonOptions::default()
        };
        deflated_newton(&mut sys, &mut q, &deflation, &mut self.newton, &run).ok()?;
        // Polish undeflated: up to five full Newton steps, until a step is
        // below 1e-13 of the box; the residual is tested after them.
        let polish = NewtonOptions {
            ftol: 0.0,
            atol: 1e-13 * box_size,
            max_iter: 5,
            max_halvings: 0,
            accept_no_descent: true,
            scale_rows: true,
            ..NewtonOptions::default()
        };
        match newton(&mut sys, &mut q, &mut self.newton, &polish) {
            Ok(_) | Err(SolveError::NonConvergence { .. }) => {}
            Err(_) => return None,
        }
        let norm = self.residual(&q);
        if norm > self.tol || norm.is_nan() {
            return None;
        }
        let scale = q.iter().fold(0.0f64, |a, v| a.max(v.abs())).max(1e-300);
        let is_known = known.iter().any(|root| {
            let d = q
                .iter()
                .zip(root)
                .fold(0.0f64, |a, (x, y)| a.max((x - y).abs()));
            d <= 1e-6 * scale
        });
        (!is_known).then_some(q)
    }
}
