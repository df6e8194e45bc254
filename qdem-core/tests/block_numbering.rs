//! A body whose particles are renumbered in block order
//! (`qdem_core::continuum::tet_blocks::block_node_order`) moves exactly as the body in mesh
//! order, particle for particle: the invariant that lets the numbering change without changing
//! a result. Each particle sums the same tetrahedron forces in the same order (tetrahedra
//! within a block ascending, then the blocks ascending), so after Verlet steps on 1 and 2
//! threads, elastic and viscoelastic, every position and velocity agrees bit for bit.

use qdem_core::continuum::tet_blocks::block_node_order;
use qdem_core::{continuum::Material, continuum::TetBody, solvers::Verlet, Vec3};
use qdem_core::{step::Model, step::State, step::Stepper};
use qdem_mesh::structured_box;

/// Positions and velocities after `steps` Verlet steps of a strained, moving block whose
/// particle `i` is numbered `new_of_old[i]`, read back in the mesh's numbering.
fn run(new_of_old: &[u32], viscous: bool, threads: usize, steps: usize) -> Vec<[Vec3; 2]> {
    let mut mesh = structured_box([0.0; 3], [1.0, 0.6, 0.4], [20, 12, 8]).unwrap();
    let original: Vec<Vec3> = mesh.nodes.iter().map(|p| Vec3::from(*p)).collect();
    mesh.renumber_nodes(new_of_old);
    let reference: Vec<Vec3> = mesh.nodes.iter().map(|p| Vec3::from(*p)).collect();
    let mut material = Material::elastic(2350.0, 45e9, 0.167);
    if viscous {
        material.shear_viscosity = 1e4;
        material.bulk_viscosity = 1e3;
    }
    let body = TetBody::new("block", &reference, mesh.tets, material).unwrap();
    let mut state = State::at_rest(reference.clone());
    body.lump_mass(&mut state.mass);
    for (i, (x, v)) in state
        .position
        .iter_mut()
        .zip(&mut state.velocity)
        .enumerate()
    {
        let p = reference[i];
        *x += Vec3::new((3.0 * p.y).sin(), (2.0 * p.z).cos(), (5.0 * p.x).sin()) * 1e-3;
        *v = Vec3::new((4.0 * p.z).cos(), (p.x * 7.0).sin(), (3.0 * p.y).cos()) * 1e-2;
    }
    let dt = 0.5 * body.stable_dt(&state).unwrap();
    let mut models: Vec<Box<dyn Model>> = vec![Box::new(body)];
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .unwrap();
    pool.install(|| {
        let mut verlet = Verlet::new(dt);
        verlet.initialize(&mut state, &mut models).unwrap();
        for _ in 0..steps {
            verlet.step(&mut state, &mut models).unwrap();
        }
    });
    assert!(original.len() == state.len());
    (0..original.len())
        .map(|old| {
            let new = new_of_old[old] as usize;
            [state.position[new], state.velocity[new]]
        })
        .collect()
}

fn check(viscous: bool) {
    let mesh = structured_box([0.0; 3], [1.0, 0.6, 0.4], [20, 12, 8]).unwrap();
    let reference: Vec<Vec3> = mesh.nodes.iter().map(|p| Vec3::from(*p)).collect();
    let identity: Vec<u32> = (0..reference.len() as u32).collect();
    let blocked = block_node_order(&reference, &mesh.tets);
    assert_ne!(blocked, identity, "the block order moves particles");
    let steps = 40;
    let mesh_order = run(&identity, viscous, 1, steps);
    let moved = mesh_order
        .iter()
        .zip(&reference)
        .map(|(s, x)| (s[0] - x).norm())
        .fold(0.0, f64::max);
    assert!(moved > 1e-4, "the block moves: {moved} m");
    for threads in [1, 2] {
        let renumbered = run(&blocked, viscous, threads, steps);
        for (i, (a, b)) in mesh_order.iter().zip(&renumbered).enumerate() {
            assert!(
                a == b,
                "particle {i} on {threads} threads: {a:?} against {b:?}"
            );
        }
    }
}

#[test]
fn elastic_body_in_block_order_moves_bit_for_bit_as_in_mesh_order() {
    check(false);
}

#[test]
fn viscoelastic_body_in_block_order_moves_bit_for_bit_as_in_mesh_order() {
    check(true);
}
