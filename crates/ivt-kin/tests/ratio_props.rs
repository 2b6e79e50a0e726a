//! Property tests of the ratio functions over their whole domain (issue 2):
//! finite outputs, periodicity, symmetry, bounds; out-of-domain inputs give an
//! error, never NaN. Tolerances: periodicity/symmetry compare values computed
//! from arguments that differ by rounding of |θ| ≤ 100 (≈ 1.4e-14 rad), times
//! the slope of the ratio (≤ 10 for Eq. 8 at r ≤ 0.99 l1): 1e-11 relative.

use core::f64::consts::{FRAC_PI_2, PI, SQRT_2};
use ivt_kin::givt::GivtGeometry;
use ivt_kin::ncg::{GearRatio, SmoothNcg};
use ivt_kin::sgivt::SgivtGeometry;
use ivt_kin::{variant, KinError};
use proptest::prelude::*;

fn close(a: f64, b: f64, rel: f64) -> bool {
    (a - b).abs() <= rel * (1.0 + a.abs().max(b.abs()))
}

fn is_domain(r: &Result<f64, KinError>) -> bool {
    matches!(r, Err(KinError::OutOfDomain { .. }))
}

fn is_not_finite(r: &Result<f64, KinError>) -> bool {
    matches!(r, Err(KinError::NotFinite { .. }))
}

fn givt_geometry() -> impl Strategy<Value = GivtGeometry> {
    (0.01f64..1.0, 0.001f64..0.5).prop_map(|(l1, ro)| GivtGeometry {
        l1,
        r_output: ro,
        ..GivtGeometry::illustrative()
    })
}

proptest! {
    /// Eq. 35: finite, in [e/(√2 r_OG), e/r_OG], period π/2, even in θ.
    #[test]
    fn sgivt_ratio(theta in -100.0f64..100.0, e in 0.0f64..0.05) {
        let g = SgivtGeometry::prototype();
        let r = g.ratio(theta, e).unwrap();
        prop_assert!(r.is_finite());
        let hi = e / g.r_og;
        prop_assert!(r <= hi * (1.0 + 1e-15) && r >= hi / SQRT_2 * (1.0 - 1e-12));
        prop_assert!(close(g.ratio(theta + FRAC_PI_2, e).unwrap(), r, 1e-11));
        prop_assert!(close(g.ratio(-theta, e).unwrap(), r, 1e-11));
    }

    /// Eq. 8: finite for 0 ≤ r < l1, 2π-periodic and even in θ.
    #[test]
    fn givt_single_ratio(g in givt_geometry(), theta in -100.0f64..100.0, frac in 0.0f64..0.99) {
        let r = frac * g.l1;
        let v = g.single_ratio(theta, r).unwrap();
        prop_assert!(v.is_finite());
        let scale = 1.0 / (1.0 - frac) + g.l1 / g.r_output; // |R1| and slope scale
        prop_assert!((g.single_ratio(theta + 2.0 * PI, r).unwrap() - v).abs() <= 1e-11 * scale);
        prop_assert!((g.single_ratio(-theta, r).unwrap() - v).abs() <= 1e-11 * scale);
    }

    /// Eq. 9: period π/2, even, ≥ each crank-slider, ≥ 0.
    #[test]
    fn givt_module_ratio(g in givt_geometry(), theta in -100.0f64..100.0, frac in 0.0f64..0.99) {
        let r = frac * g.l1;
        let v = g.module_ratio(theta, r).unwrap();
        prop_assert!(v.is_finite() && v >= 0.0);
        let scale = 1.0 / (1.0 - frac) + g.l1 / g.r_output;
        prop_assert!((g.module_ratio(theta + FRAC_PI_2, r).unwrap() - v).abs() <= 1e-11 * scale);
        prop_assert!((g.module_ratio(-theta, r).unwrap() - v).abs() <= 1e-11 * scale);
        for k in 0..4 {
            prop_assert!(v >= g.single_ratio(theta + k as f64 * FRAC_PI_2, r).unwrap());
        }
        prop_assert!(close(g.final_ratio(theta, r).unwrap(), 3.0 * v, 1e-15));
    }

    /// Eq. 43/38: finite, in [π/4, π/(2√2)], period π/2, even.
    #[test]
    fn variant_modulation(theta in -100.0f64..100.0) {
        let f = variant::f(theta);
        prop_assert!(f.is_finite());
        prop_assert!(f >= PI / 4.0 * (1.0 - 1e-12) && f <= PI / (2.0 * SQRT_2) * (1.0 + 1e-15));
        prop_assert!(close(variant::f(theta + FRAC_PI_2), f, 1e-11));
        prop_assert!(close(variant::f(-theta), f, 1e-11));
    }

    /// Eq. 42 (printed): positive (a valid gear ratio), period π/2, even.
    #[test]
    fn smooth_ratio(theta in -100.0f64..100.0) {
        let g = SmoothNcg::PRINTED;
        let v = g.ratio(theta);
        prop_assert!(v > 0.8 && v < 1.2);
        prop_assert!(close(g.ratio(theta + FRAC_PI_2), v, 1e-11));
        prop_assert!(close(g.ratio(-theta), v, 1e-11));
    }

    /// Out of domain: r ≥ l1, r < 0, e < 0, non-finite inputs → Err, never NaN.
    #[test]
    fn out_of_domain_errors(g in givt_geometry(), theta in -10.0f64..10.0, over in 1.0f64..1e6, neg in -1e6f64..-1e-300) {
        prop_assert!(is_domain(&g.single_ratio(theta, over * g.l1)));
        prop_assert!(is_domain(&g.module_ratio(theta, neg)));
        prop_assert!(is_not_finite(&g.module_ratio(f64::NAN, 0.5 * g.l1)));
        prop_assert!(is_not_finite(&g.single_ratio(theta, f64::NAN)));
        let s = SgivtGeometry::prototype();
        prop_assert!(is_domain(&s.ratio(theta, neg)));
        prop_assert!(is_not_finite(&s.ratio(f64::INFINITY, 0.01)));
        prop_assert!(s.crank_length(neg).is_err());
    }
}
