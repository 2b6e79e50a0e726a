//! The work a scene asks for, estimated from its inputs before anything runs
//! (issue 30: a scene that would run for days, or never end, is refused with
//! the estimate in the message instead of spinning).
//!
//! The closed loop ([`crate::run::Simulation::run`]) stops at every encoder
//! pulse and every sensor reading; each stop costs at least one integrator
//! step. Their count bounds the run's work from below and, with the
//! per-advance step cap ([`crate::integrate::MAX_STEPS_PER_ADVANCE`]), from
//! above.

use super::{IntegratorMethod, Scene};

/// Default cap on the events of one run ([`Scene::estimated_events`]): 1e9,
/// about 40 min of wall time at the ≈ 4e5 events/s of `scenes/drive.toml`
/// (126 000 events in 0.31 s on a loaded 2-core machine; measured, not
/// asserted). `ivt sim --max-events` and
/// [`crate::run::Simulation::max_events`] raise it.
pub const DEFAULT_MAX_EVENTS: f64 = 1e9;

/// The events a scene's run meets, term by term.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct EventEstimate {
    /// Encoder pulses at the larger of ω0 and the initial speed.
    pub pulses: f64,
    /// Sensor readings (`duration_s / sensors.period_s`).
    pub sensor_samples: f64,
    /// Fixed angle steps of RK4 (`θ` travelled / `integrator.dtheta`; 0 for
    /// the adaptive DP5, whose steps end at the events).
    pub fixed_steps: f64,
}

impl EventEstimate {
    /// All of them.
    #[must_use]
    pub fn total(&self) -> f64 {
        self.pulses + self.sensor_samples + self.fixed_steps
    }
}

impl Scene {
    /// The events of a time integration of this scene (the angle travelled
    /// at the larger of ω0 and ω(0): a controlled run holds ω near ω0).
    #[must_use]
    pub fn estimated_events(&self) -> EventEstimate {
        let omega = self.omega0_rad_s().max(self.initial.omega);
        let angle = self.duration_s * omega;
        EventEstimate {
            pulses: angle * self.encoder.ppr as f64 / std::f64::consts::TAU,
            sensor_samples: self.duration_s / self.sensors.period_s,
            fixed_steps: match self.integrator.method {
                IntegratorMethod::Rk4 => angle / self.integrator.dtheta,
                IntegratorMethod::Dp5 => 0.0,
            },
        }
    }

    /// Refuse a run of more than `max_events` events.
    ///
    /// # Errors
    /// The estimate, term by term, and the limit.
    pub fn check_events(&self, max_events: f64) -> Result<(), String> {
        let e = self.estimated_events();
        if e.total() <= max_events {
            return Ok(());
        }
        Err(format!(
            "the scene asks for about {:.3e} integration events ({:.3e} encoder pulses + {:.3e} sensor readings + {:.3e} fixed RK4 steps), more than the limit {max_events:.3e}: shorten duration_s, lengthen sensors.period_s or integrator.dtheta, or raise the limit (ivt sim --max-events)",
            e.total(),
            e.pulses,
            e.sensor_samples,
            e.fixed_steps
        ))
    }
}

#[cfg(test)]
mod tests {
    use crate::scene::Scene;

    const BASE: &str = "duration_s = 10.0\n[inputs]\nv_m = [[0.0, 8.0]]\nt_u = [[0.0, 4.0]]\n";

    #[test]
    fn events_by_closed_form_and_refused_over_the_limit() {
        let s = Scene::parse(BASE, "s.toml").unwrap();
        let e = s.estimated_events();
        // 10 s at ω0 = 100 rpm (f32) = 1000/60 rev · 1200 pulses = 2e4; 10 s / 0.01 s = 1000
        assert!((e.pulses - 2e4).abs() < 1e-3, "{e:?}");
        assert!((e.sensor_samples - 1000.0).abs() < 1e-9, "{e:?}");
        assert_eq!(e.fixed_steps, 0.0);
        assert!(s.check_events(2.11e4).is_ok());
        let m = s.check_events(2.09e4).unwrap_err();
        assert!(
            m.contains("about 2.100e4") && m.contains("--max-events"),
            "{m}"
        );
        let rk4 = Scene::parse(
            &format!("{BASE}[integrator]\nmethod = \"rk4\"\ndtheta = 1e-9\n"),
            "s.toml",
        )
        .unwrap();
        // angle 10 s · 10.472 rad/s = 104.72 rad / 1e-9 rad
        assert!((rk4.estimated_events().fixed_steps / 1.0472e11 - 1.0).abs() < 1e-4);
    }
}
