//! The refitted open-loop law (REFIT, the default since SPEC §5) against the
//! printed one (THESIS) as the feed-forward of the delay law Eq. 180, on the
//! printed plant: load steps at three points of the feasible band.
//!
//! Why REFIT must win: Eq. 180 is `r = u_ol + r_d`, so after an input step
//! the integral r_d has to make up `r̄(new) − u_ol(new)`. REFIT is fitted to
//! r̄ (RMS error 4e-5 m), so r_d barely moves. THESIS asks for r_max
//! (over-drive) at most of the band (Eq. 159's boundary V_m = 1.579 T_U + 0.632
//! lies far above it), so u_ol does not change across the step and r_d alone
//! must travel the whole Δr̄ at the loop's rate — the transient of the
//! no-feed-forward loop. Same gains (k = 2, k2 = 1 mm·rad⁻¹), same stepper.
// A test may index and unwrap (the package's panic lints guard library code).
#![allow(clippy::indexing_slicing, clippy::unwrap_used)]

use ivt_sim::record::Channel;
use ivt_sim::run::{RunResult, Simulation};
use ivt_sim::scene::{ChannelSpec, OpenLoopLaw, Scene};
use std::path::PathBuf;

fn load_step(v_m: f64, t_from: f64, t_to: f64, open_loop: OpenLoopLaw, gains: (f64, f64)) -> Scene {
    let p = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../scenes/load_step_delay.toml");
    let mut s = Scene::load(&p).unwrap();
    s.duration_s = 12.0;
    s.inputs.v_m = vec![[0.0, v_m]];
    s.inputs.t_u = vec![[0.0, t_from], [6.0, t_from], [6.01, t_to]];
    s.controller.feedforward = true;
    s.controller.open_loop = open_loop;
    (s.controller.k_mm_per_rad, s.controller.k2_mm_per_rad) = gains;
    s.metrics.from_s = 6.0;
    s.metrics.static_window_s = 2.0;
    s.outputs = Default::default();
    s.outputs.channels = vec![ChannelSpec {
        name: Channel::Plant,
        every: 1,
    }];
    s
}

/// (∫|ω_a − ω0| dt over [6, 12] s, max |ω_a − ω0| there) in (rad, rad/s).
fn transient(res: &RunResult) -> (f64, f64) {
    let w0 = res.summary.omega0_rad_s;
    let p = res.channels.plant.as_ref().unwrap();
    let (mut iae, mut peak) = (0.0, 0.0f64);
    for w in p.windows(2) {
        if w[0].t >= 6.0 {
            let e = (w[1].omega_a - w0).abs();
            iae += e * (w[1].t - w[0].t);
            peak = peak.max(e);
        }
    }
    (iae, peak)
}

/// Three band points (band at 100 rpm: V_m ∈ [7.869, 7.869 + 0.1537 T_U]),
/// two gain sets. Measured (IAE over the 6 s after the step, peak |ω_a − ω0|):
///
/// | gains k, k2 | point | IAE REFIT / THESIS [rad] | peak REFIT / THESIS [rad/s] |
/// |---|---|---|---|
/// | 2, 1 (scenes) | 8.6 V, 6 → 8 | 0.103 / 0.125 (1.2×) | 0.113 / 0.152 |
/// | 2, 1 | 8.3 V, 3 → 5 | 0.211 / 0.189 (0.9×) | 0.198 / 0.239 |
/// | 2, 1 | 8.0 V, 1.5 → 3 | 0.072 / 0.183 (2.6×) | 0.073 / 0.150 |
/// | 0.01, 0.02 (thesis) | 8.6 V, 6 → 8 | 0.126 / 0.353 (2.8×) | 0.098 / 0.199 |
/// | 0.01, 0.02 | 8.3 V, 3 → 5 | 0.151 / 2.19 (15×) | 0.187 / 0.400 |
/// | 0.01, 0.02 | 8.0 V, 1.5 → 3 | 0.069 / 2.46 (36×) | 0.062 / 0.433 |
///
/// With the thesis's slow gains the feed-forward is what moves r, and REFIT
/// wins by 3–36× in IAE (THESIS has not settled 6 s after two of the steps).
/// With the fast scene gains the integral already settles in about a
/// revolution, and ω_a (a one-revolution mean) lags the plant by that much
/// anyway: REFIT still lowers the peak at every point (by 17–52 %), but the
/// IAE is not reliably smaller (0.9× at 8.3 V, where feed-forward and the
/// fast integral overshoot together). Asserted: peak smaller at every point
/// and gain set; IAE at least 2× smaller with the thesis's gains.
#[test]
fn refit_feedforward_shrinks_the_step_transient() {
    for (gains, min_iae_ratio) in [((2.0, 1.0), None), ((0.01, 0.02), Some(2.0))] {
        for (v, a, b) in [(8.6, 6.0, 8.0), (8.3, 3.0, 5.0), (8.0, 1.5, 3.0)] {
            let refit = Simulation::new(&load_step(v, a, b, OpenLoopLaw::Refit, gains))
                .run()
                .unwrap();
            let thesis = Simulation::new(&load_step(v, a, b, OpenLoopLaw::Thesis, gains))
                .run()
                .unwrap();
            let (iae_r, peak_r) = transient(&refit);
            let (iae_t, peak_t) = transient(&thesis);
            eprintln!(
                "k, k2 = {gains:?}, V_m = {v} V, T_U {a} → {b} N·m: IAE refit {iae_r:.4e} vs thesis {iae_t:.4e} rad ({:.1}×), peak {peak_r:.4} vs {peak_t:.4} rad/s, settling {:?} vs {:?} s",
                iae_t / iae_r,
                refit.summary.settling_time_s,
                thesis.summary.settling_time_s
            );
            assert!(peak_r < peak_t, "peak {peak_r} vs {peak_t}");
            if let Some(ratio) = min_iae_ratio {
                assert!(iae_t > ratio * iae_r, "IAE {iae_r} vs {iae_t}");
            }
        }
    }
}
