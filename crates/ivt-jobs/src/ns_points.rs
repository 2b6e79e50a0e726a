//! The Neimark–Sacker boundary of a forced family in (ω, p), sampled: at each
//! requested p the frequency-response curve of `family(p)` is traced with
//! its events ([`ivt_hb::branches::frc`]) and each of its Neimark–Sacker points
//! is located on the engine's extended system ([`ivt_hb::branches::events`]: a
//! pair of Floquet multipliers on the unit circle). Not a continuation of the curve: a turn of the boundary
//! in p between two samples is not followed, and each sample costs a trace
//! (the continuation is [`ivt_hb::branches::codim2::bifurcation_curve`]).

use crate::{frc, FrcRequest};
use faer::c64;
use ivt_hb::branches::events::BifurcationKind;
use ivt_hb::branches::frc::FrcOptions;
use ivt_hb::orbit::ihb::HbOptions;
use ivt_hb::problem::{boxed_family, BoxedFamily, PeriodicProblem};
use ivt_hb::HbError;

/// A located Neimark–Sacker point of the FRC at one p.
#[derive(Debug, Clone, PartialEq)]
pub struct NeimarkSackerPoint {
    /// The second parameter.
    pub p: f64,
    /// Excitation frequency ω_f.
    pub omega: f64,
    /// Fourier coefficients of the orbit.
    pub coeffs: Vec<f64>,
    /// Its Floquet multipliers (the critical pair on the unit circle first).
    pub multipliers: Vec<c64>,
}

/// The located Neimark–Sacker points of the FRC `sweep` (its interval and
/// path) of `family(p)`, for each p of `ps`, in order (module docs).
/// A point whose location failed is left out.
///
/// # Errors
/// `family`'s error; the start or trace failures of each FRC.
pub fn neimark_sacker_points<'p, P, F>(
    family: F,
    hb: &HbOptions,
    sweep: &FrcOptions,
    ps: &[f64],
) -> Result<Vec<NeimarkSackerPoint>, HbError>
where
    P: PeriodicProblem + 'p,
    F: Fn(f64) -> Result<P, HbError>,
{
    neimark_sacker_points_of(&boxed_family(family), hb, sweep, ps)
}

/// [`neimark_sacker_points`] on the boxed family.
fn neimark_sacker_points_of(
    family: &BoxedFamily<'_, '_>,
    hb: &HbOptions,
    sweep: &FrcOptions,
    ps: &[f64],
) -> Result<Vec<NeimarkSackerPoint>, HbError> {
    let mut found = Vec::new();
    let req = FrcRequest {
        options: sweep.clone(),
        events: true,
    };
    for &p in ps {
        let curve = frc(&family(p)?, hb, &req)?;
        for e in curve.bifurcations {
            if let (BifurcationKind::NeimarkSacker, true, Some(omega), Some(q), Some(mu)) =
                (e.kind, e.located, e.omega, e.coeffs, e.multipliers)
            {
                found.push(NeimarkSackerPoint {
                    p,
                    omega,
                    coeffs: q.0,
                    multipliers: mu.iter().map(|[re, im]| c64::new(*re, *im)).collect(),
                });
            }
        }
    }
    Ok(found)
}
