//! The small CSV files scenes name and runs write (stones, poses): a fixed header line, then
//! one row of comma-separated fields per line; every malformed line is refused with its number.

use std::path::Path;

/// One data row: its 1-based line number and its trimmed fields.
pub(crate) type Row<'a> = (usize, Vec<&'a str>);

/// Reads `path`, whose first line must be `header`; `bad(line, message)` makes the error (line 0
/// when the file cannot be read).
pub(crate) fn read_text<E>(
    path: &Path,
    header: &str,
    bad: &impl Fn(usize, String) -> E,
) -> Result<String, E> {
    let text = std::fs::read_to_string(path).map_err(|e| bad(0, e.to_string()))?;
    match text.lines().next() {
        Some(h) if h.trim() == header => Ok(text),
        _ => Err(bad(1, format!("the first line must be `{header}`"))),
    }
}

/// The rows after the header of `text`, blank lines skipped, each with exactly `fields` fields.
pub(crate) fn rows<'a, E>(
    text: &'a str,
    fields: usize,
    bad: &impl Fn(usize, String) -> E,
) -> Result<Vec<Row<'a>>, E> {
    let mut out = Vec::new();
    for (i, line) in text.lines().enumerate().skip(1) {
        if line.trim().is_empty() {
            continue;
        }
        let row: Vec<&str> = line.split(',').map(str::trim).collect();
        if row.len() != fields {
            return Err(bad(
                i + 1,
                format!("expected {fields} fields, found {}", row.len()),
            ));
        }
        out.push((i + 1, row));
    }
    Ok(out)
}

/// The fields of a row as finite numbers.
pub(crate) fn finite<E, const N: usize>(
    row: &[&str],
    line: usize,
    bad: &impl Fn(usize, String) -> E,
) -> Result<[f64; N], E> {
    let mut v = [0.0; N];
    for (x, f) in v.iter_mut().zip(row) {
        *x = f
            .parse::<f64>()
            .ok()
            .filter(|x| x.is_finite())
            .ok_or_else(|| bad(line, format!("{f:?} is not a finite number")))?;
    }
    Ok(v)
}
