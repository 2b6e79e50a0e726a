//! Issue #28 item 3: the default step control resolves a lightly damped
//! resonance. The linear oscillator `x″ + 0.002 x′ + x = cos θ` (m = 1,
//! c = 0.002, k = 1: ζ = c/(2√(km)) = 0.001) swept over 0.5 ≤ ω ≤ 1.5. Its
//! amplitude `1/√((1 − ω²)² + (2ζω)²)` peaks at `1/(2ζ√(1 − ζ²))` =
//! 500.00025 (closed form, at `ω = √(1 − 2ζ²)`); in the plane of the first
//! harmonic the curve is a circle of that diameter, 1571 long, which the old
//! absolute cap `ds_max = 0.08` could not climb within `max_points` (the
//! default curve stopped at 359).
#![allow(clippy::unwrap_used)]

use ivt_hb::{frequency_response, Corrector, Duffing, FrcOptions, HbOptions, Termination};

/// The highest amplitude of the sweep, its point count and termination.
fn peak(opts: FrcOptions) -> (f64, usize, Termination) {
    // ξ = 0.001, α = 1, ε = 0, F = 1: m = 1, c = 2ξ = 0.002, k = 1.
    let oscillator = Duffing::new(0.001, 1.0, 0.0, 1.0);
    let opts = FrcOptions {
        from: 0.5,
        to: 1.5,
        ..opts
    };
    let frc = frequency_response(&oscillator, &HbOptions::new(3, 16), &opts).unwrap();
    let top = frc.points.iter().map(|p| p.amplitude).fold(0.0, f64::max);
    (top, frc.points.len(), frc.termination)
}

#[test]
fn default_frc_finds_the_peak_of_a_lightly_damped_resonance() {
    let zeta: f64 = 0.001;
    let exact = 1.0 / (2.0 * zeta * (1.0 - zeta * zeta).sqrt());
    for corrector in [Corrector::Broyden, Corrector::Newton] {
        let mut opts = FrcOptions::default();
        opts.path.continuation.corrector = corrector;
        let (top, points, end) = peak(opts);
        assert_eq!(
            end,
            Termination::LeftInterval,
            "{corrector:?}: must reach ω = 1.5"
        );
        assert!(
            (top - exact).abs() <= 1e-4 * exact,
            "{corrector:?}: peak {top} vs {exact} ({points} points)"
        );
    }
    // The test can fail: with the cap absolute (the old step control) the
    // default sweep runs out of points on the way up the circle.
    let mut absolute = FrcOptions::default();
    absolute.path.continuation.ds_relative_scale = f64::INFINITY;
    let (top, points, end) = peak(absolute);
    assert!(
        end == Termination::MaxPoints && top < 0.8 * exact,
        "{end:?}: {top} after {points} points"
    );
}
