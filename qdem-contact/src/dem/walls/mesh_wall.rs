//! Triangulated walls: a rigid surface given by triangles (a gmsh surface mesh, or the boundary
//! of a tetrahedral mesh), moving with a constant velocity from where it starts (its offset
//! from the mesh file's coordinates, zero unless a stage carries the wall's place over from a
//! checkpoint), with its own friction. The closest
//! point of the mesh to a sphere's centre comes from parry3d's bounding-volume hierarchy
//! (`PointQuery::project_local_point`), so each sphere touches a mesh wall at one point at most,
//! and a sphere over an edge or vertex is pushed away from that edge or vertex rather than
//! twice by two faces. The surface is two-sided: a centre must not cross it. A copy of the
//! mesh with outward pseudo-normals (when its triangles close a solid) tells whether a centre
//! is inside the wall, and a ray along a centre's path whether it crossed the surface: what
//! the pass-through check reads (`dem_contacts/tunnelling.rs`); the contact law never reads
//! the copy, so the forces are those of the plain mesh.

use crate::dem::broad_phase::bounds;
use crate::error::ContactError;
use parry3d_f64::math::Vector;
use parry3d_f64::query::{PointQuery, Ray, RayCast};
use parry3d_f64::shape::{TriMesh, TriMeshFlags};
use qdem_core::Vec3;

/// A rigid triangulated surface moving with a constant velocity: at time t its points are the
/// mesh's moved by `offset` + `velocity` t.
#[derive(Clone)]
pub struct MeshWall {
    mesh: TriMesh,
    /// Velocity of the wall (m/s).
    pub velocity: Vec3,
    /// Its displacement at t = 0 from the mesh's coordinates (m).
    pub offset: Vec3,
    lower: Vec3,
    upper: Vec3,
    /// The same triangles, outward, with pseudo-normals; `None` when they enclose no volume.
    solid: Option<TriMesh>,
}

impl std::fmt::Debug for MeshWall {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("MeshWall")
            .field("triangles", &self.mesh.num_triangles())
            .field("velocity", &self.velocity)
            .field("offset", &self.offset)
            .finish()
    }
}

fn to_parry(x: &Vec3) -> Vector {
    Vector::new(x.x, x.y, x.z)
}

fn from_parry(x: Vector) -> Vec3 {
    Vec3::new(x.x, x.y, x.z)
}

/// `triangles` as a mesh whose pseudo-normals point out of the volume they enclose (turned
/// round if they face in), or `None` when they enclose none (an open surface).
pub(crate) fn oriented(vertices: &[Vec3], triangles: &[[u32; 3]]) -> Option<TriMesh> {
    let volume: f64 = triangles
        .iter()
        .map(|t| {
            let [a, b, c] = t.map(|i| vertices[i as usize]);
            a.dot(&b.cross(&c)) / 6.0
        })
        .sum();
    let (lower, upper) = bounds(vertices);
    let scale = (upper - lower).norm();
    if triangles.is_empty() || volume.abs() <= 1e-9 * scale.powi(3) {
        return None;
    }
    let indices = triangles
        .iter()
        .map(|&[a, b, c]| if volume > 0.0 { [a, b, c] } else { [a, c, b] })
        .collect();
    let points = vertices.iter().map(to_parry).collect();
    TriMesh::with_flags(points, indices, TriMeshFlags::ORIENTED).ok()
}

impl MeshWall {
    /// A wall of `triangles` (indices into `vertices`) at rest at t = 0.
    pub fn new(
        name: &str,
        vertices: &[Vec3],
        triangles: &[[u32; 3]],
        velocity: Vec3,
    ) -> Result<MeshWall, ContactError> {
        let points: Vec<Vector> = vertices.iter().map(to_parry).collect();
        let mesh = TriMesh::new(points.clone(), triangles.to_vec()).map_err(|e| {
            ContactError::MeshWall {
                wall: name.to_string(),
                reason: e.to_string(),
            }
        })?;
        let (lower, upper) = bounds(vertices);
        Ok(MeshWall {
            mesh,
            velocity,
            offset: Vec3::zeros(),
            lower,
            upper,
            solid: oriented(vertices, triangles),
        })
    }

    /// Its displacement at time `t` from the mesh's coordinates, `offset` + `velocity` t.
    #[inline]
    pub fn shift(&self, t: f64) -> Vec3 {
        self.offset + self.velocity * t
    }

    /// How deep the point `x` lies inside the wall's solid at time `t` (its distance to the
    /// surface), or `None` when it is outside or the wall encloses no volume.
    pub fn depth_inside(&self, x: &Vec3, t: f64) -> Option<f64> {
        let local = x - self.shift(t);
        if !self.may_touch(&local, 0.0, 0.0) {
            return None;
        }
        let solid = self.solid.as_ref()?;
        let projection = solid.project_local_point(to_parry(&local), false);
        projection
            .is_inside
            .then(|| (from_parry(projection.point) - local).norm())
    }

    /// Whether a point that moved from `from` at time `from_time` to `to` at time `to_time`
    /// crossed the wall's surface on the way, along the straight path in the wall's frame.
    pub fn crossed(&self, (from, from_time): (&Vec3, f64), (to, to_time): (&Vec3, f64)) -> bool {
        let (a, b) = (from - self.shift(from_time), to - self.shift(to_time));
        let reach = (b - a).norm();
        if reach == 0.0 || !self.may_touch(&b, reach, 0.0) {
            return false;
        }
        let ray = Ray::new(to_parry(&a), to_parry(&(b - a)));
        self.mesh.cast_local_ray(&ray, 1.0, false).is_some()
    }

    /// Whether a sphere at `x` with reach `reach` (radius plus skin) can touch the wall's
    /// bounding box at time `t`.
    pub fn may_touch(&self, x: &Vec3, reach: f64, t: f64) -> bool {
        let local = x - self.shift(t);
        (0..3).all(|k| local[k] > self.lower[k] - reach && local[k] < self.upper[k] + reach)
    }

    /// The wall's triangles at time `t`: its vertices moved by its shift, and three vertex
    /// indices per triangle.
    pub fn surface(&self, t: f64) -> (Vec<Vec3>, Vec<[u32; 3]>) {
        let shift = self.shift(t);
        let vertices = self.mesh.vertices().iter().map(|&v| from_parry(v) + shift);
        (vertices.collect(), self.mesh.indices().to_vec())
    }

    /// Overlap δ = r − |x − p| with p the closest point of the wall at time `t`, and the unit
    /// normal from the sphere towards p.
    pub fn overlap(&self, x: &Vec3, radius: f64, t: f64) -> (f64, Vec3) {
        let shift = self.shift(t);
        let local = x - shift;
        let projection = self.mesh.project_local_point(to_parry(&local), false);
        let towards = from_parry(projection.point) - local;
        let distance = towards.norm();
        let normal = if distance > 0.0 {
            towards / distance
        } else {
            Vec3::zeros()
        };
        (radius - distance, normal)
    }
}
