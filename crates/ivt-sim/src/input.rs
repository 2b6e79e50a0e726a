//! The one way a user's input file is opened: every reader of the toolkit
//! (scenes, a scene's `[plant] file`, plant files, pulse logs, commissioning
//! recordings; from the CLI and from Python) goes through [`open`].
//!
//! - Only a regular file is read. A FIFO, a device (`/dev/zero`, a
//!   terminal), a socket or a directory is refused with what it is. The
//!   open is non-blocking (`O_NONBLOCK | O_NOCTTY`) and the type is taken
//!   from the open descriptor, so a FIFO without a writer never blocks and a
//!   terminal never becomes the controlling one.
//! - Each kind of input has a size budget, checked against the file's size
//!   before a byte is read and again while reading (a file that grows is cut
//!   at the budget).
//! - Every file opened is remembered by its device and inode ([`read_as`]):
//!   the output writer ([`crate::atomic`]) refuses to replace a file the
//!   process has read, whatever path names it (a hard link, `./x` for `x`).
//!   A command-line run is one process; in Python the rule holds for the
//!   session.

use std::fs::File;
use std::io::{Error, ErrorKind, Read};
use std::os::unix::fs::{FileTypeExt as _, MetadataExt as _, OpenOptionsExt as _};
use std::path::{Path, PathBuf};
use std::sync::Mutex;

/// Largest scene or plant file read \[bytes\]: 1 MiB, about 100× the longest
/// scene in `scenes/`.
pub const MAX_SCENE_BYTES: u64 = 1 << 20;

/// The files this process has read: (device, inode, the path read).
static READ: Mutex<Vec<(u64, u64, PathBuf)>> = Mutex::new(Vec::new());

/// An input file open for reading: a regular file of at most its budget,
/// read no further than that budget.
#[derive(Debug)]
pub struct Input {
    file: File,
    /// Bytes read so far.
    read: u64,
    /// The budget \[bytes\].
    limit: u64,
    /// The file's size when it was opened \[bytes\].
    len: u64,
}

impl Input {
    /// The file's size when it was opened \[bytes\].
    #[must_use]
    pub fn len(&self) -> u64 {
        self.len
    }

    /// Whether the file was empty when it was opened.
    #[must_use]
    pub fn is_empty(&self) -> bool {
        self.len == 0
    }
}

impl Read for Input {
    /// Reads as a file does, and fails (kind `FileTooLarge`) once more than
    /// the budget would have been read.
    fn read(&mut self, buf: &mut [u8]) -> std::io::Result<usize> {
        let room = usize::try_from(self.limit.saturating_add(1) - self.read.min(self.limit))
            .unwrap_or(usize::MAX);
        let want = buf.len().min(room);
        let n = self.file.read(buf.get_mut(..want).unwrap_or_default())?;
        self.read += n as u64;
        if self.read > self.limit {
            return Err(too_big(
                &format!("reading stopped after {} bytes", self.read),
                self.limit,
            ));
        }
        Ok(n)
    }
}

fn too_big(size: &str, limit: u64) -> Error {
    Error::new(
        ErrorKind::FileTooLarge,
        format!("{size}: more than the {limit} bytes this input may have"),
    )
}

/// What a file that is not a regular file is, for the refusal.
fn what(t: std::fs::FileType) -> &'static str {
    if t.is_dir() {
        "a directory"
    } else if t.is_fifo() {
        "a FIFO (named pipe)"
    } else if t.is_char_device() {
        "a character device"
    } else if t.is_block_device() {
        "a block device"
    } else if t.is_socket() {
        "a socket"
    } else {
        "not a regular file"
    }
}

/// Opens `path` as an input of at most `limit` bytes and remembers it
/// ([`read_as`]).
///
/// # Errors
/// The open fails (the OS error: missing file, permissions); the path names
/// something else than a regular file (kind `InvalidInput`, saying what it
/// is); the file has more than `limit` bytes (kind `FileTooLarge`, with its
/// size).
pub fn open(path: &Path, limit: u64) -> std::io::Result<Input> {
    let file = std::fs::OpenOptions::new()
        .read(true)
        .custom_flags(libc::O_NONBLOCK | libc::O_NOCTTY)
        .open(path)?;
    let meta = file.metadata()?;
    if !meta.file_type().is_file() {
        return Err(Error::new(
            ErrorKind::InvalidInput,
            format!(
                "is {}, not a regular file (inputs are read from regular files only)",
                what(meta.file_type())
            ),
        ));
    }
    if meta.len() > limit {
        return Err(too_big(&format!("{} bytes", meta.len()), limit));
    }
    {
        let mut read = READ
            .lock()
            .unwrap_or_else(std::sync::PoisonError::into_inner);
        let id = (meta.dev(), meta.ino());
        if !read.iter().any(|(d, i, _)| (*d, *i) == id) {
            read.push((id.0, id.1, path.to_path_buf()));
        }
    }
    Ok(Input {
        file,
        read: 0,
        limit,
        len: meta.len(),
    })
}

/// The path under which this process read the file that `target` names (the
/// same device and inode), if it did; None for a target that does not exist.
/// An input whose path no longer names that file (deleted or replaced since)
/// does not count: its inode may have been reused by an unrelated file.
#[must_use]
pub fn read_as(target: &Path) -> Option<PathBuf> {
    let meta = std::fs::metadata(target).ok()?;
    let id = (meta.dev(), meta.ino());
    let read = READ
        .lock()
        .unwrap_or_else(std::sync::PoisonError::into_inner);
    read.iter()
        .filter(|(d, i, _)| (*d, *i) == id)
        .find(|(_, _, p)| std::fs::metadata(p).is_ok_and(|m| (m.dev(), m.ino()) == id))
        .map(|(_, _, p)| p.clone())
}

/// The whole of the input `path` ([`open`]), at most `limit` bytes.
///
/// # Errors
/// As [`open`], or reading fails.
pub fn read_bounded(path: &Path, limit: u64) -> std::io::Result<Vec<u8>> {
    let mut input = open(path, limit)?;
    let mut bytes = Vec::with_capacity(usize::try_from(input.len()).unwrap_or(0));
    input.read_to_end(&mut bytes)?;
    Ok(bytes)
}

/// [`read_bounded`] as UTF-8 text.
///
/// # Errors
/// As [`read_bounded`], or the bytes are not UTF-8 (kind `InvalidData`, the
/// only error of this module that is about the content, with the offset of
/// the first bad byte).
pub fn read_text_bounded(path: &Path, limit: u64) -> std::io::Result<String> {
    String::from_utf8(read_bounded(path, limit)?).map_err(|e| {
        Error::new(
            ErrorKind::InvalidData,
            format!("not UTF-8 text (byte {})", e.utf8_error().valid_up_to()),
        )
    })
}

/// Longest excerpt of a user's line shown in an error \[chars\].
pub const EXCERPT_CHARS: usize = 200;

/// `line` for an error message: at most [`EXCERPT_CHARS`] characters, with
/// the count of the rest (a 10 MB line is not echoed).
#[must_use]
pub fn excerpt(line: &str) -> String {
    match line.char_indices().nth(EXCERPT_CHARS) {
        None => format!("{line:?}"),
        Some((cut, _)) => {
            let rest = line.get(cut..).map_or(0, |r| r.chars().count());
            format!(
                "{:?}… ({rest} more chars)",
                line.get(..cut).unwrap_or_default()
            )
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::testing::scratch::Scratch;

    /// Not crate::testing::scratch_dir: testing reads scenes, which read
    /// input (a module cycle).
    fn scratch(name: &str) -> Scratch {
        Scratch::new(&format!("input-{name}"))
    }

    #[test]
    fn only_regular_files_within_their_budget_are_read() {
        for (path, what) in [
            ("/dev/zero", "a character device"),
            ("/dev/null", "a character device"),
            ("/tmp", "a directory"),
        ] {
            let e = read_bounded(Path::new(path), 1000).unwrap_err();
            assert_eq!(e.kind(), ErrorKind::InvalidInput, "{path}: {e}");
            assert!(e.to_string().contains(what), "{path}: {e}");
        }
        let d = scratch("bounded");
        let f = d.join("small.toml");
        std::fs::write(&f, "x = 1\n").unwrap();
        assert_eq!(read_text_bounded(&f, 6).unwrap(), "x = 1\n");
        let e = read_text_bounded(&f, 5).unwrap_err().to_string();
        assert!(e.contains("6 bytes: more than the 5"), "{e}");
        std::fs::write(&f, b"a\xffb").unwrap();
        let e = read_text_bounded(&f, 10).unwrap_err().to_string();
        assert!(e.contains("not UTF-8 text (byte 1)"), "{e}");
        let e = read_bounded(&d.join("missing"), 10).unwrap_err();
        assert_eq!(e.kind(), ErrorKind::NotFound);
        std::fs::remove_dir_all(&d).unwrap();
    }

    /// A FIFO without a writer is refused at once instead of blocking the
    /// open.
    #[test]
    fn a_fifo_without_a_writer_is_refused_at_once() {
        let d = scratch("fifo");
        let fifo = d.join("pipe");
        let made = std::process::Command::new("mkfifo")
            .arg(&fifo)
            .status()
            .unwrap();
        assert!(made.success());
        let t0 = std::time::Instant::now();
        let e = read_bounded(&fifo, 1000).unwrap_err();
        assert!(e.to_string().contains("a FIFO (named pipe)"), "{e}");
        assert!(t0.elapsed() < std::time::Duration::from_secs(1));
        std::fs::remove_dir_all(&d).unwrap();
    }

    /// A file that grows after it was opened is cut at its budget.
    #[test]
    fn a_growing_file_is_cut_at_the_budget() {
        let d = scratch("grow");
        let f = d.join("log.csv");
        std::fs::write(&f, "1234").unwrap();
        let mut input = open(&f, 6).unwrap();
        std::fs::write(&f, "1234567890").unwrap();
        let mut bytes = vec![];
        let e = input.read_to_end(&mut bytes).unwrap_err();
        assert!(e.to_string().contains("stopped after 7 bytes"), "{e}");
        std::fs::remove_dir_all(&d).unwrap();
    }

    /// A file read is known by its identity under any of its names.
    #[test]
    fn a_file_read_is_known_under_any_name() {
        let d = scratch("identity");
        let f = d.join("plant.toml");
        std::fs::write(&f, "[plant]\n").unwrap();
        assert_eq!(read_as(&f), None);
        read_bounded(&f, 100).unwrap();
        std::fs::hard_link(&f, d.join("other.toml")).unwrap();
        assert_eq!(read_as(&d.join("other.toml")), Some(f.clone()));
        assert_eq!(read_as(&d.join(".").join("plant.toml")), Some(f.clone()));
        assert_eq!(read_as(&d.join("new.toml")), None);
        // once the input's path is gone, its inode is no longer its own
        std::fs::remove_file(&f).unwrap();
        assert_eq!(read_as(&d.join("other.toml")), None);
        std::fs::remove_dir_all(&d).unwrap();
    }

    #[test]
    fn long_lines_are_cut() {
        assert_eq!(excerpt("1,2"), "\"1,2\"");
        let long = "x".repeat(10_000);
        let e = excerpt(&long);
        // 200 x's, the quotes, and the count of the other 9800
        assert!(e.starts_with(&format!("\"{}\"…", "x".repeat(200))), "{e}");
        assert!(e.ends_with("(9800 more chars)") && e.len() < 230, "{e}");
    }
}
