//! Writing what a scene asked for: an MCAP log (one JSON-schema channel per
//! signal group, zstd chunks, Foxglove-readable), CSV files, the summary JSON
//! and a PNG with one panel per requested plot.
//!
//! [`write_all`] writes them from a finished run; [`run_and_write`] (what
//! `ivt sim` uses) writes the MCAP log on a second thread while the loop
//! runs — on two cores it costs little more than the loop alone.
//!
//! Every file is written under a temporary name and the set is renamed into
//! place only when all of it is complete ([`crate::atomic::Staged`]): a failed
//! run, a failed plot or an interrupted run leaves the directory as it was.

use crate::atomic::Staged;
use crate::error::{io_at as io, mcap_at as mcap_error, SimError};
use crate::record::{Record, Sample, CHANNELS};
use crate::run::{Channels, RunResult};
use crate::scene::Scene;
use std::collections::BTreeMap;
use std::fs::File;
use std::io::BufWriter;
use std::path::{Path, PathBuf};

pub use crate::record::channel_fields;

/// The JSON schema of a channel (`ivt.<name>`), as written into MCAP logs.
pub fn json_schema(name: &str) -> String {
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

/// Adds the channel `/name` with the JSON schema `ivt.name` to an MCAP log.
pub(crate) fn add_json_channel<W: std::io::Write + std::io::Seek>(
    w: &mut mcap::Writer<W>,
    name: &str,
    meta: &BTreeMap<String, String>,
) -> Result<u16, mcap::McapError> {
    let schema = w.add_schema(
        &format!("ivt.{name}"),
        "jsonschema",
        json_schema(name).as_bytes(),
    )?;
    w.add_channel(schema, &format!("/{name}"), "json", meta)
}

/// An MCAP log being written: one JSON-schema channel per recorded signal
/// group, zstd chunks.
struct McapLog {
    path: PathBuf,
    w: mcap::Writer<BufWriter<File>>,
    /// MCAP channel id and next sequence number per entry of [`CHANNELS`].
    channels: [Option<(u16, u32)>; 4],
    /// The JSON text of the message being written (reused).
    buf: Vec<u8>,
}

impl McapLog {
    /// Creates the log of `path` at the staged name `tmp`, with the channels
    /// of [`CHANNELS`] marked in `wanted`.
    fn create(tmp: &Path, path: &Path, scene: &Scene, wanted: [bool; 4]) -> Result<Self, SimError> {
        let err = mcap_error(path);
        let file = File::create(tmp).map_err(io(path))?;
        let mut w = mcap::WriteOptions::new()
            .compression(Some(mcap::Compression::Zstd))
            // level 1: ~3× faster than the default 3 on these JSON logs, files ~10 % larger
            .compression_level(1)
            // no zstd worker threads: the whole log runs on its own writer thread
            // (`run_and_write`) already, and chunks are small
            .compression_threads(0)
            .profile("")
            .create(BufWriter::new(file))
            .map_err(&err)?;
        let mut meta = BTreeMap::new();
        meta.insert("scene".to_string(), scene.name.clone());
        meta.insert("description".to_string(), scene.description.clone());
        let mut channels = [None; 4];
        for (k, name) in CHANNELS.iter().enumerate() {
            if !wanted[k] {
                continue;
            }
            let id = add_json_channel(&mut w, name, &meta).map_err(&err)?;
            channels[k] = Some((id, 0));
        }
        Ok(Self {
            path: path.to_path_buf(),
            w,
            channels,
            buf: Vec::with_capacity(512),
        })
    }

    /// Appends one message (ignored if its channel was not created).
    fn write(&mut self, s: &Sample) -> Result<(), SimError> {
        let Some((id, seq)) = self.channels[s.channel()].as_mut() else {
            return Ok(());
        };
        let ns = (s.time().max(0.0) * 1e9).round() as u64;
        let header = mcap::records::MessageHeader {
            channel_id: *id,
            sequence: *seq,
            log_time: ns,
            publish_time: ns,
        };
        *seq = seq.wrapping_add(1);
        self.buf.clear();
        s.write_json(&mut self.buf);
        self.w
            .write_to_known_channel(&header, &self.buf)
            .map_err(mcap_error(&self.path))
    }

    /// Writes the summary section and closes the file.
    fn finish(mut self) -> Result<(), SimError> {
        self.w.finish().map_err(mcap_error(&self.path))?;
        Ok(())
    }
}

/// The recorded channels in [`CHANNELS`] order, as samples.
fn recorded(ch: &Channels) -> [Option<Vec<Sample>>; 4] {
    fn wrap<T: Copy>(v: &Option<Vec<T>>, f: fn(T) -> Sample) -> Option<Vec<Sample>> {
        v.as_ref().map(|v| v.iter().map(|&s| f(s)).collect())
    }
    [
        wrap(&ch.plant, Sample::Plant),
        wrap(&ch.control, Sample::Control),
        wrap(&ch.stepper, Sample::Stepper),
        wrap(&ch.sensors, Sample::Sensors),
    ]
}

/// Write the MCAP log of the recorded channels to `path` (channel after
/// channel; [`run_and_write`] streams them in time order instead).
///
/// # Errors
/// I/O or MCAP errors.
pub fn write_mcap(path: &Path, result: &RunResult, scene: &Scene) -> Result<(), SimError> {
    let mut staged = Staged::new();
    stage_mcap(&mut staged, path, result, scene)?;
    staged.commit().map_err(io(path))?;
    Ok(())
}

fn stage_mcap(
    staged: &mut Staged,
    path: &Path,
    result: &RunResult,
    scene: &Scene,
) -> Result<(), SimError> {
    let channels = recorded(&result.channels);
    let tmp = staged.path(path);
    let mut log = McapLog::create(&tmp, path, scene, channels.each_ref().map(Option::is_some))?;
    for s in channels.iter().flatten().flatten() {
        log.write(s)?;
    }
    log.finish()
}

/// Write one CSV per recorded channel; returns the paths.
///
/// # Errors
/// I/O errors.
pub fn write_csv(dir: &Path, stem: &str, ch: &Channels) -> Result<Vec<PathBuf>, SimError> {
    let mut staged = Staged::new();
    stage_csv(&mut staged, dir, stem, ch)?;
    staged.commit().map_err(io(dir))
}

fn stage_csv(staged: &mut Staged, dir: &Path, stem: &str, ch: &Channels) -> Result<(), SimError> {
    fn one<T: Record>(
        staged: &mut Staged,
        dir: &Path,
        stem: &str,
        samples: &Option<Vec<T>>,
    ) -> Result<(), SimError> {
        let Some(samples) = samples else {
            return Ok(());
        };
        let path = dir.join(format!("{stem}_{}.csv", T::CHANNEL));
        let header: Vec<&str> = T::FIELDS.iter().map(|(n, _)| *n).collect();
        let mut text = header.join(",").into_bytes();
        text.push(b'\n');
        for s in samples {
            s.write_csv(&mut text);
        }
        std::fs::write(staged.path(&path), text).map_err(io(&path))
    }
    one(staged, dir, stem, &ch.plant)?;
    one(staged, dir, stem, &ch.control)?;
    one(staged, dir, stem, &ch.stepper)?;
    one(staged, dir, stem, &ch.sensors)
}

/// Everything the scene asked for, under `dir`, from a finished run;
/// returns the written paths.
///
/// # Errors
/// I/O, MCAP or plot errors.
pub fn write_all(dir: &Path, scene: &Scene, result: &RunResult) -> Result<Vec<PathBuf>, SimError> {
    let o = &scene.outputs;
    if !(o.mcap || o.csv || o.summary || !o.plots.is_empty()) {
        return Ok(vec![]);
    }
    let ((), paths) = in_dir(dir, |staged| -> Result<(), SimError> {
        if o.mcap {
            stage_mcap(staged, &mcap_path(dir, scene), result, scene)?;
        }
        stage_rest(staged, dir, scene, result)
    })?;
    Ok(paths)
}

/// Create `dir` if needed, stage files into it with `write`, and commit them
/// all; on any failure the staged files are removed, and so is `dir` when
/// this call created it (if it is still empty).
fn in_dir<T, E, F>(dir: &Path, write: F) -> Result<(T, Vec<PathBuf>), E>
where
    E: From<SimError>,
    F: FnOnce(&mut Staged) -> Result<T, E>,
{
    let created = !dir.exists();
    std::fs::create_dir_all(dir).map_err(io(dir))?;
    let mut staged = Staged::new();
    let done = write(&mut staged).and_then(|value| {
        let paths = staged.commit().map_err(io(dir))?;
        Ok((value, paths))
    });
    if done.is_err() && created {
        let _ = std::fs::remove_dir(dir);
    }
    done
}

fn mcap_path(dir: &Path, scene: &Scene) -> PathBuf {
    dir.join(format!("{}.mcap", scene.name))
}

/// Stage the outputs other than the MCAP log: CSV, summary, plots.
fn stage_rest(
    staged: &mut Staged,
    dir: &Path,
    scene: &Scene,
    result: &RunResult,
) -> Result<(), SimError> {
    let o = &scene.outputs;
    if o.csv {
        stage_csv(staged, dir, &scene.name, &result.channels)?;
    }
    if o.summary {
        let p = dir.join(format!("{}_summary.json", scene.name));
        let text = serde_json::to_string_pretty(&result.summary).unwrap_or_default();
        std::fs::write(staged.path(&p), text + "\n").map_err(io(&p))?;
    }
    if !o.plots.is_empty() {
        if let Some(series) = &result.channels.plot {
            let p = dir.join(format!("{}.png", scene.name));
            crate::plot::draw(
                &staged.path(&p),
                &scene.name,
                &o.plots,
                series,
                result.summary.omega0_rad_s,
            )?;
        }
    }
    Ok(())
}

/// Samples per message of the writer thread's channel: large enough that
/// the hand-over costs nothing per sample, small enough to start writing early.
const BATCH: usize = 256;
/// Batches in flight: a writer that falls behind stalls the run loop
/// instead of buffering the whole log twice.
const IN_FLIGHT: usize = 32;

/// Runs a scene and writes everything it asks for under `dir`, as
/// `ivt sim` does: the MCAP log is written *while* the loop runs, by a
/// writer thread fed through a bounded channel (JSON + zstd of a 60 s run
/// take about as long as the simulation, so on two cores they overlap);
/// CSV, summary and plots follow the run. `run` is the closed loop with a
/// sample sink, e.g. `|sink| Simulation::new(scene).sink(sink).run()`.
///
/// Messages are in time order across channels (each channel's sequence
/// counts from 0), the same channels and counts as [`write_all`].
///
/// # Errors
/// The run's error or an output error; either way no file is left behind.
pub fn run_and_write<F>(
    dir: &Path,
    scene: &Scene,
    run: F,
) -> Result<(RunResult, Vec<PathBuf>), SimError>
where
    F: FnOnce(&mut dyn FnMut(Sample)) -> Result<RunResult, SimError>,
{
    if !scene.outputs.mcap {
        let result = run(&mut |_| {})?;
        let paths = write_all(dir, scene, &result)?;
        return Ok((result, paths));
    }
    in_dir(dir, |staged| -> Result<RunResult, SimError> {
        let result = stream_mcap(staged, &mcap_path(dir, scene), scene, run)?;
        stage_rest(staged, dir, scene, &result)?;
        Ok(result)
    })
}

/// Run the loop while a writer thread streams its samples into the staged
/// MCAP log at `path`.
fn stream_mcap<F>(
    staged: &mut Staged,
    path: &Path,
    scene: &Scene,
    run: F,
) -> Result<RunResult, SimError>
where
    F: FnOnce(&mut dyn FnMut(Sample)) -> Result<RunResult, SimError>,
{
    let wanted = CHANNELS.map(|name| scene.outputs.every(name).is_some());
    let log = McapLog::create(&staged.path(path), path, scene, wanted)?;
    let (tx, rx) = std::sync::mpsc::sync_channel::<Vec<Sample>>(IN_FLIGHT);
    let writer = std::thread::Builder::new()
        .name("mcap-writer".into())
        .spawn(move || -> Result<(), SimError> {
            let mut log = log;
            for batch in rx {
                for s in &batch {
                    log.write(s)?;
                }
            }
            log.finish()
        })
        .map_err(io(path))?;
    let mut batch = Vec::with_capacity(BATCH);
    let ran = run(&mut |s| {
        batch.push(s);
        if batch.len() == BATCH {
            // a send fails only when the writer stopped on an error, which
            // `join` reports below
            let _ = tx.send(std::mem::replace(&mut batch, Vec::with_capacity(BATCH)));
        }
    });
    if !batch.is_empty() {
        let _ = tx.send(batch);
    }
    drop(tx);
    let written = writer.join().unwrap_or_else(|_| {
        Err(SimError::Mcap {
            path: path.to_path_buf(),
            msg: "writer thread panicked".into(),
        })
    });
    let result = ran?;
    written?;
    Ok(result)
}
