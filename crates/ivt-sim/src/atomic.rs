//! Atomic output files and interruption.
//!
//! Every output is written under a temporary name in its target directory
//! (`.tmp-<pid>-<name>`, the extension kept) and renamed over the target only
//! when the whole set is complete ([`Staged::commit`]); dropping a [`Staged`]
//! set removes its temporary files, so a failed command leaves the directory
//! as it was. The temporary names are also kept in a process-wide registry so
//! that a SIGINT/SIGTERM handler can delete them ([`on_interrupt`]) — unless a
//! loop that can finish its file cleanly (the rig recorder closing its MCAP
//! with a footer) is [`listen`]ing, in which case the handler only raises the
//! flag that loop polls ([`interrupted`]).

use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};
use std::sync::Mutex;

/// Temporary files of every live [`Staged`] set.
static STAGED: Mutex<Vec<PathBuf>> = Mutex::new(Vec::new());
/// Loops that poll [`interrupted`] and finish their file on their own.
static LISTENERS: AtomicUsize = AtomicUsize::new(0);
static INTERRUPTED: AtomicBool = AtomicBool::new(false);

fn registry() -> std::sync::MutexGuard<'static, Vec<PathBuf>> {
    STAGED
        .lock()
        .unwrap_or_else(std::sync::PoisonError::into_inner)
}

/// A set of output files written under temporary names, renamed together.
#[derive(Debug, Default)]
pub struct Staged {
    /// (temporary, target) pairs not yet renamed.
    files: Vec<(PathBuf, PathBuf)>,
}

impl Staged {
    /// An empty set.
    pub fn new() -> Self {
        Self::default()
    }

    /// The temporary path to write `target` to (same directory, same
    /// extension); it is renamed to `target` by [`Staged::commit`].
    pub fn path(&mut self, target: &Path) -> PathBuf {
        let name = target
            .file_name()
            .map_or_else(|| "out".into(), |n| n.to_string_lossy().into_owned());
        let tmp = target.with_file_name(format!(".tmp-{}-{name}", std::process::id()));
        registry().push(tmp.clone());
        self.files.push((tmp.clone(), target.to_path_buf()));
        tmp
    }

    /// Rename every temporary file to its target; returns the targets.
    ///
    /// # Errors
    /// The first failed rename (the remaining temporary files are removed).
    pub fn commit(mut self) -> std::io::Result<Vec<PathBuf>> {
        let mut done = Vec::with_capacity(self.files.len());
        while !self.files.is_empty() {
            let (tmp, target) = self.files.remove(0);
            forget(&tmp);
            if let Err(e) = std::fs::rename(&tmp, &target) {
                let _ = std::fs::remove_file(&tmp);
                return Err(e);
            }
            done.push(target);
        }
        Ok(done)
    }
}

impl Drop for Staged {
    fn drop(&mut self) {
        for (tmp, _) in self.files.drain(..) {
            forget(&tmp);
            let _ = std::fs::remove_file(&tmp);
        }
    }
}

fn forget(tmp: &Path) {
    registry().retain(|p| p != tmp);
}

/// Write `bytes` to `path` atomically (temporary file + rename).
///
/// # Errors
/// I/O errors; `path` is then untouched.
pub fn write_atomic(path: &Path, bytes: &[u8]) -> std::io::Result<()> {
    let mut staged = Staged::new();
    std::fs::write(staged.path(path), bytes)?;
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
/// temporary files of every live [`Staged`] set are deleted and the caller
/// should exit.
pub fn on_interrupt() -> bool {
    INTERRUPTED.store(true, Ordering::SeqCst);
    if LISTENERS.load(Ordering::SeqCst) > 0 {
        return true;
    }
    for tmp in registry().drain(..) {
        let _ = std::fs::remove_file(tmp);
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
            let tmp = s.path(&d.join("keep.csv"));
            assert_eq!(tmp.extension().unwrap(), "csv");
            std::fs::write(&tmp, "new").unwrap();
            std::fs::write(s.path(&d.join("b.png")), "b").unwrap();
            // dropped without commit: a failed command
        }
        assert_eq!(listing(&d), ["keep.csv"]);
        assert_eq!(std::fs::read_to_string(d.join("keep.csv")).unwrap(), "old");
        let mut s = Staged::new();
        std::fs::write(s.path(&d.join("keep.csv")), "new").unwrap();
        std::fs::write(s.path(&d.join("b.png")), "b").unwrap();
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
}
