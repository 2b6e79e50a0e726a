//! Parameters (Table 1) and coefficients of the IVT dynamic equation, Eq. 151:
//!
//! ```text
//! J(r,θ) θ̈ = G(θ) r − ½ J_θ(θ) θ̇² − F_m(θ) θ̇ + f1(θ, V_m) − f2(θ, T_U) r
//! J   = J_a + J_b r² + J_c r² f² + J_d f²
//! J_θ = 2 (J_c r² + J_d) f f_θ
//! G   = g (sin θ + cos θ)            (printed form; see [`GravityModel`])
//! F_m = (k_t k_e / R_a) f²,  f1 = (k_t / R_a) f V_m,  f2 = 2√2 f T_U / (π r_u)
//! ```
//!
//! θ is the angle of the driven noncircular gear, r the roller eccentricity,
//! V_m the motor voltage and T_U the brake torque (SI units throughout).

use crate::{params, variant};
use core::f64::consts::{PI, SQRT_2};

/// How the gravity term G(θ) of Eq. 151 is formed.
///
/// The thesis prints `G = g(sin θ + cos θ)`, but the potential energy Eq. 148,
/// `V_t = m_r g (−sin θ + cos θ) r`, implies `G = m_r g (sin θ + cos θ)`
/// (SPEC §5). The printed form is the default so that results compare with
/// the thesis; the mass-weighted form is what Lagrange's equation gives.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum GravityModel {
    /// `G = g (sin θ + cos θ)`, as printed under Eq. 151.
    #[default]
    Printed,
    /// `G = m_r g (sin θ + cos θ)`, consistent with Eq. 148.
    RollerMass,
}

/// Physical parameters of the IVT system (Table 1), SI units.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PlantParams {
    /// Armature resistance R_a \[Ω\].
    pub r_a: f64,
    /// Back-EMF (velocity) constant k_e \[V·s/rad\].
    pub k_e: f64,
    /// Torque constant k_t \[N·m/A\].
    pub k_t: f64,
    /// Armature inductance L_a \[H\] (Eq. 137; 0 = neglected as in Eq. 138).
    pub l_a: f64,
    /// Driving noncircular gear inertia J_N1 \[kg·m²\] (= J_d).
    pub j_n1: f64,
    /// Driven noncircular gear inertia J_N2 \[kg·m²\].
    pub j_n2: f64,
    /// Input shaft inertia \[kg·m²\].
    pub j_inshaft: f64,
    /// Carriers with planet gears \[kg·m²\].
    pub j_carrier: f64,
    /// Two sets of ring gears \[kg·m²\].
    pub j_ring: f64,
    /// Crank shaft, crank gears and rollers about their centres \[kg·m²\].
    pub j_crk: f64,
    /// Mass of all rollers m_r \[kg\].
    pub m_r: f64,
    /// Reduced driver mass m_dr = m_d + J_u/r_u² \[kg\].
    pub m_dr: f64,
    /// Output shaft and brake inertia J_U \[kg·m²\].
    pub j_u: f64,
    /// Output gear radius r_u \[m\].
    pub r_u: f64,
    /// Gravitational acceleration g \[m/s²\].
    pub g: f64,
    /// Sun/planet diameter ratio d_S/d_P of the input-control module (1 in the design).
    pub sun_to_planet: f64,
    /// Which form of G(θ) to use.
    pub gravity: GravityModel,
    /// Largest eccentricity the mechanism allows, r_max \[m\] (§4.2.1: 0.012 m).
    pub r_max: f64,
}

impl PlantParams {
    /// Table 1 as printed, `G` in its printed form, r_max = 0.012 m, L_a = 0.
    pub const fn printed() -> Self {
        Self {
            r_a: 0.24,
            k_e: 0.75,
            k_t: 0.76,
            l_a: 0.0,
            j_n1: 0.002347,
            j_n2: 0.002293,
            j_inshaft: 0.00002,
            j_carrier: 0.001618,
            j_ring: 0.00663,
            j_crk: 0.007995,
            m_r: 1.16,
            m_dr: 0.9664,
            j_u: 0.000206,
            r_u: 0.0222,
            g: 9.8,
            sun_to_planet: 1.0,
            gravity: GravityModel::Printed,
            r_max: 0.012,
        }
    }

    /// The calibration under which Chapter 4's computations reproduce (SPEC §5):
    /// Table 1 with both motor constants divided by 10, k_t = 0.076 N·m/A and
    /// k_e = 0.075 V·s/rad, everything else as printed.
    ///
    /// Inferred, not printed: with these constants the full Eq. 151 dynamics
    /// give r̄(6 V, 6 N·m) ≈ 0.0068 m (Fig. 39: 0.0067) and the printed Eq. 158
    /// fits the steady-state sweep to about its own fit residual, while the
    /// rig data (Fig. 50) fit Table 1. See [`PlantPreset::ThesisCh4`].
    pub const fn thesis_ch4() -> Self {
        let mut p = Self::printed();
        p.k_t = 0.076;
        p.k_e = 0.075;
        p
    }

    /// J_a = J_N2 + J_carrier + J_inshaft + J_crk + J_ring·4(d_S+d_P)²/(d_S+2d_P)² (§4.1).
    pub fn j_a(&self) -> f64 {
        let (ds, dp) = (self.sun_to_planet, 1.0);
        let ring = 4.0 * (ds + dp) * (ds + dp) / ((ds + 2.0 * dp) * (ds + 2.0 * dp));
        self.j_n2 + self.j_carrier + self.j_inshaft + self.j_crk + self.j_ring * ring
    }

    /// J_b = m_r + m_dr (§4.1).
    pub fn j_b(&self) -> f64 {
        self.m_r + self.m_dr
    }

    /// J_c = J_U · 8/(π² r_u²) (§4.1).
    pub fn j_c(&self) -> f64 {
        self.j_u * 8.0 / (PI * PI * self.r_u * self.r_u)
    }

    /// J_d = J_N1 (§4.1).
    pub fn j_d(&self) -> f64 {
        self.j_n1
    }

    /// Electrical damping k_t k_e / R_a: F_m = this · f² (thesis: 2.375).
    pub fn motor_damping(&self) -> f64 {
        self.k_t * self.k_e / self.r_a
    }

    /// Voltage gain k_t / R_a: f1 = this · f · V_m (thesis: 3.1667).
    pub fn motor_gain(&self) -> f64 {
        self.k_t / self.r_a
    }

    /// Load gain 2√2/(π r_u): f2 = this · f · T_U (thesis: 40.5548).
    pub fn load_gain(&self) -> f64 {
        2.0 * SQRT_2 / (PI * self.r_u)
    }

    /// Coefficient of (sin θ + cos θ) in G: g, or m_r g (see [`GravityModel`]).
    pub fn gravity_gain(&self) -> f64 {
        match self.gravity {
            GravityModel::Printed => self.g,
            GravityModel::RollerMass => self.m_r * self.g,
        }
    }

    /// All coefficients of Eq. 151 at (θ, r) for inputs (V_m, T_U).
    #[inline]
    pub fn terms(&self, theta: f64, r: f64, v_m: f64, t_u: f64) -> PlantTerms {
        let (f, f_theta) = variant::f_and_f_theta(theta);
        self.terms_with_f(theta, f, f_theta, r, v_m, t_u)
    }

    /// As [`Self::terms`] with f and f_θ already known (the integrators
    /// evaluate them once per stage).
    #[inline]
    pub fn terms_with_f(
        &self,
        theta: f64,
        f: f64,
        ft: f64,
        r: f64,
        v_m: f64,
        t_u: f64,
    ) -> PlantTerms {
        let (s, c) = (libm::sin(theta), libm::cos(theta));
        self.terms_with_trig(s, c, f, ft, r, v_m, t_u)
    }

    /// As [`Self::terms_with_f`] with sin θ and cos θ also known (harmonic
    /// balance evaluates one `sin_cos` per sample and derives f from it).
    #[inline]
    #[allow(clippy::too_many_arguments)]
    pub fn terms_with_trig(
        &self,
        sin_theta: f64,
        cos_theta: f64,
        f: f64,
        f_theta: f64,
        r: f64,
        v_m: f64,
        t_u: f64,
    ) -> PlantTerms {
        let (j_c, j_d) = (self.j_c(), self.j_d());
        let r2 = r * r;
        let f2sq = f * f;
        PlantTerms {
            f,
            f_theta,
            j: self.j_a() + self.j_b() * r2 + j_c * r2 * f2sq + j_d * f2sq,
            j_theta: 2.0 * (j_c * r2 + j_d) * f * f_theta,
            j_r: 2.0 * self.j_b() * r + 2.0 * j_c * r * f2sq,
            j_theta_r: 4.0 * j_c * r * f * f_theta,
            g: self.gravity_gain() * (sin_theta + cos_theta),
            f_m: self.motor_damping() * f2sq,
            f1: self.motor_gain() * f * v_m,
            f2: self.load_gain() * f * t_u,
        }
    }

    /// θ̈ from Eq. 151 at (θ, ω = θ̇) with eccentricity r and inputs (V_m, T_U).
    #[inline]
    pub fn acceleration(&self, theta: f64, omega: f64, r: f64, v_m: f64, t_u: f64) -> f64 {
        self.terms(theta, r, v_m, t_u).acceleration(omega, r)
    }

    /// Check every parameter against its range in [`params::KEYS`]
    /// (`plant.<field>`: finite, > 0 where a zero divides or is no machine,
    /// >= 0 where 0 neglects the term, below a physical ceiling).
    ///
    /// # Errors
    /// Names the first offending parameter, in Table 1 order.
    pub fn validate(&self) -> Result<(), ParamError> {
        /// `[("field", "plant.field", self.field), ...]`.
        macro_rules! named {
            ($($field:ident),*) => {
                [$((stringify!($field), concat!("plant.", stringify!($field)), self.$field)),*]
            };
        }
        #[rustfmt::skip]
        let all = named!(r_a, k_e, k_t, l_a, j_n1, j_n2, j_inshaft, j_carrier, j_ring,
                         j_crk, m_r, m_dr, j_u, r_u, g, sun_to_planet, r_max);
        for (name, key, value) in all {
            params::check(key, value).map_err(|refused| ParamError {
                name,
                value,
                refused,
            })?;
        }
        Ok(())
    }
}

impl Default for PlantParams {
    fn default() -> Self {
        Self::printed()
    }
}

/// A named parameter set of the plant: what `--plant` and a scene's
/// `[plant] preset` select.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum PlantPreset {
    /// Table 1 as printed ([`PlantParams::printed`]); the default.
    #[default]
    Printed,
    /// Table 1 with k_t and k_e divided by 10 ([`PlantParams::thesis_ch4`]),
    /// the calibration Chapter 4's computations appear to use (SPEC §5).
    ThesisCh4,
}

impl PlantPreset {
    /// Every preset, in the order the CLI lists them.
    pub const ALL: [Self; 2] = [Self::Printed, Self::ThesisCh4];

    /// The parameters of this preset.
    pub const fn params(self) -> PlantParams {
        match self {
            Self::Printed => PlantParams::printed(),
            Self::ThesisCh4 => PlantParams::thesis_ch4(),
        }
    }

    /// The stable name used by the CLI, scenes, JSON and Python.
    pub const fn name(self) -> &'static str {
        match self {
            Self::Printed => "printed",
            Self::ThesisCh4 => "thesis-ch4",
        }
    }

    /// The preset of a name, `None` for an unknown one.
    pub fn from_name(name: &str) -> Option<Self> {
        Self::ALL.into_iter().find(|p| p.name() == name)
    }
}

/// A plant parameter outside its range ([`params::KEYS`]' `plant.<field>`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ParamError {
    /// Field name in [`PlantParams`].
    pub name: &'static str,
    /// The offending value.
    pub value: f64,
    /// The refusal: the value as typed and the range.
    pub refused: params::Refused,
}

impl core::fmt::Display for ParamError {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        write!(f, "plant parameter `{}` {}", self.name, self.refused)
    }
}

#[cfg(feature = "std")]
impl std::error::Error for ParamError {}

/// The coefficients of Eq. 151 at one (θ, r, V_m, T_U), plus the r-derivatives
/// that the linearization of Appendix B needs.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PlantTerms {
    /// f(θ), Eq. 43.
    pub f: f64,
    /// f_θ(θ), Eq. 139.
    pub f_theta: f64,
    /// J(r, θ).
    pub j: f64,
    /// J_θ = ∂J/∂θ at constant r.
    pub j_theta: f64,
    /// J_r = ∂J/∂r = 2 J_b r + 2 J_c r f² (Appendix B).
    pub j_r: f64,
    /// J_θr = ∂²J/∂θ∂r = 4 J_c r f f_θ (Appendix B).
    pub j_theta_r: f64,
    /// G(θ).
    pub g: f64,
    /// F_m(θ).
    pub f_m: f64,
    /// f1(θ, V_m).
    pub f1: f64,
    /// f2(θ, T_U) (multiplies r).
    pub f2: f64,
}

impl PlantTerms {
    /// Net driving torque Γ = G r + f1 − f2 r (Eq. 161).
    #[inline]
    pub fn drive(&self, r: f64) -> f64 {
        self.g * r + self.f1 - self.f2 * r
    }

    /// θ̈ = (Γ − ½ J_θ ω² − F_m ω)/J, Eq. 151.
    #[inline]
    pub fn acceleration(&self, omega: f64, r: f64) -> f64 {
        (self.drive(r) - 0.5 * self.j_theta * omega * omega - self.f_m * omega) / self.j
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn close(a: f64, b: f64, rel: f64) -> bool {
        (a - b).abs() <= rel * b.abs()
    }

    /// §4.1 prints J_a = 0.0237 kg·m², J_b = 2.1264 kg, J_c = 0.3388 kg,
    /// F_m = 2.375 f², f1 = 3.1667 f V_m, f2 = 40.5548 f T_U: each to the
    /// printed digits (half a unit in the last place).
    #[test]
    fn derived_constants_match_section_4_1() {
        let p = PlantParams::printed();
        assert!((p.j_a() - 0.0237).abs() <= 0.5e-4, "J_a = {}", p.j_a());
        assert!((p.j_b() - 2.1264).abs() <= 0.5e-4, "J_b = {}", p.j_b());
        assert!((p.j_c() - 0.3388).abs() <= 0.5e-4, "J_c = {}", p.j_c());
        assert!((p.motor_damping() - 2.375).abs() <= 0.5e-3);
        assert!((p.motor_gain() - 3.1667).abs() <= 0.5e-4);
        assert!(
            (p.load_gain() - 40.5548).abs() <= 0.5e-4,
            "{}",
            p.load_gain()
        );
    }

    /// J_θ is the θ-derivative of J at constant r; J_r and J_θr likewise in r.
    #[test]
    fn inertia_derivatives_by_finite_differences() {
        let p = PlantParams::printed();
        let (h, r) = (1e-6, 0.008);
        for k in 0..200 {
            let th = 0.01 + k as f64 * 0.031;
            let phi = (th + core::f64::consts::FRAC_PI_4).rem_euclid(core::f64::consts::FRAC_PI_2);
            if !(1e-3..=core::f64::consts::FRAC_PI_2 - 1e-3).contains(&phi) {
                continue;
            }
            let t = p.terms(th, r, 6.0, 6.0);
            let dj = (p.terms(th + h, r, 6.0, 6.0).j - p.terms(th - h, r, 6.0, 6.0).j) / (2.0 * h);
            assert!((dj - t.j_theta).abs() < 1e-9);
            let djr = (p.terms(th, r + h, 6.0, 6.0).j - p.terms(th, r - h, 6.0, 6.0).j) / (2.0 * h);
            assert!((djr - t.j_r).abs() < 1e-8);
            let djtr = (p.terms(th, r + h, 6.0, 6.0).j_theta
                - p.terms(th, r - h, 6.0, 6.0).j_theta)
                / (2.0 * h);
            assert!((djtr - t.j_theta_r).abs() < 1e-8);
        }
    }

    #[test]
    fn gravity_models() {
        let mut p = PlantParams::printed();
        let t = p.terms(0.3, 0.01, 6.0, 6.0);
        assert!(close(t.g, 9.8 * (0.3f64.sin() + 0.3f64.cos()), 1e-15));
        p.gravity = GravityModel::RollerMass;
        let t = p.terms(0.3, 0.01, 6.0, 6.0);
        assert!(close(
            t.g,
            1.16 * 9.8 * (0.3f64.sin() + 0.3f64.cos()),
            1e-15
        ));
    }

    #[test]
    fn validate_names_bad_parameter() {
        let mut p = PlantParams::printed();
        assert!(p.validate().is_ok());
        p.r_u = f64::NAN;
        assert_eq!(p.validate().unwrap_err().name, "r_u");
        p = PlantParams::printed();
        p.m_r = -1.0;
        assert_eq!(p.validate().unwrap_err().name, "m_r");
    }

    /// `thesis-ch4` divides the two motor constants of Table 1 by 10 and
    /// nothing else: the motor gain k_t/R_a falls 10× and the damping
    /// k_t·k_e/R_a 100× (0.31667 and 0.02375 against §4.1's 3.1667, 2.375).
    #[test]
    fn thesis_ch4_preset_divides_only_the_motor_constants() {
        let (p, c) = (PlantParams::printed(), PlantParams::thesis_ch4());
        assert_eq!(c.k_t, 0.076);
        assert_eq!(c.k_e, 0.075);
        let mut back = c;
        back.k_t = p.k_t;
        back.k_e = p.k_e;
        assert_eq!(back, p);
        assert!(close(c.motor_gain(), 0.316667, 1e-5));
        assert!(close(c.motor_damping(), 0.02375, 1e-9));
        assert!(c.validate().is_ok());
        for preset in PlantPreset::ALL {
            assert_eq!(PlantPreset::from_name(preset.name()), Some(preset));
        }
        assert_eq!(PlantPreset::from_name("thesis"), None);
        assert_eq!(PlantPreset::default().params(), p);
    }
}
