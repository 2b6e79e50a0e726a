//! The Neimark–Sacker boundary of a forced family in (ω, p), sampled: at each
//! requested p the frequency-response curve of `family(p)` is traced
//! ([`trace`]) and each of its Neimark–Sacker points located on the engine's
//! extended system ([`crate::bifurcation`]: a pair of Floquet multipliers on
//! the unit circle). Not a continuation of the curve: a turn of the boundary
//! in p between two samples is not followed, and each sample costs a trace.

use crate::bifurcation::{BifurcationError, BifurcationKind};
use crate::error::HbError;
use crate::events::{trace, TraceOptions};
use crate::family::{FamilyBranch, Frequency};
use crate::ihb::HbOptions;
use crate::modified::ModifiedIhb;
use crate::problem::{AtFrequency, PeriodicProblem};
use faer::c64;

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

/// The located Neimark–Sacker points of the FRC of `family(p)` from
/// `omega_from` to `omega_to`, for each p of `ps`, in order (module docs).
/// A point whose location failed is left out.
///
/// # Errors
/// `family`'s error; the start or trace failures of each FRC.
pub fn neimark_sacker_points<P, F>(
    family: F,
    hb: &HbOptions,
    omega_from: f64,
    omega_to: f64,
    ps: &[f64],
) -> Result<Vec<NeimarkSackerPoint>, HbError>
where
    P: PeriodicProblem,
    F: Fn(f64) -> Result<P, HbError>,
{
    let mut found = Vec::new();
    for &p in ps {
        let problem = family(p)?;
        let at = AtFrequency::new(&problem, omega_from);
        let start = ModifiedIhb::new(&at, hb.clone())?.solve(omega_from, None)?;
        let mut branch = FamilyBranch::new(Frequency(&problem), hb, omega_from)?;
        let opts = TraceOptions {
            lambda_to: omega_to,
            ..TraceOptions::default()
        };
        let traced = trace(&mut branch, &start.coeffs, omega_from, &opts).map_err(|e| match e {
            BifurcationError::Hb(h) => h,
            other => HbError::InvalidInput(other.to_string()),
        })?;
        for event in traced.events {
            if let (BifurcationKind::NeimarkSacker, Ok(b)) = (event.kind, event.location) {
                found.push(NeimarkSackerPoint {
                    p,
                    omega: b.lambda,
                    coeffs: b.q,
                    multipliers: b.multipliers,
                });
            }
        }
    }
    Ok(found)
}
