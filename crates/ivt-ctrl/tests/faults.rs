//! Faults, safe states, memory bound, and a proptest that arbitrary
//! timestamps, intervals and readings never panic and always give a finite
//! r in [0, r_max] (issue 5).
#![allow(clippy::indexing_slicing, clippy::unwrap_used)]

use ivt_ctrl::{ActuatorMap, Config, Controller, Fault, Gains, LawKind, StepperLimits, REFIT};
use proptest::prelude::*;
use std::sync::atomic::{AtomicU32, Ordering};

const F: f32 = 1.0e6;

fn cfg() -> Config {
    Config {
        f_timer_hz: F,
        law: LawKind::Delay,
        ..Config::default()
    }
}

/// Feed `n` pulses 500 ticks apart (100 rpm at PPR 1200, 1 MHz) from `t0`.
fn spin<const P: usize>(c: &mut Controller<P>, t0: u32, n: u32) -> u32 {
    let mut t = t0;
    for _ in 0..n {
        t = t.wrapping_add(500);
        c.on_pulse(t);
    }
    t
}

#[test]
fn controller_1200_fits_in_5_kib() {
    let size = core::mem::size_of::<Controller<1200>>();
    println!("size_of::<Controller<1200>>() = {size} bytes");
    assert!(size <= 5 * 1024, "{size}");
}

#[test]
fn stall_seen_by_step_tick_goes_to_safe_r_and_recovers() {
    let mut c = Controller::<1200>::new(cfg());
    let t = spin(&mut c, 0, 2500);
    assert!(c.output().ready && c.output().r > 0.0);
    // Default stall timeout 0.5 s = 500_000 ticks.
    assert_eq!(c.step_tick(t.wrapping_add(400_000)).fault, Fault::None);
    let st = c.step_tick(t.wrapping_add(600_000));
    assert_eq!(st.fault, Fault::Stall);
    let o = c.output();
    assert_eq!(
        (o.r, o.r_d, o.ready, o.fault),
        (0.0, 0.0, false, Fault::Stall)
    );
    assert_eq!(o.stepper_target, ActuatorMap::sgivt(3200.0).steps(0.0));
    // Pulses resume: the first reports the stall restart, then open loop
    // (r = u_ol) until a full revolution, then the law runs again.
    let t2 = t.wrapping_add(700_000);
    assert_eq!(c.on_pulse(t2).fault, Fault::Stall);
    let o = c.on_pulse(t2.wrapping_add(500));
    assert_eq!((o.fault, o.ready, o.r), (Fault::None, false, o.r_ol));
    spin(&mut c, t2.wrapping_add(500), 1201);
    assert!(c.output().ready);
}

#[test]
fn late_pulse_is_a_stall_restart_without_step_ticks() {
    let mut c = Controller::<80>::new(cfg());
    let t = spin(&mut c, 0, 200);
    let o = c.on_pulse(t.wrapping_add(2_000_000));
    assert_eq!((o.fault, o.ready, o.r_d), (Fault::Stall, false, 0.0));
}

#[test]
fn zero_and_too_short_intervals_are_ignored() {
    let mut c = Controller::<80>::new(cfg());
    let t = spin(&mut c, 0, 200);
    let before = c.output();
    let dup = c.on_pulse(t);
    assert_eq!(dup.fault, Fault::IntervalTooShort);
    assert_eq!(Controller::<80>::new(cfg()).on_pulse(0).fault, Fault::None);
    // ω_max = 200 rad/s at PPR 80 → intervals < 1e6·(2π/80)/200 = 392 ticks rejected.
    assert_eq!(
        c.on_pulse(t.wrapping_add(300)).fault,
        Fault::IntervalTooShort
    );
    assert_eq!((dup.r, dup.omega_a), (before.r, before.omega_a));
    // The glitch did not enter the history: the next good pulse is normal.
    assert_eq!(c.on_pulse(t.wrapping_add(500)).fault, Fault::None);
}

#[test]
fn invalid_readings_are_held_and_flagged() {
    let mut c = Controller::<80>::new(cfg());
    c.update_inputs(6.0, 6.0);
    let r_ol = c.output().r_ol;
    for (v, t) in [
        (f32::NAN, 6.0),
        (6.0, f32::INFINITY),
        (1000.0, 6.0),
        (6.0, -50.0),
    ] {
        c.update_inputs(v, t);
        assert_eq!(
            (c.output().fault, c.output().r_ol),
            (Fault::InputInvalid, r_ol)
        );
    }
    // Still reported on pulses until a valid reading arrives.
    assert_eq!(c.on_pulse(1000).fault, Fault::InputInvalid);
    c.update_inputs(30.0, 6.0); // plausible, outside the working region: clamped, no fault
    assert_eq!(c.output().fault, Fault::None);
    assert!(c.output().inputs_clamped);
}

#[test]
fn invalid_config_is_a_permanent_safe_state() {
    for bad in [
        Config {
            f_timer_hz: 0.0,
            ..cfg()
        },
        Config {
            omega0: f32::NAN,
            ..cfg()
        },
        Config {
            decimation: 0,
            ..cfg()
        },
        Config {
            stepper: StepperLimits {
                max_speed: -1.0,
                accel: 1.0,
            },
            ..cfg()
        },
        Config {
            gains: Gains {
                k: f32::INFINITY,
                ..Gains::default()
            },
            ..cfg()
        },
    ] {
        let mut c = Controller::<80>::new(bad);
        for t in [0u32, 500, 1000] {
            let o = c.on_pulse(t);
            assert_eq!((o.fault, o.r), (Fault::Config, 0.0));
        }
        assert!(!c.step_tick(2000).step);
    }
    assert_eq!(Controller::<0>::new(cfg()).on_pulse(5).fault, Fault::Config);
}

#[derive(Clone, Debug)]
enum Op {
    Pulse(u32),
    PulseAfter(u32),
    Inputs(f32, f32),
    Tick(u32),
}

fn any_f32() -> impl Strategy<Value = f32> {
    prop_oneof![
        Just(f32::NAN),
        Just(f32::INFINITY),
        Just(f32::NEG_INFINITY),
        Just(0.0),
        Just(f32::MAX),
        -20.0f32..60.0,
        any::<f32>(),
    ]
}

fn any_u32() -> impl Strategy<Value = u32> {
    prop_oneof![1 => Just(0u32), 1 => Just(u32::MAX), 1 => Just(1u32), 4 => 8_000u32..400_000, 1 => any::<u32>()]
}

fn op() -> impl Strategy<Value = Op> {
    prop_oneof![
        1 => any_u32().prop_map(Op::Pulse),
        4 => any_u32().prop_map(Op::PulseAfter),
        1 => (any_f32(), any_f32()).prop_map(|(v, t)| Op::Inputs(v, t)),
        1 => any_u32().prop_map(Op::Tick),
    ]
}

fn law() -> impl Strategy<Value = LawKind> {
    prop_oneof![
        Just(LawKind::Delay),
        Just(LawKind::NoDelay),
        Just(LawKind::Prop),
        Just(LawKind::Open)
    ]
}

fn check_output(o: ivt_ctrl::ControlOutput, r_max: f32) -> Result<(), TestCaseError> {
    prop_assert!(o.r.is_finite() && o.r >= 0.0 && o.r <= r_max, "r = {}", o.r);
    prop_assert!(o.r_d.is_finite() && o.r_ol.is_finite());
    Ok(())
}

/// Pulses on which the law ran, over all cases (the generator must reach it).
static READY_PULSES: AtomicU32 = AtomicU32::new(0);

#[test]
fn proptest_reaches_the_running_law() {
    never_panics_and_r_stays_in_range();
    let n = READY_PULSES.load(Ordering::Relaxed);
    println!("pulses with the law running: {n}");
    assert!(n > 100);
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 256, .. ProptestConfig::default() })]

    /// Arbitrary pulse timestamps (absolute or as intervals, incl. 0 and
    /// u32::MAX), readings (NaN, ±∞, 0, huge) and step ticks, on PPR 4 so a
    /// short sequence reaches the running law.
    #[test]
    fn never_panics_and_r_stays_in_range(
        ops in proptest::collection::vec(op(), 1..400),
        law in law(),
        k in any_f32(),
    ) {
        let gains = Gains { k: if k.is_finite() { k * 1e-4 } else { k }, ..Gains::default() };
        let mut c = Controller::<4>::new(Config { law, gains, ..cfg() });
        let mut t = 0u32;
        let mut ready = 0u32;
        for op in ops {
            match op {
                Op::Pulse(x) => { t = x; check_output(c.on_pulse(x), REFIT.r_max)?; }
                Op::PulseAfter(d) => {
                    t = t.wrapping_add(d);
                    let o = c.on_pulse(t);
                    ready += u32::from(o.ready);
                    check_output(o, REFIT.r_max)?;
                }
                Op::Inputs(v, tu) => { c.update_inputs(v, tu); check_output(c.output(), REFIT.r_max)?; }
                Op::Tick(d) => { let _ = c.step_tick(t.wrapping_add(d)); check_output(c.output(), REFIT.r_max)?; }
            }
        }
        READY_PULSES.fetch_add(ready, Ordering::Relaxed);
    }

    /// Arbitrary configurations (any f32 in every numeric field) never panic.
    #[test]
    fn arbitrary_config_never_panics(
        f in any_f32(), w0 in any_f32(), wmax in any_f32(), stall in any_f32(),
        spm in any_f32(), vmax in any_f32(), acc in any_f32(), safe in any_f32(),
        dec in any::<u16>(), law in law(), pulses in proptest::collection::vec(any_u32(), 1..50),
    ) {
        let config = Config {
            f_timer_hz: f, omega0: w0, omega_max: wmax, stall_timeout_s: stall, decimation: dec, law,
            actuator: ActuatorMap { steps_per_metre: spm, offset_steps: 0 },
            stepper: StepperLimits { max_speed: vmax, accel: acc }, safe_r: safe,
            ..cfg()
        };
        let mut c = Controller::<3>::new(config);
        let mut t = 0u32;
        for p in pulses {
            t = t.wrapping_add(p);
            check_output(c.on_pulse(t), REFIT.r_max)?;
            let _ = c.step_tick(t);
        }
    }
}

/// `unconfigured()` is a `const` (a firmware `static` initializer) in the
/// config-fault safe state; `reset` in place behaves exactly like `new`,
/// also after the controller has run.
#[test]
fn reset_in_place_equals_new() {
    const IDLE: Controller<80> = Controller::unconfigured();
    let mut c = IDLE;
    let o = c.on_pulse(100);
    assert_eq!((o.fault, o.r), (Fault::Config, 0.0));
    assert!(!c.step_tick(200).step);

    let mut fresh = Controller::<80>::new(cfg());
    c.reset(cfg());
    spin(&mut c, 0, 500);
    let mut run_a = Vec::new();
    let mut run_b = Vec::new();
    // Reset again after running, then compare pulse by pulse with a new one.
    c.reset(cfg());
    let mut t = 1_000_000u32;
    for k in 0..300u32 {
        t = t.wrapping_add(7000 + (k % 7) * 13);
        run_a.push(c.on_pulse(t));
        run_b.push(fresh.on_pulse(t));
    }
    assert_eq!(run_a, run_b);
}
