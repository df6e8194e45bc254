//! In the small-strain limit the QDEM kernel is the linear-tetrahedron FEM stiffness:
//! f_QDEM(X + u) = −K u + O(|u|²), and a clamped block under a tip load solved statically by
//! the linear-tet oracle is in equilibrium under the QDEM forces.

use qdem_core::continuum::linear_tet::LinearTets;
use qdem_core::{
    continuum::Material, continuum::TetBody, step::Dofs, step::Model, step::State, Vec3,
};
use qdem_mesh::structured_box;

fn setup() -> (Vec<Vec3>, Vec<[u32; 4]>, Material) {
    let mesh = structured_box([0.0; 3], [1.2, 0.2, 0.15], [12, 3, 2]).unwrap();
    let reference = mesh.nodes.iter().map(|p| Vec3::from(*p)).collect();
    (reference, mesh.tets, Material::elastic(2350.0, 45e9, 0.167))
}

fn qdem_force(reference: &[Vec3], tets: &[[u32; 4]], material: &Material, u: &[Vec3]) -> Vec<Vec3> {
    let mut body = TetBody::new("block", reference, tets.to_vec(), material.clone()).unwrap();
    let mut state = State::at_rest(reference.to_vec());
    for (x, d) in state.position.iter_mut().zip(u) {
        *x += d;
    }
    let mut force = vec![Vec3::zeros(); reference.len()];
    body.add_forces(&state, &mut force, &mut []);
    force
}

#[test]
fn qdem_force_linearises_to_the_linear_tet_stiffness() {
    let (reference, tets, material) = setup();
    let k = LinearTets::new(&reference, &tets, material.elastic_lame());
    let shape = |x: &Vec3| {
        Vec3::new(
            (2.0 * x.y).sin() + x.z,
            (3.0 * x.x).cos(),
            (x.x * x.y * 5.0).sin(),
        )
    };
    for amplitude in [1e-6, 1e-7] {
        let u: Vec<Vec3> = reference.iter().map(|x| amplitude * shape(x)).collect();
        let mut ku = vec![Vec3::zeros(); u.len()];
        k.apply(&u, &mut ku);
        let f = qdem_force(&reference, &tets, &material, &u);
        let diff: f64 = f
            .iter()
            .zip(&ku)
            .map(|(a, b)| (a + b).norm_squared())
            .sum::<f64>()
            .sqrt();
        let size: f64 = ku.iter().map(|v| v.norm_squared()).sum::<f64>().sqrt();
        // The geometric non-linearity is of the order of the strain (~amplitude here).
        assert!(
            diff / size < 10.0 * amplitude,
            "amplitude {amplitude:e}: relative difference {:e}",
            diff / size
        );
    }
}

/// Relative residual ‖f_QDEM(u) + K u‖/‖K u‖ at the linear-tet static solution u of a clamped
/// block under a tip load `load` (N).
fn static_residual(load: f64) -> f64 {
    let (reference, tets, material) = setup();
    let k = LinearTets::new(&reference, &tets, material.elastic_lame());
    let fixed: Vec<Dofs> = reference
        .iter()
        .map(|x| if x.x == 0.0 { Dofs::ALL } else { Dofs::NONE })
        .collect();
    let tip: Vec<usize> = (0..reference.len())
        .filter(|&i| (reference[i].x - 1.2).abs() < 1e-12)
        .collect();
    let mut f = vec![Vec3::zeros(); reference.len()];
    for &i in &tip {
        f[i] = Vec3::new(0.0, 0.0, -load / tip.len() as f64);
    }
    let solution = k.solve(&f, &fixed, 1e-14);
    assert!(solution.relative_residual <= 1e-14);
    let internal = qdem_force(&reference, &tets, &material, &solution.displacement);
    let mut ku = vec![Vec3::zeros(); reference.len()];
    k.apply(&solution.displacement, &mut ku);
    let diff: f64 = internal
        .iter()
        .zip(&ku)
        .map(|(a, b)| (a + b).norm_squared())
        .sum::<f64>()
        .sqrt();
    diff / ku.iter().map(|v| v.norm_squared()).sum::<f64>().sqrt()
}

#[test]
fn static_oracle_solution_differs_from_qdem_equilibrium_only_at_second_order() {
    // The linearised field's rotation part ω gives F Fᵀ − I = −ω² in the QDEM kernel: a stress
    // of order E·ω², quadratic in the load. The linear parts agree exactly, so the relative
    // residual must fall tenfold when the load does.
    let (big, small) = (static_residual(200.0), static_residual(20.0));
    assert!(big < 1e-3, "relative residual {big:e} at 200 N");
    let ratio = small / big;
    assert!(
        (ratio - 0.1).abs() < 0.001,
        "residual ratio {ratio} for a tenfold load ratio"
    );
}
