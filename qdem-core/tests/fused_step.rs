//! The Verlet step a deformable body takes inside its block pass (`qdem_core::step::fused`)
//! gives the same bits as the stepper's separate sweeps: on a deformed, moving block of many
//! blocks with free particles before and after it, gravity deferred to the integration, fixed
//! directions, elastic and viscoelastic, on 1 and 2 threads; and a non-finite state names the
//! same particle either way.

use qdem_core::error::CoreError;
use qdem_core::loads::Gravity;
use qdem_core::solvers::Verlet;
use qdem_core::step::{Dofs, Model, State, Stepper};
use qdem_core::{continuum::Material, continuum::TetBody, Vec3};
use qdem_mesh::structured_box;

/// Free particles before the body's.
const BEFORE: usize = 3;

/// A block of 11,520 tetrahedra (16 blocks or more) between free particles, deformed and
/// moving, its x = 0 face held and a line of particles held in z, under gravity.
fn scene(viscous: bool) -> (State, Vec<Box<dyn Model>>, f64) {
    let mesh = structured_box([0.0; 3], [1.0, 0.6, 0.4], [20, 12, 8]).unwrap();
    let mut reference: Vec<Vec3> = (0..BEFORE)
        .map(|i| Vec3::new(-1.0, i as f64, 0.0))
        .collect();
    reference.extend(mesh.nodes.iter().map(|p| Vec3::from(*p)));
    reference.extend([Vec3::new(2.0, 0.0, 0.0), Vec3::new(2.0, 1.0, 0.0)]);
    let tets = mesh
        .tets
        .iter()
        .map(|t| t.map(|n| n + BEFORE as u32))
        .collect();
    let mut material = Material::elastic(2350.0, 45e9, 0.167);
    if viscous {
        material.shear_viscosity = 1e4;
        material.bulk_viscosity = 1e3;
    }
    let body = TetBody::new("block", &reference, tets, material).unwrap();
    assert!(body.block_layout().blocks >= 16 && body.block_layout().interior > 0);
    let mut state = State::at_rest(reference.clone());
    body.lump_mass(&mut state.mass);
    let free = (0..BEFORE).chain(reference.len() - 2..reference.len());
    for i in free {
        state.mass[i] = 1.0;
        state.velocity[i] = Vec3::new(0.1, 0.0, 0.2);
    }
    for (i, p) in reference.iter().enumerate().skip(BEFORE) {
        state.position[i] +=
            Vec3::new((3.0 * p.y).sin(), (2.0 * p.z).cos(), (5.0 * p.x).sin()) * 1e-4;
        state.velocity[i] =
            Vec3::new((4.0 * p.z).cos(), (p.x * 7.0).sin(), (3.0 * p.y).cos()) * 1e-2;
        if p.x == 0.0 {
            state.fixed[i] = Dofs::ALL;
            state.velocity[i] = Vec3::zeros();
        } else if p.y == 0.3 {
            state.fixed[i] = Dofs::parse("z").unwrap();
            state.velocity[i].z = 0.0;
        }
    }
    let dt = 0.5 * body.stable_dt(&state).unwrap();
    let models: Vec<Box<dyn Model>> = vec![
        Box::new(body),
        Box::new(Gravity::new(Vec3::new(0.0, 0.0, -9.81))),
    ];
    (state, models, dt)
}

/// `steps` steps on `threads` threads, fused or in separate passes, from the state `poison`
/// changes after the initialisation: the state and the last forces, or the error.
fn run(
    viscous: bool,
    threads: usize,
    fused: bool,
    steps: usize,
    poison: impl Fn(&mut State) + Send + Sync,
) -> Result<(State, Vec<Vec3>), CoreError> {
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .unwrap();
    pool.install(|| {
        let (mut state, mut models, dt) = scene(viscous);
        assert!(models[0].fused().is_some());
        let mut verlet = match fused {
            true => Verlet::new(dt),
            false => Verlet::new(dt).with_separate_passes(),
        };
        verlet.initialize(&mut state, &mut models)?;
        poison(&mut state);
        for _ in 0..steps {
            verlet.step(&mut state, &mut models)?;
        }
        Ok((state, Stepper::forces(&verlet).to_vec()))
    })
}

fn same_bits(viscous: bool) {
    let (want, want_forces) = run(viscous, 1, false, 40, |_| {}).unwrap();
    let moved = (want.position[BEFORE + 500] - want.reference[BEFORE + 500]).norm();
    assert!(moved > 1e-5 && want.kinetic_energy().is_finite());
    for threads in [1, 2] {
        let (state, forces) = run(viscous, threads, true, 40, |_| {}).unwrap();
        assert!(state == want, "{threads} threads, viscous: {viscous}");
        assert!(
            forces == want_forces,
            "{threads} threads, viscous: {viscous}"
        );
    }
}

#[test]
fn a_fused_elastic_step_is_bit_identical_to_the_separate_passes() {
    same_bits(false);
}

#[test]
fn a_fused_viscoelastic_step_is_bit_identical_to_the_separate_passes() {
    same_bits(true);
}

#[test]
fn a_non_finite_state_names_the_same_particle_fused_or_not() {
    let poison = |state: &mut State| state.velocity[BEFORE + 1200].y = f64::NAN;
    let particle = |fused, threads| match run(true, threads, fused, 3, poison) {
        Err(CoreError::NonFinite { particle, .. }) => particle,
        other => panic!("fused: {fused}: {:?}", other.map(|_| ())),
    };
    let want = particle(false, 1);
    assert!(want >= BEFORE);
    assert_eq!(particle(true, 1), want);
    assert_eq!(particle(true, 2), want);
}
