//! Numbers the results carry as columns: JSON lists, numpy arrays in Python.

use ivt_hb::{c64, HbError};
use serde::{Serialize, Serializer};

/// The newtype-struct name by which a serializer recognizes an [`Array`]
/// (ivt-py turns it into a numpy array; JSON sees the plain list).
pub const ARRAY_NAME: &str = "ivt_jobs::Array";

/// A column of numbers (coefficients, a curve's ω or amplitudes): a list in
/// JSON, a numpy array in Python.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Array<T>(pub Vec<T>);

impl<T: Serialize> Serialize for Array<T> {
    fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        s.serialize_newtype_struct(ARRAY_NAME, &self.0)
    }
}

impl<T> FromIterator<T> for Array<T> {
    fn from_iter<I: IntoIterator<Item = T>>(iter: I) -> Self {
        Self(iter.into_iter().collect())
    }
}

/// Floquet multipliers as `[[re, im], ...]`.
pub fn pairs(mu: &[c64]) -> Vec<[f64; 2]> {
    mu.iter().map(|m| [m.re, m.im]).collect()
}

/// [`pairs`] of the multipliers of the orbit at `omega` when every one is
/// finite: a non-finite multiplier means the stability is unknown, which is
/// an error ([`HbError::NonFiniteMultipliers`], `steps` the Hsu sub-intervals
/// or their cap), never a verdict "unstable".
///
/// # Errors
/// [`HbError::NonFiniteMultipliers`].
pub fn finite_pairs(mu: &[c64], omega: f64, steps: usize) -> Result<Vec<[f64; 2]>, HbError> {
    check_finite(mu, omega, steps).map(|()| pairs(mu))
}

/// [`finite_pairs`]'s check alone (no copy of the multipliers).
///
/// # Errors
/// [`HbError::NonFiniteMultipliers`].
pub fn check_finite(mu: &[c64], omega: f64, steps: usize) -> Result<(), HbError> {
    if mu.iter().all(|m| m.re.is_finite() && m.im.is_finite()) {
        Ok(())
    } else {
        Err(HbError::NonFiniteMultipliers { omega, steps })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn finite_multipliers_pass_and_any_nan_or_inf_is_an_error() {
        let ok = [c64::new(0.5, 0.1), c64::new(0.5, -0.1)];
        assert_eq!(
            finite_pairs(&ok, 1.0, 256).unwrap(),
            vec![[0.5, 0.1], [0.5, -0.1]]
        );
        for bad in [f64::NAN, f64::INFINITY, f64::NEG_INFINITY] {
            let mu = [c64::new(0.5, 0.0), c64::new(bad, 0.0)];
            assert!(matches!(
                finite_pairs(&mu, 2.0, 256),
                Err(HbError::NonFiniteMultipliers { omega, steps: 256 }) if omega == 2.0
            ));
            let mu = [c64::new(0.5, bad)];
            assert!(finite_pairs(&mu, 2.0, 256).is_err());
        }
    }
}
