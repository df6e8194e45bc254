//! The contacts as linear springs about a state, for a modal analysis ([`qdem_core::lanczos`]):
//! the sleeper's modes on its settled bed, paper 000 §4.2.
//!
//! A touching contact with unit normal n (from the first sphere towards the second, or from
//! the wall to the sphere) and the law's normal and tangential stiffness kn, kt at its overlap
//! (constant for the linear law, Hertz–Mindlin's √δ-dependent pair for the other) is the
//! spring k = kn n nᵀ + kt (I − n nᵀ) between the two spheres' carriers: the tangent
//! K = −∂f/∂x adds k to both diagonal blocks and −k to the two off-diagonal ones (a wall
//! contact only to its sphere's). The contacts are taken as sticking (a sliding contact would
//! give no tangential stiffness) and their damping is left out, as the modes are undamped.

use qdem_core::{Mat3, Tangent, Vec3};

/// The spring of a contact with unit normal `normal` and stiffnesses `kn`, `kt`.
pub(crate) fn spring(normal: &Vec3, kn: f64, kt: f64) -> Mat3 {
    let nn = normal * normal.transpose();
    nn * kn + (Mat3::identity() - nn) * kt
}

/// Adds the spring `k` between particles `a` and `b` (to the ground, a wall, when `b` is
/// `None`) to `tangent`.
pub(crate) fn add_spring(tangent: &mut Tangent, a: usize, b: Option<usize>, k: &Mat3) {
    tangent.add_stiffness(a, a, k);
    if let Some(b) = b {
        tangent.add_stiffness(b, b, k);
        tangent.add_stiffness(a, b, &-k);
        tangent.add_stiffness(b, a, &-k);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_spring_is_stiff_along_its_normal_and_shears_across_it() {
        let n = Vec3::new(0.6, 0.0, 0.8);
        let k = spring(&n, 10.0, 4.0);
        assert!((k * n - 10.0 * n).norm() < 1e-12);
        let t = Vec3::new(-0.8, 0.0, 0.6);
        assert!((k * t - 4.0 * t).norm() < 1e-12);
        assert!((k - k.transpose()).norm() < 1e-15);
    }
}
