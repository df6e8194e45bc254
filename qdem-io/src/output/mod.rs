//! Output writers of a run: VTU snapshots with a PVD index, probe CSV, summary JSON.
//!
//! Every file is written atomically ([`write_atomic`], [`AtomicFile`]): written to a
//! temporary file `.NAME.tmp-<pid>` in the target's directory, synced, then renamed over
//! the target. A reader never sees a partial file, and a failed write leaves the previous
//! content in place and no temporary file behind. A run that is killed mid-write does leave
//! one: [`remove_stale_temporaries`], called at the start of every run, removes those whose
//! process is gone. A run holds its folder's [`FolderLock`] from start to end, so that a second
//! run into the same folder is refused instead of mixing its files with the first's.
//!
//! | file | writer |
//! | --- | --- |
//! | `*.vtu` (VTK XML UnstructuredGrid, linear tets, binary base64) | [`write_vtu`] |
//! | `*.vtu` of vertices, lines or triangles (spheres, contacts, bonds, walls) | [`write_vtu_mesh`] |
//! | `*.pvd` (ParaView time-series collection) | [`PvdIndex`] |
//! | `probes.csv` (per-probe u, v, a, ω over time, streamed) | [`ProbeCsv`] |
//! | `summary.json` | [`write_summary`] |
//!
//! Floating-point numbers written as text (CSV, PVD times) use the shortest decimal form
//! that parses back to the same `f64`; binary VTU arrays hold the exact bits. Every error
//! is an [`OutputError`] naming the path it concerns.

mod atomic;
mod error;
mod folder_lock;
mod probes_csv;
mod pvd;
mod summary;
mod vtu;

pub use atomic::{remove_stale_temporaries, write_atomic, AtomicFile};
pub use error::{IoStage, OutputError};
pub use folder_lock::{FolderLock, LockError, LOCK_FILE};
pub use probes_csv::{ProbeCsv, ProbeSample, PROBE_COLUMNS, REGION_COLUMNS, TIME_COLUMN};
pub use pvd::PvdIndex;
pub use summary::write_summary;
pub use vtu::{
    write_vtu, write_vtu_mesh, write_vtu_mesh_at, VtuCells, VtuField, VtuGrid, VtuMesh, VTK_TETRA,
};

use std::borrow::Cow;
use std::io::{self, Write};

/// The version of the output files' layout a run writes, in `summary.json` as
/// `output_format`: 1 until `probes.csv` named its time column `t` (the other CSVs `time`)
/// and had no angular velocity; 2: `probes.csv`'s time column is `time` and every probe has
/// `wx,wy,wz`, `walls.csv` has each wall's position `wallK.x,y,z`.
pub const OUTPUT_FORMAT: u32 = 2;

/// Writes `x` in the shortest decimal form that parses back to the same `f64`: plain
/// notation for zero and magnitudes in `[1e-5, 1e16)`, scientific (`1.5e-7`) otherwise;
/// `NaN`, `inf`, `-inf` for non-finite values.
pub(crate) fn write_f64(w: &mut dyn Write, x: f64) -> io::Result<()> {
    let a = x.abs();
    if a == 0.0 || !x.is_finite() || (1e-5..1e16).contains(&a) {
        write!(w, "{x}")
    } else {
        write!(w, "{x:e}")
    }
}

/// Escapes `s` for use inside a double-quoted XML attribute value.
pub(crate) fn xml_escape(s: &str) -> Cow<'_, str> {
    if !s.contains(['&', '<', '>', '"', '\'']) {
        return Cow::Borrowed(s);
    }
    let mut out = String::with_capacity(s.len() + 8);
    for c in s.chars() {
        match c {
            '&' => out.push_str("&amp;"),
            '<' => out.push_str("&lt;"),
            '>' => out.push_str("&gt;"),
            '"' => out.push_str("&quot;"),
            '\'' => out.push_str("&apos;"),
            c => out.push(c),
        }
    }
    Cow::Owned(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn fmt(x: f64) -> String {
        let mut out = Vec::new();
        write_f64(&mut out, x).unwrap();
        String::from_utf8(out).unwrap()
    }

    #[test]
    fn f64_text_round_trips_exactly() {
        let values = [
            0.0,
            -0.0,
            1.0,
            0.1,
            1.0 / 3.0,
            -2.5e-7,
            1e-5,
            9.999999999999999e-6,
            1e16,
            123456789.125,
            f64::MIN_POSITIVE,
            5e-324,
            f64::MAX,
            -f64::MAX,
            std::f64::consts::PI * 1e-300,
        ];
        for x in values {
            let s = fmt(x);
            let back: f64 = s.parse().unwrap();
            assert_eq!(back.to_bits(), x.to_bits(), "{x:?} -> {s}");
        }
        assert_eq!(fmt(0.5), "0.5");
        assert_eq!(fmt(-2.5e-7), "-2.5e-7");
        assert_eq!(fmt(1e20), "1e20");
        assert_eq!(fmt(f64::NAN), "NaN");
        assert_eq!(fmt(f64::NEG_INFINITY), "-inf");
    }

    #[test]
    fn xml_escaping() {
        assert!(matches!(xml_escape("plain"), Cow::Borrowed("plain")));
        assert_eq!(
            xml_escape("a<b & \"c\"'"),
            "a&lt;b &amp; &quot;c&quot;&apos;"
        );
    }
}
