//! STHB core checks: linear limit (Eq. 115), exact Jacobian against finite
//! differences (Eq. 119–125), Newton convergence.
#![allow(clippy::indexing_slicing, clippy::unwrap_used)]

use faer::Mat;
use ivt_sthb::{Boundary, StringHb, StringParams};
use std::f64::consts::PI;

/// Deterministic pseudo-random coefficients (xorshift) decaying with harmonic.
fn guess(hb: &StringHb, amp: f64, seed: u64) -> Vec<f64> {
    let mut s = seed;
    let mut a = vec![0.0; hb.dim()];
    for (i, v) in a.iter_mut().enumerate() {
        s ^= s << 13;
        s ^= s >> 7;
        s ^= s << 17;
        let u = (s % 10_000) as f64 / 10_000.0 - 0.5;
        let h = i / hb.coords();
        *v = amp * u / (1.0 + h as f64);
    }
    a
}

#[test]
fn linear_limit_equals_closed_form() {
    // k_d = 0: a = J_lin⁻¹ f̂ (Eq. 115). Only mode 1, harmonic 1 is excited:
    // (π² − ω²) c + ω c_d s = y0, −ω c_d c + (π² − ω²) s = 0.
    for omega in [0.7, 2.0, PI, 4.5] {
        let p = StringParams {
            kd: 0.0,
            ..Default::default()
        };
        let mut hb = StringHb::new(p.clone()).unwrap();
        let mut a = vec![0.0; hb.dim()];
        hb.solve(omega, &mut a, 1e-14, 5).unwrap();
        let lam = PI * PI - omega * omega;
        let wc = omega * p.cd;
        let den = lam * lam + wc * wc;
        let (c, s) = (lam * p.y0 / den, wc * p.y0 / den);
        for (i, v) in a.iter().enumerate() {
            let exact = if i == hb.index(1, 0) {
                c
            } else if i == hb.index(2, 0) {
                s
            } else {
                0.0
            };
            assert!(
                (v - exact).abs() <= 1e-12,
                "omega {omega} index {i}: {v} vs {exact}"
            );
        }
    }
}

/// The string with Duffing coefficient `kd`, `modes` modes, `harmonics` harmonics,
/// `ns` spatial and `ms` time samples; other parameters default.
fn sized(kd: f64, modes: usize, harmonics: usize, ns: usize, ms: usize) -> StringParams {
    StringParams {
        kd,
        modes,
        harmonics,
        ns,
        ms,
        ..Default::default()
    }
}

fn check_fd(p: StringParams, amp: f64, omega: f64) {
    let mut hb = StringHb::new(p).unwrap();
    let n = hb.dim();
    let a = guess(&hb, amp, 0x9E37_79B9_7F4A_7C15);
    let mut r0 = vec![0.0; n];
    let mut jac = Mat::zeros(n, n);
    hb.residual_jacobian(&a, omega, &mut r0, &mut jac);
    // Central differences: truncation O(h²·|R'''|) plus rounding O(ε|R|/h).
    let h = 1e-6;
    let (mut rp, mut rm) = (vec![0.0; n], vec![0.0; n]);
    let mut ap = a.clone();
    let mut max_err: f64 = 0.0;
    let mut max_ref: f64 = 0.0;
    for j in 0..n {
        ap[j] = a[j] + h;
        hb.residual(&ap, omega, &mut rp);
        ap[j] = a[j] - h;
        hb.residual(&ap, omega, &mut rm);
        ap[j] = a[j];
        for i in 0..n {
            let fd = (rp[i] - rm[i]) / (2.0 * h);
            max_err = max_err.max((fd - jac[(i, j)]).abs());
            max_ref = max_ref.max(jac[(i, j)].abs());
        }
    }
    // Residual entries are O(κ_N |a|) ~ 1e2; rounding in FD ≈ 1e-16·1e2/1e-6 = 1e-8 relative to max entry.
    assert!(
        max_err <= 1e-7 * max_ref,
        "FD mismatch {max_err:e} (max entry {max_ref:e})"
    );
    // dR/dω by central differences too.
    let mut dro = vec![0.0; n];
    hb.d_residual_d_omega(&a, omega, &mut dro);
    hb.residual(&a, omega + h, &mut rp);
    hb.residual(&a, omega - h, &mut rm);
    for i in 0..n {
        let fd = (rp[i] - rm[i]) / (2.0 * h);
        assert!(
            (fd - dro[i]).abs() <= 1e-6 * (1.0 + dro[i].abs()),
            "dR/domega row {i}"
        );
    }
}

#[test]
fn jacobian_matches_finite_differences_fixed() {
    check_fd(sized(30.0, 4, 5, 32, 32), 0.3, 2.7);
}

#[test]
fn jacobian_matches_finite_differences_aliased() {
    // M_s = 24 < 4M + 1: products alias in time; the Jacobian stays exact for the sampled residual.
    check_fd(sized(10.0, 3, 7, 16, 24), 0.3, 3.3);
}

#[test]
fn jacobian_matches_finite_differences_spring() {
    let p = StringParams {
        boundary: Boundary::Spring { k0: 10.0 },
        ..sized(10.0, 4, 4, 32, 32)
    };
    check_fd(p, 0.3, 2.1);
}

#[test]
fn newton_converges_quadratically() {
    let mut hb = StringHb::new(StringParams::default()).unwrap();
    let mut a = vec![0.0; hb.dim()];
    let stats = hb.solve(3.5, &mut a, 1e-12, 30).unwrap();
    // From a = 0 next to the peak: a damped phase (step halving), then the
    // quadratic tail of the exact Jacobian, r_{k+1} ≤ C r_k² with C ~ 1
    // (measured: 5.2e-3, 2.8e-5, 3.2e-10, 3.6e-16 in 13 iterations).
    let h = &stats.history;
    assert!(stats.iterations <= 15, "{h:?}");
    let k = h.len();
    assert!(h[k - 1] < 1e-11, "{h:?}");
    // (the last step sits at the rounding floor, so check the two before it)
    for i in k - 4..k - 2 {
        assert!(
            h[i + 1] <= 10.0 * h[i] * h[i],
            "not quadratic at {i}: {h:?}"
        );
    }
}

#[test]
fn direct_spatial_sums_equal_rustdct() {
    for boundary in [Boundary::Fixed, Boundary::Spring { k0: 7.0 }] {
        let p = StringParams {
            kd: 30.0,
            modes: 6,
            harmonics: 5,
            boundary,
            ..Default::default()
        };
        let mut fast = StringHb::with_spatial(p.clone(), Some(false)).unwrap();
        let mut direct = StringHb::with_spatial(p, Some(true)).unwrap();
        let n = fast.dim();
        let a = guess(&fast, 0.3, 7);
        let (mut r1, mut r2) = (vec![0.0; n], vec![0.0; n]);
        let (mut j1, mut j2) = (Mat::zeros(n, n), Mat::zeros(n, n));
        fast.residual_jacobian(&a, 2.5, &mut r1, &mut j1);
        direct.residual_jacobian(&a, 2.5, &mut r2, &mut j2);
        // Same sums in a different order: rounding only (entries up to ~1e3).
        for i in 0..n {
            assert!((r1[i] - r2[i]).abs() < 1e-10, "residual {i}");
            for j in 0..n {
                assert!((j1[(i, j)] - j2[(i, j)]).abs() < 1e-9, "jacobian {i},{j}");
            }
        }
    }
}

/// `σ_min / σ_max` of the exact Jacobian at `(a, ω)`.
fn jacobian_conditioning(hb: &mut StringHb, a: &[f64], omega: f64) -> f64 {
    let n = hb.dim();
    let mut r = vec![0.0; n];
    let mut jac = Mat::zeros(n, n);
    hb.residual_jacobian(a, omega, &mut r, &mut jac);
    let s = jac.singular_values().unwrap();
    s.iter().copied().fold(f64::INFINITY, f64::min) / s.iter().copied().fold(0.0, f64::max)
}

#[test]
fn kd30_folds_are_located_by_the_bordered_system() {
    // Fig. 35 (k_d = 30): both turns of the curve are located by Newton on the
    // bordered fold system. At a fold (simple turning point) `J = ∂R/∂a` is
    // singular and the path tangent has ∂ω/∂s = 0; near it σ_min(J) ∝ |s − s*| and
    // ω − ω* ∝ (s − s*)², so σ_min/σ_max ≤ 1e-12 (measured ~4e-18) puts the
    // located ω far within 1e-8 of the turn (relative to the conditioning at the nearest path point,
    // ~0.02 of arclength away: measured 3e-6–1e-5).
    use ivt_sthb::frc::{frequency_response, trace, StringFrcOptions};
    let p = StringParams {
        kd: 30.0,
        ..Default::default()
    };
    let opts = StringFrcOptions::default();
    let mut hb = StringHb::new(p.clone()).unwrap();
    let frc = frequency_response(&mut hb, 1.0, 6.0, &opts).unwrap();
    let path = trace(&mut hb, 1.0, 6.0, &opts.continuation).unwrap();
    assert_eq!(frc.frc.events.len(), 2, "Fig. 35 has two folds");
    assert_eq!(path.events.len(), 2);
    for (f, turn) in frc.frc.events.iter().zip(&path.events) {
        assert!(f.located, "fold near ω = {} not located", turn.lambda);
        // The parabola through the points around the turn is accurate to the step.
        let moved = (f.omega_f - turn.lambda).abs();
        assert!(
            moved < opts.continuation.ds_max,
            "located ω = {} is {moved:e} from the parabola {}",
            f.omega_f,
            turn.lambda
        );
        let mut r = vec![0.0; hb.dim()];
        hb.residual(&f.coeffs, f.omega_f, &mut r);
        let res = r.iter().map(|x| x * x).sum::<f64>().sqrt();
        assert!(res < 1e-9, "‖R‖ = {res:e} at the fold");
        let at_fold = jacobian_conditioning(&mut hb, &f.coeffs, f.omega_f);
        let near = &frc.frc.points[f.index];
        let at_point = jacobian_conditioning(&mut hb, &near.coeffs, near.omega_f);
        println!(
            "fold ω = {:.12} (parabola {:.12}), ‖R‖ = {res:.1e}, σ_min/σ_max = {at_fold:.1e} (path point {at_point:.1e})",
            f.omega_f, turn.lambda
        );
        assert!(at_fold < 1e-12, "J not singular at the fold: {at_fold:e}");
        assert!(at_point > 1e4 * at_fold, "path point {at_point:e}");
    }
}
