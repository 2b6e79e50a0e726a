//! Hysteretic forces in the AFT (issue 27, item 6): the Jenkins element, a
//! spring `k` in series with a Coulomb slider of slip force `F_s`, whose force
//! `F = k(δ − z)` depends on the slider position `z`, i.e. on the history of the
//! relative displacement δ, not on `(δ, δ̇)` alone.
//!
//! Along sampled δ the slider is the play operator of half-width `F_s/k`:
//! `z ← clamp(z, δ − F_s/k, δ + F_s/k)` at each sample (stick while
//! `|k(δ − z)| < F_s`, slip otherwise). A periodic orbit's samples cover one
//! period; the state at its start is that at its end. Two passes find it: the
//! first from the virgin state `z = 0` only to reach the end state, the second
//! from there. After one slip the play operator has forgotten its start, so
//! the second pass is exactly periodic; an orbit that never slips keeps the
//! virgin state (`F = kδ`, the spring alone).
//!
//! The tangent `∂F/∂δ` is the local one, `k` in stick and 0 in slip. It is
//! what Newton and Broyden need; it leaves out the dependence of a stick
//! phase's force on δ at its reversal, so the Galerkin Jacobian of a problem
//! with hysteretic elements, and the folds and Floquet multipliers computed
//! from it, are approximations (the orbits are not: they solve the residual).

/// The Jenkins force and local tangent at the samples `delta` of one period
/// (see the module docs), into `force` and `tangent` (`delta.len()` each).
pub(crate) fn jenkins_period(
    k: f64,
    slip_force: f64,
    delta: &[f64],
    force: &mut [f64],
    tangent: &mut [f64],
) {
    let half = slip_force / k;
    let mut z = 0.0;
    for &d in delta {
        z = play(z, d, half);
    }
    for ((&d, f), t) in delta.iter().zip(force.iter_mut()).zip(tangent.iter_mut()) {
        let next = play(z, d, half);
        *t = if next == z { k } else { 0.0 };
        z = next;
        *f = k * (d - z);
    }
}

/// One step of the play operator of half-width `half`: the slider `z` moves
/// only as far as it must to keep `|δ − z| ≤ half`.
fn play(z: f64, delta: f64, half: f64) -> f64 {
    z.clamp(delta - half, delta + half)
}

/// The ends of the periods in a batch of samples: a period ends where the
/// phase θ stops increasing (every caller passes whole periods in order, and
/// stacks copies one after another: differencing, several grids).
pub(crate) fn period_ranges(theta: &[f64]) -> Vec<std::ops::Range<usize>> {
    let mut ranges = Vec::new();
    let mut start = 0;
    for (i, (prev, next)) in theta.iter().zip(theta.iter().skip(1)).enumerate() {
        if next <= prev {
            ranges.push(start..i + 1);
            start = i + 1;
        }
    }
    if start < theta.len() {
        ranges.push(start..theta.len());
    }
    ranges
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_full_cycle_traces_the_elastic_perfectly_plastic_loop() {
        // δ = 2 cos τ at 8 points, k = 1, F_s = 1 (yield at δ − z = ±1).
        let delta: Vec<f64> = (0..8)
            .map(|i| 2.0 * (std::f64::consts::PI * i as f64 / 4.0).cos())
            .collect();
        let (mut f, mut t) = ([0.0; 8], [0.0; 8]);
        jenkins_period(1.0, 1.0, &delta, &mut f, &mut t);
        // τ = 0: slipping forward at F = +1 (z = 1); τ = π/4: δ = √2, stick,
        // F = √2 − 1; τ = π/2: δ = 0, just at the yield, F = −1 (still
        // stick); τ = 3π/4, π: slip back at −1; then the mirror image.
        let s2 = 2.0f64.sqrt();
        let want = [1.0, s2 - 1.0, -1.0, -1.0, -1.0, 1.0 - s2, 1.0, 1.0];
        for (got, want) in f.iter().zip(want) {
            assert!((got - want).abs() < 1e-15, "{f:?}");
        }
        assert_eq!(t, [0.0, 1.0, 1.0, 0.0, 0.0, 1.0, 1.0, 0.0]);
    }

    #[test]
    fn an_orbit_that_never_slips_is_the_spring() {
        let delta = [0.5, 0.1, -0.5, 0.2];
        let (mut f, mut t) = ([0.0; 4], [0.0; 4]);
        jenkins_period(3.0, 2.0, &delta, &mut f, &mut t);
        assert_eq!(f, [1.5, 3.0 * 0.1, -1.5, 3.0 * 0.2]);
        assert_eq!(t, [3.0; 4]);
    }

    #[test]
    fn periods_split_where_the_phase_restarts() {
        assert_eq!(
            period_ranges(&[0.0, 1.0, 2.0, 0.0, 1.0, 2.0]),
            vec![0..3, 3..6]
        );
        assert_eq!(period_ranges(&[0.5]), vec![0..1]);
        assert!(period_ranges(&[]).is_empty());
    }
}
