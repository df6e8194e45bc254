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

/// The resultant (N, at load factor 1) of the `[[load]]` numbered `k` (from 0) of `scene`:
/// its `total_force`, or the sum of its pressure's or traction's nodal forces
/// ([`lumped_forces`]): p·A along the inward normal for a pressure on a plane face of area A,
/// t·A for a traction. Reads the body's mesh for a pressure or traction only, placed as
/// `rotate_deg` and `translate` place it; `pose_from` and `rest_on` then move the body
/// rigidly, which keeps the resultant's size (the faces a `box` selects are those of the
/// mesh so placed).
///
/// ```no_run
/// # fn main() -> Result<(), Box<dyn std::error::Error>> {
/// let scene = qdem_io::scene::Scene::load(std::path::Path::new("block.toml"))?;
/// let force = qdem_io::build::load_resultant(&scene, 0)?;
/// println!("the first load pushes with {:.3e} N", force.norm());
/// # Ok(())
/// # }
/// ```
pub fn load_resultant(scene: &Scene, k: usize) -> Result<Vec3, BuildError> {
    let load = &scene.loads[k];
    let Some(area) = load.area else {
        return Ok(Vec3::from(load.total_force));
    };
    let body = &scene.bodies[scene.refs().load_bodies[k]];
    let path = scene.mesh_path(body);
    let mut mesh = super::read_mesh(&path, &mut Vec::new())?;
    if body.merge_nodes {
        mesh.merge_coincident_nodes();
    }
    super::place(&mut mesh, body.rotate_deg, body.translate);
    let placed = PlacedMesh {
        particles: 0..mesh.nodes.len(),
        mesh,
        path,
        rotation: nalgebra::UnitQuaternion::identity(),
    };
    let what = format!("[[load]] #{}", k + 1);
    let selected = super::select(scene, &placed, &load.selection, &what, &load.body)?;
    let forces = lumped_forces(scene, &placed, &selected, area, (&what, &load.body))?;
    Ok(forces.iter().map(|(_, f)| f).sum())
}
