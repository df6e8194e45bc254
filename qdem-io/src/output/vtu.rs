//! VTK XML UnstructuredGrid (`.vtu`) writer: linear tetrahedra ([`VtuGrid`], the bodies), and
//! vertices, lines or triangles ([`VtuMesh`]: contact spheres, force chains, bonds, walls).
//!
//! The file is self-contained and readable by ParaView, VTK and meshio (which reads no VTK
//! PolyData, hence UnstructuredGrids of vertex and line cells rather than `.vtp` files):
//! - `byte_order="LittleEndian"`, `header_type="UInt64"`;
//! - every DataArray is inline `format="binary"`: one base64 stream holding the array's
//!   byte count as a little-endian `u64`, followed by the little-endian values;
//! - points and real fields are `Float64`, integer fields, connectivity and offsets `Int64`,
//!   cell types `UInt8` (one type per file: [`VtuCells`]).
//!
//! Values are written bit for bit (no rounding), so a file can be compared exactly with
//! the state it came from. The base64 encoding is streamed, so no copy of a field is held
//! in memory. The file is written through [`write_atomic`](super::write_atomic).

use std::io::{self, Write};
use std::path::Path;

use nalgebra::Vector3;

use super::atomic::write_atomic_as;
use super::error::OutputError;
use super::xml_escape;

/// The VTK cell type of a linear tetrahedron (`VTK_TETRA`).
pub const VTK_TETRA: u8 = 10;

/// A linear tetrahedral mesh with point and cell fields, borrowed for writing.
///
/// # Example
/// ```
/// # use qdem_io::output::{write_vtu, VtuGrid};
/// use nalgebra::Vector3;
/// let points = [Vector3::zeros(), Vector3::x(), Vector3::y(), Vector3::z()];
/// let tets = [[0, 1, 2, 3]];
/// let u = [Vector3::new(0.0, 0.0, 1e-3); 4];
/// let von_mises = [1.5e6];
/// let grid = VtuGrid {
///     points: &points,
///     tets: &tets,
///     point_vectors: vec![("displacement", &u)],
///     cell_scalars: vec![("von_mises", &von_mises)],
/// };
/// let path = std::env::temp_dir().join(format!("qdem-doc-{}.vtu", std::process::id()));
/// write_vtu(&path, &grid).unwrap();
/// # std::fs::remove_file(&path).unwrap();
/// ```
#[derive(Debug, Clone)]
pub struct VtuGrid<'a> {
    /// Point coordinates.
    pub points: &'a [Vector3<f64>],
    /// Tetrahedra as four indices into `points` each.
    pub tets: &'a [[u32; 4]],
    /// Named 3-vector fields with one value per point (displacement, velocity, ...).
    pub point_vectors: Vec<(&'a str, &'a [Vector3<f64>])>,
    /// Named scalar fields with one value per tetrahedron (von Mises stress, ...).
    pub cell_scalars: Vec<(&'a str, &'a [f64])>,
}

impl<'a> VtuGrid<'a> {
    /// The same grid as a [`VtuMesh`] of tetrahedra.
    #[must_use]
    pub fn mesh(&self) -> VtuMesh<'a> {
        VtuMesh {
            points: self.points,
            cells: VtuCells::Tets(self.tets),
            point_data: self
                .point_vectors
                .iter()
                .map(|&(n, v)| (n, VtuField::Vectors(v)))
                .collect(),
            cell_data: self
                .cell_scalars
                .iter()
                .map(|&(n, v)| (n, VtuField::Scalars(v)))
                .collect(),
        }
    }

    /// Checks the grid before anything is written to `path` (used in error messages).
    ///
    /// # Errors
    /// As [`VtuMesh::validate`]: [`OutputError::Length`] if a point field does not have
    /// `points.len()` entries or a cell field `tets.len()` entries,
    /// [`OutputError::PointIndex`] if a tetrahedron references a point that does not exist,
    /// [`OutputError::InvalidName`] if a field name is empty, contains a control character
    /// or is used twice in the same section.
    pub fn validate(&self, path: &Path) -> Result<(), OutputError> {
        self.mesh().validate(path)
    }
}

/// The cells of a [`VtuMesh`], all of one VTK type.
#[derive(Debug, Clone, Copy)]
pub enum VtuCells<'a> {
    /// One `VTK_VERTEX` per point, in point order: points for ParaView's Glyph filter.
    Vertices,
    /// `VTK_LINE`s, two indices into the points each.
    Lines(&'a [[u32; 2]]),
    /// `VTK_TRIANGLE`s, three indices into the points each.
    Triangles(&'a [[u32; 3]]),
    /// `VTK_TETRA`s, four indices into the points each.
    Tets(&'a [[u32; 4]]),
}

impl VtuCells<'_> {
    /// The number of cells, given the number of points.
    fn len(&self, points: usize) -> usize {
        match self {
            VtuCells::Vertices => points,
            VtuCells::Lines(c) => c.len(),
            VtuCells::Triangles(c) => c.len(),
            VtuCells::Tets(c) => c.len(),
        }
    }

    /// The VTK cell type, the points per cell and what a cell is called in messages.
    fn kind(&self) -> (u8, usize, &'static str) {
        match self {
            VtuCells::Vertices => (1, 1, "vertex"),
            VtuCells::Lines(_) => (3, 2, "line"),
            VtuCells::Triangles(_) => (5, 3, "triangle"),
            VtuCells::Tets(_) => (VTK_TETRA, 4, "tetrahedron"),
        }
    }

    /// The point indices of every cell, cell after cell.
    fn connectivity(&self, points: usize) -> Box<dyn Iterator<Item = u32> + '_> {
        match self {
            VtuCells::Vertices => Box::new(0..points as u32),
            VtuCells::Lines(c) => Box::new(c.iter().flatten().copied()),
            VtuCells::Triangles(c) => Box::new(c.iter().flatten().copied()),
            VtuCells::Tets(c) => Box::new(c.iter().flatten().copied()),
        }
    }
}

/// One named field of a [`VtuMesh`]: one value per point or per cell.
#[derive(Debug, Clone, Copy)]
pub enum VtuField<'a> {
    /// Real scalars (`Float64`).
    Scalars(&'a [f64]),
    /// Real 3-vectors (`Float64`, three components).
    Vectors(&'a [Vector3<f64>]),
    /// Integers (`Int64`): indices, flags.
    Integers(&'a [i64]),
    /// Symmetric tensors (`Float64`, six components in ParaView's order xx, yy, zz, xy, yz,
    /// xz, which it shows as a symmetric tensor): a Cauchy stress.
    SymTensors(&'a [[f64; 6]]),
}

impl VtuField<'_> {
    /// The number of values.
    fn len(&self) -> usize {
        match self {
            VtuField::Scalars(v) => v.len(),
            VtuField::Vectors(v) => v.len(),
            VtuField::Integers(v) => v.len(),
            VtuField::SymTensors(v) => v.len(),
        }
    }
}

/// Points, cells of one type and named fields, borrowed for writing.
///
/// # Example
/// Two spheres touching, as a line with its force:
/// ```
/// # use qdem_io::output::{write_vtu_mesh, VtuCells, VtuField, VtuMesh};
/// use nalgebra::Vector3;
/// let ends = [Vector3::zeros(), Vector3::new(0.02, 0.0, 0.0)];
/// let force = [Vector3::new(-3.0, 0.0, 0.0)];
/// let spheres = [0, 1];
/// let mesh = VtuMesh {
///     points: &ends,
///     cells: VtuCells::Lines(&[[0, 1]]),
///     point_data: vec![("sphere", VtuField::Integers(&spheres))],
///     cell_data: vec![("normal_force", VtuField::Vectors(&force))],
/// };
/// let path = std::env::temp_dir().join(format!("qdem-doc-line-{}.vtu", std::process::id()));
/// write_vtu_mesh(&path, &mesh).unwrap();
/// # std::fs::remove_file(&path).unwrap();
/// ```
#[derive(Debug, Clone)]
pub struct VtuMesh<'a> {
    /// Point coordinates.
    pub points: &'a [Vector3<f64>],
    /// The cells.
    pub cells: VtuCells<'a>,
    /// Named fields with one value per point.
    pub point_data: Vec<(&'a str, VtuField<'a>)>,
    /// Named fields with one value per cell.
    pub cell_data: Vec<(&'a str, VtuField<'a>)>,
}

impl VtuMesh<'_> {
    /// Checks the mesh before anything is written to `path` (used in error messages).
    ///
    /// # Errors
    /// [`OutputError::Length`] if a point field does not have one entry per point or a
    /// cell field one per cell, [`OutputError::PointIndex`] if a cell references a point
    /// that does not exist, [`OutputError::InvalidName`] if a field name is empty, contains
    /// a control character or is used twice in the same section.
    pub fn validate(&self, path: &Path) -> Result<(), OutputError> {
        let np = self.points.len();
        let nc = self.cells.len(np);
        let lens = self
            .point_data
            .iter()
            .map(|(n, v)| (*n, v.len(), np))
            .chain(self.cell_data.iter().map(|(n, v)| (*n, v.len(), nc)));
        for (name, found, expected) in lens {
            if found != expected {
                return Err(OutputError::Length {
                    path: path.to_path_buf(),
                    name: name.to_string(),
                    expected,
                    found,
                });
            }
        }
        check_names(path, self.point_data.iter().map(|(n, _)| *n))?;
        check_names(path, self.cell_data.iter().map(|(n, _)| *n))?;
        let (_, per_cell, kind) = self.cells.kind();
        let bad = self
            .cells
            .connectivity(np)
            .enumerate()
            .find(|&(_, i)| i as usize >= np);
        if let Some((at, index)) = bad {
            return Err(OutputError::PointIndex {
                path: path.to_path_buf(),
                kind,
                cell: at / per_cell,
                index,
                num_points: np,
            });
        }
        Ok(())
    }
}

/// Rejects empty names, names with control characters and duplicates within a section.
fn check_names<'a>(path: &Path, names: impl Iterator<Item = &'a str>) -> Result<(), OutputError> {
    let mut seen: Vec<&str> = Vec::new();
    for name in names {
        let reason = if name.is_empty() {
            Some("field names must not be empty")
        } else if name.chars().any(char::is_control) {
            Some("field names must not contain control characters")
        } else if seen.contains(&name) {
            Some("the same field name is used twice")
        } else {
            None
        };
        if let Some(reason) = reason {
            return Err(OutputError::InvalidName {
                path: path.to_path_buf(),
                name: name.to_string(),
                reason,
            });
        }
        seen.push(name);
    }
    Ok(())
}

/// Writes `grid` to `path` as a VTK XML UnstructuredGrid of tetrahedra, atomically.
///
/// The grid is validated first ([`VtuGrid::validate`]); nothing is created on a
/// validation error.
///
/// # Errors
/// The validation errors of [`VtuGrid::validate`], and [`OutputError::Io`] (or
/// [`OutputError::NoFileName`]) if the file cannot be written; the target is then untouched
/// and no temporary file is left behind.
pub fn write_vtu(path: &Path, grid: &VtuGrid<'_>) -> Result<(), OutputError> {
    write_vtu_mesh(path, &grid.mesh())
}

/// Writes `mesh` to `path` as a VTK XML UnstructuredGrid, atomically.
///
/// The mesh is validated first ([`VtuMesh::validate`]); nothing is created on a
/// validation error.
///
/// # Errors
/// The validation errors of [`VtuMesh::validate`], and [`OutputError::Io`] (or
/// [`OutputError::NoFileName`]) if the file cannot be written; the target is then untouched
/// and no temporary file is left behind.
pub fn write_vtu_mesh(path: &Path, mesh: &VtuMesh<'_>) -> Result<(), OutputError> {
    write_vtu_mesh_at(path, mesh, None)
}

/// [`write_vtu_mesh`] of one time of a series: with `time` (s), the file carries it as the
/// `TimeValue` field data that ParaView and VTK read as the dataset's time, so a file opened
/// on its own (not through `results.pvd`) shows its simulated time.
///
/// # Errors
/// As [`write_vtu_mesh`].
pub fn write_vtu_mesh_at(
    path: &Path,
    mesh: &VtuMesh<'_>,
    time: Option<f64>,
) -> Result<(), OutputError> {
    mesh.validate(path)?;
    write_atomic_as(path, "VTU file", |w| write_vtu_to(w, mesh, time))
}

/// Writes the XML of an already validated mesh, with its `TimeValue` if given.
fn write_vtu_to(w: &mut dyn Write, mesh: &VtuMesh<'_>, time: Option<f64>) -> io::Result<()> {
    let np = mesh.points.len();
    let nc = mesh.cells.len(np);
    writeln!(w, "<?xml version=\"1.0\"?>")?;
    writeln!(
        w,
        "<VTKFile type=\"UnstructuredGrid\" version=\"1.0\" \
         byte_order=\"LittleEndian\" header_type=\"UInt64\">"
    )?;
    writeln!(w, "  <UnstructuredGrid>")?;
    if let Some(t) = time {
        writeln!(w, "    <FieldData>")?;
        writeln!(
            w,
            "      <DataArray type=\"Float64\" Name=\"TimeValue\" NumberOfTuples=\"1\" \
             format=\"ascii\">{t:?}</DataArray>"
        )?;
        writeln!(w, "    </FieldData>")?;
    }
    writeln!(
        w,
        "    <Piece NumberOfPoints=\"{np}\" NumberOfCells=\"{nc}\">"
    )?;
    fields(w, "PointData", &mesh.point_data)?;
    fields(w, "CellData", &mesh.cell_data)?;

    writeln!(w, "      <Points>")?;
    data_array(
        w,
        "Float64",
        "Points",
        3,
        3 * np,
        mesh.points.iter().flat_map(vec3_bytes),
    )?;
    writeln!(w, "      </Points>")?;

    let (vtk_type, per_cell, _) = mesh.cells.kind();
    writeln!(w, "      <Cells>")?;
    data_array(
        w,
        "Int64",
        "connectivity",
        1,
        per_cell * nc,
        mesh.cells
            .connectivity(np)
            .map(|i| i64::from(i).to_le_bytes()),
    )?;
    data_array(
        w,
        "Int64",
        "offsets",
        1,
        nc,
        (1..=nc as i64).map(|i| (per_cell as i64 * i).to_le_bytes()),
    )?;
    data_array(w, "UInt8", "types", 1, nc, (0..nc).map(|_| [vtk_type]))?;
    writeln!(w, "      </Cells>")?;

    writeln!(w, "    </Piece>")?;
    writeln!(w, "  </UnstructuredGrid>")?;
    writeln!(w, "</VTKFile>")?;
    Ok(())
}

/// Writes a `<PointData>` or `<CellData>` section (`section`), naming its first scalar and
/// first vector field as the active ones.
fn fields(w: &mut dyn Write, section: &str, data: &[(&str, VtuField<'_>)]) -> io::Result<()> {
    write!(w, "      <{section}")?;
    let first_scalar = data.iter().find(|(_, f)| matches!(f, VtuField::Scalars(_)));
    if let Some((name, _)) = first_scalar {
        write!(w, " Scalars=\"{}\"", xml_escape(name))?;
    }
    let first_vector = data.iter().find(|(_, f)| matches!(f, VtuField::Vectors(_)));
    if let Some((name, _)) = first_vector {
        write!(w, " Vectors=\"{}\"", xml_escape(name))?;
    }
    writeln!(w, ">")?;
    for (name, field) in data {
        match field {
            VtuField::Scalars(v) => data_array(
                w,
                "Float64",
                name,
                1,
                v.len(),
                v.iter().map(|x| x.to_le_bytes()),
            )?,
            VtuField::Vectors(v) => data_array(
                w,
                "Float64",
                name,
                3,
                3 * v.len(),
                v.iter().flat_map(vec3_bytes),
            )?,
            VtuField::Integers(v) => data_array(
                w,
                "Int64",
                name,
                1,
                v.len(),
                v.iter().map(|x| x.to_le_bytes()),
            )?,
            VtuField::SymTensors(v) => data_array(
                w,
                "Float64",
                name,
                6,
                6 * v.len(),
                v.iter().flatten().map(|x| x.to_le_bytes()),
            )?,
        }
    }
    writeln!(w, "      </{section}>")
}

/// The little-endian bytes of the three components of `v`.
fn vec3_bytes(v: &Vector3<f64>) -> [[u8; 8]; 3] {
    [v.x.to_le_bytes(), v.y.to_le_bytes(), v.z.to_le_bytes()]
}

/// Writes one inline binary `<DataArray>`: the base64 of the byte count (`u64` LE) followed
/// by the items' bytes, as a single stream.
fn data_array<const N: usize>(
    w: &mut dyn Write,
    vtk_type: &str,
    name: &str,
    components: usize,
    num_items: usize,
    items: impl Iterator<Item = [u8; N]>,
) -> io::Result<()> {
    write!(
        w,
        "        <DataArray type=\"{vtk_type}\" Name=\"{}\" ",
        xml_escape(name)
    )?;
    if components != 1 {
        write!(w, "NumberOfComponents=\"{components}\" ")?;
    }
    write!(w, "format=\"binary\">")?;
    let num_bytes = (num_items * N) as u64;
    let mut enc = Base64Writer::new(w);
    enc.write(&num_bytes.to_le_bytes())?;
    let mut written = 0;
    for item in items {
        enc.write(&item)?;
        written += 1;
    }
    debug_assert_eq!(written, num_items, "DataArray `{name}`: wrong item count");
    enc.finish()?;
    writeln!(w, "</DataArray>")
}

/// The standard base64 alphabet (RFC 4648).
const BASE64_ALPHABET: &[u8; 64] =
    b"ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";

/// A streaming base64 encoder (standard alphabet, `=` padding, no line breaks).
struct Base64Writer<'w> {
    /// Where the encoded text goes.
    out: &'w mut dyn Write,
    /// Input bytes not yet forming a full group of three.
    pending: [u8; 3],
    /// How many bytes of `pending` are used.
    num_pending: usize,
    /// Encoded text not yet written to `out`.
    buf: [u8; 4096],
    /// How many bytes of `buf` are used.
    num_buf: usize,
}

impl<'w> Base64Writer<'w> {
    /// An encoder writing into `out`.
    fn new(out: &'w mut dyn Write) -> Self {
        Self {
            out,
            pending: [0; 3],
            num_pending: 0,
            buf: [0; 4096],
            num_buf: 0,
        }
    }

    /// Encodes `data`.
    fn write(&mut self, mut data: &[u8]) -> io::Result<()> {
        while self.num_pending > 0 && !data.is_empty() {
            self.pending[self.num_pending] = data[0];
            self.num_pending += 1;
            data = &data[1..];
            if self.num_pending == 3 {
                self.num_pending = 0;
                self.group(self.pending, 3)?;
            }
        }
        let mut chunks = data.chunks_exact(3);
        for c in &mut chunks {
            self.group([c[0], c[1], c[2]], 3)?;
        }
        for &b in chunks.remainder() {
            self.pending[self.num_pending] = b;
            self.num_pending += 1;
        }
        Ok(())
    }

    /// Encodes one group of `n` (1 to 3) bytes into four characters.
    fn group(&mut self, g: [u8; 3], n: usize) -> io::Result<()> {
        if self.num_buf + 4 > self.buf.len() {
            self.out.write_all(&self.buf[..self.num_buf])?;
            self.num_buf = 0;
        }
        let v = (u32::from(g[0]) << 16) | (u32::from(g[1]) << 8) | u32::from(g[2]);
        let chars = [
            BASE64_ALPHABET[(v >> 18) as usize & 63],
            BASE64_ALPHABET[(v >> 12) as usize & 63],
            if n > 1 {
                BASE64_ALPHABET[(v >> 6) as usize & 63]
            } else {
                b'='
            },
            if n > 2 {
                BASE64_ALPHABET[v as usize & 63]
            } else {
                b'='
            },
        ];
        self.buf[self.num_buf..self.num_buf + 4].copy_from_slice(&chars);
        self.num_buf += 4;
        Ok(())
    }

    /// Pads the last group and writes out everything.
    fn finish(mut self) -> io::Result<()> {
        if self.num_pending > 0 {
            let mut g = [0; 3];
            g[..self.num_pending].copy_from_slice(&self.pending[..self.num_pending]);
            self.group(g, self.num_pending)?;
        }
        self.out.write_all(&self.buf[..self.num_buf])
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn b64(chunks: &[&[u8]]) -> String {
        let mut out = Vec::new();
        let mut enc = Base64Writer::new(&mut out);
        for c in chunks {
            enc.write(c).unwrap();
        }
        enc.finish().unwrap();
        String::from_utf8(out).unwrap()
    }

    #[test]
    fn base64_rfc4648_vectors() {
        let cases = [
            ("", ""),
            ("f", "Zg=="),
            ("fo", "Zm8="),
            ("foo", "Zm9v"),
            ("foob", "Zm9vYg=="),
            ("fooba", "Zm9vYmE="),
            ("foobar", "Zm9vYmFy"),
        ];
        for (input, expected) in cases {
            assert_eq!(b64(&[input.as_bytes()]), expected);
        }
    }

    #[test]
    fn base64_is_independent_of_chunking() {
        let data: Vec<u8> = (0..10_000u32).map(|i| (i * 7919 % 251) as u8).collect();
        let whole = b64(&[&data]);
        let pieces: Vec<&[u8]> = data.chunks(5).collect();
        assert_eq!(b64(&pieces), whole);
        let pieces: Vec<&[u8]> = data.chunks(1).collect();
        assert_eq!(b64(&pieces), whole);
        assert_eq!(whole.len(), data.len().div_ceil(3) * 4);
    }
}
