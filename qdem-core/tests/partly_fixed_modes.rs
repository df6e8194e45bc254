//! Modes of a body fixed in some directions that keeps rigid-body motions (issue 43): a
//! 10 × 10 × 1 m plate simply supported on its bottom edges (u_z = 0 there, free in its
//! plane) has its two in-plane translations and its rotation about z as zero-frequency modes,
//! and its elastic modes, against a dense solve of the same K and M.

use nalgebra::{DMatrix, SymmetricEigen};
use qdem_core::modal::lanczos::natural_modes;
use qdem_core::{
    continuum::Material, continuum::TetBody, step::Dofs, step::Linearized, step::Model,
    step::State, step::Tangent, Vec3,
};
use qdem_mesh::structured_box;
use std::f64::consts::PI;

/// The plate of `cells` in steel, its bottom edges held in z.
fn plate(cells: [usize; 3]) -> (State, TetBody) {
    let mesh = structured_box([0.0; 3], [10.0, 10.0, 1.0], cells).unwrap();
    let reference: Vec<Vec3> = mesh.nodes.iter().map(|p| Vec3::from(*p)).collect();
    let body = TetBody::new(
        "plate",
        &reference,
        mesh.tets.clone(),
        Material::elastic(8000.0, 200e9, 0.3),
    )
    .unwrap();
    let mut state = State::at_rest(reference);
    body.lump_mass(&mut state.mass);
    for i in 0..state.len() {
        let x = state.reference[i];
        let edge = x.x == 0.0 || x.x == 10.0 || x.y == 0.0 || x.y == 10.0;
        if x.z == 0.0 && edge {
            state.fix(i, Dofs::parse("z").unwrap());
        }
    }
    (state, body)
}

/// The frequencies (Hz) of K φ = ω² M φ over the free DOFs, by a dense symmetric solve of
/// M^-½ K M^-½.
fn dense_frequencies(state: &State, body: &TetBody) -> Vec<f64> {
    let mut tangent = Tangent::new();
    body.add_tangent(state, &mut tangent);
    let free: Vec<usize> = (0..3 * state.len())
        .filter(|d| !state.fixed[d / 3].contains(d % 3))
        .collect();
    let mut slot = vec![usize::MAX; 3 * state.len()];
    for (i, &d) in free.iter().enumerate() {
        slot[d] = i;
    }
    let n = free.len();
    let mut k = DMatrix::<f64>::zeros(n, n);
    for e in tangent.stiffness_entries() {
        let (r, c) = (slot[e.row], slot[e.col]);
        if r == usize::MAX || c == usize::MAX {
            continue;
        }
        k[(r, c)] += e.val;
        if r != c {
            k[(c, r)] += e.val;
        }
    }
    let scale: Vec<f64> = free
        .iter()
        .map(|d| 1.0 / state.mass[d / 3].sqrt())
        .collect();
    let a = DMatrix::from_fn(n, n, |r, c| k[(r, c)] * scale[r] * scale[c]);
    let mut omega2: Vec<f64> = SymmetricEigen::new(a).eigenvalues.iter().copied().collect();
    omega2.sort_by(f64::total_cmp);
    omega2
        .iter()
        .map(|w| w.max(0.0).sqrt() / (2.0 * PI))
        .collect()
}

#[test]
fn a_simply_supported_plate_has_three_in_plane_rigid_modes_and_the_dense_elastic_ones() {
    let (state, body) = plate([6, 6, 2]);
    let dense = dense_frequencies(&state, &body);
    let models: Vec<Box<dyn Model>> = vec![Box::new(body)];
    let modes = natural_modes(&state, &models, 9).unwrap();
    let rigid: Vec<_> = modes.modes.iter().filter(|m| m.rigid).collect();
    assert_eq!(
        rigid.len(),
        3,
        "two in-plane translations and the rotation about z"
    );
    for m in &rigid {
        assert!(
            m.frequency_hz < 1.0,
            "a rigid mode at {} Hz",
            m.frequency_hz
        );
        // In-plane: no z motion.
        assert!(m.motion[2] < 1e-12, "{:?}", m.motion);
    }
    // The dense solve has the same three zeros (to rounding) below 1 Hz, then the elastic
    // spectrum that Lanczos must reproduce.
    assert!(dense[..3].iter().all(|&f| f < 1.0), "{:?}", &dense[..4]);
    assert!(dense[3] > 10.0, "{:?}", &dense[..4]);
    for (m, d) in modes.modes[3..].iter().zip(&dense[3..]) {
        assert!(!m.rigid);
        assert!(
            (m.frequency_hz / d - 1.0).abs() < 1e-8,
            "{} vs {d} Hz",
            m.frequency_hz
        );
    }
}
