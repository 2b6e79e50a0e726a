//! Reading a user's file with its size known first: never more than a stated
//! limit, whatever the path names (`/dev/zero`, a FIFO, a 10 GB log). A file
//! over the limit is refused with its size (or "more than" the limit for a
//! stream) before its content is parsed.

use std::io::Read;
use std::path::Path;

/// Largest scene or plant file read \[bytes\]: 1 MiB, about 100× the longest
/// scene in `scenes/`.
pub const MAX_SCENE_BYTES: u64 = 1 << 20;

/// At most `limit` bytes of `path`; an error (kind `InvalidData`) naming the
/// size when the file is larger. Reads at most `limit + 1` bytes, so a
/// device or FIFO without end costs no more than a regular file.
///
/// # Errors
/// Opening or reading fails, or the file has more than `limit` bytes.
pub fn read_bounded(path: &Path, limit: u64) -> std::io::Result<Vec<u8>> {
    let file = std::fs::File::open(path)?;
    let too_big = |size: String| {
        std::io::Error::new(
            std::io::ErrorKind::InvalidData,
            format!("{size}: more than the {limit} bytes this input may have"),
        )
    };
    let meta = file.metadata()?;
    if meta.is_dir() {
        return Err(std::io::Error::new(
            std::io::ErrorKind::InvalidInput,
            "is a directory, not a file",
        ));
    }
    if meta.is_file() && meta.len() > limit {
        return Err(too_big(format!("{} bytes", meta.len())));
    }
    let mut bytes = Vec::new();
    file.take(limit.saturating_add(1)).read_to_end(&mut bytes)?;
    if bytes.len() as u64 > limit {
        return Err(too_big(format!(
            "reading stopped after {} bytes",
            bytes.len()
        )));
    }
    Ok(bytes)
}

/// [`read_bounded`] as UTF-8 text.
///
/// # Errors
/// As [`read_bounded`], or the bytes are not UTF-8 (kind `InvalidData`,
/// with the offset of the first bad byte).
pub fn read_text_bounded(path: &Path, limit: u64) -> std::io::Result<String> {
    String::from_utf8(read_bounded(path, limit)?).map_err(|e| {
        std::io::Error::new(
            std::io::ErrorKind::InvalidData,
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

    #[test]
    fn a_stream_without_end_is_cut_at_the_limit() {
        // /dev/zero never ends: the read stops at limit + 1 bytes
        let e = read_bounded(Path::new("/dev/zero"), 1000).unwrap_err();
        assert!(
            e.to_string()
                .contains("stopped after 1001 bytes: more than the 1000"),
            "{e}"
        );
        // Not crate::testing::scratch_dir: testing reads scenes, which read
        // input (a module cycle).
        let d = std::env::temp_dir().join(format!("ivt-input-bounded-{}", std::process::id()));
        std::fs::create_dir_all(&d).unwrap();
        let f = d.join("small.toml");
        std::fs::write(&f, "x = 1\n").unwrap();
        assert_eq!(read_text_bounded(&f, 6).unwrap(), "x = 1\n");
        let e = read_text_bounded(&f, 5).unwrap_err().to_string();
        assert!(e.contains("6 bytes: more than the 5"), "{e}");
        std::fs::write(&f, b"a\xffb").unwrap();
        let e = read_text_bounded(&f, 10).unwrap_err().to_string();
        assert!(e.contains("not UTF-8 text (byte 1)"), "{e}");
        assert!(read_bounded(&d, 10).is_err());
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
