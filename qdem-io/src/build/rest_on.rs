//! `[[body]] rest_on`: a body laid on a granular sample, as a sleeper section is laid on its
//! ballast bed in the box tests of paper 003 §2.
//!
//! The box-test depositions lay their sleepers on the bed this way: from its design height
//! the body is lowered straight down (along −z) until its first contact sphere touches a
//! stone's sphere. (The loading scenes start the sleepers where the deposition left them,
//! [`crate::pose_from`]: crib stones nestled against the sides of a sleeper that settled
//! would stop it here before it reached the bed.) A
//! body sphere b (radius r_b) touches a stone sphere s (radius r_s) beneath it, at horizontal
//! distance h < r_b + r_s, once it has come down by
//!
//! d = (z_b − z_s) − √((r_b + r_s)² − h²),
//!
//! and the body comes down by the least d over all such pairs (a negative d lifts a body that
//! starts overlapping a stone). Horizontal distances are minimum images along periodic axes,
//! so a body rests on the stones across a periodic boundary too. Only spheres of the stone
//! lower than the body sphere count, so stones lying on the body do not hold it up.

use crate::build::{BuildError, PlacedMesh};
use crate::scene::Scene;
use qdem_contact::boundaries::periodic_boundary::PeriodicBox;
use qdem_contact::samples::clump_sample::Stone;
use qdem_core::Vec3;

/// Lowers every body with `rest_on` onto `stones` (the scene's `[granular]` sample).
pub(crate) fn rest_bodies(
    scene: &Scene,
    meshes: &mut [PlacedMesh],
    stones: &[Stone],
    periodic: Option<&PeriodicBox>,
) -> Result<(), BuildError> {
    for (body, placed) in scene.bodies.iter().zip(meshes.iter_mut()) {
        if body.rest_on.is_none() {
            continue;
        }
        let radius = body
            .contact_radius
            .expect("validated: rest_on needs contact_radius");
        let spheres: Vec<Vec3> = placed
            .mesh
            .surface_nodes()
            .iter()
            .map(|&n| Vec3::from(placed.mesh.nodes[n as usize]))
            .collect();
        let drop =
            resting_drop(&spheres, radius, stones, periodic).ok_or_else(|| BuildError::RestOn {
                scene: scene.path.clone(),
                body: body.name.clone(),
            })?;
        for p in &mut placed.mesh.nodes {
            p[2] -= drop;
        }
    }
    Ok(())
}

/// How far spheres of radius `radius` at `spheres` come down before the first touches a stone
/// sphere beneath it (module docs); `None` if no stone lies beneath any of them.
pub(crate) fn resting_drop(
    spheres: &[Vec3],
    radius: f64,
    stones: &[Stone],
    periodic: Option<&PeriodicBox>,
) -> Option<f64> {
    let mut drop: Option<f64> = None;
    for stone in stones {
        for (c, &r) in stone.centers.iter().zip(&stone.radii) {
            let reach = radius + r;
            for b in spheres {
                let mut d = b - c;
                if let Some(p) = periodic {
                    d = p.minimum_image(d);
                }
                let h2 = d.x * d.x + d.y * d.y;
                if d.z <= 0.0 || h2 >= reach * reach {
                    continue;
                }
                let gap = d.z - (reach * reach - h2).sqrt();
                drop = Some(drop.map_or(gap, |g: f64| g.min(gap)));
            }
        }
    }
    drop
}

#[cfg(test)]
mod tests {
    use super::*;

    fn stone(centers: &[[f64; 3]], radius: f64) -> Stone {
        Stone {
            centers: centers.iter().map(|c| Vec3::from(*c)).collect(),
            radii: vec![radius; centers.len()],
        }
    }

    #[test]
    fn a_sphere_comes_down_onto_the_highest_stone_beneath_it() {
        // Sphere r = 0.1 at height 1 over stones r = 0.2 topped at 0.3 (straight under) and
        // at 0.5 (offset 0.2): it touches the offset one first, at centre distance 0.3, i.e.
        // at height 0.3 + √(0.09 − 0.04) above that stone's centre.
        let stones = [
            stone(&[[0.0, 0.0, 0.1]], 0.2),
            stone(&[[0.2, 0.0, 0.3]], 0.2),
        ];
        let drop = resting_drop(&[Vec3::new(0.0, 0.0, 1.0)], 0.1, &stones, None).unwrap();
        let expected = 1.0 - (0.3 + (0.09f64 - 0.04).sqrt());
        assert!((drop - expected).abs() < 1e-12, "{drop} vs {expected}");
    }

    #[test]
    fn stones_above_or_beside_do_not_hold_a_sphere_up() {
        // One stone higher than the sphere, one horizontally out of reach.
        let stones = [
            stone(&[[0.0, 0.0, 2.0]], 0.2),
            stone(&[[0.31, 0.0, 0.0]], 0.2),
        ];
        assert_eq!(
            resting_drop(&[Vec3::new(0.0, 0.0, 1.0)], 0.1, &stones, None),
            None
        );
    }

    #[test]
    fn a_stone_across_a_periodic_boundary_holds_the_sphere() {
        // Period 1 along y: a stone at y = 0.95 is 0.1 from a sphere at y = 0.05.
        let periodic = PeriodicBox::new(Vec3::zeros(), [None, Some(1.0), None]).unwrap();
        let stones = [stone(&[[0.0, 0.95, 0.0]], 0.2)];
        let drop =
            resting_drop(&[Vec3::new(0.0, 0.05, 1.0)], 0.1, &stones, Some(&periodic)).unwrap();
        let expected = 1.0 - (0.09f64 - 0.01).sqrt();
        assert!((drop - expected).abs() < 1e-12, "{drop} vs {expected}");
        assert_eq!(
            resting_drop(&[Vec3::new(0.0, 0.05, 1.0)], 0.1, &stones, None),
            None
        );
    }
}
