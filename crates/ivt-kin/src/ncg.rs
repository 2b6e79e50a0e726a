//! Noncircular gears (§2.1.5, §2.2.4): the speed ratio R_n of the pair, the
//! pitch profiles of the driving gear NG1 and the driven gear NG2 for a centre
//! distance D, and the smooth cosine series Eq. 42 with its Fourier fit.
//!
//! For a ratio R_n(θ₂) = ω_NG1/ω_NG2 at the driven-gear angle θ₂ (Eq. 11, 36):
//! - `r_NG2 = D R_n/(R_n + 1)`, `r_NG1 = D − r_NG2` (Eq. 14–16, 39–40),
//! - the driving-gear angle `φ(θ₂) = ∫₀^θ₂ R_n dθ₂` (Eq. 17, 41).
//!
//! The designs here: [`SgivtNcg`] (Eq. 38, mean 1: a 1:1 pair), [`SmoothNcg`]
//! (Eq. 42 and its refits), [`GivtNcg`] (Eq. 13, mean 3).

use crate::error::{filled, finite, in_range, positive, KinError};
use crate::givt::{GivtGeometry, MAX_CORNERS, MODULE_PERIOD};
use crate::quad::simpson;
use crate::variant;
use core::f64::consts::{FRAC_PI_2, FRAC_PI_4, PI};

/// Absolute tolerance of every angle-map quadrature \[rad\].
const ANGLE_TOL: f64 = 1e-14;

/// A noncircular-gear speed ratio R_n(θ₂) = ω_NG1/ω_NG2 = dφ/dθ₂.
pub trait GearRatio {
    /// R_n at the driven-gear angle θ₂ \[rad\]; positive, finite for finite θ₂.
    fn ratio(&self, theta2: f64) -> f64;
    /// dR_n/dθ₂; at a corner, the value of the piece that starts there.
    fn ratio_derivative(&self, theta2: f64) -> f64;
    /// Period of R_n in θ₂ \[rad\]; 2π is an integer multiple of it.
    fn period(&self) -> f64;
    /// Mean of R_n over a period: NG1 revolutions per NG2 revolution.
    fn turns_ratio(&self) -> f64;
    /// The corners (kinks) of R_n in `[0, period)`, sorted.
    fn corners(&self) -> &[f64];
}

/// SGIVT pair, Eq. 38: R_n = π/(2√2) max{sin θ, sin(θ−90°), sin(θ−180°),
/// sin(θ−270°)} (the same function as the variant's f(θ), Eq. 43).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct SgivtNcg;

const SGIVT_CORNERS: [f64; 1] = [FRAC_PI_4];

impl GearRatio for SgivtNcg {
    fn ratio(&self, theta2: f64) -> f64 {
        variant::f(theta2)
    }
    fn ratio_derivative(&self, theta2: f64) -> f64 {
        variant::f_theta(theta2)
    }
    fn period(&self) -> f64 {
        FRAC_PI_2
    }
    fn turns_ratio(&self) -> f64 {
        1.0
    }
    fn corners(&self) -> &[f64] {
        &SGIVT_CORNERS
    }
}

/// Coefficients of the cos(4kθ) terms, k = 1..4, of Eq. 42 as printed.
pub const EQ42_PRINTED: [f64; 4] = [0.12, -0.0286, 0.0126, -0.007];

/// Smooth ratio Eq. 42: `1 + Σ_k a_k cos(4kθ)`, k = 1..4.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SmoothNcg {
    /// a_1..a_4.
    pub coeffs: [f64; 4],
}

impl SmoothNcg {
    /// Eq. 42 with the printed coefficients.
    pub const PRINTED: SmoothNcg = SmoothNcg {
        coeffs: EQ42_PRINTED,
    };

    /// The exact truncated Fourier series of Eq. 38 (see [`fourier_coefficient_eq38`]).
    pub fn fourier() -> Self {
        Self {
            coeffs: [1, 2, 3, 4].map(fourier_coefficient_eq38),
        }
    }
}

impl GearRatio for SmoothNcg {
    fn ratio(&self, theta2: f64) -> f64 {
        let mut r = 1.0;
        for (k, a) in self.coeffs.iter().enumerate() {
            r += a * libm::cos(4.0 * (k + 1) as f64 * theta2);
        }
        r
    }
    fn ratio_derivative(&self, theta2: f64) -> f64 {
        let mut d = 0.0;
        for (k, a) in self.coeffs.iter().enumerate() {
            let m = 4.0 * (k + 1) as f64;
            d -= a * m * libm::sin(m * theta2);
        }
        d
    }
    fn period(&self) -> f64 {
        FRAC_PI_2
    }
    fn turns_ratio(&self) -> f64 {
        1.0
    }
    fn corners(&self) -> &[f64] {
        &[]
    }
}

/// Exact Fourier coefficient a_k of Eq. 38 in `R_n = a_0 + Σ a_k cos(4kθ)`:
/// a_0 = 1 and, integrating A cos φ cos(4kφ) over one segment |φ| ≤ π/4
/// (A = π/(2√2)), `a_k = 2(−1)^(k+1)/(16k² − 1)`: 2/15, −2/63, 2/143, −2/255, ...
pub fn fourier_coefficient_eq38(k: u32) -> f64 {
    if k == 0 {
        return 1.0;
    }
    let kk = k as f64;
    let sign = if k % 2 == 1 { 1.0 } else { -1.0 };
    2.0 * sign / (16.0 * kk * kk - 1.0)
}

/// Fourier cosine coefficient a_k = (2/P)∫₀^P R_n cos(2πkθ/P) dθ (a_0: the
/// mean) of any gear ratio by adaptive quadrature split at its corners.
///
/// # Errors
/// `NotConverged` if the quadrature fails.
pub fn fourier_coefficient<G: GearRatio + ?Sized>(gear: &G, k: u32) -> Result<f64, KinError> {
    let p = gear.period();
    let w = 2.0 * PI * k as f64 / p;
    let g = |t: f64| gear.ratio(t) * libm::cos(w * t);
    let (value, ok, err) = integrate_pieces(gear, &g, 0.0, p);
    if !ok {
        return Err(KinError::NotConverged {
            what: "Fourier coefficient",
            achieved: err,
        });
    }
    Ok(if k == 0 { value / p } else { 2.0 * value / p })
}

/// ∫_a^b g over [a, b] ⊂ one or more periods, split at the gear's corners.
fn integrate_pieces<G: GearRatio + ?Sized, F: Fn(f64) -> f64>(
    gear: &G,
    g: &F,
    a: f64,
    b: f64,
) -> (f64, bool, f64) {
    let p = gear.period();
    let mut total = 0.0;
    let mut ok = true;
    let mut err = 0.0;
    let mut lo = a;
    let first = libm::floor(a / p);
    let mut m = first;
    'outer: loop {
        for &c in gear.corners() {
            let x = m * p + c;
            if x <= lo {
                continue;
            }
            if x >= b {
                break 'outer;
            }
            let q = simpson(g, lo, x, ANGLE_TOL);
            ok &= q.converged;
            err += q.error;
            total += q.value;
            lo = x;
        }
        m += 1.0;
        if m * p >= b {
            break;
        }
    }
    let q = simpson(g, lo, b, ANGLE_TOL);
    ok &= q.converged;
    (total + q.value, ok, err + q.error)
}

/// Driving-gear angle φ(θ₂) = ∫₀^θ₂ R_n (Eq. 17, 41), for θ₂ ≥ 0: whole
/// periods contribute `turns_ratio · period` each (the mean), the remainder
/// is integrated piecewise between corners.
///
/// # Errors
/// θ₂ must be finite and ≥ 0; `NotConverged` if the quadrature fails.
pub fn driving_angle<G: GearRatio + ?Sized>(gear: &G, theta2: f64) -> Result<f64, KinError> {
    let th = in_range("theta2", theta2, 0.0, f64::INFINITY, "theta2 >= 0")?;
    let p = gear.period();
    let whole = libm::floor(th / p);
    let rem = th - whole * p;
    let (part, ok, err) = integrate_pieces(gear, &|t| gear.ratio(t), 0.0, rem);
    if !ok {
        return Err(KinError::NotConverged {
            what: "angle map Eq. 17/41",
            achieved: err,
        });
    }
    Ok(whole * gear.turns_ratio() * p + part)
}

/// Driven-gear angle θ₂ for a driving-gear angle φ ≥ 0: the inverse of
/// [`driving_angle`] by safeguarded Newton (φ' = R_n > 0), to 1e-14 rad.
/// φ is integrated once at the first guess; each Newton step then adds only
/// the integral over the step, so the cost is about one quadrature.
///
/// # Errors
/// φ must be finite and ≥ 0; `NotConverged` if Newton stalls.
pub fn driven_angle<G: GearRatio + ?Sized>(gear: &G, phi: f64) -> Result<f64, KinError> {
    let ph = in_range("phi", phi, 0.0, f64::INFINITY, "phi >= 0")?;
    let p = gear.period();
    let per = gear.turns_ratio() * p; // φ advance per period of R_n
    let whole = libm::floor(ph / per);
    let target = ph - whole * per;
    let (mut lo, mut hi) = (0.0, p);
    let mut t = target / gear.turns_ratio();
    let mut phi_t = driving_angle(gear, t)?;
    for _ in 0..100 {
        let f = phi_t - target;
        if libm::fabs(f) <= 1e-14 {
            return Ok(whole * p + t);
        }
        if f > 0.0 {
            hi = t;
        } else {
            lo = t;
        }
        let newton = t - f / gear.ratio(t);
        let next = if newton > lo && newton < hi {
            newton
        } else {
            0.5 * (lo + hi)
        };
        if hi - lo <= 4.0 * f64::EPSILON * p {
            return Ok(whole * p + t);
        }
        let (a, b, sign) = if next >= t {
            (t, next, 1.0)
        } else {
            (next, t, -1.0)
        };
        let (inc, ok, _) = integrate_pieces(gear, &|x| gear.ratio(x), a, b);
        if !ok {
            return Err(KinError::NotConverged {
                what: "inverse angle map",
                achieved: libm::fabs(f),
            });
        }
        phi_t += sign * inc;
        t = next;
    }
    Err(KinError::NotConverged {
        what: "inverse angle map",
        achieved: hi - lo,
    })
}

/// One point of a pair of pitch profiles.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct PitchPoint {
    /// Driven-gear (NG2) angle θ₂ \[rad\].
    pub theta_driven: f64,
    /// NG2 pitch radius at θ₂ \[m\], Eq. 16.
    pub r_driven: f64,
    /// Driving-gear (NG1) angle φ(θ₂) \[rad\], Eq. 17/41.
    pub theta_driving: f64,
    /// NG1 pitch radius at φ \[m\], Eq. 15.
    pub r_driving: f64,
}

/// What the profile generator checked.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ProfileCheck {
    /// φ(2π) − 2π·turns_ratio \[rad\]: zero when both profiles close (for the
    /// 1:1 SGIVT pair: both gears turn exactly once per NG2 revolution).
    pub closure_error: f64,
    /// max |r_NG1 + r_NG2 − D| over the points \[m\] (Eq. 15/39).
    pub max_centre_distance_error: f64,
    /// Smallest and largest NG2 radius \[m\].
    pub r_driven_range: (f64, f64),
    /// Smallest and largest NG1 radius \[m\].
    pub r_driving_range: (f64, f64),
}

/// Fill `out` with pitch-profile points at θ₂ = 2π j/(n−1), j = 0..n−1
/// (both ends included), integrating Eq. 17/41 interval by interval.
///
/// # Errors
/// D finite and > 0; `out.len() >= 2`; `NotConverged` if a quadrature fails.
pub fn pitch_profile<G: GearRatio + ?Sized>(
    gear: &G,
    centre_distance: f64,
    out: &mut [PitchPoint],
) -> Result<ProfileCheck, KinError> {
    let d = positive("centre_distance", centre_distance)?;
    if out.len() < 2 {
        return Err(KinError::BufferTooSmall {
            needed: 2,
            capacity: out.len(),
        });
    }
    let n = out.len();
    let h = 2.0 * PI / (n - 1) as f64;
    let mut phi = 0.0;
    let mut prev = 0.0;
    let mut check = ProfileCheck {
        closure_error: 0.0,
        max_centre_distance_error: 0.0,
        r_driven_range: (f64::INFINITY, 0.0),
        r_driving_range: (f64::INFINITY, 0.0),
    };
    for (j, pt) in out.iter_mut().enumerate() {
        let th = if j == n - 1 { 2.0 * PI } else { j as f64 * h };
        if j > 0 {
            let (inc, ok, err) = integrate_pieces(gear, &|t| gear.ratio(t), prev, th);
            if !ok {
                return Err(KinError::NotConverged {
                    what: "pitch profile angle map",
                    achieved: err,
                });
            }
            phi += inc;
        }
        prev = th;
        let rn = gear.ratio(th);
        let r2 = d * rn / (rn + 1.0);
        let r1 = d / (rn + 1.0);
        *pt = PitchPoint {
            theta_driven: th,
            r_driven: r2,
            theta_driving: phi,
            r_driving: r1,
        };
        check.max_centre_distance_error =
            libm::fmax(check.max_centre_distance_error, libm::fabs(r1 + r2 - d));
        check.r_driven_range = (
            libm::fmin(check.r_driven_range.0, r2),
            libm::fmax(check.r_driven_range.1, r2),
        );
        check.r_driving_range = (
            libm::fmin(check.r_driving_range.0, r1),
            libm::fmax(check.r_driving_range.1, r1),
        );
    }
    check.closure_error = phi - 2.0 * PI * gear.turns_ratio();
    Ok(check)
}

/// GIVT pair, Eq. 13: R_n(θ') = 3 R_r(3θ', r_o), where θ' = θ/3 is the NG2
/// angle and R_r the reduced ratio at the design eccentricity r_o. Mean 3:
/// NG1 turns three times per NG2 revolution (§2.1.5).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct GivtNcg {
    geometry: GivtGeometry,
    r_o: f64,
    mean_r: f64,
    corners: [f64; MAX_CORNERS],
    n_corners: usize,
}

impl GivtNcg {
    /// Design for eccentricity r_o (§2.1.5 uses r_o = 10 mm).
    ///
    /// # Errors
    /// As [`GivtGeometry::reduced_ratio`]; r_o must be > 0.
    pub fn new(geometry: GivtGeometry, r_o: f64) -> Result<Self, KinError> {
        positive("r_o", r_o)?;
        let mean_r = geometry.average_module_ratio(r_o)?;
        let mut c = [0.0; MAX_CORNERS];
        let n = geometry.module_corners(r_o, &mut c)?;
        for x in filled(&mut c, n)? {
            *x /= 3.0; // θ' = θ/3
        }
        Ok(Self {
            geometry,
            r_o,
            mean_r,
            corners: c,
            n_corners: n,
        })
    }

    /// The design eccentricity r_o \[m\].
    pub fn r_o(&self) -> f64 {
        self.r_o
    }

    /// ω_out/ω_NG1 = 3R(θ, r)/R_n(θ') (Eq. 12) at crank angle θ = 3θ' for an
    /// eccentricity r (constant = avg R(r_o) when r = r_o).
    ///
    /// # Errors
    /// As [`GivtGeometry::module_ratio`].
    pub fn output_to_ng1(&self, theta_prime: f64, r: f64) -> Result<f64, KinError> {
        let th = finite("theta_prime", theta_prime)?;
        Ok(3.0 * self.geometry.module_ratio(3.0 * th, r)? / self.ratio(th))
    }

    /// `scale · module(3θ₂, r_o) / mean R`: R_n (Eq. 13) with `module_ratio`
    /// and scale 3, dR_n/dθ₂ with `module_ratio_derivative` and scale 9
    /// (chain rule through θ = 3θ₂).
    fn of_module(
        &self,
        module: fn(&GivtGeometry, f64, f64) -> Result<f64, KinError>,
        scale: f64,
        theta2: f64,
    ) -> f64 {
        // r_o was validated in `new`; θ finite is the caller's contract.
        let value = module(&self.geometry, 3.0 * theta2, self.r_o).unwrap_or(f64::NAN);
        scale * value / self.mean_r
    }
}

impl GearRatio for GivtNcg {
    fn ratio(&self, theta2: f64) -> f64 {
        self.of_module(GivtGeometry::module_ratio, 3.0, theta2)
    }
    fn ratio_derivative(&self, theta2: f64) -> f64 {
        self.of_module(GivtGeometry::module_ratio_derivative, 9.0, theta2)
    }
    fn period(&self) -> f64 {
        MODULE_PERIOD / 3.0
    }
    fn turns_ratio(&self) -> f64 {
        3.0
    }
    fn corners(&self) -> &[f64] {
        // `new` checked n_corners against the buffer (`filled`).
        self.corners.get(..self.n_corners).unwrap_or_default()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::NCG_AMPLITUDE;

    /// Closed-form angle map of Eq. 38: on the segment θ = kπ/2 + φ, |φ| ≤ π/4,
    /// R_n = A cos φ, so θ_eng = kπ/2 + A sin φ (A√2 = π/2 per segment).
    fn closed_form_phi(theta: f64) -> f64 {
        let k = libm::floor((theta + FRAC_PI_4) / FRAC_PI_2);
        k * FRAC_PI_2 + NCG_AMPLITUDE * libm::sin(theta - k * FRAC_PI_2)
    }

    /// NG1 radius as a function of its own angle, closed form (inverse of the above).
    fn closed_form_r1(theta_eng: f64, d: f64) -> f64 {
        let k = libm::floor((theta_eng + FRAC_PI_4) / FRAC_PI_2);
        let s = (theta_eng - k * FRAC_PI_2) / NCG_AMPLITUDE;
        let rn = NCG_AMPLITUDE * libm::sqrt(1.0 - s * s); // A cos φ
        d / (rn + 1.0)
    }

    /// Eq. 39–41 for the SGIVT (D = 5.25 in): the integrated angle map equals
    /// the closed form to 1e-12 rad, both gears close after one revolution
    /// (φ(2π) = 2π), and NG1's radius looked up at its *own* angle (closed
    /// form) plus NG2's radius is D at every point.
    #[test]
    fn sgivt_profiles_close_and_keep_centre_distance() {
        // The prototype's D (`SgivtGeometry::prototype().ncg_centre_distance`).
        let d = crate::units::inch_to_m(5.25);
        let mut pts = [PitchPoint::default(); 721];
        let check = pitch_profile(&SgivtNcg, d, &mut pts).unwrap();
        assert!(check.closure_error.abs() < 1e-12, "{}", check.closure_error);
        for p in &pts {
            let exact = closed_form_phi(p.theta_driven);
            assert!(
                (p.theta_driving - exact).abs() < 1e-12,
                "θ₂={}",
                p.theta_driven
            );
            let r1 = closed_form_r1(p.theta_driving, d);
            assert!((r1 + p.r_driven - d).abs() < 1e-12 * d);
        }
        // Radii of Fig. 23(a): R_n ∈ [π/4, π/(2√2)] gives r_NG2 ∈ [D·0.4399, D·0.5262].
        let lo = d * (PI / 4.0) / (PI / 4.0 + 1.0);
        let hi = d * NCG_AMPLITUDE / (NCG_AMPLITUDE + 1.0);
        assert!((check.r_driven_range.0 - lo).abs() < 1e-12);
        assert!((check.r_driven_range.1 - hi).abs() < 1e-12);
    }

    /// Rolling without slip: the two pitch curves have the same arc length
    /// between matching points (polyline lengths converge to each other).
    #[test]
    fn pitch_curves_roll_without_slip() {
        let d = 0.1;
        let mut pts = [PitchPoint::default(); 4001];
        pitch_profile(&SgivtNcg, d, &mut pts).unwrap();
        let len = |f: &dyn Fn(&PitchPoint) -> (f64, f64)| {
            pts.windows(2)
                .map(|w| {
                    let (r0, a0) = f(&w[0]);
                    let (r1, a1) = f(&w[1]);
                    let (dx, dy) = (r1 * a1.cos() - r0 * a0.cos(), r1 * a1.sin() - r0 * a0.sin());
                    (dx * dx + dy * dy).sqrt()
                })
                .sum::<f64>()
        };
        let l2 = len(&|p| (p.r_driven, p.theta_driven));
        let l1 = len(&|p| (p.r_driving, p.theta_driving));
        assert!((l1 - l2).abs() < 1e-6 * l2, "{l1} vs {l2}");
    }

    /// Eq. 42: the exact Fourier coefficients of Eq. 38 by quadrature equal the
    /// closed form 2(−1)^(k+1)/(16k²−1); the printed ones are 0.9 times them.
    #[test]
    fn fourier_fit_of_eq38() {
        assert!((fourier_coefficient(&SgivtNcg, 0).unwrap() - 1.0).abs() < 1e-13);
        for k in 1..=8 {
            let num = fourier_coefficient(&SgivtNcg, k).unwrap();
            assert!(
                (num - fourier_coefficient_eq38(k)).abs() < 1e-13,
                "k={k}: {num}"
            );
        }
        for (k, printed) in EQ42_PRINTED.iter().enumerate() {
            let exact = fourier_coefficient_eq38(k as u32 + 1);
            // The printed digits are not the Fourier coefficients ...
            assert!((printed - exact).abs() > 5e-4, "k={}", k + 1);
            // ... but 0.9 × them, rounded (to 3 significant digits; 0.007 to 1).
            let half_ulp = if k == 3 { 5e-4 } else { 5e-5 };
            assert!((printed - 0.9 * exact).abs() <= half_ulp, "k={}", k + 1);
        }
    }

    /// The smooth ratio Eq. 42 keeps the 1:1 design (mean 1): its profiles close.
    #[test]
    fn smooth_profiles_close() {
        let mut pts = [PitchPoint::default(); 361];
        for g in [SmoothNcg::PRINTED, SmoothNcg::fourier()] {
            let c = pitch_profile(&g, 0.13335, &mut pts).unwrap();
            assert!(c.closure_error.abs() < 1e-12);
        }
    }

    /// GIVT pair (r_o = 10 mm, D = 10 mm): mean of R_n is 3, NG1 turns three
    /// times per NG2 revolution (closure), and ω_out/ω_NG1 = avg R is constant
    /// at r = r_o (Eq. 12–13) and varies at r = 5 mm (Fig. 10).
    #[test]
    fn givt_pair_design() {
        let g = GivtNcg::new(GivtGeometry::illustrative(), 0.010).unwrap();
        let mut pts = [PitchPoint::default(); 1441];
        let c = pitch_profile(&g, 0.010, &mut pts).unwrap();
        assert!(c.closure_error.abs() < 1e-10, "{}", c.closure_error);
        assert!(c.max_centre_distance_error < 1e-15);
        assert!((fourier_coefficient(&g, 0).unwrap() - 3.0).abs() < 1e-12);
        let avg = GivtGeometry::illustrative()
            .average_module_ratio(0.010)
            .unwrap();
        for k in 0..500 {
            let t = k as f64 * 0.0123;
            assert!((g.output_to_ng1(t, 0.010).unwrap() - avg).abs() < 1e-12 * avg);
        }
    }

    /// driven_angle inverts driving_angle.
    #[test]
    fn angle_map_inverse() {
        for k in 0..100 {
            let t = k as f64 * 0.0777;
            let phi = driving_angle(&SgivtNcg, t).unwrap();
            assert!((driven_angle(&SgivtNcg, phi).unwrap() - t).abs() < 1e-12);
        }
        assert!(driving_angle(&SgivtNcg, -1.0).is_err());
        assert!(driven_angle(&SgivtNcg, f64::NAN).is_err());
    }
}
