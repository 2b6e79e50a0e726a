//! The unit tests' random numbers: a fixed-seed xorshift64 stream, uniform
//! in [−½, ½), so each test's random matrices are the same on every run.

/// The stream from `seed` (nonzero): each call returns the next number.
pub(crate) fn uniform(mut seed: u64) -> impl FnMut() -> f64 {
    move || {
        seed ^= seed << 13;
        seed ^= seed >> 7;
        seed ^= seed << 17;
        (seed >> 11) as f64 / (1u64 << 53) as f64 - 0.5
    }
}
