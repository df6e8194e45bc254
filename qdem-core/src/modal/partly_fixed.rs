//! The rigid-body motions that a body's fixes leave free, for a modal analysis
//! ([`crate::modal::lanczos`]): a plate simply supported on its bottom edges (u_z = 0 there,
//! the classic free-vibration benchmark of solids) keeps its two in-plane translations and its
//! rotation about z. These are zero-frequency modes like a free body's six, formed directly and
//! deflated from the Lanczos iteration (which would find one vector only of a repeated zero).
//!
//! A rigid motion u(x) = t + θ × (x − c) = R(x − c) v, v = (t, θ), is left free by the fixes
//! when it vanishes in every fixed direction: v is in the null space of the 6 × 6 Gram matrix
//! Σ r_d r_dᵀ over the fixed DOFs d, r_d the row of R for that DOF (the test the static solve
//! makes in `unconstrained_bodies`, which also checks that no stiffness resists them).

use crate::solvers::sparse::rigid_motion;
use crate::{Mat3, Vec3};
use nalgebra::{Matrix6, SymmetricEigen};

/// Eigenvalue of the Gram matrix, per fixed DOF, below which a rigid motion counts as free
/// (the arms are scaled to at most 1, so the matrix's entries are of order one per DOF).
const FREE: f64 = 1e-10;

/// The rigid motions of `particles` that vanish in their fixed directions, each over the
/// system DOFs (`index`: the system DOF of a global one, `None` where fixed; `global`: the
/// global DOF of each system DOF; `frame`: a particle's local basis where its DOFs are
/// numbered in one, whose rows R then gives as Rᵀ R), not normalised.
pub(crate) fn free_rigid_motions(
    position: &[Vec3],
    particles: &[usize],
    index: &dyn Fn(usize) -> Option<usize>,
    frame: &dyn Fn(usize) -> Option<Mat3>,
    global: &[usize],
) -> Vec<Vec<f64>> {
    if particles.is_empty() {
        return Vec::new();
    }
    let centre = particles.iter().map(|&p| position[p]).sum::<Vec3>() / particles.len() as f64;
    let size = particles
        .iter()
        .map(|&p| (position[p] - centre).norm())
        .fold(f64::MIN_POSITIVE, f64::max);
    let motion = |p: usize| {
        let rows = rigid_motion((position[p] - centre) / size);
        match frame(p) {
            Some(r) => r.transpose() * rows,
            None => rows,
        }
    };
    let mut gram = Matrix6::zeros();
    let mut rows = 0usize;
    for &p in particles {
        for axis in (0..3).filter(|&a| index(3 * p + a).is_none()) {
            let row = motion(p).row(axis).transpose();
            gram += row * row.transpose();
            rows += 1;
        }
    }
    let mut in_body = vec![false; position.len()];
    for &p in particles {
        in_body[p] = true;
    }
    let eigen = SymmetricEigen::new(gram);
    (0..6)
        .filter(|&k| eigen.eigenvalues[k] <= FREE * rows.max(1) as f64)
        .map(|k| {
            let v = eigen.eigenvectors.column(k).into_owned();
            global
                .iter()
                .map(|&d| {
                    let p = d / 3;
                    match p < position.len() && in_body[p] {
                        true => (motion(p) * v)[d % 3],
                        false => 0.0,
                    }
                })
                .collect()
        })
        .collect()
}
