//! Pulse logs replayed through the controller (`ivt ctrl replay`, SPEC §6):
//! CSV with one encoder pulse per row, columns `ticks[,vm,tu]` (raw timer
//! captures, V, N·m), by name when a header gives them (in any order), else
//! in that order. Never read by position under a header, never more than
//! [`MAX_PULSES`] rows.

use crate::input::excerpt;

/// One row of the log.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PulseRow {
    /// The timer capture of the pulse.
    pub ticks: u32,
    /// `(V_m, T_U)` read with it, when the log has those columns.
    pub inputs: Option<(f32, f32)>,
}

/// A malformed log: one line naming the line number and the problem.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("{0}")]
pub struct PulseLogError(pub String);

/// Most pulses of one replayed log: about 3 h at 100 rpm and 1200 PPR, and
/// ~200 MB of JSON output.
pub const MAX_PULSES: usize = 1_000_000;

/// Largest pulse log read \[bytes\]: [`MAX_PULSES`] rows of up to 64 bytes.
pub const MAX_LOG_BYTES: u64 = 64 * MAX_PULSES as u64;

/// Where each field is in a row: from the header by name (`ticks`, `vm` or
/// `v_m`, `tu` or `t_u`, in any order), or `ticks[,vm,tu]` by position in a
/// log without a header.
#[derive(Clone, Copy, Debug, PartialEq)]
struct Columns {
    ticks: usize,
    inputs: Option<(usize, usize)>,
    count: usize,
}

impl Columns {
    /// The documented order, for a log without a header.
    fn positional(count: usize) -> Option<Self> {
        match count {
            1 => Some(Self {
                ticks: 0,
                inputs: None,
                count,
            }),
            3 => Some(Self {
                ticks: 0,
                inputs: Some((1, 2)),
                count,
            }),
            _ => None,
        }
    }

    /// The columns a header names; every name must be known and given once,
    /// `ticks` is required, `vm` and `tu` come together.
    fn from_header(names: &[&str]) -> Result<Self, String> {
        let mut slots: [Option<usize>; 3] = [None; 3];
        for (i, name) in names.iter().enumerate() {
            let slot = match name.to_ascii_lowercase().as_str() {
                "ticks" => 0,
                "vm" | "v_m" => 1,
                "tu" | "t_u" => 2,
                _ => {
                    return Err(format!(
                        "unknown column {} (known: ticks, vm or v_m, tu or t_u)",
                        excerpt(name)
                    ))
                }
            };
            match slots.get_mut(slot) {
                Some(s @ None) => *s = Some(i),
                _ => return Err(format!("column {} is given twice", excerpt(name))),
            }
        }
        let [ticks, vm, tu] = slots;
        let ticks = ticks.ok_or("the header has no `ticks` column")?;
        let inputs = match (vm, tu) {
            (Some(v), Some(t)) => Some((v, t)),
            (None, None) => None,
            _ => return Err("the header names one of vm, tu without the other".into()),
        };
        Ok(Self {
            ticks,
            inputs,
            count: names.len(),
        })
    }
}

/// The pulses of a log's text: one row per encoder pulse, blank lines and
/// `#` comments skipped, an optional header naming the columns.
///
/// # Errors
/// [`PulseLogError`] naming the line (its first [`crate::input::EXCERPT_CHARS`]
/// characters) and what is wrong: an unknown or repeated column, a row with
/// another column count, a value that does not parse, more than
/// [`MAX_PULSES`] pulses, or none.
pub fn parse_pulse_log(text: &str) -> Result<Vec<PulseRow>, PulseLogError> {
    let mut rows = Vec::new();
    let mut columns: Option<Columns> = None;
    for (n, line) in text.lines().enumerate() {
        let line = line.trim();
        if line.is_empty() || line.starts_with('#') {
            continue;
        }
        let bad = |what: &str| PulseLogError(format!("line {}: {what}: {}", n + 1, excerpt(line)));
        let cols: Vec<&str> = line.split(',').map(str::trim).collect();
        let first = cols.first().copied().unwrap_or("");
        let layout = match columns {
            Some(c) => c,
            None if first.parse::<f64>().is_err() => {
                // the header: the columns by name
                columns = Some(Columns::from_header(&cols).map_err(|e| bad(&e))?);
                continue;
            }
            None => {
                let c = Columns::positional(cols.len()).ok_or_else(|| {
                    bad("expected columns ticks[,vm,tu] (or a header naming them)")
                })?;
                columns = Some(c);
                c
            }
        };
        if cols.len() != layout.count {
            return Err(bad(&format!(
                "{} columns where the log has {}",
                cols.len(),
                layout.count
            )));
        }
        let field = |i: usize| cols.get(i).copied().unwrap_or("");
        let ticks: u64 = field(layout.ticks)
            .parse()
            .map_err(|_| bad("ticks is not an unsigned integer"))?;
        let ticks =
            u32::try_from(ticks).map_err(|_| bad("ticks exceeds u32 (log raw timer captures)"))?;
        let inputs = match layout.inputs {
            None => None,
            Some((v, t)) => {
                // Readings are passed through unchanged (NaN included): the
                // controller's own validation is what is being replayed.
                let v: f32 = field(v).parse().map_err(|_| bad("vm is not a number"))?;
                let t: f32 = field(t).parse().map_err(|_| bad("tu is not a number"))?;
                Some((v, t))
            }
        };
        if rows.len() == MAX_PULSES {
            return Err(PulseLogError(format!(
                "the log has more than {MAX_PULSES} pulses (the JSON of more is hundreds of MB); split it"
            )));
        }
        rows.push(PulseRow { ticks, inputs });
    }
    if rows.is_empty() {
        return Err(PulseLogError("the log has no pulses".into()));
    }
    Ok(rows)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn columns_by_header_name_in_any_order() {
        let by_name = parse_pulse_log("t_u,v_m,ticks\n4,8,100\n4.5,7,600\n").unwrap();
        let by_order = parse_pulse_log("100,8,4\n600,7,4.5\n").unwrap();
        assert_eq!(by_name, by_order);
        assert_eq!(
            by_name[1],
            PulseRow {
                ticks: 600,
                inputs: Some((7.0, 4.5))
            }
        );
        let plain = parse_pulse_log("# comment\nticks\n\n5\n").unwrap();
        assert_eq!(
            plain,
            vec![PulseRow {
                ticks: 5,
                inputs: None
            }]
        );
    }

    #[test]
    fn bad_logs_name_the_line_and_the_problem() {
        let e = |t: &str| parse_pulse_log(t).unwrap_err().0;
        assert!(e("ticks,speed\n1,2\n").contains("unknown column \"speed\""));
        assert!(e("ticks,ticks\n1,2\n").contains("given twice"));
        assert!(e("vm,tu\n1,2\n").contains("no `ticks` column"));
        assert!(e("ticks,vm\n1,2\n").contains("without the other"));
        assert!(e("ticks,vm,tu\n1,2\n").starts_with("line 2: 2 columns where the log has 3"));
        assert!(e("1,2\n").contains("expected columns"));
        assert!(e("ticks\n4294967296\n").contains("exceeds u32"));
        assert!(e("# only\n").contains("no pulses"));
        // a 10 MB line is echoed as its first 200 characters
        let long = format!("ticks\n1{}\n", "9".repeat(10_000_000));
        assert!(e(&long).len() < 400);
    }
}
