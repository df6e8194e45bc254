//! The blocked scatter of a body's tetrahedron forces (`qdem_core::continuum::tet_blocks`) gives every
//! particle the sum of its tetrahedra's forces: against a plain serial sum over the
//! tetrahedra in mesh order, on a deformed, moving block of many blocks, elastic and
//! viscoelastic, equal to round-off (the two sum in different orders).

use qdem_core::continuum::tet_kernel::{edge_matrix, tet_stress, vertex_forces};
use qdem_core::{continuum::Material, continuum::TetBody, step::Model, step::State, Vec3};
use qdem_mesh::structured_box;

fn check(viscous: bool) {
    let mesh = structured_box([0.0; 3], [1.0, 0.6, 0.4], [20, 12, 8]).unwrap();
    let reference: Vec<Vec3> = mesh.nodes.iter().map(|p| Vec3::from(*p)).collect();
    let mut material = Material::elastic(2350.0, 45e9, 0.167);
    if viscous {
        material.shear_viscosity = 1e4;
        material.bulk_viscosity = 1e3;
    }
    let lame = (material.elastic_lame(), material.viscous_lame());
    let mut body = TetBody::new("block", &reference, mesh.tets.clone(), material).unwrap();
    let mut state = State::at_rest(reference.clone());
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
    let mut force = vec![Vec3::zeros(); state.len()];
    body.add_forces(&state, &mut force, &mut []);

    let mut serial = vec![Vec3::zeros(); state.len()];
    for tet in &mesh.tets {
        let x = tet.map(|n| state.position[n as usize]);
        let v = tet.map(|n| state.velocity[n as usize]);
        let dm_inv = edge_matrix(&tet.map(|n| reference[n as usize]))
            .try_inverse()
            .unwrap();
        let (t, cof) = tet_stress(
            &x,
            viscous.then_some(&v),
            &dm_inv,
            (lame.0.lambda, lame.0.mu),
            (lame.1.lambda, lame.1.mu),
        );
        for (&n, f) in tet.iter().zip(vertex_forces(&t, &cof)) {
            serial[n as usize] += f;
        }
    }
    // Round-off of a sum of about 20 terms per particle, each up to the largest tetrahedron
    // force: a few ulps of that force.
    let largest = serial.iter().map(|f| f.norm()).fold(0.0, f64::max);
    for (i, (a, b)) in force.iter().zip(&serial).enumerate() {
        assert!(
            (a - b).norm() <= 1e-13 * largest,
            "particle {i}: blocked {a} against serial {b}"
        );
    }
    assert!(largest > 1e3, "the block is strained: {largest} N");
}

#[test]
fn elastic_blocked_forces_equal_the_serial_sum() {
    check(false);
}

#[test]
fn viscoelastic_blocked_forces_equal_the_serial_sum() {
    check(true);
}
