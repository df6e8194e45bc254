//! A `[[load]]`'s `pressure` or `traction` on a face: the body's boundary triangles whose
//! three nodes are all selected (by the physical group or the box), lumped to their nodes by
//! area ([`qdem_core::loads::surface_load::lump_traction`]), on the placed reference mesh.

use super::{BuildError, PlacedMesh};
use crate::scene::{AreaLoad, Scene, Selection};
use qdem_core::loads::surface_load::lump_traction;
use qdem_core::Vec3;

/// The mesh-local nodal forces (N, at load factor 1) of `area` on the boundary triangles of
/// `placed` whose nodes are all in `selected` (sorted mesh-local nodes); refused when no
/// boundary triangle is wholly selected or when `selection` is a volume group, whose
/// boundary is the body's whole closed surface (`what`, `body`: the load and its body, for
/// the message).
pub(super) fn lumped_forces(
    scene: &Scene,
    placed: &PlacedMesh,
    selected: &[u32],
    (selection, area): (&Selection, AreaLoad),
    (what, body): (&str, &str),
) -> Result<Vec<(u32, Vec3)>, BuildError> {
    let mesh = &placed.mesh;
    let not_a_face = |message: String| BuildError::NotAFace {
        scene: scene.path.clone(),
        what: what.to_string(),
        body: body.to_string(),
        message,
    };
    let boundary = mesh.surface_triangles();
    let points: Vec<Vec3> = mesh.nodes.iter().map(|p| Vec3::from(*p)).collect();
    if let Some(group) = volume_group(placed, selection) {
        let area: f64 = boundary.iter().map(|t| triangle_area(&points, t)).sum();
        return Err(not_a_face(format!(
            "`{group}` is a volume group: its nodes are all the body's, so the load would act \
             on the body's whole closed boundary ({} triangles, {area:.6e} m², held faces \
             included), where a uniform pressure sums to zero; fix: give the physical surface \
             of the loaded face as `group` (or a `box` around it)",
            boundary.len()
        )));
    }
    let faces: Vec<[u32; 3]> = boundary
        .into_iter()
        .filter(|t| t.iter().all(|n| selected.binary_search(n).is_ok()))
        .collect();
    if faces.is_empty() {
        return Err(not_a_face(format!(
            "the selection holds {} particle(s) but no boundary triangle whose three nodes it \
             holds, and a pressure or traction acts on such triangles; fix: select a whole face \
             (its physical surface group, or a box around it), or load a point or a line with \
             `total_force`",
            selected.len()
        )));
    }
    Ok(match area {
        AreaLoad::Pressure(p) => lump_traction(&points, &faces, |n| -p * n),
        AreaLoad::Traction(t) => lump_traction(&points, &faces, |_| Vec3::from(t)),
    })
}

/// The name of the volume (dimension 3) physical group `selection` names, if it does.
fn volume_group<'a>(placed: &PlacedMesh, selection: &'a Selection) -> Option<&'a str> {
    match selection {
        Selection::Group(name) => placed
            .mesh
            .group(name)
            .is_some_and(|g| g.dim == 3)
            .then_some(name.as_str()),
        Selection::Box(_) => None,
    }
}

/// The area of triangle `t` of `points`.
fn triangle_area(points: &[Vec3], t: &[u32; 3]) -> f64 {
    let [a, b, c] = t.map(|n| points[n as usize]);
    0.5 * (b - a).cross(&(c - a)).norm()
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
    let forces = lumped_forces(
        scene,
        &placed,
        &selected,
        (&load.selection, area),
        (&what, &load.body),
    )?;
    Ok(forces.iter().map(|(_, f)| f).sum())
}
