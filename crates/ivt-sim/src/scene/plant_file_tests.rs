//! Plant files: round trip, merge into scenes, errors with positions.

use super::*;
use crate::scene::Scene;
use crate::testing::scratch::Scratch;

/// A scratch directory unique to this test process and `name`.
fn scratch(name: &str) -> Scratch {
    Scratch::new(&format!("plant-file-{name}"))
}

/// Every parameter changed from the preset survives `from_params` →
/// `to_toml` → `parse_file` → `params` bit for bit; unchanged ones are not
/// written.
#[test]
fn plant_file_round_trips_bit_for_bit() {
    let mut p = PlantParams::thesis_ch4();
    p.k_t = 0.0812345678901234;
    p.r_u = 0.0381;
    p.j_ring *= 1.0 / 3.0;
    let s = PlantSection::from_params(PresetName::ThesisCh4, &p);
    let text = s.to_toml();
    assert_eq!(text.lines().count(), 6, "{text}"); // header, preset, gravity + 3 overrides
    let back = PlantSection::parse_file(&text, "p.toml").unwrap();
    assert_eq!(back.params().unwrap(), p);
    assert_eq!(back, s);
}

/// `[plant] file` in a scene: the file's preset and overrides, then the
/// scene's own overrides on top; the path is relative to the scene.
#[test]
fn scene_plant_file_merges_under_the_scenes_overrides() {
    let dir = scratch("merge");
    std::fs::write(
        dir.join("rig.toml"),
        "[plant]\npreset = \"thesis-ch4\"\nk_t = 0.08\nr_a = 0.3\n",
    )
    .unwrap();
    let scene = "duration_s = 1.0\n[inputs]\nv_m = [[0.0, 8.0]]\nt_u = [[0.0, 4.0]]\n\
                 [plant]\nfile = \"rig.toml\"\nr_a = 0.25\n";
    let path = dir.join("s.toml");
    std::fs::write(&path, scene).unwrap();
    let s = Scene::load(&path).unwrap();
    let p = s.plant_params().unwrap();
    let mut want = PlantParams::thesis_ch4();
    want.k_t = 0.08;
    want.r_a = 0.25;
    assert_eq!(p, want);
}

/// Errors name the file, line and column: a bad value inside the plant file,
/// a preset beside `file`, a chain of plant files, a missing file.
#[test]
fn plant_file_errors_name_file_line_and_key() {
    let dir = scratch("errors");
    let bad = dir.join("bad.toml");
    std::fs::write(&bad, "[plant]\npreset = \"printed\"\nk_t = -1.0\n").unwrap();
    let e = PlantSection::from_file(&bad).unwrap_err().message;
    assert!(e.contains("bad.toml:3:1: `plant.k_t`"), "{e}");
    std::fs::write(&bad, "[plant]\nk_tt = 1.0\n").unwrap();
    let e = PlantSection::from_file(&bad).unwrap_err().message;
    assert!(e.contains("bad.toml:2:1") && e.contains("k_tt"), "{e}");
    std::fs::write(&bad, "[plant]\nfile = \"other.toml\"\n").unwrap();
    let e = PlantSection::from_file(&bad).unwrap_err().message;
    assert!(e.contains("`plant.file`") && e.contains("chains"), "{e}");
    let e = PlantSection::from_file(&dir.join("missing.toml"))
        .unwrap_err()
        .message;
    assert!(e.contains("missing.toml"), "{e}");
    let head = "duration_s = 1.0\n[inputs]\nv_m = [[0.0, 8.0]]\nt_u = [[0.0, 4.0]]\n";
    let e = Scene::parse_in(
        &format!("{head}[plant]\nfile = \"x.toml\"\npreset = \"printed\"\n"),
        "s.toml",
        &dir,
    )
    .unwrap_err()
    .message;
    assert!(e.starts_with("s.toml:7:1: `plant.preset`"), "{e}");
    std::fs::write(dir.join("neg.toml"), "[plant]\nr_a = 0.0\n").unwrap();
    let e = Scene::parse_in(
        &format!("{head}[plant]\nfile = \"neg.toml\"\n"),
        "s.toml",
        &dir,
    )
    .unwrap_err()
    .message;
    assert!(
        e.starts_with("s.toml:6:1: `plant.file`") && e.contains("neg.toml:2:1: `plant.r_a`"),
        "{e}"
    );
}

/// Nothing outside `[plant]`: a key above the table and another table are
/// refused by name, as an unknown key inside it is (they were ignored).
#[test]
fn a_plant_file_holds_the_plant_table_alone() {
    for (text, name) in [
        ("k_t = 0.1\n[plant]\npreset = \"printed\"\n", "k_t"),
        (
            "[plant]\npreset = \"printed\"\n[controller]\nk_prop_deg_per_rpm = 5.0\n",
            "controller",
        ),
        ("[plant]\n[plant.extra]\nx = 1\n", "extra"),
    ] {
        let e = PlantSection::parse_file(text, "p.toml").unwrap_err();
        assert!(!e.unreadable, "{e}");
        assert!(
            e.message.starts_with("p.toml:") && e.message.contains(name),
            "{text:?}: {e}"
        );
    }
    // a missing file is unreadable (the CLI's kind `io`), a bad value is not
    let dir = scratch("kinds");
    let e = PlantSection::from_file(&dir.join("missing.toml")).unwrap_err();
    assert!(e.unreadable, "{e}");
    let e = PlantSection::from_file(&dir).unwrap_err();
    assert!(e.unreadable && e.message.contains("a directory"), "{e}");
}
