//! Limit cycles from a state (issue 27, item 4): Van der Pol
//! `ẍ − μ(1 − x²)ẋ + x = 0` and Rayleigh `ẍ − μ(ẋ − ẋ³/3) + x = 0` from the
//! default start (1, 0) and from other states, their periods against shooting
//! on an RK4 integration that shares no code with the transient or HB.
#![allow(clippy::expect_used, clippy::indexing_slicing)]

use ivt_hb::problem::ode::rk4;
use ivt_hb::Oscillator;
use ivt_hb::{
    limit_cycle_from_state, settle, GeneralProblem, HbError, HbOptions, PeriodicProblem,
    TransientOptions,
};

mod common;
use common::assert_period;
use common::shooting::newton_plane;

/// `ẍ = accel(x, ẋ)` of each oscillator.
fn accel(rayleigh: bool, mu: f64) -> impl Fn(f64, f64) -> f64 + Copy {
    move |x: f64, v: f64| {
        if rayleigh {
            mu * (v - v * v * v / 3.0) - x
        } else {
            mu * (1.0 - x * x) * v - x
        }
    }
}

/// The oscillator as a problem: C = −μ, K = 1 and the rest in g.
fn problem(rayleigh: bool, mu: f64) -> impl PeriodicProblem {
    let model = if rayleigh {
        Oscillator::Rayleigh
    } else {
        Oscillator::VanDerPol
    };
    model.problem(mu)
}

/// RK4 flow of `ẍ = a(x, ẋ)` over `t` in `steps` steps.
fn flow(a: impl Fn(f64, f64) -> f64 + Copy, y: [f64; 2], t: f64, steps: usize) -> [f64; 2] {
    let mut y = y;
    rk4(
        |_t, y: &[f64], dy: &mut [f64]| {
            dy[0] = y[1];
            dy[1] = a(y[0], y[1]);
        },
        0.0,
        &mut y,
        t / steps as f64,
        steps,
    );
    y
}

/// Period by shooting on the section ẋ = 0 (unknowns x₀, T; Newton with central
/// differences), started from a crude RK4 transient: 60 time units from (2, 0)
/// at dt = 1e-3, then the spacing of the last two maxima of x.
fn shooting_period(a: impl Fn(f64, f64) -> f64 + Copy, steps: usize) -> f64 {
    let dt = 1e-3;
    let mut y = flow(a, [2.0, 0.0], 60.0, 60_000);
    let mut maxima = Vec::new();
    for i in 0..40_000 {
        let next = flow(a, y, dt, 1);
        if y[1] > 0.0 && next[1] <= 0.0 {
            maxima.push((i as f64 * dt, next[0]));
        }
        y = next;
    }
    let (t1, x1) = maxima[maxima.len() - 1];
    let (t0, _) = maxima[maxima.len() - 2];
    let residual = |u: [f64; 2]| {
        let y = flow(a, [u[0], 0.0], u[1], steps);
        [y[0] - u[0], y[1]]
    };
    let h = |u: [f64; 2]| u.map(|v| 1e-6 * v.abs().max(1.0));
    newton_plane(residual, [x1, t1 - t0], h, [1e-13, 1e-12]).expect("shooting converges")[1]
}

#[test]
fn van_der_pol_and_rayleigh_from_the_default_and_other_states_match_shooting() {
    // (Rayleigh?, μ, harmonics, RK4 steps per period of the reference).
    let cases = [
        (false, 0.2, 15, 20_000),
        (false, 1.0, 30, 20_000),
        (false, 5.0, 120, 80_000),
        (true, 2.0, 60, 40_000),
        (true, 5.0, 120, 80_000),
    ];
    for (rayleigh, mu, n, steps) in cases {
        let a = accel(rayleigh, mu);
        let (t_ref, t_fine) = (shooting_period(a, steps), shooting_period(a, 2 * steps));
        // RK4 error ∝ h⁴: halving the step changes the period by 15/16 of the
        // coarse error, so the fine one is exact to below the 1e-8 asserted.
        assert!(
            (t_ref - t_fine).abs() < 1e-10 * t_fine,
            "reference {t_ref} vs {t_fine}"
        );
        let p = problem(rayleigh, mu);
        let hb = HbOptions::new(n, 4 * n);
        // The default start (1, 0), one inside and one outside the cycle.
        for state in [[1.0, 0.0], [0.05, 0.0], [3.0, -2.0]] {
            let lc = limit_cycle_from_state(&p, &hb, &state, &TransientOptions::default(), 1024)
                .unwrap_or_else(|e| panic!("μ = {mu}, rayleigh {rayleigh}, {state:?}: {e}"));
            assert_period(
                &lc,
                t_fine,
                &format!("rayleigh {rayleigh} μ = {mu} from {state:?}"),
            );
            assert!(lc.stable(), "{:?}", lc.multipliers);
        }
    }
}

#[test]
fn a_start_in_the_basin_of_the_equilibrium_is_named() {
    // μ < 0: the origin is a stable focus and there is no cycle near it.
    let p = problem(false, -0.5);
    let err = settle(&p, &[0.5, 0.0], &TransientOptions::default()).unwrap_err();
    assert_eq!(err, HbError::Equilibrium);
}

#[test]
fn bad_states_and_forced_problems_are_invalid_input() {
    let p = problem(false, 1.0);
    let opts = TransientOptions::default();
    for state in [&[0.0, 0.0][..], &[1.0][..], &[f64::NAN, 0.0][..]] {
        assert!(matches!(
            settle(&p, state, &opts),
            Err(HbError::InvalidInput(_))
        ));
    }
    let forced = GeneralProblem::new(
        1,
        vec![1.0],
        vec![0.1],
        vec![1.0],
        |_x: &[f64], _v: &[f64], _th: f64, out: &mut [f64]| out[0] = 0.0,
        |th: f64, out: &mut [f64]| out[0] = th.cos(),
    );
    assert!(matches!(
        settle(&forced, &[1.0, 0.0], &opts),
        Err(HbError::InvalidInput(_))
    ));
}

/// The defaults docs/guide/src/model/limit-cycles.md states: tolerance 1e-10, settled at 1e-6, up to 8 crossings
/// per period.
#[test]
fn defaults_are_the_readme_values() {
    let o = TransientOptions::default();
    assert_eq!((o.tol, o.settle, o.max_returns), (1e-10, 1e-6, 8));
}
