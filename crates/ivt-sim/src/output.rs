//! Writing what a scene asked for: an MCAP log (one JSON-schema channel per
//! signal group, zstd chunks, Foxglove-readable), CSV files, the summary JSON
//! and a PNG with one panel per requested plot.
//!
//! [`write_outputs`] writes them from a scene's answer (either route),
//! [`write_all`] from a finished time integration; [`run_and_write`] (what
//! `ivt sim` uses) writes the MCAP log on a second thread while the loop
//! runs — on two cores it costs little more than the loop alone.
//!
//! Every file, the summary included, is staged in one
//! [`crate::atomic::Staged`] set and the set is renamed into place once,
//! when all of it is complete: a failed run, a failed plot or an interrupted
//! run leaves the directory as it was (and removes it if the run created it).

use crate::atomic::Staged;
use crate::error::{io_at as io, mcap_at as mcap_error, SimError};
use crate::record::{Channel, Sample};
use crate::run::{Channels, RunResult};
use crate::scene::Scene;
use crate::steady::SceneRun;
use std::collections::BTreeMap;
use std::fs::File;
use std::io::BufWriter;
use std::path::{Path, PathBuf};

/// The JSON schema of a channel (`ivt.<name>`), as written into MCAP logs.
#[must_use]
pub fn json_schema(channel: Channel) -> String {
    let props: serde_json::Map<String, serde_json::Value> = channel
        .fields()
        .iter()
        .map(|f| {
            (
                f.name.to_string(),
                serde_json::json!({ "type": f.json_type }),
            )
        })
        .collect();
    serde_json::json!({
        "title": format!("ivt.{}", channel.name()),
        "type": "object",
        "properties": props,
    })
    .to_string()
}

/// Adds the channel `/name` with the JSON schema `ivt.name` to an MCAP log.
pub(crate) fn add_json_channel<W: std::io::Write + std::io::Seek>(
    w: &mut mcap::Writer<W>,
    channel: Channel,
    meta: &BTreeMap<String, String>,
) -> Result<u16, mcap::McapError> {
    add_schema_channel(w, channel.name(), &json_schema(channel), meta)
}

/// Adds the channel `/name` with the JSON schema text `schema` (titled
/// `ivt.name`) to an MCAP log: [`add_json_channel`] for the simulator's
/// channels, and the rig-only channels of a recording
/// ([`crate::recording`]).
pub(crate) fn add_schema_channel<W: std::io::Write + std::io::Seek>(
    w: &mut mcap::Writer<W>,
    name: &str,
    schema: &str,
    meta: &BTreeMap<String, String>,
) -> Result<u16, mcap::McapError> {
    let id = w.add_schema(&format!("ivt.{name}"), "jsonschema", schema.as_bytes())?;
    w.add_channel(id, &format!("/{name}"), "json", meta)
}

/// An MCAP log being written: one JSON-schema channel per recorded signal
/// group, zstd chunks.
struct McapLog {
    path: PathBuf,
    w: mcap::Writer<BufWriter<File>>,
    /// MCAP channel id and next sequence number per [`Channel`] (in
    /// [`Channel::ALL`] order; None: not logged).
    channels: Vec<Option<(u16, u32)>>,
    /// The JSON text of the message being written (reused).
    buf: Vec<u8>,
}

impl McapLog {
    /// Creates the log of `path` in the staged set, with the channels
    /// `wanted`.
    fn create(
        staged: &mut Staged,
        path: &Path,
        scene: &Scene,
        wanted: impl Fn(Channel) -> bool,
    ) -> Result<Self, SimError> {
        let err = mcap_error(path);
        let (_, file) = staged.file(path).map_err(io(path))?;
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
        let mut channels = vec![None; Channel::ALL.len()];
        for (slot, &channel) in channels.iter_mut().zip(Channel::ALL) {
            if wanted(channel) {
                let id = add_json_channel(&mut w, channel, &meta).map_err(&err)?;
                *slot = Some((id, 0));
            }
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
        let Some((id, seq)) = self
            .channels
            .get_mut(s.channel() as usize)
            .and_then(Option::as_mut)
        else {
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
    let ch = &result.channels;
    let mut log = McapLog::create(staged, path, scene, |c| ch.recorded(c))?;
    for &channel in Channel::ALL {
        for s in ch.samples(channel).iter().flatten() {
            log.write(s)?;
        }
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
    for &channel in Channel::ALL {
        if let Some(text) = ch.csv(channel) {
            let path = dir.join(format!("{stem}_{}.csv", channel.name()));
            staged.write(&path, &text).map_err(io(&path))?;
        }
    }
    Ok(())
}

/// Everything the scene asked for, under `dir`, from a finished time
/// integration (the summary file as [`SceneRun::time_integration`] gives
/// it); returns the written paths.
///
/// # Errors
/// I/O, MCAP or plot errors.
pub fn write_all(dir: &Path, scene: &Scene, result: &RunResult) -> Result<Vec<PathBuf>, SimError> {
    write_outputs(
        dir,
        scene,
        &SceneRun::time_integration(scene, result.clone()),
    )
}

/// Everything the scene asked for under `dir`, from its answer on either
/// route: the time route's MCAP, CSV and plots, and the summary file
/// ([`SceneRun::summary_json`], which names the route), staged as one set
/// and renamed together. Returns the written paths.
///
/// # Errors
/// I/O, MCAP or plot errors; no file of the set is then written.
pub fn write_outputs(
    dir: &Path,
    scene: &Scene,
    answer: &SceneRun,
) -> Result<Vec<PathBuf>, SimError> {
    let o = &scene.outputs;
    let has_run = answer.run.is_some();
    if !(o.summary || has_run && (o.mcap || o.csv || !o.plots.is_empty())) {
        return Ok(vec![]);
    }
    let mut staged = Staged::in_dir(dir).map_err(io(dir))?;
    if let (Some(result), true) = (&answer.run, o.mcap) {
        stage_mcap(&mut staged, &mcap_path(dir, scene), result, scene)?;
    }
    stage_rest(&mut staged, dir, scene, answer)?;
    staged.commit().map_err(io(dir))
}

fn mcap_path(dir: &Path, scene: &Scene) -> PathBuf {
    dir.join(format!("{}.mcap", scene.name))
}

/// Stage the outputs other than the MCAP log: CSV of the time route, the
/// summary, plots of the time route (in this order).
fn stage_rest(
    staged: &mut Staged,
    dir: &Path,
    scene: &Scene,
    answer: &SceneRun,
) -> Result<(), SimError> {
    let o = &scene.outputs;
    if let Some(result) = &answer.run {
        if o.csv {
            stage_csv(staged, dir, &scene.name, &result.channels)?;
        }
    }
    if o.summary {
        let p = dir.join(format!("{}_summary.json", scene.name));
        let text = serde_json::to_string_pretty(&answer.summary_json(scene)).unwrap_or_default();
        staged.write(&p, (text + "\n").as_bytes()).map_err(io(&p))?;
    }
    if let Some(result) = &answer.run {
        if let (Some(series), false) = (&result.channels.plot, o.plots.is_empty()) {
            let p = dir.join(format!("{}.png", scene.name));
            let tmp = staged.path(&p).map_err(io(&p))?;
            crate::plot::draw(
                &tmp,
                &scene.name,
                &o.plots,
                series,
                result.summary.omega0_rad_s,
            )
            .map_err(|e| match e {
                SimError::Plot { msg, .. } => SimError::Plot {
                    path: p.clone(),
                    msg,
                },
                e => e,
            })?;
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

/// Runs a scene's time integration and writes everything it asks for under
/// `dir`, as `ivt sim` does: the MCAP log is written *while* the loop runs,
/// by a writer thread fed through a bounded channel (JSON + zstd of a 60 s
/// run take about as long as the simulation, so on two cores they overlap);
/// CSV, plots and the summary follow the run, and the whole set is renamed
/// into place at the end. `run` is the closed loop with a sample sink, e.g.
/// `|sink| Simulation::new(scene).sink(sink).answer_by_time_integration()`.
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
) -> Result<(SceneRun, Vec<PathBuf>), SimError>
where
    F: FnOnce(&mut dyn FnMut(Sample)) -> Result<SceneRun, SimError>,
{
    if !scene.outputs.mcap {
        let answer = run(&mut |_| {})?;
        let paths = write_outputs(dir, scene, &answer)?;
        return Ok((answer, paths));
    }
    let mut staged = Staged::in_dir(dir).map_err(io(dir))?;
    let answer = stream_mcap(&mut staged, &mcap_path(dir, scene), scene, run)?;
    stage_rest(&mut staged, dir, scene, &answer)?;
    let paths = staged.commit().map_err(io(dir))?;
    Ok((answer, paths))
}

/// Run the loop while a writer thread streams its samples into the staged
/// MCAP log at `path`.
fn stream_mcap<F>(
    staged: &mut Staged,
    path: &Path,
    scene: &Scene,
    run: F,
) -> Result<SceneRun, SimError>
where
    F: FnOnce(&mut dyn FnMut(Sample)) -> Result<SceneRun, SimError>,
{
    let log = McapLog::create(staged, path, scene, |c| scene.outputs.every(c).is_some())?;
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
