//! Triangulated walls: a rigid surface given by triangles (a gmsh surface mesh, or the boundary
//! of a tetrahedral mesh), moving with a constant velocity, with its own friction. The closest
//! point of the mesh to a sphere's centre comes from parry3d's bounding-volume hierarchy
//! (`PointQuery::project_local_point`), so each sphere touches a mesh wall at one point at most,
//! and a sphere over an edge or vertex is pushed away from that edge or vertex rather than
//! twice by two faces. The surface is two-sided: a centre must not cross it.

use crate::broad_phase::bounds;
use crate::error::ContactError;
use parry3d_f64::math::Vector;
use parry3d_f64::query::PointQuery;
use parry3d_f64::shape::TriMesh;
use qdem_core::Vec3;

/// A rigid triangulated surface moving with a constant velocity.
#[derive(Clone)]
pub struct MeshWall {
    mesh: TriMesh,
    /// Velocity of the wall (m/s).
    pub velocity: Vec3,
    lower: Vec3,
    upper: Vec3,
}

impl std::fmt::Debug for MeshWall {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("MeshWall")
            .field("triangles", &self.mesh.num_triangles())
            .field("velocity", &self.velocity)
            .finish()
    }
}

fn to_parry(x: &Vec3) -> Vector {
    Vector::new(x.x, x.y, x.z)
}

fn from_parry(x: Vector) -> Vec3 {
    Vec3::new(x.x, x.y, x.z)
}

impl MeshWall {
    /// A wall of `triangles` (indices into `vertices`) at rest at t = 0.
    pub fn new(
        name: &str,
        vertices: &[Vec3],
        triangles: &[[u32; 3]],
        velocity: Vec3,
    ) -> Result<MeshWall, ContactError> {
        let points = vertices.iter().map(to_parry).collect();
        let mesh =
            TriMesh::new(points, triangles.to_vec()).map_err(|e| ContactError::MeshWall {
                wall: name.to_string(),
                reason: e.to_string(),
            })?;
        let (lower, upper) = bounds(vertices);
        Ok(MeshWall {
            mesh,
            velocity,
            lower,
            upper,
        })
    }

    /// Whether a sphere at `x` with reach `reach` (radius plus skin) can touch the wall's
    /// bounding box at time `t`.
    pub fn may_touch(&self, x: &Vec3, reach: f64, t: f64) -> bool {
        let local = x - self.velocity * t;
        (0..3).all(|k| local[k] > self.lower[k] - reach && local[k] < self.upper[k] + reach)
    }

    /// The wall's triangles at time `t`: its vertices moved by v t, and three vertex indices
    /// per triangle.
    pub fn surface(&self, t: f64) -> (Vec<Vec3>, Vec<[u32; 3]>) {
        let shift = self.velocity * t;
        let vertices = self.mesh.vertices().iter().map(|&v| from_parry(v) + shift);
        (vertices.collect(), self.mesh.indices().to_vec())
    }

    /// Overlap δ = r − |x − p| with p the closest point of the wall at time `t`, and the unit
    /// normal from the sphere towards p.
    pub fn overlap(&self, x: &Vec3, radius: f64, t: f64) -> (f64, Vec3) {
        let shift = self.velocity * t;
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
