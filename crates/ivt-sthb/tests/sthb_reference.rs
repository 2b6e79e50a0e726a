//! The string curves of the solver before issue 28 (dense Newton, fold location
//! by finite-difference `∂g`, Hill on a full `2N(2M+1)` eigenproblem), saved as
//! reference values, and the current solver checked against them to 1e-10.
//!
//! How the references were made: `REFERENCE_OUT=path cargo test --release -p
//! ivt-hb --test sthb_reference -- --ignored regenerate` on commit b9a8621
//! (main before issue 28) writes `sthb_reference_data.txt`: for each case, every
//! point of `frequency_response` over ω ∈ [1, 6] (default options) re-solved at
//! its own ω by Newton to `‖R‖ ≤ 1e-12 (1 + y0)` from the curve point, its
//! `‖a‖`, the verdict and `|μ|` of its critical multiplier with the method, and
//! the located folds. The values are path independent: the check re-solves at
//! each reference ω from the nearest point of the new curve.
#![allow(clippy::indexing_slicing, clippy::panic, clippy::unwrap_used)]

use ivt_sthb::frc::{frequency_response, StringFrc, StringFrcOptions};
use ivt_sthb::stability::StabilityMethod;
use ivt_sthb::{StringHb, StringParams};
use std::fmt::Write as _;

/// The cases: (k_d, N, M).
const CASES: [(f64, usize, usize); 3] = [(10.0, 5, 19), (10.0, 10, 19), (30.0, 5, 19)];

fn params((kd, modes, harmonics): (f64, usize, usize)) -> StringParams {
    StringParams {
        kd,
        modes,
        harmonics,
        ..Default::default()
    }
}

/// `a` at `omega` by Newton from `guess`, `None` if it does not converge tightly.
fn resolve(hb: &mut StringHb, omega: f64, guess: &[f64]) -> Option<Vec<f64>> {
    let mut a = guess.to_vec();
    hb.solve(omega, &mut a, 1e-12, 12).ok().map(|_| a)
}

fn curve(case: (f64, usize, usize)) -> (StringHb, StringFrc) {
    let mut hb = StringHb::new(params(case)).unwrap();
    let frc = frequency_response(&mut hb, 1.0, 6.0, &StringFrcOptions::default()).unwrap();
    (hb, frc)
}

#[test]
#[ignore = "writes the reference file; run on the reference commit only"]
fn regenerate() {
    let out = std::env::var("REFERENCE_OUT").expect("REFERENCE_OUT=path");
    let mut text = String::new();
    for case in CASES {
        let (mut hb, frc) = curve(case);
        writeln!(text, "case {} {} {}", case.0, case.1, case.2).unwrap();
        for (p, method) in frc.frc.points.iter().zip(&frc.methods) {
            let Some(a) = resolve(&mut hb, p.omega_f, &p.coeffs) else {
                continue;
            };
            writeln!(
                text,
                "point {:?} {:?} {} {:?} {:?}",
                p.omega_f,
                hb.complex_norm(&a),
                p.kind.name(),
                p.multipliers[0].norm(),
                method
            )
            .unwrap();
        }
        for f in &frc.frc.events {
            writeln!(text, "fold {:?} {:?} {}", f.omega_f, f.amplitude, f.located).unwrap();
        }
    }
    std::fs::write(out, text).unwrap();
}

/// One case of the reference file: points `(ω, ‖a‖, kind, |μ|, method)` and
/// folds `(ω, ‖a‖)`.
struct Reference {
    case: (f64, usize, usize),
    points: Vec<(f64, f64, String, f64, String)>,
    folds: Vec<(f64, f64)>,
}

fn references() -> Vec<Reference> {
    let mut out: Vec<Reference> = Vec::new();
    for line in include_str!("sthb_reference_data.txt").lines() {
        let f: Vec<&str> = line.split_whitespace().collect();
        let num = |i: usize| f[i].parse::<f64>().unwrap();
        match f[0] {
            "case" => out.push(Reference {
                case: (num(1), f[2].parse().unwrap(), f[3].parse().unwrap()),
                points: Vec::new(),
                folds: Vec::new(),
            }),
            "point" => out.last_mut().unwrap().points.push((
                num(1),
                num(2),
                f[3].to_string(),
                num(4),
                f[5].to_string(),
            )),
            "fold" => out.last_mut().unwrap().folds.push((num(1), num(2))),
            other => panic!("bad line {other}"),
        }
    }
    out
}

#[test]
fn curves_equal_the_pre_issue_28_solver() {
    let refs = references();
    assert_eq!(refs.len(), CASES.len());
    for r in refs {
        let (mut hb, frc) = curve(r.case);
        let pts = &frc.frc.points;
        let norm_max = pts.iter().map(|p| p.amplitude).fold(0.0, f64::max);
        let (mut worst, mut kinds_checked) = (0.0f64, 0);
        for (omega, norm, kind, mu, method) in &r.points {
            // Re-solve at the reference ω from the nearest point of the new curve.
            let near = pts
                .iter()
                .min_by(|a, b| {
                    let d = |p: &ivt_hb::FrcPoint| {
                        ((p.omega_f - omega) / 5.0).hypot((p.amplitude - norm) / norm_max)
                    };
                    d(a).total_cmp(&d(b))
                })
                .unwrap();
            let a = resolve(&mut hb, *omega, &near.coeffs)
                .unwrap_or_else(|| panic!("{:?}: no solution at ω = {omega}", r.case));
            let err = (hb.complex_norm(&a) - norm).abs() / norm;
            worst = worst.max(err);
            assert!(err <= 1e-10, "{:?} ω = {omega}: ‖a‖ off by {err:e}", r.case);
            // The same stability function at the re-solved point: the same verdict
            // and |μ| to 1e-8 (RK4 of a solution 1e-10 away, different rounding).
            let s = match method.as_str() {
                "Hill" => ivt_sthb::stability::hill(&hb, *omega),
                _ => ivt_sthb::stability::monodromy(&hb, *omega),
            }
            .unwrap();
            assert_eq!(s.kind.name(), kind, "{:?} ω = {omega}", r.case);
            let dmu = (s.critical().norm() - mu).abs() / mu;
            assert!(dmu <= 1e-8, "{:?} ω = {omega}: |μ| off by {dmu:e}", r.case);
            kinds_checked += 1;
        }
        assert_eq!(kinds_checked, r.points.len());
        // Folds: the same count, located to 1e-10.
        assert_eq!(frc.frc.events.len(), r.folds.len(), "{:?}", r.case);
        for (f, (omega, norm)) in frc.frc.events.iter().zip(&r.folds) {
            assert!(f.located);
            let (dw, dn) = (
                (f.omega_f - omega).abs() / omega,
                (f.amplitude - norm).abs() / norm,
            );
            assert!(
                dw <= 1e-10 && dn <= 1e-10,
                "{:?} fold: ω {dw:e}, ‖a‖ {dn:e}",
                r.case
            );
        }
        // The new curve's own verdicts: each point's kind is the monodromy's or a
        // confirmation's at that point (same method list as the reference run).
        for (p, m) in pts.iter().zip(&frc.methods) {
            assert!(
                matches!(m, StabilityMethod::Monodromy | StabilityMethod::Hill),
                "{:?}: {m:?} at ω = {} below HILL_MAX_DIM",
                r.case,
                p.omega_f
            );
        }
        eprintln!("{:?}: worst ‖a‖ deviation {worst:e}", r.case);
    }
}
