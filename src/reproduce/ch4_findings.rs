//! Findings on Chapter 4's printed text, each checked by computation: the
//! infimum of f used in Γ̂ (§4.2.2), the §4.3 example point against the
//! thesis's own law (Eq. 159), and Eq. 158 at the Fig. 39 point.

use super::{fmt_sig, Cause, Context};
use ivt_design::fit::OpenLoopLaw;
use ivt_kin::variant::f;
use std::f64::consts::{PI, SQRT_2};

/// min of f over one period, sampled finely (f has its minimum at the
/// corners θ = π/4 + kπ/2, which the sampling hits exactly).
fn inf_f() -> f64 {
    (0..=7200)
        .map(|i| f(2.0 * PI * i as f64 / 7200.0))
        .fold(f64::INFINITY, f64::min)
}

/// f_B of Eq. 159 (> 0: over-drive, u_ol = r_max, Eq. 160).
fn f_b(v: f64, t: f64) -> f64 {
    let b = OpenLoopLaw::thesis().boundary;
    b[0] * v + b[1] * t + b[2]
}

pub(crate) fn run(ctx: &mut Context) {
    let inf = inf_f();
    ctx.compare(
        "inf f over θ (used in Γ̂, §4.2.2)",
        1.0 / SQRT_2,
        "1/√2, §4.2.2 and Fig. 40",
        inf,
        5e-5,
        6,
        "minimum of ivt-kin's f over 7200 samples of a revolution",
        Some(Cause {
            why: "f = (π/(2√2))·max(|sin θ|, |cos θ|) is normalized to ⟨f⟩ = 1, so its minimum is \
                  (π/(2√2))·(1/√2) = π/4; 1/√2 is the minimum of the unnormalized max(|sin θ|, |cos θ|)",
            test: "src/reproduce/ch4_findings.rs::inf_f_is_pi_over_4",
        }),
    );
    let fb = f_b(7.0, 2.0);
    ctx.differs(
        "f_B(7 V, 2 N·m) of Eq. 159 at the §4.3 example point [V]",
        "an operating point of the law (§4.3: multipliers 0.7776, 0.4871)",
        format!("{} V > 0: over-drive, u_ol = r_max", fmt_sig(fb, 3)),
        "—",
        Cause {
            why: "7 − 1.579·2 − 0.632 = 3.21 > 0, so Eq. 160 saturates u_ol at r_max there; the thesis linearizes \
                  about the unconstrained orbit (r̄ = 0.0242 m on thesis-ch4, beyond r_max = 0.012 m)",
            test: "src/reproduce/ch4_findings.rs::seven_volts_two_nm_is_over_drive",
        },
    );
    let r_f = OpenLoopLaw::thesis().r_f(6.0, 6.0);
    ctx.compare(
        "Eq. 158 r_f at (6 V, 6 N·m) against Fig. 39's r̄ [m]",
        0.0067,
        "Fig. 39",
        r_f,
        5e-5,
        4,
        "the printed polynomial evaluated",
        Some(Cause {
            why: "Eq. 158 is a fit: on thesis-ch4 it is 0.42 mm RMS from r̄ over the grid, and here 0.66 mm from \
                  r̄ = 0.00678 m; its printed digits cannot do better (rounding the exact fit to them gives ~0.8 mm)",
            test: "src/reproduce/design.rs::printed_digits_limit_eq158",
        }),
    );
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::f64::consts::FRAC_PI_4;

    #[test]
    fn inf_f_is_pi_over_4() {
        assert!((inf_f() - FRAC_PI_4).abs() < 1e-12, "{}", inf_f());
        assert!((inf_f() - 1.0 / SQRT_2).abs() > 0.078);
        // ⟨f⟩ = 1 (the normalization that moves the minimum).
        let n = 100_000;
        let mean: f64 = (0..n)
            .map(|i| f(2.0 * PI * (i as f64 + 0.5) / n as f64))
            .sum::<f64>()
            / n as f64;
        assert!((mean - 1.0).abs() < 1e-8, "{mean}");
    }

    #[test]
    fn seven_volts_two_nm_is_over_drive() {
        assert!((f_b(7.0, 2.0) - 3.21).abs() < 1e-12);
        assert_eq!(OpenLoopLaw::thesis().u_ol(7.0, 2.0), 0.012);
    }
}
