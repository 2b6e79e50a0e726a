//! The plant's view of the one Runge–Kutta layer ([`ivt_num`]): systems
//! `y' = F(x, y)` with a fixed-size state, returned by value.
//!
//! The time- and angle-domain systems in [`crate::integrate`] both wrap
//! [`crate::plant::Plant::derivatives`]; the stepping (RK4, the
//! Dormand–Prince 5(4) pair with dense output) is [`ivt_num::ExplicitRk`].

pub use ivt_num::Tolerance;
use ivt_num::{ExplicitRk, RK4};

/// A first-order system `y' = F(x, y)` of dimension `N`.
pub trait OdeSystem<const N: usize> {
    /// The right-hand side F(x, y).
    fn rhs(&self, x: f64, y: &[f64; N]) -> [f64; N];
}

/// `sys` as the right-hand side `rhs(x, y, dy)` of the stepper.
#[inline(always)]
pub fn as_rhs<S: OdeSystem<N>, const N: usize>(
    sys: &S,
) -> impl FnMut(f64, &[f64], &mut [f64]) + '_ {
    move |x, y, dy| {
        let y: &[f64; N] = y.try_into().expect("state of dimension N");
        dy.copy_from_slice(&sys.rhs(x, y));
    }
}

/// One classical fourth-order Runge–Kutta step of size `h`.
pub fn rk4_step<S: OdeSystem<N>, const N: usize>(
    sys: &S,
    x: f64,
    y: &[f64; N],
    h: f64,
) -> [f64; N] {
    let mut y1 = *y;
    ExplicitRk::<4, [f64; N]>::new(&RK4).step(&mut as_rhs(sys), x, h, &mut y1);
    y1
}
