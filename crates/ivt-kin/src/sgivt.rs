//! The scotch-yoke geared IVT, SGIVT (§2.2): input-control module Eq. 20–21,
//! 31–32; crank Eq. 22–23, 33–34; yokes Eq. 24–29; output gears and the
//! rectified output Eq. 30; the speed ratio Eq. 35; and the stepper ↔ crank
//! map of the prototype Eq. 182–185 with `R_avg(θ_CT)` (§4.4.2).
//!
//! Sign conventions: every angular speed is positive counter-clockwise in its
//! own gear's frame, and an external mesh reverses the sign (the thesis's
//! `ω_CG1 = −3ω_RG1/4`, `ω_SG1 = −7ω_ACG/18`). The crank angle θ_CRK of
//! Fig. 21 is measured *clockwise*; in that sense Eq. 33 reads ω_CRK = ω_in
//! (see [`SgivtGeometry::crank_speed_clockwise`]).

use crate::error::{finite, in_range, KinError};
use crate::units::{deg_to_rad, inch_to_m};
use core::f64::consts::{FRAC_PI_2, PI, SQRT_2};

/// Dimensions of the SGIVT prototype (§2.2.2–2.2.4, §4.4.2), SI units.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SgivtGeometry {
    /// Pitch diameter of the sun gears SG1, SG2 d_SG \[m\] (1.375 in).
    pub d_sg: f64,
    /// Pitch diameter of the planet gears d_PG \[m\] (1.375 in).
    pub d_pg: f64,
    /// Pitch diameter of the control gears ACG and ICG \[m\] (1.75 in).
    pub d_acg: f64,
    /// Pitch diameter of the extended sun gears eSG1, eSG2 \[m\] (4.5 in).
    pub d_esg: f64,
    /// Pitch diameter of the extended ring gears eRG1, eRG2 \[m\] (4.5 in).
    pub d_erg: f64,
    /// Pitch diameter of the extended crank gears eCG1, eCG2 \[m\] (6 in).
    pub d_ecg: f64,
    /// Radius of the crank gears r_CG \[m\] (1 in, Eq. 23).
    pub r_cg: f64,
    /// Radius of the output gears r_OG \[m\] (1.5 in, Eq. 35 and §4.4.2).
    pub r_og: f64,
    /// Stepper-to-ACG speed factor: ω_ACG = −k ω_CT with k = 1/4 (Eq. 182).
    pub stepper_to_acg: f64,
    /// Centre distance of the noncircular gears D \[m\] (5.25 in, Eq. 39).
    pub ncg_centre_distance: f64,
    /// Largest stepper angle θ_CT \[rad\] (3600°, §4.4.2: maximum crank length).
    pub theta_ct_max: f64,
}

impl SgivtGeometry {
    /// The prototype as printed in §2.2 and §4.4.2.
    pub fn prototype() -> Self {
        Self {
            d_sg: inch_to_m(1.375),
            d_pg: inch_to_m(1.375),
            d_acg: inch_to_m(1.75),
            d_esg: inch_to_m(4.5),
            d_erg: inch_to_m(4.5),
            d_ecg: inch_to_m(6.0),
            r_cg: inch_to_m(1.0),
            r_og: inch_to_m(1.5),
            stepper_to_acg: 0.25,
            ncg_centre_distance: inch_to_m(5.25),
            theta_ct_max: deg_to_rad(3600.0),
        }
    }

    /// Sun-gear speeds from the original control speed ω_ACG (§2.2.2):
    /// ω_ICG = −ω_ACG, ω_SG1 = −(d_ACG/d_eSG) ω_ACG = −7ω_ACG/18,
    /// ω_SG2 = −(d_ACG/d_eSG) ω_ICG. Returns (ω_SG1, ω_SG2).
    pub fn sun_speeds(&self, omega_acg: f64) -> (f64, f64) {
        let k = self.d_acg / self.d_esg;
        let omega_icg = -omega_acg;
        (-k * omega_acg, -k * omega_icg)
    }

    /// Ring-gear (output) speeds of the two planetary sets, Eq. 20–21:
    /// ω_RGi = (2(d_SG + d_PG) ω_in − d_SG ω_SGi)/(d_SG + 2 d_PG).
    pub fn ring_speeds(&self, omega_in: f64, omega_sg1: f64, omega_sg2: f64) -> (f64, f64) {
        let (ds, dp) = (self.d_sg, self.d_pg);
        let den = ds + 2.0 * dp;
        let carrier = 2.0 * (ds + dp) * omega_in;
        (
            (carrier - ds * omega_sg1) / den,
            (carrier - ds * omega_sg2) / den,
        )
    }

    /// Crank-gear speeds from the ring-gear speeds (external mesh eRG → eCG):
    /// ω_CGi = −(d_eRG/d_eCG) ω_RGi = −3ω_RGi/4 (§2.2.3).
    pub fn crank_gear_speeds(&self, omega_rg1: f64, omega_rg2: f64) -> (f64, f64) {
        let k = self.d_erg / self.d_ecg;
        (-k * omega_rg1, -k * omega_rg2)
    }

    /// Crank rotation speed ω_CRK = (ω_CG1 + ω_CG2)/2, Eq. 22 (counter-clockwise
    /// sense of the crank gears).
    pub fn crank_speed(&self, omega_cg1: f64, omega_cg2: f64) -> f64 {
        0.5 * (omega_cg1 + omega_cg2)
    }

    /// Crank-length rate v_CRK = (ω_CG1 − ω_CG2) r_CG / 2, Eq. 23 \[m/s\].
    pub fn crank_length_rate(&self, omega_cg1: f64, omega_cg2: f64) -> f64 {
        0.5 * (omega_cg1 - omega_cg2) * self.r_cg
    }

    /// The whole chain ω_in, ω_ACG → (ω_CRK, v_CRK) with ω_CRK measured
    /// clockwise as θ_CRK in Fig. 21, so that Eq. 33 reads ω_CRK = ω_in.
    pub fn crank_speed_clockwise(&self, omega_in: f64, omega_acg: f64) -> (f64, f64) {
        let (sg1, sg2) = self.sun_speeds(omega_acg);
        let (rg1, rg2) = self.ring_speeds(omega_in, sg1, sg2);
        let (cg1, cg2) = self.crank_gear_speeds(rg1, rg2);
        (
            -self.crank_speed(cg1, cg2),
            self.crank_length_rate(cg1, cg2),
        )
    }

    /// Crank-length rate per stepper speed, v_CRK/ω_CT = 7 r_CG/288 (Eq. 184),
    /// computed through the gear chain Eq. 182 → 20–21 → 23.
    pub fn crank_length_per_stepper_rad(&self) -> f64 {
        let omega_acg = -self.stepper_to_acg; // ω_ACG for ω_CT = 1 rad/s, Eq. 182
        self.crank_speed_clockwise(0.0, omega_acg).1
    }

    /// Crank length e from the stepper angle θ_CT \[rad\] (Eq. 185 integrated from e = 0).
    ///
    /// # Errors
    /// θ_CT must be finite and in `[0, theta_ct_max]`.
    pub fn crank_length(&self, theta_ct: f64) -> Result<f64, KinError> {
        let th = in_range(
            "theta_ct",
            theta_ct,
            0.0,
            self.theta_ct_max * (1.0 + 1e-12),
            "0 <= theta_ct <= theta_ct_max (3600 deg, §4.4.2)",
        )?;
        Ok(self.crank_length_per_stepper_rad() * th)
    }

    /// Stepper angle θ_CT \[rad\] for a crank length e \[m\]: the inverse of Eq. 185.
    ///
    /// # Errors
    /// e must be finite and within `[0, e_max]`.
    pub fn stepper_angle(&self, e: f64) -> Result<f64, KinError> {
        let e_max = self.crank_length_per_stepper_rad() * self.theta_ct_max;
        let e = in_range(
            "e",
            e,
            0.0,
            e_max * (1.0 + 1e-12),
            "0 <= e <= e(theta_ct_max) (Eq. 185)",
        )?;
        Ok(e / self.crank_length_per_stepper_rad())
    }

    /// Speed ratio without noncircular gears, Eq. 35:
    /// R = (e/r_OG) max{sin θ, sin(θ−90°), sin(θ−180°), sin(θ−270°)}.
    ///
    /// # Errors
    /// θ must be finite; e finite and ≥ 0.
    pub fn ratio(&self, theta_in: f64, e: f64) -> Result<f64, KinError> {
        let th = finite("theta_in", theta_in)?;
        let e = in_range("e", e, 0.0, f64::INFINITY, "crank length e >= 0")?;
        Ok(e / self.r_og * rectified_shape(th))
    }

    /// Average of Eq. 35 over a period: (2√2/π) e/r_OG (the mean of the
    /// rectified shape is 2√2/π, the reciprocal of the amplitude of Eq. 38).
    ///
    /// # Errors
    /// e must be finite and ≥ 0.
    pub fn average_ratio(&self, e: f64) -> Result<f64, KinError> {
        let e = in_range("e", e, 0.0, f64::INFINITY, "crank length e >= 0")?;
        Ok(2.0 * SQRT_2 / PI * e / self.r_og)
    }

    /// R_avg(θ_CT) of §4.4.2: Eq. 185 substituted into the average of Eq. 35,
    /// `(2√2/π)(7π/51840) θ_CT,deg / r_OG,inch ≈ 7 θ_CT,deg / 27492`.
    ///
    /// # Errors
    /// As [`Self::crank_length`].
    pub fn average_ratio_from_stepper(&self, theta_ct: f64) -> Result<f64, KinError> {
        self.average_ratio(self.crank_length(theta_ct)?)
    }
}

impl SgivtGeometry {
    /// Output-to-engine speed ratio with a noncircular pair, Eq. 37: R/R_n at
    /// θ_in. Constant, (2√2/π) e/r_OG, for the exact pair Eq. 38; nearly
    /// constant for the smooth Eq. 42 (Fig. 24).
    ///
    /// # Errors
    /// As [`Self::ratio`].
    pub fn output_to_engine_ratio<G: crate::ncg::GearRatio>(
        &self,
        ncg: &G,
        theta_in: f64,
        e: f64,
    ) -> Result<f64, KinError> {
        Ok(self.ratio(theta_in, e)? / ncg.ratio(theta_in))
    }
}

impl Default for SgivtGeometry {
    fn default() -> Self {
        Self::prototype()
    }
}

/// The printed slope of §4.4.2: R_avg ≈ 7/27492 per degree of θ_CT.
pub const R_AVG_SLOPE_PRINTED_PER_DEG: f64 = 7.0 / 27492.0;

/// The printed constant of Eq. 185: e \[inch\] = 7π/51840 · θ_CT \[deg\].
pub const CRANK_PER_STEPPER_INCH_PER_DEG: f64 = 7.0 * PI / 51840.0;

/// max{sin θ, sin(θ−90°), sin(θ−180°), sin(θ−270°)} = max(|sin θ|, |cos θ|):
/// the four phases are ±sin θ and ±cos θ. Period π/2, even in θ, range [1/√2, 1].
#[inline]
pub fn rectified_shape(theta: f64) -> f64 {
    libm::fmax(libm::fabs(libm::sin(theta)), libm::fabs(libm::cos(theta)))
}

/// Range of the SGIVT output/engine ratio R/R_n (Eq. 37 with Eq. 35) over a
/// period, relative to its mean: `(min/mean, max/mean)`, sampled at `n`
/// points. (1, 1) for the exact pair Eq. 38; the smooth Eq. 42 leaves a ripple
/// (Fig. 24).
///
/// # Errors
/// `n` must be ≥ 2.
pub fn output_ripple<G: crate::ncg::GearRatio + ?Sized>(
    gear: &G,
    n: usize,
) -> Result<(f64, f64), KinError> {
    if n < 2 {
        return Err(KinError::BufferTooSmall {
            needed: 2,
            capacity: n,
        });
    }
    let (mut lo, mut hi, mut sum) = (f64::INFINITY, f64::NEG_INFINITY, 0.0);
    for j in 0..n {
        let t = FRAC_PI_2 * (j as f64 + 0.5) / n as f64;
        let v = rectified_shape(t) / gear.ratio(t);
        lo = libm::fmin(lo, v);
        hi = libm::fmax(hi, v);
        sum += v;
    }
    let mean = sum / n as f64;
    Ok((lo / mean, hi / mean))
}

/// Yoke displacements and speeds, Eq. 24–27: `x1 = e cos θ`,
/// `x2 = e cos(θ − 90°)`, and their time derivatives with ė ≠ 0.
/// θ = θ_CRK and ω = ω_CRK in the clockwise sense of Fig. 21.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct YokeMotion {
    /// x1 \[m\], Eq. 24.
    pub x1: f64,
    /// v1 \[m/s\], Eq. 25.
    pub v1: f64,
    /// x2 \[m\], Eq. 26.
    pub x2: f64,
    /// v2 \[m/s\], Eq. 27.
    pub v2: f64,
}

/// Yoke motion Eq. 24–27 (Eq. 28–29 when `e_dot = 0`).
pub fn yoke_motion(theta_crk: f64, omega_crk: f64, e: f64, e_dot: f64) -> YokeMotion {
    let (s, c) = (libm::sin(theta_crk), libm::cos(theta_crk));
    let (s2, c2) = (
        libm::sin(theta_crk - FRAC_PI_2),
        libm::cos(theta_crk - FRAC_PI_2),
    );
    YokeMotion {
        x1: e * c,
        v1: e_dot * c - e * omega_crk * s,
        x2: e * c2,
        v2: e_dot * c2 - e * omega_crk * s2,
    }
}

/// Speeds of the four output gears (§2.2.3): ω_OG1 = v1/r_OG, ω_OG2 = −v1/r_OG,
/// ω_OG3 = v2/r_OG, ω_OG4 = −v2/r_OG (clockwise positive).
pub fn output_gear_speeds(yoke: &YokeMotion, r_og: f64) -> [f64; 4] {
    [
        yoke.v1 / r_og,
        -yoke.v1 / r_og,
        yoke.v2 / r_og,
        -yoke.v2 / r_og,
    ]
}

/// Output-shaft speed through the one-way bearings, Eq. 30: the largest of the
/// four output-gear speeds.
pub fn rectified_output(omega_og: &[f64; 4]) -> f64 {
    omega_og.iter().copied().fold(f64::NEG_INFINITY, libm::fmax)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::ncg::{SgivtNcg, SmoothNcg};
    use crate::units::{m_to_inch, rad_to_deg};

    /// Fig. 24: the exact pair Eq. 38 leaves no ripple (Eq. 37: the output
    /// ratio is constant), to rounding.
    #[test]
    fn output_ripple_of_exact_pair_is_zero() {
        let (lo, hi) = output_ripple(&SgivtNcg, 10_000).unwrap();
        assert!((lo - 1.0).abs() < 1e-12 && (hi - 1.0).abs() < 1e-12);
    }

    /// Regression pin, not a correctness check (no independent value: the
    /// thesis shows Fig. 24 without numbers): the Fourier truncation of
    /// Eq. 38 leaves 4.55 % peak-to-peak, the printed (softened) Eq. 42
    /// series 6.84 %, as measured when this was written.
    #[test]
    fn regression_pin_output_ripple_of_smooth_series() {
        let (lo, hi) = output_ripple(&SmoothNcg::fourier(), 100_000).unwrap();
        assert!((hi - lo - 0.0455).abs() < 5e-4, "{lo} {hi}");
        let (lo, hi) = output_ripple(&SmoothNcg::PRINTED, 100_000).unwrap();
        assert!((hi - lo - 0.0684).abs() < 5e-4, "{lo} {hi}");
    }

    /// Eq. 31–32: with d_SG = d_PG and ω_SG2 = −ω_SG1 the ring speeds are
    /// 4ω_in/3 ∓ ω_SG1/3; Eq. 33: the crank turns at ω_in whatever the control
    /// speed (clockwise sense of θ_CRK; −ω_in counter-clockwise through the
    /// external meshes eRG → eCG).
    #[test]
    fn planetary_relations_eq31_to_33() {
        let g = SgivtGeometry::prototype();
        for &(w_in, w_acg) in &[
            (10.0, 0.0),
            (10.0, 3.0),
            (-4.0, 7.5),
            (0.0, 2.0),
            (123.4, -56.7),
        ] {
            let (sg1, sg2) = g.sun_speeds(w_acg);
            assert!((sg1 + sg2).abs() < 1e-15, "ω_SG1 = −ω_SG2");
            assert!(
                (sg1 + 7.0 * w_acg / 18.0).abs() < 1e-12,
                "ω_SG1 = −7ω_ACG/18"
            );
            let (rg1, rg2) = g.ring_speeds(w_in, sg1, sg2);
            assert!(
                (rg1 - (4.0 / 3.0 * w_in - sg1 / 3.0)).abs() < 1e-12,
                "Eq. 31"
            );
            assert!(
                (rg2 - (4.0 / 3.0 * w_in + sg1 / 3.0)).abs() < 1e-12,
                "Eq. 32"
            );
            let (cg1, cg2) = g.crank_gear_speeds(rg1, rg2);
            assert!((g.crank_speed(cg1, cg2) + w_in).abs() < 1e-12);
            let (w_crk, _) = g.crank_speed_clockwise(w_in, w_acg);
            assert!((w_crk - w_in).abs() < 1e-12, "Eq. 33");
        }
    }

    /// Eq. 183–185: v_CRK = (ω_SG1 − ω_SG2) r_CG/8 = 7 ω_CT r_CG/288, and
    /// e = 7π/51840 θ_CT in inch and degree.
    #[test]
    fn stepper_to_crank_eq183_to_185() {
        let g = SgivtGeometry::prototype();
        let per_rad = g.crank_length_per_stepper_rad();
        assert!((per_rad - 7.0 * g.r_cg / 288.0).abs() < 1e-15);
        let (sg1, sg2) = g.sun_speeds(-0.25 * 2.0);
        let (_, v) = g.crank_speed_clockwise(0.0, -0.25 * 2.0);
        assert!((v - (sg1 - sg2) * g.r_cg / 8.0).abs() < 1e-15, "Eq. 183");
        for deg in [0.0, 100.0, 1800.0, 3600.0] {
            let e = g.crank_length(deg_to_rad(deg)).unwrap();
            let printed = CRANK_PER_STEPPER_INCH_PER_DEG * deg;
            assert!((m_to_inch(e) - printed).abs() < 1e-12, "Eq. 185 at {deg}°");
            let back = rad_to_deg(g.stepper_angle(e).unwrap());
            assert!((back - deg).abs() < 1e-9);
        }
    }

    /// §4.4.2: R_avg(θ_CT) = (2√2/π)(7π/51840) θ_CT/r_OG is linear with slope
    /// 14√2/77760 = 2.54617e-4 per degree; the printed 7/27492 = 2.54620e-4
    /// rounds 77760/(2√2) = 27492.3 to an integer, a relative difference of
    /// 1.1e-5. Each figure is asserted to half a unit of its last digit.
    #[test]
    fn r_avg_slope_7_over_27492() {
        let g = SgivtGeometry::prototype();
        let exact_slope = 14.0 * SQRT_2 / 77760.0;
        assert!((exact_slope - 2.54617e-4).abs() < 5e-10, "{exact_slope}");
        assert!((R_AVG_SLOPE_PRINTED_PER_DEG - 2.54620e-4).abs() < 5e-10);
        let denominator = 77760.0 / (2.0 * SQRT_2);
        assert!((denominator - 27492.3).abs() < 0.05, "{denominator}");
        assert_eq!(denominator.round(), 27492.0);
        for deg in [100.0, 1000.0, 3600.0] {
            let r = g.average_ratio_from_stepper(deg_to_rad(deg)).unwrap();
            assert!((r / deg - exact_slope).abs() < 1e-15);
            let rel = R_AVG_SLOPE_PRINTED_PER_DEG / (r / deg) - 1.0;
            assert!((rel - 1.1e-5).abs() < 5e-7, "{rel:e}");
        }
    }

    /// Eq. 35: R/e is the same function of θ for every e (the shape does not
    /// depend on e), and the numeric mean matches the closed form 2√2/π·e/r_OG.
    #[test]
    fn ratio_shape_independent_of_e_eq35() {
        let g = SgivtGeometry::prototype();
        let es = [1e-4, 0.005, 0.02, 0.0388];
        let n = 4096;
        for k in 0..n {
            let th = -3.0 + 9.0 * k as f64 / n as f64;
            let base = g.ratio(th, es[0]).unwrap() / es[0];
            for &e in &es[1..] {
                let s = g.ratio(th, e).unwrap() / e;
                assert!((s - base).abs() <= 1e-14 * base, "θ={th}, e={e}");
            }
        }
        // Mean by the midpoint rule on a grid that puts the kinks on cell
        // edges: error ≤ h²/24·max|R''| with max|R''| = e/r_OG (the shape is
        // ±sin or ±cos on each cell), i.e. 9.8e-8·e/r_OG for n = 4096.
        let e = 0.02;
        let h = 2.0 * PI / n as f64;
        let mean: f64 = (0..n)
            .map(|k| g.ratio((k as f64 + 0.5) * h, e).unwrap())
            .sum::<f64>()
            / n as f64;
        let exact = g.average_ratio(e).unwrap();
        let bound = h * h / 24.0 * e / g.r_og;
        assert!((mean - exact).abs() <= bound, "{mean} vs {exact}");
    }

    /// Eq. 28–30 with ω_CRK = ω_in (Eq. 33–34) reproduce Eq. 35: the rectified
    /// output over the input speed equals the closed-form ratio.
    #[test]
    fn rectified_output_eq30_equals_eq35() {
        let g = SgivtGeometry::prototype();
        let (e, w) = (0.02, 7.0);
        for k in 0..1000 {
            let th = k as f64 * 0.0131;
            let y = yoke_motion(th, w, e, 0.0);
            let out = rectified_output(&output_gear_speeds(&y, g.r_og));
            let r = g.ratio(th, e).unwrap();
            assert!((out / w - r).abs() < 1e-14, "θ={th}");
        }
    }

    /// Eq. 25/27 are the time derivatives of Eq. 24/26 (central differences
    /// along θ = ω t, e = e0 + ė t).
    #[test]
    fn yoke_speeds_are_derivatives() {
        let (w, e0, ed, dt) = (3.0, 0.01, 0.002, 1e-6);
        for k in 0..50 {
            let t = 0.07 * k as f64;
            let at = |t: f64| yoke_motion(w * t, w, e0 + ed * t, ed);
            let (a, b, m) = (at(t - dt), at(t + dt), at(t));
            assert!(((b.x1 - a.x1) / (2.0 * dt) - m.v1).abs() < 1e-8);
            assert!(((b.x2 - a.x2) / (2.0 * dt) - m.v2).abs() < 1e-8);
        }
    }

    /// Eq. 37–38: with the exact pair the output/engine ratio R/R_n is the
    /// constant (2√2/π) e/r_OG at every θ_in.
    #[test]
    fn eq37_constant_with_exact_pair() {
        let g = SgivtGeometry::prototype();
        let e = 0.03;
        let expected = g.average_ratio(e).unwrap();
        for k in 0..5000 {
            let th = -4.0 + k as f64 * 0.0017;
            let v = g.output_to_engine_ratio(&SgivtNcg, th, e).unwrap();
            assert!((v - expected).abs() <= 1e-12 * expected, "θ={th}");
        }
    }

    #[test]
    fn out_of_domain_is_an_error() {
        let g = SgivtGeometry::prototype();
        crate::error::assert_rejects_bad_theta_and_r(|th, r| g.ratio(th, r));
        assert!(g.crank_length(-0.1).is_err());
        assert!(g.crank_length(deg_to_rad(3700.0)).is_err());
        assert!(g.stepper_angle(1.0).is_err());
    }
}
