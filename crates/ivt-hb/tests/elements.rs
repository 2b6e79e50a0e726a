//! The element library in use: the friction-damper FRC of
//! `examples/friction_damper.rs` against time integration.

use ivt_hb::orbit::aft::eval_series;
use ivt_hb::problem::ode::{first_order, rk4};
use ivt_hb::{frequency_response, FrcOptions, HbOptions, HbSolution, ModifiedIhb};

// The example's model, shared so that the test checks exactly what it shows.
#[path = "../examples/friction_damper.rs"]
#[allow(dead_code)]
mod example;
use example::damper;

#[test]
fn friction_damper_frc_matches_time_integration() {
    let p = damper();
    let hb = HbOptions::new(45, 256);
    let opts = FrcOptions {
        from: 0.6,
        to: 1.4,
        ..FrcOptions::default()
    };
    let frc = frequency_response(&p, &hb, &opts).unwrap();
    assert!(
        frc.points.len() > 10 && frc.events.is_empty(),
        "{:?}",
        frc.events
    );
    // Friction bounds the resonance: the peak amplitude is finite and the
    // damped linear response 0.2/0.01 = 20 is far away.
    let peak = frc.points.iter().fold(0.0f64, |a, q| a.max(q.amplitude));
    assert!(peak > 1.0 && peak < 20.0, "{peak}");
    for w in [0.8, 1.0, 1.2] {
        // HB at ω_f (from the linear guess), then RK4 (2000 steps per period)
        // from the HB state for 20 periods: the stable orbit is followed.
        let sol: HbSolution = ModifiedIhb::new(&p, hb.clone())
            .unwrap()
            .solve(w, None)
            .unwrap();
        let period = 2.0 * std::f64::consts::PI / w;
        let mut y = [sol.x_at(0, 0.0), w * eval_series(sol.dof(0), 0.0, 1)];
        let mut dev = 0.0f64;
        let dt = period / 32.0;
        for j in 0..20 * 32 {
            rk4(first_order(&p, w), j as f64 * dt, &mut y, dt / 64.0, 64);
            dev = dev.max((y[0] - sol.x_at(0, (j + 1) as f64 * dt)).abs());
        }
        let amp = sol.amplitude(0);
        // Measured 2e-10, 3.6e-6 (the resonance, amplitude 13.6, where the
        // tanh transition is shortest) and 1.6e-9 relative at ω_f = 0.8, 1, 1.2.
        assert!(dev < 1e-4 * amp, "ω_f {w}: {dev:e} vs amplitude {amp}");
    }
}
