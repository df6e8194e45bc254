//! Probe time histories as CSV, written row by row during a run.
//!
//! Layout ([`OUTPUT_FORMAT`](super::OUTPUT_FORMAT) 2): a header line
//! `time,P.ux,P.uy,P.uz,P.vx,P.vy,P.vz,P.ax,P.ay,P.az,P.wx,P.wy,P.wz,...` (twelve columns per
//! probe `P`: displacement, velocity, acceleration, angular velocity), then five per box probe
//! `R` (`R.vx,R.vy,R.vz,R.ke,R.count`: mean velocity, kinetic energy, count of the stones
//! inside), then one line per sample time. Format 1 named the time column `t` and had no
//! angular velocity; [`ProbeCsv::resume`] refuses such a file by name.
//! Numbers are written with the shortest decimal form that parses back to the same `f64`
//! (plain notation for magnitudes in `[1e-5, 1e16)` and zero, scientific `1.5e-7`
//! otherwise; NaN and infinities as `NaN`, `inf`, `-inf`), so nothing is lost.
//!
//! The file is an [`AtomicFile`]: it appears under its name only on [`ProbeCsv::finish`];
//! a run that fails leaves any previous file untouched.

use std::io::Write;
use std::path::Path;

use nalgebra::Vector3;

use super::atomic::AtomicFile;
use super::error::{IoStage, OutputError};
use super::write_f64;

/// The name of the time column, the first of every row (`t` in output format 1).
pub const TIME_COLUMN: &str = "time";

/// The column suffixes written for each probe, in order.
pub const PROBE_COLUMNS: [&str; 12] = [
    "ux", "uy", "uz", "vx", "vy", "vz", "ax", "ay", "az", "wx", "wy", "wz",
];

/// One probe's sample: displacement (m), velocity (m/s), acceleration (m/s²) and angular
/// velocity (rad/s), the order of [`PROBE_COLUMNS`].
pub type ProbeSample = [Vector3<f64>; 4];

/// The column suffixes written for each box probe, in order.
pub const REGION_COLUMNS: [&str; 5] = ["vx", "vy", "vz", "ke", "count"];

/// A probe CSV being written.
///
/// # Example
/// ```
/// # use qdem_io::output::ProbeCsv;
/// use nalgebra::Vector3;
/// let path = std::env::temp_dir().join(format!("qdem-doc-{}-probes.csv", std::process::id()));
/// let mut csv = ProbeCsv::create(&path, &["tip".to_string()]).unwrap();
/// let (u, v, a) = (Vector3::new(0.0, 0.0, -1e-4), Vector3::zeros(), Vector3::zeros());
/// let w = Vector3::new(0.0, 2.0, 0.0);
/// csv.row(0.5, &[[u, v, a, w]]).unwrap();
/// csv.finish().unwrap();
/// let text = std::fs::read_to_string(&path).unwrap();
/// assert!(text.starts_with("time,tip.ux,tip.uy,"));
/// assert!(text.contains(",tip.wx,tip.wy,tip.wz\n0.5,"));
/// # std::fs::remove_file(&path).unwrap();
/// ```
#[derive(Debug)]
pub struct ProbeCsv {
    /// The file being written.
    file: AtomicFile,
    /// The number of probes (twelve columns each, [`PROBE_COLUMNS`]).
    num_probes: usize,
    /// The number of box probes (five columns each, after the probes').
    num_regions: usize,
    /// The number of data rows written.
    num_rows: usize,
}

impl ProbeCsv {
    /// Creates the temporary file for `path` and writes the header.
    ///
    /// # Errors
    /// [`OutputError::InvalidName`] if a probe name is empty, is used twice, or contains a
    /// comma, a double quote or a control character (names are written unquoted);
    /// [`OutputError::Io`] (or [`OutputError::NoFileName`]) if the file cannot be created.
    pub fn create(path: &Path, probe_names: &[String]) -> Result<Self, OutputError> {
        Self::with_regions(path, probe_names, &[])
    }

    /// [`ProbeCsv::create`] with box probes `region_names` after the probes (five columns
    /// each, [`REGION_COLUMNS`]); the names of both kinds must differ.
    ///
    /// # Errors
    /// Those of [`ProbeCsv::create`].
    pub fn with_regions(
        path: &Path,
        probe_names: &[String],
        region_names: &[String],
    ) -> Result<Self, OutputError> {
        let names: Vec<&String> = probe_names.iter().chain(region_names).collect();
        for (i, &name) in names.iter().enumerate() {
            let reason = if name.is_empty() {
                Some("probe names must not be empty")
            } else if name.contains([',', '"']) || name.chars().any(char::is_control) {
                Some("probe names must not contain commas, double quotes or control characters")
            } else if names[..i].contains(&name) {
                Some("the same probe name is used twice")
            } else {
                None
            };
            if let Some(reason) = reason {
                return Err(OutputError::InvalidName {
                    path: path.to_path_buf(),
                    name: name.clone(),
                    reason,
                });
            }
        }
        let mut file = AtomicFile::create_as(path, "probe CSV")?;
        let header = (|| {
            let w = file.writer();
            w.write_all(header(probe_names, region_names).as_bytes())?;
            w.write_all(b"\n")
        })();
        if let Err(source) = header {
            return Err(file.error(IoStage::Write, source));
        }
        Ok(Self {
            file,
            num_probes: probe_names.len(),
            num_regions: region_names.len(),
            num_rows: 0,
        })
    }

    /// The number of probes (as given to [`ProbeCsv::create`]).
    #[must_use]
    pub fn num_probes(&self) -> usize {
        self.num_probes
    }

    /// The number of data rows written so far.
    #[must_use]
    pub fn num_rows(&self) -> usize {
        self.num_rows
    }

    /// The path the file will have after [`ProbeCsv::finish`].
    #[must_use]
    pub fn path(&self) -> &Path {
        self.file.path()
    }

    /// Writes one row: time `t`, then for each probe its displacement, velocity,
    /// acceleration and angular velocity (`samples[i] = [u, v, a, ω]`).
    ///
    /// # Errors
    /// [`OutputError::Length`] if `samples.len()` is not the number of probes,
    /// [`OutputError::NonFinite`] if `t` is NaN or infinite (sample values may be
    /// non-finite: a diverging run should still be visible), [`OutputError::Io`] if writing
    /// fails. Nothing is written on a validation error.
    pub fn row(&mut self, t: f64, samples: &[ProbeSample]) -> Result<(), OutputError> {
        self.row_with_regions(t, samples, &[])
    }

    /// [`ProbeCsv::row`] followed by each box probe's five values ([`REGION_COLUMNS`]).
    ///
    /// # Errors
    /// Those of [`ProbeCsv::row`]; [`OutputError::Length`] also if `regions.len()` is not the
    /// number of box probes.
    pub fn row_with_regions(
        &mut self,
        t: f64,
        samples: &[ProbeSample],
        regions: &[[f64; 5]],
    ) -> Result<(), OutputError> {
        for (name, expected, found) in [
            ("probe samples", self.num_probes, samples.len()),
            ("box probe samples", self.num_regions, regions.len()),
        ] {
            if found != expected {
                return Err(OutputError::Length {
                    path: self.file.path().to_path_buf(),
                    name: name.to_string(),
                    expected,
                    found,
                });
            }
        }
        if !t.is_finite() {
            return Err(OutputError::NonFinite {
                path: self.file.path().to_path_buf(),
                what: "probe sample time",
                value: t,
            });
        }
        let result = (|| {
            let w = self.file.writer();
            write_f64(w, t)?;
            let probes = samples.iter().flat_map(|s| s.iter().flat_map(|v| v.iter()));
            for x in probes.chain(regions.iter().flatten()) {
                w.write_all(b",")?;
                write_f64(w, *x)?;
            }
            w.write_all(b"\n")
        })();
        result.map_err(|source| self.file.error(IoStage::Write, source))?;
        self.num_rows += 1;
        Ok(())
    }

    /// Continues the file at `path` written by an earlier run of the same probes: the header
    /// and its first `rows` rows are kept (rows after them, written by a run that went on
    /// past the checkpoint being resumed, are dropped: the resumed run writes them again)
    /// and new rows follow.
    ///
    /// # Errors
    /// [`OutputError::Resume`] if the file cannot be read, has another header or fewer than
    /// `rows` rows; the errors of [`ProbeCsv::create`].
    pub fn resume(path: &Path, probe_names: &[String], rows: usize) -> Result<Self, OutputError> {
        Self::resume_with_regions(path, probe_names, &[], rows)
    }

    /// [`ProbeCsv::resume`] of a file with box probes ([`ProbeCsv::with_regions`]).
    ///
    /// # Errors
    /// Those of [`ProbeCsv::resume`].
    pub fn resume_with_regions(
        path: &Path,
        probe_names: &[String],
        region_names: &[String],
        rows: usize,
    ) -> Result<Self, OutputError> {
        let resume_error = |reason: String| OutputError::Resume {
            path: path.to_path_buf(),
            reason,
        };
        let text = std::fs::read_to_string(path).map_err(|e| resume_error(e.to_string()))?;
        let mut csv = Self::with_regions(path, probe_names, region_names)?;
        let mut lines = text.lines();
        let header = lines.next().unwrap_or("");
        let expected = self::header(probe_names, region_names);
        if header.split(',').next() == Some("t") {
            return Err(resume_error(format!(
                "it is a probes.csv of output format 1 (time column `t`, no angular velocity), \
                 this qdem writes format {}; fix: start the run afresh (without --resume)",
                super::OUTPUT_FORMAT
            )));
        }
        if header != expected {
            return Err(resume_error(format!(
                "its header `{header}` is not that of the scene's probes `{expected}`"
            )));
        }
        let kept: Vec<&str> = lines.take(rows).collect();
        if kept.len() < rows {
            return Err(resume_error(format!(
                "it has {} rows but the checkpoint was taken after {rows}",
                kept.len()
            )));
        }
        let result = kept
            .iter()
            .try_for_each(|line| writeln!(csv.file.writer(), "{line}"));
        result.map_err(|source| csv.file.error(IoStage::Write, source))?;
        csv.num_rows = rows;
        Ok(csv)
    }

    /// Makes the rows written so far visible under the file's name ([`AtomicFile::publish`]).
    ///
    /// # Errors
    /// [`OutputError::Io`] if that fails.
    pub fn publish(&mut self) -> Result<(), OutputError> {
        self.file.publish()
    }

    /// Flushes, syncs and renames the file into place.
    ///
    /// # Errors
    /// [`OutputError::Io`] if that fails; the target is then untouched.
    pub fn finish(self) -> Result<(), OutputError> {
        self.file.commit()
    }
}

/// The header line (without its newline): `time`, each probe's twelve columns, each box
/// probe's five.
fn header(probe_names: &[String], region_names: &[String]) -> String {
    let columns = |names: &[String], suffixes: &'static [&'static str]| {
        names
            .iter()
            .flat_map(move |n| suffixes.iter().map(move |c| format!("{n}.{c}")))
            .collect::<Vec<_>>()
    };
    std::iter::once(TIME_COLUMN.to_string())
        .chain(columns(probe_names, &PROBE_COLUMNS))
        .chain(columns(region_names, &REGION_COLUMNS))
        .collect::<Vec<_>>()
        .join(",")
}
