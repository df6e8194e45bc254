//! Test scenes shared by several integration tests.

use qdem_core::{Dofs, Gravity, Material, Model, NodalLoad, State, TetBody, TimeFunction, Vec3};
use qdem_mesh::TetMesh;

/// A cantilever over `mesh` (clamped on its `xmin` group) of `material`, under gravity and a
/// tip load `tip_force` on its `xmax` group ramped up over the first millisecond: the state at
/// rest with lumped masses and the models (the body first).
pub fn clamped_beam(
    mesh: &TetMesh,
    material: Material,
    tip_force: Vec3,
) -> (State, Vec<Box<dyn Model>>) {
    let reference: Vec<Vec3> = mesh.nodes.iter().map(|p| Vec3::from(*p)).collect();
    let body = TetBody::new("beam", &reference, mesh.tets.clone(), material).unwrap();
    let mut state = State::at_rest(reference);
    body.lump_mass(&mut state.mass);
    for &n in &mesh.group("xmin").unwrap().nodes {
        state.fix(n as usize, Dofs::ALL);
    }
    let tip = mesh.group("xmax").unwrap().nodes.clone();
    let ramp = TimeFunction::new(vec![(0.0, 0.0), (1e-3, 1.0)]).unwrap();
    let models: Vec<Box<dyn Model>> = vec![
        Box::new(body),
        Box::new(Gravity::new(Vec3::new(0.0, 0.0, -9.81))),
        Box::new(NodalLoad::new("tip", tip, tip_force, ramp)),
    ];
    (state, models)
}
