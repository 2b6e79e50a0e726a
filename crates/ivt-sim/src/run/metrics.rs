//! The summary metrics of a run (SPEC §3), accumulated pulse by pulse.

use super::Summary;
use crate::scene::Scene;

/// Running sums over the pulses at or after `metrics.from_s`.
#[derive(Default)]
pub(super) struct Metrics {
    dtheta: f64,
    from: f64,
    band: f64,
    static_from: f64,
    omega0: f64,
    last_out: Option<f64>,
    seen: bool,
    max_dev: f64,
    min_dev: f64,
    static_sum: f64,
    static_n: u64,
    drdth_sq: f64,
    drdt_sq: f64,
    max_drdt: f64,
    n_rate: u64,
    saturated: u64,
    pulses: u64,
    faults: u64,
    final_omega_a: f64,
}

impl Metrics {
    pub(super) fn new(scene: &Scene, omega0: f64, dtheta: f64) -> Self {
        let m = &scene.metrics;
        Self {
            from: m.from_s,
            band: m.band,
            static_from: (scene.duration_s - m.static_window_s).max(m.from_s),
            omega0,
            dtheta,
            final_omega_a: f64::NAN,
            ..Self::default()
        }
    }

    /// One pulse at `t`: ω_a (NaN in the first revolution), the change of
    /// the commanded r since the last pulse and the time since it.
    pub(super) fn pulse(&mut self, t: f64, omega_a: f64, dr: f64, dt: f64, sat: bool, fault: bool) {
        self.pulses += 1;
        self.faults += u64::from(fault);
        if omega_a.is_finite() {
            self.final_omega_a = omega_a;
        }
        if t < self.from {
            return;
        }
        self.saturated += u64::from(sat);
        if dt > 0.0 {
            let rate = dr / dt;
            self.drdt_sq += rate * rate;
            self.max_drdt = self.max_drdt.max(rate.abs());
        }
        self.drdth_sq += (dr / self.dtheta) * (dr / self.dtheta);
        self.n_rate += 1;
        if !omega_a.is_finite() {
            self.last_out = Some(t);
            return;
        }
        self.seen = true;
        let dev = omega_a - self.omega0;
        self.max_dev = self.max_dev.max(dev);
        self.min_dev = self.min_dev.min(dev);
        if dev.abs() > self.band * self.omega0 {
            self.last_out = Some(t);
        }
        if t >= self.static_from {
            self.static_sum += dev;
            self.static_n += 1;
        }
    }

    /// Why the ω_a metrics are empty (None: they are not).
    fn empty_window(&self) -> Option<String> {
        if self.n_rate == 0 {
            Some(format!(
                "no encoder pulse at or after metrics.from_s = {} s",
                self.from
            ))
        } else if !self.seen {
            Some(format!(
                "no full revolution of pulses (ω_a) at or after metrics.from_s = {} s",
                self.from
            ))
        } else {
            None
        }
    }

    /// The summary; metrics over an empty window are NaN (null in JSON) and
    /// `metrics_note` says why.
    pub(super) fn summary(
        &self,
        scene: &Scene,
        last_pulse_t: f64,
        missed_steps: u64,
        integrator_steps: [u64; 3],
        wall_s: f64,
    ) -> Summary {
        let note = self.empty_window();
        let omega_metric = |x: f64| if self.seen { x } else { f64::NAN };
        let rate_metric = |x: f64| {
            if self.n_rate > 0 {
                x / self.n_rate as f64
            } else {
                f64::NAN
            }
        };
        Summary {
            scene: scene.name.clone(),
            law: scene.controller.law,
            ppr: scene.encoder.ppr,
            duration_s: scene.duration_s,
            omega0_rad_s: self.omega0,
            pulses: self.pulses,
            settling_time_s: if !self.seen {
                None
            } else {
                match self.last_out {
                    None => Some(0.0),
                    Some(t) if t >= last_pulse_t => None,
                    Some(t) => Some(t - self.from),
                }
            },
            overshoot_pct: omega_metric(100.0 * self.max_dev / self.omega0),
            undershoot_pct: omega_metric(-100.0 * self.min_dev / self.omega0),
            static_error_rad_s: if self.static_n > 0 {
                self.static_sum / self.static_n as f64
            } else {
                f64::NAN
            },
            final_omega_a_rad_s: self.final_omega_a,
            rms_control_effort_m_per_rad: rate_metric(self.drdth_sq).sqrt(),
            rms_dr_dt_m_per_s: rate_metric(self.drdt_sq).sqrt(),
            max_abs_dr_dt_m_per_s: if self.n_rate > 0 {
                self.max_drdt
            } else {
                f64::NAN
            },
            saturated_fraction: rate_metric(self.saturated as f64),
            metrics_note: note,
            fault_pulses: self.faults,
            missed_steps,
            integrator_steps,
            wall_time_s: wall_s,
            realtime_factor: scene.duration_s / wall_s.max(1e-9),
        }
    }
}
