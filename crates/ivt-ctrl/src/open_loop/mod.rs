//! The open-loop law `u_ol(V_m, T_U)`, Eq. 158–160 (§4.2.1).
//!
//! The coefficient type [`OpenLoopCoeffs`] is plain `f32` arrays so that a
//! generated file can declare one as a `const` (the `design` helper's
//! `ivt ol fit --emit-rust` writes `refit.rs` with `pub const REFIT`). The
//! printed set is [`THESIS`].
//!
//! Evaluation (done at the slow input rate, never per pulse):
//! 1. clamp (V_m, T_U) to the working region and flag it (no silent
//!    extrapolation of the fit);
//! 2. if the boundary `f_B > 0` (Eq. 159) → over-drive, `u_ol = r_max` (Eq. 160);
//! 3. else `u_ol = r_f(V_m, T_U)` (Eq. 158), limited to `[0, r_max]`, where a
//!    negative value is reported as under-drive (SPEC §5).

mod thesis;
pub use thesis::THESIS;

/// Number of powers of V_m in `poly` (V_m⁰…V_m², as in Eq. 158).
pub const POLY_V_TERMS: usize = 3;
/// Number of powers of T_U in `poly` (T_U⁰…T_U⁴, as in Eq. 158).
pub const POLY_T_TERMS: usize = 5;

/// Coefficients of an open-loop law of the form of Eq. 158–160.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct OpenLoopCoeffs {
    /// `poly[i][j]` multiplies `V_m^i · T_U^j`, r_f in metres: the form of
    /// Eq. 158 (degree ≤ 2 in V_m, ≤ 4 in T_U; unused terms are 0).
    pub poly: [[f32; POLY_T_TERMS]; POLY_V_TERMS],
    /// Boundary `f_B = b[0]·V_m + b[1]·T_U + b[2]` (Eq. 159); `f_B > 0` means
    /// over-drive (u_ol = r_max). A set without a boundary uses `[0, 0, -1]`.
    pub boundary: [f32; 3],
    /// Largest eccentricity r_max \[m\] (§4.2.1: 0.012 m).
    pub r_max: f32,
    /// Working region of V_m \[V\], `[min, max]`; readings outside are clamped.
    pub v_m_range: [f32; 2],
    /// Working region of T_U \[N·m\], `[min, max]`; readings outside are clamped.
    pub t_u_range: [f32; 2],
}

/// Which branch of Eq. 160 produced `u_ol`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
#[repr(u8)]
pub enum OlRegion {
    /// `0 ≤ r_f ≤ r_max`, `f_B ≤ 0`: the polynomial value.
    #[default]
    Normal = 0,
    /// `f_B > 0` or `r_f > r_max`: u_ol = r_max, the speed will exceed ω0.
    OverDrive = 1,
    /// `r_f < 0`: the target speed is not reachable even at r = 0.
    UnderDrive = 2,
}

/// Result of evaluating the open-loop law.
#[derive(Clone, Copy, Debug, PartialEq, Default)]
pub struct OpenLoopValue {
    /// u_ol \[m\], in `[0, r_max]`.
    pub r_ol: f32,
    /// The branch of Eq. 160 taken.
    pub region: OlRegion,
    /// True if V_m or T_U lay outside the working region and were clamped.
    pub inputs_clamped: bool,
}

/// Clamp without the `f32::clamp` assertion (min > max would panic there).
#[inline]
pub(crate) fn clamp_f32(x: f32, lo: f32, hi: f32) -> f32 {
    let y = if x < lo { lo } else { x };
    if y > hi {
        hi
    } else {
        y
    }
}

impl OpenLoopCoeffs {
    /// True if every coefficient is finite and the ranges are ordered.
    #[must_use]
    pub fn is_valid(&self) -> bool {
        let finite = self.poly.iter().flatten().all(|c| c.is_finite())
            && self.boundary.iter().all(|c| c.is_finite());
        let ranges =
            self.v_m_range[0] <= self.v_m_range[1] && self.t_u_range[0] <= self.t_u_range[1];
        finite && ranges && self.r_max.is_finite() && self.r_max > 0.0
    }

    /// The polynomial r_f of Eq. 158 at (V_m, T_U), no clamping (Horner in
    /// T_U for each power of V_m, then Horner in V_m).
    #[must_use]
    pub fn r_f(&self, v_m: f32, t_u: f32) -> f32 {
        let mut acc = 0.0_f32;
        for row in self.poly.iter().rev() {
            let mut in_t = 0.0_f32;
            for c in row.iter().rev() {
                in_t = in_t * t_u + c;
            }
            acc = acc * v_m + in_t;
        }
        acc
    }

    /// The boundary function f_B of Eq. 159.
    #[must_use]
    pub fn f_b(&self, v_m: f32, t_u: f32) -> f32 {
        let [a, b, c] = self.boundary;
        a * v_m + b * t_u + c
    }

    /// u_ol by Eq. 160 with the clamping and flags described in the module doc.
    /// Non-finite inputs give u_ol = 0 with `inputs_clamped` set (the caller
    /// validates readings before this; this is the last line of defence).
    #[must_use]
    pub fn evaluate(&self, v_m: f32, t_u: f32) -> OpenLoopValue {
        if !(v_m.is_finite() && t_u.is_finite()) {
            return OpenLoopValue {
                r_ol: 0.0,
                region: OlRegion::UnderDrive,
                inputs_clamped: true,
            };
        }
        let v = clamp_f32(v_m, self.v_m_range[0], self.v_m_range[1]);
        let t = clamp_f32(t_u, self.t_u_range[0], self.t_u_range[1]);
        let inputs_clamped = v != v_m || t != t_u;
        let (r_ol, region) = if self.f_b(v, t) > 0.0 {
            (self.r_max, OlRegion::OverDrive)
        } else {
            let r = self.r_f(v, t);
            if r.is_nan() || r < 0.0 {
                (0.0, OlRegion::UnderDrive)
            } else if r > self.r_max {
                (self.r_max, OlRegion::OverDrive)
            } else {
                (r, OlRegion::Normal)
            }
        };
        OpenLoopValue {
            r_ol,
            region,
            inputs_clamped,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Eq. 158 written out term by term in f64, as printed.
    fn r_f_printed(v: f64, t: f64) -> f64 {
        3.2e-5 * t.powi(4) - 2.3e-5 * v * t.powi(3) - 6.65e-4 * t.powi(3)
            + 4.7e-4 * v * t * t
            + 4.6e-3 * t * t
            - 3.23e-3 * v * t
            - 2.1e-5 * v * v
            - 1.17e-2 * t
            + 8.85e-3 * v
            + 6.43e-3
    }

    #[test]
    fn thesis_polynomial_matches_printed_terms() {
        // Over the working grid of §4.2.1 (V_m 2:0.4:12, T_U 1.5:0.5:9).
        // f32 Horner vs f64 term-by-term: terms reach ~0.3 (3.2e-5·9⁴) and
        // cancel to ~1e-2, so allow 0.3 · 2⁻²³ · 8 ≈ 3e-7 m.
        for i in 0..=25 {
            for j in 0..=15 {
                let v = 2.0 + 0.4 * f64::from(i);
                let t = 1.5 + 0.5 * f64::from(j);
                let got = f64::from(THESIS.r_f(v as f32, t as f32));
                let want = r_f_printed(v, t);
                assert!((got - want).abs() < 3e-7, "V={v} T={t}: {got} vs {want}");
            }
        }
    }

    #[test]
    fn thesis_figure_39_point_and_boundary() {
        // Eq. 158 at (6 V, 6 N·m), by hand: 0.041472 − 0.029808 − 0.143640
        // + 0.101520 + 0.165600 − 0.116280 − 0.000756 − 0.070200 + 0.053100
        // + 0.006430 = 0.007438 m. Fig. 39 quotes the IHB value r̄ = 0.0067 m
        // there: the printed fit is 0.74 mm off its own data point (noted in
        // the README, like the other inconsistencies of SPEC §5).
        let v = THESIS.evaluate(6.0, 6.0);
        assert_eq!(v.region, OlRegion::Normal);
        assert!((v.r_ol - 0.007438).abs() < 2e-7, "{}", v.r_ol);
        // Eq. 159 → Eq. 160: V_m = 12, T_U = 1.5 gives f_B = 12 − 2.37 − 0.632 > 0.
        let o = THESIS.evaluate(12.0, 1.5);
        assert_eq!((o.r_ol, o.region), (0.012, OlRegion::OverDrive));
    }

    #[test]
    fn out_of_region_inputs_are_clamped_and_flagged() {
        let inside = THESIS.evaluate(12.0, 9.0);
        let outside = THESIS.evaluate(30.0, 20.0);
        assert!(!inside.inputs_clamped);
        assert!(outside.inputs_clamped);
        assert_eq!(inside.r_ol, outside.r_ol);
        let nan = THESIS.evaluate(f32::NAN, 3.0);
        assert!(nan.inputs_clamped && nan.r_ol == 0.0);
    }
}
