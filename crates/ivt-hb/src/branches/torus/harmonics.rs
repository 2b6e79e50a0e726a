//! The harmonics of a two-frequency ansatz: which `k = (k₁, k₂)` of
//! `x(θ₁, θ₂) = a₀/2 + Σ_k a_k cos(k₁θ₁ + k₂θ₂) + b_k sin(k₁θ₁ + k₂θ₂)` are
//! kept ([`Truncation`]), one of each pair `±k` (the half set: `k₂ > 0`, or
//! `k₂ = 0` and `k₁ > 0`), in a fixed order.

use crate::error::HbError;

/// Which harmonics `k = (k₁, k₂)` a torus keeps (Krack & Gross, ch. 5: the
/// box and the diamond truncation).
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "snake_case", tag = "kind")]
pub enum Truncation {
    /// `|k₁| ≤ h1` and `|k₂| ≤ h2`.
    Box {
        /// Largest `|k₁|`.
        h1: usize,
        /// Largest `|k₂|`.
        h2: usize,
    },
    /// `|k₁| + |k₂| ≤ h`.
    Diamond {
        /// Largest `|k₁| + |k₂|`.
        h: usize,
    },
}

impl Truncation {
    /// Whether `(k1, k2)` is kept.
    pub fn keeps(self, k1: i64, k2: i64) -> bool {
        match self {
            Self::Box { h1, h2 } => {
                k1.unsigned_abs() as usize <= h1 && k2.unsigned_abs() as usize <= h2
            }
            Self::Diamond { h } => (k1.unsigned_abs() + k2.unsigned_abs()) as usize <= h,
        }
    }

    /// The largest `|k₁|` and `|k₂|` kept.
    pub fn extent(self) -> (usize, usize) {
        match self {
            Self::Box { h1, h2 } => (h1, h2),
            Self::Diamond { h } => (h, h),
        }
    }

    /// The truncation grown where the torus `coeffs` (`n_dof` blocks over
    /// `harmonics`, this truncation's) is least resolved: along an axis
    /// whose edge harmonics (`|k₁| = h1`, `|k₂| = h2`) hold at least a tenth
    /// of the larger edge's largest amplitude, by a quarter (θ₁) or a half
    /// (θ₂) of its order and at least by 2 and 4. A diamond grows by 4.
    pub fn grown(self, harmonics: &TorusHarmonics, coeffs: &[f64]) -> Self {
        let Self::Box { h1, h2 } = self else {
            return self.widened(4);
        };
        let (h, l) = (harmonics.len(), harmonics.coeff_len());
        let (mut t1, mut t2) = (0.0f64, 0.0f64);
        for block in coeffs.chunks_exact(l) {
            for (i, (k1, k2)) in harmonics.iter().enumerate() {
                let a = block.get(1 + i).copied().unwrap_or(0.0);
                let b = block.get(1 + h + i).copied().unwrap_or(0.0);
                let size = a.hypot(b);
                if k1.unsigned_abs() as usize == h1 {
                    t1 = t1.max(size);
                }
                if k2.unsigned_abs() as usize == h2 {
                    t2 = t2.max(size);
                }
            }
        }
        let top = t1.max(t2);
        let grow1 = if t1 >= 0.1 * top { (h1 / 4).max(2) } else { 0 };
        let grow2 = if t2 >= 0.1 * top { (h2 / 2).max(4) } else { 0 };
        Self::Box {
            h1: h1 + grow1,
            h2: h2 + grow2,
        }
    }

    /// The same kind of truncation `extra` orders wider (the error estimate's).
    pub fn widened(self, extra: usize) -> Self {
        match self {
            Self::Box { h1, h2 } => Self::Box {
                h1: h1 + extra,
                h2: h2 + extra,
            },
            Self::Diamond { h } => Self::Diamond { h: h + extra },
        }
    }
}

/// The kept half set of harmonics, ordered by `k₂`, then `k₁`.
#[derive(Debug, Clone, PartialEq)]
pub struct TorusHarmonics {
    truncation: Truncation,
    list: Vec<(i64, i64)>,
}

impl TorusHarmonics {
    /// The half set of `truncation`.
    ///
    /// # Errors
    /// [`HbError::InvalidInput`] when no harmonic with `k₂ ≠ 0` is kept
    /// (no torus) or the set exceeds [`crate::limits`]'s unknowns.
    pub fn new(truncation: Truncation) -> Result<Self, HbError> {
        let (h1, h2) = truncation.extent();
        let count = match truncation {
            Truncation::Box { h1, h2 } => h1
                .checked_mul(2)
                .and_then(|w| w.checked_add(1))
                .and_then(|w| w.checked_mul(h2))
                .and_then(|c| c.checked_add(h1)),
            Truncation::Diamond { h } => h.checked_mul(h).and_then(|c| c.checked_add(h)),
        };
        match count {
            Some(c) if crate::limits::unknowns_error(1, c).is_none() => {}
            _ => {
                return Err(HbError::InvalidInput(format!(
                    "torus truncation {truncation:?} keeps more than {} harmonics",
                    crate::limits::MAX_UNKNOWNS / 2
                )))
            }
        }
        let (e1, e2) = (h1 as i64, h2 as i64);
        let mut list = Vec::new();
        for k2 in 0..=e2 {
            for k1 in -e1..=e1 {
                let upper = k2 > 0 || k1 > 0;
                if upper && truncation.keeps(k1, k2) {
                    list.push((k1, k2));
                }
            }
        }
        if !list.iter().any(|&(_, k2)| k2 != 0) {
            return Err(HbError::InvalidInput(
                "a torus needs a harmonic of the second frequency (h2 ≥ 1)".into(),
            ));
        }
        Ok(Self { truncation, list })
    }

    /// The truncation.
    pub fn truncation(&self) -> Truncation {
        self.truncation
    }

    /// Number of kept harmonics H (the half set, the mean excluded).
    pub fn len(&self) -> usize {
        self.list.len()
    }

    /// True without harmonics (never: [`Self::new`] refuses it).
    pub fn is_empty(&self) -> bool {
        self.list.is_empty()
    }

    /// Coefficients per DOF: `2H + 1` (`[a₀, a_1..a_H, b_1..b_H]`).
    pub fn coeff_len(&self) -> usize {
        2 * self.list.len() + 1
    }

    /// The harmonics in order.
    pub fn iter(&self) -> impl Iterator<Item = (i64, i64)> + '_ {
        self.list.iter().copied()
    }

    /// Harmonic `i` (0-based in the half set).
    pub fn get(&self, i: usize) -> Option<(i64, i64)> {
        self.list.get(i).copied()
    }

    /// The index of `(k1, k2)` in the half set, with `+1` if it is listed as
    /// itself and `−1` if as its mirror `−k` (`None` for `(0, 0)` and
    /// harmonics not kept).
    pub fn index(&self, k1: i64, k2: i64) -> Option<(usize, f64)> {
        let (k, sign) = if k2 > 0 || (k2 == 0 && k1 > 0) {
            ((k1, k2), 1.0)
        } else {
            ((-k1, -k2), -1.0)
        };
        self.list
            .binary_search_by(|&(a1, a2)| (a2, a1).cmp(&(k.1, k.0)))
            .ok()
            .map(|i| (i, sign))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn box_and_diamond_half_sets() {
        let b = TorusHarmonics::new(Truncation::Box { h1: 2, h2: 1 }).unwrap();
        // k₂ = 0: k₁ = 1, 2; k₂ = 1: k₁ = −2..2.
        assert_eq!(b.len(), 7);
        assert_eq!(b.get(2), Some((-2, 1)));
        let d = TorusHarmonics::new(Truncation::Diamond { h: 2 }).unwrap();
        // 2h² + 2h + 1 = 13 lattice points, 6 in the half set.
        assert_eq!(d.len(), 6);
        assert_eq!(d.index(0, 2), Some((5, 1.0)));
        assert_eq!(d.index(-1, -1), Some((4, -1.0)));
        assert_eq!(d.index(0, 0), None);
        assert_eq!(d.index(2, 1), None);
        assert!(TorusHarmonics::new(Truncation::Box { h1: 3, h2: 0 }).is_err());
    }
}
