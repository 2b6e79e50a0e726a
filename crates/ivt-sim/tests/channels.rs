//! The channel table of `ivt_sim::record` reaches every output: a scene that
//! names every channel and every plot panel (by the table's names) writes an
//! MCAP log with one `/name` topic per channel under the JSON schema
//! `ivt.name` whose properties are the channel's fields, one CSV per channel
//! whose header is the field list, and a PNG with a panel per plot. Adding a
//! channel to the table is checked here without editing this test.
// A test may expect (the package's panic lints guard library code).
#![allow(clippy::expect_used)]

use ivt_sim::output::{json_schema, write_all};
use ivt_sim::record::{Channel, Panel, PlantSample, Record};
use ivt_sim::run::Simulation;
use ivt_sim::scene::Scene;
use ivt_sim::testing::{listing, scratch_dir};
use std::collections::{BTreeMap, BTreeSet};

/// A 1.5 s scene from rest logging every channel of the table and drawing
/// every panel, written as TOML from the table's names.
fn every_output_scene() -> Scene {
    let mut src = String::from(
        "name = \"all\"\nduration_s = 1.5\n[inputs]\nv_m = [[0.0, 8.2]]\nt_u = [[0.0, 4.0]]\n\
         [initial]\nomega = 10.0\n[outputs]\nmcap = true\ncsv = true\nsummary = true\n",
    );
    let plots: Vec<String> = Panel::ALL
        .iter()
        .map(|p| format!("\"{}\"", p.name()))
        .collect();
    src.push_str(&format!("plots = [{}]\n", plots.join(", ")));
    for c in Channel::ALL {
        src.push_str(&format!("[[outputs.channels]]\nname = \"{}\"\n", c.name()));
    }
    Scene::parse(&src, "all.toml").expect("the table's names are a valid scene")
}

#[test]
fn every_channel_reaches_every_output() {
    let scene = every_output_scene();
    let res = Simulation::new(&scene).run().unwrap();
    let dir = scratch_dir("channels-every-output");
    let paths = write_all(&dir, &scene, &res).unwrap();

    // names: unique, found by name, as the scene named them
    let names: BTreeSet<&str> = Channel::ALL.iter().map(|c| c.name()).collect();
    assert_eq!(names.len(), Channel::ALL.len());
    for &c in Channel::ALL {
        assert_eq!(Channel::from_name(c.name()), Some(c));
        assert_eq!(scene.outputs.every(c), Some(1), "{c:?}");
        let fields = c.fields();
        assert_eq!(fields.first().map(|f| (f.name, f.unit)), Some(("t", "s")));
        for f in fields {
            assert!(
                f.json_type != "number" || !f.unit.is_empty(),
                "{}.{} has no unit",
                c.name(),
                f.name
            );
        }
    }
    assert_eq!(Channel::from_name("nope"), None);

    // MCAP: one topic per channel, schema ivt.<name> with the fields, messages
    // carrying exactly those keys
    let bytes = std::fs::read(dir.join("all.mcap")).unwrap();
    let mut topics: BTreeMap<String, usize> = BTreeMap::new();
    for m in mcap::MessageStream::new(&bytes).unwrap() {
        let m = m.unwrap();
        let name = m.channel.topic.trim_start_matches('/');
        let c = Channel::from_name(name).unwrap_or_else(|| panic!("unknown topic {name}"));
        let schema = m.channel.schema.as_ref().unwrap();
        assert_eq!(schema.name, format!("ivt.{name}"));
        assert_eq!(schema.data.as_ref(), json_schema(c).as_bytes());
        let s: serde_json::Value = serde_json::from_slice(&schema.data).unwrap();
        let props: BTreeSet<&str> = s["properties"]
            .as_object()
            .unwrap()
            .keys()
            .map(String::as_str)
            .collect();
        let fields: BTreeSet<&str> = c.fields().iter().map(|f| f.name).collect();
        assert_eq!(props, fields, "{name}");
        for f in c.fields() {
            assert_eq!(
                s["properties"][f.name]["type"], f.json_type,
                "{name}.{}",
                f.name
            );
        }
        let v: serde_json::Value = serde_json::from_slice(&m.data).unwrap();
        let keys: BTreeSet<&str> = v.as_object().unwrap().keys().map(String::as_str).collect();
        assert_eq!(keys, fields, "{name}");
        *topics.entry(name.to_string()).or_default() += 1;
    }
    assert_eq!(
        topics.keys().map(String::as_str).collect::<BTreeSet<_>>(),
        names,
        "every channel is a topic"
    );

    // CSV: one file per channel, header = field names, one row per sample
    for &c in Channel::ALL {
        let text = std::fs::read_to_string(dir.join(format!("all_{}.csv", c.name()))).unwrap();
        let mut lines = text.lines();
        let header: Vec<&str> = c.fields().iter().map(|f| f.name).collect();
        assert_eq!(lines.next(), Some(header.join(",").as_str()), "{c:?}");
        assert_eq!(lines.count(), topics[c.name()], "{c:?}");
    }
    // the PNG and the summary; nothing else, no temporary file
    let mut expected: Vec<String> = Channel::ALL
        .iter()
        .map(|c| format!("all_{}.csv", c.name()))
        .collect();
    expected.extend(["all.mcap", "all.png", "all_summary.json"].map(String::from));
    expected.sort();
    assert_eq!(listing(&dir), expected);
    assert_eq!(paths.len(), expected.len());
    std::fs::remove_dir_all(&dir).unwrap();
}

/// Every plot panel is a `plant` field, read from the sample by that name.
#[test]
fn every_panel_is_a_plant_field_read_by_name() {
    let s = PlantSample {
        t: 0.5,
        theta: 1.0,
        omega: 2.0,
        omega_a: 3.0,
        r: 4.0,
        v_m: 5.0,
        t_u: 6.0,
        i_a: 7.0,
    };
    let mut json = vec![];
    s.write_json(&mut json);
    let v: serde_json::Value = serde_json::from_slice(&json).unwrap();
    let mut seen = BTreeSet::new();
    for p in Panel::ALL {
        assert!(
            Channel::Plant.fields().iter().any(|f| f.name == p.name()),
            "{p:?}"
        );
        assert_eq!(v[p.name()].as_f64(), Some(p.of(&s)), "{p:?}");
        assert_eq!(Panel::from_name(p.name()), Some(p));
        assert!(seen.insert(p.name()));
        let (label, scale) = p.label();
        assert!(!label.is_empty() && scale > 0.0);
    }
    assert_eq!(Panel::from_name("theta_dot"), None);
}

/// A scene naming an unknown channel or panel is refused with the table's
/// names in the message.
#[test]
fn unknown_names_are_refused_with_the_table() {
    let base = "duration_s = 1.0\n[inputs]\nv_m = [[0.0, 8.0]]\nt_u = [[0.0, 4.0]]\n";
    let e = Scene::parse(
        &format!("{base}[[outputs.channels]]\nname = \"plnat\"\n"),
        "s.toml",
    )
    .unwrap_err()
    .message;
    assert!(e.contains("plnat") && e.contains("outputs.channels"), "{e}");
    for c in Channel::ALL {
        assert!(e.contains(c.name()), "{e}");
    }
    let e = Scene::parse(&format!("{base}[outputs]\nplots = [\"w\"]\n"), "s.toml")
        .unwrap_err()
        .message;
    assert!(e.contains("\"w\"") && e.contains("outputs.plots"), "{e}");
}
