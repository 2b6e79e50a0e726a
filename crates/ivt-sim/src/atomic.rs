//! The toolkit's one output writer: every file it writes (scene outputs,
//! plots, CSV, JSON, emitted Rust, MCAP, reports) goes through a [`Staged`]
//! set, and a SIGINT/SIGTERM removes what a run created.
//!
//! - Each file is first written under a temporary name beside its target,
//!   `.tmp-<pid>-<counter>-<random>-<name>` (the extension kept), created
//!   exclusively (`O_CREAT | O_EXCL`: never through a symlink, never shared
//!   by two calls, threads or processes).
//! - A target must be absent or a regular file that is not an input of the
//!   run: a symlink, a directory, a device (`/dev/full`) or a file the process
//!   has read ([`crate::input`], by device and inode) is refused with an error
//!   before anything is written, and checked again at the commit.
//! - [`Staged::commit`] renames the whole set into place, all or none: the
//!   targets that existed are kept under a backup link until every rename
//!   succeeded, and put back if one fails. Dropping a set without committing
//!   removes its temporary files and the directories [`Staged::in_dir`]
//!   created, so a failed command leaves the file system as it was.
//! - The temporary files and created directories of every live set are kept
//!   in a process-wide registry so that a SIGINT/SIGTERM handler can delete
//!   them ([`on_interrupt`]) — unless a loop that can finish its file
//!   cleanly (the rig recorder closing its MCAP with a footer) is
//!   [`listen`]ing, in which case the handler only raises the flag that loop
//!   polls ([`interrupted`]). After an interruption no new file is staged.

use std::fs::{File, OpenOptions};
use std::hash::{BuildHasher, Hasher};
use std::io::{Error, ErrorKind};
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, AtomicU64, AtomicUsize, Ordering};
use std::sync::{Mutex, MutexGuard};

/// What a SIGINT/SIGTERM removes: the temporary files of every live
/// [`Staged`] set and the directories they created (deepest first).
#[derive(Default)]
struct Registry {
    files: Vec<PathBuf>,
    dirs: Vec<PathBuf>,
}

static REGISTRY: Mutex<Registry> = Mutex::new(Registry {
    files: Vec::new(),
    dirs: Vec::new(),
});
/// Loops that poll [`interrupted`] and finish their file on their own.
static LISTENERS: AtomicUsize = AtomicUsize::new(0);
static INTERRUPTED: AtomicBool = AtomicBool::new(false);
/// Temporary names made by this process (part of each name).
static COUNTER: AtomicU64 = AtomicU64::new(0);

fn registry() -> MutexGuard<'static, Registry> {
    REGISTRY
        .lock()
        .unwrap_or_else(std::sync::PoisonError::into_inner)
}

/// A set of output files written under temporary names, renamed together.
#[derive(Debug, Default)]
pub struct Staged {
    /// (temporary, target) pairs not yet renamed.
    files: Vec<(PathBuf, PathBuf)>,
    /// Directories this set created, deepest first (removed if it fails).
    dirs: Vec<PathBuf>,
}

/// Refuses to replace anything but a regular file (or nothing): a symlink
/// is never written through, a device or directory never replaced, and a
/// file this process has read ([`crate::input::read_as`]: compared by
/// device and inode, so a hard link or another path to an input is one too)
/// is never replaced by an output.
///
/// # Errors
/// [`ErrorKind::InvalidInput`] saying what the target is, or the error of
/// reading its metadata.
pub fn check_target(target: &Path) -> std::io::Result<()> {
    match std::fs::symlink_metadata(target) {
        Ok(m) if m.file_type().is_file() => match crate::input::read_as(target) {
            None => Ok(()),
            Some(read) => Err(Error::new(
                ErrorKind::InvalidInput,
                format!(
                    "is an input of this run (read as {}); refusing to replace it",
                    read.display()
                ),
            )),
        },
        Ok(m) => {
            let what = if m.file_type().is_symlink() {
                "a symbolic link (never written through)"
            } else if m.is_dir() {
                "a directory"
            } else {
                "not a regular file (a device, pipe or socket)"
            };
            Err(Error::new(
                ErrorKind::InvalidInput,
                format!("is {what}; refusing to replace it"),
            ))
        }
        Err(e) if e.kind() == ErrorKind::NotFound => Ok(()),
        Err(e) => Err(e),
    }
}

/// A fresh name beside `target`: `.tmp-<pid>-<counter>-<random>-<name><suffix>`.
fn fresh_name(target: &Path, suffix: &str) -> PathBuf {
    let name = target
        .file_name()
        .map_or_else(|| "out".into(), |n| n.to_string_lossy().into_owned());
    let n = COUNTER.fetch_add(1, Ordering::Relaxed);
    // RandomState is seeded per process from the OS; the counter and the
    // clock make each name differ within the process too.
    let mut h = std::collections::hash_map::RandomState::new().build_hasher();
    h.write_u64(n);
    if let Ok(d) = std::time::SystemTime::now().duration_since(std::time::UNIX_EPOCH) {
        h.write_u128(d.as_nanos());
    }
    let random = h.finish();
    target.with_file_name(format!(
        ".tmp-{}-{n}-{random:016x}-{name}{suffix}",
        std::process::id()
    ))
}

/// Creates a fresh file beside `target` exclusively and registers it for
/// removal on interruption; refused once interrupted.
fn create_fresh(target: &Path, suffix: &str) -> std::io::Result<(PathBuf, File)> {
    let mut reg = registry();
    if interrupted() {
        return Err(Error::new(ErrorKind::Interrupted, "interrupted"));
    }
    loop {
        let tmp = fresh_name(target, suffix);
        match OpenOptions::new().write(true).create_new(true).open(&tmp) {
            Ok(file) => {
                reg.files.push(tmp.clone());
                return Ok((tmp, file));
            }
            // a name taken by someone else: draw another
            Err(e) if e.kind() == ErrorKind::AlreadyExists => {}
            Err(e) => return Err(e),
        }
    }
}

fn forget(tmp: &Path) {
    registry().files.retain(|p| p != tmp);
}

impl Staged {
    /// An empty set.
    #[must_use]
    pub fn new() -> Self {
        Self::default()
    }

    /// An empty set writing into `dir`, which is created (with its missing
    /// parents) if needed; if the set is dropped without a commit, the
    /// directories it created are removed again (when empty).
    ///
    /// # Errors
    /// The directory cannot be created, or it or a parent exists and is not
    /// a directory (kind `NotADirectory`).
    pub fn in_dir(dir: &Path) -> std::io::Result<Self> {
        let mut missing = vec![];
        let mut d = Some(dir);
        while let Some(p) = d.filter(|p| !p.as_os_str().is_empty()) {
            if std::fs::symlink_metadata(p).is_ok() {
                if !std::fs::metadata(p).is_ok_and(|m| m.is_dir()) {
                    let what = if p == dir {
                        "is not a directory".to_string()
                    } else {
                        format!("{} (a parent) is not a directory", p.display())
                    };
                    return Err(Error::new(ErrorKind::NotADirectory, what));
                }
                break;
            }
            missing.push(p.to_path_buf());
            d = p.parent();
        }
        let mut set = Self::new();
        {
            let mut reg = registry();
            if interrupted() {
                return Err(Error::new(ErrorKind::Interrupted, "interrupted"));
            }
            std::fs::create_dir_all(dir)?;
            reg.dirs.extend(missing.iter().cloned());
        }
        set.dirs = missing;
        Ok(set)
    }

    /// Stages `target`: checks that it is absent or a regular file
    /// ([`check_target`]) and creates its temporary file exclusively; returns
    /// the temporary path to write (same directory, same extension), renamed
    /// to `target` by [`Staged::commit`].
    ///
    /// # Errors
    /// A target that is not a regular file, or the temporary file cannot be
    /// created (missing directory, permissions, interrupted).
    pub fn path(&mut self, target: &Path) -> std::io::Result<PathBuf> {
        self.file(target).map(|(tmp, _)| tmp)
    }

    /// As [`Staged::path`], with the temporary file open for writing.
    ///
    /// # Errors
    /// As [`Staged::path`].
    pub fn file(&mut self, target: &Path) -> std::io::Result<(PathBuf, File)> {
        check_target(target)?;
        let (tmp, file) = create_fresh(target, "")?;
        self.files.push((tmp.clone(), target.to_path_buf()));
        Ok((tmp, file))
    }

    /// Stages `target` with the content `bytes`.
    ///
    /// # Errors
    /// As [`Staged::path`], or the write fails (full disk, ...).
    pub fn write(&mut self, target: &Path, bytes: &[u8]) -> std::io::Result<()> {
        use std::io::Write as _;
        let (_, mut file) = self.file(target)?;
        file.write_all(bytes)?;
        file.flush()
    }

    /// Renames every temporary file to its target, all or none; returns the
    /// targets.
    ///
    /// # Errors
    /// A target that became something else than a regular file, or a failed
    /// backup or rename; the targets are then as they were before the call
    /// and the temporary files are removed.
    pub fn commit(mut self) -> std::io::Result<Vec<PathBuf>> {
        for (_, target) in &self.files {
            check_target(target)?;
        }
        // Keep what the renames replace until all of them succeeded.
        let mut backups: Vec<Option<PathBuf>> = Vec::with_capacity(self.files.len());
        let done = self
            .back_up(&mut backups)
            .and_then(|()| self.rename_all(&backups));
        for b in backups.iter().flatten() {
            let _ = std::fs::remove_file(b);
            forget(b);
        }
        done?;
        let files = std::mem::take(&mut self.files);
        {
            let mut reg = registry();
            reg.files.retain(|p| !files.iter().any(|(tmp, _)| tmp == p));
            reg.dirs.retain(|p| !self.dirs.contains(p));
        }
        self.dirs.clear();
        Ok(files.into_iter().map(|(_, target)| target).collect())
    }

    /// A backup link of every target that exists (None for the others).
    fn back_up(&self, backups: &mut Vec<Option<PathBuf>>) -> std::io::Result<()> {
        for (_, target) in &self.files {
            if std::fs::symlink_metadata(target).is_err() {
                backups.push(None);
                continue;
            }
            let bak = fresh_name(target, ".bak");
            registry().files.push(bak.clone());
            backups.push(Some(bak.clone()));
            if std::fs::hard_link(target, &bak).is_err() {
                // a file system without hard links: a copy
                std::fs::copy(target, &bak)?;
            }
        }
        Ok(())
    }

    /// Renames the temporary files over their targets; on a failure the
    /// renamed targets are restored from `backups` (or removed).
    fn rename_all(&self, backups: &[Option<PathBuf>]) -> std::io::Result<()> {
        for (k, (tmp, target)) in self.files.iter().enumerate() {
            if let Err(e) = std::fs::rename(tmp, target) {
                for ((_, t), b) in self.files.iter().zip(backups).take(k) {
                    let _ = match b {
                        Some(b) => std::fs::rename(b, t),
                        None => std::fs::remove_file(t),
                    };
                }
                return Err(e);
            }
        }
        Ok(())
    }
}

impl Drop for Staged {
    fn drop(&mut self) {
        for (tmp, _) in self.files.drain(..) {
            forget(&tmp);
            let _ = std::fs::remove_file(&tmp);
        }
        if !self.dirs.is_empty() {
            let mut reg = registry();
            for d in self.dirs.drain(..) {
                reg.dirs.retain(|p| *p != d);
                // only succeeds while empty: another writer's files stay
                let _ = std::fs::remove_dir(&d);
            }
        }
    }
}

/// Write `bytes` to `path` atomically (temporary file + rename).
///
/// # Errors
/// As [`Staged::write`] and [`Staged::commit`]; `path` is then untouched.
pub fn write_atomic(path: &Path, bytes: &[u8]) -> std::io::Result<()> {
    let mut staged = Staged::new();
    staged.write(path, bytes)?;
    staged.commit().map(|_| ())
}

/// Marks a loop that polls [`interrupted`] and then finishes its output
/// cleanly; while one lives, [`on_interrupt`] only raises the flag.
#[derive(Debug)]
pub struct Listener(());

/// Start listening for interruption (see [`Listener`]).
pub fn listen() -> Listener {
    LISTENERS.fetch_add(1, Ordering::SeqCst);
    Listener(())
}

impl Drop for Listener {
    fn drop(&mut self) {
        LISTENERS.fetch_sub(1, Ordering::SeqCst);
    }
}

/// Whether SIGINT/SIGTERM was received (set by [`on_interrupt`]).
pub fn interrupted() -> bool {
    INTERRUPTED.load(Ordering::SeqCst)
}

/// What a SIGINT/SIGTERM handler calls. Returns `true` when a [`Listener`]
/// will finish its output and the process should keep running; otherwise the
/// temporary files of every live [`Staged`] set and the directories they
/// created are deleted, no new file can be staged, and the caller should
/// exit.
pub fn on_interrupt() -> bool {
    INTERRUPTED.store(true, Ordering::SeqCst);
    if LISTENERS.load(Ordering::SeqCst) > 0 {
        return true;
    }
    let mut reg = registry();
    for tmp in reg.files.drain(..) {
        let _ = std::fs::remove_file(tmp);
    }
    for d in reg.dirs.drain(..) {
        let _ = std::fs::remove_dir(d);
    }
    false
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::testing::{listing, scratch_dir};

    #[test]
    fn commit_renames_and_drop_leaves_the_directory_as_it_was() {
        let d = scratch_dir("atomic-commit");
        std::fs::write(d.join("keep.csv"), "old").unwrap();
        {
            let mut s = Staged::new();
            let tmp = s.path(&d.join("keep.csv")).unwrap();
            assert_eq!(tmp.extension().unwrap(), "csv");
            assert!(tmp
                .file_name()
                .unwrap()
                .to_str()
                .unwrap()
                .starts_with(".tmp-"));
            std::fs::write(&tmp, "new").unwrap();
            s.write(&d.join("b.png"), b"b").unwrap();
            // dropped without commit: a failed command
        }
        assert_eq!(listing(&d), ["keep.csv"]);
        assert_eq!(std::fs::read_to_string(d.join("keep.csv")).unwrap(), "old");
        let mut s = Staged::new();
        s.write(&d.join("keep.csv"), b"new").unwrap();
        s.write(&d.join("b.png"), b"b").unwrap();
        let done = s.commit().unwrap();
        assert_eq!(done, [d.join("keep.csv"), d.join("b.png")]);
        assert_eq!(listing(&d), ["b.png", "keep.csv"]);
        assert_eq!(std::fs::read_to_string(d.join("keep.csv")).unwrap(), "new");
        write_atomic(&d.join("c.json"), b"{}").unwrap();
        assert_eq!(listing(&d), ["b.png", "c.json", "keep.csv"]);
        // a directory that does not exist: error, nothing written
        assert!(write_atomic(&d.join("missing").join("x"), b"x").is_err());
        assert_eq!(listing(&d), ["b.png", "c.json", "keep.csv"]);
        std::fs::remove_dir_all(&d).unwrap();
    }

    /// Two sets staging the same target never share a temporary file.
    #[test]
    fn temporary_names_are_unique_per_call() {
        let d = scratch_dir("atomic-unique");
        let target = d.join("a.json");
        let (mut s1, mut s2) = (Staged::new(), Staged::new());
        let (t1, t2) = (s1.path(&target).unwrap(), s2.path(&target).unwrap());
        assert_ne!(t1, t2);
        std::fs::write(&t1, "1").unwrap();
        std::fs::write(&t2, "2").unwrap();
        s1.commit().unwrap();
        assert_eq!(std::fs::read_to_string(&target).unwrap(), "1");
        s2.commit().unwrap();
        assert_eq!(std::fs::read_to_string(&target).unwrap(), "2");
        assert_eq!(listing(&d), ["a.json"]);
        std::fs::remove_dir_all(&d).unwrap();
    }

    /// A symlink, a directory and a device are refused, never replaced nor
    /// written through.
    #[cfg(unix)]
    #[test]
    fn refuses_symlinks_directories_and_devices() {
        let d = scratch_dir("atomic-refuse");
        std::fs::write(d.join("real"), "real").unwrap();
        std::os::unix::fs::symlink(d.join("real"), d.join("link")).unwrap();
        std::fs::create_dir(d.join("dir")).unwrap();
        for target in [d.join("link"), d.join("dir")] {
            let e = write_atomic(&target, b"x").unwrap_err();
            assert_eq!(e.kind(), ErrorKind::InvalidInput, "{e}");
        }
        let e = write_atomic(Path::new("/dev/null"), b"x").unwrap_err();
        assert!(e.to_string().contains("not a regular file"), "{e}");
        assert_eq!(std::fs::read_to_string(d.join("real")).unwrap(), "real");
        assert!(std::fs::symlink_metadata(d.join("link"))
            .unwrap()
            .file_type()
            .is_symlink());
        assert_eq!(listing(&d), ["dir", "link", "real"]);
        std::fs::remove_dir_all(&d).unwrap();
    }

    /// A rename that fails half-way through the set puts back the targets
    /// already replaced: all or none.
    #[test]
    fn a_failed_commit_restores_every_target() {
        let d = scratch_dir("atomic-all-or-none");
        std::fs::write(d.join("a.csv"), "old a").unwrap();
        let mut s = Staged::new();
        s.write(&d.join("a.csv"), b"new a").unwrap();
        s.write(&d.join("b.csv"), b"new b").unwrap();
        let c = d.join("c.csv");
        s.write(&c, b"new c").unwrap();
        // c becomes a non-empty directory after staging: its rename fails
        std::fs::create_dir(&c).unwrap();
        std::fs::write(c.join("inside"), "x").unwrap();
        // the commit's check refuses it before any rename ...
        assert!(s.commit().is_err());
        assert_eq!(std::fs::read_to_string(d.join("a.csv")).unwrap(), "old a");
        assert_eq!(listing(&d), ["a.csv", "c.csv"]);
        // ... and a rename failing after the check is rolled back too
        let mut s = Staged::new();
        s.write(&d.join("a.csv"), b"new a").unwrap();
        s.write(&d.join("b.csv"), b"new b").unwrap();
        let mut backups = vec![];
        s.back_up(&mut backups).unwrap();
        // make b's rename fail: its temporary file disappears
        let tmp_b = s.files[1].0.clone();
        std::fs::remove_file(&tmp_b).unwrap();
        assert!(s.rename_all(&backups).is_err());
        assert_eq!(std::fs::read_to_string(d.join("a.csv")).unwrap(), "old a");
        for b in backups.iter().flatten() {
            let _ = std::fs::remove_file(b);
        }
        drop(s);
        assert_eq!(listing(&d), ["a.csv", "c.csv"]);
        std::fs::remove_dir_all(&d).unwrap();
    }

    /// A set in a directory it created removes it when it fails.
    #[test]
    fn a_failed_set_removes_the_directories_it_created() {
        let d = scratch_dir("atomic-dirs");
        let out = d.join("a").join("b");
        {
            let mut s = Staged::in_dir(&out).unwrap();
            s.write(&out.join("x.json"), b"{}").unwrap();
        }
        assert!(listing(&d).is_empty());
        let mut s = Staged::in_dir(&out).unwrap();
        s.write(&out.join("x.json"), b"{}").unwrap();
        s.commit().unwrap();
        assert_eq!(listing(&out), ["x.json"]);
        std::fs::remove_dir_all(&d).unwrap();
    }
}
