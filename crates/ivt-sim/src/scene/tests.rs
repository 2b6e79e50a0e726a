use super::*;

const OK: &str = r#"
duration_s = 2.0
[inputs]
v_m = [[0.0, 8.0]]
t_u = [[0.0, 4.0]]
"#;

fn err(src: &str) -> String {
    let e = Scene::parse(src, "s.toml").unwrap_err().message;
    assert!(!e.contains('\n'), "multi-line error: {e}");
    e
}

#[test]
fn minimal_scene_parses_with_defaults() {
    let s = Scene::parse(OK, "s.toml").unwrap();
    assert_eq!(s.encoder.ppr, 1200);
    assert_eq!(s.controller.law, Law::Delay);
    assert_eq!(s.controller.open_loop, OpenLoopLaw::Refit);
    assert_eq!(s.integrator.method, IntegratorMethod::Dp5);
    assert_eq!(s.outputs.route, RouteRequest::Auto);
    assert_eq!(s.plant.preset, PresetName::Printed);
    assert!(!s.outputs.mcap && s.outputs.channels.is_empty());
}

/// Every default the scene-key table of the guide (docs/guide/src/controller/scenes.md) states, read back from a scene
/// that sets none of them.
#[test]
fn readme_scene_table_defaults() {
    let s = Scene::parse(OK, "s.toml").unwrap();
    assert_eq!((s.name.as_str(), s.seed), ("scene", 0));
    assert_eq!(s.plant.gravity, Gravity::Printed);
    assert_eq!(
        (s.initial.theta, s.initial.omega, s.initial.r),
        (0.0, 0.0, 0.0)
    );
    let i = &s.integrator;
    assert_eq!(
        (i.rtol, i.atol, i.dtheta, i.omega_handover),
        (1e-8, 1e-8, 0.02, 0.5)
    );
    assert_eq!((s.encoder.f_timer_hz, s.encoder.jitter_s), (1e6, 0.0));
    let n = &s.sensors;
    assert_eq!(n.period_s, 0.01);
    assert_eq!(
        (n.v_m_noise, n.v_m_quantum, n.t_u_noise, n.t_u_quantum),
        (0.0, 0.0, 0.0, 0.0)
    );
    let st = &s.stepper;
    assert_eq!(
        (st.steps_per_rev, st.max_speed, st.accel, st.miss_prob),
        (3200.0, 4000.0, 40_000.0, 0.0)
    );
    let c = &s.controller;
    assert_eq!(
        (c.omega0_rpm, c.k_mm_per_rad, c.k2_mm_per_rad),
        (100.0, 1.0, 2.0)
    );
    assert_eq!(
        (c.k_prop_deg_per_rpm, c.prop_period_s, c.feedforward),
        (50.0, 0.1, true)
    );
    assert_eq!(
        (s.metrics.from_s, s.metrics.band, s.metrics.static_window_s),
        (0.0, 0.02, 2.0)
    );
    let o = &s.outputs;
    assert!(!o.csv && !o.summary && !o.steady_state && o.plots.is_empty());
    assert_eq!(o.max_bytes, 1e9);
    let with_channel = format!("{OK}\n[[outputs.channels]]\nname = \"plant\"\n");
    let s = Scene::parse(&with_channel, "s.toml").unwrap();
    assert_eq!(s.outputs.channels.first().map(|c| c.every), Some(1));
}

#[test]
fn errors_are_one_line_and_name_the_problem() {
    let e = err(&format!("{OK}\n[encoder]\nbogus = 3\n"));
    assert!(e.contains("s.toml:8") && e.contains("bogus"), "{e}");
    let e = err(&OK.replace("duration_s = 2.0", "duration_s = \"long\""));
    assert!(e.contains("s.toml:2") && e.contains("duration"), "{e}");
    let e = err(&OK.replace("duration_s = 2.0", "duration_s = -1.0"));
    assert!(e.contains("s.toml:2") && e.contains("`duration_s`"), "{e}");
    let e = err(&OK.replace("[[0.0, 8.0]]", "[[0.0, 8.0], [2.0, 9.0], [1.0, 7.0]]"));
    assert!(e.contains("inputs.v_m") && e.contains("increase"), "{e}");
    let e = err(&OK.replace("[[0.0, 4.0]]", "[[0.0, -4.0]]"));
    assert!(e.contains("inputs.t_u") && e.contains("s.toml:5"), "{e}");
    let e = err(&format!("{OK}\n[encoder]\nppr = 7\n"));
    assert!(e.contains("encoder.ppr"), "{e}");
    let e = err(&format!("{OK}\n[plant]\nr_a = -0.2\n"));
    assert!(e.contains("plant.r_a"), "{e}");
    let e = err(&format!("{OK}\n[controller]\nlaw = \"pid\"\n"));
    assert!(e.contains("controller.law"), "{e}");
    let e = err(&format!("{OK}\n[controller]\nopen_loop = \"printed\"\n"));
    assert!(
        e.contains("s.toml:8") && e.contains("controller.open_loop") && e.contains("refit"),
        "{e}"
    );
    let e = err(&format!(
        "{OK}\n[[outputs.channels]]\nname = \"plant\"\n[[outputs.channels]]\nname = \"nope\"\n"
    ));
    assert!(e.contains("nope") && e.contains("s.toml:10"), "{e}");
    let e = err("duration_s = 1.0\n");
    assert!(e.contains("inputs"), "{e}");
    let e = err("duration_s = \n");
    assert!(e.contains("s.toml:1"), "{e}");
}

/// Positions come from toml's spans: the exact line and column of the
/// offending key or array element, also inside multi-line arrays and
/// repeated `[[outputs.channels]]` tables.
#[test]
fn positions_are_line_and_column_of_the_key() {
    let e = err(&format!(
        "{OK}\n[controller]\nomega0_rpm = 50\n  law = \"pid\"\n"
    ));
    assert!(e.starts_with("s.toml:9:9: `controller.law`"), "{e}");
    let e = err(&OK.replace(
        "t_u = [[0.0, 4.0]]",
        "t_u = [\n  [0.0, 4.0],\n  [0.5, -1.0],\n]",
    ));
    assert!(e.starts_with("s.toml:7:3: `inputs.t_u[1]`"), "{e}");
    let e = err(&format!(
        "{OK}\n[[outputs.channels]]\nname = \"plant\"\n[[outputs.channels]]\nname = \"plant\"\nevery = 0\n"
    ));
    assert!(
        e.starts_with("s.toml:11:1: `outputs.channels[1].every`"),
        "{e}"
    );
    let e = err(&format!(
        "{OK}\n[[outputs.channels]]\nname = \"plant\"\n[[outputs.channels]]\nname = \"plant\"\n"
    ));
    assert!(
        e.starts_with("s.toml:10:1: `outputs.channels[1].name`") && e.contains("twice"),
        "{e}"
    );
    // a key that is not in the file (a required combination) has no position
    let e = err(&format!("{OK}\n[controller]\nlaw = \"none\"\n"));
    assert!(e.starts_with("s.toml: `controller.r_schedule`"), "{e}");
}

#[test]
fn enums_accept_exactly_the_documented_names() {
    let with = |section: &str, kv: &str| format!("{OK}\n[{section}]\n{kv}\n");
    for (law, want) in [
        ("delay", Law::Delay),
        ("nodelay", Law::NoDelay),
        ("prop", Law::Prop),
        ("open", Law::Open),
    ] {
        let s = Scene::parse(&with("controller", &format!("law = \"{law}\"")), "s").unwrap();
        assert_eq!(s.controller.law, want);
        assert_eq!(want.name(), law);
    }
    let s = Scene::parse(&with("integrator", "method = \"rk4\""), "s").unwrap();
    assert_eq!(s.integrator.method, IntegratorMethod::Rk4);
    let s = Scene::parse(&with("plant", "preset = \"thesis-ch4\""), "s").unwrap();
    assert_eq!(
        s.plant_params().unwrap(),
        ivt_kin::plant::PlantParams::thesis_ch4()
    );
    let s = Scene::parse(&with("plant", "gravity = \"roller_mass\""), "s").unwrap();
    assert_eq!(s.plant.gravity, Gravity::RollerMass);
    let s = Scene::parse(&with("outputs", "route = \"time_integration\""), "s").unwrap();
    assert_eq!(s.outputs.route.forced(), Some(Route::TimeIntegration));
    let e = err(&with("integrator", "method = \"euler\""));
    assert!(e.contains("integrator.method") && e.contains("rk4"), "{e}");
    let e = err(&with("plant", "preset = \"thesis_ch4\""));
    assert!(
        e.contains("plant.preset") && e.contains("thesis-ch4"),
        "{e}"
    );
    let e = err(&with("outputs", "route = \"fast\""));
    assert!(e.contains("outputs.route") && e.contains("auto"), "{e}");
}

/// Scene limits: duration_s ≤ MAX_DURATION_S, and the recorded channels'
/// size estimate ≤ outputs.max_bytes. The estimate for one plant channel at
/// every pulse: 2 s · ω0 (100 rpm = 10.47 rad/s) · 1200/2π pulses = 4000
/// samples of 8 fields · 24 bytes, once in memory and once for CSV.
#[test]
fn duration_and_output_size_are_capped() {
    let e = err(&OK.replace("duration_s = 2.0", "duration_s = 1e7"));
    assert!(e.contains("`duration_s`") && e.contains("1e6"), "{e}");
    let logged = format!("{OK}\n[outputs]\ncsv = true\n[[outputs.channels]]\nname = \"plant\"\n");
    let s = Scene::parse(&logged, "s").unwrap();
    let pulses = 2.0 * s.omega0_rad_s() * 1200.0 / std::f64::consts::TAU;
    let fields = crate::record::Channel::Plant.fields().len() as f64;
    let want = pulses.ceil() * fields * 24.0 * 2.0;
    assert!((s.estimated_output_bytes() - want).abs() < 1e-9 * want);
    let capped = logged.replace("csv = true", "csv = true\nmax_bytes = 1e5");
    let e = err(&capped);
    assert!(
        e.contains("outputs.max_bytes") && e.contains("1.000e5"),
        "{e}"
    );
    let e = err(&OK.replace("duration_s = 2.0", "duration_s = 9e5").replace(
        "[inputs]",
        "[[outputs.channels]]\nname = \"plant\"\n[inputs]",
    ));
    assert!(e.contains("outputs.max_bytes"), "{e}");
}
