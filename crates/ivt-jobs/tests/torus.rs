//! Quasi-periodic responses (issue 45 item 1) against time integration: the
//! torus branch of the forced Van der Pol oscillator from its located
//! Neimark–Sacker point, its rotation number and mean and maximum `|x|`
//! against a long RK6 integration's Poincaré map (`common/quasi.rs`), the
//! error estimate against the true error of a coarse torus, a torus
//! followed in the force, and a torus of Rust elements.
#![allow(
    clippy::unwrap_used,
    clippy::expect_used,
    clippy::indexing_slicing,
    clippy::panic
)]

#[path = "../../ivt-hb/tests/common/mod.rs"]
mod common;

use common::quasi::{reference, Reference};
use ivt_hb::branches::torus::{torus_start, NeimarkSackerStart, TorusOptions, Truncation};
use ivt_hb::problem::elements::{Element, ElementProblem, Harmonic, Law};
use ivt_hb::{
    c64, BifurcationKind, FrcOptions, Frequency, GeneralProblem, HbOptions, LocateOptions,
    PeriodicProblem,
};
use ivt_jobs::{self as jobs, EventRecord, FrcRequest, TorusCurve, TorusPoint, TorusRequest};
use ivt_path::continuation::Termination;

const MU: f64 = 0.2;

fn van_der_pol(force: f64) -> impl PeriodicProblem {
    GeneralProblem::new(
        1,
        vec![1.0],
        vec![-MU],
        vec![1.0],
        move |x: &[f64], v: &[f64], _t: f64, g: &mut [f64]| g[0] = MU * x[0] * x[0] * v[0],
        move |t: f64, f: &mut [f64]| f[0] = force * t.cos(),
    )
}

/// The reference at ω (F = 0.2): 300 periods of transient, 1500 measured,
/// 128 RK6 steps per period.
fn vdp_reference(force: f64, omega: f64) -> Reference {
    let accel =
        move |t: f64, x: f64, v: f64| MU * (1.0 - x * x) * v - x + force * (omega * t).cos();
    reference(accel, omega, [0.5, 0.0], 300, 1500, 128)
}

/// The located Neimark–Sacker point of the FRC from ω = 0.6 to 1.6.
fn neimark_sacker<P: PeriodicProblem>(
    problem: &P,
    hb: &HbOptions,
    from: f64,
    to: f64,
) -> EventRecord {
    let req = FrcRequest {
        options: FrcOptions {
            from,
            to,
            ..FrcOptions::default()
        },
        events: true,
    };
    let frc = jobs::frc(problem, hb, &req).unwrap();
    frc.bifurcations
        .into_iter()
        .find(|e| e.kind == BifurcationKind::NeimarkSacker && e.located)
        .expect("a located Neimark–Sacker point")
}

fn torus_request(
    ns: &EventRecord,
    omega_to: f64,
    at: Vec<f64>,
    truncation: Truncation,
) -> TorusRequest {
    TorusRequest {
        omega: ns.omega.unwrap(),
        coeffs: ns.coeffs.clone().unwrap().0,
        multipliers: ns
            .multipliers
            .clone()
            .unwrap()
            .iter()
            .map(|m| c64::new(m[0], m[1]))
            .collect(),
        omega_to,
        at,
        torus: TorusOptions {
            truncation,
            ..TorusOptions::default()
        },
        ..TorusRequest::default()
    }
}

/// `|hb − reference|` of the three measures.
fn deviations(p: &TorusPoint, r: &Reference) -> [f64; 3] {
    [
        (p.rotation_number - r.rotation_number).abs(),
        (p.amplitude_mean - r.amplitude_mean).abs(),
        (p.amplitude_max - r.amplitude_max).abs(),
    ]
}

fn at(curve: &TorusCurve, omega: f64) -> &TorusPoint {
    curve
        .at
        .iter()
        .find(|p| (p.omega - omega).abs() < 1e-12)
        .expect("the at torus")
}

#[test]
fn van_der_pol_torus_from_its_neimark_sacker_point_matches_time_integration() {
    // x″ − μ(1 − x²)x′ + x = F cos ωt, μ = F = 0.2: the entrained orbit
    // loses stability at ω = 0.94525643 (frc.md, shooting) through the pair
    // e^{±iφ}; below it the response is quasi-periodic. The branch is
    // followed from that point with the box |k₁| ≤ 5, |k₂| ≤ 12 and the tori
    // at 0.93 and 0.90 refined until their estimates are ≤ 1e-7.
    let p = van_der_pol(0.2);
    let hb = HbOptions::new(12, 32);
    let ns = neimark_sacker(&p, &hb, 0.6, 1.6);
    assert!((ns.omega.unwrap() - 0.94525643).abs() < 1e-7);
    let req = torus_request(
        &ns,
        0.89,
        vec![0.93, 0.90],
        Truncation::Box { h1: 5, h2: 12 },
    );
    let curve = jobs::torus(&p, &hb, &req).unwrap();
    assert_eq!(curve.termination, Termination::LeftInterval);
    // The first torus has the Neimark–Sacker point's rotation φ/2π.
    let first = curve.points.first().unwrap();
    assert!((first.rotation_number - curve.angle / std::f64::consts::TAU).abs() < 1e-3);
    for omega in [0.93, 0.90] {
        let torus = at(&curve, omega);
        let r = vdp_reference(0.2, omega);
        let dev = deviations(torus, &r);
        let est = torus.errors.unwrap();
        eprintln!(
            "ω = {omega}: ρ {:.10} (ref {:.10}), mean |x| {:.10} (ref {:.10}), max |x| {:.10} (ref {:.10}); \
             |Δ| {dev:?}, estimates {est:?}, normal exponent {:?}",
            torus.rotation_number,
            r.rotation_number,
            torus.amplitude_mean,
            r.amplitude_mean,
            torus.amplitude_max,
            r.amplitude_max,
            torus.normal_exponent
        );
        // The acceptance: within 1e-5 of the Poincaré map.
        assert!(dev.iter().all(|d| *d < 1e-5), "{dev:?}");
        // The torus attracts (the integration found it).
        assert_eq!(torus.stable, Some(true));
        let section = torus.section.as_ref().unwrap();
        assert_eq!(section.x.0.len(), req.section_points);
    }
}

#[test]
fn the_error_estimate_covers_the_error_of_a_coarse_torus() {
    // The tori at 0.93 and 0.90 of the small box |k₁| ≤ 3, |k₂| ≤ 8, not
    // refined (tol ∞): each measure's estimate (its change to the box 4
    // orders wider) is at least its deviation from the time integration
    // (whose own error is below 1e-7 for ρ and the mean, 1e-6 for the max).
    let p = van_der_pol(0.2);
    let hb = HbOptions::new(12, 32);
    let ns = neimark_sacker(&p, &hb, 0.6, 1.6);
    let req = TorusRequest {
        tol: f64::INFINITY,
        ..torus_request(
            &ns,
            0.89,
            vec![0.93, 0.90],
            Truncation::Box { h1: 3, h2: 8 },
        )
    };
    let curve = jobs::torus(&p, &hb, &req).unwrap();
    for omega in [0.93, 0.90] {
        let torus = at(&curve, omega);
        let r = vdp_reference(0.2, omega);
        let dev = deviations(torus, &r);
        let e = torus.errors.unwrap();
        let est = [e.rotation_number, e.amplitude_mean, e.amplitude_max];
        eprintln!("ω = {omega}: |Δ| {dev:?}, estimates {est:?}");
        for ((d, e), floor) in dev.iter().zip(est).zip([1e-7, 1e-7, 1e-6]) {
            assert!(
                *d <= e + floor,
                "ω = {omega}: deviation {d:e} > estimate {e:e}"
            );
        }
    }
}

#[test]
fn a_torus_followed_in_the_force_matches_time_integration() {
    // The torus at ω = 0.93, F = 0.2 (the job's `at` torus) continued in F
    // at fixed ω down to F = 0.16 on the engine's stepper: there against
    // the time integration (acceptance-level 1e-5) in the refined `at`
    // torus's truncation.
    let p = van_der_pol(0.2);
    let hb = HbOptions::new(12, 32);
    let ns = neimark_sacker(&p, &hb, 0.6, 1.6);
    let req = torus_request(&ns, 0.92, vec![0.93], Truncation::Box { h1: 5, h2: 12 });
    let curve = jobs::torus(&p, &hb, &req).unwrap();
    // The refined torus (its estimate ≤ 1e-7) and its truncation.
    let start = at(&curve, 0.93);
    let options = TorusOptions {
        truncation: start.truncation,
        ..TorusOptions::default()
    };
    let family = |f: f64| (van_der_pol(f), 0.93);
    let mut branch =
        ivt_hb::branches::torus::TorusBranch::new(family, &options, 0.2, &start.coeffs.0).unwrap();
    let mut x0 = start.coeffs.0.clone();
    x0.extend([start.second_frequency, 0.2]);
    let mut copts = ivt_hb::ContinuationOptions {
        ds: 0.01,
        ds_max: 0.05,
        corrector: ivt_hb::Corrector::Newton,
        ..Default::default()
    };
    (copts.lambda_min, copts.lambda_max) = (0.16, 0.2);
    let (path, termination) = jobs::torus::follow(&mut branch, &x0, -1.0, &copts).unwrap();
    assert_eq!(termination, Termination::LeftInterval);
    let last = path.last().unwrap();
    let (&force, q) = last.split_last().unwrap();
    assert_eq!(force, 0.16);
    let m = branch.measures(q, force, 0).unwrap();
    let r = vdp_reference(0.16, 0.93);
    let dev = [
        (m.rotation_number - r.rotation_number).abs(),
        (m.amplitude_mean - r.amplitude_mean).abs(),
        (m.amplitude_max - r.amplitude_max).abs(),
    ];
    eprintln!("F = 0.16, ω = 0.93: {m:?} vs {r:?}: |Δ| {dev:?}");
    assert!(dev.iter().all(|d| *d < 1e-5), "{dev:?}");
}

/// The forced Rayleigh oscillator ẍ − μ(1 − ẋ²/3)ẋ + x = F cos ωt as Rust
/// elements: C = −μ and the cubic damper (μ/3)ẋ³.
fn rayleigh(extra: Option<Law>) -> ElementProblem {
    let mut elements = vec![Element {
        a: 0,
        b: None,
        law: Law::CubicDamper { c3: MU / 3.0 },
    }];
    elements.extend(extra.map(|law| Element { a: 0, b: None, law }));
    ElementProblem::new(
        1,
        [vec![1.0], vec![-MU], vec![1.0]],
        elements,
        vec![Harmonic {
            dof: 0,
            amplitude: 0.2,
            phase: 0.0,
        }],
    )
    .unwrap()
}

#[test]
fn a_torus_of_rust_elements_matches_time_integration_and_jenkins_is_refused() {
    let p = rayleigh(None);
    let hb = HbOptions::new(12, 32);
    let ns = neimark_sacker(&p, &hb, 0.6, 1.6);
    // Above its entrainment band: the torus leaves towards larger ω.
    let omega = ns.omega.unwrap() + 0.02;
    let req = torus_request(
        &ns,
        omega + 0.005,
        vec![omega],
        Truncation::Box { h1: 5, h2: 12 },
    );
    let curve = jobs::torus(&p, &hb, &req).unwrap();
    let torus = at(&curve, omega);
    let accel =
        move |t: f64, x: f64, v: f64| MU * (1.0 - v * v / 3.0) * v - x + 0.2 * (omega * t).cos();
    let r = reference(accel, omega, [0.5, 0.0], 300, 1500, 128);
    let dev = deviations(torus, &r);
    eprintln!(
        "Rayleigh, NS at {:.8}, ω = {omega:.8}: {dev:?}, estimate {:?}",
        ns.omega.unwrap(),
        torus.error_estimate
    );
    assert!(dev.iter().all(|d| *d < 1e-5), "{dev:?}");
    // A hysteretic element has no state along the torus's trajectories.
    let jenkins = rayleigh(Some(Law::Jenkins {
        k: 1.0,
        slip_force: 0.1,
    }));
    let multipliers: Vec<c64> = ns
        .multipliers
        .as_ref()
        .unwrap()
        .iter()
        .map(|m| c64::new(m[0], m[1]))
        .collect();
    let start = NeimarkSackerStart {
        coeffs: &ns.coeffs.as_ref().unwrap().0,
        harmonics: 12,
        lambda: ns.omega.unwrap(),
        multipliers: &multipliers,
    };
    let err = torus_start(
        Frequency(&jenkins),
        &start,
        &TorusOptions::default(),
        0.02,
        &LocateOptions::default(),
    )
    .err()
    .expect("refused");
    assert_eq!(err.kind(), "input");
    assert!(err.to_string().contains("hysteretic"), "{err}");
}
