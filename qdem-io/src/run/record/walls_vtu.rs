//! `vtu/walls.vtu`: the `[[wall]]`s as triangles, with `wall` per triangle (the wall's index
//! in scene order). A mesh wall is its own surface; an infinite plane is drawn as the
//! rectangle of it that covers the scene: the box of every particle at the time of writing,
//! widened by a tenth of its diagonal on every side, projected onto the plane. Written once
//! when no wall moves (none has a velocity or a servo), else at every `vtu_every` as `vtu/walls_NNNNN.vtu`.

use crate::output::{write_vtu_mesh_at, OutputError, VtuCells, VtuField, VtuMesh};
use qdem_contact::{PlaneWall, Wall, WallShape};
use qdem_core::{step::State, Vec3};
use std::path::Path;

/// Whether some wall of `walls` has a velocity (and so needs a file per time; so does a servo
/// wall's, [`qdem_contact::DemContacts::has_servo`]).
pub(crate) fn walls_move(walls: &[Wall]) -> bool {
    walls.iter().any(|w| w.velocity() != Vec3::zeros())
}

/// Writes `walls` at `state`'s time, the planes over the extent of `state`'s particles, to
/// `path`; `timed`: with that time as the file's `TimeValue` (walls that move; the file of
/// walls that stay serves every time).
pub(crate) fn write_walls(
    walls: &[Wall],
    state: &State,
    path: &Path,
    timed: bool,
) -> Result<(), OutputError> {
    let (lower, upper) = extent(&state.position);
    let (mut points, mut triangles, mut index) = (Vec::new(), Vec::new(), Vec::new());
    for (w, wall) in walls.iter().enumerate() {
        let (vertices, faces) = match &wall.shape {
            WallShape::Plane(plane) => patch(plane, state.time, lower, upper),
            WallShape::Mesh(mesh) => mesh.surface(state.time),
        };
        let offset = points.len() as u32;
        points.extend(vertices);
        index.extend(std::iter::repeat_n(w as i64, faces.len()));
        triangles.extend(faces.iter().map(|t| t.map(|i| i + offset)));
    }
    let mesh = VtuMesh {
        points: &points,
        cells: VtuCells::Triangles(&triangles),
        point_data: Vec::new(),
        cell_data: vec![("wall", VtuField::Integers(&index))],
    };
    write_vtu_mesh_at(path, &mesh, timed.then_some(state.time))
}

/// The box of `points` widened by a tenth of its diagonal (a unit box about the origin
/// without points).
fn extent(points: &[Vec3]) -> (Vec3, Vec3) {
    let Some(first) = points.first() else {
        return (Vec3::repeat(-0.5), Vec3::repeat(0.5));
    };
    let (lower, upper) = points
        .iter()
        .fold((*first, *first), |(lo, hi), p| (lo.inf(p), hi.sup(p)));
    let margin = 0.1 * (upper - lower).norm().max(f64::MIN_POSITIVE);
    (lower.add_scalar(-margin), upper.add_scalar(margin))
}

/// The rectangle of `plane` at time `t` covering the box `lower`–`upper`: the box's corners
/// projected onto the plane, bounded along two in-plane axes; two triangles.
fn patch(plane: &PlaneWall, t: f64, lower: Vec3, upper: Vec3) -> (Vec<Vec3>, Vec<[u32; 3]>) {
    let n = plane.normal;
    let origin = plane.point + plane.velocity * t;
    let helper = if n.x.abs() < 0.9 {
        Vec3::x()
    } else {
        Vec3::y()
    };
    let u = n.cross(&helper).normalize();
    let v = n.cross(&u);
    let (mut lo, mut hi) = ([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]);
    for corner in 0..8 {
        let pick = |k: usize| {
            if corner >> k & 1 == 0 {
                lower[k]
            } else {
                upper[k]
            }
        };
        let d = Vec3::new(pick(0), pick(1), pick(2)) - origin;
        for (axis, c) in [d.dot(&u), d.dot(&v)].into_iter().enumerate() {
            lo[axis] = lo[axis].min(c);
            hi[axis] = hi[axis].max(c);
        }
    }
    let at = |a: f64, b: f64| origin + a * u + b * v;
    let corners = vec![
        at(lo[0], lo[1]),
        at(hi[0], lo[1]),
        at(hi[0], hi[1]),
        at(lo[0], hi[1]),
    ];
    (corners, vec![[0, 1, 2], [0, 2, 3]])
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_plane_patch_lies_in_the_plane_and_covers_the_box_above_it() {
        let plane = PlaneWall::new(
            Vec3::new(0.0, 0.0, 0.1),
            Vec3::new(0.0, 0.0, 2.0),
            Vec3::zeros(),
        );
        let (lower, upper) = (Vec3::new(-1.0, -2.0, 0.0), Vec3::new(3.0, 4.0, 1.0));
        let (corners, triangles) = patch(&plane, 0.0, lower, upper);
        assert_eq!(triangles.len(), 2);
        for c in &corners {
            assert!((c.z - 0.1).abs() < 1e-15, "{c:?} off the plane");
        }
        let (lo, hi) = extent(&corners);
        // The patch spans the box's footprint exactly (then widened by extent's margin).
        let margin = 0.1 * ((4.0f64).powi(2) + 36.0).sqrt();
        assert!((lo.x + 1.0 + margin).abs() < 1e-12 && (hi.y - 4.0 - margin).abs() < 1e-12);
    }
}
