//! The equation-error rows: Eq. 151 integrated over windows of θ.
//!
//! With E(θ) = ½ J(θ, r) θ̇², dE/dθ = J θ̈ + ½ J_θ θ̇² at constant r, so
//! Eq. 151 over a window [θ_a, θ_b] at constant r reads
//!
//! ```text
//! J_a·½Δ(ω²) + J_b·½r²Δ(ω²) + J_c·½r²Δ(f²ω²) + J_d·½Δ(f²ω²)
//!   + (k_t k_e/R_a)·∫f²ω dθ − (k_t/R_a)·∫f V_m dθ + (2√2/(π r_u))·∫f T_U r dθ
//!   = g·∫(sin θ + cos θ) r dθ
//! ```
//!
//! — linear in the seven coefficients, with no θ̈: the speeds enter only at
//! the two ends (point speeds from a local cubic fit of t(θ) to the pulse
//! times) and inside integrals (the mean speed of each pulse interval), so
//! timer quantization and jitter are averaged instead of differentiated.
//!
//! With the armature inductance L_a of Eq. 137 the motor torque is k_t f i_a
//! with L_a di_a/dt = V_m − R_a i_a − k_e f ω: i_a is (V_m − k_e f ω)/R_a
//! passed through the first-order lag of time constant τ_e = L_a/R_a. The
//! rows stay linear in the same seven coefficients with V_m and f ω replaced
//! by their lagged values (`lag_s` = τ_e; 0 gives Eq. 138, L_a = 0). Left
//! out, the lag would bias J_d by −τ_e k_t k_e/R_a: to first order in τ_e,
//! f·d(f ω)/dt has exactly the form of the J_d terms of Eq. 151, so L_a and
//! J_d cannot be told apart from the motion and τ_e must be known (measured
//! on the motor; the nominal plant's L_a/R_a).
//!
//! The window ends sit at θ = kπ/2 and kπ/2 ± π/8: π/8 away from the kinks
//! of f at π/4 + kπ/2 (Eq. 139), where ω is smooth enough for the cubic fit,
//! and at two different values of f (A and A cos π/8) so that J_a and J_d are
//! told apart (with ends at one value of f the two columns would be equal).

use super::Recording;
use core::f64::consts::{FRAC_PI_2, FRAC_PI_8};
use ivt_kin::variant;

/// Number of unknowns of a row: J_a, J_b, J_c, J_d, motor damping, motor gain, load gain.
pub const UNKNOWNS: usize = 7;

/// One equation-error row: regressors x and the known gravity side y.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Row {
    /// Coefficients of [J_a, J_b, J_c, J_d, k_t k_e/R_a, k_t/R_a, 2√2/(π r_u)].
    pub x: [f64; UNKNOWNS],
    /// ∫(sin θ + cos θ) r dθ (times the known gravity gain gives y).
    pub gravity: f64,
    /// Time of the window's start \[s\].
    pub t: f64,
    /// Which window: the index of its start among the angles kπ/2,
    /// kπ/2 ± π/8 (the same window in every view of a recording).
    pub key: i64,
}

/// Pulses on each side of a window end in the local cubic fit of t(θ).
fn half_span(ppr: usize) -> usize {
    (ppr / 150).clamp(3, 32)
}

/// Speed θ̇ at pulse `k` from a cubic least-squares fit of t(θ) over pulses
/// k−m..k+m: θ̇ = 1/t′(θ_k). None if the span leaves the data.
fn point_speed(t: &[f64], k: usize, m: usize, dtheta: f64) -> Option<f64> {
    let lo = k.checked_sub(m)?;
    let span = t.get(lo..=k + m)?;
    let t0 = *t.get(k)?;
    // Normal equations of t − t_k = c1 u + c2 u² + c3 u³ (u = pulse offset).
    let mut a = nalgebra::Matrix3::<f64>::zeros();
    let mut b = nalgebra::Vector3::<f64>::zeros();
    for (i, ti) in span.iter().enumerate() {
        let u = i as f64 - m as f64;
        let phi = nalgebra::Vector3::new(u, u * u, u * u * u);
        a += phi * phi.transpose();
        b += phi * (ti - t0);
    }
    let c = a.lu().solve(&b)?;
    let dt_dtheta = c.x / dtheta;
    (dt_dtheta > 0.0).then(|| 1.0 / dt_dtheta)
}

/// The window ends: (angle index, first pulse at or after the angle) for the
/// angles kπ/2, kπ/2 ± π/8 in order, inside the data.
/// At most one quarter turn per pulse and two more are walked, whatever
/// θ0 is (a θ0 far outside its range cannot make the loop run without bound).
fn window_ends(rec: &Recording) -> Vec<(i64, usize)> {
    let dtheta = rec.dtheta();
    let n = rec.pulse_t.len();
    let theta_end = rec.theta0 + dtheta * n.saturating_sub(1) as f64;
    // Ends repeat every π/2 at offsets −π/8, 0, +π/8.
    let first = ((rec.theta0 + FRAC_PI_8) / (4.0 * FRAC_PI_8)).floor() as i64;
    let mut ends = Vec::new();
    for j in (first..).take(n.saturating_add(2)) {
        let base = j as f64 * 4.0 * FRAC_PI_8;
        if base - FRAC_PI_8 > theta_end {
            break;
        }
        for (o, off) in [-FRAC_PI_8, 0.0, FRAC_PI_8].into_iter().enumerate() {
            let k = ((base + off - rec.theta0) / dtheta).ceil();
            let key = 3 * j + o as i64;
            if k >= 0.0
                && (k as usize) < n
                && ends
                    .last()
                    .is_none_or(|e: &(i64, usize)| (k as usize) > e.1)
            {
                ends.push((key, k as usize));
            }
        }
    }
    ends
}

/// The equation-error rows of a recording: one per window between
/// consecutive ends over which r is constant and every input is known;
/// `lag_s` the motor's electrical time constant L_a/R_a (Eq. 137).
pub fn rows(rec: &Recording, lag_s: f64) -> Vec<Row> {
    let m = half_span(rec.ppr);
    let ends = window_ends(rec);
    let mut out = Vec::new();
    for pair in ends.windows(2) {
        let &[(key, a), (next, b)] = pair else {
            continue;
        };
        if next != key + 1 {
            continue;
        }
        if let Some(row) = window_row(rec, (a, b), m, lag_s, key) {
            if row.x.iter().chain([&row.gravity]).all(|v| v.is_finite()) {
                out.push(row);
            }
        }
    }
    out
}

/// The row of the window from pulse `a` to pulse `b` (None: r changes in
/// it, an input is missing, or a point speed cannot be fitted).
fn window_row(
    rec: &Recording,
    (a, b): (usize, usize),
    m: usize,
    lag_s: f64,
    key: i64,
) -> Option<Row> {
    let t = &rec.pulse_t;
    let dtheta = rec.dtheta();
    let (ta, tb) = (*t.get(a)?, *t.get(b)?);
    if !rec.settled(ta) || rec.stage_start(ta) != rec.stage_start(tb) {
        return None;
    }
    let r = rec.eccentricity_at(ta)?;
    if rec.eccentricity_at(tb)? != r || rec.eccentricity_changes_in(ta, tb) {
        return None;
    }
    let (wa, wb) = (point_speed(t, a, m, dtheta)?, point_speed(t, b, m, dtheta)?);
    let (tha, thb) = (rec.theta_of(a), rec.theta_of(b));
    let (fa, fb) = (variant::f(tha), variant::f(thb));
    let d_w2 = 0.5 * (wb * wb - wa * wa);
    let d_fw2 = 0.5 * (fb * fb * wb * wb - fa * fa * wa * wa);
    let i = integrals(rec, a, b, r, lag_s)?;
    Some(Row {
        x: [
            d_w2,
            r * r * d_w2,
            r * r * d_fw2,
            d_fw2,
            i.damp,
            -i.volt,
            i.load,
        ],
        gravity: i.grav,
        t: ta,
        key,
    })
}

/// The θ-integrals of one stretch of pulses at constant r.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Integrals {
    /// ∫ f·(f ω)_lag dθ (ω: the mean speed of each pulse interval).
    pub damp: f64,
    /// ∫ f (V_m)_lag dθ.
    pub volt: f64,
    /// ∫ f T_U r dθ.
    pub load: f64,
    /// ∫ (sin θ + cos θ) r dθ.
    pub grav: f64,
    /// ∫ T_U dθ.
    pub torque: f64,
}

/// Settling of the lag's state before a window: this many time constants
/// (e^−12 ≈ 6e-6 of the start value left).
const LAG_WARMUP: f64 = 12.0;

/// The first-order lag of time constant τ (Eq. 137's armature current),
/// exact for inputs held constant over each pulse interval.
#[derive(Clone, Copy, Debug)]
struct Lag {
    tau: f64,
    /// States of the lagged V_m and f ω (None before the first input).
    state: Option<[f64; 2]>,
}

impl Lag {
    /// Feed the inputs `u` held over `dt`; their mean lagged values over it
    /// (`u` itself when τ = 0).
    fn step(&mut self, u: [f64; 2], dt: f64) -> [f64; 2] {
        if self.tau <= 0.0 {
            return u;
        }
        let ([s_v, s_w], [u_v, u_w]) = (self.state.unwrap_or(u), u);
        let decay = (-dt / self.tau).exp();
        // the mean of x + (s − x) e^{−t/τ} over [0, dt], and its end value
        let w = self.tau / dt * (1.0 - decay);
        self.state = Some([u_v + (s_v - u_v) * decay, u_w + (s_w - u_w) * decay]);
        [u_v + (s_v - u_v) * w, u_w + (s_w - u_w) * w]
    }
}

/// ∫ f dθ, ∫ f² dθ and ∫ f·(θ − θ_m) dθ (θ_m the middle) over [θ0, θ1]
/// exactly (Eq. 43: f = A cos(θ − kπ/2) on segment k), split at a corner
/// π/4 + kπ/2 inside (f has a kink there).
///
/// A midpoint rule here biased J_d by +1 %: the motor's work per window
/// (≈ 10 J) is three orders above the gravity work that fixes the scale
/// (≈ 0.04 J), so its O(h²) curvature error (−h²/24 relative, 5e-5 J per
/// window) and its error on the interval that holds the corner (+3.8e-4 J,
/// f's kink) are of the size of the equation noise, and they are correlated
/// with the J_d column (the windows across a corner are those from
/// kπ/2 + π/8 to kπ/2 + 3π/8).
pub fn f_integrals(theta0: f64, theta1: f64) -> [f64; 3] {
    let middle = 0.5 * (theta0 + theta1);
    let on = |a: f64, b: f64, k: i64| {
        // c = θ − kπ/2 at the ends as mid ± half: every sine from the two
        // pairs (sums and differences in product form, no cancellation
        // over a pulse interval).
        let (c0, c1) = (a - k as f64 * FRAC_PI_2, b - k as f64 * FRAC_PI_2);
        let (s_m, c_m) = (0.5 * (c0 + c1)).sin_cos();
        let (s_h, c_h) = (0.5 * (c1 - c0)).sin_cos();
        let half = 0.5 * (c1 - c0);
        let (sin_c0, sin_c1) = (s_m * c_h - c_m * s_h, s_m * c_h + c_m * s_h);
        let amp = ivt_kin::NCG_AMPLITUDE;
        // cos 2·mid · sin 2·half
        let cos2m_sin2h = (1.0 - 2.0 * s_m * s_m) * 2.0 * s_h * c_h;
        // the primitive of A cos c·(θ − θ_m) is A((θ − θ_m) sin c + cos c)
        let moment = (b - middle) * sin_c1 - (a - middle) * sin_c0 - 2.0 * s_m * s_h;
        [
            2.0 * amp * c_m * s_h,
            amp * amp * (half + 0.5 * cos2m_sin2h),
            amp * moment,
        ]
    };
    let (k0, k1) = (variant::segment_of(theta0), variant::segment_of(theta1));
    if k1 == k0 {
        return on(theta0, theta1, k0);
    }
    let corner = variant::segment_end(k0);
    let ([a1, a2, a3], [b1, b2, b3]) = (on(theta0, corner, k0), on(corner, theta1, k1));
    [a1 + b1, a2 + b2, a3 + b3]
}

/// The motor's inputs over pulse interval k (Eq. 137's armature voltage and
/// back-EMF speed): V_m at its middle, and the mean motor speed f ω over it,
/// ∫ f dθ / Δt exactly; with ∫ f dθ, ∫ f² dθ ([`f_integrals`]), T_U and the
/// duration Δt. None: a non-increasing pulse time or an input outside the
/// sensor record.
fn interval(rec: &Recording, k: usize) -> Option<([f64; 2], [f64; 3], f64, f64)> {
    let t = &rec.pulse_t;
    let (t0, t1) = (*t.get(k)?, *t.get(k + 1)?);
    let dt = t1 - t0;
    if dt.is_nan() || dt <= 0.0 {
        return None;
    }
    let f = f_integrals(rec.theta_of(k), rec.theta_of(k + 1));
    let (v_m, t_u) = rec.inputs_at(0.5 * (t0 + t1))?;
    Some(([v_m, f[0] / dt], f, t_u, dt))
}

/// [`Integrals`] from pulse `a` to pulse `b` at eccentricity `r` with the
/// motor lag `lag_s` = L_a/R_a (its state settled over the
/// 12 (`LAG_WARMUP`) time constants of pulses before `a`, as far as they are
/// recorded without a gap). None: a non-increasing pulse time or an input
/// outside the sensor record.
pub fn integrals(rec: &Recording, a: usize, b: usize, r: f64, lag_s: f64) -> Option<Integrals> {
    let t = &rec.pulse_t;
    let dtheta = rec.dtheta();
    let mut s = Integrals {
        damp: 0.0,
        volt: 0.0,
        load: 0.0,
        grav: 0.0,
        torque: 0.0,
    };
    let mut lag = Lag {
        tau: lag_s,
        state: None,
    };
    if lag_s > 0.0 {
        let ta = *t.get(a)?;
        let mut from = a;
        while let Some(k) = from.checked_sub(1) {
            let tk = *t.get(k)?;
            // the lag restarts at a stage start (pulses are logged by stage)
            if ta - tk > LAG_WARMUP * lag_s || rec.stage_start(tk) != rec.stage_start(ta) {
                break;
            }
            from = k;
        }
        for k in from..a {
            let (u, _, _, dt) = interval(rec, k)?;
            lag.step(u, dt);
        }
    }
    for k in a..b {
        let (th0, th1) = (rec.theta_of(k), rec.theta_of(k + 1));
        let (u, [f1, f2, f1_moment], t_u, dt) = interval(rec, k)?;
        let [v_m, f_omega] = lag.step(u, dt);
        // ∫ f (f ω)_lag dθ: with τ = 0 the speed is the interval's mean
        // dθ/dt against the exact ∫ f² dθ; with τ > 0 the lagged speed x
        // as a line in θ over the interval, its mean and its slope
        // dx/dθ = (u − x)/(τ ω) from the lag's own equation, against the
        // exact ∫ f and ∫ f·(θ − θ_m) (the slope term matters on the
        // interval that holds a corner of f).
        s.damp += if lag_s > 0.0 {
            let slope = (u[1] - f_omega) * dt / (lag_s * dtheta);
            f1 * f_omega + slope * f1_moment
        } else {
            f2 * dtheta / dt
        };
        s.volt += f1 * v_m;
        s.load += f1 * t_u * r;
        s.torque += t_u * dtheta;
        // ∫(sin θ + cos θ) dθ exactly over the pulse interval.
        s.grav += ((th0.cos() - th1.cos()) + (th1.sin() - th0.sin())) * r;
    }
    Some(s)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A cubic t(θ) is fitted exactly: the point speed is 1/t′ to rounding.
    #[test]
    fn point_speed_is_exact_for_a_cubic() {
        let h = 0.005;
        let t: Vec<f64> = (0..40)
            .map(|k| {
                let u = k as f64 * h;
                0.1 * u + 0.02 * u * u - 0.003 * u * u * u
            })
            .collect();
        let k = 20;
        let u = k as f64 * h;
        let want = 1.0 / (0.1 + 0.04 * u - 0.009 * u * u);
        let got = point_speed(&t, k, 8, h).unwrap();
        assert!((got / want - 1.0).abs() < 1e-9, "{got} vs {want}");
        assert_eq!(point_speed(&t, 3, 8, h), None);
    }

    /// The lag's mean and end state over one interval equal those of
    /// τ ṡ = u − s integrated by RK4 in 10⁴ steps (trapezoidal mean); τ = 0
    /// passes the inputs through.
    #[test]
    fn lag_matches_the_integrated_first_order_equation() {
        let (tau, dt, s0, u) = (4e-3, 1.5e-3, [1.0, 2.0], [3.0, -1.0]);
        let mut lag = Lag {
            tau,
            state: Some(s0),
        };
        let mean = lag.step(u, dt);
        for i in 0..2 {
            let (n, h) = (10_000, dt / 10_000.0);
            let (mut s, mut sum) = (s0[i], 0.0);
            let d = |s: f64| (u[i] - s) / tau;
            for _ in 0..n {
                let k1 = d(s);
                let k2 = d(s + 0.5 * h * k1);
                let k3 = d(s + 0.5 * h * k2);
                let k4 = d(s + h * k3);
                let next = s + h / 6.0 * (k1 + 2.0 * k2 + 2.0 * k3 + k4);
                sum += 0.5 * (s + next) * h;
                s = next;
            }
            assert!(
                (mean[i] - sum / dt).abs() < 1e-8,
                "{} vs {}",
                mean[i],
                sum / dt
            );
            assert!((lag.state.unwrap()[i] - s).abs() < 1e-12);
        }
        let mut none = Lag {
            tau: 0.0,
            state: None,
        };
        assert_eq!(none.step(u, dt), u);
    }

    /// ∫ f, ∫ f² and ∫ f·(θ − θ_m) over intervals inside a segment and across a corner
    /// equal a composite Simpson rule on each side of the corner (10⁴
    /// panels each, error ~1e-17), to 1e-14; the midpoint rule they
    /// replace is off by ~h²/24 relative inside and by ~A h²/(8√2) at
    /// a corner.
    #[test]
    fn f_integrals_are_exact_across_a_corner() {
        let simpson = |a: f64, b: f64, p: i32, m: f64| {
            let n = 10_000;
            let h = (b - a) / n as f64;
            // p = 3: f·(θ − m)
            let g = |x: f64| {
                if p == 3 {
                    variant::f(x) * (x - m)
                } else {
                    variant::f(x).powi(p)
                }
            };
            let odd: f64 = (0..n / 2).map(|i| g(a + (2 * i + 1) as f64 * h)).sum();
            let even: f64 = (1..n / 2).map(|i| g(a + (2 * i) as f64 * h)).sum();
            h / 3.0 * (g(a) + g(b) + 4.0 * odd + 2.0 * even)
        };
        let corner = variant::segment_end(3);
        for (a, b) in [
            (0.1, 0.1 + 0.0052),
            (corner - 0.002, corner + 0.0032),
            (corner - 0.0052, corner),
            (-7.0, -6.99),
            (400.0, 400.02),
        ] {
            let got = f_integrals(a, b);
            let (k0, k1) = (variant::segment_of(a), variant::segment_of(b));
            let mid = if k1 > k0 { variant::segment_end(k0) } else { b };
            let m = 0.5 * (a + b);
            for p in [1, 2, 3] {
                let want =
                    simpson(a, mid, p, m) + if k1 > k0 { simpson(mid, b, p, m) } else { 0.0 };
                let e = got[p as usize - 1] - want;
                assert!(e.abs() < 1e-14, "[{a}, {b}] integral {p}: {e:e}");
            }
        }
    }

    /// A θ0 of 1e20 (refused by `identify`, but reaching the window search
    /// anyway) ends the search: it walks at most one quarter turn per pulse.
    #[test]
    fn window_search_is_bounded_whatever_theta0() {
        for theta0 in [1e20, -1e20, 1e300] {
            let rec = Recording {
                ppr: 8,
                theta0,
                pulse_t: (0..100).map(f64::from).collect(),
                ..Recording::default()
            };
            assert!(window_ends(&rec).len() <= 3 * 102);
        }
    }
}
