//! Positions in a TOML source (scenes, plant files; the CLI's harmonic-balance
//! model files), from toml's own spans: the line and column
//! of a key path (`controller.law`, `outputs.channels[1].name`) and the key
//! path at a byte offset (for serde errors, which carry only a span).

use std::ops::Range;
use toml::de::{DeTable, DeValue};
use toml::Spanned;

/// The parsed document with its spans (None if the text is not TOML).
pub struct Doc<'s> {
    src: &'s str,
    root: Option<Spanned<DeTable<'s>>>,
}

/// One step of a key path.
enum Seg<'k> {
    Key(&'k str),
    Index(usize),
}

fn segments(path: &str) -> Vec<Seg<'_>> {
    let mut out = Vec::new();
    for part in path.split('.') {
        let (key, rest) = part.split_once('[').unwrap_or((part, ""));
        out.push(Seg::Key(key));
        for idx in rest.split('[') {
            if let Ok(k) = idx.trim_end_matches(']').parse() {
                out.push(Seg::Index(k));
            }
        }
    }
    out
}

impl<'s> Doc<'s> {
    /// The document of `src` (without spans if `src` is not TOML).
    #[must_use]
    pub fn new(src: &'s str) -> Self {
        Self {
            src,
            root: DeTable::parse(src).ok(),
        }
    }

    /// `origin:line:col` of the start of `span`, or `origin` without one.
    #[must_use]
    pub fn at(&self, origin: &str, span: Option<Range<usize>>) -> String {
        match span {
            Some(s) => {
                let (line, col) = self.line_col(s.start);
                format!("{origin}:{line}:{col}")
            }
            None => origin.to_string(),
        }
    }

    /// A deserialization error of this document as one line: its position,
    /// the key path there and toml's message.
    #[must_use]
    pub fn serde_error(&self, origin: &str, e: &toml::de::Error) -> String {
        let key = e
            .span()
            .and_then(|s| self.path_at(s.start))
            .map(|k| format!("`{k}`: "))
            .unwrap_or_default();
        let msg = e.message().replace('\n', " ");
        format!("{}: {key}{}", self.at(origin, e.span()), msg.trim())
    }

    /// 1-based (line, column) of byte `offset`.
    pub fn line_col(&self, offset: usize) -> (usize, usize) {
        let before = &self.src[..floor_char_boundary(self.src, offset)];
        let line = before.matches('\n').count() + 1;
        let col = before.rsplit('\n').next().map_or(0, |l| l.chars().count()) + 1;
        (line, col)
    }

    /// Span of the key that names `path` (its value's span for array
    /// elements); None when the key is not in the source (a default).
    pub fn span_of(&self, path: &str) -> Option<Range<usize>> {
        let root = self.root.as_ref()?;
        let mut table = root.get_ref();
        let mut value: Option<&Spanned<DeValue<'_>>> = None;
        let mut span = None;
        for seg in segments(path) {
            match seg {
                Seg::Key(k) => {
                    if let Some(v) = value {
                        table = match v.get_ref() {
                            DeValue::Table(t) => t,
                            _ => return None,
                        };
                    }
                    let (key, v) = table.iter().find(|(key, _)| key.get_ref() == k)?;
                    span = Some(key.span());
                    value = Some(v);
                }
                Seg::Index(i) => {
                    let DeValue::Array(a) = value?.get_ref() else {
                        return None;
                    };
                    let v = a.get(i)?;
                    span = Some(v.span());
                    value = Some(v);
                }
            }
        }
        span
    }

    /// The dotted key path whose key or value holds byte `offset`
    /// (innermost), e.g. `controller.law`; None outside every key.
    pub fn path_at(&self, offset: usize) -> Option<String> {
        path_in(self.root.as_ref()?.get_ref(), offset)
    }
}

/// [`Doc::path_at`] below `table`. Tables are searched by their entries'
/// spans (a `[section]` table's own span is only its header).
fn path_in(table: &DeTable<'_>, offset: usize) -> Option<String> {
    for (key, v) in table {
        let name = key.get_ref();
        if key.span().contains(&offset) {
            return Some(name.to_string());
        }
        let inner = match v.get_ref() {
            DeValue::Table(t) => path_in(t, offset).map(|p| format!("{name}.{p}")),
            DeValue::Array(a) => a.iter().enumerate().find_map(|(i, e)| match e.get_ref() {
                DeValue::Table(t) => path_in(t, offset).map(|p| format!("{name}[{i}].{p}")),
                _ => e.span().contains(&offset).then(|| format!("{name}[{i}]")),
            }),
            _ => None,
        };
        if inner.is_some() {
            return inner;
        }
        if v.span().contains(&offset) {
            return Some(name.to_string());
        }
    }
    None
}

fn floor_char_boundary(s: &str, i: usize) -> usize {
    let mut i = i.min(s.len());
    while !s.is_char_boundary(i) {
        i -= 1;
    }
    i
}
