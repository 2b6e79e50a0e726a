//! Period-doubling cascade of the Mathieu–Duffing equation (§3.2.5, Eq. 81–85):
//! period-1 → 2 → 4, returning the critical β where each branch loses stability
//! through a multiplier −1.
//!
//! 1. The period-1 solution at β₀ = 3.6 is solved from the thesis's printed
//!    coefficients (n = 9) and followed in β by pseudo-arclength continuation
//!    with Hsu multipliers at every point.
//! 2. The crossing μ = −1, bracketed by two path points, is located by Newton
//!    on the extended system of [`crate::branches::events`] (the branch in β with
//!    the bordered test function of Φ + I), as every event of [`crate::trace`].
//! 3. The period-2p branch is entered with the controlled-amplitude scheme of
//!    Eq. 84–85: the solution is embedded with harmonic k → 2k
//!    (`a_{2j}^{(2)} = a_j^{(1)}`), the amplitude `a_1` of the new lowest harmonic is
//!    prescribed (non-zero forces the new branch) and β takes its slot among the
//!    unknowns; `a_1` is then the continuation parameter.

use crate::branches::events::{
    locate_multiplier_crossing, BifurcationError, BifurcationKind, LocateOptions,
};
use crate::branches::family::FamilyBranch;
use crate::orbit::aft::{embed_subharmonic, resize_harmonics};
use crate::orbit::ihb::{HbError, HbOptions, HbResidual, HbSolution};
use crate::orbit::modified::ModifiedIhb;
use crate::problem::MathieuDuffing;
use crate::stability::floquet::HsuRule;
use crate::stability::StabilityAnalyzer;
use faer::c64;
use ivt_num::{broyden_solve, BroydenOptions, BroydenStats, BroydenWorkspace};
use ivt_path::continuation::{follow_residual, ContinuationOptions, Path, Steps};

/// The thesis's period-1 coefficients at β₀ = 3.6, n = 9 (§3.2.5; the printed
/// "=0.0001" is read as −0.0001).
pub const THESIS_A0: [f64; 19] = [
    0.7881, -1.3956, 0.2686, 0.1121, -0.0260, 0.0026, -0.0008, -0.0001, -0.0001, 0.0, 1.9884,
    -0.1693, 0.0471, -0.0175, -0.0042, 0.0021, -0.0003, 0.0, 0.0,
];

/// Parameters of the cascade.
#[derive(Debug, Clone, PartialEq)]
pub struct CascadeOptions {
    /// Damping ratio ξ̂ (0.125).
    pub xi: f64,
    /// Stiffness α̂ (1, enters as −α̂).
    pub alpha: f64,
    /// Excitation frequency Ω (2).
    pub omega: f64,
    /// Cubic stiffness γ (1).
    pub gamma: f64,
    /// Start β₀ (3.6).
    pub beta0: f64,
    /// Harmonics of the period-1 solution; period 2^k uses 2^k times as many.
    pub harmonics: usize,
    /// Number of period doublings to find (3: β1, β2, β4).
    pub doublings: usize,
    /// Hsu sub-intervals per harmonic of the solution (total = this × n).
    pub hsu_steps_per_harmonic: usize,
    /// AFT samples N (2N per period) of the period-1 orbit; `None`: 4n.
    /// The period-2^k branch uses 2^k times as many, as it does harmonics.
    pub samples: Option<usize>,
    /// Overrides of every leg's steps ([`CascadeOptions::period_one_path`],
    /// [`CascadeOptions::doubled_path`]); `max_points` counts per leg.
    pub steps: Steps,
}

impl Default for CascadeOptions {
    fn default() -> Self {
        Self {
            xi: 0.125,
            alpha: 1.0,
            omega: 2.0,
            gamma: 1.0,
            beta0: 3.6,
            harmonics: 12,
            doublings: 3,
            hsu_steps_per_harmonic: 24,
            samples: None,
            steps: Steps::default(),
        }
    }
}

impl CascadeOptions {
    /// The AFT samples N of the period-1 orbit (`samples`, or 4n).
    ///
    /// # Errors
    /// [`HbError::InvalidInput`] when the period-4 branch's 4n harmonics
    /// exceed [`crate::limits::unknowns_error`]'s bound, when N ≤ n, or when
    /// the period-2^k branch's samples exceed
    /// [`crate::limits::samples_error`]'s.
    pub fn period_one_samples(&self) -> Result<usize, HbError> {
        // Refused before any allocation (the period-4 branch carries 4n harmonics).
        if let Some(why) = crate::limits::unknowns_error(1, self.harmonics.saturating_mul(4)) {
            return Err(HbError::InvalidInput(why));
        }
        let n_half = self
            .samples
            .unwrap_or_else(|| self.harmonics.saturating_mul(4));
        if n_half <= self.harmonics {
            return Err(HbError::InvalidInput(format!(
                "`samples` = {n_half} must exceed `n` = {} (2N > 2n AFT samples)",
                self.harmonics
            )));
        }
        let last = 1usize << self.doublings.saturating_sub(1).min(30);
        if let Some(why) = crate::limits::samples_error(n_half.saturating_mul(last)) {
            return Err(HbError::InvalidInput(format!(
                "`samples` = {n_half} on the period-{last} branch: {why}"
            )));
        }
        Ok(n_half)
    }

    /// The period-1 branch in β: Δη from 0.02 up to 0.05, 4000 points, β ≤ 20,
    /// with [`steps`](Self::steps).
    ///
    /// # Errors
    /// [`HbError::InvalidInput`] for steps [`Steps::on`] refuses.
    pub fn period_one_path(&self) -> Result<ContinuationOptions, HbError> {
        self.stepped(ContinuationOptions {
            ds: 0.02,
            ds_max: 0.05,
            lambda_max: 20.0,
            max_points: 4000,
            ..ContinuationOptions::default()
        })
    }

    /// A period-2^k branch in its controlled amplitude a₁ (Eq. 84–85), scaled
    /// to `amp`, the largest coefficient of the orbit that doubled: Δη from
    /// 0.01·amp up to 0.02·amp, a₁ in [0, 10·amp], 4000 points, with
    /// [`steps`](Self::steps).
    ///
    /// # Errors
    /// [`HbError::InvalidInput`] for steps [`Steps::on`] refuses.
    pub fn doubled_path(&self, amp: f64) -> Result<ContinuationOptions, HbError> {
        self.stepped(ContinuationOptions {
            ds: 0.01 * amp,
            ds_max: 0.02 * amp,
            lambda_min: 0.0,
            lambda_max: 10.0 * amp,
            max_points: 4000,
            ..ContinuationOptions::default()
        })
    }

    fn stepped(&self, own: ContinuationOptions) -> Result<ContinuationOptions, HbError> {
        self.steps.on(own).map_err(HbError::InvalidInput)
    }
}

/// A path point with its period-doubling indicator (μ_min + 1).
type Sample = (Vec<f64>, f64);

/// The first sign change of the period-doubling indicator from `> 0` to `≤ 0`
/// along a path: the bracketing pair of points, once found.
#[derive(Default)]
struct PdBracket {
    prev: Option<Sample>,
    found: Option<(Sample, Sample)>,
}

impl PdBracket {
    /// Records the path point `x` with indicator `g`; `false` (stop the path) once
    /// the change is bracketed.
    fn push(&mut self, x: &[f64], g: f64) -> bool {
        let cur = (x.to_vec(), g);
        if let Some(pr) = self.prev.take() {
            if pr.1 > 0.0 && g <= 0.0 {
                self.found = Some((pr, cur));
                return false;
            }
        }
        self.prev = Some(cur);
        true
    }
}

/// One period-doubling point.
#[derive(Debug, Clone, PartialEq)]
pub struct PeriodDoubling {
    /// Period (in forcing periods) of the branch that loses stability.
    pub period: usize,
    /// Critical β.
    pub beta: f64,
    /// The critical multiplier (≈ −1).
    pub multiplier: c64,
    /// The solution at the critical point (period-`period` coefficients).
    pub solution: HbSolution,
}

/// The most negative real multiplier + 1 (positive when none is ≤ −1 … or when no
/// multiplier is real and negative): the function whose zero marks a period doubling.
fn pd_indicator(mu: &[c64]) -> (f64, c64) {
    mu.iter()
        .filter(|m| m.im.abs() <= 1e-7 * m.norm().max(1e-300) && m.re < 0.0)
        .map(|m| (m.re + 1.0, *m))
        .fold((1.0, c64::new(f64::NAN, 0.0)), |a, b| {
            if b.0 < a.0 {
                b
            } else {
                a
            }
        })
}

/// Solves the controlled-amplitude system: unknowns `y` = coefficients with slot
/// `c` holding β, prescribed `q[c] = a_c` (Eq. 85).
struct Controlled {
    res: HbResidual,
    p: MathieuDuffing,
    c: usize,
    omega: f64,
    q: Vec<f64>,
}

impl Controlled {
    fn eval(&mut self, y: &[f64], a_c: f64, r: &mut [f64]) {
        self.q.copy_from_slice(y);
        set(&mut self.q, self.c, a_c);
        self.p.beta = y.get(self.c).copied().unwrap_or(f64::NAN);
        self.res.eval(&self.p, &self.q, self.omega, 1.0, r);
    }
    fn solution(&self, y: &[f64], a_c: f64, harmonics: usize, period: usize) -> (HbSolution, f64) {
        let mut q = y.to_vec();
        set(&mut q, self.c, a_c);
        let stats = BroydenStats::default();
        (
            HbSolution {
                coeffs: q,
                omega_f: self.omega,
                harmonics,
                subharmonic: period,
                stats,
            },
            y.get(self.c).copied().unwrap_or(f64::NAN),
        )
    }
}

/// `x[k] = v` (nothing for `k` out of range).
fn set(x: &mut [f64], k: usize, v: f64) {
    if let Some(e) = x.get_mut(k) {
        *e = v;
    }
}

/// A path point `x` as its unknowns and its parameter (the last entry).
fn split_param(x: &[f64]) -> (&[f64], f64) {
    x.split_last().map_or((&[][..], f64::NAN), |(l, q)| (q, *l))
}

/// Of two bracketing path points with period-doubling indicators `ga`, `gb`,
/// the orbit `(q, β)` (by `orbit`) of the one nearer the crossing.
fn nearer(
    xa: &[f64],
    ga: f64,
    xb: &[f64],
    gb: f64,
    orbit: impl Fn(&[f64]) -> (Vec<f64>, f64),
) -> (Vec<f64>, f64) {
    orbit(if ga.abs() <= gb.abs() { xa } else { xb })
}

/// The period doubling of the period-`period` branch in β next to its orbit
/// `(q, β)`: Newton on the extended system `[R(q, β); ψ(q, β)] = 0`, ψ the
/// bordered test function of `Φ + I` (Hsu with the cascade's sub-intervals),
/// [`locate_multiplier_crossing`].
fn locate_period_doubling(
    opts: &CascadeOptions,
    hb: &HbOptions,
    period: usize,
    q: &[f64],
    beta: f64,
) -> Result<PeriodDoubling, HbError> {
    let family = |b: f64| {
        (
            MathieuDuffing::new(opts.xi, opts.alpha, b, opts.gamma),
            opts.omega,
        )
    };
    let mut branch = FamilyBranch::new(family, hb, beta)?;
    let located = locate_multiplier_crossing(
        &mut branch,
        BifurcationKind::PeriodDoubling,
        q,
        beta,
        &LocateOptions {
            stability_steps: opts.hsu_steps_per_harmonic * hb.harmonics,
            ..LocateOptions::default()
        },
    )
    .map_err(|e| match e {
        BifurcationError::Hb(h) => h,
        other => HbError::InvalidInput(other.to_string()),
    })?;
    let multiplier = located
        .multipliers
        .iter()
        .copied()
        .min_by(|a, b| (a + 1.0).norm().total_cmp(&(b + 1.0).norm()))
        .unwrap_or(c64::new(f64::NAN, 0.0));
    Ok(PeriodDoubling {
        period,
        beta: located.lambda,
        multiplier,
        solution: HbSolution {
            coeffs: located.q,
            omega_f: opts.omega,
            harmonics: hb.harmonics,
            subharmonic: period,
            stats: BroydenStats {
                iterations: located.iterations,
                residual_evals: 0,
                jacobian_refreshes: 0,
                residual_norm: located.residual_norm,
            },
        },
    })
}

/// The period-`period` branch ended (`path`'s termination, after its
/// points) without a multiplier reaching −1.
fn never_doubled(period: usize, path: &Path) -> HbError {
    HbError::InvalidInput(format!(
        "period-{period} branch never reached μ = −1: it ended with `{}` after {} points",
        path.termination.as_str(),
        path.points.len()
    ))
}

/// Runs the cascade and returns the critical points β1, β2, β4, … in order.
///
/// # Errors
/// [`HbError`] if a solve or a branch switch fails.
pub fn period_doubling_cascade(opts: &CascadeOptions) -> Result<Vec<PeriodDoubling>, HbError> {
    let mut out = Vec::new();
    // --- period 1: continuation in β.
    let n1 = opts.harmonics;
    let n_half1 = opts.period_one_samples()?;
    let copts = opts.period_one_path()?;
    let hb1 = HbOptions::new(n1, n_half1);
    let problem = MathieuDuffing::new(opts.xi, opts.alpha, opts.beta0, opts.gamma);
    let guess = resize_harmonics(&THESIS_A0, n1);
    let start = ModifiedIhb::new(problem.clone(), hb1.clone())?.solve(opts.omega, Some(&guess))?;
    let mut res = HbResidual::new(&problem, &hb1)?;
    let mut x0 = start.coeffs.clone();
    x0.push(opts.beta0);
    let mut an = StabilityAnalyzer::new(&problem, n1, opts.hsu_steps_per_harmonic * n1)?;
    let mut bracket = PdBracket::default();
    let mut p = problem.clone();
    let stab = |an: &mut StabilityAnalyzer,
                p: &MathieuDuffing,
                coeffs: &[f64],
                harmonics: usize,
                period: usize| {
        let stats = BroydenStats::default();
        let sol = HbSolution {
            coeffs: coeffs.to_vec(),
            omega_f: opts.omega,
            harmonics,
            subharmonic: period,
            stats,
        };
        pd_indicator(&an.hsu(p, &sol, HsuRule::Magnus4).multipliers)
    };
    let residual = |x: &[f64], r: &mut [f64]| {
        let mut pp = problem.clone();
        let (q, beta) = split_param(x);
        pp.beta = beta;
        res.eval(&pp, q, opts.omega, 1.0, r)
    };
    let path = follow_residual(residual, &x0, None, 1.0, &copts, |pt| {
        p.beta = pt.lambda();
        let (g, _) = stab(&mut an, &p, split_param(&pt.x).0, n1, 1);
        bracket.push(&pt.x, g)
    })
    .map_err(|e| HbError::InvalidInput(format!("period-1 continuation: {e}")))?;
    let ((xa, ga), (xb, gb)) = bracket.found.ok_or_else(|| never_doubled(1, &path))?;
    let (q, beta) = nearer(&xa, ga, &xb, gb, |x| {
        let (q, beta) = split_param(x);
        (q.to_vec(), beta)
    });
    let mut crit = locate_period_doubling(opts, &hb1, 1, &q, beta)?;
    out.push(crit.clone());
    // --- period 2, 4, …: controlled amplitude a_1.
    let mut period = 1;
    let mut n = n1;
    while out.len() < opts.doublings {
        let (new_period, new_n) = (2 * period, 2 * n);
        let hb = HbOptions::new(new_n, new_period * n_half1).with_subharmonic(new_period);
        let mut y = embed_subharmonic(&crit.solution.coeffs, 2, new_n);
        let c = 1; // a_1 of the new lowest harmonic
        set(&mut y, c, crit.beta);
        let l = y.len();
        let mut pp = MathieuDuffing::new(opts.xi, opts.alpha, crit.beta, opts.gamma);
        let mut ctl = Controlled {
            res: HbResidual::new(&pp, &hb)?,
            p: pp.clone(),
            c,
            omega: opts.omega,
            q: vec![0.0; l],
        };
        let mut an2 = StabilityAnalyzer::new(&pp, new_n, opts.hsu_steps_per_harmonic * new_n)?;
        // First point: a small prescribed a_1 (scaled to the solution size).
        let amp = crit
            .solution
            .coeffs
            .iter()
            .fold(0.0f64, |a, v| a.max(v.abs()));
        let a_start = 1e-3 * amp;
        let mut ws = BroydenWorkspace::new(l);
        let bopts = BroydenOptions {
            max_iter: 200,
            max_refreshes: 20,
            ..BroydenOptions::default()
        };
        broyden_solve(
            &mut |yv: &[f64], r: &mut [f64]| ctl.eval(yv, a_start, r),
            &mut y,
            &mut ws,
            &bopts,
        )?;
        let mut x0 = y.clone();
        x0.push(a_start);
        let copts = opts.doubled_path(amp)?;
        let mut bracket = PdBracket::default();
        // Skip the start region where the new branch's multiplier is still ≈ +1.
        let residual = |x: &[f64], r: &mut [f64]| {
            let (y, a) = split_param(x);
            ctl.eval(y, a, r)
        };
        let path = follow_residual(residual, &x0, None, 1.0, &copts, |pt| {
            let (y, a) = split_param(&pt.x);
            pp.beta = y.get(c).copied().unwrap_or(f64::NAN);
            let mut q = y.to_vec();
            set(&mut q, c, a);
            let (g, _) = stab(&mut an2, &pp, &q, new_n, new_period);
            bracket.push(&pt.x, g)
        })?;
        let ((xa, ga), (xb, gb)) = bracket
            .found
            .ok_or_else(|| never_doubled(new_period, &path))?;
        // The bracketing points as orbits of the period-2p branch in β.
        let (q, beta) = nearer(&xa, ga, &xb, gb, |x| {
            let (y, a) = split_param(x);
            let (sol, beta) = ctl.solution(y, a, new_n, new_period);
            (sol.coeffs, beta)
        });
        crit = locate_period_doubling(opts, &hb, new_period, &q, beta)?;
        out.push(crit.clone());
        period = new_period;
        n = new_n;
    }
    Ok(out)
}
