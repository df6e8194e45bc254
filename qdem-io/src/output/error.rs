//! The error type shared by every output writer.
//!
//! Every variant carries the path of the file being written, so that a message shown to a
//! user of a long simulation run says which output failed and where.

use std::fmt;
use std::io;
use std::path::PathBuf;

/// What an output writer was doing when an I/O operation failed.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum IoStage {
    /// Creating the temporary file next to the target.
    CreateTemp,
    /// Writing the content into the temporary file.
    Write,
    /// Flushing buffered content and syncing the temporary file to disk.
    Sync,
    /// Renaming the temporary file over the target.
    Rename,
}

impl fmt::Display for IoStage {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            IoStage::CreateTemp => "creating the temporary file for",
            IoStage::Write => "writing",
            IoStage::Sync => "flushing and syncing",
            IoStage::Rename => "renaming the temporary file onto",
        })
    }
}

/// An error raised by a writer of [`crate::output`].
///
/// Every variant names the path of the output file it concerns.
#[derive(Debug, thiserror::Error)]
pub enum OutputError {
    /// A plot could not be drawn.
    #[error("cannot draw the plot `{path}`: {message}")]
    Plot {
        /// The SVG file.
        path: PathBuf,
        /// What the plotting library reported.
        message: String,
    },
    /// An I/O operation failed. The target file was left untouched.
    #[error("{stage} {what} `{path}` (temporary file `{temp}`): {source}")]
    Io {
        /// The kind of output, e.g. "VTU file" or "probe CSV".
        what: &'static str,
        /// The target path.
        path: PathBuf,
        /// The temporary file the content was being written to.
        temp: PathBuf,
        /// What was being done when the error occurred.
        stage: IoStage,
        /// The underlying error.
        #[source]
        source: io::Error,
    },
    /// The target path has no file name (e.g. it ends in `..` or is a root).
    #[error("cannot write to `{path}`: the path has no file name")]
    NoFileName {
        /// The offending path.
        path: PathBuf,
    },
    /// An array has the wrong number of entries.
    #[error("cannot write `{path}`: `{name}` has {found} entries, expected {expected}")]
    Length {
        /// The target path.
        path: PathBuf,
        /// The name of the offending array (a field name, "probe samples", ...).
        name: String,
        /// The number of entries required.
        expected: usize,
        /// The number of entries given.
        found: usize,
    },
    /// A cell (a tetrahedron, line, triangle) references a point that does not exist.
    #[error(
        "cannot write `{path}`: {kind} {cell} references point {index}, \
         but there are only {num_points} points"
    )]
    PointIndex {
        /// The target path.
        path: PathBuf,
        /// What the cells are ("tetrahedron", "line", "triangle").
        kind: &'static str,
        /// The index of the offending cell.
        cell: usize,
        /// The out-of-range point index.
        index: u32,
        /// The number of points in the grid.
        num_points: usize,
    },
    /// A field, probe or file name cannot be written into this format.
    #[error("cannot write `{path}`: invalid name {name:?}: {reason}")]
    InvalidName {
        /// The target path.
        path: PathBuf,
        /// The offending name.
        name: String,
        /// Why the name is rejected.
        reason: &'static str,
    },
    /// A value that must be finite (e.g. a time) is NaN or infinite.
    #[error("cannot write `{path}`: {what} must be finite, got {value}")]
    NonFinite {
        /// The target path.
        path: PathBuf,
        /// What the value is, e.g. "PVD time step".
        what: &'static str,
        /// The offending value.
        value: f64,
    },
    /// An output of an earlier run that a resumed run cannot continue.
    #[error(
        "cannot continue `{path}` from the checkpoint: {reason}; resume into the output \
         directory the checkpoint was written in, or run the scene from the start"
    )]
    Resume {
        /// The output file.
        path: PathBuf,
        /// Why.
        reason: String,
    },
}
