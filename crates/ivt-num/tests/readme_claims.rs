//! The defaults the README states for the damped Newton method.

use ivt_num::NewtonOptions;

/// "residual test `ftol`: 1e-10, step test …: off, `max_iter`: 50,
/// `max_halvings`: 8, `accept_no_descent`: false".
#[test]
fn newton_defaults_are_the_readme_values() {
    let o = NewtonOptions::default();
    assert_eq!(o.ftol, 1e-10);
    assert_eq!((o.rtol, o.atol), (0.0, 0.0), "step test off");
    assert_eq!((o.max_iter, o.max_halvings), (50, 8));
    assert!(!o.accept_no_descent);
}
