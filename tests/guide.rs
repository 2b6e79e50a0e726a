//! The guide's (docs/guide) conventions that make every code block run in CI:
//!
//! - every chapter file is listed in `SUMMARY.md` and every listed file exists;
//! - every chapter is included by `src/lib.rs` as a `#[cfg(doctest)]` module,
//!   so its ```rust blocks are doctests of the root crate;
//! - every fenced block is ```rust (a doctest), ```python or ```console (run by
//!   crates/ivt-py/tests/test_guide.py) or ```text (output shown); any other
//!   fence, a bare one or ```rust,ignore included, is refused here.
// A test may expect (the package's panic lints guard library code).
#![allow(clippy::expect_used)]

use std::collections::BTreeSet;
use std::path::{Path, PathBuf};

/// The book's source directory.
fn guide_src() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("docs/guide/src")
}

/// Every Markdown chapter under `dir` but SUMMARY.md, as paths relative to
/// the book's source directory (`model/orbit.md`).
fn chapters(dir: &Path, out: &mut BTreeSet<String>) {
    let mut entries: Vec<_> = std::fs::read_dir(dir)
        .expect("read the guide's source directory")
        .map(|e| e.expect("directory entry").path())
        .collect();
    entries.sort();
    for path in entries {
        if path.is_dir() {
            chapters(&path, out);
        } else if path.extension().is_some_and(|e| e == "md") && !path.ends_with("SUMMARY.md") {
            let rel = path.strip_prefix(guide_src()).expect("under the guide");
            out.insert(rel.to_string_lossy().replace('\\', "/"));
        }
    }
}

fn all_chapters() -> BTreeSet<String> {
    let mut out = BTreeSet::new();
    chapters(&guide_src(), &mut out);
    assert!(out.len() >= 20, "the book's chapters: {out:?}");
    out
}

/// The link targets `(path.md)` of SUMMARY.md.
fn summary_targets() -> BTreeSet<String> {
    let summary = std::fs::read_to_string(guide_src().join("SUMMARY.md")).expect("SUMMARY.md");
    summary
        .split("](")
        .skip(1)
        .filter_map(|rest| rest.split(')').next())
        .map(str::to_owned)
        .collect()
}

#[test]
fn summary_lists_exactly_the_chapter_files() {
    let files = all_chapters();
    let listed = summary_targets();
    let unlisted: Vec<_> = files.difference(&listed).collect();
    let missing: Vec<_> = listed.difference(&files).collect();
    assert!(
        unlisted.is_empty(),
        "chapters not in SUMMARY.md: {unlisted:?}"
    );
    assert!(
        missing.is_empty(),
        "SUMMARY.md entries without a file: {missing:?}"
    );
}

#[test]
fn every_chapter_is_a_doctest_module_of_the_root_crate() {
    let lib = std::fs::read_to_string(Path::new(env!("CARGO_MANIFEST_DIR")).join("src/lib.rs"))
        .expect("src/lib.rs");
    let doctest_part = lib
        .split("#[cfg(doctest)]")
        .nth(1)
        .expect("src/lib.rs has a #[cfg(doctest)] module of guide chapters");
    let missing: Vec<_> = all_chapters()
        .into_iter()
        .filter(|c| {
            !doctest_part.contains(&format!("#[doc = include_str!(\"../docs/guide/src/{c}\")]"))
        })
        .collect();
    assert!(
        missing.is_empty(),
        "chapters not included as doctests in src/lib.rs: {missing:?}"
    );
}

/// The fence languages the guide's runners know.
const KNOWN_FENCES: [&str; 4] = ["rust", "python", "console", "text"];

/// `(line number, info string)` of every opening fence of a Markdown text
/// (``` or ~~~, any indentation; a closing fence has the opening's marker).
fn opening_fences(text: &str) -> Vec<(usize, String)> {
    let mut out = Vec::new();
    let mut open: Option<String> = None;
    for (i, line) in text.lines().enumerate() {
        let trimmed = line.trim_start();
        let marker_len = |c: char| trimmed.chars().take_while(|&x| x == c).count();
        let (marker, n) = match (marker_len('`'), marker_len('~')) {
            (n, _) if n >= 3 => ("`", n),
            (_, n) if n >= 3 => ("~", n),
            _ => continue,
        };
        let fence = marker.repeat(n);
        match &open {
            Some(o) if trimmed.starts_with(o.as_str()) && trimmed[n..].trim().is_empty() => {
                open = None;
            }
            Some(_) => {}
            None => {
                out.push((i + 1, trimmed[n..].trim().to_owned()));
                open = Some(fence);
            }
        }
    }
    assert!(open.is_none(), "a fence is never closed");
    out
}

#[test]
fn every_code_block_has_a_known_language() {
    let mut bad = Vec::new();
    for chapter in all_chapters() {
        let text = std::fs::read_to_string(guide_src().join(&chapter)).expect("chapter");
        for (line, info) in opening_fences(&text) {
            let mut words = info.split([',', ' ']);
            let lang = words.next().unwrap_or("");
            // `ignore` would keep a Rust block from running at all.
            if !KNOWN_FENCES.contains(&lang) || words.any(|w| w == "ignore") {
                bad.push(format!("{chapter}:{line}: ```{info}"));
            }
        }
    }
    assert!(
        bad.is_empty(),
        "code blocks the guide's runners do not run (use rust, python, console or text): {bad:#?}"
    );
}

#[test]
fn fence_reader_sees_languages_and_bare_fences() {
    let text = "a\n```python\nx = 1\n```\n\n  ```\nbare\n  ```\n~~~text\n```\n~~~\n";
    assert_eq!(
        opening_fences(text),
        vec![
            (2, "python".to_owned()),
            (6, String::new()),
            (9, "text".to_owned())
        ]
    );
}

/// Issue 31's limits: the root README ≤ 10 KB (the two commands, the crate
/// map, the links), each crate's and the firmware's ≤ 8 KB (what it is, one
/// example, where its chapter is); the tables live in the guide.
#[test]
fn readmes_stay_short() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let size = |p: &Path| std::fs::metadata(p).map(|m| m.len()).unwrap_or(u64::MAX);
    let readme = root.join("README.md");
    assert!(
        size(&readme) <= 10 * 1024,
        "{}: {} bytes",
        readme.display(),
        size(&readme)
    );
    let mut crates: Vec<PathBuf> = std::fs::read_dir(root.join("crates"))
        .unwrap()
        .map(|e| e.unwrap().path().join("README.md"))
        .collect();
    crates.push(root.join("firmware/README.md"));
    assert!(crates.len() >= 10, "{crates:?}");
    for readme in crates {
        assert!(
            size(&readme) <= 8 * 1024,
            "{}: {} bytes",
            readme.display(),
            size(&readme)
        );
    }
}
