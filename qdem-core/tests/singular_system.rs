//! Singular systems are refused with a message naming the body: a deformable body free to move
//! rigidly under a static solve gives `Unconstrained`, while implicit Newmark (whose effective
//! matrix M + γ∆t C + β∆t² K is positive definite through the mass) steps it fine; a failed
//! factorisation names the particle of the failing pivot and its model.

use qdem_core::{
    continuum::Material, continuum::TetBody, error::CoreError, loads::NodalLoad,
    loads::TimeFunction, solvers::Newmark, solvers::StaticSolver, step::Dofs, step::Linearized,
    step::Model, step::State, step::Stepper, step::Tangent, Mat3, Vec3,
};
use qdem_mesh::structured_box;

const FORCE: [f64; 3] = [0.0, 0.0, -500.0];

/// A free 1 × 0.4 × 0.3 m block named "block" with a constant total load on its x = 1 face.
fn block() -> (State, Vec<Box<dyn Model>>) {
    let mesh = structured_box([0.0; 3], [1.0, 0.4, 0.3], [5, 2, 2]).unwrap();
    let reference: Vec<Vec3> = mesh.nodes.iter().map(|p| Vec3::from(*p)).collect();
    let body = TetBody::new(
        "block",
        &reference,
        mesh.tets,
        Material::elastic(2000.0, 1e9, 0.25),
    )
    .unwrap();
    let mut state = State::at_rest(reference);
    body.lump_mass(&mut state.mass);
    let face: Vec<u32> = (0..state.len() as u32)
        .filter(|&i| state.reference[i as usize].x == 1.0)
        .collect();
    let load = NodalLoad::new("tip", face, Vec3::from(FORCE), TimeFunction::constant(1.0));
    (state, vec![Box::new(body), Box::new(load)])
}

/// Fixes `dofs` on the x = 0 face.
fn fix_face(state: &mut State, dofs: Dofs) {
    for i in 0..state.len() {
        if state.reference[i].x == 0.0 {
            state.fix(i, dofs);
        }
    }
}

#[test]
fn a_free_block_is_refused_by_the_static_solve_naming_it() {
    let (mut state, mut models) = block();
    let error = StaticSolver::new()
        .solve(&mut state, &mut models, 0.0)
        .unwrap_err();
    let message = error.to_string();
    println!("{message}");
    assert!(matches!(
        error,
        CoreError::Unconstrained { ref body, modes: 6, .. } if body == "block"
    ));
    assert!(message.contains("`block`"), "{message}");
    assert!(message.contains("[[fix]]"), "{message}");
    assert!(state
        .position
        .iter()
        .all(|x| x.iter().all(|c| c.is_finite())));
}

#[test]
fn a_block_on_rollers_only_is_still_refused() {
    // Fixing x on a face removes the x translation and the rotations about y and z only.
    let (mut state, mut models) = block();
    fix_face(&mut state, Dofs::parse("x").unwrap());
    let error = StaticSolver::new()
        .solve(&mut state, &mut models, 0.0)
        .unwrap_err();
    println!("{error}");
    assert!(matches!(
        error,
        CoreError::Unconstrained { ref body, modes: 3, .. } if body == "block"
    ));
}

#[test]
fn a_free_block_steps_implicitly_with_momentum_growing_as_force_times_time() {
    let (mut state, mut models) = block();
    let dt = 1e-4;
    let mut stepper = Newmark::average_acceleration(dt);
    stepper.initialize(&mut state, &mut models).unwrap();
    let steps = 200;
    for _ in 0..steps {
        stepper.step(&mut state, &mut models).unwrap();
    }
    assert!(state
        .position
        .iter()
        .chain(&state.velocity)
        .all(|x| x.iter().all(|c| c.is_finite())));
    let momentum: Vec3 = (0..state.len())
        .map(|i| state.mass[i] * state.velocity[i])
        .sum();
    let expected = Vec3::from(FORCE) * state.time;
    let error = (momentum - expected).norm() / expected.norm();
    println!("momentum {momentum:?}, F t = {expected:?}, relative error {error:.2e}");
    assert!(error < 1e-9, "relative momentum error {error:e}");
}

#[test]
fn a_block_fixed_on_one_face_solves() {
    let (mut state, mut models) = block();
    fix_face(&mut state, Dofs::ALL);
    let mut solver = StaticSolver::new();
    solver.solve(&mut state, &mut models, 0.0).unwrap();
    let tip = (0..state.len())
        .filter(|&i| state.reference[i].x == 1.0)
        .map(|i| state.displacement(i).z)
        .sum::<f64>();
    assert!(state
        .position
        .iter()
        .all(|x| x.iter().all(|c| c.is_finite())));
    assert!(tip < 0.0, "the tip moves with the load: {tip}");
}

/// Springs from each particle to its reference position, one of them of zero stiffness; the
/// model owns the particles, so it is named like a body.
struct Springs {
    loose: usize,
    count: usize,
}

impl Model for Springs {
    fn name(&self) -> &str {
        "springs"
    }

    fn add_forces(&mut self, state: &State, force: &mut [Vec3], _torque: &mut [Vec3]) {
        for (i, f) in force.iter_mut().enumerate().take(self.count) {
            if i != self.loose {
                *f -= state.displacement(i);
            }
        }
    }

    fn linearized(&self) -> Option<&dyn Linearized> {
        Some(self)
    }
}

impl Linearized for Springs {
    fn add_tangent(&self, _state: &State, tangent: &mut Tangent) {
        for i in (0..self.count).filter(|&i| i != self.loose) {
            tangent.add_stiffness(i, i, &Mat3::identity());
        }
    }
    fn particles(&self) -> Vec<usize> {
        (0..self.count).collect()
    }
}

#[test]
fn a_failed_pivot_names_its_particle_and_model() {
    let count = 12;
    for loose in [0, 5, 11] {
        let reference = (0..count).map(|i| Vec3::new(i as f64, 0.0, 0.0)).collect();
        let mut state = State::at_rest(reference);
        state.mass.fill(1.0);
        let mut models: Vec<Box<dyn Model>> = vec![Box::new(Springs { loose, count })];
        let error = StaticSolver::new()
            .solve(&mut state, &mut models, 0.0)
            .unwrap_err();
        let message = error.to_string();
        println!("{message}");
        assert!(matches!(
            error,
            CoreError::NotPositiveDefinite { particle: Some(p), body: Some(ref b), .. }
                if p == loose && b == "springs"
        ));
        assert!(message.contains(&format!("particle {loose}")), "{message}");
    }
}
