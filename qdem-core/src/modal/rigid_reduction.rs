//! Rigid bodies in a modal analysis ([`crate::modal::lanczos`]): each body's members and its rotation
//! expressed through the body's six degrees of freedom, the translation of its centre and the
//! rotation about its principal axes (the 6 DOFs of paper 000 §4.2's sleeper when it is taken
//! rigid).
//!
//! - A member at arm r = x_m − x_c from its body's centre moves as u_m = u_c + θ × r =
//!   u_c − [r]× θ, θ the body's small rotation in world axes. The models' tangents attach to
//!   members, and a contact on a sphere that turns also to θ itself, at the body's rotation
//!   node ([`State::body_rotation_node`]), through the arm from the sphere's centre to the
//!   contact point.
//! - The analysis takes as the body's rotational DOFs ψ the rotations about its principal axes,
//!   scaled: θ = R D ψ with R the principal frame, D = diag(√(Ī / I_k)) and Ī the mean of the
//!   principal moments I_k. Then the rotational kinetic energy ½ θ̇ᵀ J θ̇ = ½ Ī |ψ̇|², so the
//!   rotation node carries one mass Ī in its three directions like a particle, and M stays
//!   diagonal, as the lumped-mass layout of the solvers needs.
//! - With u = T q (q: the particles' free DOFs, the centres' translations and the ψ), the
//!   reduced stiffness is Tᵀ K T: each member entry spreads over its centre and its rotation
//!   node. The members leave the system (their DOFs are fixed in it), the centre keeps its
//!   fixity and ψ is fixed where the body's rotation is held.
//! - A mode's shape is mapped back to the members by the same T; its kinetic energy in the
//!   world direction d is m u_{c,d}² + (θ × e_d)ᵀ S (θ × e_d), with S = R diag(s) Rᵀ the body's
//!   second moment of mass about its centre, s_k = ½ ΣI − I_k, so that the three shares sum to
//!   m |u_c|² + θᵀ J θ.

use crate::step::state::{Dofs, State};
use crate::step::tangent::{Entry, Tangent};
use crate::{Mat3, Vec3};
use faer::sparse::Triplet;

/// The map from the state's generalised nodes to the rigid bodies' six DOFs.
pub(crate) struct RigidReduction {
    /// The first rotation node ([`State::body_rotation_node`] of body 0).
    base: usize,
    /// R D of each body: its world rotation θ from its scaled principal rotations ψ.
    frame: Vec<Mat3>,
    /// (R D)⁻¹ = D⁻¹ Rᵀ of each body: ψ from θ.
    inverse: Vec<Mat3>,
    /// Ī of each body, the mass of its rotation node (kg m²).
    mean: Vec<f64>,
    /// The second moment of mass S of each body about its centre, world axes (kg m²).
    second: Vec<Mat3>,
}

/// A global DOF as a combination of at most four reduced ones.
type Spread = ([(usize, f64); 4], usize);

impl RigidReduction {
    /// The reduction of `state`'s rigid bodies at their current poses.
    pub(crate) fn new(state: &State) -> RigidReduction {
        let rigid = &state.rigid;
        let mut reduction = RigidReduction {
            base: state.body_rotation_node(0),
            frame: Vec::with_capacity(rigid.len()),
            inverse: Vec::with_capacity(rigid.len()),
            mean: Vec::with_capacity(rigid.len()),
            second: Vec::with_capacity(rigid.len()),
        };
        for b in 0..rigid.len() {
            let r = *rigid.orientation[b].to_rotation_matrix().matrix();
            let moments = rigid.inertia[b];
            let mean = moments.sum() / 3.0;
            let d = Mat3::from_diagonal(&moments.map(|i| (mean / i).sqrt()));
            let d_inv = Mat3::from_diagonal(&moments.map(|i| (i / mean).sqrt()));
            let s = moments.map(|i| 0.5 * moments.sum() - i);
            reduction.frame.push(r * d);
            reduction.inverse.push(d_inv * r.transpose());
            reduction.mean.push(mean);
            reduction
                .second
                .push(r * Mat3::from_diagonal(&s) * r.transpose());
        }
        reduction
    }

    /// Number of rigid bodies.
    fn bodies(&self) -> usize {
        self.frame.len()
    }

    /// The rigid body whose rotation node is `node`, if it is one.
    pub(crate) fn body_of_node(&self, node: usize) -> Option<usize> {
        node.checked_sub(self.base).filter(|&b| b < self.bodies())
    }

    /// The fixity of every generalised node of the reduced system: `nodes` (the state's
    /// [`State::node_fixity`]) with the members fixed, then a rotation node per body, fixed
    /// where the body's rotation is held.
    pub(crate) fn fixity(&self, state: &State, mut nodes: Vec<Dofs>) -> Vec<Dofs> {
        for b in 0..self.bodies() {
            for &m in state.rigid.members(b) {
                nodes[m] = Dofs::ALL;
            }
        }
        nodes.extend(state.rigid.spin_fixed.iter().map(|&held| match held {
            true => Dofs::ALL,
            false => Dofs::NONE,
        }));
        nodes
    }

    /// The mass of every generalised node: `nodes` (the state's [`State::node_mass`]), then
    /// Ī per body.
    pub(crate) fn node_mass(&self, mut nodes: Vec<f64>) -> Vec<f64> {
        nodes.extend(&self.mean);
        nodes
    }

    /// Tᵀ K T: `tangent`'s stiffness over the reduced DOFs (lower triangle, global numbering);
    /// its damping is dropped (the modes are undamped).
    pub(crate) fn reduce(&self, state: &State, tangent: Tangent) -> Tangent {
        if self.bodies() == 0 {
            return tangent;
        }
        let mut reduced = Tangent::new();
        for e in tangent.stiffness_entries() {
            let (rows, cols) = (self.spread(state, e.row), self.spread(state, e.col));
            for &(p, a) in &rows.0[..rows.1] {
                for &(q, b) in &cols.0[..cols.1] {
                    push(&mut reduced.stiffness, e.row == e.col, p, q, a * b * e.val);
                }
            }
        }
        reduced
    }

    /// Global DOF `dof` as a combination of reduced DOFs.
    fn spread(&self, state: &State, dof: usize) -> Spread {
        let (node, axis) = (dof / 3, dof % 3);
        let mut out = ([(0, 0.0); 4], 0);
        if let Some(b) = self.body_of_node(node) {
            // θ_axis = Σ_k (R D)[axis, k] ψ_k.
            for k in 0..3 {
                out.0[k] = (3 * (self.base + b) + k, self.frame[b][(axis, k)]);
            }
            out.1 = 3;
            return out;
        }
        let body = (node < state.len())
            .then(|| state.rigid.body_of_member(node))
            .flatten();
        let Some(b) = body else {
            out.0[0] = (dof, 1.0);
            out.1 = 1;
            return out;
        };
        // u_m = u_c − [r]× R D ψ.
        let c = state.rigid.center[b];
        let arm = state.position[node] - state.position[c];
        let lever = -arm.cross_matrix() * self.frame[b];
        out.0[0] = (3 * c + axis, 1.0);
        for k in 0..3 {
            out.0[k + 1] = (3 * (self.base + b) + k, lever[(axis, k)]);
        }
        out.1 = 4;
        out
    }

    /// The world rotation θ of body `b` from its reduced rotation DOFs ψ.
    pub(crate) fn rotation(&self, b: usize, psi: &Vec3) -> Vec3 {
        self.frame[b] * psi
    }

    /// The reduced rotation DOFs ψ of body `b` for a world rotation θ.
    pub(crate) fn psi(&self, b: usize, theta: &Vec3) -> Vec3 {
        self.inverse[b] * theta
    }

    /// Puts every member's motion u_c + θ × r into `shape` (one vector per particle), θ of body
    /// b being `theta[b]`.
    pub(crate) fn place_members(&self, state: &State, theta: &[Vec3], shape: &mut [Vec3]) {
        for (b, t) in theta.iter().enumerate() {
            let c = state.rigid.center[b];
            for &m in state.rigid.members(b) {
                shape[m] = shape[c] + t.cross(&(state.position[m] - state.position[c]));
            }
        }
    }

    /// The rotational kinetic energy of body `b` turning at θ, twice, split by world direction:
    /// (θ × e_d)ᵀ S (θ × e_d) for d = x, y, z.
    pub(crate) fn rotation_energy(&self, b: usize, theta: &Vec3) -> [f64; 3] {
        std::array::from_fn(|d| {
            let t = theta.cross(&Vec3::ith(d, 1.0));
            t.dot(&(self.second[b] * t))
        })
    }
}

/// Pushes the contribution `value` of a stored entry at reduced (p, q) into the lower
/// triangle. A diagonal entry K_rr stands for itself: its (p, q) above the diagonal are the
/// mirrors of its (q, p) and are dropped. An off-diagonal entry K_rc stands also for K_cr,
/// whose contribution lands at (q, p): one of the two is on or below the diagonal, or both
/// on it.
fn push(list: &mut Vec<Entry>, diagonal: bool, p: usize, q: usize, value: f64) {
    match (diagonal, p.cmp(&q)) {
        (_, std::cmp::Ordering::Greater) => list.push(Triplet::new(p, q, value)),
        (true, std::cmp::Ordering::Less) => {}
        (false, std::cmp::Ordering::Less) => list.push(Triplet::new(q, p, value)),
        (true, std::cmp::Ordering::Equal) => list.push(Triplet::new(p, p, value)),
        (false, std::cmp::Ordering::Equal) => list.push(Triplet::new(p, p, 2.0 * value)),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::DMatrix;

    /// A rigid body of four members about a centre, turned off its principal axes.
    fn body() -> State {
        let points = vec![
            Vec3::new(0.1, 0.2, -0.1),
            Vec3::new(1.3, 0.0, 0.2),
            Vec3::new(-0.2, 0.9, 0.1),
            Vec3::new(0.3, -0.1, 1.1),
            Vec3::new(0.35, 0.25, 0.3),
        ];
        let mut state = State::at_rest(points);
        state.mass = vec![1.0; 5];
        let inertia = Mat3::new(2.0, 0.3, -0.1, 0.3, 1.5, 0.2, -0.1, 0.2, 1.1);
        state
            .add_rigid_body("stone", 4, &[0, 1, 2, 3], inertia)
            .unwrap();
        state
    }

    /// The dense symmetric matrix of a lower-triangle tangent over `n` DOFs.
    fn dense(tangent: &Tangent, n: usize) -> DMatrix<f64> {
        let mut k = DMatrix::zeros(n, n);
        for e in tangent.stiffness_entries() {
            k[(e.row, e.col)] += e.val;
            if e.row != e.col {
                k[(e.col, e.row)] += e.val;
            }
        }
        k
    }

    /// Tᵀ K T from the stored entries equals the dense product with the T of the module docs,
    /// for springs between members, a member and the rotation node, and the ground.
    #[test]
    fn the_reduced_stiffness_is_the_dense_t_transpose_k_t() {
        let state = body();
        let reduction = RigidReduction::new(&state);
        let n = 3 * (state.len() + 1);
        let mut tangent = Tangent::new();
        let k = Mat3::new(3.0, 0.5, 0.1, 0.5, 2.0, -0.4, 0.1, -0.4, 1.0);
        tangent.add_stiffness(0, 0, &k);
        tangent.add_stiffness(1, 1, &(2.0 * k));
        tangent.add_stiffness(1, 2, &-k);
        tangent.add_stiffness(2, 1, &-k.transpose());
        tangent.add_stiffness(3, 5, &(0.5 * k));
        tangent.add_stiffness(5, 3, &(0.5 * k.transpose()));
        tangent.add_stiffness(5, 5, &k);
        let full = dense(&tangent, n);
        let mut t = DMatrix::<f64>::zeros(n, n);
        for dof in 0..n {
            let (s, len) = reduction.spread(&state, dof);
            for &(q, v) in &s[..len] {
                t[(dof, q)] += v;
            }
        }
        let expected: DMatrix<f64> = t.transpose() * full * &t;
        let reduced: DMatrix<f64> = dense(&reduction.reduce(&state, tangent), n);
        let error = (&reduced - &expected).abs().max();
        assert!(error < 1e-13 * expected.abs().max(), "error {error:e}");
    }

    /// ψ carries one mass Ī: the rotational energy θᵀ J θ of θ = R D ψ is Ī |ψ|², and the three
    /// directional shares sum to it.
    #[test]
    fn the_scaled_principal_rotations_share_one_mass() {
        let state = body();
        let reduction = RigidReduction::new(&state);
        let rigid = &state.rigid;
        let r = *rigid.orientation[0].to_rotation_matrix().matrix();
        let j = r * Mat3::from_diagonal(&rigid.inertia[0]) * r.transpose();
        let psi = Vec3::new(0.3, -1.2, 0.7);
        let theta = reduction.rotation(0, &psi);
        let energy = theta.dot(&(j * theta));
        let expected = reduction.mean[0] * psi.norm_squared();
        assert!((energy / expected - 1.0).abs() < 1e-14);
        let shares: f64 = reduction.rotation_energy(0, &theta).iter().sum();
        assert!((shares / energy - 1.0).abs() < 1e-14);
        assert!((reduction.psi(0, &theta) - psi).norm() < 1e-14);
    }
}
