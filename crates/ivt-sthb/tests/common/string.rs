//! The string of §3.3 solved from rest at one ω: shared by the STHB tests
//! and benches (`#[path]`-included there).
#![allow(clippy::unwrap_used)]

use ivt_sthb::{StringHb, StringParams};

/// The string with `modes` sine modes, `harmonics` harmonics and the spring
/// `kd` (the other parameters the default's), solved by Newton from rest at
/// `omega` to `tol`: the solver and the coefficients.
pub fn solved(
    modes: usize,
    harmonics: usize,
    kd: f64,
    omega: f64,
    tol: f64,
) -> (StringHb, Vec<f64>) {
    let mut hb = StringHb::new(StringParams {
        modes,
        harmonics,
        kd,
        ..Default::default()
    })
    .unwrap();
    let mut a = vec![0.0; hb.dim()];
    hb.solve(omega, &mut a, tol, 50).unwrap();
    (hb, a)
}
