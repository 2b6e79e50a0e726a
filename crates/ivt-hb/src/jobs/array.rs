//! Numbers the results carry as columns: JSON lists, numpy arrays in Python.

use crate::c64;
use serde::{Serialize, Serializer};

/// The newtype-struct name by which a serializer recognizes an [`Array`]
/// (ivt-py turns it into a numpy array; JSON sees the plain list).
pub const ARRAY_NAME: &str = "ivt_hb::jobs::Array";

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
