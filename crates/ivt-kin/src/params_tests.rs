//! The table itself: every key once with an ordered range, every alias
//! pointing at a key, messages as typed. (That each boundary refuses through
//! it is tested at the boundaries: ivt-sim's scene tests, the CLI's
//! tests/boundary.rs, ivt-py's test_boundary.py.)

extern crate std;

use super::*;
use std::string::{String, ToString};

fn refused(name: &str, value: f64) -> String {
    check(name, value).unwrap_err().to_string()
}

#[test]
fn every_key_once_with_an_ordered_range() {
    for (i, k) in KEYS.iter().enumerate() {
        assert!(
            KEYS.iter().skip(i + 1).all(|o| o.name != k.name),
            "{} twice",
            k.name
        );
        assert!(k.min.value() < k.max.value(), "{}", k.name);
        assert!(k.min.value().is_finite() && k.max.value().is_finite());
    }
}

/// Every key is set by a scene or by at least one flag or argument, and every
/// alias names a key and appears once.
#[test]
fn every_key_reachable_and_every_alias_described() {
    for k in KEYS {
        assert!(
            k.scene || ALIASES.iter().any(|a| a.key == k.name),
            "{} is set by no boundary",
            k.name
        );
    }
    for (i, a) in ALIASES.iter().enumerate() {
        assert!(find(a.key).is_some(), "{a:?}");
        assert!(!ALIASES.iter().skip(i + 1).any(|o| o == a), "{a:?} twice");
        assert_eq!(
            check_as(a.boundary, a.name, a.key, f64::NAN)
                .unwrap_err()
                .key,
            find(a.key)
        );
    }
    // an alias outside the table is refused, not checked against a guess
    let e = check_as(Boundary::Cli, "--k", "controller.omega0_rpm", 1.0).unwrap_err();
    assert_eq!(e.key, None);
    assert!(e.to_string().contains("no description"), "{e}");
}

#[test]
fn values_as_typed_and_f32_overflow() {
    let e = refused("controller.k_mm_per_rad", 1e300);
    assert!(e.contains("= 1e300 mm/rad") && e.contains("f32"), "{e}");
    let e = refused("integrator.rtol", 1e-300);
    assert_eq!(e, "= 1e-300 is outside [1e-14, 1)");
    let e = refused("duration_s", 1e7);
    assert_eq!(e, "= 1e7 s is outside (0, 1e6] s");
    let e = refused("kin.theta_ct_deg", 3600.0000001);
    assert_eq!(e, "= 3600.0000001 deg is outside [0, 3600] deg");
    assert_eq!(Typed(3600.0000001).to_string(), "3600.0000001");
    assert_eq!(Typed(0.01).to_string(), "0.01");
    assert_eq!(Typed(-2.5).to_string(), "-2.5");
    assert_eq!(Typed(1e6).to_string(), "1e6");
    assert_eq!(Typed(100.0).to_string(), "100");
    assert_eq!(Typed(1e-300).to_string(), "1e-300");
    assert!(check("inputs.t_u[]", f64::NAN).is_err());
    assert!(check("controller.omega0_rpm", 100.0).is_ok());
    // 1e-50 is representable as f64 but flushes to 0 in f32
    assert!(!fits_f32(1e-50) && fits_f32(0.0) && fits_f32(-3.0e38));
    // the bounds NOT_F32 states are f32's own
    assert!(NOT_F32.contains(&std::format!("[{:e}, {:e}]", f32::MIN_POSITIVE, f32::MAX)));
    assert!(check("no.such.key", 1.0).is_err());
}

/// Open and closed bounds are honoured at the bound itself.
#[test]
fn bounds_at_the_edge() {
    assert!(check("plant.r_u", 0.0).is_err());
    assert!(check("plant.m_r", 0.0).is_ok());
    assert!(check("plant.m_r", -1e-300).is_err());
    assert!(check("kin.theta_ct_deg", 3600.0).is_ok());
    assert!(check("controller.omega0_rpm", 1e4).is_err());
    assert!(check("controller.k_mm_per_rad", 1e6).is_ok());
    assert!(check("controller.k_mm_per_rad", f64::INFINITY).is_err());
}
