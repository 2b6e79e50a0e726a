//! STHB acceptance (issue 4): independent Galerkin time integration, Hill
//! against monodromy, Figs. 34–36 behaviour, stress.
#![allow(clippy::indexing_slicing, clippy::unwrap_used)]

use ivt_hb::Frc;
use ivt_hb::HbError;
use ivt_num::{ExplicitRk, RK4};
use ivt_sthb::frc::{frequency_response, trace, StringFrcOptions};
use ivt_sthb::modal::ModalString;
use ivt_sthb::spring::spring_frequency_response;
use ivt_sthb::stability::{hill, hill_exponents, monodromy, monodromy_multipliers, StabilityKind};
use ivt_sthb::{Boundary, StringHb, StringParams};
use realfft::num_complex::Complex;
use std::f64::consts::PI;

/// Arclength curve without stability (the k_d = 10 branch is too steep near
/// ω ≈ 3.9 for warm-started Newton in ω).
fn curve(
    p: &StringParams,
    from: f64,
    to: f64,
    step_max: f64,
) -> (StringHb, Vec<(f64, f64, Vec<f64>)>) {
    let mut hb = StringHb::new(p.clone()).unwrap();
    let mut opts = StringFrcOptions::default().continuation;
    opts.ds_max = step_max;
    let path = trace(&mut hb, from, to, &opts).unwrap();
    let n = hb.dim();
    let points = path
        .points
        .iter()
        .map(|p| (p.lambda(), hb.complex_norm(&p.x[..n]), p.x[..n].to_vec()))
        .collect();
    (hb, points)
}

/// Largest distance from the points of `b` to the polyline `a`, in axis units
/// (ω over its range, ‖a‖ over its maximum): how far apart the plotted curves are.
fn plot_distance(a: &[(f64, f64, Vec<f64>)], b: &[(f64, f64, Vec<f64>)]) -> f64 {
    let w_range = a.last().unwrap().0 - a[0].0;
    let n_max = a.iter().map(|p| p.1).fold(0.0, f64::max);
    let xy = |p: &(f64, f64, Vec<f64>)| (p.0 / w_range, p.1 / n_max);
    b.iter()
        .map(|q| {
            let (qx, qy) = xy(q);
            a.windows(2)
                .map(|s| {
                    let ((x0, y0), (x1, y1)) = (xy(&s[0]), xy(&s[1]));
                    let (dx, dy) = (x1 - x0, y1 - y0);
                    let t =
                        (((qx - x0) * dx + (qy - y0) * dy) / (dx * dx + dy * dy)).clamp(0.0, 1.0);
                    (qx - x0 - t * dx).hypot(qy - y0 - t * dy)
                })
                .fold(f64::INFINITY, f64::min)
        })
        .fold(0.0, f64::max)
}

#[test]
fn periodic_response_matches_modal_time_integration() {
    // k_d = 10, N = 5: the branch is single-valued and stable (Fig. 34), so RK4 of
    // the closed-form Galerkin ODEs from rest settles on the STHB response.
    let p = StringParams {
        kd: 10.0,
        ..Default::default()
    };
    let (hb, pts) = curve(&p, 1.0, 6.0, 0.05);
    let modal = ModalString::new(p.clone());
    // Off resonance (≈ 2.0, 5.5), on the resonant peak (≈ 3.8) and just past it.
    for target in [2.0, 3.8, 3.95, 5.5] {
        let (omega, _, a) = pts
            .iter()
            .min_by(|x, y| (x.0 - target).abs().total_cmp(&(y.0 - target).abs()))
            .unwrap();
        let (omega, a) = (*omega, a);
        // Transient decays like exp(−π c_d/ω) per period: ≤ 1e-9 after 60 periods at ω = 5.5.
        // RK4 with 3000 steps/period: h·ρ ≤ 2π/3000 · 5π/2 ≈ 0.016, global error ~1e-9.
        let mut y = vec![0.0; 2 * p.modes];
        modal.integrate(omega, &mut y, 60, 3000);
        let mut max_err: f64 = 0.0;
        let sub = 20;
        // Compare over one period sample by sample.
        let steps = 3000;
        let per = steps / sub;
        let mut ys = y.clone();
        for s in 0..sub {
            let t = 2.0 * PI * s as f64 / sub as f64;
            for (n, q) in ys.iter().take(p.modes).enumerate() {
                max_err = max_err.max((q - hb.coordinate_at(a, n, t)).abs());
            }
            integrate_from(&modal, omega, &mut ys, s * per, per, steps);
        }
        assert!(
            max_err <= 1e-6,
            "omega {omega}: max |q_HB − q_RK4| = {max_err:e}"
        );
    }
}

/// RK4 from step index `start` for `count` steps (forcing phase kept).
fn integrate_from(
    m: &ModalString,
    omega: f64,
    y: &mut [f64],
    start: usize,
    count: usize,
    steps: usize,
) {
    let h = 2.0 * PI / steps as f64;
    let mut scr = vec![0.0; y.len() / 2];
    let mut rhs = |t: f64, y: &[f64], dy: &mut [f64]| m.rhs(omega, t, y, dy, &mut scr);
    let mut rk = ExplicitRk::with_dim(&RK4, y.len());
    for i in start..start + count {
        rk.step(&mut rhs, i as f64 * h, h, y);
    }
}

#[test]
fn kd10_curve_all_stable_and_n5_n10_overlap() {
    // Fig. 34: all stable; N = 5 and 10 "almost overlapped".
    let frc = frequency_response(
        &mut StringHb::new(StringParams::default()).unwrap(),
        1.0,
        6.0,
        &StringFrcOptions::default(),
    )
    .unwrap()
    .frc;
    assert!(frc.points.iter().all(|p| p.stable()));
    assert!((frc.points.last().unwrap().omega_f - 6.0).abs() < 1e-12);
    let [c5, c10] = [5, 10].map(|modes| {
        let p = StringParams {
            modes,
            ..Default::default()
        };
        curve(&p, 1.0, 6.0, 0.02).1
    });
    // "Plotting accuracy": within 1 % of the axes (2 px on a 200-px plot).
    // Measured 6.1e-3, on the steep side of the peak (ω ≈ 3.9).
    let d = plot_distance(&c5, &c10).max(plot_distance(&c10, &c5));
    assert!(d < 1e-2, "N = 5 and N = 10 curves {d:e} apart (axis units)");
}

/// The default string (thesis §4 parameters) with Duffing coefficient `kd`.
fn string_hb(kd: f64) -> StringHb {
    StringHb::new(StringParams {
        kd,
        ..Default::default()
    })
    .unwrap()
}

#[test]
fn kd30_has_unstable_middle_branch_without_period_doubling() {
    // Fig. 35: unstable solutions between two folds, no period doubling or NS.
    let mut hb = string_hb(30.0);
    let frc = frequency_response(&mut hb, 1.0, 6.0, &StringFrcOptions::default()).unwrap();
    assert_unstable_exactly_between_folds(&frc.frc);
}

/// Fig. 35's pattern: ≥ 5 unstable points, all of fold type (no period doubling or
/// Neimark–Sacker), exactly where ω runs backwards (between the folds).
fn assert_unstable_exactly_between_folds(frc: &Frc) {
    let kinds: Vec<StabilityKind> = frc.points.iter().map(|p| p.kind).collect();
    let unstable = kinds
        .iter()
        .filter(|k| **k != StabilityKind::Stable)
        .count();
    assert!(
        unstable >= 5,
        "expected an unstable middle branch, got {unstable} points"
    );
    assert!(kinds
        .iter()
        .all(|k| matches!(k, StabilityKind::Stable | StabilityKind::Fold)));
    // The unstable points are exactly where ω runs backwards (between the folds).
    let w: Vec<f64> = frc.points.iter().map(|p| p.omega_f).collect();
    for i in 1..w.len() - 1 {
        let backwards = w[i + 1] < w[i] && w[i] < w[i - 1];
        let forwards = w[i + 1] > w[i] && w[i] > w[i - 1];
        if backwards {
            assert_ne!(
                kinds[i],
                StabilityKind::Stable,
                "stable point on the middle branch at {}",
                w[i]
            );
        }
        if forwards {
            assert_eq!(
                kinds[i],
                StabilityKind::Stable,
                "unstable point on an outer branch at {}",
                w[i]
            );
        }
    }
}

#[test]
fn spring_k0_1e4_stability_matches_fixed() {
    // The spring boundary's stability (Tau row eliminated, see sthb::stability)
    // on the k_d = 30 curve: k0 = 1e4 must look like fixed–fixed (Fig. 35).
    let fixed = StringParams {
        kd: 30.0,
        ..Default::default()
    };
    let spring = StringParams {
        boundary: Boundary::Spring { k0: 10_000.0 },
        ..fixed.clone()
    };
    let trace = |p: &StringParams| {
        let mut hb = StringHb::new(p.clone()).unwrap();
        let frc = frequency_response(&mut hb, 1.0, 6.0, &StringFrcOptions::default()).unwrap();
        (hb, frc.frc)
    };
    let (mut hf, ff) = trace(&fixed);
    let (mut hs, fs) = trace(&spring);
    assert_unstable_exactly_between_folds(&fs);
    // The unstable stretch spans the same ω interval (between the folds).
    let span = |frc: &Frc| {
        frc.points
            .iter()
            .filter(|p| !p.stable())
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), p| {
                (lo.min(p.omega_f), hi.max(p.omega_f))
            })
    };
    let (sf, ss) = (span(&ff), span(&fs));
    eprintln!("unstable ω span: fixed {sf:?}, spring k0 = 1e4 {ss:?}");
    // Folds at ω ≈ 4.32 and 4.43 (the ends of the span); the spring moves them by
    // O(1/k0) times the curve's sensitivity: measured 3.7e-3 and 1.5e-3, 1e-2 asserted (less
    // than one arclength step near the folds, where the points are ~0.01 apart).
    assert!((sf.0 - ss.0).abs() < 1e-2 && (sf.1 - ss.1).abs() < 1e-2);
    // Multipliers at equal ω on all three branches: Newton for the spring from the
    // fixed solution (q_(N+1) = 0), then all 2N monodromy multipliers of each.
    //
    // Tolerance off the folds: k0 = 1e4 raises each linear eigenfrequency from nπ
    // to β_n with tan β_n = β_n/k0, i.e. by nπ/k0; over one period 2π/ω that turns
    // every multiplier (|μ| = e^(−π c_d/ω) for all modes) by 2π nπ/(k0 ω) radians,
    // so |Δμ| ≤ |μ| 2π Nπ/(k0 ω) to first order (measured 0.4–0.6 of it); twice
    // that is asserted. Within 0.1 of a fold the solution at fixed ω is
    // square-root sensitive (‖a‖ moves by up to 2.3e-3) and the leading real
    // multiplier with it: there the verdict must agree and |μ|max within 1e-2
    // (measured ≤ 5.2e-3).
    let folds = [sf.0, sf.1];
    let (mut compared, mut near) = (0, 0);
    for pt in ff.points.iter().step_by(3) {
        let nq = hs.coords();
        let mut a = vec![0.0; hs.dim()];
        for h in 0..2 * fixed.harmonics + 1 {
            for n in 0..fixed.modes {
                a[h * nq + n] = pt.coeffs[h * fixed.modes + n];
            }
        }
        let near_fold = folds.iter().any(|f| (pt.omega_f - f).abs() < 0.1);
        if let Err(e) = hs.solve(pt.omega_f, &mut a, 1e-10, 20) {
            // Between the fixed and the spring fold (≤ 4e-3 apart) the branch has
            // no spring counterpart at this ω.
            assert!(near_fold, "spring Newton at ω = {}: {e}", pt.omega_f);
            continue;
        }
        hf.linearize(&pt.coeffs);
        let (mf, ms) = (
            monodromy_multipliers(&hf, pt.omega_f).unwrap(),
            monodromy_multipliers(&hs, pt.omega_f).unwrap(),
        );
        assert_eq!(
            mf[0].norm() < 1.0,
            ms[0].norm() < 1.0,
            "verdicts differ at ω = {}",
            pt.omega_f
        );
        if near_fold {
            let d = (mf[0].norm() - ms[0].norm()).abs();
            assert!(
                d <= 1e-2,
                "ω = {} (near a fold): |μ|max differ by {d:e}",
                pt.omega_f
            );
            near += 1;
            continue;
        }
        // Distance between the multiplier sets (each to its nearest partner, both ways).
        let one_way = |x: &[Complex<f64>], y: &[Complex<f64>]| {
            x.iter()
                .map(|u| {
                    y.iter()
                        .map(|v| (u - v).norm())
                        .fold(f64::INFINITY, f64::min)
                })
                .fold(0.0, f64::max)
        };
        let d = one_way(&mf, &ms).max(one_way(&ms, &mf));
        let bound = mf[0].norm() * 2.0 * PI * fixed.modes as f64 * PI / (1e4 * pt.omega_f);
        assert!(
            d <= 2.0 * bound,
            "ω = {}: multipliers differ by {d:e} (first-order bound {bound:e})",
            pt.omega_f
        );
        compared += 1;
    }
    assert!(
        compared >= 30 && near >= 10,
        "{compared} / {near} points compared"
    );
}

/// Root of `g(x) = 0` by Newton from `x`.
fn newton_root(mut x: f64, g: impl Fn(f64) -> (f64, f64)) -> f64 {
    for _ in 0..100 {
        let (f, df) = g(x);
        x -= f / df;
    }
    x
}

#[test]
fn spring_linear_stability_converges_to_the_exact_string() {
    // Outside check of the Tau elimination in the stability code. At k_d = 0 the
    // linearization is the damped linear string with k0 w(1) = w_x(1) (Eq. 132 as
    // printed), solvable in closed form: oscillatory modes sin βx with
    // tan β = β/k0, exponents −c_d/(2ω) ± j√(β² − c_d²/4)/ω; and, for k0 > 1, a
    // growing mode sinh γx with tanh γ = γ/k0 (the printed sign is a *negative*
    // spring), exponent (−c_d + √(c_d² + 4γ²))/(2ω). k0 < 0 is a restoring
    // spring of stiffness −k0: no growing mode. The Tau model must converge to
    // these as N grows (measured O(1/N): it expands sin βx, β ≠ nπ, in sine modes).
    let omega = 8.0; // arg μ1 < π: the first mode's multiplier does not wrap
    for k0 in [10.0, -10.0] {
        let beta = newton_root(if k0 > 0.0 { 3.3 } else { 2.9 }, |b| {
            (b.tan() - b / k0, 1.0 / b.cos().powi(2) - 1.0 / k0)
        });
        let mut prev: Option<(f64, f64)> = None;
        for modes in [5usize, 10, 20, 40] {
            let p = StringParams {
                kd: 0.0,
                modes,
                ns: 128,
                harmonics: 3,
                ms: 16,
                boundary: Boundary::Spring { k0 },
                ..Default::default()
            };
            let cd = p.cd;
            let mut hb = StringHb::new(p).unwrap();
            let mut a = vec![0.0; hb.dim()];
            hb.solve(omega, &mut a, 1e-12, 5).unwrap();
            let mu1 = (Complex::new(
                -cd / (2.0 * omega),
                (beta * beta - cd * cd / 4.0).sqrt() / omega,
            ) * (2.0 * PI))
                .exp();
            let d_mu1 = monodromy_multipliers(&hb, omega)
                .unwrap()
                .iter()
                .map(|m| (m - mu1).norm())
                .fold(f64::INFINITY, f64::min);
            let lead = hill_exponents(&hb, omega).unwrap()[0];
            let d_lead = if k0 > 1.0 {
                let gamma = newton_root(k0, |g| {
                    (g.tanh() - g / k0, 1.0 / g.cosh().powi(2) - 1.0 / k0)
                });
                let grow = (-cd + (cd * cd + 4.0 * gamma * gamma).sqrt()) / (2.0 * omega);
                assert!(lead.im.abs() < 1e-9, "growing exponent {lead} not real");
                (lead.re - grow).abs() / grow
            } else {
                // Proportional damping: every oscillatory mode decays at c_d/(2ω).
                (lead.re + cd / (2.0 * omega)).abs()
            };
            eprintln!("k0 {k0}, N {modes}: |μ1 − exact| {d_mu1:.2e}, lead exponent {lead:.4} (error {d_lead:.2e})");
            if let Some((pm, pl)) = prev {
                // Doubling N at least ~halves the first mode's error (measured 0.51–0.54).
                assert!(d_mu1 <= 0.6 * pm, "N = {modes}: {d_mu1:e} after {pm:e}");
                if k0 > 1.0 {
                    // The growing mode converges too (measured 2.1, 0.33, 0.13, 0.06 relative).
                    assert!(
                        d_lead <= 0.6 * pl,
                        "N = {modes}: growth error {d_lead:e} after {pl:e}"
                    );
                }
            }
            if k0 < 0.0 {
                assert!(d_lead < 1e-9, "restoring spring: lead exponent {lead}");
            }
            prev = Some((d_mu1, d_lead));
        }
        let (d_mu1, d_lead) = prev.unwrap();
        assert!(d_mu1 < 2e-3 && (k0 < 0.0 || d_lead < 0.1));
    }
}

#[test]
fn hill_agrees_with_monodromy() {
    // Two independent routes to the multipliers of Eq. 126: Hill (Eq. 130–131)
    // and RK4 of A(t). Compare the largest modulus on both sides of the folds.
    let mut hb = string_hb(30.0);
    let path = trace(&mut hb, 3.0, 5.0, &StringFrcOptions::default().continuation).unwrap();
    let n = hb.dim();
    let mut checked_unstable = 0;
    for (i, pt) in path.points.iter().enumerate().filter(|(i, _)| i % 7 == 0) {
        let omega = pt.lambda();
        hb.linearize(&pt.x[..n]);
        let (h, m) = (hill(&hb, omega).unwrap(), monodromy(&hb, omega).unwrap());
        assert_eq!(h.kind, m.kind, "point {i} at ω = {omega}");
        // RK4 with h·ρ ≤ 0.3 over one period: |μ| to a few 1e-4 (measured 3e-3 at h·ρ ≤ 0.5).
        let (a, b) = (h.critical().norm(), m.critical().norm());
        assert!(
            (a - b).abs() <= 1e-3 * a.max(1.0),
            "ω = {omega}: Hill {a} vs monodromy {b}"
        );
        checked_unstable += usize::from(!h.is_stable());
    }
    assert!(checked_unstable > 0);
}

#[test]
fn spring_boundary_fig36() {
    let base = StringParams::default();
    let (hf, fixed) = curve(&base, 2.0, 5.0, 0.05);
    let stiff = StringParams {
        boundary: Boundary::Spring { k0: 10_000.0 },
        ..base.clone()
    };
    // Pointwise at equal ω the relative difference reaches 1.03e-3 on the steep
    // side of the peak (a frequency shift of O(1/k0) times a slope of order 1);
    // the curves themselves are compared as drawn: distance ≤ 1e-3 of the axes.
    let (_, sp) = curve(&stiff, 2.0, 5.0, 0.05);
    let d = plot_distance(&fixed, &sp).max(plot_distance(&sp, &fixed));
    assert!(d <= 1e-3, "k0 = 1e4 vs fixed–fixed: curves {d:e} apart");
    let _ = &hf;
    // Broyden (engine continuation, as in §3.3.5) agrees with Newton on a stretch.
    let br = spring_frequency_response(stiff.clone(), 2.0, 2.3, 0.05).unwrap();
    // Pointwise: Newton at each Broyden point's ω, warm-started from the nearest
    // Newton-path point. Broyden stops at ‖F‖ ≤ 1e-10, so norms agree to ~1e-9.
    let mut hs = StringHb::new(stiff.clone()).unwrap();
    assert!(br.len() >= 3 && br.last().unwrap().omega >= 2.29);
    for p in &br {
        let near = sp
            .iter()
            .min_by(|x, y| (x.0 - p.omega).abs().total_cmp(&(y.0 - p.omega).abs()))
            .unwrap();
        let mut b = near.2.clone();
        hs.solve(p.omega, &mut b, 1e-12, 50).unwrap();
        let nn = hs.complex_norm(&b);
        assert!(
            (nn - p.norm).abs() <= 1e-7 * nn,
            "ω = {}: Broyden {} vs Newton {nn}",
            p.omega,
            p.norm
        );
    }
    // k0 = 10 shifts the peak: with Eq. 132 as printed (k0 w = +w_x) the first
    // linear mode sin βx has tan β = β/k0, β ≈ 3.4761 > π, so the peak moves up.
    let peak = |params: StringParams| {
        let (_, pts) = curve(&params, 2.0, 5.0, 0.05);
        assert!((pts.last().unwrap().0 - 5.0).abs() < 1e-9);
        pts.iter()
            .fold((0.0, 0.0), |m, p| if p.1 > m.1 { (p.0, p.1) } else { m })
    };
    let (w_stiff, _) = peak(stiff);
    let (w_soft, _) = peak(StringParams {
        boundary: Boundary::Spring { k0: 10.0 },
        ..base.clone()
    });
    let (w_fixed, _) = peak(base);
    assert!(
        (w_stiff - w_fixed).abs() < 0.06,
        "peak k0 = 1e4 at {w_stiff}, fixed at {w_fixed}"
    );
    assert!(
        w_soft - w_fixed > 0.15,
        "peak k0 = 10 at {w_soft}, fixed at {w_fixed}"
    );
}

#[test]
fn stress_cases_trace_the_whole_curve() {
    // k_d = 100, M = 40 and N = 20 (rustdct path): each traces the whole curve.
    for p in [
        StringParams {
            kd: 100.0,
            ..Default::default()
        },
        StringParams {
            kd: 30.0,
            harmonics: 40,
            ..Default::default()
        },
        StringParams {
            kd: 10.0,
            modes: 20,
            ..Default::default()
        },
    ] {
        let mut hb = StringHb::new(p.clone()).unwrap();
        let mut opts = StringFrcOptions::default().continuation;
        opts.ds_max = 0.1;
        // Each of the three converges over the whole range (measured: 42, 87
        // and 138 points); an error, even a clean one, is a regression here.
        let path = trace(&mut hb, 2.5, 4.5, &opts).unwrap_or_else(|e| panic!("{p:?}: {e}"));
        let (first, last) = (&path.points[0], &path.points[path.points.len() - 1]);
        assert!(
            (first.lambda() - 2.5).abs() < 1e-9 && (last.lambda() - 4.5).abs() < 1e-9,
            "{p:?}: ω from {} to {}",
            first.lambda(),
            last.lambda()
        );
        let dim = hb.dim();
        let mut r = vec![0.0; dim];
        for pt in &path.points {
            hb.residual(&pt.x[..dim], pt.lambda(), &mut r);
            let n = r.iter().map(|v| v * v).sum::<f64>().sqrt();
            assert!(
                n < 1e-8 && hb.complex_norm(&pt.x[..dim]).is_finite(),
                "{p:?} at ω = {}: ‖R‖ = {n:e}",
                pt.lambda()
            );
        }
    }
    // Nonsense input is rejected, not computed.
    assert!(matches!(
        StringHb::new(StringParams {
            ns: 8,
            modes: 5,
            ..Default::default()
        }),
        Err(HbError::InvalidInput(_))
    ));
    assert!(matches!(
        StringHb::new(StringParams {
            kd: f64::NAN,
            ..Default::default()
        }),
        Err(HbError::InvalidInput(_))
    ));
    let mut hb = StringHb::new(StringParams::default()).unwrap();
    let mut a = vec![f64::NAN; hb.dim()];
    assert!(matches!(
        hb.solve(3.0, &mut a, 1e-10, 5),
        Err(HbError::NonFinite { .. })
    ));
}
