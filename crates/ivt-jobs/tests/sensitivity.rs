//! Sensitivities of located features (issue 45 item 3) against finite
//! differences: the thesis Duffing's folds (Eq. 49, ξ = 0.02, α = ε = 1) in
//! the force against Richardson-extrapolated differences of shooting folds
//! (RK4, no HB), with the work of a gradient against that of locating the
//! fold; the other features (period doubling, Neimark–Sacker point, branch
//! point, amplitude peak) against differences of their own located points.
#![allow(
    clippy::unwrap_used,
    clippy::expect_used,
    clippy::indexing_slicing,
    clippy::panic
)]

#[path = "../../ivt-hb/tests/common/mod.rs"]
mod common;

use common::shooting::{newton3, orbit_state as state, period_map, period_map_jacobian};
use ivt_hb::analyses::sensitivity::{sensitivity, Feature};
use ivt_hb::problem::boxed_family;
use ivt_hb::{
    locate_fold, BifurcationKind, Duffing, FamilyBranch, FrcOptions, Frequency, GeneralProblem,
    HbError, HbOptions, LocateOptions, PeriodicProblem,
};
use ivt_jobs::{self as jobs, FrcRequest};
use std::cell::Cell;

/// A problem that counts its batched `g` and `∂g` evaluations.
struct Counting<'c, P> {
    inner: P,
    g: &'c Cell<usize>,
    jac: &'c Cell<usize>,
}

impl<P: PeriodicProblem> PeriodicProblem for Counting<'_, P> {
    fn n_dof(&self) -> usize {
        self.inner.n_dof()
    }
    fn mass(&self) -> &[f64] {
        self.inner.mass()
    }
    fn damping(&self) -> &[f64] {
        self.inner.damping()
    }
    fn stiffness(&self) -> &[f64] {
        self.inner.stiffness()
    }
    fn velocity_dependent(&self) -> bool {
        self.inner.velocity_dependent()
    }
    fn nonlinear(&self, x: &[f64], v: &[f64], theta: f64, out: &mut [f64]) {
        self.inner.nonlinear(x, v, theta, out)
    }
    fn nonlinear_samples(&self, x: &[f64], v: &[f64], theta: &[f64], out: &mut [f64]) {
        self.g.set(self.g.get() + 1);
        self.inner.nonlinear_samples(x, v, theta, out)
    }
    fn excitation(&self, theta: f64, out: &mut [f64]) {
        self.inner.excitation(theta, out)
    }
    fn nonlinear_jacobian(&self, x: &[f64], v: &[f64], theta: f64, dg: &mut [f64]) {
        self.inner.nonlinear_jacobian(x, v, theta, dg)
    }
    fn nonlinear_jacobian_samples(&self, x: &[f64], v: &[f64], theta: &[f64], dg: &mut [f64]) {
        self.jac.set(self.jac.get() + 1);
        self.inner.nonlinear_jacobian_samples(x, v, theta, dg)
    }
}

/// `[P(y) − y, det(∂P/∂y − I)]` of the thesis Duffing at F (a fold by
/// shooting, as tests/fold_curve.rs).
fn fold_residual(force: f64, omega: f64, y: [f64; 2]) -> [f64; 3] {
    let d = Duffing::new(0.02, 1.0, 1.0, force);
    let p = period_map(&d, omega, y);
    let j = period_map_jacobian(&d, omega, y);
    [
        p[0] - y[0],
        p[1] - y[1],
        j[0][0] * j[1][1] - j[0][1] * j[1][0],
    ]
}

/// The derivative of `f` at `x` by central differences with steps `h` and
/// `2h`, Richardson-extrapolated (O(h⁴)).
fn richardson(f: impl Fn(f64) -> f64, x: f64, h: f64) -> f64 {
    let d = |s: f64| (f(x + s) - f(x - s)) / (2.0 * s);
    (4.0 * d(h) - d(2.0 * h)) / 3.0
}

#[test]
fn duffing_fold_frequencies_move_with_the_force_as_shooting_says() {
    // Both folds of Fig. 29's curve at F = 0.1 and 0.2: dω_fold/dF by the
    // adjoint against Richardson differences (h = 1e-4) of the folds that
    // shooting locates at F ± h, F ± 2h. Issue 45 asks for 1e-6 relative.
    let hb = HbOptions::new(20, 64).with_tol(1e-11);
    let (g, jac) = (Cell::new(0), Cell::new(0));
    let family = |f: f64| -> Result<_, HbError> {
        Ok(Counting {
            inner: Duffing::new(0.02, 1.0, 1.0, f),
            g: &g,
            jac: &jac,
        })
    };
    for force in [0.1, 0.2] {
        let d = Duffing::new(0.02, 1.0, 1.0, force);
        let req = FrcRequest {
            options: FrcOptions {
                from: 0.5,
                to: 2.5,
                ..FrcOptions::default()
            },
            events: false,
        };
        let frc = jobs::frc(&d, &hb, &req).unwrap();
        assert_eq!(frc.folds.len(), 2);
        for fold in &frc.folds {
            g.set(0);
            jac.set(0);
            let s = sensitivity(
                &boxed_family(family),
                &hb,
                Feature::Event(BifurcationKind::Fold),
                (&fold.coeffs.0, fold.omega),
                force,
                0,
            )
            .unwrap();
            let cost = (g.get(), jac.get());
            // Shooting: the fold at F ± h from the HB fold's state.
            let y = state(&fold.coeffs.0, fold.omega);
            let shoot = |f: f64| {
                newton3(
                    |u| fold_residual(f, u[2], [u[0], u[1]]),
                    [y[0], y[1], fold.omega],
                )[2]
            };
            let reference = richardson(shoot, force, 1e-4);
            let rel = (s.d_omega_dp - reference).abs() / reference.abs();
            // One fold location, as the curve does it: from its point
            // nearest the turn.
            let near = &frc.points[fold.index];
            g.set(0);
            jac.set(0);
            let counted = family(force).unwrap();
            let mut branch = FamilyBranch::new(Frequency(&counted), &hb, near.omega).unwrap();
            let located = locate_fold(
                &mut branch,
                &near.coeffs.0,
                near.omega,
                &LocateOptions::fold(),
            )
            .unwrap();
            let location = (g.get(), jac.get());
            eprintln!(
                "F = {force}: fold ω {:.10}: dω/dF {:.12} (shooting {reference:.12}, rel {rel:.1e}), \
                 dA/dF {:.6}; g, ∂g calls: gradient {cost:?}, location {location:?} ({} steps)",
                s.omega, s.d_omega_dp, s.d_amplitude_dp, located.iterations
            );
            assert!((s.omega - fold.omega).abs() < 1e-9);
            assert!(rel < 1e-6, "F = {force}: {} vs {reference}", s.d_omega_dp);
            assert!(
                cost.0 <= 2 * location.0 && cost.1 <= 2 * location.1,
                "{cost:?} vs {location:?}"
            );
        }
    }
}

#[test]
fn duffing_fold_amplitude_and_a_stiffness_derivative_match_differences_of_located_folds() {
    // dA/dF of the upper fold at F = 0.1 and dω/dε, dA/dε of both (ε the
    // cubic stiffness, which moves g rather than f) against central
    // differences of the folds located at the perturbed parameter.
    let hb = HbOptions::new(20, 64).with_tol(1e-11);
    let d = Duffing::new(0.02, 1.0, 1.0, 0.1);
    let frc = jobs::frc(&d, &hb, &FrcRequest::default()).unwrap();
    let by_force = |f: f64| -> Result<_, HbError> { Ok(Duffing::new(0.02, 1.0, 1.0, f)) };
    let by_eps = |e: f64| -> Result<_, HbError> { Ok(Duffing::new(0.02, 1.0, e, 0.1)) };
    let fold = Feature::Event(BifurcationKind::Fold);
    for f in &frc.folds {
        let start = (f.coeffs.0.as_slice(), f.omega);
        let s = sensitivity(&boxed_family(by_force), &hb, fold, start, 0.1, 0).unwrap();
        let amplitude_at = |force: f64| {
            sensitivity(&boxed_family(by_force), &hb, fold, start, force, 0)
                .unwrap()
                .amplitude
        };
        let da = richardson(amplitude_at, 0.1, 1e-4);
        let e = sensitivity(&boxed_family(by_eps), &hb, fold, start, 1.0, 0).unwrap();
        let at_eps =
            |eps: f64| sensitivity(&boxed_family(by_eps), &hb, fold, start, eps, 0).unwrap();
        let dw_eps = richardson(|x| at_eps(x).omega, 1.0, 1e-4);
        let da_eps = richardson(|x| at_eps(x).amplitude, 1.0, 1e-4);
        eprintln!(
            "fold {:.8}: dA/dF {} ({da}), dω/dε {} ({dw_eps}), dA/dε {} ({da_eps})",
            s.omega, s.d_amplitude_dp, e.d_omega_dp, e.d_amplitude_dp
        );
        for (got, want) in [
            (s.d_amplitude_dp, da),
            (e.d_omega_dp, dw_eps),
            (e.d_amplitude_dp, da_eps),
        ] {
            assert!(
                (got - want).abs() <= 1e-6 * want.abs().max(1e-3),
                "{got} vs {want}"
            );
        }
    }
}

/// `(ω, A)` of `feature` located at `p` from `start` and its adjoint
/// derivatives there, against Richardson differences of the located `(ω, A)`
/// at `p ± h`, `p ± 2h`: the deviations of `dω/dp` relative to itself and
/// of `dA/dp` relative to `A/p` (a small `dA/dp` is a difference of large
/// terms).
fn against_differences<P, F>(
    family: F,
    hb: &HbOptions,
    feature: Feature,
    start: (&[f64], f64),
    p: f64,
    h: f64,
) -> f64
where
    P: PeriodicProblem,
    F: Fn(f64) -> Result<P, HbError> + Copy,
{
    let s = sensitivity(&boxed_family(family), hb, feature, start, p, 0).unwrap();
    let located = |x: f64| {
        sensitivity(
            &boxed_family(family),
            hb,
            feature,
            (&s.coeffs, s.omega),
            x,
            0,
        )
        .unwrap()
    };
    eprintln!("  located in {} steps", s.iterations);
    let dw = richardson(|x| located(x).omega, p, h);
    let da = richardson(|x| located(x).amplitude, p, h);
    eprintln!(
        "{} at ω {:.8}: dω/dp {} ({dw}), dA/dp {} ({da})",
        feature.words(),
        s.omega,
        s.d_omega_dp,
        s.d_amplitude_dp
    );
    let scale = (s.amplitude / p.abs()).max(da.abs());
    ((s.d_omega_dp - dw).abs() / dw.abs()).max((s.d_amplitude_dp - da).abs() / scale)
}

#[test]
fn period_doubling_and_neimark_sacker_points_move_as_their_located_points() {
    // The twin-well Duffing about its well (x″ + 0.1x′ + 2x + 3x² + x³ =
    // F cos ωt, F = 0.5; period doubling at ω = 2.93667, two-parameter.md)
    // and the forced Van der Pol oscillator (μ = F = 0.2, NS at
    // ω = 0.94525643), both in F.
    let well = |f: f64| -> Result<_, HbError> {
        Ok(GeneralProblem::new(
            1,
            vec![1.0],
            vec![0.1],
            vec![2.0],
            |x: &[f64], _v: &[f64], _t: f64, g: &mut [f64]| g[0] = x[0] * x[0] * (3.0 + x[0]),
            move |t: f64, out: &mut [f64]| out[0] = f * t.cos(),
        )
        .with_velocity_dependent(false))
    };
    let hb = HbOptions::new(10, 32);
    let req = FrcRequest {
        options: FrcOptions {
            from: 3.6,
            to: 2.2,
            ..FrcOptions::default()
        },
        events: true,
    };
    let frc = jobs::frc(&well(0.5).unwrap(), &hb, &req).unwrap();
    let pd = frc
        .bifurcations
        .iter()
        .find(|e| e.kind == BifurcationKind::PeriodDoubling)
        .unwrap();
    let start = (pd.coeffs.as_ref().unwrap().0.as_slice(), pd.omega.unwrap());
    let worst = against_differences(
        well,
        &hb,
        Feature::Event(BifurcationKind::PeriodDoubling),
        start,
        0.5,
        1e-3,
    );
    assert!(worst < 1e-5, "{worst:e}");

    let vdp = |f: f64| -> Result<_, HbError> {
        Ok(GeneralProblem::new(
            1,
            vec![1.0],
            vec![-0.2],
            vec![1.0],
            |x: &[f64], v: &[f64], _t: f64, g: &mut [f64]| g[0] = 0.2 * x[0] * x[0] * v[0],
            move |t: f64, out: &mut [f64]| out[0] = f * t.cos(),
        ))
    };
    let hb = HbOptions::new(9, 32);
    let req = FrcRequest {
        options: FrcOptions {
            from: 0.6,
            to: 1.6,
            ..FrcOptions::default()
        },
        events: true,
    };
    let frc = jobs::frc(&vdp(0.2).unwrap(), &hb, &req).unwrap();
    let ns = frc
        .bifurcations
        .iter()
        .find(|e| e.kind == BifurcationKind::NeimarkSacker)
        .unwrap();
    let start = (ns.coeffs.as_ref().unwrap().0.as_slice(), ns.omega.unwrap());
    let worst = against_differences(
        vdp,
        &hb,
        Feature::Event(BifurcationKind::NeimarkSacker),
        start,
        0.2,
        1e-3,
    );
    assert!(worst < 1e-5, "{worst:e}");
}

#[test]
fn a_symmetric_branch_point_and_an_amplitude_peak_move_as_their_located_points() {
    // The symmetric chain of tests/bifurcation.rs (a pitchfork at
    // ω ≈ 1.2) in its forcing amplitude; its branch point at F ± 2h
    // located on frequency responses around it.
    let chain = |f: f64| -> Result<_, HbError> {
        Ok(GeneralProblem::new(
            2,
            vec![1.0, 0.0, 0.0, 1.0],
            vec![0.02, 0.0, 0.0, 0.02],
            vec![1.1, 0.1, 0.1, 1.1],
            |x: &[f64], _v: &[f64], _t: f64, g: &mut [f64]| {
                g[0] = x[0].powi(3);
                g[1] = x[1].powi(3);
            },
            move |t: f64, out: &mut [f64]| {
                out[0] = f * t.cos();
                out[1] = f * t.cos();
            },
        )
        .with_velocity_dependent(false))
    };
    let hb = HbOptions::new(9, 32);
    let located = |f: f64, from: f64, to: f64| {
        let req = FrcRequest {
            options: FrcOptions {
                from,
                to,
                ..FrcOptions::default()
            },
            events: true,
        };
        let frc = jobs::frc(&chain(f).unwrap(), &hb, &req).unwrap();
        frc.bifurcations
            .into_iter()
            .find(|e| e.kind == BifurcationKind::BranchPoint && e.located)
            .unwrap()
    };
    let bp = located(0.05, 0.8, 2.5);
    let omega = bp.omega.unwrap();
    let s = sensitivity(
        &boxed_family(chain),
        &hb,
        Feature::Event(BifurcationKind::BranchPoint),
        (&bp.coeffs.as_ref().unwrap().0, omega),
        0.05,
        0,
    )
    .unwrap();
    let h = 1e-4;
    let near = |f: f64| located(f, 0.8, omega + 0.05).omega.unwrap();
    let reference = richardson(near, 0.05, h);
    eprintln!(
        "branch point at ω {omega:.8}: dω/dF {} ({reference})",
        s.d_omega_dp
    );
    assert!(
        (s.d_omega_dp - reference).abs() < 1e-5 * reference.abs(),
        "{} vs {reference}",
        s.d_omega_dp
    );

    // A peak without folds: Duffing at F = 0.01 (backbone shift 0.02 below
    // the band 2ξ = 0.04), its highest point as the start.
    let duffing = |f: f64| -> Result<_, HbError> { Ok(Duffing::new(0.02, 1.0, 1.0, f)) };
    let hb = HbOptions::new(9, 32).with_tol(1e-12);
    let frc = jobs::frc(&duffing(0.01).unwrap(), &hb, &FrcRequest::default()).unwrap();
    assert!(frc.folds.is_empty());
    let top = frc
        .points
        .iter()
        .max_by(|a, b| a.amplitude.total_cmp(&b.amplitude))
        .unwrap();
    let worst = against_differences(
        duffing,
        &hb,
        Feature::Peak,
        (&top.coeffs.0, top.omega),
        0.01,
        1e-6,
    );
    assert!(worst < 1e-5, "{worst:e}");
}
