//! Acceptance (issue 5): f32 controller vs an f64 reference over 10⁶ pulses;
//! the integral law removes a static error on a first-order surrogate plant;
//! anti-windup recovers within one revolution after leaving saturation.
#![allow(clippy::indexing_slicing, clippy::unwrap_used)]

mod common;
use common::{ticks_at, u_ol_f64, RefLaw, Reference, Surrogate};
use ivt_ctrl::{units, Config, Controller, Gains, LawKind, THESIS};
use std::f64::consts::TAU;

const PPR: usize = 1200;
const F_TIMER: f64 = 1.0e6;

fn config(law: LawKind) -> Config {
    Config {
        f_timer_hz: F_TIMER as f32,
        law,
        // §4.3's faster pair (0.06, 0.12 mm·rad⁻¹; eigenvalue 0.4871 at 7 V / 2 N·m).
        gains: Gains::from_thesis_mm_per_rad(0.06, 0.12),
        stall_timeout_s: 2.0,
        ..Config::default()
    }
}

/// (V_m, T_U) for revolution `rev`: a piecewise-constant schedule whose
/// steady-state r lies inside (0, r_max) on the surrogate (see `Surrogate::new`).
fn schedule(rev: usize) -> (f64, f64) {
    const STEPS: [(f64, f64); 5] = [(8.0, 8.0), (8.0, 6.0), (7.8, 8.0), (7.5, 5.0), (8.2, 9.0)];
    STEPS[(rev / 170) % STEPS.len()]
}

/// The f64 reference runs the loop; the f32 controller replays the same
/// timestamps and inputs. Bound on |r32 − r64| (derivation):
/// - u_ol: f32 Horner vs f64 on the same coefficients, ≤ 3e-7 m (unit test
///   `thesis_polynomial_matches_printed_terms`); it enters r directly.
/// - r_d: each increment carries f32 rounding of ω_a, ω, ω_T (≤ 4·2⁻²⁴
///   relative, ~3e-6 rad/s) and of ω0·Δθ; in the loop the speed error averages
///   to zero, so only the constant part accumulates: the 2π·f_timer constant
///   (≤ 2⁻²⁴·ω0 ≈ 6e-7 rad/s) times k·θ_total = 6e-5·(833·2π) ≈ 0.31 m·s/rad
///   → ≤ 2e-7 m; the rest is a random walk (√10⁶ · 3e-12 m ≈ 3e-9 m). The
///   Kahan-compensated sum keeps the summation error at O(ulp(r_d)) = 1e-9 m.
/// - Total: 3e-7 + 2e-7 + small ⇒ assert ≤ 6e-7 m, i.e. half a microstep of
///   the SGIVT map at 3200 steps/rev (1.2 µm per microstep) and 5e-5 of r_max.
#[test]
fn f32_matches_f64_reference_over_a_million_pulses() {
    let cfg = config(LawKind::Delay);
    let mut ctrl = Controller::<PPR>::new(cfg);
    let k = f64::from(cfg.gains.k);
    let k2 = f64::from(cfg.gains.k2);
    // The reference uses the controller's parameters (f32 values, exactly in f64).
    let omega0 = f64::from(cfg.omega0);
    let mut reference = Reference::new(
        PPR,
        F_TIMER,
        omega0,
        RefLaw::Delay { k, k2 },
        f64::from(THESIS.r_max),
    );
    let mut plant = Surrogate::new(omega0);
    let dtheta = TAU / PPR as f64;
    let mut inputs = (f64::NAN, f64::NAN);
    let mut r = 0.0;
    let mut max_diff = 0.0f64;
    let mut end_diff = 0.0;
    let mut sat_pulses = 0u32;
    let n = 1_000_000usize;
    for i in 0..n {
        let now = schedule(i / PPR);
        if now != inputs {
            inputs = now;
            ctrl.update_inputs(now.0 as f32, now.1 as f32);
            reference.r_ol = u_ol_f64(&THESIS, now.0, now.1);
        }
        let t = plant.advance(dtheta, r, inputs.0, inputs.1);
        let tk = ticks_at(t, F_TIMER, 0);
        let o64 = reference.on_pulse(tk);
        let o32 = ctrl.on_pulse(tk);
        r = o64.r;
        let d = (f64::from(o32.r) - o64.r).abs();
        max_diff = max_diff.max(d);
        end_diff = d;
        sat_pulses += u32::from(o32.saturated);
    }
    println!("10⁶ pulses: max |r32 − r64| = {max_diff:.3e} m, at the end {end_diff:.3e} m, saturated pulses {sat_pulses}");
    assert!(max_diff <= 6e-7, "max |Δr| = {max_diff:e}");
    // The run must exercise the integrator (not sit at a bound).
    assert!(sat_pulses < (n / 10) as u32);
}

/// Closed loop of the f32 controller on the surrogate; returns per-pulse
/// (ω_a, r) and calls `inputs(rev)` each revolution. Checks on every pulse
/// that the integrator never winds beyond the bounds (r_d ∈ [−u_ol, r_max − u_ol]).
fn run(law: LawKind, revs: usize, inputs: impl Fn(usize) -> (f64, f64)) -> Vec<(f32, f32)> {
    let cfg = config(law);
    let mut ctrl = Controller::<PPR>::new(cfg);
    let mut plant = Surrogate::new(f64::from(cfg.omega0));
    let dtheta = TAU / PPR as f64;
    let mut r = f64::from(ctrl.output().r);
    let mut log = Vec::with_capacity(revs * PPR);
    for i in 0..revs * PPR {
        let (v, t_u) = inputs(i / PPR);
        if i % PPR == 0 {
            ctrl.update_inputs(v as f32, t_u as f32);
        }
        let t = plant.advance(dtheta, r, v, t_u);
        let o = ctrl.on_pulse(ticks_at(t, F_TIMER, 0));
        assert!(
            o.r_d >= -o.r_ol && o.r_d <= ctrl.r_max() - o.r_ol,
            "wound up at {i}: {o:?}"
        );
        r = f64::from(o.r);
        log.push((o.omega_a, o.r));
    }
    log
}

/// A load step 8 → 6 N·m at revolution 20 (V_m = 8 V). Open loop alone
/// leaves a static error; Eq. 180 removes it.
#[test]
fn integral_law_removes_static_error_after_load_step() {
    let omega0 = units::rpm_to_rad_s(100.0);
    let load = |rev: usize| if rev < 20 { (8.0, 8.0) } else { (8.0, 6.0) };
    let closed = run(LawKind::Delay, 400, load);
    let open = run(LawKind::Open, 400, load);
    let last = |log: &[(f32, f32)]| log[log.len() - 1];
    let err_closed = (last(&closed).0 - omega0).abs() / omega0;
    let err_open = (last(&open).0 - omega0).abs() / omega0;
    println!("static error of ω_a: open loop {err_open:.3e}, Eq. 180 {err_closed:.3e}");
    // Open loop: u_ol(8, 6) = 0.009694 m (Eq. 158) while the surrogate needs
    // (12 − 10.472)/150 = 0.010187 m; it settles at ω̄ = 12 − 150·0.009694 =
    // 10.5459 rad/s, and ω_a is the harmonic mean of ω̄(1 + 0.02 sin 4θ),
    // ω̄·√(1 − 0.02²) = 10.5438 rad/s → error 6.86e-3 (quantization ≪ 1e-5).
    let predicted = (12.0 - 150.0 * 0.009694) * (1.0f64 - 0.02 * 0.02).sqrt();
    let predicted_err = (predicted - f64::from(omega0)) / f64::from(omega0);
    assert!(
        (f64::from(err_open) - predicted_err).abs() < 2e-5,
        "{err_open} vs {predicted_err}"
    );
    // Closed loop: within 1e-4 (50× the 1 MHz quantization bound 1.7e-6).
    assert!(err_closed < 1e-4, "{err_closed:e}");
}

/// V_m drops to 6.5 V (free speed 9.75 rad/s < ω0: infeasible, r pinned at 0)
/// for 40 revolutions, then returns to 8 V. Without anti-windup r_d would have
/// integrated k·Δω·2π·40 ≈ 6e-5·0.72·251 ≈ 11 mm below the bound and need tens
/// of revolutions to unwind; with it, r must leave 0 within one revolution
/// of the feasible band being re-entered.
#[test]
fn anti_windup_recovers_within_one_revolution() {
    let step_back = 100;
    let log = run(LawKind::Delay, 300, |rev| {
        if (60..step_back).contains(&rev) {
            (6.5, 8.0)
        } else {
            (8.0, 8.0)
        }
    });
    let start = step_back * PPR;
    assert!(
        log[start - 1].1 == 0.0,
        "r not saturated at 0 before the step back: {}",
        log[start - 1].1
    );
    let leave = log[start..].iter().position(|&(_, r)| r > 1e-5).unwrap();
    println!(
        "r left saturation {leave} pulses ({:.2} rev) after V_m returned",
        leave as f64 / PPR as f64
    );
    assert!(leave <= PPR, "left saturation after {leave} pulses");
    let omega0 = units::rpm_to_rad_s(100.0);
    let end = log[log.len() - 1].0;
    assert!((end - omega0).abs() / omega0 < 1e-3, "ω_a = {end}");
}
