//! The element bound of the stable step is an upper bound of the true highest frequency of
//! the assembled lumped-mass system, and not a loose one; Verlet runs stably at the bound and
//! diverges just above the true limit; a too-large user step is refused with the bound.

use qdem_core::step::stepper::compute_accelerations;
use qdem_core::{
    continuum::Material, continuum::TetBody, error::CoreError, solvers::Verlet,
    step::stepper::choose_step, step::Model, step::State, step::Stepper, Vec3,
};
use qdem_mesh::structured_box;

fn body_and_state(material: Material) -> (Vec<Box<dyn Model>>, State) {
    let mesh = structured_box([0.0; 3], [0.4, 0.3, 0.2], [4, 3, 2]).unwrap();
    let reference: Vec<Vec3> = mesh.nodes.iter().map(|p| Vec3::from(*p)).collect();
    let body = TetBody::new("block", &reference, mesh.tets, material).unwrap();
    let mut state = State::at_rest(reference);
    body.lump_mass(&mut state.mass);
    (vec![Box::new(body)], state)
}

/// Largest eigenvalue of M⁻¹K by power iteration with small displacements (K from the kernel
/// itself, linearised by a tiny amplitude).
fn largest_eigenvalue(models: &mut [Box<dyn Model>], state: &mut State) -> f64 {
    let n = state.len();
    let mut u: Vec<Vec3> = (0..n)
        .map(|i| {
            Vec3::new(
                (i as f64 * 1.3).sin(),
                (i as f64 * 0.7).cos(),
                (i as f64 * 2.1).sin(),
            )
        })
        .collect();
    let mut force = Vec::new();
    let mut lambda = 0.0;
    let m_dot = |a: &[Vec3], b: &[Vec3], mass: &[f64]| -> f64 {
        a.iter()
            .zip(b)
            .zip(mass)
            .map(|((x, y), m)| m * x.dot(y))
            .sum()
    };
    for _ in 0..3000 {
        let norm = m_dot(&u, &u, &state.mass).sqrt();
        u.iter_mut().for_each(|v| *v /= norm);
        let amp = 1e-9;
        for ((x, x0), ui) in state.position.iter_mut().zip(&state.reference).zip(&u) {
            *x = x0 + amp * ui;
        }
        compute_accelerations(state, models, &mut force, &mut Vec::new()).unwrap();
        // M⁻¹K u = −a / amp; Rayleigh quotient in the M inner product (M⁻¹K is M-symmetric).
        let next: Vec<Vec3> = state.acceleration.iter().map(|a| -a / amp).collect();
        lambda = m_dot(&next, &u, &state.mass);
        u = next;
    }
    lambda
}

#[test]
fn element_bound_is_an_upper_bound_and_tight_within_a_factor_two() {
    let material = Material::elastic(2350.0, 45e9, 0.167);
    let (mut models, mut state) = body_and_state(material);
    let bound = models[0].stable_dt(&state).unwrap();
    let exact_lambda = largest_eigenvalue(&mut models, &mut state);
    let exact_dt = 2.0 / exact_lambda.sqrt();
    assert!(
        bound <= exact_dt,
        "bound {bound:e} above the true limit {exact_dt:e}"
    );
    assert!(
        bound > 0.5 * exact_dt,
        "bound {bound:e} far below the true limit {exact_dt:e}"
    );
}

fn run_free_vibration(dt: f64) -> f64 {
    let material = Material::elastic(2350.0, 45e9, 0.167);
    let (mut models, mut state) = body_and_state(material);
    for (i, v) in state.velocity.iter_mut().enumerate() {
        *v = Vec3::new(
            (i as f64).sin(),
            (i as f64 * 1.7).cos(),
            (i as f64 * 0.3).sin(),
        ) * 1e-3;
    }
    let mut stepper = Verlet::new(dt);
    stepper.initialize(&mut state, &mut models).unwrap();
    let e0 = state.kinetic_energy();
    for _ in 0..4000 {
        if stepper.step(&mut state, &mut models).is_err() {
            return f64::INFINITY;
        }
    }
    state.kinetic_energy() / e0
}

#[test]
fn verlet_is_stable_at_the_bound_and_unstable_well_above_it() {
    let material = Material::elastic(2350.0, 45e9, 0.167);
    let (mut models, mut state) = body_and_state(material);
    let bound = models[0].stable_dt(&state).unwrap();
    let exact = 2.0 / largest_eigenvalue(&mut models, &mut state).sqrt();
    assert!(run_free_vibration(bound) < 10.0);
    assert!(run_free_vibration(1.05 * exact) > 1e6);
}

#[test]
fn viscosity_shrinks_the_bound_and_a_larger_user_step_is_refused() {
    let elastic = Material::elastic(2350.0, 45e9, 0.167);
    let mut viscous = elastic.clone();
    viscous.shear_viscosity = 5e4;
    let (models_e, state) = body_and_state(elastic);
    let (models_v, _) = body_and_state(viscous);
    let (dt_e, dt_v) = (
        models_e[0].stable_dt(&state).unwrap(),
        models_v[0].stable_dt(&state).unwrap(),
    );
    assert!(dt_v < dt_e);
    match choose_step(&state, &models_v, Some(1.01 * dt_v), 0.9) {
        Err(CoreError::StepTooLarge { bound, .. }) => assert_eq!(bound, dt_v),
        other => panic!("expected StepTooLarge, got {other:?}"),
    }
    let auto = choose_step(&state, &models_v, None, 0.9).unwrap();
    assert_eq!(auto, 0.9 * dt_v);
    let message = choose_step(&state, &models_v, Some(1.0), 0.9)
        .unwrap_err()
        .to_string();
    assert!(message.contains(&format!("{dt_v:e}")), "{message}");
}
