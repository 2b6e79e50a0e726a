//! The error type of the kinematics functions (a plain enum: the crate is
//! `no_std`). Out-of-domain inputs give an error instead of NaN.

use core::fmt;

/// Why a kinematic quantity could not be computed.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum KinError {
    /// An input is NaN or infinite.
    NotFinite {
        /// Name of the input (the symbol of the thesis, e.g. `"theta"`).
        name: &'static str,
    },
    /// An input is finite but outside the domain where the equation holds.
    OutOfDomain {
        /// Name of the input.
        name: &'static str,
        /// The offending value (SI units).
        value: f64,
        /// What it must satisfy, e.g. `"0 <= r < l1 (Eq. 8)"`.
        requirement: &'static str,
    },
    /// A caller-provided output slice is too short.
    BufferTooSmall {
        /// How many elements the result needs (at least).
        needed: usize,
        /// How many the slice holds.
        capacity: usize,
    },
    /// An iterative construction did not reach its tolerance.
    NotConverged {
        /// What was being built.
        what: &'static str,
        /// The best error reached.
        achieved: f64,
    },
}

impl fmt::Display for KinError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            KinError::NotFinite { name } => write!(f, "input `{name}` is not finite"),
            KinError::OutOfDomain {
                name,
                value,
                requirement,
            } => write!(
                f,
                "input `{name}` = {value} is out of domain: {requirement}"
            ),
            KinError::BufferTooSmall { needed, capacity } => write!(
                f,
                "output buffer too small: needs at least {needed}, holds {capacity}"
            ),
            KinError::NotConverged { what, achieved } => {
                write!(f, "{what} did not reach its tolerance (best {achieved:e})")
            }
        }
    }
}

#[cfg(feature = "std")]
impl std::error::Error for KinError {}

/// `Ok(x)` if `x` is finite, else [`KinError::NotFinite`].
#[inline]
pub(crate) fn finite(name: &'static str, x: f64) -> Result<f64, KinError> {
    if x.is_finite() {
        Ok(x)
    } else {
        Err(KinError::NotFinite { name })
    }
}

/// Write `value` at `out[*count]` and advance `count`, or report how large
/// the caller's buffer must be.
#[inline]
pub(crate) fn push<T>(out: &mut [T], count: &mut usize, value: T) -> Result<(), KinError> {
    let capacity = out.len();
    let slot = out.get_mut(*count).ok_or(KinError::BufferTooSmall {
        needed: *count + 1,
        capacity,
    })?;
    *slot = value;
    *count += 1;
    Ok(())
}

/// The first `count` entries of a buffer filled by [`push`], or
/// `BufferTooSmall` if it has fewer (a count from elsewhere).
#[inline]
pub(crate) fn filled<T>(out: &mut [T], count: usize) -> Result<&mut [T], KinError> {
    let capacity = out.len();
    out.get_mut(..count).ok_or(KinError::BufferTooSmall {
        needed: count,
        capacity,
    })
}

/// `Ok(x)` if `x` is finite and `lo <= x < hi` (pass `f64::INFINITY` for no
/// upper bound), else the matching error.
#[inline]
pub(crate) fn in_range(
    name: &'static str,
    x: f64,
    lo: f64,
    hi: f64,
    requirement: &'static str,
) -> Result<f64, KinError> {
    let x = finite(name, x)?;
    if x >= lo && x < hi {
        Ok(x)
    } else {
        Err(KinError::OutOfDomain {
            name,
            value: x,
            requirement,
        })
    }
}

/// `Ok(x)` if `x` is finite and `> 0`.
#[inline]
pub(crate) fn positive(name: &'static str, x: f64) -> Result<f64, KinError> {
    let x = finite(name, x)?;
    if x > 0.0 {
        Ok(x)
    } else {
        Err(KinError::OutOfDomain {
            name,
            value: x,
            requirement: "must be > 0",
        })
    }
}

/// Test helper: a ratio function of (θ, r) rejects a NaN angle as
/// [`KinError::NotFinite`], a negative eccentricity as
/// [`KinError::OutOfDomain`] and an infinite one as an error.
#[cfg(test)]
pub(crate) fn assert_rejects_bad_theta_and_r(ratio: impl Fn(f64, f64) -> Result<f64, KinError>) {
    assert!(matches!(
        ratio(f64::NAN, 0.01),
        Err(KinError::NotFinite { .. })
    ));
    assert!(matches!(
        ratio(0.1, -0.01),
        Err(KinError::OutOfDomain { .. })
    ));
    assert!(ratio(0.1, f64::INFINITY).is_err());
}
