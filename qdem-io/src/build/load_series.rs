//! `[[load]] series`: a load's time factor read from a CSV file (paper 000 §4 drives the
//! sleeper with the rail-seat pressures measured at 10 kHz and interpolates them linearly to
//! the 10⁻⁷ s step).
//!
//! The file has a header row naming its columns; the first column is time in seconds,
//! non-decreasing; the named column gives the factor. The factor becomes a piecewise-linear
//! [`qdem_core::loads::TimeFunction`] (held before the first and after the last row).

use crate::build::BuildError;
use std::path::Path;

/// The `(time, value)` rows of column `column` of the CSV file at `path`.
///
/// # Errors
/// [`BuildError::Series`] naming the file and line: unreadable file, no such column, a row
/// with too few fields or a field that is not a finite number, time going backwards, or no
/// data row.
pub(crate) fn read_series(path: &Path, column: &str) -> Result<Vec<(f64, f64)>, BuildError> {
    let refused = |line: usize, message: String| BuildError::Series {
        path: path.to_path_buf(),
        line,
        message,
    };
    let text = std::fs::read_to_string(path).map_err(|e| refused(0, e.to_string()))?;
    let mut lines = text
        .lines()
        .enumerate()
        .filter(|(_, l)| !l.trim().is_empty());
    let (_, header) = lines
        .next()
        .ok_or_else(|| refused(1, "the file is empty".to_string()))?;
    let names: Vec<&str> = header.split(',').map(str::trim).collect();
    let Some(index) = names
        .iter()
        .skip(1)
        .position(|n| *n == column)
        .map(|i| i + 1)
    else {
        return Err(refused(
            1,
            format!(
                "no column `{column}` after the time column (the header has {})",
                names.join(", ")
            ),
        ));
    };
    let mut rows: Vec<(f64, f64)> = Vec::new();
    for (i, line) in lines {
        let fields: Vec<&str> = line.split(',').map(str::trim).collect();
        let number = |k: usize| -> Result<f64, BuildError> {
            let field = fields.get(k).ok_or_else(|| {
                refused(
                    i + 1,
                    format!("{} fields, column {} missing", fields.len(), k + 1),
                )
            })?;
            field
                .parse::<f64>()
                .ok()
                .filter(|v| v.is_finite())
                .ok_or_else(|| refused(i + 1, format!("`{field}` is not a finite number")))
        };
        let (t, v) = (number(0)?, number(index)?);
        if let Some(&(previous, _)) = rows.last() {
            if t < previous {
                return Err(refused(
                    i + 1,
                    format!("time {t} s comes after {previous} s"),
                ));
            }
        }
        rows.push((t, v));
    }
    if rows.is_empty() {
        return Err(refused(2, "no data row after the header".to_string()));
    }
    Ok(rows)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn file(name: &str, text: &str) -> std::path::PathBuf {
        let path = std::env::temp_dir().join(format!("qdem-series-{}-{name}", std::process::id()));
        std::fs::write(&path, text).unwrap();
        path
    }

    #[test]
    fn a_column_is_read_and_bad_files_name_their_line() {
        let good = file("good.csv", "time,Rp1,Rp2\n0,1,2\n0.5,3,4\n");
        assert_eq!(
            read_series(&good, "Rp2").unwrap(),
            vec![(0.0, 2.0), (0.5, 4.0)]
        );
        let line = |text: &str, column: &str| match read_series(&file("bad.csv", text), column) {
            Err(BuildError::Series { line, .. }) => line,
            other => panic!("expected a series error, got {other:?}"),
        };
        assert_eq!(line("time,Rp1\n0,1\n", "Rp3"), 1);
        assert_eq!(line("time,Rp1\n0,1\n1,x\n", "Rp1"), 3);
        assert_eq!(line("time,Rp1\n0,1\n1\n", "Rp1"), 3);
        assert_eq!(line("time,Rp1\n1,1\n0,1\n", "Rp1"), 3);
        assert_eq!(line("time,Rp1\n", "Rp1"), 2);
        assert_eq!(line("time,Rp1\n0,inf\n", "Rp1"), 2);
    }
}
