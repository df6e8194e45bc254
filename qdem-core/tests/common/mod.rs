//! Test scenes shared by several integration tests.

#![allow(dead_code)] // each test binary uses a subset

use qdem_core::{
    continuum::Material, continuum::TetBody, loads::Gravity, loads::NodalLoad, loads::TimeFunction,
    step::Dofs, step::Model, step::State, Vec3,
};
use qdem_mesh::{structured_box, TetMesh};

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

/// The viscoelastic concrete cantilever of the determinism tests: 60 × 6 × 6 cells (12,960
/// tetrahedra, large enough that rayon splits the tetrahedron and particle loops and that its
/// 16 blocks fall on several ranks), clamped, under a tip load of (0, 100, −200) kN.
pub fn viscoelastic_beam() -> (State, Vec<Box<dyn Model>>) {
    let mesh = structured_box([0.0; 3], [2.4, 0.25, 0.22], [60, 6, 6]).unwrap();
    let material = Material {
        density: 2350.0,
        young: 45e9,
        poisson: 0.167,
        shear_viscosity: 2e3,
        bulk_viscosity: 1e3,
    };
    clamped_beam(&mesh, material, Vec3::new(0.0, 1e5, -2e5))
}

/// The bits of every position, velocity and acceleration of `s`, for bit-for-bit comparisons.
pub fn motion_bits(s: &State) -> Vec<u64> {
    s.position
        .iter()
        .chain(&s.velocity)
        .chain(&s.acceleration)
        .flat_map(|v| v.iter().map(|c| c.to_bits()).collect::<Vec<_>>())
        .collect()
}
