//! The continuation settings a user sets on any path — the keywords `ds`,
//! `ds_min`, `ds_max` and `max_points` of every Python function and CLI
//! command that follows one — as overrides of the path's own
//! [`ContinuationOptions`]: each path keeps its tuned defaults (the FRC's
//! Δη ≤ 0.08, the string curve's 0.05, a family's 0.02–0.05) and the user
//! changes only what they name.

use super::ContinuationOptions;
use crate::limits::path_points_error;
use serde::{Deserialize, Serialize};

/// Overrides of a path's steps and length; `None` keeps the path's own.
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Steps {
    /// First arclength step Δη ([`ContinuationOptions::ds`]).
    pub ds: Option<f64>,
    /// Smallest step before the path gives up ([`ContinuationOptions::ds_min`]).
    pub ds_min: Option<f64>,
    /// Largest step ([`ContinuationOptions::ds_max`]).
    pub ds_max: Option<f64>,
    /// Most points, the start included ([`ContinuationOptions::max_points`]).
    pub max_points: Option<usize>,
}

impl Steps {
    /// `base` with the given overrides.
    ///
    /// # Errors
    /// The reason, naming the keywords, when a given step is not finite and
    /// positive, when the merged steps break `ds_min ≤ ds ≤ ds_max` (a
    /// default taking part is named as the path's), or when `max_points` is
    /// 0 or above [`crate::limits::MAX_PATH_POINTS`]. A given `ds_max` below
    /// the path's first step, or a given `ds` below its smallest, is no
    /// error: the first step starts at the cap, the smallest is lowered to
    /// the first.
    pub fn on(&self, base: ContinuationOptions) -> Result<ContinuationOptions, String> {
        let given = [
            ("ds", self.ds),
            ("ds_min", self.ds_min),
            ("ds_max", self.ds_max),
        ];
        let bad = given.iter().find_map(|&(name, v)| {
            v.filter(|v| !(v.is_finite() && *v > 0.0))
                .map(|v| (name, v))
        });
        if let Some((name, v)) = bad {
            return Err(format!("`{name}` = {v:?} must be finite and > 0"));
        }
        if self.max_points == Some(0) {
            return Err("`max_points` must be ≥ 1".into());
        }
        let mut opts = base;
        opts.max_points = self.max_points.unwrap_or(opts.max_points);
        if let Some(why) = path_points_error(opts.max_points) {
            return Err(why);
        }
        opts.ds_max = self.ds_max.unwrap_or(opts.ds_max);
        // A cap below the path's first step starts at the cap; a first step
        // below the path's smallest one lowers that bound to it.
        opts.ds = self.ds.unwrap_or(opts.ds.min(opts.ds_max));
        opts.ds_min = self.ds_min.unwrap_or(opts.ds_min.min(opts.ds));
        let shown = |name: &str, v: f64, own: Option<f64>| match own {
            Some(_) => format!("`{name}` = {v:?}"),
            None => format!("the path's `{name}` = {v:?}"),
        };
        if opts.ds_min > opts.ds {
            return Err(format!(
                "{} exceeds {}",
                shown("ds_min", opts.ds_min, self.ds_min),
                shown("ds", opts.ds, self.ds)
            ));
        }
        if opts.ds > opts.ds_max {
            return Err(format!(
                "{} exceeds {}",
                shown("ds", opts.ds, self.ds),
                shown("ds_max", opts.ds_max, self.ds_max)
            ));
        }
        Ok(opts)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn base() -> ContinuationOptions {
        ContinuationOptions {
            ds: 0.05,
            ds_min: 1e-7,
            ds_max: 0.08,
            max_points: 5000,
            ..ContinuationOptions::default()
        }
    }

    #[test]
    fn none_keeps_the_paths_own_steps() {
        assert_eq!(Steps::default().on(base()), Ok(base()));
    }

    #[test]
    fn given_steps_replace_only_what_they_name() {
        let s = Steps {
            ds_max: Some(0.2),
            max_points: Some(12),
            ..Steps::default()
        };
        let opts = s.on(base()).unwrap();
        assert_eq!((opts.ds, opts.ds_min, opts.ds_max), (0.05, 1e-7, 0.2));
        assert_eq!(opts.max_points, 12);
    }

    #[test]
    fn a_small_cap_or_first_step_moves_the_paths_own_bounds() {
        let capped = Steps {
            ds_max: Some(0.01),
            ..Steps::default()
        }
        .on(base())
        .unwrap();
        assert_eq!((capped.ds, capped.ds_max), (0.01, 0.01));
        let tiny = Steps {
            ds: Some(1e-9),
            ds_max: Some(1e-9),
            ..Steps::default()
        };
        let tiny = tiny.on(base()).unwrap();
        assert_eq!((tiny.ds_min, tiny.ds, tiny.ds_max), (1e-9, 1e-9, 1e-9));
    }

    #[test]
    fn bad_steps_are_refused_by_name() {
        let refused = |s: Steps| s.on(base()).unwrap_err();
        let e = refused(Steps {
            ds: Some(f64::NAN),
            ..Steps::default()
        });
        assert!(e.contains("`ds` = NaN"), "{e}");
        let e = refused(Steps {
            ds_min: Some(-1.0),
            ..Steps::default()
        });
        assert!(e.contains("`ds_min` = -1.0"), "{e}");
        let e = refused(Steps {
            ds: Some(0.1),
            ..Steps::default()
        });
        assert_eq!(e, "`ds` = 0.1 exceeds the path's `ds_max` = 0.08");
        let e = refused(Steps {
            ds_min: Some(0.06),
            ..Steps::default()
        });
        assert_eq!(e, "`ds_min` = 0.06 exceeds the path's `ds` = 0.05");
        let e = refused(Steps {
            ds: Some(0.01),
            ds_max: Some(0.005),
            ..Steps::default()
        });
        assert_eq!(e, "`ds` = 0.01 exceeds `ds_max` = 0.005");
        let e = refused(Steps {
            max_points: Some(0),
            ..Steps::default()
        });
        assert!(e.contains("`max_points` must be ≥ 1"), "{e}");
        let e = refused(Steps {
            max_points: Some(usize::MAX),
            ..Steps::default()
        });
        assert!(e.contains("exceeds the limit"), "{e}");
    }
}
