//! The direction control module of the GIVT (§2.1.6, Eq. 18–19): two
//! planetary sets whose held member selects forward or reverse output.

use crate::error::{finite, positive, KinError};

/// Which member of the direction module is held (§2.1.6).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum DirectionMode {
    /// Ring gear 1 and carrier 2 grounded, ω_rg1 = 0.
    Forward,
    /// Sun gears grounded, ω_sunDIR = 0.
    Reverse,
}

/// Speeds of the direction module for an input ω_rg2 (Eq. 18–19).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DirectionSpeeds {
    /// Sun-gear speed ω_sunDIR.
    pub omega_sun: f64,
    /// Ring gear 1 / carrier 2 speed ω_rg1.
    pub omega_rg1: f64,
    /// Output, carrier 1: ω_carrier1.
    pub omega_carrier1: f64,
}

/// The direction control module of §2.1.6: two planetary sets PG1, PG2 with
/// equal sun radii and equal planet radii.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DirectionModule {
    /// Sun-gear radius r_sunDIR \[m\].
    pub r_sun: f64,
    /// Planet-gear radius r_planetDIR \[m\].
    pub r_planet: f64,
}

impl DirectionModule {
    /// Speeds for the input ω_rg2 in the given mode: Eq. 18–19 with the held
    /// member's speed set to zero, solved as a 2×2 linear system (Cramer's rule).
    ///
    /// # Errors
    /// Radii must be finite and positive; ω_rg2 finite.
    pub fn speeds(&self, mode: DirectionMode, omega_rg2: f64) -> Result<DirectionSpeeds, KinError> {
        let s = positive("r_sun", self.r_sun)?;
        let p = positive("r_planet", self.r_planet)?;
        let w2 = finite("omega_rg2", omega_rg2)?;
        let (ring, carrier) = (s + 2.0 * p, 2.0 * (s + p));
        // Eq. 18: s ω_sun + ring ω_rg1 − carrier ω_c1 = 0
        // Eq. 19: s ω_sun − carrier ω_rg1 = −ring ω_rg2
        Ok(match mode {
            DirectionMode::Forward => {
                // unknowns (ω_sun, ω_c1), ω_rg1 = 0:
                // [s, −carrier; s, 0] x = [0; −ring ω_rg2]
                let det = s * 0.0 - (-carrier) * s;
                let omega_sun = (0.0 * 0.0 - (-carrier) * (-ring * w2)) / det;
                let omega_c1 = (s * (-ring * w2) - s * 0.0) / det;
                DirectionSpeeds {
                    omega_sun,
                    omega_rg1: 0.0,
                    omega_carrier1: omega_c1,
                }
            }
            DirectionMode::Reverse => {
                // unknowns (ω_rg1, ω_c1), ω_sun = 0:
                // [ring, −carrier; −carrier, 0] x = [0; −ring ω_rg2]
                let det = ring * 0.0 - (-carrier) * (-carrier);
                let omega_rg1 = (0.0 * 0.0 - (-carrier) * (-ring * w2)) / det;
                let omega_c1 = (ring * (-ring * w2) - (-carrier) * 0.0) / det;
                DirectionSpeeds {
                    omega_sun: 0.0,
                    omega_rg1,
                    omega_carrier1: omega_c1,
                }
            }
        })
    }

    /// ω_carrier1/ω_rg2 in forward mode from Eq. 18–19:
    /// −(r_s + 2r_p)/(2(r_s + r_p)). The thesis prints 4 in the denominator,
    /// which Eq. 18–19 do not give (see the crate README).
    pub fn forward_ratio(&self) -> f64 {
        let (s, p) = (self.r_sun, self.r_planet);
        -(s + 2.0 * p) / (2.0 * (s + p))
    }

    /// ω_carrier1/ω_rg2 in reverse mode from Eq. 18–19:
    /// +(r_s + 2r_p)²/(4(r_s + r_p)²). The thesis prints a minus sign, which
    /// would make both modes turn the same way.
    pub fn reverse_ratio(&self) -> f64 {
        let (s, p) = (self.r_sun, self.r_planet);
        let q = (s + 2.0 * p) / (2.0 * (s + p));
        q * q
    }

    /// The forward ratio as printed under Eq. 19: −(r_s + 2r_p)/(4(r_s + r_p)).
    pub fn forward_ratio_printed(&self) -> f64 {
        let (s, p) = (self.r_sun, self.r_planet);
        -(s + 2.0 * p) / (4.0 * (s + p))
    }

    /// The reverse ratio as printed: −(r_s + 2r_p)²/(4(r_s + r_p)²).
    pub fn reverse_ratio_printed(&self) -> f64 {
        -self.reverse_ratio()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Eq. 18–19 solved by substitution (independently of the Cramer solve in
    /// the code) for several radius pairs: forward −(s+2p)/(2(s+p)), reverse
    /// +((s+2p)/(2(s+p)))². The printed forms differ: forward has 4 in the
    /// denominator (half the magnitude), reverse has the wrong sign.
    #[test]
    fn direction_module_eq18_19() {
        for &(s, p) in &[(1.0, 1.0), (2.0, 1.0), (0.02, 0.007), (1.0, 3.0)] {
            let m = DirectionModule {
                r_sun: s,
                r_planet: p,
            };
            let w2 = 2.5;
            // Forward: ω_rg1 = 0 ⇒ Eq. 19: ω_sun = −(s+2p)ω_rg2/s;
            //          Eq. 18: ω_c1 = s ω_sun/(2(s+p)).
            let sun = -(s + 2.0 * p) * w2 / s;
            let c1 = s * sun / (2.0 * (s + p));
            let f = m.speeds(DirectionMode::Forward, w2).unwrap();
            assert!((f.omega_sun - sun).abs() < 1e-12 && (f.omega_carrier1 - c1).abs() < 1e-12);
            assert!((c1 / w2 - m.forward_ratio()).abs() < 1e-14);
            // residuals of Eq. 18–19 themselves
            let res18 =
                f.omega_sun * s + f.omega_rg1 * (s + 2.0 * p) - 2.0 * f.omega_carrier1 * (s + p);
            let res19 = f.omega_sun * s + w2 * (s + 2.0 * p) - 2.0 * f.omega_rg1 * (s + p);
            assert!(res18.abs() < 1e-12 && res19.abs() < 1e-12);
            // Reverse: ω_sun = 0 ⇒ Eq. 19: ω_rg1 = (s+2p)ω_rg2/(2(s+p));
            //          Eq. 18: ω_c1 = (s+2p)ω_rg1/(2(s+p)).
            let rg1 = (s + 2.0 * p) * w2 / (2.0 * (s + p));
            let c1 = (s + 2.0 * p) * rg1 / (2.0 * (s + p));
            let r = m.speeds(DirectionMode::Reverse, w2).unwrap();
            assert!((r.omega_rg1 - rg1).abs() < 1e-12 && (r.omega_carrier1 - c1).abs() < 1e-12);
            assert!((c1 / w2 - m.reverse_ratio()).abs() < 1e-14);
            // The two modes turn the output in opposite directions.
            assert!(m.forward_ratio() < 0.0 && m.reverse_ratio() > 0.0);
            // Printed forms: forward is half the derived one, reverse the negative.
            assert!((m.forward_ratio_printed() - 0.5 * m.forward_ratio()).abs() < 1e-15);
            assert!((m.reverse_ratio_printed() + m.reverse_ratio()).abs() < 1e-15);
        }
    }
}
