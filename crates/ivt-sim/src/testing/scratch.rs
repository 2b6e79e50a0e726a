//! Scratch directories for tests that remove themselves.
//!
//! A test that writes recordings (a commissioning run is ~140 MB) and leaves
//! them behind fills the disk of the machine its CI shares: [`Scratch`]
//! deletes its directory when dropped. It keeps it when the test is
//! panicking, so that a failure can be inspected.

use std::ops::Deref;
use std::path::{Path, PathBuf};

/// A fresh, empty directory `ivt-{name}-{pid}` under the system temporary
/// directory, removed with its contents when dropped (unless the thread is
/// panicking). Dereferences to its [`Path`].
#[derive(Debug)]
pub struct Scratch {
    path: PathBuf,
}

impl Scratch {
    /// Creates the directory (removing first what a previous run of the same
    /// process id left).
    ///
    /// # Panics
    /// If the directory cannot be created.
    #[allow(clippy::expect_used)]
    pub fn new(name: &str) -> Self {
        let path = std::env::temp_dir().join(format!("ivt-{name}-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&path);
        std::fs::create_dir_all(&path).expect("create scratch directory");
        Scratch { path }
    }
}

impl Deref for Scratch {
    type Target = Path;
    fn deref(&self) -> &Path {
        &self.path
    }
}

impl AsRef<Path> for Scratch {
    fn as_ref(&self) -> &Path {
        &self.path
    }
}

impl Drop for Scratch {
    fn drop(&mut self) {
        if !std::thread::panicking() {
            let _ = std::fs::remove_dir_all(&self.path);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::Scratch;

    #[test]
    fn the_directory_and_its_files_are_gone_after_the_drop() {
        let d = Scratch::new("scratch-self-test");
        std::fs::create_dir_all(d.join("a/b")).unwrap();
        std::fs::write(d.join("a/b/f.bin"), [0u8; 1024]).unwrap();
        let path = d.to_path_buf();
        assert!(path.join("a/b/f.bin").is_file());
        drop(d);
        assert!(!path.exists(), "{} left behind", path.display());
    }
}
