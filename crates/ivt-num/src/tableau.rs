//! Explicit Runge–Kutta methods as data (Butcher tableaux).
//!
//! A method of `S` stages is its nodes `c`, its strictly lower-triangular
//! matrix `a` and its weights `b`; an embedded pair adds the error weights
//! `e = b − b̂`, and a method with dense output adds the weights `d` of
//! Hairer's quartic continuous extension (see [`crate::rk::ExplicitRk::dense`]).
//! The stepper skips zero coefficients, so a sparse tableau costs no more
//! than a hand-written kernel.

/// The Butcher tableau of an explicit Runge–Kutta method with `S` stages.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Tableau<const S: usize> {
    /// Order of the propagated solution.
    pub order: u32,
    /// Nodes c_i: stage i is evaluated at x + c_i h.
    pub c: [f64; S],
    /// Stage coefficients a_ij (j < i).
    pub a: [[f64; S]; S],
    /// Weights b_i of the propagated solution.
    pub b: [f64; S],
    /// Error weights e_i = b_i − b̂_i of the embedded lower-order solution.
    pub e: Option<[f64; S]>,
    /// Weights of the quartic term of the dense output (Hairer's CONTD5 form).
    pub d: Option<[f64; S]>,
    /// First same as last: the last stage is evaluated at the new state, so
    /// it is the first stage of the next step.
    pub fsal: bool,
}

/// The classical fourth-order method (Kutta 1901; Hairer–Nørsett–Wanner I,
/// Table II.1.2).
pub const RK4: Tableau<4> = Tableau {
    order: 4,
    c: [0.0, 0.5, 0.5, 1.0],
    a: [
        [0.0, 0.0, 0.0, 0.0],
        [0.5, 0.0, 0.0, 0.0],
        [0.0, 0.5, 0.0, 0.0],
        [0.0, 0.0, 1.0, 0.0],
    ],
    b: [1.0 / 6.0, 1.0 / 3.0, 1.0 / 3.0, 1.0 / 6.0],
    e: None,
    d: None,
    fsal: false,
};

/// Butcher's 7-stage, order-6 method (Butcher 1964; Hairer–Nørsett–Wanner I, §II.5).
pub const RK6: Tableau<7> = Tableau {
    order: 6,
    c: [0.0, 1.0 / 3.0, 2.0 / 3.0, 1.0 / 3.0, 0.5, 0.5, 1.0],
    a: [
        [0.0; 7],
        [1.0 / 3.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0],
        [0.0, 2.0 / 3.0, 0.0, 0.0, 0.0, 0.0, 0.0],
        [1.0 / 12.0, 1.0 / 3.0, -1.0 / 12.0, 0.0, 0.0, 0.0, 0.0],
        [
            -1.0 / 16.0,
            9.0 / 8.0,
            -3.0 / 16.0,
            -3.0 / 8.0,
            0.0,
            0.0,
            0.0,
        ],
        [0.0, 9.0 / 8.0, -3.0 / 8.0, -3.0 / 4.0, 0.5, 0.0, 0.0],
        [
            9.0 / 44.0,
            -9.0 / 11.0,
            63.0 / 44.0,
            18.0 / 11.0,
            0.0,
            -16.0 / 11.0,
            0.0,
        ],
    ],
    b: [
        11.0 / 120.0,
        0.0,
        27.0 / 40.0,
        27.0 / 40.0,
        -4.0 / 15.0,
        -4.0 / 15.0,
        11.0 / 120.0,
    ],
    e: None,
    d: None,
    fsal: false,
};

const DP5_B: [f64; 7] = [
    35.0 / 384.0,
    0.0,
    500.0 / 1113.0,
    125.0 / 192.0,
    -2187.0 / 6784.0,
    11.0 / 84.0,
    0.0,
];

/// The Dormand–Prince 5(4) pair with first-same-as-last and Hairer's
/// fourth-order dense output (Hairer–Nørsett–Wanner I, §II.5–6, DOPRI5).
pub const DP5: Tableau<7> = Tableau {
    order: 5,
    c: [0.0, 1.0 / 5.0, 3.0 / 10.0, 4.0 / 5.0, 8.0 / 9.0, 1.0, 1.0],
    a: [
        [0.0; 7],
        [1.0 / 5.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0],
        [3.0 / 40.0, 9.0 / 40.0, 0.0, 0.0, 0.0, 0.0, 0.0],
        [44.0 / 45.0, -56.0 / 15.0, 32.0 / 9.0, 0.0, 0.0, 0.0, 0.0],
        [
            19372.0 / 6561.0,
            -25360.0 / 2187.0,
            64448.0 / 6561.0,
            -212.0 / 729.0,
            0.0,
            0.0,
            0.0,
        ],
        [
            9017.0 / 3168.0,
            -355.0 / 33.0,
            46732.0 / 5247.0,
            49.0 / 176.0,
            -5103.0 / 18656.0,
            0.0,
            0.0,
        ],
        DP5_B,
    ],
    b: DP5_B,
    e: Some([
        71.0 / 57600.0,
        0.0,
        -71.0 / 16695.0,
        71.0 / 1920.0,
        -17253.0 / 339200.0,
        22.0 / 525.0,
        -1.0 / 40.0,
    ]),
    d: Some([
        -12715105075.0 / 11282082432.0,
        0.0,
        87487479700.0 / 32700410799.0,
        -10690763975.0 / 1880347072.0,
        701980252875.0 / 199316789632.0,
        -1453857185.0 / 822651844.0,
        69997945.0 / 29380423.0,
    ]),
    fsal: true,
};

#[cfg(test)]
mod tests {
    use super::*;

    /// Row sums of `a` equal the nodes `c`, the weights sum to one and the
    /// error weights to zero (consistency conditions, HNW I §II.1), for every
    /// tableau; an FSAL tableau's last row is its weights.
    #[test]
    fn tableaux_are_consistent() {
        fn check<const S: usize>(t: &Tableau<S>) {
            for i in 0..S {
                let row: f64 = t.a[i].iter().sum();
                assert!((row - t.c[i]).abs() < 1e-14, "row {i}: {row} vs {}", t.c[i]);
                assert!(t.a[i][i..].iter().all(|&x| x == 0.0), "explicit");
            }
            assert!((t.b.iter().sum::<f64>() - 1.0).abs() < 1e-14);
            if let Some(e) = t.e {
                assert!(e.iter().sum::<f64>().abs() < 1e-14);
            }
            if t.fsal {
                assert_eq!(t.a[S - 1], t.b);
            }
        }
        check(&RK4);
        check(&RK6);
        check(&DP5);
    }
}
