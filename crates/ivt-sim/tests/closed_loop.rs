//! Closed loop through the SIL backend (the `ivt-ctrl` controller), scenes
//! and outputs. Scenes come from `scenes/` so that what is tested is what ships.
// A test may index and unwrap (the package's panic lints guard library code).
#![allow(clippy::indexing_slicing, clippy::unwrap_used)]

use ivt_sim::record::Channel;
use ivt_sim::run::{RunResult, Simulation};
use ivt_sim::scene::{ChannelSpec, Law, Scene};
use std::path::PathBuf;

fn scene(name: &str) -> Scene {
    let p = PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("../../scenes")
        .join(format!("{name}.toml"));
    Scene::load(&p).unwrap()
}

fn go(s: &Scene) -> RunResult {
    Simulation::new(s).run().unwrap()
}

fn keep_all(s: &mut Scene) {
    s.outputs.channels = vec![
        ChannelSpec {
            name: Channel::Plant,
            every: 1,
        },
        ChannelSpec {
            name: Channel::Control,
            every: 1,
        },
    ];
}

/// RMS over pulses after `from` of the feedback part's dr_d/dθ (Δr_d between
/// consecutive pulses / Δθ): the law's own output, without the open-loop
/// step u_ol adds to r under either law.
fn rms_dr_dtheta(res: &RunResult, from: f64, dtheta: f64) -> f64 {
    let c = res.channels.control.as_ref().unwrap();
    let (mut s, mut n) = (0.0, 0);
    for w in c.windows(2) {
        if w[0].t >= from {
            let d = f64::from(w[1].out.r_d - w[0].out.r_d) / dtheta;
            s += d * d;
            n += 1;
        }
    }
    (s / n as f64).sqrt()
}

/// Time after `from` when ω_a last leaves ±`band` around its own final
/// value (mean over the last 3 s).
fn settling_to_final(res: &RunResult, from: f64, band: f64) -> (f64, f64) {
    let p = res.channels.plant.as_ref().unwrap();
    let t_end = p.last().unwrap().t;
    let tail: Vec<f64> = p
        .iter()
        .filter(|s| s.t > t_end - 3.0)
        .map(|s| s.omega_a)
        .collect();
    let fin = tail.iter().sum::<f64>() / tail.len() as f64;
    let last_out = p
        .iter()
        .filter(|s| s.t >= from && (s.omega_a - fin).abs() > band)
        .map(|s| s.t)
        .fold(from, f64::max);
    (last_out - from, fin)
}

/// Eq. 180 inside the band (T_U step 6 → 8 N·m at V_m = 8.6 V): ω_a returns
/// to ω0 with no static error. Bound 1e-4 rad/s (1e-5 relative): the 1 MHz
/// timer resolves ω_a of one revolution (≈ 0.6 s) to 1.7e-6 relative, and the
/// stepper's 1.2 µm steps move ω_a by ≈ 1.6e-4 rad/s, which the integral
/// dithers around; the measured mean error is ≈ 6e-8 rad/s. Without feedback
/// (the refitted u_ol alone, law "open") the error is the fit error of the
/// law at 8.6 V / 8 N·m, more than 1000× larger.
#[test]
fn delay_law_has_no_static_error_inside_the_band() {
    let s = scene("load_step_delay");
    let res = go(&s);
    let e = res.summary.static_error_rad_s;
    assert!(e.abs() < 1e-4, "static error {e}");
    assert!(
        res.summary.settling_time_s.is_some_and(|t| t < 5.0),
        "{:?}",
        res.summary
    );
    assert_eq!(res.summary.saturated_fraction, 0.0);
    let mut open = s.clone();
    open.controller.law = Law::Open;
    open.controller.feedforward = true;
    let e_open = go(&open).summary.static_error_rad_s;
    assert!(
        e_open.abs() > 1000.0 * e.abs().max(1e-6),
        "open-loop error {e_open}"
    );
}

/// Fig. 45's claim, quantified on the load step (both scenes with the
/// refitted feed-forward, the same integral gain k = 2 mm·rad⁻¹): the delay
/// law's feedback part is much smoother — measured RMS dr_d/dθ 7.7e-5 vs
/// 1.8e-3 m/rad (24×; asserted ≥ 10×). The no-delay law integrates ω itself,
/// so r_d follows its 4-per-revolution ripple; it also regulates the θ-mean
/// of ω instead of ω_a (the harmonic mean), leaving a static error in ω_a of
/// ≈ −0.08 rad/s, and it settles to its own final value later (measured
/// 3.8 s vs 1.2 s within ±0.05 rad/s; asserted: not earlier than the delay
/// law). (Without feed-forward both settled alike in 0.89 s, with the same
/// 25× smoothness ratio: u_ol adds the same step to r under both laws.)
#[test]
fn delay_law_is_smoother_than_no_delay_law() {
    let mut d = scene("load_step_delay");
    let mut n = scene("load_step_nodelay");
    keep_all(&mut d);
    keep_all(&mut n);
    let (rd, rn) = (go(&d), go(&n));
    let dtheta = std::f64::consts::TAU / d.encoder.ppr as f64;
    let (sd, fd) = settling_to_final(&rd, 10.0, 0.05);
    let (sn, fn_) = settling_to_final(&rn, 10.0, 0.05);
    let (qd, qn) = (
        rms_dr_dtheta(&rd, 10.0, dtheta),
        rms_dr_dtheta(&rn, 10.0, dtheta),
    );
    eprintln!("delay: settle {sd:.2} s → {fd:.5}, RMS dr/dθ {qd:.3e}; nodelay: settle {sn:.2} s → {fn_:.5}, RMS dr/dθ {qn:.3e}");
    assert!(sd <= sn, "convergence: {sd} vs {sn}");
    assert!(qn > 10.0 * qd, "RMS dr/dθ delay {qd:e} vs nodelay {qn:e}");
    let w0 = rd.summary.omega0_rad_s;
    assert!(
        (fd - w0).abs() < 1e-3 && (fn_ - w0) < -0.02,
        "finals {fd} {fn_} vs {w0}"
    );
}

/// Leaving the band (V_m 8 → 7 V at T_U = 8 N·m, the thesis's §4.3 step):
/// r saturates at 0 and ω_a falls below ω0; after V_m returns to 8.6 V the
/// loop recovers to ω0 within 5 s with a bounded overshoot (anti-windup: r_d
/// did not integrate the 15 s of error).
#[test]
fn saturation_and_recovery() {
    let mut s = scene("saturation");
    keep_all(&mut s);
    let res = go(&s);
    let c = res.channels.control.as_ref().unwrap();
    let p = res.channels.plant.as_ref().unwrap();
    let w0 = res.summary.omega0_rad_s;
    // late in the out-of-band phase: saturated at r = 0, ω_a well below ω0
    let late: Vec<_> = c
        .iter()
        .zip(p)
        .filter(|(c, _)| c.t > 15.0 && c.t < 20.0)
        .collect();
    assert!(late.iter().all(|(c, _)| c.out.saturated && c.out.r == 0.0));
    assert!(late.iter().all(|(_, p)| p.omega_a < 0.95 * w0));
    assert!(late.iter().all(|(c, _)| c.out.r_d.abs() < 1e-3), "wind-up");
    let st = res.summary.settling_time_s.expect("recovers");
    assert!(st < 5.0, "recovery took {st} s");
    assert!(
        res.summary.overshoot_pct < 10.0,
        "{}",
        res.summary.overshoot_pct
    );
    assert!(res.summary.static_error_rad_s.abs() < 1e-4);
}

/// Only what the scene asks for is recorded; the MCAP file holds exactly the
/// requested channels with the decimated counts, and reads back with the
/// `mcap` crate (JSON messages with the schema's fields).
#[test]
fn mcap_has_exactly_the_requested_channels() {
    let mut s = scene("load_step_delay");
    s.duration_s = 3.0;
    s.outputs.plots.clear();
    s.outputs.summary = false;
    s.outputs.channels = vec![
        ChannelSpec {
            name: Channel::Plant,
            every: 5,
        },
        ChannelSpec {
            name: Channel::Sensors,
            every: 3,
        },
    ];
    let res = go(&s);
    assert!(
        res.channels.control.is_none()
            && res.channels.stepper.is_none()
            && res.channels.plot.is_none()
    );
    let pulses = res.summary.pulses as usize;
    let n_plant = res.channels.plant.as_ref().unwrap().len();
    assert_eq!(n_plant, pulses.div_ceil(5));
    let n_sensors = res.channels.sensors.as_ref().unwrap().len();
    // sensor samples every 10 ms over 3 s (t = 0 … 2.99 s plus the final one) → 301, every 3rd
    assert!((100..=101).contains(&n_sensors), "{n_sensors}");

    let dir = std::env::temp_dir().join(format!("ivt-sim-mcap-{}", std::process::id()));
    let paths = ivt_sim::output::write_all(&dir, &s, &res).unwrap();
    assert_eq!(paths.len(), 1);
    let bytes = std::fs::read(&paths[0]).unwrap();
    let mut counts = std::collections::BTreeMap::new();
    for m in mcap::MessageStream::new(&bytes).unwrap() {
        let m = m.unwrap();
        let schema = m.channel.schema.as_ref().unwrap();
        assert_eq!(schema.encoding, "jsonschema");
        assert_eq!(m.channel.message_encoding, "json");
        let v: serde_json::Value = serde_json::from_slice(&m.data).unwrap();
        assert!(v.get("t").is_some());
        if m.channel.topic == "/plant" {
            assert!(v.get("omega").and_then(|w| w.as_f64()).is_some());
        }
        *counts.entry(m.channel.topic.clone()).or_insert(0usize) += 1;
    }
    // CSV on request: one file per channel, a header and one row per sample
    let mut s_csv = s.clone();
    s_csv.outputs.mcap = false;
    s_csv.outputs.csv = true;
    let csv = ivt_sim::output::write_all(&dir, &s_csv, &res).unwrap();
    assert_eq!(csv.len(), 2);
    let plant_csv = std::fs::read_to_string(&csv[0]).unwrap();
    let mut lines = plant_csv.lines();
    assert_eq!(lines.next().unwrap(), "t,theta,omega,omega_a,r,v_m,t_u,i_a");
    assert_eq!(lines.count(), n_plant);
    let expected: std::collections::BTreeMap<String, usize> = [
        ("/plant".to_string(), n_plant),
        ("/sensors".to_string(), n_sensors),
    ]
    .into();
    assert_eq!(counts, expected);

    // Streamed while the loop runs (what `ivt sim` does): the same messages,
    // byte for byte and in each channel's order, only interleaved in time.
    let streamed_dir = dir.join("streamed");
    let (res2, paths2) = ivt_sim::output::run_and_write(&streamed_dir, &s, |sink| {
        Simulation::new(&s).sink(sink).answer_by_time_integration()
    })
    .unwrap();
    assert_eq!(res2.run.unwrap().summary.pulses, res.summary.pulses);
    assert_eq!(paths2.len(), 1);
    let by_topic = |bytes: &[u8]| {
        let mut m: std::collections::BTreeMap<String, Vec<(u32, u64, Vec<u8>)>> =
            Default::default();
        let (mut last_time, mut in_time_order) = (0, true);
        for msg in mcap::MessageStream::new(bytes).unwrap() {
            let msg = msg.unwrap();
            m.entry(msg.channel.topic.clone()).or_default().push((
                msg.sequence,
                msg.log_time,
                msg.data.to_vec(),
            ));
            in_time_order &= msg.log_time >= last_time;
            last_time = msg.log_time;
        }
        (m, in_time_order)
    };
    let (serial, _) = by_topic(&bytes);
    let (streamed, in_time_order) = by_topic(&std::fs::read(&paths2[0]).unwrap());
    assert_eq!(streamed, serial);
    assert!(in_time_order);
    for msgs in streamed.values() {
        assert!(msgs.iter().enumerate().all(|(k, m)| m.0 == k as u32));
    }
    let _ = std::fs::remove_dir_all(&dir);
}

/// A run that fails while its MCAP log is being streamed leaves no log.
#[test]
fn failed_streamed_run_leaves_no_log() {
    let mut s = scene("load_step_delay");
    s.duration_s = 1.0;
    s.outputs.plots.clear();
    let dir = std::env::temp_dir().join(format!("ivt-sim-mcap-fail-{}", std::process::id()));
    let err = ivt_sim::output::run_and_write(&dir, &s, |sink| {
        let r = Simulation::new(&s).sink(sink).run()?;
        assert!(r.summary.pulses > 0);
        Err(ivt_sim::SimError::Scene("stopped on purpose".into()))
    })
    .unwrap_err();
    assert!(err.to_string().contains("stopped on purpose"), "{err}");
    assert!(!dir.join(format!("{}.mcap", s.name)).exists());
    let _ = std::fs::remove_dir_all(&dir);
}

/// The open-loop schedule (law "none") follows r(t) exactly and needs no
/// controller; a run that asks for nothing records nothing.
#[test]
fn scheduled_r_without_controller() {
    let src = r#"
name = "sched"
duration_s = 4.0
[inputs]
v_m = [[0.0, 8.6]]
t_u = [[0.0, 6.0]]
[initial]
omega = 10.0
[controller]
law = "none"
r_schedule = [[0.0, 0.004], [2.0, 0.004], [3.0, 0.008]]
"#;
    let s = Scene::parse(src, "sched").unwrap();
    let res = go(&s);
    assert!(res.channels.plant.is_none() && res.channels.plot.is_none());
    let mut s2 = s.clone();
    keep_all(&mut s2);
    s2.outputs.channels.truncate(1);
    let res = go(&s2);
    for p in res.channels.plant.as_ref().unwrap() {
        let want = if p.t <= 2.0 {
            0.004
        } else {
            (0.004 + 0.004 * (p.t - 2.0)).min(0.008)
        };
        assert!((p.r - want).abs() < 1e-5, "t={} r={} want {want}", p.t, p.r);
    }
}

/// Every shipped scene parses, and the default drive cycle stays inside the
/// band: r never saturates and ω_a ends within 0.1 % of ω0.
#[test]
fn shipped_scenes_parse_and_drive_cycle_stays_in_band() {
    let dir = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../scenes");
    let mut n = 0;
    for e in std::fs::read_dir(&dir).unwrap() {
        let p = e.unwrap().path();
        if p.extension().is_some_and(|x| x == "toml") {
            Scene::load(&p).unwrap();
            n += 1;
        }
    }
    assert!(n >= 7, "{n} scenes");
    let mut s = scene("drive");
    s.outputs.channels.clear();
    s.outputs.plots.clear();
    let res = go(&s);
    assert_eq!(res.summary.saturated_fraction, 0.0);
    let rel = (res.summary.final_omega_a_rad_s / res.summary.omega0_rad_s - 1.0).abs();
    assert!(rel < 1e-3, "{rel}");
}

/// Sensor noise and quantization, encoder jitter and 1 % missed steps: the
/// delay law still holds ω_a at ω0 on average (the integral absorbs the lost
/// steps), the lost steps are counted, and a run is reproducible from its seed.
#[test]
fn noisy_sensors_jitter_and_missed_steps() {
    let mut s = scene("load_step_delay");
    s.encoder.jitter_s = 2e-6;
    s.sensors.v_m_noise = 0.02;
    s.sensors.v_m_quantum = 0.01;
    s.sensors.t_u_noise = 0.05;
    s.stepper.miss_prob = 0.01;
    s.seed = 42;
    let a = go(&s);
    let b = go(&s);
    assert_eq!(a.summary.static_error_rad_s, b.summary.static_error_rad_s);
    assert!(a.summary.missed_steps > 10, "{}", a.summary.missed_steps);
    // jitter of 2 µs on a ≈ 0.6 s revolution: ω_a noise ≈ 5e-5 rad/s per sample
    assert!(
        a.summary.static_error_rad_s.abs() < 1e-3,
        "{}",
        a.summary.static_error_rad_s
    );
    assert_eq!(a.summary.fault_pulses, 0);
}

/// A stiff inductance is refused with a one-line error naming `plant.l_a`.
#[test]
fn tiny_inductance_is_refused() {
    let src =
        "duration_s = 1.0\n[plant]\nl_a = 1e-9\n[inputs]\nv_m = [[0.0, 8.0]]\nt_u = [[0.0, 4.0]]\n";
    let e = Scene::parse(src, "s.toml").unwrap_err().message;
    assert!(e.contains("plant.l_a") && e.contains("s.toml:3"), "{e}");
}
