//! The continuation stepper (§3.2.3, Eq. 68–77): one point of a branch per
//! [`Stepper::next`], from the predictor ([`super::predictor`]), the step
//! rule ([`super::step_control`]) and a [`PathCorrector`]. A caller that
//! watches points as they arrive (stability, events) loops over `next()`;
//! [`Stepper::run`] collects the whole [`Path`].

use super::corrector::{DirectionError, PathCorrector, Prediction, Retry};
use super::predictor::{curvature_between, distance, predict};
use super::step_control::StepControl;
use super::{turn, ContinuationOptions, Path, PathPoint, Termination, Turn};
use crate::branch::Branch;
use crate::error::PathError;
use ivt_num::vector::dot;
use ivt_num::SolveError;

/// What [`Stepper::next`] gives.
#[derive(Debug, Clone, PartialEq)]
pub enum Step {
    /// The next converged point.
    Point(PathPoint),
    /// The path ended (every later call repeats it).
    Stop(Termination),
}

/// A path being followed: the branch, the corrector and the state between
/// two points.
pub struct Stepper<'b, B: Branch> {
    branch: &'b mut B,
    corrector: Box<dyn PathCorrector<B>>,
    opts: ContinuationOptions,
    control: StepControl,
    /// The last point and its unit direction (secant or tangent).
    x: Vec<f64>,
    direction: Vec<f64>,
    /// The direction at the point before, and the curvature between them.
    prev_direction: Vec<f64>,
    curvature: Vec<f64>,
    x_new: Vec<f64>,
    u_pred: Vec<f64>,
    /// The two points before the next one (fold detection, curvature).
    before_last: Option<PathPoint>,
    last: Option<PathPoint>,
    /// The point not yet handed out (the start).
    pending: Option<PathPoint>,
    count: usize,
    landed: bool,
    turn: Option<Turn>,
    done: Option<Termination>,
    /// Cancellation (checked before each step).
    token: ivt_num::cancel::Token,
}

impl<'b, B: Branch> Stepper<'b, B> {
    /// The path of `branch` from `start` (`m` unknowns then λ;
    /// `start_iterations` reported with it) in the direction of increasing λ
    /// if `direction > 0`: the corrector prepares the start and its
    /// direction here.
    ///
    /// # Errors
    /// [`PathError::InvalidInput`] for a start of the wrong size or non-finite
    /// entries or steps, or `max_points` above [`crate::limits::MAX_PATH_POINTS`];
    /// the corrector's start errors
    /// ([`PathCorrector::start`]).
    pub fn new(
        branch: &'b mut B,
        mut corrector: Box<dyn PathCorrector<B>>,
        start: &[f64],
        start_iterations: usize,
        direction: f64,
        opts: &ContinuationOptions,
    ) -> Result<Self, PathError> {
        let m = branch.len();
        if m == 0 || start.len() != m + 1 {
            return Err(PathError::InvalidInput(
                "continuation: start must hold m ≥ 1 unknowns and λ".into(),
            ));
        }
        if !(start.iter().all(|v| v.is_finite()) && opts.ds > 0.0 && opts.ds_min > 0.0) {
            return Err(PathError::InvalidInput(
                "continuation: non-finite start or step".into(),
            ));
        }
        if let Some(why) = crate::limits::path_points_error(opts.max_points) {
            return Err(PathError::InvalidInput(why));
        }
        let mut x = start.to_vec();
        let mut dir = vec![0.0; m + 1];
        if let Some(sign) = dir.last_mut() {
            *sign = if direction >= 0.0 { 1.0 } else { -1.0 };
        }
        corrector.start(branch, &mut x, &mut dir)?;
        let first = PathPoint {
            x: x.clone(),
            iterations: start_iterations,
            dlambda: dir.last().copied().unwrap_or(0.0),
            bordered_sign: corrector.bordered_sign(),
        };
        Ok(Self {
            branch,
            corrector,
            opts: opts.clone(),
            control: StepControl::new(opts),
            x,
            direction: dir,
            prev_direction: vec![0.0; m + 1],
            curvature: vec![0.0; m + 1],
            x_new: vec![0.0; m + 1],
            u_pred: vec![0.0; m + 1],
            before_last: None,
            last: None,
            pending: Some(first),
            count: 0,
            landed: false,
            turn: None,
            done: None,
            token: ivt_num::cancel::Token::now(),
        })
    }

    /// The branch (e.g. for the samples of its last assembly).
    pub fn branch(&mut self) -> &mut B {
        self.branch
    }

    /// The turn (a sign change of the direction's λ component) between the
    /// last three points, found as the last point was handed out.
    pub fn turn(&self) -> Option<Turn> {
        self.turn
    }

    /// The next point of the path, or why it ended.
    #[allow(clippy::should_implement_trait)]
    pub fn next(&mut self) -> Step {
        if let Some(t) = &self.done {
            return Step::Stop(t.clone());
        }
        if let Some(first) = self.pending.take() {
            return Step::Point(self.hand_out(first));
        }
        let lambda = self.x.last().copied().unwrap_or(f64::NAN);
        if self.landed || lambda < self.opts.lambda_min || lambda > self.opts.lambda_max {
            return self.finish(Termination::LeftInterval);
        }
        if self.count >= self.opts.max_points {
            return self.finish(Termination::MaxPoints);
        }
        if self.token.cancelled() {
            return self.finish(Termination::Interrupted);
        }
        match self.step() {
            Ok(point) => Step::Point(self.hand_out(point)),
            Err(t) => self.finish(t),
        }
    }

    /// Follows the path to its end, `on_point(branch, point)` called with
    /// each point as it arrives (`false` stops the path).
    pub fn run(&mut self, mut on_point: impl FnMut(&mut B, &PathPoint) -> bool) -> Path {
        let (mut points, mut turns) = (Vec::new(), Vec::new());
        let termination = loop {
            match self.next() {
                Step::Point(p) => {
                    turns.extend(self.turn);
                    let go_on = on_point(self.branch, &p);
                    points.push(p);
                    if !go_on {
                        break Termination::Stopped;
                    }
                }
                Step::Stop(t) => break t,
            }
        };
        Path {
            points,
            events: turns,
            termination,
        }
    }

    fn finish(&mut self, termination: Termination) -> Step {
        self.done = Some(termination.clone());
        Step::Stop(termination)
    }

    /// Records `point` as the last (a turn if its direction turned in λ).
    fn hand_out(&mut self, point: PathPoint) -> PathPoint {
        self.turn = match (&self.before_last, &self.last) {
            (Some(a), Some(b)) if b.dlambda * point.dlambda < 0.0 => {
                let (turned, nearest) = turn(a, b, &point);
                Some(Turn {
                    index: self.count - 2 + nearest,
                    lambda: turned.last().copied().unwrap_or(f64::NAN),
                    bracket: self.count - 2,
                })
            }
            _ => None,
        };
        self.before_last = self.last.replace(point.clone());
        self.count += 1;
        point
    }

    /// Predicts and corrects until a point is accepted (halving the step on
    /// failures and on rejected points, [`StepControl::rejected`]) or the
    /// path ends.
    fn step(&mut self) -> Result<PathPoint, Termination> {
        let opts = &self.opts;
        let curved = self.corrector.second_order()
            && self.before_last.as_ref().is_some_and(|prev| {
                curvature_between(
                    &prev.x,
                    &self.x,
                    &self.prev_direction,
                    &self.direction,
                    &mut self.curvature,
                )
            });
        let d_lambda = self.direction.last().copied().unwrap_or(0.0);
        loop {
            let lambda = self.x.last().copied().unwrap_or(f64::NAN);
            let Some(plan) = self.control.plan(lambda, d_lambda, opts) else {
                return Err(Termination::LeftInterval);
            };
            predict(
                &self.x,
                &self.direction,
                plan.step,
                curved.then_some(self.curvature.as_slice()),
                plan.landing,
                &mut self.u_pred,
            );
            let pred = Prediction {
                x_prev: &self.x,
                direction: &self.direction,
                u_pred: &self.u_pred,
                step: plan.step,
                fix: plan.landing,
            };
            let corrected = self.corrector.correct(self.branch, &pred, &mut self.x_new);
            let why = match corrected {
                Ok(c) => {
                    // The landing constraint λ = bound is linear: its solution
                    // is the bound itself (the corrector's last step may leave
                    // an ulp of rounding on it).
                    if let (Some(bound), Some(l)) = (plan.landing, self.x_new.last_mut()) {
                        *l = bound;
                    }
                    // Converged far from the prediction: onto another part
                    // of the branch (across a sharp peak, say).
                    let correction = distance(&self.x_new, &self.u_pred);
                    if StepControl::too_far(correction, plan.step, opts)
                        && self.control.rejected(plan.step, opts)
                    {
                        self.corrector.retry(self.branch, &self.x, Retry::Rejected);
                        continue;
                    }
                    let l = self.x_new.last().copied().unwrap_or(f64::NAN);
                    if plan.landing.is_none() && (l < opts.lambda_min || l > opts.lambda_max) {
                        // Corrected past a bound: redo the step onto it.
                        self.control.force_landing();
                        self.corrector.retry(self.branch, &self.x, Retry::Rejected);
                        continue;
                    }
                    self.prev_direction.copy_from_slice(&self.direction);
                    match self.corrector.direction(
                        self.branch,
                        &self.x,
                        &self.x_new,
                        &mut self.direction,
                    ) {
                        Ok(())
                            if StepControl::turned(
                                dot(&self.prev_direction, &self.direction),
                                opts,
                            ) && self.control.rejected(plan.step, opts) =>
                        {
                            self.direction.copy_from_slice(&self.prev_direction);
                            self.corrector.retry(self.branch, &self.x, Retry::Turned);
                            continue;
                        }
                        Ok(()) => {
                            let shrink_at = self.corrector.shrink_at(opts.target_iter);
                            self.control
                                .accepted(c.effort, shrink_at, &self.x_new, opts);
                            self.landed = plan.landing.is_some();
                            std::mem::swap(&mut self.x, &mut self.x_new);
                            return Ok(PathPoint {
                                x: self.x.clone(),
                                iterations: c.iterations,
                                dlambda: self.direction.last().copied().unwrap_or(0.0),
                                bordered_sign: self.corrector.bordered_sign(),
                            });
                        }
                        Err(DirectionError::Singular) => {
                            return Err(Termination::StepTooSmall(SolveError::SingularJacobian {
                                iteration: 0,
                                history: Vec::new(),
                            }))
                        }
                        Err(DirectionError::Backwards(e)) => (e, Retry::Rejected),
                    }
                }
                Err(e) => (e, Retry::Failed),
            };
            if !self.control.failed(opts) {
                return Err(Termination::StepTooSmall(why.0));
            }
            self.corrector.retry(self.branch, &self.x, why.1);
        }
    }
}
