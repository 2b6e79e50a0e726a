//! Shooting on the thesis Duffing (Eq. 49) with RK4: the reference without HB
//! of the fold-curve and all-solutions tests.

use ivt_hb::ode::{first_order, rk4};
use ivt_hb::Duffing;
use std::f64::consts::PI;

/// RK4 steps per period of the period map.
pub const STEPS: usize = 4000;

/// The period map of `duffing` at ω: the state `y = (x, ẋ)` at t = 0 carried
/// over 2π/ω (RK4, [`STEPS`] steps).
pub fn period_map(duffing: &Duffing, omega: f64, y: [f64; 2]) -> [f64; 2] {
    let mut y = y;
    rk4(
        first_order(duffing, omega),
        0.0,
        &mut y,
        2.0 * PI / omega / STEPS as f64,
        STEPS,
    );
    y
}

/// ∂P/∂y − I of [`period_map`] at `y` by central differences (step 1e-6).
pub fn period_map_jacobian(duffing: &Duffing, omega: f64, y: [f64; 2]) -> [[f64; 2]; 2] {
    let h = 1e-6;
    let mut j = [[0.0; 2]; 2];
    for k in 0..2 {
        let (mut yp, mut ym) = (y, y);
        yp[k] += h;
        ym[k] -= h;
        let (a, b) = (
            period_map(duffing, omega, yp),
            period_map(duffing, omega, ym),
        );
        for i in 0..2 {
            j[i][k] = (a[i] - b[i]) / (2.0 * h) - f64::from(u8::from(i == k));
        }
    }
    j
}
