//! A strict reader of real square Matrix Market files (the NIST exchange
//! format FE codes export), into a dense row-major matrix for the model files
//! of `ivt hb frc|solve`.
//!
//! Accepted: `%%MatrixMarket matrix coordinate|array real|integer
//! general|symmetric`. Refused with the line that breaks the rule: complex,
//! pattern, hermitian and skew-symmetric files, a non-square size, more than
//! [`MAX_DOFS`] rows, an index outside the size, an upper-triangle entry of a
//! symmetric file, a non-finite value, too few or too many entries. Repeated
//! coordinates are summed (as `scipy.io.mmread(...).toarray()`, the Python
//! side's reader). The file is read through [`ivt_sim::input`], so its size
//! budget holds before a byte is parsed.

use std::path::Path;

/// Most rows of a matrix read: the dense harmonic-balance engine's limit of
/// unknowns ([`ivt_hb::limits::MAX_UNKNOWNS`]) with one harmonic; the
/// dense copy is then at most 128 MiB.
pub const MAX_DOFS: usize = ivt_hb::limits::MAX_UNKNOWNS;

/// Largest Matrix Market file read \[bytes\]: 64 MiB, about two million
/// coordinate entries.
pub const MAX_BYTES: u64 = 64 << 20;

/// Why a file could not be read: the OS's error (kind `io`) or the content
/// (kind `input`), each a message without the path.
#[derive(Debug)]
pub enum ReadError {
    /// Opening or reading failed.
    Io(String),
    /// The content is not an accepted Matrix Market matrix.
    Format(String),
}

/// `(n, entries)` of the square matrix in `path`, row-major `n × n`.
///
/// # Errors
/// [`ReadError::Io`] when the file cannot be read within [`MAX_BYTES`];
/// [`ReadError::Format`] naming the line that breaks the format.
pub fn read(path: &Path) -> Result<(usize, Vec<f64>), ReadError> {
    let text = ivt_sim::input::read_text_bounded(path, MAX_BYTES)
        .map_err(|e| ReadError::Io(e.to_string()))?;
    parse(&text).map_err(ReadError::Format)
}

/// Layout of the entries.
#[derive(Clone, Copy, PartialEq)]
enum Layout {
    Coordinate,
    Array,
}

/// [`read`] on the text of a file.
fn parse(text: &str) -> Result<(usize, Vec<f64>), String> {
    let mut lines = text.lines().enumerate().map(|(i, l)| (i + 1, l));
    let (_, banner) = lines
        .next()
        .ok_or("empty file (no %%MatrixMarket banner)")?;
    let (layout, symmetric) = banner_of(banner)?;
    let mut data = lines.filter(|(_, l)| !(l.trim().is_empty() || l.starts_with('%')));
    let (size_line, size) = data.next().ok_or("no size line")?;
    let dims: Vec<usize> = size
        .split_whitespace()
        .map(str::parse)
        .collect::<Result<_, _>>()
        .map_err(|_| format!("line {size_line}: size {} is not integers", excerpt(size)))?;
    let (n, count) = match (layout, dims.as_slice()) {
        (Layout::Coordinate, &[r, c, nnz]) if r == c => (r, nnz),
        (Layout::Array, &[r, c]) if r == c => (r, 0),
        _ => {
            return Err(format!(
                "line {size_line}: size {} must be `n n nnz` (coordinate) or `n n` (array) of a square matrix",
                excerpt(size)
            ))
        }
    };
    if n == 0 || n > MAX_DOFS {
        return Err(format!(
            "line {size_line}: {n} rows; a model has 1 to {MAX_DOFS} DOFs"
        ));
    }
    // n ≤ 4096: no overflow.
    let stored = if symmetric { n * (n + 1) / 2 } else { n * n };
    // A coordinate file may repeat an entry (summed), so its count is not
    // bounded by n²; nothing is allocated by it, and the file's size bounds
    // the lines read.
    let count = match layout {
        Layout::Array => stored,
        Layout::Coordinate => count,
    };
    let mut a = vec![0.0; n * n];
    let mut seen = 0;
    for (line, l) in data {
        if seen == count {
            return Err(format!(
                "line {line}: more than the {count} entries the size line declares"
            ));
        }
        let (i, j, v) = match layout {
            Layout::Coordinate => coordinate(l, n).map_err(|e| format!("line {line}: {e}"))?,
            Layout::Array => {
                let (i, j) = array_position(seen, n, symmetric);
                (
                    i,
                    j,
                    value(l.trim()).map_err(|e| format!("line {line}: {e}"))?,
                )
            }
        };
        if symmetric && j > i {
            return Err(format!(
                "line {line}: entry ({}, {}) above the diagonal of a symmetric file (only the lower triangle is stored)",
                i + 1,
                j + 1
            ));
        }
        add(&mut a, n, i, j, v);
        if symmetric && i != j {
            add(&mut a, n, j, i, v);
        }
        seen += 1;
    }
    if seen < count {
        return Err(format!(
            "{seen} entries, but the size line declares {count}"
        ));
    }
    Ok((n, a))
}

/// `a[i][j] += v` (i, j < n, checked by the callers).
fn add(a: &mut [f64], n: usize, i: usize, j: usize, v: f64) {
    if let Some(x) = a.get_mut(i * n + j) {
        *x += v;
    }
}

/// The layout and symmetry the banner declares.
fn banner_of(banner: &str) -> Result<(Layout, bool), String> {
    let words: Vec<String> = banner
        .split_whitespace()
        .map(str::to_ascii_lowercase)
        .collect();
    let words: Vec<&str> = words.iter().map(String::as_str).collect();
    let [head, "matrix", layout, field, symmetry] = words.as_slice() else {
        return Err(format!(
            "line 1: {} is not a `%%MatrixMarket matrix <layout> <field> <symmetry>` banner",
            excerpt(banner)
        ));
    };
    if *head != "%%matrixmarket" {
        return Err(format!(
            "line 1: {} does not start with %%MatrixMarket",
            excerpt(banner)
        ));
    }
    let layout = match *layout {
        "coordinate" => Layout::Coordinate,
        "array" => Layout::Array,
        other => return Err(format!("line 1: layout `{other}`: coordinate or array")),
    };
    if !matches!(*field, "real" | "integer" | "double") {
        return Err(format!(
            "line 1: field `{field}`: real or integer (a model's M, C, K are real; complex structural damping is not supported)"
        ));
    }
    let symmetric = match *symmetry {
        "general" => false,
        "symmetric" => true,
        other => return Err(format!("line 1: symmetry `{other}`: general or symmetric")),
    };
    Ok((layout, symmetric))
}

/// `(i, j, v)` (0-based) of a coordinate line `i j v` (1-based indices ≤ n).
fn coordinate(line: &str, n: usize) -> Result<(usize, usize, f64), String> {
    let parts: Vec<&str> = line.split_whitespace().collect();
    let &[i, j, v] = parts.as_slice() else {
        return Err(format!("{} is not `row column value`", excerpt(line)));
    };
    let index = |s: &str| match s.parse::<usize>() {
        Ok(k) if (1..=n).contains(&k) => Ok(k - 1),
        _ => Err(format!("index {} is not an integer in 1..={n}", excerpt(s))),
    };
    Ok((index(i)?, index(j)?, value(v)?))
}

/// The (row, column) of the `k`-th value of an array file (column-major; a
/// symmetric file stores the lower triangle, column by column).
fn array_position(k: usize, n: usize, symmetric: bool) -> (usize, usize) {
    if !symmetric {
        return (k % n, k / n);
    }
    let (mut j, mut k) = (0, k);
    while k >= n - j {
        k -= n - j;
        j += 1;
    }
    (j + k, j)
}

/// A finite number.
fn value(s: &str) -> Result<f64, String> {
    match s.parse::<f64>() {
        Ok(v) if v.is_finite() => Ok(v),
        _ => Err(format!("value {} is not a finite number", excerpt(s))),
    }
}

fn excerpt(s: &str) -> String {
    ivt_sim::input::excerpt(s)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn coordinate_symmetric_and_array_files_give_the_same_matrix() {
        // [[2, -1], [-1, 3]] three ways; the repeated (1,1) entry is summed.
        let general = "%%MatrixMarket matrix coordinate real general\n% c\n2 2 5\n1 1 1.5\n1 1 0.5\n1 2 -1\n2 1 -1\n2 2 3\n";
        let symmetric =
            "%%MatrixMarket matrix coordinate real symmetric\n2 2 3\n1 1 2\n2 1 -1\n2 2 3\n";
        let array = "%%MatrixMarket matrix array real general\n2 2\n2\n-1\n-1\n3\n";
        let lower = "%%MatrixMarket matrix array real symmetric\n2 2\n2\n-1\n3\n";
        for text in [general, symmetric, array, lower] {
            assert_eq!(
                parse(text).unwrap(),
                (2, vec![2.0, -1.0, -1.0, 3.0]),
                "{text}"
            );
        }
    }

    #[test]
    fn broken_files_name_the_line() {
        let cases = [
            (
                "%%MatrixMarket matrix coordinate complex general\n1 1 1\n1 1 1 0\n",
                "line 1",
            ),
            (
                "%%MatrixMarket matrix coordinate real general\n2 3 1\n1 1 1\n",
                "line 2",
            ),
            (
                "%%MatrixMarket matrix coordinate real general\n2 2 1\n3 1 1\n",
                "line 3",
            ),
            (
                "%%MatrixMarket matrix coordinate real general\n2 2 1\n1 1 nan\n",
                "line 3",
            ),
            (
                "%%MatrixMarket matrix coordinate real symmetric\n2 2 1\n1 2 1\n",
                "line 3",
            ),
            (
                "%%MatrixMarket matrix coordinate real general\n2 2 1\n1 1 1\n2 2 1\n",
                "line 4",
            ),
            (
                "%%MatrixMarket matrix coordinate real general\n2 2 2\n1 1 1\n",
                "declares 2",
            ),
            (
                "%%MatrixMarket matrix coordinate real general\n5000 5000 1\n1 1 1\n",
                "line 2",
            ),
        ];
        for (text, want) in cases {
            let e = parse(text).unwrap_err();
            assert!(e.contains(want), "{text}: {e}");
        }
    }
}
