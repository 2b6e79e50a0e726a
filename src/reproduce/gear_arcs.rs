//! §2.2.4: the SGIVT pitch profiles replaced by tangent circular arcs
//! (Fig. 23(b), `ivt_kin::arcs`), and the speed ratio such a pair gives
//! (the curve "with the approximated function" of Fig. 24, and the
//! ripple the rig's arc-cut gears predict for Fig. 48).

use ivt_kin::arcs::{fit_arcs, Arc, ArcFit, ArcOptions, GearProfile, Member};
use ivt_kin::ncg::SgivtNcg;
use ivt_kin::sgivt::SgivtGeometry;
use ivt_kin::KinError;
use std::f64::consts::PI;

/// Points sampled along each arc to tabulate r(ψ): with 24 arcs per
/// revolution (§2.2.4 at 1 %) the polar spacing is ~4e-3 rad, so linear
/// interpolation of r(ψ) between samples is exact to ~1e-5 relative
/// (h²/8 times the relative curvature of r), far below the 1e-2 ripple it
/// is used for (test `arc_chain_radius_and_ratio`).
const SAMPLES_PER_ARC: usize = 64;

/// One SGIVT gear (Eq. 38, D = 5.25 in) as a chain of tangent arcs, tabulated
/// as its polar radius r(ψ) over one revolution.
pub(crate) struct ArcProfile {
    /// The arcs in order along the curve.
    pub arcs: Vec<Arc>,
    /// What the fit achieved (deviations from the theoretical radius).
    pub fit: ArcFit,
    /// Polar angles of the samples in [0, 2π), increasing.
    psi: Vec<f64>,
    /// Polar radii at `psi` \[m\].
    rho: Vec<f64>,
}

impl ArcProfile {
    /// Fit the arcs of §2.2.4 (1 % away from the corners, corners rounded
    /// over ±2°, `ArcOptions::default`) to one member of the SGIVT pair.
    ///
    /// # Errors
    /// As [`fit_arcs`].
    pub(crate) fn sgivt(member: Member) -> Result<Self, KinError> {
        let profile = GearProfile {
            gear: &SgivtNcg,
            centre_distance: SgivtGeometry::prototype().ncg_centre_distance,
            member,
        };
        let mut buf = vec![Arc::default(); 1 << 14];
        let fit = fit_arcs(&profile, &ArcOptions::default(), &mut buf)?;
        buf.truncate(fit.count);
        let mut polar: Vec<(f64, f64)> = buf
            .iter()
            .flat_map(|a| {
                (0..SAMPLES_PER_ARC).map(move |j| {
                    let p = a.point_at(a.length * j as f64 / SAMPLES_PER_ARC as f64);
                    (p[1].atan2(p[0]).rem_euclid(2.0 * PI), p[0].hypot(p[1]))
                })
            })
            .collect();
        polar.sort_by(|a, b| a.0.total_cmp(&b.0));
        let (psi, rho) = polar.into_iter().unzip();
        Ok(Self {
            arcs: buf,
            fit,
            psi,
            rho,
        })
    }

    /// Polar radius of the arc chain at ψ \[m\] (linear between samples,
    /// periodic in 2π). NaN for a chain without samples.
    pub(crate) fn radius(&self, psi: f64) -> f64 {
        let psi = psi.rem_euclid(2.0 * PI);
        let i = self.psi.partition_point(|&p| p <= psi);
        let sample = |j: usize| self.psi.get(j).copied().zip(self.rho.get(j).copied());
        let last = self.psi.len().checked_sub(1).and_then(sample);
        // Neighbours (angle, radius) on either side, wrapping across 0 = 2π.
        let lo = match i.checked_sub(1) {
            Some(j) => sample(j),
            None => last.map(|(p, r)| (p - 2.0 * PI, r)),
        };
        let hi = sample(i).or_else(|| sample(0).map(|(p, r)| (p + 2.0 * PI, r)));
        match lo.zip(hi) {
            Some(((p0, r0), (p1, r1))) => r0 + (psi - p0) / (p1 - p0) * (r1 - r0),
            None => f64::NAN,
        }
    }

    /// R_n = ω_NG1/ω_NG2 of a pair whose NG2 (this profile) is the arc chain
    /// and whose NG1 is its conjugate on the line of centres: Eq. 16 inverted,
    /// R_n = r_NG2/(D − r_NG2), at the NG2 angle θ_in.
    pub(crate) fn ratio(&self, theta_in: f64) -> f64 {
        let r = self.radius(theta_in);
        r / (SgivtGeometry::prototype().ncg_centre_distance - r)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use ivt_kin::ncg::GearRatio;
    use std::f64::consts::FRAC_PI_4;

    /// The tabulated arc chain against the closed-form Eq. 38 radius
    /// r_NG2 = D R_n/(R_n + 1), R_n = A cos(θ − kπ/2): within the 1 % of
    /// §2.2.4 away from the corner windows (±2°), within the fit's reported
    /// corner deviation (+1e-4 for the interpolation) inside them; and the
    /// arc pair's R_n equals Eq. 38's where the chain follows the curve.
    #[test]
    fn arc_chain_radius_and_ratio() {
        let p = ArcProfile::sgivt(Member::Driven).unwrap();
        let d = SgivtGeometry::prototype().ncg_centre_distance;
        let a = PI / (2.0 * 2f64.sqrt());
        let mut worst_smooth: f64 = 0.0;
        for j in 0..7200 {
            let psi = 2.0 * PI * (j as f64 + 0.5) / 7200.0;
            let k = ((psi + FRAC_PI_4) / (0.5 * PI)).floor();
            let rn = a * (psi - k * 0.5 * PI).cos();
            let exact = d * rn / (rn + 1.0);
            let dev = (p.radius(psi) - exact).abs() / exact;
            let corner = (psi - FRAC_PI_4).rem_euclid(0.5 * PI);
            let near_corner = corner.min(0.5 * PI - corner) < 2f64.to_radians();
            if near_corner {
                assert!(dev <= p.fit.max_corner_deviation + 1e-4, "ψ = {psi}: {dev}");
            } else {
                assert!(dev <= 0.01, "ψ = {psi}: {dev}");
                worst_smooth = worst_smooth.max(dev);
                // R_n = r/(D − r): a 1 % radius error is ≤ ~2 % in R_n.
                let rel = (p.ratio(psi) - SgivtNcg.ratio(psi)).abs() / SgivtNcg.ratio(psi);
                assert!(rel <= 0.021, "ψ = {psi}: R_n off by {rel}");
            }
        }
        // The interpolated chain reaches the deviation the fit reports (the
        // table is the chain, not the theoretical curve).
        assert!(
            (worst_smooth - p.fit.max_deviation).abs() < 2e-4,
            "{worst_smooth} vs {}",
            p.fit.max_deviation
        );
    }
}
