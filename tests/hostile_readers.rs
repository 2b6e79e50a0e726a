//! Issue 43, part A: every reader bounded by construction. Each hostile
//! input runs through the `ivt` binary under `ulimit -v` and a time limit
//! and must end in exit 2 with exactly one `{"error", "kind"}` object: the
//! commissioning recordings that aborted, panicked or allocated gigabytes
//! (records and chunks claiming 2³⁶, 2⁶⁴ − 9 or 2³¹ bytes, a zstd bomb, a
//! `/pulses` array of tens of millions of zeros, strings claiming more than
//! their record), and a FIFO, a device or a directory wherever a file is
//! read (they blocked, or were read up to the budget). Plant files hold the
//! `[plant]` table alone.
// A test may index and unwrap (the package's panic lints guard library code).
#![allow(
    clippy::expect_used,
    clippy::indexing_slicing,
    clippy::panic,
    clippy::unwrap_used
)]

#[path = "common/mcap_forge.rs"]
mod forge;

use std::path::Path;
use std::process::Command;

#[path = "common/limited.rs"]
mod limited;

/// One hostile input's memory bound: 1 GiB of address space (the issue's
/// 100 MB recording reached 2 GB; the budgets of the reader keep it near
/// 100 MB). The time bound is `limited::TIME_LIMIT`, 20 s.
const MEMORY_LIMIT_KB: u64 = 1024 * 1024;

fn refused(args: &[&str], kind: &str) -> String {
    limited::refused(args, kind, MEMORY_LIMIT_KB)
}

fn scratch(name: &str) -> ivt_sim::testing::Scratch {
    ivt_sim::testing::scratch_dir(&format!("hostile-readers-{name}"))
}

fn write(dir: &Path, name: &str, bytes: &[u8]) -> String {
    let p = dir.join(name);
    std::fs::write(&p, bytes).unwrap();
    p.to_str().unwrap().to_string()
}

/// A record inside a zstd chunk claiming 2³⁶ bytes aborted `rig identify`
/// on a failed allocation (exit 134), 2⁶⁴ − 9 panicked in the mcap reader
/// (exit 101), 2³¹ allocated 2 GB before its clean error: every claim beyond
/// what the chunk holds is refused with the offset, the file 164 bytes.
#[test]
fn a_record_claiming_more_than_its_chunk_holds_is_refused() {
    let dir = scratch("claims");
    for claim in [1u64 << 36, u64::MAX - 8, 1 << 31, 1 << 20, 11] {
        let inner = forge::record_claiming(0x05, claim, &[0u8; 10]);
        let bytes = forge::file(&[forge::zstd_chunk(&inner)]);
        let path = write(&dir, &format!("claim{claim}.mcap"), &bytes);
        let e = refused(&["rig", "identify", &path], "input");
        assert!(
            e.contains("byte offset") && e.contains(&format!("claims {claim} bytes")),
            "{claim}: {e}"
        );
    }
    // the issue's size: a file of about 164 bytes
    let inner = forge::record_claiming(0x05, 1 << 36, &[0u8; 10]);
    assert!(forge::file(&[forge::zstd_chunk(&inner)]).len() < 200);
    std::fs::remove_dir_all(&dir).unwrap();
}

/// The same claims on a record outside any chunk, and on a chunk's declared
/// uncompressed size (refused before anything is decompressed); a chunk
/// that decompresses past its declared size stops at that size.
#[test]
fn records_and_chunks_beyond_their_budgets_are_refused_before_allocation() {
    let dir = scratch("budgets");
    for claim in [1u64 << 36, u64::MAX - 8, 1 << 31] {
        let mut bytes = forge::MAGIC.to_vec();
        bytes.extend(forge::record_claiming(0x05, claim, &[0u8; 64]));
        let path = write(&dir, &format!("top{claim}.mcap"), &bytes);
        let e = refused(&["rig", "identify", &path], "input");
        assert!(
            e.contains("byte offset 8") && e.contains(&claim.to_string()),
            "{claim}: {e}"
        );
    }
    let small = zstd::bulk::compress(&[0u8; 100], 3).unwrap();
    for declared in [1u64 << 40, u64::MAX, (64 << 20) + 1] {
        let bytes = forge::file(&[forge::chunk("zstd", declared, 0, &small)]);
        let path = write(&dir, "declared.mcap", &bytes);
        let e = refused(&["rig", "identify", &path], "input");
        assert!(
            e.contains(&format!("claims {declared} uncompressed bytes")),
            "{e}"
        );
    }
    // 1 MiB of records declared as 100 bytes
    let big = zstd::bulk::compress(&vec![0u8; 1 << 20], 3).unwrap();
    let bytes = forge::file(&[forge::chunk("zstd", 100, 0, &big)]);
    let e = refused(
        &["rig", "identify", &write(&dir, "under.mcap", &bytes)],
        "input",
    );
    assert!(e.contains("within its 100 bytes"), "{e}");
    // an unknown compression, a chunk inside a chunk
    let bytes = forge::file(&[forge::chunk("lz77", 10, 0, &[0; 10])]);
    let e = refused(
        &["rig", "identify", &write(&dir, "lz.mcap", &bytes)],
        "input",
    );
    assert!(e.contains("\"lz77\" is not supported"), "{e}");
    let inner = forge::chunk("", 0, 0, &[]);
    let bytes = forge::file(&[forge::zstd_chunk(&inner)]);
    let e = refused(
        &["rig", "identify", &write(&dir, "nested.mcap", &bytes)],
        "input",
    );
    assert!(e.contains("a chunk inside a chunk"), "{e}");
    std::fs::remove_dir_all(&dir).unwrap();
}

/// A zstd bomb: 240 chunks of 64 MiB of zeros each (15 GiB decompressed;
/// zeros are 9-byte records of opcode 0 and length 0, so each chunk is
/// valid) in a file of a few hundred kB decompressed to 15 GB. The declared
/// sizes add up past the 1 GiB budget at the 17th chunk: refused there,
/// within the time and memory limits.
#[test]
fn a_zstd_bomb_stops_at_the_decompressed_budget() {
    let dir = scratch("bomb");
    let zeros = vec![0u8; (64 << 20) / 9 * 9];
    let compressed = zstd::bulk::compress(&zeros, 19).unwrap();
    let crc = crc32fast::hash(&zeros);
    let one = forge::chunk("zstd", zeros.len() as u64, crc, &compressed);
    let bytes = forge::file(&vec![one; 240]);
    assert!(bytes.len() < 2 << 20, "{} bytes", bytes.len());
    let path = write(&dir, "bomb.mcap", &bytes);
    let e = refused(&["rig", "identify", &path], "input");
    assert!(
        e.contains("1140850620 in the chunks so far") && e.contains("1073741824"),
        "{e}"
    );
    std::fs::remove_dir_all(&dir).unwrap();
}

/// A `/pulses` message holding one array of zeros: a 100 MB one is longer
/// than a record may be; a 60 MB one (30 million edges) is parsed straight
/// into the edge array and stops at its budget of 4 million edges — no JSON
/// value tree (which took 2 GB).
#[test]
fn a_pulses_array_of_zeros_stays_within_its_budget() {
    let dir = scratch("pulses");
    let array = |n: usize| {
        let mut m = String::with_capacity(2 * n + 16);
        m.push_str("{\"t\":[0");
        for _ in 1..n {
            m.push_str(",0");
        }
        m.push_str("]}");
        m
    };
    let mut records = forge::ivt_channels();
    records.push(forge::ivt_metadata());
    records.push(forge::message(1, 0, array(50_000_000).as_bytes()));
    let path = write(&dir, "huge.mcap", &forge::file(&records));
    let e = refused(&["rig", "identify", &path], "input");
    assert!(
        e.contains("more than the 67108864 a record may have"),
        "{e}"
    );
    records.pop();
    records.push(forge::message(1, 0, array(30_000_000).as_bytes()));
    let path = write(&dir, "long.mcap", &forge::file(&records));
    let e = refused(&["rig", "identify", &path], "input");
    assert!(
        e.contains("more than the 4000000 encoder edges a recording may have"),
        "{e}"
    );
    std::fs::remove_dir_all(&dir).unwrap();
}

/// mcap's record parser reserves a string's claimed length before reading
/// it: a topic, a metadata name or a chunk's compression claiming 4 GiB in
/// a record of a few bytes is refused by the length check instead.
#[test]
fn strings_claiming_more_than_their_record_are_refused() {
    let dir = scratch("strings");
    let huge = u32::MAX.to_le_bytes();
    let mut channel = 1u16.to_le_bytes().to_vec();
    channel.extend_from_slice(&0u16.to_le_bytes());
    channel.extend_from_slice(&huge);
    let mut meta = huge.to_vec();
    meta.extend_from_slice(b"ivt");
    let mut chunk = vec![0u8; 28];
    chunk.extend_from_slice(&huge);
    for (name, record) in [
        ("topic", forge::record(0x04, &channel)),
        ("name", forge::record(0x0C, &meta)),
        ("compression", forge::record(0x06, &chunk)),
    ] {
        let path = write(&dir, &format!("{name}.mcap"), &forge::file(&[record]));
        let e = refused(&["rig", "identify", &path], "input");
        assert!(
            e.contains(&format!("{name} of 4294967295 bytes runs past the end")),
            "{name}: {e}"
        );
    }
    // a JSON message missing a field names it (the message was echoed whole)
    let mut records = forge::ivt_channels();
    records.push(forge::message(2, 7, b"{\"t\": 0.5, \"v_m\": 8.0}"));
    let path = write(&dir, "field.mcap", &forge::file(&records));
    let e = refused(&["rig", "identify", &path], "input");
    assert!(
        e.contains("message 7 on /sensors") && e.contains("missing field `t_u`"),
        "{e}"
    );
    // metadata `plant` can neither write TOML lines through a key nor a preset
    for plant in [
        r#"{"k_t = 0.1\n[controller]\nk": 1}"#,
        "printed\"\nk_t = 5\n#",
    ] {
        let mut records = forge::ivt_channels();
        records.push(forge::metadata("ivt", &[("ppr", "1200"), ("plant", plant)]));
        let path = write(&dir, "plant.mcap", &forge::file(&records));
        let e = refused(&["rig", "identify", &path], "input");
        assert!(
            e.contains("is not a plant parameter") || e.contains("not a preset"),
            "{plant:?}: {e}"
        );
    }
    std::fs::remove_dir_all(&dir).unwrap();
}

/// Every option and argument that reads a file, given `path`.
fn readers(path: &str, dir: &Path) -> Vec<Vec<String>> {
    let scene_with_plant = dir.join("plant-file-scene.toml");
    std::fs::write(
        &scene_with_plant,
        format!(
            "duration_s = 0.5\n[inputs]\nv_m = [[0.0, 8.0]]\nt_u = [[0.0, 4.0]]\n[plant]\nfile = {path:?}\n"
        ),
    )
    .unwrap();
    let out = dir.join("out").to_str().unwrap().to_string();
    let mcap = dir.join("x.mcap").to_str().unwrap().to_string();
    let point = ["--vm", "8", "--tu", "4"];
    let v = |a: &[&str]| a.iter().map(|s| s.to_string()).collect::<Vec<_>>();
    vec![
        v(&["rig", "identify", path]),
        v(&[&["ol", "solve", "--plant-file", path][..], &point].concat()),
        v(&["ol", "table", "--quiet", "--plant-file", path]),
        v(&["ol", "fit", "--quiet", "--plant-file", path]),
        v(&[&["stability", "--plant-file", path][..], &point].concat()),
        v(&["stability-map", "--plant-file", path]),
        v(&["sim", path, "--out", &out]),
        v(&["sim", scene_with_plant.to_str().unwrap(), "--out", &out]),
        v(&[
            "rig",
            "commission",
            "--sim",
            "--plant-file",
            path,
            "--out",
            &mcap,
        ]),
        v(&["ctrl", "replay", path]),
    ]
}

/// A FIFO without a writer blocked every reader forever (and Ctrl-C with
/// it); /dev/zero was read to the budget; a directory said "no such file".
/// Inputs are regular files: each is refused at once, kind `io`, saying what
/// it is.
#[test]
fn fifos_devices_and_directories_are_refused_by_every_reader() {
    let dir = scratch("fifo");
    let fifo = dir.join("pipe.toml");
    assert!(Command::new("mkfifo")
        .arg(&fifo)
        .status()
        .unwrap()
        .success());
    let subdir = dir.join("a-directory");
    std::fs::create_dir(&subdir).unwrap();
    for (path, what) in [
        (fifo.to_str().unwrap(), "a FIFO (named pipe)"),
        ("/dev/zero", "a character device"),
        (subdir.to_str().unwrap(), "a directory"),
    ] {
        for argv in readers(path, &dir) {
            let args: Vec<&str> = argv.iter().map(String::as_str).collect();
            let e = refused(&args, "io");
            assert!(e.contains(what) && e.contains(path), "{args:?}: {e}");
        }
    }
    assert!(!dir.join("out").exists() && !dir.join("x.mcap").exists());
    // a missing file is `io` too, naming it
    let missing = dir.join("missing.toml");
    for argv in readers(missing.to_str().unwrap(), &dir) {
        let args: Vec<&str> = argv.iter().map(String::as_str).collect();
        let e = refused(&args, "io");
        assert!(e.contains("missing.toml"), "{args:?}: {e}");
    }
    std::fs::remove_dir_all(&dir).unwrap();
}

/// A plant file is its `[plant]` table: a key above it or another table was
/// ignored (unknown keys inside it were refused); every value is checked
/// against the one range table. Each is `input`, naming the key.
#[test]
fn plant_files_hold_the_plant_table_alone_within_its_ranges() {
    let dir = scratch("plant");
    for (text, needle) in [
        ("k_t = 0.1\n[plant]\npreset = \"printed\"\n", "k_t"),
        (
            "[plant]\n[controller]\nk_prop_deg_per_rpm = 5.0\n",
            "controller",
        ),
        ("[plant]\nk_tt = 1.0\n", "k_tt"),
        (
            "[plant]\nk_t = 1e-300\n",
            "`plant.k_t` = 1e-300 N·m/A is outside",
        ),
        ("[plant]\nr_a = 1e300\n", "`plant.r_a` = 1e300 Ω is outside"),
        ("[plant]\nj_n1 = nan\n", "`plant.j_n1` = NaN"),
        ("", "plant"),
    ] {
        let path = write(&dir, "p.toml", text.as_bytes());
        for args in [
            &[
                "ol",
                "solve",
                "--vm",
                "8",
                "--tu",
                "4",
                "--plant-file",
                &path,
            ][..],
            &[
                "rig",
                "commission",
                "--sim",
                "--plant-file",
                &path,
                "--out",
                "x.mcap",
            ],
        ] {
            let e = refused(args, "input");
            assert!(e.contains("p.toml") && e.contains(needle), "{text:?}: {e}");
        }
    }
    std::fs::remove_dir_all(&dir).unwrap();
}
