//! The 2-DOF cubic chain of issue 17 and the guide's FRC chapter (M = I, K = [[2, −1],
//! [−1, 2]], C = 0.02 I, g = [0.5 x₁³, 0], f = [0.1 cos θ, 0]) with a Rust
//! element: shared by the tests and the benches (`#[path]`-included there).
#![allow(clippy::expect_used)]

use ivt_hb::{Element, ElementProblem, Harmonic, Law};

/// The chain as an [`ElementProblem`].
pub fn cubic_chain() -> ElementProblem {
    ElementProblem::new(
        2,
        [
            vec![1.0, 0.0, 0.0, 1.0],
            vec![0.02, 0.0, 0.0, 0.02],
            vec![2.0, -1.0, -1.0, 2.0],
        ],
        vec![Element {
            a: 0,
            b: None,
            law: Law::CubicSpring { k3: 0.5 },
        }],
        vec![Harmonic {
            dof: 0,
            amplitude: 0.1,
            phase: 0.0,
        }],
    )
    .expect("a valid chain")
}
