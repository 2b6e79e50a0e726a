//! What the Floquet multipliers of a periodic orbit say: the verdict of the
//! leading one ([`StabilityKind`], [`classify`]). A leaf of the crate (it
//! knows no branch or path): the stability analyses that compute the
//! multipliers (ivt-hb's Hsu and Hill, ivt-sthb's) and the events that read
//! them share it.

use faer::c64;

/// What the leading Floquet multiplier of a periodic orbit says.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "snake_case")]
pub enum StabilityKind {
    /// All multipliers inside the unit circle.
    Stable,
    /// A real multiplier beyond +1 (saddle-node / fold side).
    Fold,
    /// A real multiplier beyond −1 (period doubling).
    PeriodDoubling,
    /// A complex pair outside the unit circle (Neimark–Sacker / secondary Hopf).
    NeimarkSacker,
}

impl StabilityKind {
    /// Short lowercase name for tables and JSON.
    pub fn name(self) -> &'static str {
        match self {
            Self::Stable => "stable",
            Self::Fold => "fold",
            Self::PeriodDoubling => "period_doubling",
            Self::NeimarkSacker => "neimark_sacker",
        }
    }
}

/// Classifies multipliers sorted by decreasing modulus (a multiplier counts as real
/// when |Im μ| ≤ 1e-7·|μ|; a NaN one as a fold).
pub fn classify(sorted: &[c64]) -> StabilityKind {
    match sorted.first() {
        Some(m) if m.norm() >= 1.0 => {
            if m.im.abs() > 1e-7 * m.norm() {
                StabilityKind::NeimarkSacker
            } else if m.re > 0.0 {
                StabilityKind::Fold
            } else {
                StabilityKind::PeriodDoubling
            }
        }
        Some(m) if m.norm().is_nan() => StabilityKind::Fold,
        _ => StabilityKind::Stable,
    }
}
