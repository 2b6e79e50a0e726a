//! The scene's side of the one description of every user-settable number
//! ([`ivt_kin::params`]: key, unit, physical range, f32): each section's
//! `validate` checks its numbers here, and a refusal becomes an [`Invalid`]
//! naming the key (or one knot of a profile, `inputs.v_m[2]`) and the value
//! as typed. How much work a valid scene asks for is
//! [`Scene::estimated_events`](super::Scene::estimated_events)'s job.

use super::Invalid;
pub use ivt_kin::params::{find, fits_f32, Bound, Key, Refused, Typed, KEYS, NOT_F32};

/// `value` spelled as a person types it ([`Typed`]): `0.01`,
/// `3600.0000001`, `1e300` — never 300 digits.
#[must_use]
pub fn typed(value: f64) -> String {
    Typed(value).to_string()
}

/// Check `value` against `key`, the error reported at `at` (the key itself,
/// or one knot of a profile: `inputs.v_m[2]`).
///
/// # Errors
/// [`Invalid`] naming `at`, the value as typed and the range.
pub fn check_at(key: &'static Key, at: &str, value: f64) -> Result<(), Invalid> {
    key.check(value)
        .map_err(|refused| Invalid::new(at, refused.to_string()))
}

/// Check scene number `name` (one of [`KEYS`]).
///
/// # Errors
/// [`Invalid`] for a value out of range, or for a `name` that [`KEYS`] does
/// not describe (a bug the unit tests rule out).
pub fn check(name: &str, value: f64) -> Result<(), Invalid> {
    ivt_kin::params::check(name, value).map_err(|refused| Invalid::new(name, refused.to_string()))
}

/// The description of scene key `name`.
///
/// # Errors
/// [`Invalid`] for a `name` that [`KEYS`] does not describe.
pub fn described(name: &str) -> Result<&'static Key, Invalid> {
    find(name).ok_or_else(|| Invalid::new(name, "has no description in ivt_kin::params::KEYS"))
}

/// Check numbers of one section in order, each `(key, value)`; the first
/// refusal is the error.
///
/// # Errors
/// [`Invalid`] naming the first key whose value [`check`] refuses.
pub fn check_all(numbers: &[(&str, f64)]) -> Result<(), Invalid> {
    numbers
        .iter()
        .try_for_each(|&(name, value)| check(name, value))
}

/// `check_fields!(self, "stepper", accel, miss_prob)`: [`check_all`] of the
/// named fields of a section, each under its key `section.field`, so the
/// key a refusal names is the field's own name in the scene file.
macro_rules! check_fields {
    ($owner:expr, $section:literal, $($field:ident),+ $(,)?) => {
        $crate::scene::keys::check_all(&[
            $((concat!($section, ".", stringify!($field)), $owner.$field)),+
        ])
    };
}
pub(crate) use check_fields;
