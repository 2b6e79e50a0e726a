//! The logs of three runs are pinned bit for bit: the FNV-1a 64 hash of every
//! channel message's JSON bytes (what the MCAP log and the CSV files carry)
//! and of the summary's numbers. The expected hashes are those of the plant
//! kernels this integrator replaced (recorded before the change), so any
//! change in the integration order of operations, in the step-size control
//! or in what a channel logs shows here. The three runs cover every path of
//! the integrator: fixed-step RK4 in the angle domain, adaptive DP5 with
//! first-same-as-last in the angle domain, the DP5 start-up in the time
//! domain with dense-output corner landing (every run starts from rest), and
//! the armature current as a state (L_a > 0).
// A test may expect (the package's panic lints guard library code).
#![allow(clippy::expect_used)]

use ivt_sim::record::Sample;
use ivt_sim::run::Simulation;
use ivt_sim::scene::{IntegratorMethod, Scene};
use ivt_sim::testing::shipped_scene;

/// FNV-1a, 64 bit.
fn fnv(hash: &mut u64, bytes: &[u8]) {
    for &b in bytes {
        *hash ^= u64::from(b);
        *hash = hash.wrapping_mul(0x0100_0000_01b3);
    }
}

/// Hash of the run's channel messages (in log order) and of its summary
/// without the wall-clock fields; the number of messages.
fn fingerprint(scene: &Scene) -> (u64, usize) {
    let mut hash = 0xcbf2_9ce4_8422_2325;
    let mut count = 0;
    let mut buf = Vec::new();
    let mut sink = |s: Sample| {
        buf.clear();
        s.write_json(&mut buf);
        fnv(&mut hash, &buf);
        count += 1;
    };
    let run = Simulation::new(scene).sink(&mut sink).run().expect("runs");
    let s = &run.summary;
    for x in [
        s.settling_time_s.unwrap_or(f64::NAN),
        s.overshoot_pct,
        s.undershoot_pct,
        s.static_error_rad_s,
        s.final_omega_a_rad_s,
        s.rms_control_effort_m_per_rad,
        s.rms_dr_dt_m_per_s,
        s.max_abs_dr_dt_m_per_s,
        s.saturated_fraction,
    ] {
        fnv(&mut hash, &x.to_bits().to_le_bytes());
    }
    for n in [s.pulses, s.fault_pulses, s.missed_steps]
        .iter()
        .chain(&s.integrator_steps)
    {
        fnv(&mut hash, &n.to_le_bytes());
    }
    (hash, count)
}

fn drive() -> Scene {
    shipped_scene("drive.toml")
}

/// The default scene as shipped: RK4 with one step per pulse after a DP5
/// start-up in the time domain.
#[test]
fn default_scene_rk4_log_is_unchanged() {
    let (hash, count) = fingerprint(&drive());
    assert_eq!(
        (hash, count),
        (0xa413_b01a_fac8_b45c, 24001),
        "{hash:#018x}"
    );
}

/// The default scene, first 20 s, with adaptive DP5 throughout.
#[test]
fn default_scene_dp5_log_is_unchanged() {
    let mut s = drive();
    s.duration_s = 20.0;
    s.integrator.method = IntegratorMethod::Dp5;
    let (hash, count) = fingerprint(&s);
    assert_eq!((hash, count), (0x5432_7bf8_4772_5a30, 7998), "{hash:#018x}");
}

/// The default scene, first 10 s, DP5 with an armature inductance of 0.1 mH
/// (i_a integrated as a state, Eq. 137).
#[test]
fn inductive_plant_dp5_log_is_unchanged() {
    let mut s = drive();
    s.duration_s = 10.0;
    s.integrator.method = IntegratorMethod::Dp5;
    s.plant.l_a = Some(1e-4);
    let (hash, count) = fingerprint(&s);
    assert_eq!((hash, count), (0x8648_35ee_d6d7_8ff0, 4001), "{hash:#018x}");
}
