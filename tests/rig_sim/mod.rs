//! A simulated rig for the commissioning tests: the stepper-angle sweep
//! (Fig. 47/50), a long hold (Fig. 48) and a series of steps in θ_CT, V_m
//! and T_U, run on the simulator (`ivt_sim`, law "none": r follows the
//! stepper schedule), written as the commissioning recording that `ivt rig
//! identify` reads (the channel contract of `src/cli/commissioning.rs`).
//!
//! Stand-in for `ivt rig commission --sim` until that lands; kept on the
//! same contract so that the reader is exercised as on a rig's file.

#![allow(dead_code)]

use ivt_sim::run::Simulation;
use ivt_sim::scene::Scene;
use ivt_sim::sensors::{Encoder, Rng};
use std::collections::BTreeMap;
use std::io::Cursor;

/// Stepper microsteps per revolution of θ_CT (the simulator's default).
pub const STEPS_PER_REV: f64 = 3200.0;
/// Encoder pulses per revolution of θ.
pub const PPR: usize = 1200;

/// What the simulated rig's sensors do.
#[derive(Clone, Copy, Debug)]
pub struct Sensors {
    /// Timer rate of the edge captures \[Hz\].
    pub f_timer_hz: f64,
    /// Edge jitter (std) \[s\].
    pub jitter_s: f64,
    /// V_m noise (std) and quantum \[V\].
    pub v_m: (f64, f64),
    /// T_U noise (std) and quantum \[N·m\].
    pub t_u: (f64, f64),
}

impl Sensors {
    /// No noise, no jitter, a 1 GHz timer (1 ns quantum).
    pub const IDEAL: Self = Self {
        f_timer_hz: 1e9,
        jitter_s: 0.0,
        v_m: (0.0, 0.0),
        t_u: (0.0, 0.0),
    };
    /// A rig-like set: 1 MHz timer, 1 µs edge jitter, 12-bit-like readings
    /// with noise (V_m ±0.02 V, T_U ±0.02 N·m; quanta 0.005 V, 0.005 N·m).
    pub const NOISY: Self = Self {
        f_timer_hz: 1e6,
        jitter_s: 1e-6,
        v_m: (0.02, 0.005),
        t_u: (0.02, 0.005),
    };
}

/// One stage: sequence name, θ_CT \[deg\], V_m \[V\], T_U \[N·m\], duration \[s\].
pub type StageSpec = (&'static str, f64, f64, f64, f64);

/// The commissioning sequence: the sweep θ_CT = 0…1100° in 100° steps at
/// V_m = 10 V, T_U = 7.35 N·m (r ≤ r_max = 0.012 m ends the sweep at
/// 1113°, not the prototype's 3600°), a 4 s hold at 1100°, then six steps.
pub fn sequence() -> Vec<StageSpec> {
    let mut s: Vec<StageSpec> = (0..=11)
        .map(|k| ("sweep", 100.0 * f64::from(k), 10.0, 7.35, 2.0))
        .collect();
    s.push(("hold", 1100.0, 10.0, 7.35, 4.0));
    for (th, v, tu) in [
        (300.0, 8.0, 3.0),
        (1100.0, 12.0, 8.0),
        (700.0, 12.0, 3.0),
        (200.0, 8.0, 8.0),
        (900.0, 9.0, 5.0),
        (500.0, 11.0, 7.0),
    ] {
        s.push(("step", th, v, tu, 1.5));
    }
    s
}

/// Eq. 185 in SI: metres of crank per degree of θ_CT.
fn crank_m_per_deg() -> f64 {
    ivt_kin::units::inch_to_m(ivt_kin::sgivt::CRANK_PER_STEPPER_INCH_PER_DEG)
}

/// Metres of r per stepper microstep.
pub fn r_per_step() -> f64 {
    360.0 / STEPS_PER_REV * crank_m_per_deg()
}

/// Stepper position of θ_CT.
fn position(theta_ct_deg: f64) -> i64 {
    (theta_ct_deg * STEPS_PER_REV / 360.0).round() as i64
}

/// A simulated commissioning run: what a rig would record.
pub struct Run {
    /// The stages with their start times.
    pub stages: Vec<(StageSpec, f64)>,
    /// Edge times as captured (ticks over the timer rate) \[s\].
    pub times: Vec<f64>,
    /// Timer captures of the edges.
    pub ticks: Vec<u32>,
    /// Sensor readings (t, V_m, T_U).
    pub sensors: Vec<[f64; 3]>,
    /// Stepper position changes (t, position).
    pub stepper: Vec<(f64, i64)>,
    /// The timer rate \[Hz\].
    pub f_timer_hz: f64,
}

/// The run as `ivt_design::identify` arrays (what the MCAP reader returns).
pub fn recording(run: &Run) -> ivt_design::identify::Recording {
    ivt_design::identify::Recording {
        ppr: PPR,
        theta0: std::f64::consts::TAU / PPR as f64,
        pulse_t: run.times.clone(),
        sensors: run.sensors.clone(),
        eccentricity: run
            .stepper
            .iter()
            .map(|&(t, p)| (t, p as f64 * r_per_step()))
            .collect(),
        stages: run
            .stages
            .iter()
            .map(|&((name, th, ..), t)| ivt_design::identify::Stage {
                t,
                name: name.to_string(),
                theta_ct_deg: th,
            })
            .collect(),
    }
}

/// Run the sequence on the plant given by `plant_toml` (the body of a
/// `[plant]` table) and return the recording's MCAP bytes.
pub fn commission(plant_toml: &str, sensors: Sensors, seed: u64) -> Vec<u8> {
    mcap_bytes(&simulate(plant_toml, sensors, seed))
}

/// Run the sequence on the plant given by `plant_toml` (the body of a
/// `[plant]` table).
pub fn simulate(plant_toml: &str, sensors: Sensors, seed: u64) -> Run {
    let stages = sequence();
    let ramp = 0.1;
    let (mut v, mut tu, mut r) = (Vec::new(), Vec::new(), Vec::new());
    let mut t = 0.0;
    let mut starts = Vec::new();
    for (k, &(_, th, vm, load, dur)) in stages.iter().enumerate() {
        let rr = position(th) as f64 * r_per_step();
        let at = if k == 0 { 0.0 } else { t + ramp };
        for (prof, val) in [(&mut v, vm), (&mut tu, load), (&mut r, rr)] {
            prof.push(format!("[{at}, {val}]"));
        }
        starts.push(t);
        t += dur;
        for (prof, val) in [(&mut v, vm), (&mut tu, load), (&mut r, rr)] {
            prof.push(format!("[{t}, {val}]"));
        }
    }
    let scene = format!(
        "name = \"commission\"\nduration_s = {t}\nseed = {seed}\n\
         [plant]\n{plant_toml}\n\
         [inputs]\nv_m = [{}]\nt_u = [{}]\n\
         [encoder]\nppr = {PPR}\nf_timer_hz = {}\njitter_s = {}\n\
         [sensors]\nperiod_s = 0.01\nv_m_noise = {}\nv_m_quantum = {}\nt_u_noise = {}\nt_u_quantum = {}\n\
         [controller]\nlaw = \"none\"\nr_schedule = [{}]\n\
         [outputs]\nchannels = [{{name = \"plant\"}}, {{name = \"sensors\"}}]\n",
        v.join(", "),
        tu.join(", "),
        sensors.f_timer_hz,
        sensors.jitter_s,
        sensors.v_m.0,
        sensors.v_m.1,
        sensors.t_u.0,
        sensors.t_u.1,
        r.join(", "),
    );
    let scene = Scene::parse(&scene, "commission.toml").expect("commissioning scene");
    let run = Simulation::new(&scene).run().expect("simulation");
    let plant = run.channels.plant.expect("plant channel");
    let sens = run.channels.sensors.expect("sensors channel");
    let enc = Encoder {
        ppr: PPR,
        f_timer_hz: sensors.f_timer_hz,
        jitter_s: sensors.jitter_s,
    };
    let mut rng = Rng::new(seed ^ 0x5eed);
    let ticks: Vec<u32> = plant.iter().map(|p| enc.capture(p.t, &mut rng)).collect();
    // The recorded edge times are the captures (as on a rig).
    let t0 = plant.first().map_or(0.0, |p| p.t);
    let mut times = Vec::with_capacity(ticks.len());
    let mut now = t0;
    for (k, w) in ticks.iter().enumerate() {
        if k > 0 {
            now += f64::from(w.wrapping_sub(ticks[k - 1])) / sensors.f_timer_hz;
        }
        times.push(now);
    }
    let mut stepper = Vec::new();
    for p in &plant {
        let pos = (p.r / r_per_step()).round() as i64;
        if stepper.last().is_none_or(|s: &(f64, i64)| s.1 != pos) {
            stepper.push((p.t, pos));
        }
    }
    Run {
        stages: stages.into_iter().zip(starts).collect(),
        times,
        ticks,
        sensors: sens.iter().map(|s| [s.t, s.v_m, s.t_u]).collect(),
        stepper,
        f_timer_hz: sensors.f_timer_hz,
    }
}

/// The run as a commissioning recording (MCAP bytes on the reader's contract).
pub fn mcap_bytes(run: &Run) -> Vec<u8> {
    let mut w = mcap::WriteOptions::new()
        .compression(Some(mcap::Compression::Zstd))
        .profile("")
        .create(Cursor::new(Vec::new()))
        .expect("mcap writer");
    let mut ch = BTreeMap::new();
    for topic in ["/pulses", "/sensors", "/stepper", "/sequence"] {
        let schema = w
            .add_schema(
                &format!("ivt{}", topic.replace('/', ".")),
                "jsonschema",
                b"{}",
            )
            .unwrap();
        ch.insert(
            topic,
            w.add_channel(schema, topic, "json", &BTreeMap::new())
                .unwrap(),
        );
    }
    let mut seq = 0u32;
    let mut put = |w: &mut mcap::Writer<_>, topic: &str, t: f64, msg: serde_json::Value| {
        let ns = (t.max(0.0) * 1e9) as u64;
        let header = mcap::records::MessageHeader {
            channel_id: ch[topic],
            sequence: seq,
            log_time: ns,
            publish_time: ns,
        };
        seq += 1;
        w.write_to_known_channel(&header, msg.to_string().as_bytes())
            .unwrap();
    };
    for (k, &((name, th, _, _, dur), ts)) in run.stages.iter().enumerate() {
        put(
            &mut w,
            "/sequence",
            ts,
            serde_json::json!({"t": ts, "name": name, "stage": k, "theta_ct_deg": th, "hold": dur}),
        );
    }
    for s in &run.sensors {
        put(
            &mut w,
            "/sensors",
            s[0],
            serde_json::json!({"t": s[0], "v_m": s[1], "t_u": s[2]}),
        );
    }
    for &(t, pos) in &run.stepper {
        put(
            &mut w,
            "/stepper",
            t,
            serde_json::json!({"t": t, "position": pos}),
        );
    }
    for (tb, kb) in run.times.chunks(256).zip(run.ticks.chunks(256)) {
        put(
            &mut w,
            "/pulses",
            tb[0],
            serde_json::json!({"t": tb, "ticks": kb}),
        );
    }
    let meta = [
        ("frame_version", "2".to_string()),
        ("ppr", PPR.to_string()),
        ("f_timer_hz", run.f_timer_hz.to_string()),
        ("plant", "printed".to_string()),
        ("steps_per_rev", STEPS_PER_REV.to_string()),
    ];
    w.write_metadata(&mcap::records::Metadata {
        name: "ivt".into(),
        metadata: meta
            .iter()
            .map(|(k, v)| (k.to_string(), v.clone()))
            .collect(),
    })
    .unwrap();
    w.finish().unwrap();
    w.into_inner().into_inner()
}
