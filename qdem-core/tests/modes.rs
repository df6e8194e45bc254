//! Natural modes by shift-invert Lanczos ([`qdem_core::modal::lanczos`]) against an independent
//! dense eigen-solve of the same K and M, rigid-body modes, beam theory and bad input.

use nalgebra::{DMatrix, DVector, SymmetricEigen};
use qdem_core::modal::lanczos::{natural_modes, ModalError, Modes};
use qdem_core::{
    continuum::Material, continuum::TetBody, step::Dofs, step::Linearized, step::Model,
    step::State, step::Tangent, Vec3,
};
use qdem_mesh::structured_box;
use std::f64::consts::PI;

const E: f64 = 45e9;
const NU: f64 = 0.167;
const RHO: f64 = 2350.0;

/// A prism [0, l] × [0, b] × [0, h] of `cells`, clamped at x = 0 if `clamped`.
fn prism(l: f64, b: f64, h: f64, cells: [usize; 3], clamped: bool) -> (State, Vec<Box<dyn Model>>) {
    let mesh = structured_box([0.0; 3], [l, b, h], cells).unwrap();
    let reference: Vec<Vec3> = mesh.nodes.iter().map(|p| Vec3::from(*p)).collect();
    let body = TetBody::new(
        "prism",
        &reference,
        mesh.tets,
        Material::elastic(RHO, E, NU),
    )
    .unwrap();
    let mut state = State::at_rest(reference);
    body.lump_mass(&mut state.mass);
    if clamped {
        for (i, x) in state.reference.iter().enumerate() {
            if x.x == 0.0 {
                state.fixed[i] = Dofs::ALL;
            }
        }
    }
    (state, vec![Box::new(body)])
}

/// All eigenvalues ω² (ascending) and M-normalised eigenvectors of K φ = ω² M φ over the free
/// DOFs, from the dense M^{-1/2} K M^{-1/2} (nalgebra).
fn dense_modes(state: &State, body: &dyn Linearized) -> (Vec<f64>, Vec<DVector<f64>>, Vec<usize>) {
    let mut tangent = Tangent::new();
    body.add_tangent(state, &mut tangent);
    let free: Vec<usize> = (0..3 * state.len())
        .filter(|&d| !state.fixed[d / 3].contains(d % 3))
        .collect();
    let mut index = vec![usize::MAX; 3 * state.len()];
    for (i, &d) in free.iter().enumerate() {
        index[d] = i;
    }
    let n = free.len();
    let scale: Vec<f64> = free
        .iter()
        .map(|&d| state.mass[d / 3].sqrt().recip())
        .collect();
    let mut a = DMatrix::<f64>::zeros(n, n);
    for e in tangent.stiffness_entries() {
        let (r, c) = (index[e.row], index[e.col]);
        if r != usize::MAX && c != usize::MAX {
            let v = e.val * scale[r] * scale[c];
            a[(r, c)] += v;
            if r != c {
                a[(c, r)] += v;
            }
        }
    }
    let eigen = SymmetricEigen::new(a);
    let mut order: Vec<usize> = (0..n).collect();
    order.sort_by(|&x, &y| eigen.eigenvalues[x].total_cmp(&eigen.eigenvalues[y]));
    let values = order.iter().map(|&k| eigen.eigenvalues[k]).collect();
    let vectors = order
        .iter()
        .map(|&k| {
            eigen
                .eigenvectors
                .column(k)
                .component_mul(&DVector::from_vec(scale.clone()))
        })
        .collect();
    (values, vectors, free)
}

fn lanczos(state: &State, models: &[Box<dyn Model>], count: usize) -> Modes {
    natural_modes(state, models, count).unwrap()
}

/// Relative frequency difference.
fn relative(a: f64, b: f64) -> f64 {
    (a - b).abs() / b.abs()
}

/// The Lanczos modes of a small prism equal the dense solve's to 1e-8: frequencies, and the
/// shapes up to sign (M-inner product of the two shapes ±1; the prism's dimensions are
/// distinct, so no mode is repeated).
fn assert_matches_dense(clamped: bool, count: usize) {
    let (state, models) = prism(0.6, 0.08, 0.11, [6, 2, 2], clamped);
    let modes = lanczos(&state, &models, count);
    let (values, vectors, free) = dense_modes(&state, models[0].linearized().unwrap());
    assert_eq!(modes.dofs, free.len());
    let rigid = if clamped { 0 } else { 6 };
    assert_eq!(modes.modes.iter().filter(|m| m.rigid).count(), rigid);
    for (k, mode) in modes.modes.iter().enumerate().skip(rigid) {
        let dense = values[k].sqrt() / (2.0 * PI);
        assert!(
            relative(mode.frequency_hz, dense) < 1e-8,
            "mode {k}: Lanczos {} Hz, dense {dense} Hz",
            mode.frequency_hz
        );
        let overlap: f64 = free
            .iter()
            .zip(vectors[k].iter())
            .map(|(&d, v)| mode.shape[d / 3][d % 3] * state.mass[d / 3] * v)
            .sum();
        assert!(
            (overlap.abs() - 1.0).abs() < 1e-6,
            "mode {k}: overlap {overlap}"
        );
    }
}

#[test]
fn cantilevered_prism_matches_a_dense_eigen_solve() {
    assert_matches_dense(true, 12);
}

#[test]
fn free_prism_matches_a_dense_eigen_solve_after_its_six_rigid_modes() {
    assert_matches_dense(false, 14);
}

/// Asking for every mode spans the whole space: the effective mass fractions of each
/// direction then sum to 1 (the modes are an M-orthonormal basis), a free body's rigid modes
/// carry all of it, and its elastic modes none.
#[test]
fn all_modes_of_a_free_prism_carry_all_the_mass_and_rigid_ones_are_below_one_hertz() {
    let (state, models) = prism(0.3, 0.08, 0.11, [3, 1, 1], false);
    let all = lanczos(&state, &models, 3 * state.len());
    let (rigid, elastic): (Vec<_>, Vec<_>) = all.modes.iter().partition(|m| m.rigid);
    assert_eq!(rigid.len(), 6);
    assert!(rigid.iter().all(|m| m.frequency_hz < 1.0));
    assert!(elastic.iter().all(|m| m.frequency_hz > 1000.0));
    for d in 0..6 {
        let total: f64 = all.modes.iter().map(|m| m.participation[d]).sum();
        let in_rigid: f64 = rigid.iter().map(|m| m.participation[d]).sum();
        assert!((total - 1.0).abs() < 1e-9, "direction {d}: {total}");
        assert!((in_rigid - 1.0).abs() < 1e-9, "direction {d}: {in_rigid}");
    }
}

/// Lowest z-bending and y-bending frequencies (Hz) of a 1 × 0.06 × 0.05 m prism of `n` × n/10
/// × n/10 cells.
fn bending(n: usize, clamped: bool) -> (f64, f64) {
    let (state, models) = prism(1.0, 0.06, 0.05, [n, n / 10, n / 10], clamped);
    let modes = lanczos(&state, &models, if clamped { 2 } else { 8 });
    let elastic: Vec<_> = modes.modes.iter().filter(|m| !m.rigid).collect();
    let lateral = |m: &qdem_core::modal::lanczos::Mode, axis: usize| -> f64 {
        m.shape.iter().map(|u| u[axis] * u[axis]).sum()
    };
    // The lower mode bends in z (h < b): its z motion dominates (the Kuhn split, the same in
    // every cell, is not symmetric about the planes y = b/2 and z = h/2 and couples the two
    // bending planes slightly).
    assert!(lateral(elastic[0], 2) > 3.0 * lateral(elastic[0], 1));
    assert!(lateral(elastic[1], 1) > 3.0 * lateral(elastic[1], 2));
    (elastic[0].frequency_hz, elastic[1].frequency_hz)
}

/// Euler–Bernoulli: f = (βL)² / (2π L²) √(EI / ρA), I = b h³/12 for bending across h.
fn euler_bernoulli(beta_l: f64, depth: f64) -> f64 {
    beta_l * beta_l / (2.0 * PI) * (E * depth * depth / (12.0 * RHO)).sqrt()
}

/// Linear tetrahedra lock in bending, so the coarse meshes are far (60%) above beam theory;
/// what must hold is convergence to it. On three meshes halving h, the differences must
/// shrink by more than 2 (order above 1), and beam theory must lie within the finest mesh's
/// error estimate: |f_h − f_beam| ≤ |f_h − f_∞|, f_∞ the Aitken extrapolation of the three.
/// Timoshenko's shear and rotary inertia corrections at L/h = 20 lower the frequencies by
/// about (βr)²(1 + E/κG)/2: 0.1% (clamped) and 0.9% (free-free), well inside that estimate, so
/// the same assertion holds for both beam theories; the test checks both values.
fn assert_converges_to_beam_theory(clamped: bool, beta_l: f64) {
    let fs: Vec<(f64, f64)> = [20, 40, 80].iter().map(|&n| bending(n, clamped)).collect();
    for (plane, depth) in [(0usize, 0.05), (1, 0.06)] {
        let f: Vec<f64> = fs
            .iter()
            .map(|p| if plane == 0 { p.0 } else { p.1 })
            .collect();
        let (d1, d2) = (f[0] - f[1], f[1] - f[2]);
        assert!(
            d1 > 0.0 && d2 > 0.0 && d1 / d2 > 2.0,
            "plane {plane}: {f:?}"
        );
        let limit = f[2] - d2 * d2 / (d1 - d2);
        let eb = euler_bernoulli(beta_l, depth);
        let radius = depth / 12f64.sqrt();
        let shear = E / (5.0 / 6.0 * E / (2.0 * (1.0 + NU)));
        let timoshenko = eb * (1.0 - 0.5 * (beta_l * radius).powi(2) * (1.0 + shear));
        for beam in [eb, timoshenko] {
            assert!(
                (f[2] - beam).abs() <= (f[2] - limit).abs(),
                "plane {plane}: meshes {f:?}, extrapolated {limit}, beam {beam}"
            );
        }
    }
}

#[test]
fn cantilevered_prism_converges_to_beam_theory() {
    assert_converges_to_beam_theory(true, 1.875_104);
}

#[test]
fn free_prism_converges_to_beam_theory() {
    assert_converges_to_beam_theory(false, 4.730_041);
}

#[test]
fn bad_input_is_refused_with_a_typed_error() {
    let (state, models) = prism(0.3, 0.08, 0.11, [3, 1, 1], true);
    let dofs = lanczos(&state, &models, 1).dofs;
    assert!(matches!(
        natural_modes(&state, &models, dofs + 1),
        Err(ModalError::TooManyModes { count, dofs: d }) if count == dofs + 1 && d == dofs
    ));
    assert!(matches!(
        natural_modes(&state, &models, 0),
        Err(ModalError::ZeroCount)
    ));
    let nothing: Vec<Box<dyn Model>> = vec![];
    assert!(matches!(
        natural_modes(&state, &nothing, 1),
        Err(ModalError::NothingDeformable)
    ));
}

/// One particle pinned: the body still rotates about it, three zero-frequency modes that
/// leave the pinned particle where it is (issue 43: no longer refused).
#[test]
fn a_pinned_body_rotates_about_its_pin_in_three_rigid_modes() {
    let (mut state, models) = prism(0.3, 0.08, 0.11, [3, 1, 1], false);
    state.fixed[0] = Dofs::ALL;
    let modes = natural_modes(&state, &models, 4).unwrap();
    let rigid: Vec<_> = modes.modes.iter().filter(|m| m.rigid).collect();
    assert_eq!(rigid.len(), 3);
    for m in rigid {
        assert!(m.frequency_hz < 1e-3, "{} Hz", m.frequency_hz);
        assert_eq!(m.shape[0], Vec3::zeros());
    }
    assert!(!modes.modes[3].rigid && modes.modes[3].frequency_hz > 1.0);
}
