//! The Broyden driver: quasi-Newton steps (Eq. 66) with a backtracking line search
//! on ‖F‖, and the policy that refreshes the Jacobian when the line search fails or
//! the iteration stalls. The linear algebra lives in [`BroydenWorkspace`].

use super::{BroydenOptions, BroydenStats, BroydenWorkspace, SolveError, System};

/// Solves `F(x) = 0` by Broyden's method from the initial guess `x` (overwritten
/// by the solution), starting from the Jacobian held in `ws` (set with
/// [`BroydenWorkspace::set_jacobian`] or left from a previous solve; refreshed if
/// none).
///
/// # Errors
/// [`SolveError`] with the residual history when the tolerance is not reached,
/// the residual is not finite, or the Jacobian is singular;
/// [`SolveError::Dimension`] if `x` and `ws` differ in size.
pub fn broyden_solve<S: System + ?Sized>(
    sys: &mut S,
    x: &mut [f64],
    ws: &mut BroydenWorkspace,
    opts: &BroydenOptions,
) -> Result<BroydenStats, SolveError> {
    if x.len() != ws.len() {
        return Err(SolveError::Dimension {
            expected: ws.len(),
            got: x.len(),
        });
    }
    ws.begin();
    if !x.iter().all(|v| v.is_finite()) {
        return Err(SolveError::NonFinite {
            iteration: 0,
            history: Vec::new(),
        });
    }
    let mut stats = BroydenStats {
        iterations: 0,
        residual_evals: 1,
        jacobian_refreshes: 0,
        residual_norm: 0.0,
    };
    let mut norm = ws.evaluate(sys, x);
    ws.record(norm);
    if !norm.is_finite() {
        return Err(SolveError::NonFinite {
            iteration: 0,
            history: ws.history().to_vec(),
        });
    }
    if !ws.has_jacobian() {
        ws.refresh_inverse(sys, x, opts.fd_step, &mut stats)?;
    }
    let mut stalled = 0usize;
    while norm > opts.tol {
        if stats.iterations >= opts.max_iter {
            return Err(SolveError::NonConvergence {
                iterations: stats.iterations,
                history: ws.history().to_vec(),
            });
        }
        stats.iterations += 1;
        ws.direction();
        // Backtracking line search on ‖F‖.
        let mut t = 1.0;
        let mut accepted = false;
        let mut trial_norm = f64::INFINITY;
        for _ in 0..=opts.max_backtracks {
            trial_norm = ws.trial(sys, x, t);
            stats.residual_evals += 1;
            if trial_norm.is_finite() && trial_norm < norm {
                accepted = true;
                break;
            }
            t *= 0.5;
        }
        let can_refresh = opts.jacobian_refresh && stats.jacobian_refreshes < opts.max_refreshes;
        if !accepted {
            if !can_refresh {
                return Err(SolveError::NonConvergence {
                    iterations: stats.iterations,
                    history: ws.history().to_vec(),
                });
            }
            stalled = 0;
            ws.refresh_inverse(sys, x, opts.fd_step, &mut stats)?;
            continue;
        }
        let updated = ws.accept(t, x);
        let ratio = trial_norm / norm;
        norm = trial_norm;
        ws.record(norm);
        stalled = if ratio > opts.stall_ratio {
            stalled + 1
        } else {
            0
        };
        if (!updated || stalled >= opts.stall_iters) && norm > opts.tol {
            if !can_refresh {
                if !updated {
                    return Err(SolveError::SingularJacobian {
                        iteration: stats.iterations,
                        history: ws.history().to_vec(),
                    });
                }
                continue;
            }
            stalled = 0;
            ws.refresh_inverse(sys, x, opts.fd_step, &mut stats)?;
        }
    }
    stats.residual_norm = norm;
    Ok(stats)
}
