//! Open-loop steady state of the plant (constant r): power balance over a
//! period, and convergence of the start-up transient to the unique periodic
//! ω(θ) of Theorems 1–2 (§4.2.2), checked against an independent reference
//! built here (shooting with fixed-step RK4 in the angle domain, Eq. 162).
// A test may index (the package's panic lints guard library code).
#![allow(clippy::indexing_slicing)]

use ivt_kin::plant::PlantParams;
use ivt_num::{ExplicitRk, RK4};
use ivt_sim::integrate::{ConstantInputs, Method, PlantIntegrator, Tolerance};
use ivt_sim::plant::{segment_of, Inputs, Plant};
use std::f64::consts::{FRAC_PI_2, FRAC_PI_4, PI};

const U: Inputs = Inputs {
    r: 0.006,
    v_m: 8.0,
    t_u: 6.0,
};

/// The constant inputs of [`U`].
const PROFILE: ConstantInputs = ConstantInputs {
    v_m: U.v_m,
    t_u: U.t_u,
};

/// Eq. 162 in the angle domain with the running integrals of the three powers
/// appended: `[t, ω, i_a, E_motor, E_load, E_loss]`.
struct WithEnergy<'a> {
    plant: &'a Plant,
    seg: i64,
}

impl WithEnergy<'_> {
    fn rhs(&self, theta: f64, z: &[f64], dz: &mut [f64]) {
        let y = [theta, z[1], z[2]];
        let d = self.plant.derivatives(self.seg, &y, &U);
        let p = self.plant.powers(self.seg, &y, &U);
        let inv = 1.0 / z[1];
        dz.copy_from_slice(&[
            inv,
            d[1] * inv,
            d[2] * inv,
            p[0] * inv,
            p[1] * inv,
            p[2] * inv,
        ]);
    }
}

/// Fixed-step RK4 over θ ∈ [θ0, θ0 + 2π] with `n` steps per gear segment,
/// θ0 on a corner so that every step lies inside one segment.
fn rk4_period(plant: &Plant, theta0: f64, omega0: f64, n: usize) -> ([f64; 6], Vec<(f64, f64)>) {
    let mut z = [0.0, omega0, 0.0, 0.0, 0.0, 0.0];
    let h = FRAC_PI_2 / n as f64;
    let mut samples = vec![(theta0, omega0)];
    let mut rk = ExplicitRk::<4, [f64; 6]>::new(&RK4);
    for q in 0..4 {
        let start = theta0 + q as f64 * FRAC_PI_2;
        let sys = WithEnergy {
            plant,
            seg: segment_of(start + 0.5 * h),
        };
        for k in 0..n {
            rk.step(
                &mut |x, z, dz| sys.rhs(x, z, dz),
                start + k as f64 * h,
                h,
                &mut z,
            );
            samples.push((start + (k + 1) as f64 * h, z[1]));
        }
    }
    (z, samples)
}

/// Periodic ω(θ) by shooting: secant iteration on ω(θ0) so that
/// ω(θ0 + 2π) = ω(θ0), each period by fine fixed-step RK4.
fn reference_periodic(plant: &Plant, theta0: f64, n: usize) -> (f64, Vec<(f64, f64)>) {
    let g = |w: f64| rk4_period(plant, theta0, w, n).0[1] - w;
    let (mut a, mut b) = (5.0, 15.0);
    let (mut ga, mut gb) = (g(a), g(b));
    for _ in 0..50 {
        let c = b - gb * (b - a) / (gb - ga);
        a = b;
        ga = gb;
        b = c;
        gb = g(b);
        if gb.abs() < 1e-14 * b {
            break;
        }
    }
    let (_, samples) = rk4_period(plant, theta0, b, n);
    (b, samples)
}

/// Over one steady period, ½J(r,θ)ω² changes by ∫(f1 + (G − f2)r − F_m ω)ω dt.
/// Kinetic energies come from the production DP5 integrator's end states;
/// the work integrals from an independent RK4 quadrature of the powers. The
/// residual is ≤ 1e-8 of the motor's input energy (acceptance, issue 6).
#[test]
fn power_balance_closes_over_a_steady_period() {
    let plant = Plant::new(PlantParams::printed());
    let prof = PROFILE;
    let tol = Tolerance::uniform(1e-12);
    let mut it = PlantIntegrator::new(plant, Method::Dp5(tol), 0.0, 0.0, 0.0, 0.0);
    let theta0 = FRAC_PI_4 + 20.0 * PI; // a corner, ten revolutions in
    it.advance(&prof, U.r, theta0, 1e9).unwrap();
    let (w0, t0) = (it.omega(), it.t);
    let ke0 = plant.kinetic_energy(theta0, w0, U.r);
    it.advance(&prof, U.r, theta0 + 2.0 * PI, 1e9).unwrap();
    let ke1 = plant.kinetic_energy(it.theta(), it.omega(), U.r);
    let (z, _) = rk4_period(&plant, theta0, w0, 4000);
    let work = z[3] + z[4] + z[5];
    let rel = ((ke1 - ke0) - work).abs() / z[3];
    assert!(
        rel <= 1e-8,
        "ΔKE = {}, work = {work}, rel = {rel:e}",
        ke1 - ke0
    );
    // and the period took the same time in both
    assert!(
        ((it.t - t0) - z[0]).abs() < 1e-9,
        "{} vs {}",
        it.t - t0,
        z[0]
    );
    // sanity: the motor does real work against load and losses
    assert!(z[3] > 10.0 && z[4] < 0.0 && z[5] < 0.0);
}

/// Theorems 1–2: from rest and from a fast start, the DP5 start-up transient
/// (time domain, then angle domain) converges to the same periodic ω(θ), equal
/// to the shooting reference to 1e-8 rad/s at 64 angles over the period.
/// The reference's own error (RK4, 4000 steps per segment, checked by
/// halving) is below 1e-11.
#[test]
fn start_up_converges_to_the_unique_periodic_solution() {
    let plant = Plant::new(PlantParams::printed());
    let theta0 = FRAC_PI_4;
    let (w_ref, samples) = reference_periodic(&plant, theta0, 4000);
    let (w_half, _) = reference_periodic(&plant, theta0, 2000);
    assert!(
        (w_ref - w_half).abs() < 1e-11,
        "reference not converged: {w_ref} vs {w_half}"
    );
    let prof = PROFILE;
    let tol = Tolerance::uniform(1e-11);
    for omega_start in [0.0, 30.0] {
        let mut it = PlantIntegrator::new(plant, Method::Dp5(tol), 0.0, 0.0, omega_start, 0.0);
        let base = theta0 + 30.0 * 2.0 * PI; // 30 revolutions of transient
        let mut worst: f64 = 0.0;
        for &(th, w) in samples.iter().step_by(250) {
            it.advance(&prof, U.r, base + (th - theta0), 1e9).unwrap();
            worst = worst.max((it.omega() - w).abs());
        }
        assert!(
            worst <= 1e-8,
            "start ω = {omega_start}: max |Δω| = {worst:e}"
        );
    }
    // the periodic solution is a real oscillation, not a constant
    let (lo, hi) = samples
        .iter()
        .fold((f64::MAX, f64::MIN), |(lo, hi), &(_, w)| {
            (lo.min(w), hi.max(w))
        });
    assert!(hi - lo > 0.1, "ω range {lo}..{hi}");
}

/// Eq. 137 with a small armature inductance tends to Eq. 151 (L_a → 0): the
/// steady ω_a over a revolution differs from the L_a = 0 plant by an amount
/// that shrinks ∝ L_a (the electrical lag τ = L_a/R_a), here by ≈ 10× per
/// decade, and the current ends near its quasi-static value.
#[test]
fn inductance_tends_to_the_quasi_static_motor() {
    let prof = PROFILE;
    let tol = Tolerance::uniform(1e-10);
    let omega_a = |l_a: f64| {
        let mut params = PlantParams::printed();
        params.l_a = l_a;
        let plant = Plant::new(params);
        let i0 = plant.quasi_static_current(0.0, 10.0, U.v_m);
        let mut it = PlantIntegrator::new(plant, Method::Dp5(tol), 0.0, 0.0, 10.0, i0);
        it.advance(&prof, U.r, 20.0 * PI, 1e9).unwrap();
        let t0 = it.t;
        it.advance(&prof, U.r, 22.0 * PI, 1e9).unwrap();
        let i_qs = plant.quasi_static_current(it.theta(), it.omega(), U.v_m);
        (2.0 * PI / (it.t - t0), (it.y[2] - i_qs).abs() / i_qs.abs())
    };
    let (w0, _) = omega_a(0.0);
    let (w4, di4) = omega_a(1e-4);
    let (w5, di5) = omega_a(1e-5);
    let (d4, d5) = ((w4 - w0).abs(), (w5 - w0).abs());
    assert!(
        d4 > 0.0 && d5 < d4 / 5.0 && d5 < 1e-3,
        "Δω_a: {d4:e} (1e-4 H), {d5:e} (1e-5 H)"
    );
    assert!(di5 < di4 && di5 < 0.05, "current lag {di4} {di5}");
}
