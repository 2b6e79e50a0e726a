//! The defaults the guide quotes (docs/guide/src/model/orbit.md;
//! crates/ivt-hb/README.md points there): Broyden, HB options, Hsu rule.
//! (The STHB string's: ivt-sthb's tests/readme_claims.rs.)

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
