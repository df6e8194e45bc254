//! The same run gives bit-identical states with 1 and with 2 threads: tetrahedron forces are
//! gathered per particle in a fixed order, never accumulated atomically.

mod common;

use qdem_core::{solvers::Verlet, step::State, step::Stepper};

fn run() -> State {
    let (mut state, mut models) = common::viscoelastic_beam();
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
    assert!(
        common::motion_bits(&a) == common::motion_bits(&b),
        "states differ between 1 and 2 threads"
    );
}
