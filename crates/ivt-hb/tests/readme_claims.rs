//! The defaults the guide quotes (docs/guide/src/model/orbit.md and
//! string.md; crates/ivt-hb/README.md points there): Broyden, HB options, Hsu
//! rule, the STHB string of §3.3.4.

use ivt_hb::sthb::{Boundary, StringParams};
use ivt_hb::{BroydenOptions, HbOptions, HsuRule};

/// `BroydenOptions`: tol 1e-10, max_iter 100, max_backtracks 8.
#[test]
fn broyden_defaults_are_the_readme_values() {
    let b = BroydenOptions::default();
    assert_eq!((b.tol, b.max_iter, b.max_backtracks), (1e-10, 100, 8));
    assert!(b.jacobian_refresh);
}

/// `HbOptions`: atol = broyden.tol = 0, rtol 1e-9, max_iter 100; the
/// default Hsu rule is the 4th-order Magnus step.
#[test]
fn hb_defaults_are_the_readme_values() {
    let o = HbOptions::default();
    assert_eq!(
        (o.broyden.tol, o.rtol, o.broyden.max_iter),
        (0.0, 1e-9, 100)
    );
    assert_eq!(o.subharmonic, 1);
    assert_eq!(HsuRule::default(), HsuRule::Magnus4);
}

/// `StringParams::default()` = §3.3.4, whose text prints "c_d = 0.8,
/// y_0 = 0.5, M = 19, N_s = 64 and M_s = 128", k_d = 10 for the weak case and
/// N = 5 (Fig. 34); fixed ends.
#[test]
fn string_defaults_are_section_3_3_4() {
    let p = StringParams::default();
    assert_eq!((p.kd, p.cd, p.y0), (10.0, 0.8, 0.5));
    assert_eq!((p.modes, p.harmonics, p.ns, p.ms), (5, 19, 64, 128));
    assert!(matches!(p.boundary, Boundary::Fixed));
}
