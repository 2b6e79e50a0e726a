//! The search for Hopf points over a range of p: equilibria on a grid,
//! crossings of the count of complex eigenvalues with positive real part
//! located by bisection, each classified by its first Lyapunov coefficient
//! (see the parent module).

use super::*;

/// The most grid intervals [`hopf_points`] accepts (each costs an
/// equilibrium solve and an eigenvalue problem).
pub const MAX_SAMPLES: usize = 100_000;

/// A stretch of p where [`hopf_points`] could not decide whether a Hopf
/// point lies there, and why.
#[derive(Debug, Clone, PartialEq)]
pub struct Undecided {
    /// One end of the stretch (the side of `p_from`).
    pub p_from: f64,
    /// The other end.
    pub p_to: f64,
    /// Why: no equilibrium, or an eigenvalue crossing that is neither a
    /// complex pair nor a real eigenvalue, or no Lyapunov coefficient.
    pub reason: String,
}

/// The Hopf points of a range of p and the stretches left undecided.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct HopfSearch {
    /// Hopf points in order of p from `p_from`.
    pub points: Vec<HopfPoint>,
    /// Stretches where the search could not decide (module docs of
    /// [`hopf_points`]).
    pub undecided: Vec<Undecided>,
}

/// |Im λ| below this fraction of max(1, |λ|) counts as a real eigenvalue at
/// a located crossing: a crossing pair there is not a Hopf point.
const REAL_AT_CROSSING: f64 = 1e-6;

/// The equilibria of `family(p)` from `x0` at `samples + 1` values of p
/// from `p_from` to `p_to`, and the Hopf points between them.
///
/// At each grid value the eigenvalues of `A` with positive real part are
/// counted (complex or real); where the count changes between neighbours,
/// bisection locates the change to the rounding of p, and the search goes
/// on from there to the interval's end (several crossings in one interval
/// are all located). A located change is a Hopf point when the eigenvalue
/// nearest the imaginary axis there is a complex pair ±iω (|ω| above
/// 1e-6·max(1, |λ|)) and the count changed by two; a real eigenvalue
/// through zero (a fold or branch point of the equilibria) is not
/// reported; a pair that turns real inside the right half-plane changes no
/// count and is not reported. What the grid cannot see is a pair that
/// crosses and crosses back within one interval (the count is equal at
/// both ends): a finer grid decides it. Grid values where Newton finds no
/// equilibrium, and crossings whose class or Lyapunov coefficient cannot
/// be computed, are returned in [`HopfSearch::undecided`] with the
/// reason instead of ending the search.
///
/// # Errors
/// [`HbError::InvalidInput`] for bounds, sizes, a singular mass matrix, or
/// no equilibrium at `p_from`; [`HbError::Size`] for a matrix that is not
/// `n_dof×n_dof`; `family`'s error.
pub fn hopf_points<P, F>(
    family: &F,
    x0: &[f64],
    p_from: f64,
    p_to: f64,
    samples: usize,
) -> Result<HopfSearch, HbError>
where
    P: PeriodicProblem,
    F: Fn(f64) -> Result<P, HbError>,
{
    if !(p_from.is_finite()
        && p_to.is_finite()
        && p_from != p_to
        && (1..=MAX_SAMPLES).contains(&samples))
    {
        return Err(HbError::InvalidInput(format!(
            "finite p_from ≠ p_to and 1 to {MAX_SAMPLES} grid intervals"
        )));
    }
    let state = |p: f64, x: &mut Vec<f64>| -> Result<usize, HbError> {
        let problem = family(p)?;
        if problem.n_dof() != x.len() {
            return Err(HbError::InvalidInput(format!(
                "the family changes size: at p = {p} it has {} DOFs, at p_from {}",
                problem.n_dof(),
                x.len()
            )));
        }
        equilibrium(&problem, x)?;
        let field = Field::new(&problem)?;
        Ok(unstable(&field.linearisation(x), 2 * x.len()))
    };
    let mut x = x0.to_vec();
    let mut count = state(p_from, &mut x)?;
    let mut search = HopfSearch::default();
    // `prev`: the last grid value with an equilibrium; across a gap the
    // next interval spans it (a crossing there is still bisected).
    let mut prev = p_from;
    for i in 1..=samples {
        let p = p_from + (p_to - p_from) * i as f64 / samples as f64;
        let mut xi = x.clone();
        let ci = match state(p, &mut xi) {
            Ok(c) => c,
            Err(HbError::InvalidInput(why)) if why.starts_with("no equilibrium") => {
                match search.undecided.last_mut() {
                    Some(u) if u.p_from == prev => u.p_to = p,
                    _ => search.undecided.push(Undecided {
                        p_from: prev,
                        p_to: p,
                        reason: why,
                    }),
                }
                continue;
            }
            Err(e) => return Err(e),
        };
        if ci != count {
            crossings(family, &x, (prev, count), (p, ci), &state, &mut search)?;
        }
        (x, count, prev) = (xi, ci, p);
    }
    Ok(search)
}

/// Every change of the unstable count between `(a, count_a)` (equilibrium
/// `x` there) and `(b, count_b)`: each located by bisection and classified
/// ([`hopf_points`]).
fn crossings<P, F>(
    family: &F,
    x: &[f64],
    (mut a, mut count_a): (f64, usize),
    (b, count_b): (f64, usize),
    state: &impl Fn(f64, &mut Vec<f64>) -> Result<usize, HbError>,
    search: &mut HopfSearch,
) -> Result<(), HbError>
where
    P: PeriodicProblem,
    F: Fn(f64) -> Result<P, HbError>,
{
    let mut xa = x.to_vec();
    // Each pass locates one change and moves `a` past it; a change needs at
    // least one bisection step, so this ends.
    while count_a != count_b {
        let (mut lo, mut hi) = (a, b);
        let mut count_hi = count_b;
        let mut xm = xa.clone();
        while (hi - lo).abs() > 4.0 * f64::EPSILON * lo.abs().max(hi.abs()).max(1.0) {
            let mid = 0.5 * (lo + hi);
            let mut xt = xm.clone();
            let c = match state(mid, &mut xt) {
                Ok(c) => c,
                Err(HbError::InvalidInput(why)) => {
                    search.undecided.push(Undecided {
                        p_from: a,
                        p_to: b,
                        reason: format!("the unstable eigenvalue count changes here, but {why}"),
                    });
                    return Ok(());
                }
                Err(e) => return Err(e),
            };
            if c == count_a {
                lo = mid;
            } else {
                (hi, count_hi) = (mid, c);
            }
            xm = xt;
        }
        match classify(family, &xm, lo, hi, count_a.abs_diff(count_hi)) {
            Ok(Some(point)) => search.points.push(point),
            Ok(None) => {}
            Err(why) => search.undecided.push(Undecided {
                p_from: lo,
                p_to: hi,
                reason: why,
            }),
        }
        (a, count_a) = (hi, count_hi);
        let mut xh = xm;
        state(hi, &mut xh)?;
        xa = xh;
    }
    Ok(())
}

/// The located change of the unstable count by `change` between `lo` and
/// `hi` (adjacent in floating point, equilibrium near `x`): a Hopf point, or
/// `None` for a real eigenvalue through zero, or why it is undecided.
fn classify<P, F>(
    family: &F,
    x: &[f64],
    lo: f64,
    hi: f64,
    change: usize,
) -> Result<Option<HopfPoint>, String>
where
    P: PeriodicProblem,
    F: Fn(f64) -> Result<P, HbError>,
{
    let p = 0.5 * (lo + hi);
    let mut xm = x.to_vec();
    let problem = family(p).map_err(|e| e.to_string())?;
    equilibrium(&problem, &mut xm).map_err(|e| e.to_string())?;
    let field = Field::new(&problem).map_err(|e| e.to_string())?;
    let d = 2 * xm.len();
    let eigs = eigenvalues(&field.linearisation(&xm), d);
    let Some(nearest) = eigs.iter().min_by(|l, m| l.re.abs().total_cmp(&m.re.abs())) else {
        return Err("no eigenvalues at the crossing".into());
    };
    let complex = nearest.im.abs() > REAL_AT_CROSSING * nearest.norm().max(1.0);
    match (complex, change) {
        (false, 1) => return Ok(None),
        (true, 2) => {}
        _ => {
            return Err(format!(
                "{change} eigenvalue(s) cross at once, the nearest to the axis {} ± {}i: \
                 not a simple Hopf point or fold",
                nearest.re,
                nearest.im.abs()
            ))
        }
    }
    let omega = nearest.im.abs();
    let (lyapunov, eigenvector) =
        lyapunov(&field, &xm, omega).map_err(|e| format!("a complex pair crosses, but {e}"))?;
    Ok(Some(HopfPoint {
        p,
        omega,
        lyapunov,
        equilibrium: xm,
        eigenvector,
    }))
}
