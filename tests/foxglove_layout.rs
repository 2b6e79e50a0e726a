//! The shipped Foxglove layout (crates/ivt-py/python/ivt/foxglove/ivt-layout.json,
//! in the wheel as `ivt.foxglove_layout()`) against real files: every message
//! path of every panel names a channel of the MCAP, a field of that channel's
//! JSON schema, and messages that carry a value there (a number for a plot, any
//! value for the fault state panel), so that every panel shows data. Checked on
//! the default drive scene's `out/drive.mcap` and on a simulated rig's
//! commissioning recording (`ivt rig commission --sim`), which has the rig's
//! channels.
// A test may expect, index and panic (the package's panic lints guard library code).
#![allow(clippy::expect_used, clippy::indexing_slicing, clippy::panic)]

use std::collections::BTreeMap;
use std::path::Path;
use std::process::Command;

/// The layout file, parsed.
fn layout() -> serde_json::Value {
    let path = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("crates/ivt-py/python/ivt/foxglove/ivt-layout.json");
    serde_json::from_slice(&std::fs::read(path).expect("read the layout")).expect("layout JSON")
}

/// `(panel kind, message path)` of every path of every panel.
fn panel_paths(layout: &serde_json::Value) -> Vec<(String, String)> {
    let panels = layout["configById"].as_object().expect("configById");
    let mut out = Vec::new();
    for (id, config) in panels {
        let kind = id.split('!').next().expect("panel id is KIND!NAME");
        for p in config["paths"].as_array().expect("a panel's paths") {
            out.push((
                kind.to_owned(),
                p["value"].as_str().expect("path").to_owned(),
            ));
        }
    }
    out
}

/// One channel of an MCAP file: its JSON schema's field names and its messages.
#[derive(Default)]
struct ChannelData {
    fields: Vec<String>,
    messages: Vec<serde_json::Value>,
}

fn read_mcap(path: &Path) -> BTreeMap<String, ChannelData> {
    let data = std::fs::read(path).expect("read the MCAP");
    let mut out: BTreeMap<String, ChannelData> = BTreeMap::new();
    for m in mcap::MessageStream::new(&data).expect("MCAP") {
        let m = m.expect("an MCAP message");
        let ch = out.entry(m.channel.topic.clone()).or_default();
        if ch.fields.is_empty() {
            let schema = m.channel.schema.as_ref().expect("a schema");
            assert_eq!(schema.encoding, "jsonschema");
            let schema: serde_json::Value = serde_json::from_slice(&schema.data).expect("schema");
            ch.fields = schema["properties"]
                .as_object()
                .expect("schema properties")
                .keys()
                .cloned()
                .collect();
        }
        ch.messages
            .push(serde_json::from_slice(&m.data).expect("JSON message"));
    }
    out
}

/// A fresh scratch directory.
fn scratch(name: &str) -> ivt_sim::testing::Scratch {
    ivt_sim::testing::scratch_dir(&format!("foxglove-{name}"))
}

fn run_ivt(dir: &Path, args: &[&str]) {
    let out = Command::new(env!("CARGO_BIN_EXE_ivt"))
        .current_dir(dir)
        .args(args)
        .output()
        .expect("run ivt");
    assert!(out.status.success(), "ivt {args:?}: {out:?}");
}

/// Every panel path of the layout resolves in `mcap` and has data.
fn check_layout_against(mcap: &Path) {
    let channels = read_mcap(mcap);
    let paths = panel_paths(&layout());
    for (kind, path) in &paths {
        let (topic, field) = path.split_once('.').expect("message path /topic.field");
        let ch = channels
            .get(topic)
            .unwrap_or_else(|| panic!("{path}: no channel {topic} in {}", mcap.display()));
        assert!(
            ch.fields.iter().any(|f| f == field),
            "{path}: {topic}'s schema has no field {field} ({:?})",
            ch.fields
        );
        let with_value = ch
            .messages
            .iter()
            .filter(|m| match kind.as_str() {
                "Plot" => m[field].as_f64().is_some_and(f64::is_finite),
                _ => !m[field].is_null(),
            })
            .count();
        assert!(
            with_value >= 10,
            "{path} ({kind}): {with_value} messages with a value in {}",
            mcap.display()
        );
    }
}

#[test]
fn layout_has_the_panels_of_the_issue() {
    let paths: Vec<String> = panel_paths(&layout()).into_iter().map(|(_, p)| p).collect();
    for wanted in [
        "/control.omega",
        "/control.omega_a",
        "/control.r",
        "/sensors.v_m",
        "/sensors.t_u",
        "/control.fault",
        "/stepper.position",
    ] {
        assert!(
            paths.iter().any(|p| p == wanted),
            "{wanted} not in {paths:?}"
        );
    }
    // Every configured panel is placed in the layout tree.
    let l = layout();
    let text = l["layout"].to_string();
    for id in l["configById"].as_object().expect("configById").keys() {
        assert!(text.contains(&format!("\"{id}\"")), "panel {id} not placed");
    }
}

#[test]
fn layout_opens_the_default_drive_scene() {
    let dir = scratch("drive");
    run_ivt(&dir, &[]);
    check_layout_against(&dir.join("out/drive.mcap"));
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn layout_opens_a_commissioning_recording() {
    let dir = scratch("commission");
    run_ivt(
        &dir,
        &[
            "rig",
            "commission",
            "--sim",
            "--out",
            "run.mcap",
            "--sequence",
            "hold",
        ],
    );
    check_layout_against(&dir.join("run.mcap"));
    let _ = std::fs::remove_dir_all(&dir);
}
