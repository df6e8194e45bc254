//! The run summary as pretty-printed JSON.

use std::path::Path;

use super::atomic::write_atomic_as;
use super::error::OutputError;

/// Writes `summary` to `path` as pretty-printed JSON (two-space indentation, trailing
/// newline), atomically.
///
/// # Errors
/// [`OutputError::Io`] (or [`OutputError::NoFileName`]) if the file cannot be written; the
/// target is then untouched.
///
/// # Example
/// ```
/// # use qdem_io::output::write_summary;
/// let path = std::env::temp_dir().join(format!("qdem-doc-{}-summary.json", std::process::id()));
/// write_summary(&path, &serde_json::json!({ "steps": 1000, "dt": 1e-6 })).unwrap();
/// let back: serde_json::Value =
///     serde_json::from_str(&std::fs::read_to_string(&path).unwrap()).unwrap();
/// assert_eq!(back["steps"], 1000);
/// # std::fs::remove_file(&path).unwrap();
/// ```
pub fn write_summary(path: &Path, summary: &serde_json::Value) -> Result<(), OutputError> {
    write_atomic_as(path, "summary JSON", |w| {
        serde_json::to_writer_pretty(&mut *w, summary)?;
        w.write_all(b"\n")
    })
}
