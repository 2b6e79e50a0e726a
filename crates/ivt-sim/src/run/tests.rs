use super::*;

const SHORT: &str = r#"
duration_s = 3.0
[inputs]
v_m = [[0.0, 8.0]]
t_u = [[0.0, 4.0]]
[[outputs.channels]]
name = "plant"
"#;

/// With L_a = 0 the armature is quasi-static (Eq. 138): the logged i_a is
/// (V_m − k_e f(θ) ω)/R_a, checked against ivt-kin's f(θ) (Eq. 43), not 0.
#[test]
fn plant_channel_logs_the_algebraic_armature_current() {
    let scene = Scene::parse(SHORT, "s").unwrap();
    let p = scene.plant_params().unwrap();
    assert_eq!(p.l_a, 0.0);
    let res = Simulation::new(&scene).run().unwrap();
    let plant = res.channels.plant.unwrap();
    assert!(plant.len() > 1000);
    for s in &plant {
        let want = (s.v_m - p.k_e * ivt_kin::variant::f(s.theta) * s.omega) / p.r_a;
        assert!(
            (s.i_a - want).abs() <= 1e-12 * want.abs().max(1.0),
            "{s:?} vs {want}"
        );
    }
}

/// A metrics window after the end of the run: the ω_a metrics are NaN
/// (null in the summary JSON) and the summary says why, instead of 0.0.
#[test]
fn empty_metrics_window_gives_null_with_a_reason() {
    let src = format!("{SHORT}[metrics]\nfrom_s = 5.0\n");
    let scene = Scene::parse(&src, "s").unwrap();
    let s = Simulation::new(&scene).run().unwrap().summary;
    assert!(s.overshoot_pct.is_nan() && s.undershoot_pct.is_nan());
    assert!(s.rms_control_effort_m_per_rad.is_nan() && s.saturated_fraction.is_nan());
    assert_eq!(s.settling_time_s, None);
    let note = s.metrics_note.as_deref().unwrap();
    assert!(note.contains("metrics.from_s = 5"), "{note}");
    let j = serde_json::to_value(&s).unwrap();
    assert!(j["overshoot_pct"].is_null() && j["static_error_rad_s"].is_null());
    assert_eq!(j["law"], "delay");
    // with a window inside the run there is no note and the metrics exist
    let ok = Simulation::new(&Scene::parse(SHORT, "s").unwrap())
        .run()
        .unwrap()
        .summary;
    assert!(ok.metrics_note.is_none() && ok.overshoot_pct.is_finite());
    assert!(serde_json::to_value(&ok)
        .unwrap()
        .get("metrics_note")
        .is_none());
}

/// The builder's sink sees exactly the recorded samples, in order.
#[test]
fn sink_receives_every_recorded_sample() {
    let scene = Scene::parse(SHORT, "s").unwrap();
    let mut seen = Vec::new();
    let mut sink = |s: Sample| {
        if let Sample::Plant(p) = s {
            seen.push(p);
        }
    };
    let mut last = 0.0;
    let mut progress = |f: f64| {
        assert!(f >= last);
        last = f;
    };
    let res = Simulation::new(&scene)
        .sink(&mut sink)
        .progress(&mut progress)
        .run()
        .unwrap();
    assert_eq!(last, 1.0);
    let recorded = res.channels.plant.unwrap();
    assert!(recorded.len() > 1000);
    // Debug text: ω_a is NaN in the first revolution, and NaN != NaN
    assert_eq!(format!("{recorded:?}"), format!("{seen:?}"));
}
