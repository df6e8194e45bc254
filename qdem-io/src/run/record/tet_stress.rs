//! The stress fields of the tetrahedra in `vtu/state_NNNNN.vtu`: from each tetrahedron's
//! stress tensor σ (the Cauchy stress of the QDEM kernel, paper 000 Eq. 2,
//! [`qdem_core::continuum::TetBody::tet_fields`]) its six components in ParaView's symmetric-tensor
//! order (xx, yy, zz, xy, yz, xz), its three principal stresses σ₁ ≥ σ₂ ≥ σ₃ (the eigenvalues
//! of σ, tension positive) and its von Mises stress √(3/2 s:s).

use qdem_core::continuum::tet_kernel::von_mises;
use qdem_core::Mat3;

/// The cell fields of the tetrahedra, one entry per tetrahedron in each.
#[derive(Debug, Default)]
pub(crate) struct StressFields {
    /// σ as (xx, yy, zz, xy, yz, xz), Pa.
    pub(crate) stress: Vec<[f64; 6]>,
    /// σ₁, σ₂, σ₃ (largest first), Pa.
    pub(crate) principal: [Vec<f64>; 3],
    /// Von Mises stress, Pa.
    pub(crate) von_mises: Vec<f64>,
}

impl StressFields {
    /// Appends the fields of one tetrahedron of stress `t`.
    pub(crate) fn push(&mut self, t: &Mat3) {
        self.stress.push(components(t));
        for (list, value) in self.principal.iter_mut().zip(principal_stresses(t)) {
            list.push(value);
        }
        self.von_mises.push(von_mises(t));
    }

    /// Appends `count` stress-free tetrahedra (a rigid body's).
    pub(crate) fn push_zeros(&mut self, count: usize) {
        for _ in 0..count {
            self.push(&Mat3::zeros());
        }
    }
}

/// The six components of the symmetric part of `t` in ParaView's order xx, yy, zz, xy, yz,
/// xz.
pub(crate) fn components(t: &Mat3) -> [f64; 6] {
    let s = |i: usize, j: usize| 0.5 * (t[(i, j)] + t[(j, i)]);
    [s(0, 0), s(1, 1), s(2, 2), s(0, 1), s(1, 2), s(0, 2)]
}

/// The principal stresses of (the symmetric part of) `t`, largest first.
pub(crate) fn principal_stresses(t: &Mat3) -> [f64; 3] {
    let sym = (t + t.transpose()) * 0.5;
    let mut values: [f64; 3] = sym.symmetric_eigenvalues().into();
    values.sort_by(|a, b| b.total_cmp(a));
    values
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A stress with known eigenvalues (a diagonal one turned by a rotation) gives them back.
    #[test]
    fn principal_stresses_of_a_turned_tensor() {
        let r = nalgebra::Rotation3::from_euler_angles(0.3, -0.7, 1.1);
        let d = Mat3::from_diagonal(&qdem_core::Vec3::new(-2.0e6, 5.0e6, 1.0e6));
        let t = r.matrix() * d * r.matrix().transpose();
        let p = principal_stresses(&t);
        for (got, want) in p.iter().zip([5.0e6, 1.0e6, -2.0e6]) {
            assert!((got - want).abs() < 1e-8 * 5.0e6, "{p:?}");
        }
        let c = components(&t);
        assert_eq!(c[3], 0.5 * (t[(0, 1)] + t[(1, 0)]));
        assert!((c[0] + c[1] + c[2] - 4.0e6).abs() < 1e-8 * 5.0e6);
    }
}
