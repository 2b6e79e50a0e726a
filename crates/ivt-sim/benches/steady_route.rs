//! The two routes to `scenes/steady_state.toml` (issue 7, item 7): the IHB
//! periodic steady state (with and without the delay-loop stability check it
//! makes inside the band) against the closed-loop time integration of the
//! same scene (20 s from ω = 10 rad/s, last revolution measured). Also the
//! saturated case (V_m = 7 V, T_U = 8 N·m), where the route adds a secant
//! on ω0 over IHB solves.
// A bench may expect (the package's panic lints guard library code).
#![allow(clippy::expect_used)]

use ivt_sim::run::Simulation;
use ivt_sim::scene::Scene;
use ivt_sim::steady::{ihb_steady_state, Route};
use ivt_sim::testing::shipped_scene;

fn main() {
    divan::main();
}

fn scene() -> Scene {
    shipped_scene("steady_state.toml")
}

fn saturated() -> Scene {
    let mut s = scene();
    s.inputs.v_m = vec![[0.0, 7.0]];
    s.inputs.t_u = vec![[0.0, 8.0]];
    s
}

/// What `ivt sim scenes/steady_state.toml` computes (route "auto" → IHB).
#[divan::bench(sample_count = 20)]
fn ihb_route(b: divan::Bencher) {
    let s = scene();
    b.bench(|| Simulation::new(&s).answer().expect("answers"));
}

/// The same scene forced through the time integration.
#[divan::bench(sample_count = 10)]
fn time_route(b: divan::Bencher) {
    bench_time_route(b, &scene());
}

/// Under-drive: r = 0 held, mean speed by secant over IHB solves.
#[divan::bench(sample_count = 20)]
fn ihb_route_saturated(b: divan::Bencher) {
    let s = saturated();
    b.bench(|| ihb_steady_state(&s).expect("answers"));
}

/// Under-drive through the time integration (20 s).
#[divan::bench(sample_count = 10)]
fn time_route_saturated(b: divan::Bencher) {
    bench_time_route(b, &saturated());
}

/// Times the answer of `s` forced through the time integration.
fn bench_time_route(b: divan::Bencher, s: &Scene) {
    b.bench(|| {
        Simulation::new(s)
            .route(Some(Route::TimeIntegration))
            .answer()
            .expect("runs")
    });
}
