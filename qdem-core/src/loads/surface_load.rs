//! A distributed load on a surface (a pressure or a traction, Pa) lumped to the nodes of its
//! linear triangles: the consistent nodal forces of a constant traction t on a linear
//! triangle of area A are A t / 3 at each of its three nodes (∫ N_i dA = A/3 for every
//! linear shape function N_i), so the nodal forces sum to the traction times the area
//! exactly. The load is a dead load: areas and normals are those of the configuration given
//! (the reference one), as suits the small displacements of the static and elastic runs.

use crate::Vec3;

/// The nodal forces of the traction `traction(n)` (Pa; `n` the triangle's unit normal, by
/// the right-hand rule on its node order) on the `triangles` of `points`: each node gets a
/// third of each of its triangles' area times the traction, summed over its triangles.
/// Returned by increasing node, one entry per node of some triangle.
///
/// A pressure p on boundary triangles oriented outwards is the traction −p n:
/// ```
/// use qdem_core::loads::surface_load::lump_traction;
/// use qdem_core::Vec3;
/// // The unit square z = 1 as two triangles with normal +z.
/// let points = [
///     Vec3::new(0.0, 0.0, 1.0),
///     Vec3::new(1.0, 0.0, 1.0),
///     Vec3::new(1.0, 1.0, 1.0),
///     Vec3::new(0.0, 1.0, 1.0),
/// ];
/// let forces = lump_traction(&points, &[[0, 1, 2], [0, 2, 3]], |n| -2.0 * n);
/// let total: Vec3 = forces.iter().map(|(_, f)| f).sum();
/// assert!((total - Vec3::new(0.0, 0.0, -2.0)).norm() < 1e-15);
/// assert_eq!(forces[0], (0, Vec3::new(0.0, 0.0, -2.0 / 3.0)));
/// ```
pub fn lump_traction(
    points: &[Vec3],
    triangles: &[[u32; 3]],
    traction: impl Fn(Vec3) -> Vec3,
) -> Vec<(u32, Vec3)> {
    let mut per_node: Vec<(u32, Vec3)> = Vec::with_capacity(3 * triangles.len());
    for tri in triangles {
        let [a, b, c] = tri.map(|n| points[n as usize]);
        let area_vector = 0.5 * (b - a).cross(&(c - a));
        let area = area_vector.norm();
        if area == 0.0 {
            continue;
        }
        let share = traction(area_vector / area) * (area / 3.0);
        per_node.extend(tri.iter().map(|&n| (n, share)));
    }
    per_node.sort_by_key(|&(n, _)| n);
    let mut out: Vec<(u32, Vec3)> = Vec::new();
    for (n, f) in per_node {
        match out.last_mut() {
            Some(last) if last.0 == n => last.1 += f,
            _ => out.push((n, f)),
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A uniform pressure on a fan of unequal triangles: the forces sum to p·A, and the node
    /// shared by all of them gets a third of the whole area.
    #[test]
    fn forces_sum_to_pressure_times_area() {
        let points = [
            Vec3::new(0.3, 0.2, 0.0),
            Vec3::new(0.0, 0.0, 0.0),
            Vec3::new(1.0, 0.0, 0.0),
            Vec3::new(1.0, 0.7, 0.0),
            Vec3::new(0.0, 1.0, 0.0),
        ];
        let fan = [[0, 1, 2], [0, 2, 3], [0, 3, 4], [0, 4, 1]];
        let area = 0.5 * (1.0 + 0.7) * 1.0; // the trapezoid the fan covers
        let p = 1.7e5;
        let forces = lump_traction(&points, &fan, |n| -p * n);
        let total: Vec3 = forces.iter().map(|(_, f)| f).sum();
        assert!((total.z + p * area).abs() <= 1e-12 * p * area, "{total}");
        assert!(total.x.abs() + total.y.abs() <= 1e-12 * p * area);
        assert!((forces[0].1.z + p * area / 3.0).abs() <= 1e-12 * p * area);
    }
}
