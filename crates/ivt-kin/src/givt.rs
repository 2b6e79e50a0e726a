//! The crank-slider geared IVT, GIVT (§2.1): input-control module Eq. 1–2,
//! crank motion Eq. 3–4, the crank-slider ratio Eq. 8, the four-phase module
//! ratio Eq. 9, the final ratio Eq. 10, its period average and the reduced
//! ratio used to design the noncircular gears (Eq. 13); the direction
//! control module Eq. 18–19 is in [`direction`] (re-exported here).
//!
//! The thesis prints neither l1 (|O_output O_crk|) nor r_output (output gear
//! radius) for the GIVT; [`GivtGeometry::illustrative`] picks values scaled
//! from the design eccentricity r_o = 10 mm of §2.1.5 and says so.

pub mod direction;

use crate::error::{filled, finite, in_range, positive, push, KinError};
use crate::quad::{relative_tolerance, simpson};
use core::f64::consts::FRAC_PI_2;
pub use direction::{DirectionMode, DirectionModule, DirectionSpeeds};

/// Period of the module ratio R(θ, r) in θ: the four crank-sliders are 90°
/// apart (Eq. 9), so R repeats every π/2 (the thesis's "period 2π" is one
/// revolution of the crank gears, four periods of R).
pub const MODULE_PERIOD: f64 = FRAC_PI_2;

/// Largest number of corners of R(θ, r) per period that the corner finder reports.
pub const MAX_CORNERS: usize = 8;

/// Dimensions of a GIVT, SI units.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct GivtGeometry {
    /// l1 = |O_output O_crk| \[m\] (Eq. 6–8).
    pub l1: f64,
    /// Output-gear radius r_output \[m\] (Eq. 5–8).
    pub r_output: f64,
    /// Sun-gear radius of the input-control module r_sun \[m\] (Eq. 1–2).
    pub r_sun: f64,
    /// Planet-gear radius r_planet \[m\] (Eq. 1–2).
    pub r_planet: f64,
    /// Crank-gear radius r_crk \[m\] (Eq. 4).
    pub r_crk: f64,
    /// Control gear to ring gear ratio (1/3 in §2.1.3: ω_rA = ω_c1/3).
    pub control_to_ring: f64,
}

impl GivtGeometry {
    /// Illustrative dimensions: **not printed in the thesis**. l1 = 50 mm and
    /// r_output = 15 mm (5 and 1.5 times the design eccentricity r_o = 10 mm of
    /// §2.1.5), so that r_o/l1 = 0.2 and the eccentricities of Fig. 10 (5 and
    /// 10 mm) lie well inside the domain r < l1. r_sun = 2 r_planet as required
    /// for F = 3R (Eq. 10); r_planet = 10 mm and r_crk = 10 mm are placeholders
    /// that only scale ω_in ↔ ω_crk and v_crk.
    pub fn illustrative() -> Self {
        Self {
            l1: 0.050,
            r_output: 0.015,
            r_sun: 0.020,
            r_planet: 0.010,
            r_crk: 0.010,
            control_to_ring: 1.0 / 3.0,
        }
    }

    /// Check that every dimension is finite and positive.
    ///
    /// # Errors
    /// Names the first offending dimension.
    pub fn validate(&self) -> Result<(), KinError> {
        positive("l1", self.l1)?;
        positive("r_output", self.r_output)?;
        positive("r_sun", self.r_sun)?;
        positive("r_planet", self.r_planet)?;
        positive("r_crk", self.r_crk)?;
        positive("control_to_ring", self.control_to_ring)?;
        Ok(())
    }

    /// Sun-gear speeds, Eq. 1–2, from the input speed ω_in and the original
    /// control speed ω_c1: ω_rA = ω_c1/3, ω_rB = −ω_rA, and
    /// ω_s = (2(r_sun + r_planet) ω_in − (r_sun + 2 r_planet) ω_r)/r_sun.
    /// Returns (ω_sA, ω_sB).
    pub fn sun_speeds(&self, omega_in: f64, omega_c1: f64) -> (f64, f64) {
        let (rs, rp) = (self.r_sun, self.r_planet);
        let omega_ra = self.control_to_ring * omega_c1;
        let omega_rb = -omega_ra;
        let carrier = 2.0 * (rs + rp) * omega_in;
        (
            (carrier - (rs + 2.0 * rp) * omega_ra) / rs,
            (carrier - (rs + 2.0 * rp) * omega_rb) / rs,
        )
    }

    /// Crank rotation ω_crk = (ω_sA + ω_sB)/2 (Eq. 3) and translation
    /// v_crk = (ω_sA − ω_sB) r_crk/2 (Eq. 4). Returns (ω_crk, v_crk).
    pub fn crank_motion(&self, omega_sa: f64, omega_sb: f64) -> (f64, f64) {
        (
            0.5 * (omega_sa + omega_sb),
            0.5 * (omega_sa - omega_sb) * self.r_crk,
        )
    }

    /// ω_crk/ω_in at zero control speed: 2(r_sun + r_planet)/r_sun (= 3 when
    /// r_sun = 2 r_planet, Eq. 10).
    pub fn crank_to_input(&self) -> f64 {
        2.0 * (self.r_sun + self.r_planet) / self.r_sun
    }

    fn check_r(&self, r: f64) -> Result<f64, KinError> {
        self.validate()?;
        in_range(
            "r",
            r,
            0.0,
            self.l1,
            "0 <= r < l1 (Eq. 8 divides by |l1 - r|)",
        )
    }

    /// Ratio of one crank-slider, Eq. 8:
    /// `R1 = (r² − r l1 cos θ)/Q + r l1 |sin θ|/(r_output √Q)`,
    /// `Q = l1² − 2 r l1 cos θ + r²`.
    ///
    /// # Errors
    /// θ must be finite and 0 ≤ r < l1 (at r = l1, Q vanishes at θ = 0).
    pub fn single_ratio(&self, theta: f64, r: f64) -> Result<f64, KinError> {
        let th = finite("theta", theta)?;
        let r = self.check_r(r)?;
        Ok(self.r1(th, r))
    }

    /// Eq. 8 without checks (inputs already validated).
    #[inline]
    fn r1(&self, theta: f64, r: f64) -> f64 {
        let l1 = self.l1;
        let (s, c) = (libm::sin(theta), libm::cos(theta));
        let q = l1 * l1 - 2.0 * r * l1 * c + r * r;
        (r * r - r * l1 * c) / q + r * l1 * libm::fabs(s) / (self.r_output * libm::sqrt(q))
    }

    /// dR1/dθ of Eq. 8 (one-sided at sin θ = 0: the value for θ → θ⁺).
    #[inline]
    fn r1_derivative(&self, theta: f64, r: f64) -> f64 {
        let l1 = self.l1;
        let (s, c) = (libm::sin(theta), libm::cos(theta));
        let q = l1 * l1 - 2.0 * r * l1 * c + r * r;
        let dq = 2.0 * r * l1 * s;
        let n = r * r - r * l1 * c;
        let dn = r * l1 * s;
        let sgn = if s > 0.0 || (s == 0.0 && c > 0.0) {
            1.0
        } else {
            -1.0
        };
        let sq = libm::sqrt(q);
        (dn * q - n * dq) / (q * q)
            + r * l1 / self.r_output * (sgn * c / sq - 0.5 * libm::fabs(s) * dq / (q * sq))
    }

    /// Index k ∈ 0..4 of the crank-slider that drives the output at θ and its
    /// ratio: the argmax of Eq. 9.
    #[inline]
    fn active(&self, theta: f64, r: f64) -> (usize, f64) {
        let mut best = (0, f64::NEG_INFINITY);
        for k in 0..4 {
            let v = self.r1(theta + k as f64 * FRAC_PI_2, r);
            if v > best.1 {
                best = (k, v);
            }
        }
        best
    }

    /// Ratio of the motion-conversion module, Eq. 9: the largest of the four
    /// crank-slider ratios at phases 0°, 90°, 180°, 270°.
    ///
    /// # Errors
    /// As [`Self::single_ratio`].
    pub fn module_ratio(&self, theta: f64, r: f64) -> Result<f64, KinError> {
        let th = finite("theta", theta)?;
        let r = self.check_r(r)?;
        Ok(self.active(th, r).1)
    }

    /// dR/dθ of Eq. 9 (the derivative of the active crank-slider; one-sided at corners).
    ///
    /// # Errors
    /// As [`Self::single_ratio`].
    pub fn module_ratio_derivative(&self, theta: f64, r: f64) -> Result<f64, KinError> {
        let th = finite("theta", theta)?;
        let r = self.check_r(r)?;
        // One-sided: pick the phase active just after θ.
        let (k, _) = self.active(th + 1e-9, r);
        Ok(self.r1_derivative(th + k as f64 * FRAC_PI_2, r))
    }

    /// Final ratio ω_out/ω_in, Eq. 10: (ω_crk/ω_in)·R = 3R for r_sun = 2 r_planet.
    ///
    /// # Errors
    /// As [`Self::single_ratio`].
    pub fn final_ratio(&self, theta: f64, r: f64) -> Result<f64, KinError> {
        Ok(self.crank_to_input() * self.module_ratio(theta, r)?)
    }

    /// The corners (kinks) of R(θ, r) in one period [0, π/2): where the driving
    /// crank-slider changes (Eq. 9). Writes them sorted into `out` and returns
    /// how many. Found by scanning 512 cells for a change of the argmax and
    /// bisecting the difference of the two phases to machine precision.
    ///
    /// # Errors
    /// As [`Self::single_ratio`]; `BufferTooSmall` if `out` cannot hold them.
    pub fn module_corners(&self, r: f64, out: &mut [f64]) -> Result<usize, KinError> {
        let r = self.check_r(r)?;
        const CELLS: usize = 512;
        let h = MODULE_PERIOD / CELLS as f64;
        let at = |j: usize| (j as f64 + 0.5) * h;
        let mut count = 0;
        let mut prev = self.active(at(CELLS - 1) - MODULE_PERIOD, r).0;
        for j in 0..CELLS {
            let (k, _) = self.active(at(j), r);
            if k != prev {
                let (ka, kb) = (prev as f64 * FRAC_PI_2, k as f64 * FRAC_PI_2);
                let diff = |t: f64| self.r1(t + ka, r) - self.r1(t + kb, r);
                let (mut lo, mut hi) = (at(j) - h, at(j));
                let d_lo = diff(lo);
                for _ in 0..200 {
                    let mid = 0.5 * (lo + hi);
                    if mid <= lo || mid >= hi {
                        break;
                    }
                    if (diff(mid) > 0.0) == (d_lo > 0.0) {
                        lo = mid;
                    } else {
                        hi = mid;
                    }
                }
                let c = 0.5 * (lo + hi);
                let mut c = c - MODULE_PERIOD * libm::floor(c / MODULE_PERIOD);
                if c >= MODULE_PERIOD * (1.0 - 1e-12) {
                    c = 0.0; // a corner at the period boundary found from below
                }
                push(out, &mut count, c)?;
            }
            prev = k;
        }
        filled(out, count)?.sort_unstable_by(f64::total_cmp);
        Ok(count)
    }

    /// Average of R(θ, r) over a period (adaptive Simpson on each smooth piece
    /// between corners, tolerance 1e-14 relative to ∫|R|).
    ///
    /// # Errors
    /// As [`Self::single_ratio`]; `NotConverged` if the quadrature fails.
    pub fn average_module_ratio(&self, r: f64) -> Result<f64, KinError> {
        let mut corners = [0.0; MAX_CORNERS];
        let n = self.module_corners(r, &mut corners)?;
        let mut total = 0.0;
        let mut ok = true;
        let mut err = 0.0;
        let g = |t: f64| self.active(t, r).1;
        // Relative target: near r → l1 the ratio grows like l1/(l1 − r).
        let tol = relative_tolerance(&g, 0.0, MODULE_PERIOD, 1e-14);
        let mut a = 0.0;
        for &c in filled(&mut corners, n)?
            .iter()
            .chain(core::iter::once(&MODULE_PERIOD))
        {
            let q = simpson(&g, a, c, tol);
            ok &= q.converged;
            err += q.error;
            total += q.value;
            a = c;
        }
        // At the depth limit a panel may miss its share of the tolerance near
        // the r → l1 spike; the result still stands if the summed error
        // estimate meets the whole tolerance.
        let within = err <= tol; // false for a NaN estimate
        if !ok && !within {
            return Err(KinError::NotConverged {
                what: "average of Eq. 9",
                achieved: err,
            });
        }
        Ok(total / MODULE_PERIOD)
    }

    /// Average of the final ratio F = 3R over a period (Fig. 9(b)).
    ///
    /// # Errors
    /// As [`Self::average_module_ratio`].
    pub fn average_final_ratio(&self, r: f64) -> Result<f64, KinError> {
        Ok(self.crank_to_input() * self.average_module_ratio(r)?)
    }

    /// Reduced ratio R_r = R(θ, r)/avg R (§2.1.5, Fig. 10). Needs r > 0.
    ///
    /// # Errors
    /// As [`Self::single_ratio`], and r = 0 (zero average).
    pub fn reduced_ratio(&self, theta: f64, r: f64) -> Result<f64, KinError> {
        let avg = self.average_module_ratio(r)?;
        if avg <= 0.0 {
            return Err(KinError::OutOfDomain {
                name: "r",
                value: r,
                requirement: "r > 0 (the reduced ratio divides by the average)",
            });
        }
        Ok(self.module_ratio(theta, r)? / avg)
    }
}

impl Default for GivtGeometry {
    fn default() -> Self {
        Self::illustrative()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Eq. 1–4: zero control speed gives equal sun speeds, a pure rotation at
    /// 2(r_s+r_p)/r_s ω_in (Eq. 10: 3ω_in); zero input speed gives opposite
    /// sun speeds and a pure translation (Fig. 6).
    #[test]
    fn planetary_and_crank_eq1_to_4() {
        let g = GivtGeometry::illustrative();
        let (a, b) = g.sun_speeds(5.0, 0.0);
        assert!((a - b).abs() < 1e-12 && (a - 15.0).abs() < 1e-12);
        let (w, v) = g.crank_motion(a, b);
        assert!((w - 3.0 * 5.0).abs() < 1e-12 && v.abs() < 1e-15);
        let (a, b) = g.sun_speeds(0.0, 3.0);
        assert!((a + b).abs() < 1e-12);
        let (w, v) = g.crank_motion(a, b);
        // ω_rA = 1, ω_sA = −(r_s + 2r_p)/r_s = −2: v = −2 r_crk
        assert!(w.abs() < 1e-15 && (v + 2.0 * g.r_crk).abs() < 1e-15);
        assert_eq!(g.crank_to_input(), 3.0);
    }

    /// Eq. 8 is Eq. 5 with θ_s and l2 from the triangle O_output O_c O_crk:
    /// check it against finite differences of the geometry itself,
    /// θ_s = atan2(r sin θ, l1 − r cos θ) and l2 = |O_output O_c|.
    #[test]
    fn eq8_matches_triangle_geometry() {
        let g = GivtGeometry::illustrative();
        let r = 0.012;
        // O_crk at (l1, 0), O_output at the origin, O_c = O_crk + r(−cos θ, sin θ);
        // Eq. 6 measures θ_s in the sense opposite to θ, hence the minus sign.
        let geom = |t: f64| {
            let (x, y) = (g.l1 - r * t.cos(), r * t.sin());
            (-y.atan2(x), (x * x + y * y).sqrt())
        };
        let h = 1e-6;
        for k in 0..300 {
            let t = 0.013 + k as f64 * 0.0211;
            let (s0, l0) = geom(t - h);
            let (s1, l1) = geom(t + h);
            let fd = (s1 - s0) / (2.0 * h) + ((l1 - l0) / (2.0 * h)).abs() / g.r_output;
            let r1 = g.single_ratio(t, r).unwrap();
            assert!((fd - r1).abs() < 1e-8, "θ={t}: {fd} vs {r1}");
        }
    }

    /// dR1/dθ by central differences (away from sin θ = 0).
    #[test]
    fn r1_derivative_by_finite_differences() {
        let g = GivtGeometry::illustrative();
        let (r, h) = (0.02, 1e-6);
        for k in 0..400 {
            let t = 0.05 + k as f64 * 0.0157;
            if t.sin().abs() < 1e-3 {
                continue;
            }
            let fd = (g.r1(t + h, r) - g.r1(t - h, r)) / (2.0 * h);
            assert!((fd - g.r1_derivative(t, r)).abs() < 1e-7);
        }
    }

    /// Eq. 9: R is π/2-periodic, even, and ≥ each crank-slider's ratio; its
    /// corners are where two crank-sliders give the same ratio.
    #[test]
    fn module_ratio_period_and_corners() {
        let g = GivtGeometry::illustrative();
        for &r in &[0.005, 0.01, 0.03] {
            let mut c = [0.0; MAX_CORNERS];
            let n = g.module_corners(r, &mut c).unwrap();
            assert!(n >= 1, "R has at least one kink per period");
            for &ck in &c[..n] {
                assert!((0.0..MODULE_PERIOD).contains(&ck));
                // left and right slopes differ at a corner
                let dl = g.module_ratio_derivative(ck - 1e-7, r).unwrap();
                let dr = g.module_ratio_derivative(ck + 1e-7, r).unwrap();
                assert!((dl - dr).abs() > 1e-3, "kink at {ck}");
            }
            for k in 0..200 {
                let t = k as f64 * 0.0371;
                let v = g.module_ratio(t, r).unwrap();
                assert!((g.module_ratio(t + MODULE_PERIOD, r).unwrap() - v).abs() < 1e-13);
                assert!((g.module_ratio(-t, r).unwrap() - v).abs() < 1e-13);
                for p in 0..4 {
                    assert!(v >= g.single_ratio(t + p as f64 * FRAC_PI_2, r).unwrap());
                }
            }
        }
    }

    /// The corner-split Simpson average agrees with a brute-force midpoint
    /// rule (error O(h) at unresolved kinks: 1e-6 relative with 2^18 cells).
    #[test]
    fn average_matches_brute_force() {
        let g = GivtGeometry::illustrative();
        for &r in &[0.002, 0.01, 0.025, 0.045] {
            let n = 1 << 18;
            let h = MODULE_PERIOD / n as f64;
            let brute: f64 = (0..n)
                .map(|k| g.module_ratio((k as f64 + 0.5) * h, r).unwrap())
                .sum::<f64>()
                / n as f64;
            let avg = g.average_module_ratio(r).unwrap();
            assert!((avg - brute).abs() < 1e-6 * avg, "r={r}: {avg} vs {brute}");
            let f = g.average_final_ratio(r).unwrap();
            assert!((f - 3.0 * avg).abs() < 1e-15);
        }
    }

    /// Fig. 9(b): the average final ratio grows monotonically with r over the
    /// whole domain, from 0 at r = 0.
    #[test]
    fn average_ratio_monotone_in_r() {
        let g = GivtGeometry::illustrative();
        assert_eq!(g.average_final_ratio(0.0).unwrap(), 0.0);
        let mut prev = 0.0;
        for k in 1..=98 {
            let r = g.l1 * k as f64 / 100.0;
            let f = g.average_final_ratio(r).unwrap();
            assert!(f > prev, "r = {r}: {f} <= {prev}");
            prev = f;
        }
    }

    /// The reduced ratio averages to 1 (definition, §2.1.5).
    #[test]
    fn reduced_ratio_mean_is_one() {
        let g = GivtGeometry::illustrative();
        let (n, r) = (1 << 16, 0.01);
        let h = MODULE_PERIOD / n as f64;
        let avg = g.average_module_ratio(r).unwrap();
        let mean: f64 = (0..n)
            .map(|k| g.module_ratio((k as f64 + 0.5) * h, r).unwrap() / avg)
            .sum::<f64>()
            / n as f64;
        assert!((mean - 1.0).abs() < 1e-5);
        let t = 0.3;
        let rr = g.reduced_ratio(t, r).unwrap();
        assert!((rr - g.module_ratio(t, r).unwrap() / avg).abs() < 1e-15);
    }

    #[test]
    fn out_of_domain_is_an_error() {
        let g = GivtGeometry::illustrative();
        crate::error::assert_rejects_bad_theta_and_r(|th, r| g.single_ratio(th, r));
        crate::error::assert_rejects_bad_theta_and_r(|th, r| g.module_ratio(th, r));
        assert!(matches!(
            g.module_ratio(0.1, g.l1),
            Err(KinError::OutOfDomain { .. })
        ));
        assert!(g.reduced_ratio(0.1, 0.0).is_err());
        let mut bad = g;
        bad.r_output = 0.0;
        assert!(bad.single_ratio(0.1, 0.01).is_err());
        let m = DirectionModule {
            r_sun: -1.0,
            r_planet: 1.0,
        };
        assert!(m.speeds(DirectionMode::Forward, 1.0).is_err());
    }
}
