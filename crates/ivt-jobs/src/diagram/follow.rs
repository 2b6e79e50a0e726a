//! Following one branch of the diagram within the interval, and the
//! small helpers of its points: the distance to a path segment, the
//! point record, the sign of a direction.

use super::*;

/// The distance from `x` to the segment `[a, b]`.
pub(super) fn segment_distance(x: &[f64], a: &[f64], b: &[f64]) -> f64 {
    let ab: Vec<f64> = b.iter().zip(a).map(|(p, q)| p - q).collect();
    let ax: Vec<f64> = x.iter().zip(a).map(|(p, q)| p - q).collect();
    let len2: f64 = ab.iter().map(|v| v * v).sum();
    let t = if len2 > 0.0 {
        (ax.iter().zip(&ab).map(|(p, q)| p * q).sum::<f64>() / len2).clamp(0.0, 1.0)
    } else {
        0.0
    };
    ax.iter()
        .zip(&ab)
        .map(|(p, q)| (p - t * q).powi(2))
        .sum::<f64>()
        .sqrt()
}

/// The point of a periodic branch.
pub(super) fn periodic_point(p: &FrcPoint, at: bool) -> DiagramPoint {
    DiagramPoint {
        omega: p.omega_f,
        amplitude: p.amplitude,
        coeffs: Array(p.coeffs.clone()),
        stable: Some(p.stable()),
        stability: Some(p.kind),
        multipliers: Some(pairs(&p.multipliers)),
        rotation_number: None,
        at,
    }
}

/// `+1` or `−1` by the sign of `d` (`+1` for 0).
pub(super) fn sign(d: f64) -> f64 {
    if d < 0.0 {
        -1.0
    } else {
        1.0
    }
}

/// Follows `branch` from `x0` (`[q, λ]`) in the direction of `direction`
/// within the bounds of `copts`, with multipliers and events
/// ([`EventObserver`] on the one stepper); with `close`, stops where the
/// path returns to its start after leaving it (termination `stopped`).
pub(super) fn trace_within<F: Family>(
    branch: &mut FamilyBranch<F>,
    x0: &[f64],
    direction: f64,
    copts: &ContinuationOptions,
    close: bool,
) -> Result<Trace, HbError> {
    let lambda0 = x0.last().copied().unwrap_or(f64::NAN);
    let locate = LocateOptions::default();
    let mut observer = observer(
        branch,
        lambda0,
        HsuSteps::default(),
        &locate,
        every_event(&locate),
    )?;
    let mut stepper = branch.stepper(x0, 0, direction, copts)?;
    let tol = 0.5 * copts.ds;
    let (mut prev, mut far, mut closed): (Option<Vec<f64>>, bool, bool) = (None, false, false);
    let (path, events) = observe(&mut stepper, &mut observer, |_, p: &PathPoint| {
        if close {
            if let Some(a) = &prev {
                closed = far && segment_distance(x0, a, &p.x) < tol;
            }
            let gone =
                p.x.iter()
                    .zip(x0)
                    .map(|(a, b)| (a - b).powi(2))
                    .sum::<f64>()
                    .sqrt();
            far = far || gone > 4.0 * tol;
            prev = Some(p.x.clone());
        }
        !closed
    })
    .map_err(trace_error)?;
    Ok(Trace {
        points: observer.into_points(),
        events,
        termination: if closed {
            Termination::Stopped
        } else {
            path.termination
        },
    })
}
