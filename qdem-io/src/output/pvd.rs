//! ParaView collection (`.pvd`) index of a time series of VTU files.
//!
//! A [`PvdIndex`] collects `(time, file)` pairs, each in a part (`part="N"`: the datasets
//! ParaView shows side by side at one time, such as a run's bodies, spheres and contacts);
//! [`PvdIndex::write`] writes the complete collection atomically. Calling it after every added
//! file keeps the `.pvd` on disk always complete and loadable while a run is in progress.

use std::io::{self, Write};
use std::path::Path;

use super::atomic::write_atomic_as;
use super::error::OutputError;
use super::{write_f64, xml_escape};

/// A time series of data files for a ParaView `.pvd` collection.
///
/// # Example
/// ```
/// # use qdem_io::output::PvdIndex;
/// let dir = std::env::temp_dir();
/// let pvd = dir.join(format!("qdem-doc-{}.pvd", std::process::id()));
/// let mut index = PvdIndex::new();
/// for (step, t) in [0.0, 1e-3].into_iter().enumerate() {
///     // ... write_vtu(&dir.join(format!("frame_{step:06}.vtu")), ...) ...
///     index.push(t, format!("frame_{step:06}.vtu"));
///     index.write(&pvd).unwrap();
/// }
/// # std::fs::remove_file(&pvd).unwrap();
/// ```
#[derive(Debug, Clone, Default, PartialEq)]
pub struct PvdIndex {
    /// `(time, file name relative to the .pvd's directory)`, in the order added.
    entries: Vec<(f64, String)>,
    /// The part of each entry.
    parts: Vec<u32>,
}

impl PvdIndex {
    /// An empty index.
    #[must_use]
    pub fn new() -> Self {
        Self::default()
    }

    /// Adds a data file written at simulation time `time`. `file` is the path of the data
    /// file relative to the directory of the `.pvd` (use `/` as separator).
    ///
    /// Entries are written in the order added; ParaView orders them by time.
    pub fn push(&mut self, time: f64, file: impl Into<String>) {
        self.push_part(time, 0, file);
    }

    /// Adds a data file of part `part` written at simulation time `time` (see
    /// [`PvdIndex::push`]). ParaView reads each part as one block of a multiblock dataset.
    pub fn push_part(&mut self, time: f64, part: u32, file: impl Into<String>) {
        self.entries.push((time, file.into()));
        self.parts.push(part);
    }

    /// The entries added so far: `(time, relative file name)`, of every part.
    #[must_use]
    pub fn entries(&self) -> &[(f64, String)] {
        &self.entries
    }

    /// The number of entries.
    #[must_use]
    pub fn len(&self) -> usize {
        self.entries.len()
    }

    /// Whether no entry has been added.
    #[must_use]
    pub fn is_empty(&self) -> bool {
        self.entries.is_empty()
    }

    /// Writes the complete collection to `path`, atomically.
    ///
    /// Each time is written with the shortest decimal form that parses back to the same
    /// `f64`.
    ///
    /// # Errors
    /// [`OutputError::NonFinite`] if a time is NaN or infinite,
    /// [`OutputError::InvalidName`] if a file name is empty or contains a control character,
    /// [`OutputError::Io`] (or [`OutputError::NoFileName`]) if the file cannot be written.
    pub fn write(&self, path: &Path) -> Result<(), OutputError> {
        for (time, file) in &self.entries {
            if !time.is_finite() {
                return Err(OutputError::NonFinite {
                    path: path.to_path_buf(),
                    what: "PVD time step",
                    value: *time,
                });
            }
            let reason = if file.is_empty() {
                Some("data file names must not be empty")
            } else if file.chars().any(char::is_control) {
                Some("data file names must not contain control characters")
            } else {
                None
            };
            if let Some(reason) = reason {
                return Err(OutputError::InvalidName {
                    path: path.to_path_buf(),
                    name: file.clone(),
                    reason,
                });
            }
        }
        write_atomic_as(path, "PVD collection", |w| self.write_to(w))
    }

    /// Writes the XML of an already validated index.
    fn write_to(&self, w: &mut dyn Write) -> io::Result<()> {
        writeln!(w, "<?xml version=\"1.0\"?>")?;
        writeln!(
            w,
            "<VTKFile type=\"Collection\" version=\"0.1\" byte_order=\"LittleEndian\">"
        )?;
        writeln!(w, "  <Collection>")?;
        for ((time, file), part) in self.entries.iter().zip(&self.parts) {
            write!(w, "    <DataSet timestep=\"")?;
            write_f64(w, *time)?;
            writeln!(
                w,
                "\" group=\"\" part=\"{part}\" file=\"{}\"/>",
                xml_escape(file)
            )?;
        }
        writeln!(w, "  </Collection>")?;
        writeln!(w, "</VTKFile>")
    }
}
