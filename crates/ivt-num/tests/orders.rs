//! Convergence orders of the tableaux through the one stepper, on problems
//! with closed-form solutions.
// Test code: the crate's panic lints guard shipped code only.
#![allow(clippy::indexing_slicing, clippy::unwrap_used)]

use ivt_num::rk::step_factor;
use ivt_num::{ExplicitRk, Tolerance, DP5, RK4, RK6};

/// The harmonic oscillator and y' = −2xy² (y = 1/(1 + x²)): smooth and
/// nonlinear, with solution `[sin x, cos x, 1/(1 + x²)]` from `exact(0)`.
fn smooth(x: f64, y: &[f64], dy: &mut [f64]) {
    dy[0] = y[1];
    dy[1] = -y[0];
    dy[2] = -2.0 * x * y[2] * y[2];
}

fn exact(x: f64) -> [f64; 3] {
    [x.sin(), x.cos(), 1.0 / (1.0 + x * x)]
}

fn max_err(a: &[f64], b: &[f64]) -> f64 {
    a.iter()
        .zip(b)
        .map(|(p, q)| (p - q).abs())
        .fold(0.0, f64::max)
}

/// Least-squares slope of log(err) against log(h).
fn slope(errs: &[(f64, f64)]) -> f64 {
    let n = errs.len() as f64;
    let (mut sx, mut sy, mut sxx, mut sxy) = (0.0, 0.0, 0.0, 0.0);
    for &(h, e) in errs {
        let (lx, ly) = (h.ln(), e.ln());
        sx += lx;
        sy += ly;
        sxx += lx * lx;
        sxy += lx * ly;
    }
    (n * sxy - sx * sy) / (n * sxx - sx * sx)
}

/// Global error of fixed-step RK4 on [0, 2] scales as h⁴: the fitted
/// log–log slope over h = 2/10 … 2/160 is 4 ± 0.15.
#[test]
fn rk4_is_fourth_order() {
    let mut rk = ExplicitRk::<4, [f64; 3]>::new(&RK4);
    let mut errs = vec![];
    for n in [10usize, 20, 40, 80, 160] {
        let mut y = exact(0.0);
        rk.integrate(&mut smooth, 0.0, 2.0, n, &mut y);
        errs.push((2.0 / n as f64, max_err(&y, &exact(2.0))));
    }
    let p = slope(&errs);
    assert!((p - 4.0).abs() < 0.15, "RK4 order {p}, {errs:?}");
}

/// y' = cos(x) y, y(0) = 1 → y = exp(sin x). Halving h must cut the error
/// of RK6 by ≈ 2⁶ = 64 (order 6); we accept a ratio above 50, since the
/// asymptotic constant is reached only approximately at these step sizes.
#[test]
fn rk6_is_sixth_order() {
    let mut rk = ExplicitRk::with_dim(&RK6, 1);
    let exact = 3.0f64.sin().exp();
    let mut err = |n: usize| {
        let mut y = [1.0];
        let mut rhs = |x: f64, y: &[f64], dy: &mut [f64]| dy[0] = x.cos() * y[0];
        rk.integrate(&mut rhs, 0.0, 3.0, n, &mut y);
        (y[0] - exact).abs()
    };
    let (e1, e2) = (err(10), err(20));
    assert!(e1 / e2 > 50.0, "ratio {}", e1 / e2);
}

/// Fixed-step DP5 (the 5th-order solution): the error ratio between
/// h = 2/64 and 2/128 gives an observed order 5 ± 0.2 (coarser pairs are
/// pre-asymptotic: 6.0, 5.6, 5.4), and its dense output is at least
/// 4th-order accurate (slope ≥ 3.8).
#[test]
fn dp5_is_fifth_order_and_dense_output_converges() {
    let tol = Tolerance {
        rtol: 1.0,
        atol: 1.0,
    };
    let mut rk = ExplicitRk::<7, [f64; 3]>::new(&DP5);
    let (mut errs, mut dense_errs) = (vec![], vec![]);
    for n in [16usize, 32, 64, 128] {
        let h = 2.0 / n as f64;
        let mut y = exact(0.0);
        let mut worst_dense: f64 = 0.0;
        for k in 0..n {
            let x = k as f64 * h;
            let mut y1 = [0.0; 3];
            rk.try_step(&mut smooth, x, &y, None, h, &tol, &mut y1);
            let mut mid = [0.0; 3];
            rk.dense(&y, &y1, h, 0.37, &mut mid);
            // Local dense error: compare increments, removing the incoming global error.
            let (e0, em) = (exact(x), exact(x + 0.37 * h));
            let exact_mid: Vec<f64> = (0..3).map(|i| em[i] - e0[i] + y[i]).collect();
            worst_dense = worst_dense.max(max_err(&mid, &exact_mid));
            y = y1;
        }
        errs.push((h, max_err(&y, &exact(2.0))));
        dense_errs.push((h, worst_dense));
    }
    let p = slope(&errs[2..]);
    assert!((p - 5.0).abs() < 0.2, "DP5 order {p}, {errs:?}");
    let pd = slope(&dense_errs);
    assert!(pd > 3.8, "dense output order {pd}, {dense_errs:?}");
}

/// Adaptive DP5 on [0, 2] with the controller and the initial step guess:
/// at rtol = atol = 1e-10 the error at x = 2 is below 1e-8 (the global error
/// of an RMS-controlled method is a small multiple of the tolerance times the
/// number of steps), and the FSAL stage equals F at the accepted state.
#[test]
fn adaptive_dp5_meets_tolerance() {
    let tol = Tolerance {
        rtol: 1e-10,
        atol: 1e-10,
    };
    let mut rk = ExplicitRk::<7, [f64; 3]>::new(&DP5);
    let (mut x, mut y) = (0.0, exact(0.0));
    let mut k1 = [0.0; 3];
    smooth(x, &y, &mut k1);
    let mut h = rk.initial_step(&mut smooth, x, &y, &k1, &tol);
    let mut steps = 0;
    while x < 2.0 {
        let hs = h.min(2.0 - x);
        let mut y1 = [0.0; 3];
        let err = rk.try_step(&mut smooth, x, &y, Some(&k1), hs, &tol, &mut y1);
        h = hs * step_factor(err, DP5.order);
        if err <= 1.0 {
            x += hs;
            y = y1;
            k1.copy_from_slice(rk.last_stage());
            steps += 1;
        }
    }
    let mut f = [0.0; 3];
    smooth(x, &y, &mut f);
    assert_eq!(f, k1);
    let e = max_err(&y, &exact(2.0));
    assert!(e < 1e-8 && steps > 10, "error {e:e} after {steps} steps");
}
