//! The one step rule of the continuation stepper (§3.2.3): the arclength
//! step Δη adapted to the corrector's effort, halved on a failed corrector,
//! capped by [`ContinuationOptions::step_cap`], and shortened to land on a
//! bound of `[lambda_min, lambda_max]` instead of stepping past it.

use super::ContinuationOptions;

/// The planned step from a point: its length along the direction and, when
/// it lands on a bound, that bound (the corrector then closes the system
/// with `λ = bound` instead of the arclength constraint).
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Plan {
    /// Length along the unit direction.
    pub(crate) step: f64,
    /// The bound of λ the step lands on.
    pub(crate) landing: Option<f64>,
}

/// The step length Δη and the landing request of one path.
#[derive(Debug, Clone)]
pub(crate) struct StepControl {
    ds: f64,
    /// A corrected point fell outside the interval: redo the step onto the bound.
    force_landing: bool,
}

impl StepControl {
    /// Starts at `opts.ds`.
    pub(crate) fn new(opts: &ContinuationOptions) -> Self {
        Self {
            ds: opts.ds,
            force_landing: false,
        }
    }

    /// The step from λ = `lambda` along a direction of λ component
    /// `d_lambda`: `ds`, or the distance to the bound ahead when that is
    /// shorter (or a landing was forced). `None` when no step is left inside
    /// the interval (the path ends: [`super::Termination::LeftInterval`]).
    pub(crate) fn plan(
        &self,
        lambda: f64,
        d_lambda: f64,
        opts: &ContinuationOptions,
    ) -> Option<Plan> {
        let bound = if d_lambda > 0.0 {
            opts.lambda_max
        } else {
            opts.lambda_min
        };
        let to_bound = (bound - lambda) / d_lambda;
        let landing =
            (to_bound.is_finite() && (self.force_landing || to_bound <= self.ds)).then_some(bound);
        let step = if landing.is_some() { to_bound } else { self.ds };
        (step > 0.0).then_some(Plan { step, landing })
    }

    /// The corrected point left the interval on a step that did not land:
    /// the next plan lands on the bound.
    pub(crate) fn force_landing(&mut self) {
        self.force_landing = true;
    }

    /// A failed corrector: halves Δη; `false` once it is below `ds_min`.
    pub(crate) fn failed(&mut self, opts: &ContinuationOptions) -> bool {
        self.ds *= 0.5;
        self.ds >= opts.ds_min
    }

    /// An accepted point `x` whose corrector spent `effort` (iterations, a
    /// Newton iteration counted as two chord iterations): at most half of
    /// `target_iter` grows Δη by `growth` up to the cap at `x`, `shrink_at`
    /// or more ([`super::PathCorrector::shrink_at`]) shrinks it by 0.7 (not
    /// below `ds_min`).
    pub(crate) fn accepted(
        &mut self,
        effort: usize,
        shrink_at: usize,
        x: &[f64],
        opts: &ContinuationOptions,
    ) {
        self.force_landing = false;
        if effort * 2 <= opts.target_iter {
            self.ds = (self.ds * opts.growth).min(opts.step_cap(x));
        } else if effort >= shrink_at {
            self.ds = (self.ds * 0.7).max(opts.ds_min);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_step_past_the_bound_lands_on_it_and_none_is_left_there() {
        let mut opts = ContinuationOptions::default();
        (opts.ds, opts.lambda_min, opts.lambda_max) = (0.3, 0.8, 0.85);
        let control = StepControl::new(&opts);
        // From 0.8 along d_λ = 0.5: the bound is 0.1 of arclength away.
        let plan = control.plan(0.8, 0.5, &opts).unwrap();
        assert_eq!(plan.landing, Some(0.85));
        assert!((plan.step - 0.1).abs() < 1e-15, "{plan:?}");
        assert_eq!(control.plan(0.85, 0.5, &opts), None);
        // Far inside: the plain step.
        let wide = ContinuationOptions {
            lambda_max: 10.0,
            ..opts
        };
        let plan = control.plan(0.8, 0.5, &wide).unwrap();
        assert_eq!((plan.step, plan.landing), (0.3, None));
    }

    #[test]
    fn effort_grows_shrinks_and_failures_halve_down_to_ds_min() {
        let opts = ContinuationOptions {
            ds: 0.1,
            ds_max: 0.12,
            ds_min: 0.04,
            target_iter: 10,
            growth: 1.5,
            ..Default::default()
        };
        let mut c = StepControl::new(&opts);
        c.accepted(5, 11, &[0.0, 0.0], &opts); // grows, capped at ds_max
        assert_eq!(c.ds, 0.12);
        c.accepted(10, 11, &[0.0, 0.0], &opts); // below shrink_at: kept
        assert_eq!(c.ds, 0.12);
        c.accepted(11, 11, &[0.0, 0.0], &opts); // at shrink_at: × 0.7
        assert!((c.ds - 0.084).abs() < 1e-15);
        assert!(c.failed(&opts)); // 0.042
        assert!(!c.failed(&opts)); // 0.021 < ds_min
    }
}
