//! What the integration tests of ivt-wire share.

use ivt_wire::TelemetrySample;

/// A v2 telemetry sample with every field set (the inputs too, which v1
/// frames do not carry), distinct values so that a swapped field shows.
pub fn v2_sample() -> TelemetrySample {
    TelemetrySample {
        time_ticks: 5,
        omega: 1.0,
        omega_a: 2.0,
        r: 3.0,
        inputs: Some([8.5, 6.25]),
        stepper_position: 4,
        fault: 0,
    }
}
