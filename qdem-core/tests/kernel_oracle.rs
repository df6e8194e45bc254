//! The closed-form particle force T·A_j/3, in its matrix form and in the hot loop's
//! six-component form, equals the literal 12-triangle subdomain sum of paper 000 Eqs. 9–10 on
//! random tetrahedra, deformation gradients and velocity gradients.

use proptest::prelude::*;
use qdem_core::continuum::tet_kernel::{
    cofactor, edge_matrix, tet_forces, tet_stress, vertex_forces,
};
use qdem_core::continuum::tet_subdomain::subdomain_forces;
use qdem_core::{continuum::Material, continuum::TetBody, step::Model, step::State, Mat3, Vec3};

fn vec3() -> impl Strategy<Value = Vec3> {
    prop::array::uniform3(-1.0f64..1.0).prop_map(Vec3::from)
}

fn mat3(scale: f64) -> impl Strategy<Value = Mat3> {
    prop::array::uniform9(-scale..scale).prop_map(|a| Mat3::from_row_slice(&a))
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(2000))]
    #[test]
    fn closed_form_equals_twelve_triangle_oracle(
        reference in prop::array::uniform4(vec3()),
        strain in mat3(0.3),
        rate in mat3(50.0),
        offset in vec3(),
    ) {
        let mut reference = reference;
        let dm = edge_matrix(&reference);
        prop_assume!(dm.determinant().abs() > 1e-3);
        if dm.determinant() < 0.0 {
            reference.swap(1, 2);
        }
        let f = Mat3::identity() + strain;
        prop_assume!(f.determinant() > 0.1);
        let x = reference.map(|p| f * p + offset);
        let v = x.map(|p| rate * p);
        let dm_inv = edge_matrix(&reference).try_inverse().unwrap();
        let (t, cof) = tet_stress(&x, Some(&v), &dm_inv, (3.0e9, 2.0e9), (40.0, 70.0));
        let closed = vertex_forces(&t, &cof);
        let oracle = subdomain_forces(&x, &t);
        let (hot, six_volume) = tet_forces::<true>(&x, &v, &dm_inv, (3.0e9, 2.0e9), (40.0, 70.0));
        let scale = closed.iter().chain(&oracle).map(|g| g.norm()).fold(0.0, f64::max);
        for j in 0..4 {
            prop_assert!((closed[j] - oracle[j]).norm() <= 1e-12 * scale,
                "vertex {}: closed {:?} oracle {:?}", j, closed[j], oracle[j]);
            prop_assert!((hot[j] - oracle[j]).norm() <= 1e-12 * scale,
                "vertex {}: hot loop {:?} oracle {:?}", j, hot[j], oracle[j]);
        }
        prop_assert!((six_volume - edge_matrix(&x).determinant()).abs() <= 1e-12);
        prop_assert!(cofactor(&edge_matrix(&x)).determinant() > 0.0);
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(500))]
    /// The forces a body computes (through the lane kernel of `tet_lanes` where the CPU has
    /// AVX2 or AVX-512, the scalar kernel otherwise) equal the 12-triangle oracle: a single
    /// tetrahedron, so a pack with one real lane and seven padding lanes.
    #[test]
    fn a_body_forces_equal_twelve_triangle_oracle(
        reference in prop::array::uniform4(vec3()),
        strain in mat3(0.3),
        rate in mat3(50.0),
        offset in vec3(),
    ) {
        let mut reference = reference;
        let dm = edge_matrix(&reference);
        prop_assume!(dm.determinant().abs() > 1e-3);
        if dm.determinant() < 0.0 {
            reference.swap(1, 2);
        }
        let f = Mat3::identity() + strain;
        prop_assume!(f.determinant() > 0.1);
        let mut material = Material::elastic(1000.0, 4.0e9, 0.3);
        material.shear_viscosity = 70.0;
        material.bulk_viscosity = 90.0;
        let mut body =
            TetBody::new("tet", &reference, vec![[0, 1, 2, 3]], material.clone()).unwrap();
        let mut state = State::at_rest(reference.to_vec());
        let x = reference.map(|p| f * p + offset);
        state.position = x.to_vec();
        state.velocity = x.iter().map(|p| rate * p).collect();
        let mut force = vec![Vec3::zeros(); 4];
        body.add_forces(&state, &mut force, &mut []);
        let (lame, viscous) = (material.elastic_lame(), material.viscous_lame());
        let v: [Vec3; 4] = std::array::from_fn(|j| state.velocity[j]);
        let dm_inv = edge_matrix(&reference).try_inverse().unwrap();
        let (t, _) = tet_stress(
            &x, Some(&v), &dm_inv, (lame.lambda, lame.mu), (viscous.lambda, viscous.mu),
        );
        let oracle = subdomain_forces(&x, &t);
        let scale = oracle.iter().map(|g| g.norm()).fold(0.0, f64::max);
        // The lanes (fused multiply-adds) and the oracle's 12-triangle sum round differently:
        // a random case differed by 1.0e-12 of the largest force (kept in
        // kernel_oracle.proptest-regressions). 1e-11 still fails any wrong term, which moves a
        // force by far more.
        for j in 0..4 {
            prop_assert!((force[j] - oracle[j]).norm() <= 1e-11 * scale,
                "vertex {}: body {:?} oracle {:?}", j, force[j], oracle[j]);
        }
    }
}
