//! Patch tests of the QDEM kernel on a structured block of tetrahedra: rigid motions give zero
//! stress to round-off, and a uniform strain reproduces Hooke's law exactly.

use qdem_core::continuum::tet_kernel::{deformation_gradient, elastic_stress, tet_stress};
use qdem_core::{continuum::Material, continuum::TetBody, step::Model, step::State, Mat3, Vec3};
use qdem_mesh::structured_box;

const YOUNG: f64 = 45e9;

fn block() -> (Vec<Vec3>, Vec<[u32; 4]>) {
    let mesh = structured_box([0.0; 3], [1.0, 0.6, 0.4], [4, 3, 2]).unwrap();
    (
        mesh.nodes.iter().map(|p| Vec3::from(*p)).collect(),
        mesh.tets,
    )
}

fn viscoelastic() -> Material {
    Material {
        density: 2350.0,
        young: YOUNG,
        poisson: 0.167,
        shear_viscosity: 1e4,
        bulk_viscosity: 3e3,
    }
}

/// Largest particle force of the body at the given positions and velocities, in units of
/// E·(edge length)² so that round-off shows as ~1e-15.
fn largest_relative_force(positions: Vec<Vec3>, velocities: Vec<Vec3>) -> f64 {
    let (reference, tets) = block();
    let mut body = TetBody::new("block", &reference, tets, viscoelastic()).unwrap();
    let mut state = State::at_rest(reference);
    state.position = positions;
    state.velocity = velocities;
    let mut force = vec![Vec3::zeros(); state.len()];
    body.add_forces(&state, &mut force, &mut []);
    let edge = 0.2f64;
    force.iter().map(|f| f.norm()).fold(0.0, f64::max) / (YOUNG * edge * edge)
}

fn rotation(axis: Vec3, angle: f64) -> Mat3 {
    *nalgebra::Rotation3::from_axis_angle(&nalgebra::Unit::new_normalize(axis), angle).matrix()
}

#[test]
fn rigid_translation_gives_zero_force() {
    let (reference, _) = block();
    let shift = Vec3::new(12.5, -3.0, 7.25);
    let x = reference.iter().map(|p| p + shift).collect();
    let v = vec![Vec3::new(3.0, 1.0, -2.0); reference.len()];
    let r = largest_relative_force(x, v);
    assert!(r < 1e-14, "relative force {r:e}");
}

#[test]
fn ninety_degree_rotation_gives_zero_force() {
    let (reference, _) = block();
    let q = rotation(Vec3::new(1.0, 2.0, 3.0), std::f64::consts::FRAC_PI_2);
    let x = reference.iter().map(|p| q * p).collect();
    let r = largest_relative_force(x, vec![Vec3::zeros(); reference.len()]);
    assert!(r < 1e-14, "relative force {r:e}");
}

#[test]
fn fast_spin_gives_zero_stress() {
    // A body rotated by 1 rad and spinning at 1000 rad/s: the spin tensor W carries all of
    // the velocity gradient, D = 0, so neither elastic nor viscous stress may appear.
    let (reference, _) = block();
    let q = rotation(Vec3::new(0.3, -1.0, 0.5), 1.0);
    let omega = Vec3::new(0.0, 600.0, 800.0);
    let x: Vec<Vec3> = reference.iter().map(|p| q * p).collect();
    let v = x.iter().map(|p| omega.cross(p)).collect();
    let r = largest_relative_force(x, v);
    // Viscous stress ~ μ_D·|ω| = 1e7 Pa would give a relative force of 2e-4.
    assert!(r < 1e-14, "relative force {r:e}");
}

#[test]
fn uniform_strain_reproduces_hooke_and_balances_interior_particles() {
    let (reference, tets) = block();
    let material = Material::elastic(2350.0, YOUNG, 0.167);
    let lame = material.elastic_lame();
    let f = Mat3::new(
        1.0 + 2e-4,
        5e-5,
        0.0,
        -3e-5,
        1.0 - 1e-4,
        4e-5,
        1e-5,
        0.0,
        1.0 + 6e-5,
    );
    let expected = elastic_stress(&f, lame.lambda, lame.mu);
    // B − I cancels all but ~|ε| of F's digits: the round-off floor of the stress is about
    // ε_machine / |ε|. Allow 100 times that (|ε| ≈ 1e-4 here: 2.2e-10).
    let tol = 100.0 * f64::EPSILON / 1e-4;
    // Every tetrahedron sees exactly F and the Hooke stress of Eq. 2.
    let x: Vec<Vec3> = reference.iter().map(|p| f * p).collect();
    for tet in &tets {
        let xr = tet.map(|n| reference[n as usize]);
        let xc = tet.map(|n| x[n as usize]);
        let dm_inv = qdem_core::continuum::tet_kernel::edge_matrix(&xr)
            .try_inverse()
            .unwrap();
        let got_f = deformation_gradient(&xc, &dm_inv);
        assert!((got_f - f).norm() < 1e-14);
        let (t, _) = tet_stress(&xc, None, &dm_inv, (lame.lambda, lame.mu), (0.0, 0.0));
        assert!((t - expected).norm() <= tol * expected.norm());
    }
    // Under a uniform stress the forces on interior faces cancel, so every particle receives
    // −T·a/3 from each boundary triangle a it belongs to (outward, current area vector: the
    // internal force that balances an external traction T·n), and interior particles nothing.
    let mesh = structured_box([0.0; 3], [1.0, 0.6, 0.4], [4, 3, 2]).unwrap();
    let mut body = TetBody::new("block", &reference, tets, material).unwrap();
    let mut state = State::at_rest(reference.clone());
    state.position = x.clone();
    let mut force = vec![Vec3::zeros(); state.len()];
    body.add_forces(&state, &mut force, &mut []);
    let mut expected_force = vec![Vec3::zeros(); state.len()];
    for tri in mesh.surface_triangles() {
        let [a, b, c] = tri.map(|n| x[n as usize]);
        let area = 0.5 * (b - a).cross(&(c - a));
        for n in tri {
            expected_force[n as usize] -= expected * area / 3.0;
        }
    }
    let scale = expected.norm() * 0.25 * 0.2 * 0.2;
    for (got, want) in force.iter().zip(&expected_force) {
        assert!(
            (got - want).norm() < tol * scale,
            "force {got:?}, expected {want:?}"
        );
    }
}
