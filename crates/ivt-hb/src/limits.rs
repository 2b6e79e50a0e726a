//! Size limits of the harmonic-balance engines, checked before anything is
//! allocated so that an absurd request is an error, never an abort.
//!
//! The dense solvers hold a few `m × m` matrices of f64 for `m` unknowns
//! (Jacobian, its inverse or LU, Broyden's update): [`MAX_UNKNOWNS`] = 4096
//! keeps one matrix at 128 MiB and a Newton step (an `O(m³)` LU) near a
//! second. The FFT buffers hold `2N` samples per DOF: [`MAX_SAMPLES`] = 2²²
//! keeps each buffer at 32 MiB.

/// Most unknowns `n_dof·(2n+1)` of one harmonic-balance system (IHB, STHB,
/// Hill): a dense `m × m` f64 matrix is then at most 128 MiB.
pub const MAX_UNKNOWNS: usize = 4096;

/// Most AFT samples `2N` per DOF (32 MiB per f64 buffer).
pub const MAX_SAMPLES: usize = 1 << 22;

/// The path engine's limit on the points of one path (`max_points`).
pub use ivt_path::limits::{path_points_error, MAX_PATH_POINTS};

/// `None` when `n_dof·(2·harmonics + 1)` unknowns fit [`MAX_UNKNOWNS`],
/// otherwise the reason (overflow-safe for any `usize`).
pub fn unknowns_error(n_dof: usize, harmonics: usize) -> Option<String> {
    let m = harmonics
        .checked_mul(2)
        .and_then(|h| h.checked_add(1))
        .and_then(|l| l.checked_mul(n_dof));
    match m {
        Some(m) if m <= MAX_UNKNOWNS => None,
        _ => Some(format!(
            "{n_dof} DOF × (2·{harmonics} + 1) harmonics exceed the limit of {MAX_UNKNOWNS} \
             unknowns (a dense Jacobian of that size is 128 MiB and O(m³) per step)"
        )),
    }
}

/// `None` when `2·n_half` samples fit [`MAX_SAMPLES`], otherwise the reason.
pub fn samples_error(n_half: usize) -> Option<String> {
    if n_half <= MAX_SAMPLES / 2 {
        None
    } else {
        Some(format!(
            "N = {n_half} asks for {} samples; the limit is {MAX_SAMPLES} (2N ≤ 2^22, 32 MiB per buffer)",
            n_half.saturating_mul(2)
        ))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn limits_refuse_overflowing_and_oversized_requests() {
        assert!(unknowns_error(1, 20).is_none());
        // 2·2047 + 1 = 4095 fits, 2·2048 + 1 = 4097 does not.
        assert!(unknowns_error(1, 2047).is_none());
        assert!(unknowns_error(1, 2048).is_some());
        assert!(unknowns_error(2, usize::MAX / 2).is_some());
        assert!(samples_error(64).is_none());
        assert!(samples_error(1 << 21).is_none());
        assert!(samples_error((1 << 21) + 1).is_some());
        assert!(samples_error(usize::MAX).is_some());
        assert!(path_points_error(100_000).is_none());
        assert!(path_points_error(100_001).is_some());
    }
}
