//! Frequency response of an oscillator with a friction damper, built from the
//! element library: `ẍ + 0.01ẋ + x + 0.05 tanh(ẋ/0.1) = 0.2 cos ω_f t`.
//!
//! `cargo run --release -p ivt-hb --example friction_damper` prints
//! `ω_f amplitude stable` along the curve 0.6 ≤ ω_f ≤ 1.4.
#![allow(clippy::expect_used)]

use ivt_hb::{frequency_response, Element, ElementProblem, FrcOptions, Harmonic, HbOptions, Law};

/// `ẍ + 0.01ẋ + x + 0.05 tanh(ẋ/0.1) = 0.2 cos ω_f t` (also the model of
/// `tests/elements.rs`).
pub fn damper() -> ElementProblem {
    let friction = Element {
        a: 0,
        b: None,
        law: Law::Coulomb {
            force: 0.05,
            v_reg: 0.1,
        },
    };
    let forcing = Harmonic {
        dof: 0,
        amplitude: 0.2,
        phase: 0.0,
    };
    ElementProblem::new(
        1,
        [vec![1.0], vec![0.01], vec![1.0]],
        vec![friction],
        vec![forcing],
    )
    .expect("valid model")
}

fn main() {
    let damper = damper();
    let opts = FrcOptions {
        from: 0.6,
        to: 1.4,
        ..FrcOptions::default()
    };
    let frc = frequency_response(&damper, &HbOptions::new(45, 256), &opts).expect("FRC");
    for p in &frc.points {
        println!("{:.5} {:.6} {}", p.omega_f, p.amplitude, p.stable());
    }
}
