//! The amplitude peaks of a condensed curve, located between its points.
//!
//! The path's steps grow with the solution (`ds_relative_scale`), so on a
//! lightly damped resonance the highest sampled point lies below the peak
//! (2.8e-3 relative on `x″ + 0.002 x′ + x = cos θ` at the default
//! `ds_max`, `tests/condensed_resonance.rs`). A peak is an extremum of the
//! amplitude along the path: where the path is a graph over ω_f (no fold
//! among the five points around the highest one, [`peaks`]) it is the maximum of
//! the amplitude `a(ω_f)` of the orbit corrected at fixed ω_f, found by
//! successive parabolic interpolation (Brent's inverse-parabolic step,
//! bracketed) on the corrected orbits.

use ivt_hb::HbError;

/// One corrected orbit: its ω_f, amplitude and condensed unknowns.
#[derive(Debug, Clone)]
pub(super) struct Sample {
    pub(super) omega_f: f64,
    pub(super) amplitude: f64,
    pub(super) q: Vec<f64>,
}

/// Interpolation steps at most.
const MAX_STEPS: usize = 16;

/// Converged when the parabola's vertex is within this of the best sample
/// (relative amplitude; the peak's error is of that order).
const AMPLITUDE_TOL: f64 = 1e-12;

/// The indices `i` of the interior points whose amplitude is above both
/// neighbours' while ω_f is strictly monotone over `i − 2 ..= i + 2`: the
/// curve is a graph over ω_f there with a step to spare on either side. Next
/// to a fold `a(ω_f)` has a square-root branch point (`da/dω_f` unbounded),
/// which a parabola does not model: such a peak (a hardening one, next to
/// its fold) is left as sampled.
pub(super) fn peaks(omega_amplitude: &[(f64, f64)]) -> Vec<usize> {
    omega_amplitude
        .windows(5)
        .enumerate()
        .filter_map(|(i, w)| {
            let rising = w.windows(2).all(|p| matches!(p, [a, b] if a.0 < b.0));
            let falling = w.windows(2).all(|p| matches!(p, [a, b] if a.0 > b.0));
            match w {
                [_, (_, a0), (_, a1), (_, a2), _] => {
                    ((rising || falling) && a1 > a0 && a1 > a2).then_some(i + 2)
                }
                _ => None,
            }
        })
        .collect()
}

/// The peak within the bracket `[left, middle, right]` (ω_f increasing,
/// the middle highest): successive parabolic interpolation of the amplitude
/// in ω_f, each vertex corrected by `correct(guess, ω_f)` (the orbit at
/// ω_f from the guess, with its amplitude), the guess interpolated linearly
/// between the samples around the vertex. Returns the highest sample found
/// if above the middle's, `None` otherwise (no vertex inside the bracket,
/// or the first correction failed); a failed correction ends the search
/// with the best sample so far.
pub(super) fn locate_peak(
    bracket: [Sample; 3],
    mut correct: impl FnMut(Vec<f64>, f64) -> Result<Sample, HbError>,
) -> Option<Sample> {
    let [mut left, mut middle, mut right] = bracket;
    let start = middle.amplitude;
    for _ in 0..MAX_STEPS {
        let Some((omega_f, vertex)) = parabola_vertex(&left, &middle, &right) else {
            break;
        };
        if vertex - middle.amplitude <= AMPLITUDE_TOL * middle.amplitude {
            break;
        }
        let guess = {
            let (a, b) = if omega_f < middle.omega_f {
                (&left, &middle)
            } else {
                (&middle, &right)
            };
            let t = (omega_f - a.omega_f) / (b.omega_f - a.omega_f);
            a.q.iter().zip(&b.q).map(|(x, y)| x + t * (y - x)).collect()
        };
        let Ok(sample) = correct(guess, omega_f) else {
            break;
        };
        let below = sample.omega_f < middle.omega_f;
        if sample.amplitude > middle.amplitude {
            if below {
                right = std::mem::replace(&mut middle, sample);
            } else {
                left = std::mem::replace(&mut middle, sample);
            }
        } else if below {
            left = sample;
        } else {
            right = sample;
        }
    }
    (middle.amplitude > start).then_some(middle)
}

/// The vertex `(ω_f, amplitude)` of the parabola through the three samples
/// when it is a maximum strictly inside `(left, right)` and apart from the
/// middle's ω_f.
fn parabola_vertex(left: &Sample, middle: &Sample, right: &Sample) -> Option<(f64, f64)> {
    let (x0, x1, x2) = (left.omega_f, middle.omega_f, right.omega_f);
    let (y0, y1, y2) = (left.amplitude, middle.amplitude, right.amplitude);
    // Newton form: y = y1 + d01 (x − x1) + curvature (x − x0)(x − x1).
    let d01 = (y1 - y0) / (x1 - x0);
    let d12 = (y2 - y1) / (x2 - x1);
    let curvature = (d12 - d01) / (x2 - x0);
    if curvature.is_nan() || curvature >= 0.0 {
        return None;
    }
    // y′(x) = d01 + curvature (2x − x0 − x1) = 0.
    let x = 0.5 * (x0 + x1) - d01 / (2.0 * curvature);
    let y = y1 + d01 * (x - x1) + curvature * (x - x0) * (x - x1);
    let inside = x > x0 && x < x2 && x != x1;
    (inside && x.is_finite() && y.is_finite()).then_some((x, y))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The peak of the Lorentzian-like `1/√((1 − ω²)² + (2ζω)²)` (ζ =
    /// 1e-3) from three samples around it, each "correction" the closed
    /// form: within 1e-10 of `1/(2ζ√(1 − ζ²))`.
    #[test]
    fn locates_the_peak_of_a_resonance_curve() {
        let zeta = 1e-3;
        let amplitude = |w: f64| 1.0 / ((1.0 - w * w).powi(2) + (2.0 * zeta * w).powi(2)).sqrt();
        let sample = |w: f64| Sample {
            omega_f: w,
            amplitude: amplitude(w),
            q: vec![w],
        };
        let bracket = [sample(0.9992), sample(0.99995), sample(1.0003)];
        let mut calls = 0;
        let found = locate_peak(bracket, |_, w| {
            calls += 1;
            Ok(sample(w))
        })
        .unwrap();
        let exact = 1.0 / (2.0 * zeta * (1.0 - zeta * zeta).sqrt());
        assert!(
            (found.amplitude - exact).abs() <= 1e-10 * exact,
            "{} vs {exact} after {calls}",
            found.amplitude
        );
        assert!(calls <= MAX_STEPS);
    }

    /// Only interior strict maxima with ω_f monotone over two points on
    /// either side.
    #[test]
    fn peaks_skip_folds_and_ends() {
        let rising = [(1.0, 1.0), (2.0, 2.0), (3.0, 5.0), (4.0, 3.0), (5.0, 1.0)];
        assert_eq!(peaks(&rising), vec![2]);
        let falling: Vec<(f64, f64)> = rising.iter().rev().copied().collect();
        assert_eq!(peaks(&falling), vec![2]);
        // A fold two points after the maximum, and a maximum one point from the end.
        let folded = [(1.0, 1.0), (2.0, 2.0), (3.0, 5.0), (4.0, 3.0), (3.5, 1.0)];
        assert!(peaks(&folded).is_empty());
        assert!(peaks(&rising[1..]).is_empty());
    }
}
