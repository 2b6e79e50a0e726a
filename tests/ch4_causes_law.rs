//! What does and does not explain Fig. 42's printed multipliers (0.7776,
//! 0.4871 at (7 V, 2 N·m); ours 0.7866, 0.6044), continued from
//! `tests/ch4_causes.rs`: the hypotheses about the feedback law of Eq. 174
//! and its gains (the printed ratio k2 = 2k, a delay over part of a
//! revolution, the law sampled as a controller runs it, another orbit, the
//! gain scales both printed numbers determine).
// A test may expect and index (the package's panic lints guard library code).
#![allow(clippy::expect_used, clippy::indexing_slicing)]

#[path = "common/fig42.rs"]
mod fig42;

use core::f64::consts::PI;
use fig42::{ch4_pair, fig42_orbit, max_without_structural, miss, printed_pair, OURS, PRINTED};
use ivt_design::delay::{
    delay_stability_about, steady_orbit, system_matrix, DelayOptions, FeedbackGains,
};
use ivt_design::shooting::{omega_at_angles, periodic_at_r, ShootingOptions};
use ivt_design::OperatingPoint;
use ivt_hb::stability::floquet::{expm, expm_scratch_len, monodromy_uniform, HsuRule};
use ivt_kin::plant::PlantParams;

/// Why 0.4871 cannot come out with the printed gain ratio k2 = 2k: with
/// ω̄ ≈ ω0, Eq. 174.c–d give Δr' = (k/2π)∫_{θ−2π}^{θ} Δω + k2 (Δω − Δω_T),
/// a feedback law whose transfer (1 − e^{−2πs})(k/(2πs) + k2) vanishes at
/// s = −k/(2π k2), i.e. at the multiplier e^{−k/k2} = e^{−1/2} = 0.607; as
/// the gains grow along the ratio a root goes there. On thesis-ch4 at
/// (7 V, 2 N·m) max |μ| along k2 = 2k, k = 1e-3…1e2 mm·rad⁻¹, never goes
/// below 0.60, and its floor is e^{−1/2} to 5e-3; at the other operating
/// points near the example (V_m 5…9 V at 2 N·m, T_U 1.5…9 N·m at 7 V, and
/// the Fig. 42 grid nodes 6.8 and 7.2 V beside 7 V, which is not one) the
/// printed (0.06, 0.12) gives ≥ 0.59. Other ratios do get below 0.4871:
/// (k, k2) = (0.075, 0.10) gives 0.38. A unit factor on one gain only
/// (30/π for rpm, 2π per revolution, ω0, or their inverses) leaves at least
/// one multiplier 0.05 off the print.
#[test]
fn printed_gain_ratio_floors_the_multiplier_at_exp_minus_half() {
    let (plant, op, orbit) = fig42_orbit();
    let opts = DelayOptions::default();
    let mu = |k: f64, k2: f64| {
        let g = FeedbackGains::from_thesis_mm_per_rad(k, k2);
        delay_stability_about(&plant, &op, g, &orbit, &opts)
            .expect("stability")
            .max_abs_multiplier
    };
    let floor = (0..=40)
        .map(|i| 1e-3 * 1e5f64.powf(i as f64 / 40.0))
        .map(|k| mu(k, 2.0 * k))
        .fold(f64::INFINITY, f64::min);
    assert!(floor > 0.60, "floor {floor}");
    assert!((floor - (-0.5f64).exp()).abs() < 5e-3, "floor {floor}");
    assert!(mu(0.075, 0.10) < 0.40);

    let along_vm = (0..=8).map(|i| (5.0 + 0.5 * i as f64, 2.0));
    let along_tu = (0..=15).map(|i| (7.0, 1.5 + 0.5 * i as f64));
    // 7 V is not a node of Fig. 42's V_m grid (2, 2.4, …, 12): its neighbours.
    let grid_nodes = [(6.8, 2.0), (7.2, 2.0)];
    for (v_m, t_u) in along_vm.chain(along_tu).chain(grid_nodes) {
        let at = OperatingPoint::at_100_rpm(v_m, t_u);
        let o = steady_orbit(&plant, &at, None, &opts).expect("orbit");
        let pair = printed_pair(&plant, &at, &o, (1.0, 1.0));
        assert!(pair[1] > 0.59, "({v_m} V, {t_u} N·m): {pair:?}");
    }

    let omega0 = op.omega0;
    for f in [30.0 / PI, 2.0 * PI, omega0] {
        for scale in [(f, 1.0), (1.0 / f, 1.0), (1.0, f), (1.0, 1.0 / f)] {
            let pair = ch4_pair(scale);
            assert!(miss(pair) > 0.05, "{scale:?}: {pair:?}");
        }
    }
}

/// Hsu sub-intervals of the dense monodromies below; the grid 2π/(2 N_Q) puts
/// every gear corner (a multiple of π/2) on an even node, so the midpoint rule
/// never samples 𝒜 at a jump of f_θ and stays second order (1e-4 at N_Q = 1000,
/// `hsu_transformation_matrix_is_not_the_cause`).
const N_Q: usize = 1200;

/// 𝒜(θ) of Eq. 179 sampled row-major at θ_j = jπ/N_Q, j < 2 N_Q, about ω̄ =
/// `omega[j]` at r = `r`, with the delay of Eq. 171 over `len` of θ instead
/// of 2π: ω_a = len/z, z = ∫_{θ−len}^{θ} dσ/ω, Δu(θ, x) on x ∈ [0, len].
/// The Chebyshev coordinate x·2π/len maps it onto the [0, 2π] of
/// `system_matrix`, so the transport rows (Eq. 175) and their share of the
/// boundary row (Eq. 176) scale by 2π/len, as does K = −k ω0²/len
/// (Eq. 174.c); Eq. 174.d takes ω̄ at both ends, −Δu(θ,0)/ω̄(θ)² +
/// Δu(θ,len)/ω̄(θ−len)² (equal for len = 2π, the thesis's C).
fn delay_samples(
    plant: &PlantParams,
    op: &OperatingPoint,
    gains: FeedbackGains,
    (r, omega): (f64, &[f64]),
    len: f64,
) -> Vec<f64> {
    let opts = DelayOptions::default();
    let nn = opts.chebyshev_order;
    let s = 2.0 * PI / len;
    let grid = 2 * N_Q;
    let lag = (len * N_Q as f64 / PI).round() as usize;
    assert!(
        (lag as f64 * PI / N_Q as f64 - len).abs() < 1e-12,
        "len on the grid"
    );
    let mut out = Vec::with_capacity(grid * (nn + 3) * (nn + 3));
    for (j, &w) in omega.iter().enumerate() {
        let theta = j as f64 * PI / N_Q as f64;
        let mut a = system_matrix(plant, op, gains, r, theta, w, &opts).expect("𝒜");
        // Column 0 of the boundary row is B alone (dT_0/dx = 0).
        let b = a[(nn, 0)];
        let w_lag = omega[(j + grid - lag % grid) % grid];
        for n in 0..=nn {
            let t0 = if n % 2 == 0 { 1.0 } else { -1.0 };
            for i in 0..nn {
                a[(i, n)] *= s;
            }
            a[(nn, n)] = b * t0 + s * (a[(nn, n)] - b * t0);
            a[(nn + 2, n)] = -t0 / (w * w) + 1.0 / (w_lag * w_lag);
        }
        a[(nn + 1, nn + 2)] *= s;
        // DMatrix is column-major; the Hsu product wants row-major.
        out.extend_from_slice(a.transpose().as_slice());
    }
    out
}

/// Max |multiplier| (structural one aside) of the Hsu midpoint product over
/// the samples of [`delay_samples`].
fn midpoint_mu(samples: &[f64]) -> f64 {
    let dim = DelayOptions::default().chebyshev_order + 3;
    let mut m = vec![0.0; dim * dim];
    monodromy_uniform(dim, samples, N_Q, 2.0 * PI, HsuRule::Midpoint, &mut m);
    max_without_structural(&m, dim)
}

/// ω̄ at θ_j = jπ/N_Q on the orbit at r = `r` starting at `omega_start`.
fn omega_grid(plant: &PlantParams, op: &OperatingPoint, r: f64, omega_start: f64) -> Vec<f64> {
    omega_at_angles(plant, op.v_m, op.t_u, r, omega_start, 2 * N_Q, 8).expect("ω̄ samples")
}

/// Both printed cases for the 𝒜 samples `make(gains)`, reduced by `mu`.
fn pair_of(make: impl Fn(FeedbackGains) -> Vec<f64>, mu: impl Fn(&[f64]) -> f64) -> [f64; 2] {
    PRINTED.map(|(k, k2, _)| mu(&make(FeedbackGains::from_thesis_mm_per_rad(k, k2))))
}

/// `got` on `want` to the 4 digits quoted in the doc comments, and away from
/// the printed pair.
fn assert_pair(what: &str, got: [f64; 2], want: [f64; 2]) {
    for (g, w) in got.into_iter().zip(want) {
        assert!((g - w).abs() < 2e-4, "{what}: {got:?}, expected {want:?}");
    }
    assert!(miss(got) > 0.04, "{what}: {got:?}");
}

/// f has period π/2, so the law might average ω over a quarter or half
/// revolution instead of 2π: with the delay over len of θ (ω_a = len/z,
/// K = −k ω0²/len) the zero of the feedback law moves to e^{−(2π/len)k/k2},
/// 0.37 for len = π and 0.14 for π/2, so 0.4871 would not be floored.
/// Computed (Chebyshev Tau N = 16, Hsu midpoint N_Q = 1200, exact orbit):
/// len = 2π gives ours (0.7866 / 0.6044, the check of the construction),
/// len = π 0.7335 / 0.5498 and len = π/2 0.7534 / 0.6715 — neither near
/// 0.7776 / 0.4871.
#[test]
fn quarter_or_half_revolution_delay_is_not_the_cause() {
    let (plant, op, orbit) = fig42_orbit();
    let omega = omega_grid(&plant, &op, orbit.r, orbit.omega_start);
    let with_len = |len: f64| {
        pair_of(
            |g| delay_samples(&plant, &op, g, (orbit.r, &omega), len),
            midpoint_mu,
        )
    };
    let full = with_len(2.0 * PI);
    for (got, ours) in full.into_iter().zip(OURS) {
        assert!((got - ours).abs() < 1e-4, "len = 2π: {got} vs {ours}");
    }
    assert_pair("len = π", with_len(PI), [0.7335, 0.5498]);
    assert_pair("len = π/2", with_len(0.5 * PI), [0.7534, 0.6715]);
}

/// Max |multiplier| of the sampled law: r_d held between `per_rev` equally
/// spaced updates Δr ← Δr + (2π/per_rev)(K Δz + k2 [Δu(θ,0) − Δu(θ,2π)])
/// (Eq. 180 with the integral stepped as a controller does), the rest of
/// Eq. 179 continuous (Hsu midpoint with the Δr row set to zero).
fn sampled_mu(samples: &[f64], per_rev: usize) -> f64 {
    let dim = DelayOptions::default().chebyshev_order + 3;
    let (d2, dr) = (dim * dim, dim - 2);
    let every = N_Q / per_rev;
    assert_eq!(every * per_rev, N_Q, "updates on the grid");
    let (h, h_s) = (2.0 * PI / N_Q as f64, 2.0 * PI / per_rev as f64);
    // The Δr row (Eq. 177) is constant in θ: k2 (T_0 − T_I) and K.
    let law = samples[dr * dim..(dr + 1) * dim].to_vec();
    let mut m = vec![0.0; d2];
    for i in 0..dim {
        m[i * dim + i] = 1.0;
    }
    let (mut step, mut e, mut prod) = (vec![0.0; d2], vec![0.0; d2], vec![0.0; d2]);
    let mut scratch = vec![0.0; expm_scratch_len(dim)];
    for (s, mid) in samples.chunks_exact(d2).skip(1).step_by(2).enumerate() {
        for (i, (o, a)) in step.iter_mut().zip(mid).enumerate() {
            *o = if i / dim == dr { 0.0 } else { h * a };
        }
        expm(&step, dim, &mut e, &mut scratch);
        ivt_num::small::matmul(&e, &m, dim, &mut prod);
        m.copy_from_slice(&prod);
        if (s + 1) % every == 0 {
            for c in 0..dim {
                let inc: f64 = (0..dim).map(|l| law[l] * m[l * dim + c]).sum();
                m[dr * dim + c] += h_s * inc;
            }
        }
    }
    max_without_structural(&m, dim)
}

/// Three more ways the thesis might have set up Eq. 179, each checked on both
/// printed cases:
/// - the law sampled as a controller runs it, r_d stepped 4, 8 (§4.4's "every
///   45°"), 40 or 80 (every 4.5°) times per revolution: 0.7852…0.7865 /
///   0.6002…0.6044, converging to ours (0.7866 / 0.6044);
/// - linearized about the averaged orbit of §4.2 instead of the exact one:
///   ω̄ ≡ ω0 in A, B, C gives 0.7941 / 0.6126, and 𝒜 averaged over θ on the
///   exact orbit (monodromy exp(2π⟨𝒜⟩)) 0.7916 / 0.6093;
/// - about the orbit at r̄ = r_f(7, 2) of the fitted Eq. 158 (0.024195 m
///   instead of the exact 0.02422; its mean speed is 100.8 rpm):
///   0.7916 / 0.6106 with K = −k ω0²/2π, 0.7854 / 0.6037 with the orbit's
///   own mean speed in K.
#[test]
fn sampled_law_averaged_orbit_or_eq158_r_is_not_the_cause() {
    let (plant, op, orbit) = fig42_orbit();
    let omega = omega_grid(&plant, &op, orbit.r, orbit.omega_start);
    let exact = |g| delay_samples(&plant, &op, g, (orbit.r, &omega), 2.0 * PI);
    for (per_rev, want) in [
        (4, [0.7852, 0.6002]),
        (8, [0.7856, 0.6036]),
        (40, [0.7864, 0.6043]),
        (80, [0.7865, 0.6044]),
    ] {
        let got = pair_of(exact, |s| sampled_mu(s, per_rev));
        assert_pair(&format!("sampled {per_rev}/rev"), got, want);
    }

    let flat = vec![op.omega0; 2 * N_Q];
    let averaged = pair_of(
        |g| delay_samples(&plant, &op, g, (orbit.r, &flat), 2.0 * PI),
        midpoint_mu,
    );
    assert_pair("ω̄ ≡ ω0", averaged, [0.7941, 0.6126]);
    let dim = DelayOptions::default().chebyshev_order + 3;
    let mean_mu = |s: &[f64]| {
        let mut mean = vec![0.0; dim * dim];
        for a in s.chunks_exact(dim * dim) {
            for (m, v) in mean.iter_mut().zip(a) {
                *m += v * PI / N_Q as f64;
            }
        }
        let (mut e, mut scratch) = (vec![0.0; dim * dim], vec![0.0; expm_scratch_len(dim)]);
        expm(&mean, dim, &mut e, &mut scratch);
        max_without_structural(&e, dim)
    };
    assert_pair("⟨𝒜⟩", pair_of(exact, mean_mu), [0.7916, 0.6093]);

    let r_f = f64::from(ivt_ctrl::THESIS.r_f(7.0, 2.0));
    assert!((r_f - 0.024195).abs() < 1e-6, "{r_f}");
    let fitted = periodic_at_r(
        &plant,
        op.v_m,
        op.t_u,
        r_f,
        orbit.omega_start,
        &ShootingOptions::default(),
    )
    .expect("orbit at r_f");
    assert!(
        (fitted.omega_a() * 30.0 / PI - 100.8).abs() < 0.05,
        "{}",
        fitted.omega_a()
    );
    let w_f = omega_grid(&plant, &op, r_f, fitted.omega_start);
    for (omega0, want) in [
        (op.omega0, [0.7916, 0.6106]),
        (fitted.omega_a(), [0.78538, 0.6037]),
    ] {
        let at = OperatingPoint { omega0, ..op };
        let got = pair_of(
            |g| delay_samples(&plant, &at, g, (r_f, &w_f), 2.0 * PI),
            midpoint_mu,
        );
        assert_pair(&format!("r_f, K with ω0 = {omega0}"), got, want);
    }
}

/// What the two printed numbers do determine: with a separate scale on each
/// gain, (k, k2) → (s_k k, s_k2 k2), both printed multipliers hold at
/// s_k = 0.78637, s_k2 = 0.52267 (Newton from (0.78, 0.52), the best node of
/// a log grid over 0.1…10 in each scale, measured, not asserted), i.e. gains
/// in the ratio k2/k = 1.329 instead of the printed 2. Neither scale is one of
/// the unit factors tried in
/// `printed_gain_ratio_floors_the_multiplier_at_exp_minus_half`, and the
/// nearest simple fractions, (π/4, 1/2), give 0.767 / 0.516: the printed pair
/// belongs to other gains than the printed ones (or to another plant), not to
/// another reading of their unit.
#[test]
fn both_printed_multipliers_need_another_gain_ratio() {
    let residual = |s: [f64; 2]| {
        let pair = ch4_pair((s[0], s[1]));
        [pair[0] - PRINTED[0].2, pair[1] - PRINTED[1].2]
    };
    let mut s = [0.78, 0.52];
    for _ in 0..8 {
        let f = residual(s);
        let h = 1e-6;
        let fk = residual([s[0] + h, s[1]]);
        let fk2 = residual([s[0], s[1] + h]);
        let j = [
            [(fk[0] - f[0]) / h, (fk2[0] - f[0]) / h],
            [(fk[1] - f[1]) / h, (fk2[1] - f[1]) / h],
        ];
        let det = j[0][0] * j[1][1] - j[0][1] * j[1][0];
        s[0] -= (j[1][1] * f[0] - j[0][1] * f[1]) / det;
        s[1] -= (j[0][0] * f[1] - j[1][0] * f[0]) / det;
    }
    let f = residual(s);
    assert!(f[0].abs() < 1e-9 && f[1].abs() < 1e-9, "{f:?}");
    assert!(
        (s[0] - 0.78637).abs() < 1e-5 && (s[1] - 0.52267).abs() < 1e-5,
        "{s:?}"
    );
    assert!((2.0 * s[1] / s[0] - 1.329).abs() < 1e-3);
    let simple = ch4_pair((PI / 4.0, 0.5));
    for (got, want) in simple.into_iter().zip([0.7671, 0.5159]) {
        assert!((got - want).abs() < 1e-4, "(π/4, 1/2): {simple:?}");
    }
    assert!(miss(simple) > 0.01);
}
