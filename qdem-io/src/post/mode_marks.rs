//! Natural frequencies to mark on spectra (`qdem analyze --modes`): the modes of a
//! `modes.csv` written by `qdem modes` that move a sizeable share of the mass, so that a
//! spectrum's peaks can be read against them (paper 000 §4.2 reads the sleeper's spectra
//! against its rigid vertical and bending modes); and reference frequencies given by hand
//! (`qdem analyze --mark 100=paper`: a peak a paper reports).

use std::path::{Path, PathBuf};
use thiserror::Error;

/// The largest effective mass fraction a mode must reach to be marked: on a settled bed the
/// modes of single loose stones move less than 1% of the mass each, the sleeper's more than
/// 5% (docs/modes.md).
pub const MARKED_FRACTION: f64 = 0.05;

/// A mode to mark.
#[derive(Clone, Debug, PartialEq)]
pub struct ModeMark {
    /// Its number in `modes.csv`.
    pub mode: usize,
    /// Its frequency (Hz).
    pub frequency_hz: f64,
    /// Its dominant direction (`x` … `rz`).
    pub direction: String,
}

impl ModeMark {
    /// The label drawn beside its line: `mode 44 (ry)`.
    pub fn label(&self) -> String {
        format!("mode {} ({})", self.mode, self.direction)
    }
}

/// A frequency given by hand to mark (`--mark HZ=LABEL`): a peak a paper or a peer reports.
#[derive(Clone, Debug, PartialEq)]
pub struct ReferenceMark {
    /// Its frequency (Hz).
    pub frequency_hz: f64,
    /// What it is, drawn beside its line.
    pub label: String,
}

impl std::str::FromStr for ReferenceMark {
    type Err = String;

    /// Reads `HZ=LABEL` (`100=paper rigid`); `HZ` alone labels the line with its frequency.
    ///
    /// ```
    /// use qdem_io::mode_marks::ReferenceMark;
    /// let mark: ReferenceMark = "320=paper: ballast-sleeper".parse().unwrap();
    /// assert_eq!(mark.frequency_hz, 320.0);
    /// assert_eq!(mark.label, "paper: ballast-sleeper");
    /// assert!("-5=x".parse::<ReferenceMark>().is_err());
    /// ```
    fn from_str(text: &str) -> Result<Self, String> {
        let (hz, label) = text.split_once('=').unwrap_or((text, ""));
        let frequency_hz = hz
            .trim()
            .parse::<f64>()
            .ok()
            .filter(|f| f.is_finite() && *f > 0.0)
            .ok_or_else(|| {
                format!("`{text}`: expected HZ=LABEL with HZ a positive frequency, e.g. 100=paper")
            })?;
        let label = match label.trim() {
            "" => format!("{frequency_hz} Hz"),
            l => l.to_string(),
        };
        Ok(ReferenceMark {
            frequency_hz,
            label,
        })
    }
}

/// Why a `modes.csv` cannot be read.
#[derive(Debug, Error)]
pub enum ModeMarksError {
    /// The file cannot be read.
    #[error("{path}: {source}; write it with `qdem modes SCENE`")]
    Read {
        /// The file.
        path: PathBuf,
        /// Why.
        source: std::io::Error,
    },
    /// A line is not a row of `modes.csv`.
    #[error("{path}:{line}: {message} (expected the modes.csv that `qdem modes` writes)")]
    Format {
        /// The file.
        path: PathBuf,
        /// Line (1-based).
        line: usize,
        /// What is wrong.
        message: String,
    },
}

/// The elastic modes of the `modes.csv` at `path` whose largest effective mass fraction
/// (`participation`) is at least [`MARKED_FRACTION`], in file order.
///
/// ```
/// let dir = std::env::temp_dir().join(format!("qdem-mode-marks-doc-{}", std::process::id()));
/// std::fs::create_dir_all(&dir).unwrap();
/// let csv = dir.join("modes.csv");
/// std::fs::write(&csv, format!("{}\n\
///     1,5.5,elastic,rz,0.255,0,0,0,0,0,0.255,0,1,0\n\
///     2,6.1,elastic,x,0.004,0.004,0,0,0,0,0,1,0,0\n", qdem_io::modes::MODES_HEADER)).unwrap();
/// let marks = qdem_io::mode_marks::read_mode_marks(&csv).unwrap();
/// assert_eq!(marks.len(), 1);
/// assert_eq!(marks[0].label(), "mode 1 (rz)");
/// ```
pub fn read_mode_marks(path: &Path) -> Result<Vec<ModeMark>, ModeMarksError> {
    let text = std::fs::read_to_string(path).map_err(|source| ModeMarksError::Read {
        path: path.to_path_buf(),
        source,
    })?;
    let format = |line: usize, message: String| ModeMarksError::Format {
        path: path.to_path_buf(),
        line,
        message,
    };
    let mut lines = text.lines();
    if lines.next() != Some(crate::modes::MODES_HEADER) {
        return Err(format(1, "the header is not modes.csv's".to_string()));
    }
    let mut marks = Vec::new();
    for (i, line) in lines.enumerate() {
        let cells: Vec<&str> = line.split(',').collect();
        let number = |k: usize| -> Result<f64, ModeMarksError> {
            let cell = cells.get(k).copied().unwrap_or("");
            cell.parse()
                .map_err(|_| format(i + 2, format!("column {} is `{cell}`, not a number", k + 1)))
        };
        let (frequency_hz, participation) = (number(1)?, number(4)?);
        let (kind, direction) = (cells.get(2).copied(), cells.get(3).copied());
        if kind == Some("elastic") && participation >= MARKED_FRACTION {
            marks.push(ModeMark {
                mode: number(0)? as usize,
                frequency_hz,
                direction: direction.unwrap_or("").to_string(),
            });
        }
    }
    Ok(marks)
}
