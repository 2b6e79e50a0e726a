//! The trapezoidal step generator against the closed-form trapezoid, and a
//! reversal in mid-move.
#![allow(clippy::indexing_slicing, clippy::unwrap_used)]

use ivt_ctrl::{StepGenerator, StepperLimits};

const F: f32 = 1.0e6;
const LIM: StepperLimits = StepperLimits {
    max_speed: 2000.0,
    accel: 20_000.0,
};

/// Tick the generator every timer tick until it rests at its target;
/// returns the step times.
fn run_to_rest(g: &mut StepGenerator, t0: u32, limit: u32) -> Vec<u32> {
    let mut times = Vec::new();
    for now in t0..t0 + limit {
        let d = g.tick(now);
        if d.step {
            times.push(now);
        }
        if !d.moving && d.position == g.target() {
            break;
        }
    }
    times
}

#[test]
fn move_time_matches_the_trapezoid() {
    // d = 1000 steps ≥ v²/a = 200: trapezoid time T = d/v + v/a = 0.5 + 0.1 s.
    let mut g = StepGenerator::new(LIM, F);
    g.set_target(1000);
    let times = run_to_rest(&mut g, 0, 2_000_000);
    assert_eq!(times.len(), 1000);
    let t = f64::from(times[999] - times[0]) / 1e6;
    // The first step is emitted at rest (x = 1 at t = 0 instead of at
    // √(2/a) = 0.01 s), so the span from step 1 to step 1000 is 0.59 s.
    // Austin's recurrence is exact to O(1/n²) after the corrected first step;
    // integer-tick truncation of each delay shortens it by < 1 tick per step
    // (≤ 0.2 ms over the ramps). Allow 1 %.
    assert!(
        (t - 0.59).abs() < 0.0059,
        "move took {t} s, trapezoid 0.59 s"
    );
    // Ramps: the acceleration phase is v²/(2a) = 100 steps; cruise at c_min = 500 ticks.
    let dts: Vec<u32> = times.windows(2).map(|w| w[1] - w[0]).collect();
    let cruise = dts.iter().filter(|&&d| d <= 500).count();
    assert!((790..=810).contains(&cruise), "cruise steps {cruise}");
    // Acceleration over windows of 10 steps never exceeds the limit by more
    // than the tick quantization allows: each interval is truncated to whole
    // ticks (≤ 1 tick), so v = f/dt is uncertain by v/dt and the window's
    // a by (v_i/dt_i + v_j/dt_j)/T. 5 % for Austin's approximation (after
    // its corrected first step).
    for i in 2..dts.len() - 10 {
        let (di, dj) = (f64::from(dts[i]), f64::from(dts[i + 10]));
        let (vi, vj) = (1e6 / di, 1e6 / dj);
        // From the middle of interval i to the middle of interval i + 10.
        let window = (f64::from(times[i + 10] - times[i]) + (dj - di) / 2.0) / 1e6;
        let a = (vj - vi) / window;
        let tol = 20_000.0 * 1.05 + (vi / di + vj / dj) / window;
        assert!(a.abs() <= tol, "a = {a} > {tol} at step {i}");
    }
}

#[test]
fn reversal_decelerates_then_returns() {
    let mut g = StepGenerator::new(LIM, F);
    g.set_target(1000);
    let mut now = 0u32;
    // Run until cruising (position ≥ 300), then command a target behind.
    while g.position() < 300 {
        g.tick(now);
        now += 1;
    }
    g.set_target(0);
    let mut max_pos = 0;
    let mut reversed_at_speed = false;
    let mut last_step: Option<(u32, bool)> = None;
    for t in now..now + 3_000_000 {
        let d = g.tick(t);
        max_pos = max_pos.max(d.position);
        if d.step {
            if let Some((t_prev, fwd_prev)) = last_step {
                // A change of direction must happen at the slowest step rate.
                if fwd_prev != d.forward && t - t_prev < 2000 {
                    reversed_at_speed = true;
                }
            }
            last_step = Some((t, d.forward));
        }
        if !d.moving && d.position == 0 {
            break;
        }
    }
    assert_eq!(g.position(), 0);
    // Stopping from 2000 steps/s at 20000 steps/s² takes ≈ v²/(2a) = 100 steps.
    assert!((395..=410).contains(&max_pos), "overshoot to {max_pos}");
    assert!(!reversed_at_speed);
}
