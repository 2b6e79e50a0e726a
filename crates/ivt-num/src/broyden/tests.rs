//! Unit tests of the Broyden solver and its workspace updates.

use super::*;
use crate::SolveError;

#[test]
fn solves_a_small_nonlinear_system_from_identity() {
    // x² + y² = 4, x − y = 0  →  x = y = √2.
    let mut f = |x: &[f64], r: &mut [f64]| {
        r[0] = x[0] * x[0] + x[1] * x[1] - 4.0;
        r[1] = x[0] - x[1];
    };
    let mut ws = BroydenWorkspace::new(2);
    ws.set_jacobian(&[2.0, 2.0, 1.0, -1.0]).unwrap();
    let mut x = [1.0, 1.0];
    let stats = broyden_solve(&mut f, &mut x, &mut ws, &BroydenOptions::default()).unwrap();
    assert!((x[0] - 2f64.sqrt()).abs() < 1e-10 && (x[1] - 2f64.sqrt()).abs() < 1e-10);
    assert!(stats.residual_norm <= 1e-10);
}

#[test]
fn finite_difference_start_and_exact_row_is_kept() {
    // Rosenbrock-like: r0 = 10(y − x²), r1 = 1 − x; the second row is linear.
    let mut f = |x: &[f64], r: &mut [f64]| {
        r[0] = 10.0 * (x[1] - x[0] * x[0]);
        r[1] = 1.0 - x[0];
    };
    let mut ws = BroydenWorkspace::new(2);
    ws.exact_rows = 1..2;
    let mut x = [-1.2, 1.0];
    broyden_solve(&mut f, &mut x, &mut ws, &BroydenOptions::default()).unwrap();
    assert!((x[0] - 1.0).abs() < 1e-9 && (x[1] - 1.0).abs() < 1e-9);
    // Exact row −1, 0 survives all updates bit-for-bit after the FD start.
    let b = ws.jacobian();
    assert!((b[2] + 1.0).abs() < 1e-6 && b[3].abs() < 1e-6);
}

/// A 6-unknown cubic system with a known root (x = 1): diagonally dominant
/// linear part plus cubic coupling, solved from an identity-scaled start so
/// that Broyden needs several updates and some damped steps.
fn cubic_system(x: &[f64], r: &mut [f64]) {
    let n = x.len();
    for i in 0..n {
        let lin = 4.0 * x[i] - x[(i + 1) % n] - x[(i + n - 1) % n];
        let cub = 0.5 * (x[i] * x[i] * x[i] - 1.0) + 0.2 * (x[i] * x[(i + 1) % n] - 1.0);
        r[i] = lin - 2.0 + cub;
    }
}

#[test]
fn untracked_mode_matches_tracked_and_rebuilds_b_on_demand() {
    // The untracked update uses B s = −t r instead of the product with B; in exact
    // arithmetic both modes take identical steps, so the iterates, the step
    // count and the final B agree to rounding (tolerances: 1e-12 on x at a
    // 1e-13 residual, 1e-8 relative on B after a dozen rank-one updates).
    let solve = |track: bool| {
        let mut ws = BroydenWorkspace::new(6);
        ws.track_jacobian = track;
        let b0: Vec<f64> = (0..36)
            .map(|k| if k % 7 == 0 { 5.0 } else { 0.0 })
            .collect();
        ws.set_jacobian(&b0).unwrap();
        // x − 1 = 3·(1, −1, ½, 1, −0.7, 0.3): far enough for damped steps.
        let mut x = [4.0, -2.0, 2.5, 4.0, -1.1, 1.9];
        let opts = BroydenOptions::default().with_tol(1e-13);
        let stats = broyden_solve(&mut cubic_system, &mut x, &mut ws, &opts).unwrap();
        (x, stats, ws.jacobian().to_vec())
    };
    let (x_t, st_t, b_t) = solve(true);
    let (x_u, st_u, b_u) = solve(false);
    // Several updates, and at least one damped (t < 1) step among them.
    assert!(
        st_t.iterations >= 6,
        "too easy to test the update: {st_t:?}"
    );
    assert!(
        st_t.residual_evals > st_t.iterations + 1,
        "no damped step: {st_t:?}"
    );
    assert_eq!(st_t.iterations, st_u.iterations);
    assert_eq!(st_t.jacobian_refreshes, 0);
    for (a, b) in x_t.iter().zip(&x_u) {
        assert!(
            (a - 1.0).abs() < 1e-12 && (b - 1.0).abs() < 1e-12,
            "{x_t:?} {x_u:?}"
        );
    }
    let scale = b_t.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    for (a, b) in b_t.iter().zip(&b_u) {
        assert!((a - b).abs() <= 1e-8 * scale, "B differs: {a} vs {b}");
    }
}

#[test]
fn untracked_mode_keeps_the_tracked_column_and_exact_rows_of_b() {
    // The continuation corrector's set-up: the last row exact (a linear
    // equation), B not tracked except its last column. After a dozen
    // untracked updates and a row and a column replacement, the entries read
    // without rebuilding B (`jacobian_entry`) equal those of H⁻¹ (rebuilt by
    // inversion) to 1e-9 relative, and the exact row is the one set.
    let m = 6;
    let mut f = |x: &[f64], r: &mut [f64]| {
        cubic_system(&x[..m - 1], &mut r[..m - 1]);
        r[m - 1] = x.iter().sum::<f64>() - m as f64;
    };
    let mut ws = BroydenWorkspace::new(m);
    ws.track_jacobian = false;
    ws.exact_rows = m - 1..m;
    ws.tracked_column = Some(m - 1);
    let b0: Vec<f64> = (0..m * m)
        .map(|k| match (k / m, k % m) {
            (i, _) if i == m - 1 => 1.0,
            (i, j) if i == j => 5.0,
            _ => 0.0,
        })
        .collect();
    ws.set_jacobian(&b0).unwrap();
    let mut x = [4.0, -2.0, 2.5, 4.0, -1.1, 0.0];
    let opts = BroydenOptions::default().with_tol(1e-13);
    let stats = broyden_solve(&mut f, &mut x, &mut ws, &opts).unwrap();
    assert!(stats.iterations >= 6, "too easy: {stats:?}");
    let col: Vec<f64> = (0..m).map(|i| 0.5 + i as f64).collect();
    let row: Vec<f64> = (0..m).map(|j| 1.0 + 0.1 * j as f64).collect();
    ws.replace_col(m - 1, &col).unwrap();
    ws.replace_row(m - 1, &row).unwrap();
    let mut known: Vec<f64> = (0..m)
        .map(|i| ws.jacobian_entry(i, m - 1).unwrap())
        .collect();
    known.extend((0..m).map(|j| ws.jacobian_entry(m - 1, j).unwrap()));
    assert_eq!(&known[m..], &row[..]);
    let b = ws.jacobian().to_vec();
    let scale = b.iter().fold(0.0f64, |s, v| s.max(v.abs()));
    let rebuilt = (0..m)
        .map(|i| b[i * m + m - 1])
        .chain((0..m).map(|j| b[(m - 1) * m + j]));
    for (k, (a, w)) in known.iter().zip(rebuilt).enumerate() {
        assert!((a - w).abs() <= 1e-9 * scale, "entry {k}: {a} vs {w}");
    }
    assert_eq!(ws.jacobian_entry(m, 0), None);
}

#[test]
fn non_convergence_carries_history() {
    // x² + 1 = 0 has no real root.
    let mut f = |x: &[f64], r: &mut [f64]| r[0] = x[0] * x[0] + 1.0;
    let mut ws = BroydenWorkspace::new(1);
    let mut x = [0.3];
    let err = broyden_solve(
        &mut f,
        &mut x,
        &mut ws,
        &BroydenOptions::default().with_max_iter(30),
    )
    .unwrap_err();
    assert!(!err.history().is_empty(), "{err}");
}

#[test]
fn nan_input_is_an_error() {
    let mut f = |x: &[f64], r: &mut [f64]| r[0] = x[0];
    let mut ws = BroydenWorkspace::new(1);
    let mut x = [f64::NAN];
    assert!(matches!(
        broyden_solve(&mut f, &mut x, &mut ws, &BroydenOptions::default()),
        Err(SolveError::NonFinite { .. })
    ));
}

/// `B·H` for row-major `m×m` matrices, by the textbook triple loop.
fn product(b: &[f64], h: &[f64], m: usize) -> Vec<f64> {
    let mut p = vec![0.0; m * m];
    for i in 0..m {
        for j in 0..m {
            p[i * m + j] = (0..m).map(|k| b[i * m + k] * h[k * m + j]).sum();
        }
    }
    p
}

#[test]
fn replaced_row_and_column_keep_h_the_inverse_of_b() {
    // Sherman–Morrison after each replacement against (a) B'·H' = I and (b) a
    // fresh LU inversion of the same B'. B₀ is diagonally dominant (cond ≈ 3),
    // so both hold to a few ε: 1e-13.
    let m = 4;
    let b0: Vec<f64> = (0..m * m)
        .map(|k| {
            if k % (m + 1) == 0 {
                6.0
            } else {
                (k % 3) as f64 - 1.0
            }
        })
        .collect();
    let mut ws = BroydenWorkspace::new(m);
    ws.set_jacobian(&b0).unwrap();
    ws.replace_col(1, &[0.5, 7.0, -1.0, 2.0]).unwrap();
    ws.replace_row(3, &[1.0, -2.0, 0.25, 5.0]).unwrap();
    let b = ws.jacobian().to_vec();
    assert_eq!(
        &b[4..8],
        &[b0[4], 7.0, b0[6], b0[7]],
        "column 1 entry of row 1"
    );
    assert_eq!(&b[12..16], &[1.0, -2.0, 0.25, 5.0], "row 3");
    assert_eq!(b[1], 0.5);
    let h = ws.inverse_jacobian().to_vec();
    for (k, p) in product(&b, &h, m).iter().enumerate() {
        let eye = if k % (m + 1) == 0 { 1.0 } else { 0.0 };
        assert!((p - eye).abs() < 1e-13, "B·H at {k}: {p}");
    }
    let mut fresh = BroydenWorkspace::new(m);
    fresh.set_jacobian(&b).unwrap();
    for (a, e) in h.iter().zip(fresh.inverse_jacobian()) {
        assert!((a - e).abs() < 1e-13, "{a} vs {e}");
    }
}

#[test]
fn a_row_or_column_outside_the_workspace_is_a_dimension_error() {
    let mut ws = BroydenWorkspace::new(3);
    ws.set_jacobian(&[2.0, 0.0, 0.0, 0.0, 2.0, 0.0, 0.0, 0.0, 2.0])
        .unwrap();
    let dim = |expected, got| Err(SolveError::Dimension { expected, got });
    // Index 3 would need 4 unknowns; a row of 2 entries is 2 unknowns.
    assert_eq!(ws.replace_row(3, &[1.0; 3]), dim(3, 4));
    assert_eq!(ws.replace_col(usize::MAX, &[1.0; 3]), dim(3, usize::MAX));
    assert_eq!(ws.replace_row(0, &[1.0; 2]), dim(3, 2));
    assert_eq!(ws.replace_col(0, &[1.0; 4]), dim(3, 4));
    // Refused calls leave B and H as they were.
    assert_eq!(
        ws.jacobian(),
        &[2.0, 0.0, 0.0, 0.0, 2.0, 0.0, 0.0, 0.0, 2.0]
    );
    assert_eq!(ws.inverse_jacobian()[4], 0.5);
    // A zero-size workspace has no row 0 and solves its empty system at once.
    let mut empty = BroydenWorkspace::new(0);
    assert_eq!(empty.replace_row(0, &[]), dim(0, 1));
    assert_eq!(empty.replace_col(0, &[]), dim(0, 1));
    let mut none = |_: &[f64], _: &mut [f64]| {};
    let stats = broyden_solve(&mut none, &mut [], &mut empty, &BroydenOptions::default());
    assert_eq!(stats.map(|s| s.iterations), Ok(0));
}
