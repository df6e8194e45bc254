//! The same run gives bit-identical states with 1 and with 2 threads: tetrahedron forces are
//! gathered per particle in a fixed order, never accumulated atomically.

use qdem_core::{
    Dofs, Gravity, Material, Model, NodalLoad, State, Stepper, TetBody, TimeFunction, Vec3, Verlet,
};
use qdem_mesh::structured_box;

fn run() -> State {
    // Large enough that rayon splits both the tetrahedron and the particle loops.
    let mesh = structured_box([0.0; 3], [2.4, 0.25, 0.22], [60, 6, 6]);
    let reference: Vec<Vec3> = mesh.nodes.iter().map(|p| Vec3::from(*p)).collect();
    let material = Material {
        density: 2350.0,
        young: 45e9,
        poisson: 0.167,
        shear_viscosity: 2e3,
        bulk_viscosity: 1e3,
    };
    let body = TetBody::new("beam", &reference, mesh.tets.clone(), material).unwrap();
    let mut state = State::at_rest(reference);
    body.lump_mass(&mut state.mass);
    for &n in &mesh.group("xmin").unwrap().nodes {
        state.fix(n as usize, Dofs::ALL);
    }
    let tip = mesh.group("xmax").unwrap().nodes.clone();
    let ramp = TimeFunction::new(vec![(0.0, 0.0), (1e-3, 1.0)]).unwrap();
    let mut models: Vec<Box<dyn Model>> = vec![
        Box::new(body),
        Box::new(Gravity::new(Vec3::new(0.0, 0.0, -9.81))),
        Box::new(NodalLoad::new("tip", tip, Vec3::new(0.0, 1e5, -2e5), ramp)),
    ];
    let dt = 0.9 * models[0].stable_dt(&state).unwrap();
    let mut stepper = Verlet::new(dt);
    stepper.initialize(&mut state, &mut models).unwrap();
    for _ in 0..200 {
        stepper.step(&mut state, &mut models).unwrap();
    }
    state
}

fn in_pool(threads: usize) -> State {
    rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .unwrap()
        .install(run)
}

#[test]
fn one_and_two_threads_give_bit_identical_states() {
    let (a, b) = (in_pool(1), in_pool(2));
    assert!(
        a.displacement(a.len() - 1).norm() > 0.0,
        "the run must move"
    );
    let bits = |s: &State| -> Vec<u64> {
        s.position
            .iter()
            .chain(&s.velocity)
            .chain(&s.acceleration)
            .flat_map(|v| v.iter().map(|c| c.to_bits()).collect::<Vec<_>>())
            .collect()
    };
    assert!(
        bits(&a) == bits(&b),
        "states differ between 1 and 2 threads"
    );
}
