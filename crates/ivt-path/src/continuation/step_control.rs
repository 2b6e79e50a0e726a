//! The one step rule of the continuation stepper (§3.2.3): the arclength
//! step Δη adapted to the corrector's effort, halved on a failed corrector
//! and on a rejected point (its direction turned by more than
//! [`ContinuationOptions::max_turn`], or it lies farther than
//! [`ContinuationOptions::max_correction`]`·Δη` from the prediction), capped
//! by [`ContinuationOptions::step_cap`], and shortened to land on a bound of
//! `[lambda_min, lambda_max]` instead of stepping past it.

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

    /// A failed corrector: halves Δη (and drops a forced landing, whose step
    /// the halving would not shorten); `false` once it is below `ds_min`.
    pub(crate) fn failed(&mut self, opts: &ContinuationOptions) -> bool {
        self.ds *= 0.5;
        self.force_landing = false;
        self.ds >= opts.ds_min
    }

    /// Whether a converged point `correction` away from its prediction, on a
    /// step of length `step`, lies too far from it
    /// ([`ContinuationOptions::max_correction`]).
    pub(crate) fn too_far(correction: f64, step: f64, opts: &ContinuationOptions) -> bool {
        correction.is_nan() || correction > opts.max_correction * step
    }

    /// Whether the direction turned by more than
    /// [`ContinuationOptions::max_turn`] over a step: `cos_turn` is the
    /// cosine of the angle between the two unit directions.
    pub(crate) fn turned(cos_turn: f64, opts: &ContinuationOptions) -> bool {
        cos_turn.is_nan() || cos_turn < opts.max_turn.min(std::f64::consts::PI).cos()
    }

    /// A converged point rejected after a step of length `step` (too far from
    /// its prediction, or its direction turned too much): the step is redone
    /// at half that length and `true` returned, unless that is below
    /// `ds_min` (`false`: the point is kept, the step cannot shrink).
    pub(crate) fn rejected(&mut self, step: f64, opts: &ContinuationOptions) -> bool {
        let half = 0.5 * step.min(self.ds);
        if half < opts.ds_min {
            return false;
        }
        self.ds = half;
        self.force_landing = false;
        true
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

    #[test]
    fn a_far_or_turned_point_is_rejected_at_half_its_step_unless_below_ds_min() {
        let opts = ContinuationOptions {
            ds: 0.1,
            ds_min: 0.03,
            ..Default::default()
        };
        // Half a step from its prediction is still accepted; more is not.
        assert!(!StepControl::too_far(0.05, 0.1, &opts));
        assert!(StepControl::too_far(0.0501, 0.1, &opts));
        assert!(StepControl::too_far(f64::NAN, 0.1, &opts));
        // One radian of turn is accepted, more is not.
        assert!(!StepControl::turned(1.0f64.cos(), &opts));
        assert!(StepControl::turned(1.01f64.cos(), &opts));
        let off = ContinuationOptions {
            max_turn: std::f64::consts::PI,
            ..opts.clone()
        };
        assert!(!StepControl::turned(-1.0, &off));
        // A landing step of 0.08 is redone at 0.04 (not from ds = 0.1), then
        // 0.02 < ds_min: the point is kept.
        let mut c = StepControl::new(&opts);
        c.force_landing();
        assert!(c.rejected(0.08, &opts));
        assert_eq!((c.ds, c.force_landing), (0.04, false));
        assert!(!c.rejected(0.04, &opts));
        assert_eq!(c.ds, 0.04);
    }

    #[test]
    fn a_failed_forced_landing_is_not_repeated_at_the_same_length() {
        let mut opts = ContinuationOptions::default();
        (opts.ds, opts.lambda_min, opts.lambda_max) = (0.1, 0.0, 1.0);
        let mut c = StepControl::new(&opts);
        c.force_landing();
        // Forced: the whole way to the bound, 100 steps of ds along d_λ = 0.01.
        let forced = c.plan(0.9, 0.01, &opts).unwrap();
        assert_eq!(forced.landing, Some(1.0));
        assert!((forced.step - 10.0).abs() < 1e-9, "{forced:?}");
        assert!(c.failed(&opts));
        let plan = c.plan(0.9, 0.01, &opts).unwrap();
        assert_eq!((plan.step, plan.landing), (0.05, None));
    }
}
