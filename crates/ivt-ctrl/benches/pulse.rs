//! Hot paths of the controller (issue 5 target: one encoder-pulse update
//! ≤ 50 ns median on the host). Run: `cargo bench -p ivt-ctrl --bench pulse`.
#![allow(missing_docs)]

use divan::{black_box, Bencher};
use ivt_ctrl::{AngleAverager, Config, Controller, LawKind, Plan, Selection, Sequencer};

fn main() {
    divan::main();
}

/// A controller that has seen two revolutions at 100 rpm (PPR 1200, 1 MHz),
/// so every benchmarked pulse runs the full law.
fn warmed<const P: usize>(law: LawKind, interval: u32) -> (Controller<P>, u32) {
    let mut c = Controller::<P>::new(Config {
        law,
        ..Config::default()
    });
    let mut t = 0u32;
    for _ in 0..(2 * P + 4) {
        t = t.wrapping_add(interval);
        c.on_pulse(t);
    }
    (c, t)
}

/// Benches `f` on a 1 MHz timer reading that advances `dt` ticks per call
/// from `t` (wrapping like the hardware counter).
fn on_timer<R>(bencher: Bencher, mut t: u32, dt: u32, mut f: impl FnMut(u32) -> R) {
    bencher.bench_local(move || {
        t = t.wrapping_add(dt);
        black_box(f(black_box(t)))
    });
}

#[divan::bench(args = [LawKind::Delay, LawKind::NoDelay, LawKind::Prop, LawKind::Open])]
fn on_pulse_ppr1200(bencher: Bencher, law: LawKind) {
    let (mut c, mut t) = warmed::<1200>(law, 500);
    // Alternate two intervals so ω, ω_T and the law see changing data.
    let mut k = 0u32;
    bencher.bench_local(move || {
        k = k.wrapping_add(1);
        t = t.wrapping_add(if k & 1 == 0 { 499 } else { 501 });
        black_box(c.on_pulse(black_box(t)))
    });
}

#[divan::bench]
fn on_pulse_ppr80(bencher: Bencher) {
    let (mut c, t) = warmed::<80>(LawKind::Delay, 7500);
    on_timer(bencher, t, 7500, move |t| c.on_pulse(t));
}

#[divan::bench]
fn averager_push_ppr1200(bencher: Bencher) {
    let mut a = AngleAverager::<1200>::new(1.0e6);
    on_timer(bencher, 0, 500, move |t| a.push(t));
}

#[divan::bench]
fn update_inputs(bencher: Bencher) {
    let (mut c, _) = warmed::<1200>(LawKind::Delay, 500);
    let mut v = 6.0f32;
    bencher.bench_local(move || {
        v = if v > 11.0 { 6.0 } else { v + 0.01 };
        c.update_inputs(black_box(v), black_box(6.0));
    });
}

#[divan::bench]
fn step_tick(bencher: Bencher) {
    let (mut c, t) = warmed::<1200>(LawKind::Delay, 500);
    on_timer(bencher, t, 10, move |t| c.step_tick(t));
}

/// A pulse through the commissioning sequencer (stage check, hold) and the
/// controller: the firmware's `ivt_fw_sequenced_pulse`. The plan is all
/// sequences (≈ 122 s), so the benchmark's pulses stay inside it.
#[divan::bench]
fn sequenced_pulse_ppr1200(bencher: Bencher) {
    let (mut c, t) = warmed::<1200>(LawKind::Prop, 500);
    let mut seq = Sequencer::new(Plan::default(), Selection::ALL, 1.0e6);
    on_timer(bencher, t, 500, move |t| seq.on_pulse(&mut c, t));
}
