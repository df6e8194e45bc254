//! A wall of either shape with its friction: what the contact model needs of it.

use crate::dem::walls::mesh_wall::MeshWall;
use crate::dem::walls::plane_wall::PlaneWall;
use qdem_core::Vec3;

/// The geometry of a wall.
#[derive(Clone, Debug)]
pub enum WallShape {
    /// An infinite plane.
    Plane(PlaneWall),
    /// A triangulated surface.
    Mesh(Box<MeshWall>),
}

/// A rigid wall: a shape and its friction coefficient against spheres.
#[derive(Clone, Debug)]
pub struct Wall {
    /// Its geometry.
    pub shape: WallShape,
    /// Coulomb friction coefficient between the wall and any sphere.
    pub friction: f64,
}

impl Wall {
    /// Overlap with a sphere at `x` of radius `radius` at time `t`, and the unit normal from
    /// the sphere into the wall.
    #[inline]
    pub fn overlap(&self, x: &Vec3, radius: f64, t: f64) -> (f64, Vec3) {
        match &self.shape {
            WallShape::Plane(p) => p.overlap(x, radius, t),
            WallShape::Mesh(m) => m.overlap(x, radius, t),
        }
    }

    /// The wall's velocity (m/s).
    pub fn velocity(&self) -> Vec3 {
        match &self.shape {
            WallShape::Plane(p) => p.velocity,
            WallShape::Mesh(m) => m.velocity,
        }
    }

    /// Whether a sphere at `x` whose surface is within `skin` of the wall is possible.
    pub fn is_candidate(&self, x: &Vec3, radius: f64, skin: f64, t: f64) -> bool {
        match &self.shape {
            WallShape::Plane(p) => p.distance(x, t) < radius + skin,
            WallShape::Mesh(m) => {
                m.may_touch(x, radius + skin, t) && m.overlap(x, radius, t).0 > -skin
            }
        }
    }
}
