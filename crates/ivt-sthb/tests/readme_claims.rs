//! The defaults the guide quotes (docs/guide/src/model/string.md;
//! crates/ivt-sthb/README.md points there): the STHB string of §3.3.4.

use ivt_sthb::{Boundary, StringParams};

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
