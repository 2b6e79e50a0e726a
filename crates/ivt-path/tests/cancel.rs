//! Cancellation of a running path (`ivt_num::cancel`, Ctrl-C in Python). A
//! request cancels every computation of the process, so this test has a
//! binary of its own: no other test's path can be running when it requests.
// A test may index and unwrap (the crate's panic lints guard library code).
#![allow(clippy::indexing_slicing, clippy::unwrap_used)]

use ivt_path::{
    Branch, ContinuationOptions, NewtonCorrector, PathError, Step, Stepper, Termination,
};

/// x² + λ² = 1.
struct Circle;

impl Branch for Circle {
    fn len(&self) -> usize {
        1
    }
    fn residual(&mut self, u: &[f64], lambda: f64, r: &mut [f64]) {
        r[0] = u[0] * u[0] + lambda * lambda - 1.0;
    }
    fn jacobian(&mut self, u: &[f64], _lambda: f64, jac: &mut [f64]) {
        jac[0] = 2.0 * u[0];
    }
}

fn start<'b>(c: &'b mut Circle, o: &ContinuationOptions) -> Result<Stepper<'b, Circle>, PathError> {
    Stepper::new(
        c,
        Box::new(NewtonCorrector::new(1, o)),
        &[-0.6, 0.8],
        0,
        1.0,
        o,
    )
}

/// A request stops a running path before its next step
/// (`Termination::Interrupted`); a path started after it runs on;
/// `max_points` above the limit is refused before any point.
#[test]
fn a_cancelled_path_stops_before_its_next_step() {
    let mut opts = ContinuationOptions::default();
    (opts.ds, opts.max_points) = (0.05, 50);
    let mut circle = Circle;
    let mut stepper = start(&mut circle, &opts).unwrap();
    assert!(matches!(stepper.next(), Step::Point(_)));
    assert!(matches!(stepper.next(), Step::Point(_)));
    ivt_num::cancel::request();
    assert_eq!(stepper.next(), Step::Stop(Termination::Interrupted));
    assert_eq!(Termination::Interrupted.as_str(), "interrupted");
    let mut fresh = Circle;
    let mut after = start(&mut fresh, &opts).unwrap();
    assert!(matches!(after.next(), Step::Point(_)));
    assert!(matches!(after.next(), Step::Point(_)));
    opts.max_points = ivt_path::limits::MAX_PATH_POINTS + 1;
    let refused = start(&mut fresh, &opts).err().unwrap().to_string();
    assert!(
        refused.contains("max_points = 100001 exceeds the limit of 100000"),
        "{refused}"
    );
}
