//! Infinite plane walls: a point, an inward unit normal, a friction coefficient and an optional
//! constant velocity, p(t) = p₀ + v t. A plane is one-sided: a sphere whose centre is at signed
//! distance h < r along the normal overlaps it by δ = r − h, even after its centre crossed.

use qdem_core::Vec3;

/// An infinite plane that moves with a constant velocity.
#[derive(Clone, Debug, PartialEq)]
pub struct PlaneWall {
    /// A point of the plane at t = 0 (m).
    pub point: Vec3,
    /// Unit normal pointing to the side where spheres belong.
    pub normal: Vec3,
    /// Velocity of the plane (m/s).
    pub velocity: Vec3,
}

impl PlaneWall {
    /// A plane through `point` with normal along `normal` (any non-zero length).
    pub fn new(point: Vec3, normal: Vec3, velocity: Vec3) -> PlaneWall {
        PlaneWall {
            point,
            normal: normal.normalize(),
            velocity,
        }
    }

    /// Signed distance (m) of `x` from the plane at time `t`, positive on the normal's side.
    #[inline]
    pub fn distance(&self, x: &Vec3, t: f64) -> f64 {
        (x - self.point - self.velocity * t).dot(&self.normal)
    }

    /// Overlap δ = r − h and the unit normal from the sphere into the wall.
    #[inline]
    pub fn overlap(&self, x: &Vec3, radius: f64, t: f64) -> (f64, Vec3) {
        (radius - self.distance(x, t), -self.normal)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_moving_plane_measures_distance_from_where_it_is() {
        let wall = PlaneWall::new(
            Vec3::zeros(),
            Vec3::new(0.0, 0.0, 2.0),
            Vec3::new(0.0, 0.0, 1.0),
        );
        let x = Vec3::new(5.0, -3.0, 1.0);
        assert_eq!(wall.distance(&x, 0.0), 1.0);
        assert_eq!(wall.distance(&x, 0.25), 0.75);
        let (overlap, n) = wall.overlap(&x, 1.1, 0.25);
        assert!((overlap - 0.35).abs() < 1e-15);
        assert_eq!(n, Vec3::new(0.0, 0.0, -1.0));
    }
}
