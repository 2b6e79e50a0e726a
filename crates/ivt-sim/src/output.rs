//! Writing what a scene asked for: an MCAP log (one JSON-schema channel per
//! signal group, zstd chunks, Foxglove-readable), CSV files, the summary JSON
//! and a PNG with one panel per requested plot.

use crate::run::{Channels, RunResult, Timed};
use crate::scene::Scene;
use serde::Serialize;
use std::collections::BTreeMap;
use std::fs::File;
use std::io::{BufWriter, Write};
use std::path::{Path, PathBuf};

/// An output failure.
#[derive(Debug, thiserror::Error)]
pub enum OutputError {
    /// File system.
    #[error("{path}: {source}")]
    Io {
        /// The file.
        path: PathBuf,
        /// The error.
        source: std::io::Error,
    },
    /// MCAP writer.
    #[error("{path}: MCAP: {msg}")]
    Mcap {
        /// The file.
        path: PathBuf,
        /// The error.
        msg: String,
    },
    /// Plot drawing.
    #[error("{path}: plot: {msg}")]
    Plot {
        /// The file.
        path: PathBuf,
        /// The error.
        msg: String,
    },
}

fn io(path: &Path) -> impl FnOnce(std::io::Error) -> OutputError + '_ {
    move |source| OutputError::Io {
        path: path.to_path_buf(),
        source,
    }
}

/// Field names and JSON-schema types of each channel, in column order.
pub fn channel_fields(name: &str) -> &'static [(&'static str, &'static str)] {
    match name {
        "plant" => &[
            ("t", "number"),
            ("theta", "number"),
            ("omega", "number"),
            ("omega_a", "number"),
            ("r", "number"),
            ("v_m", "number"),
            ("t_u", "number"),
            ("i_a", "number"),
        ],
        "control" => &[
            ("t", "number"),
            ("ticks", "integer"),
            ("omega", "number"),
            ("omega_a", "number"),
            ("omega_t", "number"),
            ("r_ol", "number"),
            ("r_d", "number"),
            ("r", "number"),
            ("stepper_target", "integer"),
            ("saturated", "boolean"),
            ("fault", "integer"),
        ],
        "stepper" => &[
            ("t", "number"),
            ("target", "integer"),
            ("commanded", "integer"),
            ("position", "integer"),
            ("missed", "integer"),
        ],
        "sensors" => &[("t", "number"), ("v_m", "number"), ("t_u", "number")],
        _ => &[],
    }
}

fn json_schema(name: &str) -> String {
    let props: serde_json::Map<String, serde_json::Value> = channel_fields(name)
        .iter()
        .map(|(f, ty)| ((*f).to_string(), serde_json::json!({ "type": ty })))
        .collect();
    serde_json::json!({
        "title": format!("ivt.{name}"),
        "type": "object",
        "properties": props,
    })
    .to_string()
}

/// Non-finite numbers (ω_a before the first revolution) are written as
/// `null` in JSON and as empty cells in CSV.
/// (time, JSON bytes) of each sample of one channel.
type Messages = Vec<(f64, Vec<u8>)>;

fn samples_as_json<T: Serialize + Timed>(v: &[T]) -> Messages {
    v.iter()
        .map(|s| (s.time(), serde_json::to_vec(s).unwrap_or_default()))
        .collect()
}

fn channel_messages(ch: &Channels) -> Vec<(&'static str, Messages)> {
    let mut out = vec![];
    if let Some(v) = &ch.plant {
        out.push(("plant", samples_as_json(v)));
    }
    if let Some(v) = &ch.control {
        out.push(("control", samples_as_json(v)));
    }
    if let Some(v) = &ch.stepper {
        out.push(("stepper", samples_as_json(v)));
    }
    if let Some(v) = &ch.sensors {
        out.push(("sensors", samples_as_json(v)));
    }
    out
}

/// Write the MCAP log of the recorded channels to `path`.
///
/// # Errors
/// I/O or MCAP errors.
pub fn write_mcap(path: &Path, result: &RunResult, scene: &Scene) -> Result<(), OutputError> {
    let err = |e: mcap::McapError| OutputError::Mcap {
        path: path.to_path_buf(),
        msg: e.to_string(),
    };
    let file = File::create(path).map_err(io(path))?;
    let mut w = mcap::WriteOptions::new()
        .compression(Some(mcap::Compression::Zstd))
        // level 1: ~3× faster than the default 3 on these JSON logs, files ~10 % larger
        .compression_level(1)
        // no worker threads: chunks are small, and threads only add overhead
        .compression_threads(0)
        .profile("")
        .create(BufWriter::new(file))
        .map_err(err)?;
    let mut meta = BTreeMap::new();
    meta.insert("scene".to_string(), scene.name.clone());
    meta.insert("description".to_string(), scene.description.clone());
    for (name, msgs) in channel_messages(&result.channels) {
        let schema = w
            .add_schema(
                &format!("ivt.{name}"),
                "jsonschema",
                json_schema(name).as_bytes(),
            )
            .map_err(err)?;
        let id = w
            .add_channel(schema, &format!("/{name}"), "json", &meta)
            .map_err(err)?;
        for (seq, (t, data)) in msgs.iter().enumerate() {
            let ns = (t.max(0.0) * 1e9).round() as u64;
            let header = mcap::records::MessageHeader {
                channel_id: id,
                sequence: seq as u32,
                log_time: ns,
                publish_time: ns,
            };
            w.write_to_known_channel(&header, data).map_err(err)?;
        }
    }
    w.finish().map_err(err)?;
    Ok(())
}

/// Write one CSV per recorded channel; returns the paths.
///
/// # Errors
/// I/O errors.
pub fn write_csv(dir: &Path, stem: &str, ch: &Channels) -> Result<Vec<PathBuf>, OutputError> {
    let mut paths = vec![];
    for (name, msgs) in channel_messages(ch) {
        let path = dir.join(format!("{stem}_{name}.csv"));
        let mut f = BufWriter::new(File::create(&path).map_err(io(&path))?);
        let fields = channel_fields(name);
        let header: Vec<&str> = fields.iter().map(|(n, _)| *n).collect();
        writeln!(f, "{}", header.join(",")).map_err(io(&path))?;
        for (_, data) in msgs {
            let v: serde_json::Value = serde_json::from_slice(&data).unwrap_or_default();
            let row: Vec<String> = fields
                .iter()
                .map(|(n, _)| match v.get(*n) {
                    Some(serde_json::Value::Null) | None => String::new(),
                    Some(x) => x.to_string(),
                })
                .collect();
            writeln!(f, "{}", row.join(",")).map_err(io(&path))?;
        }
        f.flush().map_err(io(&path))?;
        paths.push(path);
    }
    Ok(paths)
}

/// Everything the scene asked for, under `dir`; returns the written paths.
///
/// # Errors
/// I/O, MCAP or plot errors.
pub fn write_all(
    dir: &Path,
    scene: &Scene,
    result: &RunResult,
) -> Result<Vec<PathBuf>, OutputError> {
    let o = &scene.outputs;
    if !(o.mcap || o.csv || o.summary || !o.plots.is_empty()) {
        return Ok(vec![]);
    }
    std::fs::create_dir_all(dir).map_err(io(dir))?;
    let mut paths = vec![];
    if o.mcap {
        let p = dir.join(format!("{}.mcap", scene.name));
        write_mcap(&p, result, scene)?;
        paths.push(p);
    }
    if o.csv {
        paths.extend(write_csv(dir, &scene.name, &result.channels)?);
    }
    if o.summary {
        let p = dir.join(format!("{}_summary.json", scene.name));
        let text = serde_json::to_string_pretty(&result.summary).unwrap_or_default();
        std::fs::write(&p, text + "\n").map_err(io(&p))?;
        paths.push(p);
    }
    if !o.plots.is_empty() {
        if let Some(series) = &result.channels.plot {
            let p = dir.join(format!("{}.png", scene.name));
            crate::plot::draw(
                &p,
                &scene.name,
                &o.plots,
                series,
                result.summary.omega0_rad_s,
            )?;
            paths.push(p);
        }
    }
    Ok(paths)
}
