//! A `[[load]]`'s `pressure` or `traction` on a face: the body's boundary triangles whose
//! three nodes are all selected (by the physical group or the box), lumped to their nodes by
//! area ([`qdem_core::loads::surface_load::lump_traction`]), on the placed reference mesh.

use super::{BuildError, PlacedMesh};
use crate::scene::{AreaLoad, Scene};
use qdem_core::loads::surface_load::lump_traction;
use qdem_core::Vec3;

/// The mesh-local nodal forces (N, at load factor 1) of `area` on the boundary triangles of
/// `placed` whose nodes are all in `selected` (sorted mesh-local nodes); refused when no
/// boundary triangle is wholly selected (`what`, `body`: the load and its body, for the
/// message).
pub(super) fn lumped_forces(
    scene: &Scene,
    placed: &PlacedMesh,
    selected: &[u32],
    area: AreaLoad,
    (what, body): (&str, &str),
) -> Result<Vec<(u32, Vec3)>, BuildError> {
    let mesh = &placed.mesh;
    let faces: Vec<[u32; 3]> = mesh
        .surface_triangles()
        .into_iter()
        .filter(|t| t.iter().all(|n| selected.binary_search(n).is_ok()))
        .collect();
    if faces.is_empty() {
        return Err(BuildError::EmptySelection {
            scene: scene.path.clone(),
            what: what.to_string(),
            body: body.to_string(),
            fix: "a pressure or traction acts on the boundary triangles whose three nodes are \
                  all selected, and none are; select a whole face (its physical group, or a \
                  box around it)",
        });
    }
    let points: Vec<Vec3> = mesh.nodes.iter().map(|p| Vec3::from(*p)).collect();
    Ok(match area {
        AreaLoad::Pressure(p) => lump_traction(&points, &faces, |n| -p * n),
        AreaLoad::Traction(t) => lump_traction(&points, &faces, |_| Vec3::from(t)),
    })
}
