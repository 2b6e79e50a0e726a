//! Processor in the loop: the QEMU firmware (`firmware/`, image `ivt-fw-qemu`)
//! behind the `Pil` backend against the in-process `Sil` backend: every output field must match bit for bit, since
//! both run the same f32 code (thumbv7em FPU vs x86-64 SSE, both IEEE-754
//! single precision with round-to-nearest; no fused multiply-add on either
//! side unless the compiler emits one — this test is what proves it doesn't).
//!
//! Needs QEMU and the built image: run through `firmware/run-qemu.sh test`
//! (scripts/test does), hence `#[ignore]` in a plain `cargo test`.

use ivt_ctrl::{Config, ControlOutput, LawKind};
use ivt_sim::backend::{sil, ControllerBackend};
use ivt_sim::pil::Pil;
use ivt_sim::SimError;

const PPR: usize = 1200;

fn bits(o: &ControlOutput) -> [u32; 6] {
    [o.omega, o.omega_a, o.omega_t, o.r_ol, o.r_d, o.r].map(f32::to_bits)
}

/// A pulse train of θ at ~100 rpm with a speed ripple and a slow drift, and
/// inputs that step the load: deterministic, no RNG.
fn drive(n: usize, f_timer: f32) -> Vec<(u32, Option<(f32, f32)>)> {
    let mut t: u32 = 0xFFF0_0000; // start near the u32 wrap on purpose
    let mut v = Vec::with_capacity(n);
    for k in 0..n {
        let ripple = 1.0 + 0.05 * (((k % 300) as f32 / 300.0) - 0.5);
        let drift = 1.0 + 0.1 * (k as f32 / n as f32);
        let omega = 10.47 * ripple * drift;
        let dt = (core::f32::consts::TAU / PPR as f32 / omega * f_timer) as u32;
        t = t.wrapping_add(dt);
        let inputs = if k % 100 == 0 {
            let t_u = if k < n / 2 { 4.0 } else { 7.5 }; // load step
            Some((8.0 + 0.001 * (k % 7) as f32, t_u))
        } else {
            None
        };
        v.push((t, inputs));
    }
    v
}

#[test]
#[ignore = "needs qemu-system-arm and the firmware image; run by firmware/run-qemu.sh test"]
fn pil_backend_matches_sil_backend_bit_for_bit() {
    let config = Config {
        f_timer_hz: 1.0e6,
        law: LawKind::Delay,
        ..Config::default()
    };
    let mut sil = sil(PPR, config).unwrap();
    let mut pil = Pil::start(PPR, &config).expect("start QEMU PIL");
    let pulses = drive(3 * PPR, config.f_timer_hz);
    let mut ready = 0;
    for (k, &(ticks, inputs)) in pulses.iter().enumerate() {
        if let Some((v_m, t_u)) = inputs {
            sil.update_inputs(v_m, t_u).unwrap();
            pil.update_inputs(v_m, t_u).unwrap();
        }
        let a = sil.on_pulse(ticks).unwrap();
        let b = pil.on_pulse(ticks).unwrap();
        assert_eq!(bits(&a), bits(&b), "pulse {k}: SIL {a:?} vs PIL {b:?}");
        assert_eq!(a, b, "pulse {k}");
        ready += a.ready as usize;
    }
    // The comparison must cover the closed loop, not just the start-up.
    assert!(ready > PPR, "only {ready} ready outputs");
    let rep = pil.finish().unwrap();
    assert_eq!(rep.pulses, pulses.len() as u64);
    eprintln!("firmware report: {rep:?}");
}

#[test]
#[ignore = "needs qemu-system-arm and the firmware image; run by firmware/run-qemu.sh test"]
fn pil_refuses_a_ppr_the_firmware_was_not_built_for() {
    match Pil::start(360, &Config::default()) {
        Err(SimError::BackendProtocol(msg)) => assert!(msg.contains("PPR 1200"), "{msg}"),
        Err(e) => panic!("wrong error {e}"),
        Ok(_) => panic!("PIL accepted PPR 360 on a PPR-1200 firmware"),
    }
}

#[test]
fn pil_without_an_image_is_a_clear_error() {
    let opts = ivt_wire::host::QemuOptions {
        elf: "/nonexistent/ivt-fw-qemu".into(),
        ..ivt_wire::host::QemuOptions::from_env()
    };
    match Pil::start_with(&opts, PPR, &Config::default()) {
        Err(SimError::BackendIo(msg)) => assert!(msg.contains("run-qemu.sh build"), "{msg}"),
        Err(e) => panic!("wrong error {e}"),
        Ok(_) => panic!("started without an image"),
    }
}

/// A short closed-loop scene with a load step: 2 s of θ at ~100 rpm (the
/// delay law is active after two revolutions, ≈ 1.3 s), T_U 6 → 8 N·m at
/// 1.5 s, every pulse logged.
const SHORT_LOAD_STEP: &str = r#"
name = "pil_load_step"
description = "PIL acceptance: T_U step 6 -> 8 N·m at 1.5 s, V_m = 8.6 V, delay law"
duration_s = 2.5

[inputs]
v_m = [[0.0, 8.6]]
t_u = [[0.0, 6.0], [1.5, 6.0], [1.51, 8.0]]

[initial]
omega = 10.0

[controller]
law = "delay"
k_mm_per_rad = 2.0
k2_mm_per_rad = 1.0
feedforward = false

[stepper]
max_speed = 8000

[[outputs.channels]]
name = "control"
every = 1
"#;

#[test]
#[ignore = "needs qemu-system-arm and the firmware image; run by firmware/run-qemu.sh test"]
fn pil_scene_with_load_step_gives_the_sil_r_sequence_bit_for_bit() {
    use ivt_sim::run::Simulation;
    use ivt_sim::scene::Scene;
    let scene = Scene::parse(SHORT_LOAD_STEP, "pil_load_step").unwrap();
    let sil = Simulation::new(&scene).run().unwrap();
    let pil = ivt_sim::pil::run_pil(&scene, &mut |_| {}).unwrap();
    let a = sil.channels.control.as_ref().unwrap();
    let b = pil.channels.control.as_ref().unwrap();
    assert_eq!(a.len(), b.len(), "pulse counts differ");
    let ready_after_step = a
        .iter()
        .filter(|s| s.t > 1.5 && s.out.omega_t != 0.0)
        .count();
    assert!(
        ready_after_step > 500,
        "feedback active on only {ready_after_step} pulses after the step"
    );
    for (k, (x, y)) in a.iter().zip(b).enumerate() {
        assert_eq!(
            x.out.r.to_bits(),
            y.out.r.to_bits(),
            "r differs at pulse {k} (t = {} s)",
            x.t
        );
        assert_eq!(x, y, "pulse {k}");
    }
    // The load step must have moved r, or the comparison proves little.
    let r_before = a.iter().rev().find(|s| s.t < 1.5).unwrap().out.r;
    let r_end = a.last().unwrap().out.r;
    assert_ne!(
        r_before.to_bits(),
        r_end.to_bits(),
        "r did not respond to the load step"
    );
    eprintln!("{} pulses compared; r {r_before} → {r_end} m", a.len());
}
