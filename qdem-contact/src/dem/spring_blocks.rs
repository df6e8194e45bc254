//! One contact as a linear spring about a state and its blocks in the stiffness matrix (the
//! facet that assembles every touching contact is `dem_contacts/linearized.rs`), for a modal
//! analysis ([`qdem_core::modal::lanczos`]):
//! the sleeper's modes on its settled bed, paper 000 §4.2.
//!
//! A touching contact with unit normal n (from the first sphere towards the second, or from
//! the wall to the sphere) and the law's normal and tangential stiffness kn, kt at its overlap
//! (constant for the linear law, Hertz–Mindlin's √δ-dependent pair for the other) is the
//! spring k = kn n nᵀ + kt (I − n nᵀ) between the two spheres' carriers: the tangent
//! K = −∂f/∂x adds k to both diagonal blocks and −k to the two off-diagonal ones (a wall
//! contact only to its sphere's). A sphere that turns (a rigid body's, a rotating particle's)
//! moves its contact point also by its rotation θ: u = u_p + θ × a = u_p − [a]× θ with a the arm
//! from the sphere's centre to the contact point, so its side of the spring is J = [I, −[a]×]
//! over its carrier and its rotation node, and K gains the blocks ± Jᵢᵀ k Jⱼ. The contacts are
//! taken as sticking (a sliding contact would give no tangential stiffness) and their damping
//! is left out, as the modes are undamped.

use qdem_core::{step::Tangent, Mat3, Vec3};

/// The spring of a contact with unit normal `normal` and stiffnesses `kn`, `kt`.
pub(crate) fn spring(normal: &Vec3, kn: f64, kt: f64) -> Mat3 {
    let nn = normal * normal.transpose();
    nn * kn + (Mat3::identity() - nn) * kt
}

/// Where one side of a contact's spring attaches.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Attachment {
    /// The sphere's carrier particle.
    pub(crate) particle: usize,
    /// For a sphere that turns: the generalised node of its rotation and the arm from the
    /// sphere's centre to the contact point.
    pub(crate) turn: Option<(usize, Vec3)>,
}

impl Attachment {
    /// The nodes that move the contact point, with their maps J (u = Σ J u_node).
    fn terms(&self) -> Vec<(usize, Mat3)> {
        let mut terms = vec![(self.particle, Mat3::identity())];
        if let Some((node, arm)) = self.turn {
            terms.push((node, -arm.cross_matrix()));
        }
        terms
    }
}

/// Adds the spring `k` between the contact points of `a` and `b` (to the ground, a wall,
/// when `b` is `None`) to `tangent`: the blocks a–a, b–b, a–b and b–a, in that order.
pub(crate) fn add_spring(tangent: &mut Tangent, a: Attachment, b: Option<Attachment>, k: &Mat3) {
    let mut sides = vec![(a.terms(), 1.0)];
    sides.extend(b.map(|b| (b.terms(), -1.0)));
    let pairs: &[(usize, usize)] = match sides.len() {
        1 => &[(0, 0)],
        _ => &[(0, 0), (1, 1), (0, 1), (1, 0)],
    };
    for &(i, j) in pairs {
        let ((rows, si), (cols, sj)) = (&sides[i], &sides[j]);
        for (row, ji) in rows {
            for (col, jj) in cols {
                tangent.add_stiffness(*row, *col, &((si * sj) * (ji.transpose() * k * jj)));
            }
        }
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
