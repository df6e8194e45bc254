//! Fixes in a local frame: particles whose held directions are not x, y, z (a roller on a
//! skewed face, the symmetry planes of a cylinder held in its cylindrical frame, CalculiX's
//! `*TRANSFORM`).
//!
//! A framed particle i has an orthonormal basis R_i = [e₁ e₂ e₃] (columns in world axes) and
//! a set of held local directions; its local coordinates are u′ = R_iᵀ u. The constraint is
//! e_k · u = 0 for every held k (paper 001 Eq. 23 with B's rows e_kᵀ instead of unit rows):
//!
//! - explicit steps project the acceleration and the velocity onto the free subspace,
//!   a ← a − Σ_held (e_k·a) e_k ([`ParticleFrames::hold`]);
//! - implicit, static and modal solves number the particle's DOFs in its local frame, so a
//!   held direction is eliminated as a fixed axis is: the tangent is transformed as
//!   K′ = Tᵀ K T with T block-diagonal (R_i on framed particles, I elsewhere;
//!   [`ParticleFrames::tangent_in_frames`]), loads enter as R_iᵀ f and the solution leaves as
//!   R_i u′. The lumped mass is isotropic, so M′ = M.
//!
//! The set is sparse (only framed particles are stored), so a scene without one takes the
//! same path, bit for bit, as before frames existed.

use crate::step::state::Dofs;
use crate::step::tangent::{Entry, Tangent};
use crate::{Mat3, Vec3};
use faer::sparse::Triplet;
use nalgebra::SymmetricEigen;

/// The particles held in a local frame: each its basis and its held local directions, in
/// ascending particle order.
///
/// ```
/// use qdem_core::{step::Dofs, step::State, Mat3, Vec3};
///
/// // A roller on the plane x = y: the normal (1, 1, 0)/√2 is held.
/// let mut state = State::at_rest(vec![Vec3::zeros()]);
/// let n = Vec3::new(1.0, 1.0, 0.0).normalize();
/// let frame = Mat3::from_columns(&[n, Vec3::new(-n.y, n.x, 0.0), Vec3::z()]);
/// state.fix_in_frame(0, frame, Dofs::parse("x").unwrap()).unwrap();
/// state.velocity[0] = Vec3::new(1.0, 0.0, 2.0);
/// state.hold_fixed();
/// assert!(state.velocity[0].dot(&n).abs() < 1e-15);
/// assert_eq!(state.velocity[0].z, 2.0);
/// ```
#[derive(Clone, Debug, Default, PartialEq)]
pub struct ParticleFrames {
    particles: Vec<usize>,
    frame: Vec<Mat3>,
    held: Vec<Dofs>,
}

/// Tolerance of an orthonormal basis: |RᵀR − I| entries.
const ORTHONORMAL: f64 = 1e-9;

/// Why a frame cannot hold a particle.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum FrameError {
    /// The basis given is not orthonormal.
    #[error("the frame's basis is not orthonormal (|RᵀR − I| = {deviation:.2e} > 1e-9): give three unit vectors at right angles")]
    NotOrthonormal {
        /// The largest entry of RᵀR − I.
        deviation: f64,
    },
}

/// The largest entry of RᵀR − I.
fn deviation(frame: &Mat3) -> f64 {
    (frame.transpose() * frame - Mat3::identity()).amax()
}

/// Checks that `frame`'s columns are an orthonormal basis.
pub fn check_orthonormal(frame: &Mat3) -> Result<(), FrameError> {
    match deviation(frame) {
        d if d <= ORTHONORMAL => Ok(()),
        deviation => Err(FrameError::NotOrthonormal { deviation }),
    }
}

impl ParticleFrames {
    /// Whether no particle is framed.
    pub fn is_empty(&self) -> bool {
        self.particles.is_empty()
    }

    /// Number of framed particles.
    pub fn len(&self) -> usize {
        self.particles.len()
    }

    /// Particle `i`'s basis and held local directions, if it is framed.
    pub fn get(&self, i: usize) -> Option<(&Mat3, Dofs)> {
        let k = self.particles.binary_search(&i).ok()?;
        Some((&self.frame[k], self.held[k]))
    }

    /// The framed particles, each with its basis and held local directions, ascending.
    pub fn iter(&self) -> impl Iterator<Item = (usize, &Mat3, Dofs)> {
        self.particles
            .iter()
            .zip(&self.frame)
            .zip(&self.held)
            .map(|((&i, r), &h)| (i, r, h))
    }

    /// Sets particle `i`'s basis and held directions (replacing any before); `held` empty
    /// removes it.
    pub(crate) fn set(&mut self, i: usize, frame: Mat3, held: Dofs) {
        match (self.particles.binary_search(&i), held.is_empty()) {
            (Ok(k), false) => {
                self.frame[k] = frame;
                self.held[k] = held;
            }
            (Ok(k), true) => {
                self.particles.remove(k);
                self.frame.remove(k);
                self.held.remove(k);
            }
            (Err(k), false) => {
                self.particles.insert(k, i);
                self.frame.insert(k, frame);
                self.held.insert(k, held);
            }
            (Err(_), true) => {}
        }
    }

    /// Removes from `v` of every framed particle its components along the held directions.
    pub fn hold(&self, v: &mut [Vec3]) {
        for (i, frame, held) in self.iter() {
            v[i] = project_free(frame, held, v[i]);
        }
    }

    /// The tangent with the rows and columns of every framed particle in its local frame
    /// (K′ = Tᵀ K T, C′ likewise), lower-triangle entries as before; entries between unframed
    /// particles unchanged (a particle's rotation node, numbered after every particle, is
    /// never framed). A model's kept entries are not kept through it.
    pub fn tangent_in_frames(&self, tangent: &Tangent) -> Tangent {
        let frame_of = |dof: usize| self.get(dof / 3);
        let rotate = |list: &[Entry]| {
            let mut out = Vec::with_capacity(list.len());
            for e in list {
                rotate_entry(e, frame_of(e.row), frame_of(e.col), &mut out);
            }
            out
        };
        Tangent {
            stiffness: rotate(&tangent.stiffness),
            damping: rotate(&tangent.damping),
            kept: None,
        }
    }

    /// Merges particle `i`'s held subspaces: the global axes `fixed`, its present frame's
    /// held directions and the new `frame`'s `held` ones. Returns the basis and held set that
    /// span them all: `frame` itself when nothing else is held, else the eigenvectors of
    /// Σ e eᵀ over every held unit vector e (a positive eigenvalue held).
    pub(crate) fn merged(&self, i: usize, fixed: Dofs, frame: &Mat3, held: Dofs) -> (Mat3, Dofs) {
        let present = self.get(i);
        if fixed.is_empty() && present.is_none() {
            return (*frame, held);
        }
        let mut gram = Mat3::zeros();
        let mut add = |basis: &Mat3, dofs: Dofs| {
            for k in (0..3).filter(|&k| dofs.contains(k)) {
                let e = basis.column(k);
                gram += e * e.transpose();
            }
        };
        add(&Mat3::identity(), fixed);
        if let Some((r, h)) = present {
            add(r, h);
        }
        add(frame, held);
        let eigen = SymmetricEigen::new(gram);
        let held = Dofs::from_mask(std::array::from_fn(|k| eigen.eigenvalues[k] > 1e-9));
        (eigen.eigenvectors, held)
    }
}

/// `v` less its components along the `held` columns of `frame`.
#[inline]
pub(crate) fn project_free(frame: &Mat3, held: Dofs, v: Vec3) -> Vec3 {
    let mut out = v;
    for k in (0..3).filter(|&k| held.contains(k)) {
        let e = frame.column(k);
        out -= e.dot(&v) * e;
    }
    out
}

/// Appends the entries of `e` transformed to the frames of its row's and column's particles
/// (`None`: world axes): K′_{(i,a′)(j,b′)} = Σ R_i[a, a′] K_{(i,a)(j,b)} R_j[b, b′], the
/// diagonal block's off-diagonal entry standing for both (a, b) and (b, a).
fn rotate_entry(
    e: &Entry,
    row: Option<(&Mat3, Dofs)>,
    col: Option<(&Mat3, Dofs)>,
    out: &mut Vec<Entry>,
) {
    if row.is_none() && col.is_none() {
        out.push(*e);
        return;
    }
    let (i, a, j, b) = (e.row / 3, e.row % 3, e.col / 3, e.col % 3);
    // The weights of local axis a′ in global axis a: R[a, a′] (a unit row for world axes).
    let weights = |frame: Option<(&Mat3, Dofs)>, a: usize| -> [f64; 3] {
        match frame {
            Some((r, _)) => [r[(a, 0)], r[(a, 1)], r[(a, 2)]],
            None => std::array::from_fn(|k| f64::from(u8::from(k == a))),
        }
    };
    let (wa, wb) = (weights(row, a), weights(col, b));
    let mut push = |p: usize, q: usize, v: f64| {
        if v != 0.0 {
            out.push(Triplet::new(3 * i + p, 3 * j + q, v));
        }
    };
    if i != j {
        for (p, a) in wa.iter().enumerate() {
            for (q, b) in wb.iter().enumerate() {
                push(p, q, a * e.val * b);
            }
        }
        return;
    }
    // A diagonal block: its lower triangle of the symmetric part.
    for p in 0..3 {
        for q in 0..=p {
            let v = match (a == b, p == q) {
                (true, _) => e.val * wa[p] * wa[q],
                (false, false) => e.val * (wa[p] * wb[q] + wb[p] * wa[q]),
                (false, true) => 2.0 * e.val * wa[p] * wb[p],
            };
            push(p, q, v);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A rotation about z by `deg` degrees.
    fn about_z(deg: f64) -> Mat3 {
        let (s, c) = deg.to_radians().sin_cos();
        Mat3::new(c, -s, 0.0, s, c, 0.0, 0.0, 0.0, 1.0)
    }

    /// The full symmetric matrix of a tangent's stiffness over `n` particles.
    fn dense(t: &Tangent, n: usize) -> nalgebra::DMatrix<f64> {
        let mut m = nalgebra::DMatrix::zeros(3 * n, 3 * n);
        for e in t.stiffness_entries() {
            m[(e.row, e.col)] += e.val;
            if e.row != e.col {
                m[(e.col, e.row)] += e.val;
            }
        }
        m
    }

    #[test]
    fn the_transformed_tangent_is_t_transpose_k_t() {
        // Two particles, the second framed: a full symmetric 6×6 K.
        let k = nalgebra::DMatrix::<f64>::from_fn(6, 6, |r, c| {
            1.0 + (r * 7 + c * 7 + r * c) as f64 / 10.0 + if r == c { 10.0 } else { 0.0 }
        });
        let k = &k + k.transpose();
        let mut t = Tangent::new();
        for i in 0..2 {
            for j in 0..2 {
                let block = Mat3::from_fn(|a, b| k[(3 * i + a, 3 * j + b)]);
                t.add_stiffness(i, j, &block);
            }
        }
        let r = about_z(30.0) * Mat3::new(1.0, 0.0, 0.0, 0.0, 0.6, -0.8, 0.0, 0.8, 0.6);
        let mut frames = ParticleFrames::default();
        frames.set(1, r, Dofs::parse("x").unwrap());
        let mut big_t = nalgebra::DMatrix::<f64>::identity(6, 6);
        big_t.view_mut((3, 3), (3, 3)).copy_from(&r);
        let expected = big_t.transpose() * &k * &big_t;
        let got = dense(&frames.tangent_in_frames(&t), 2);
        assert!((got - expected).amax() < 1e-12 * k.amax());
    }

    #[test]
    fn a_framed_particle_keeps_only_its_free_motion() {
        let r = about_z(30.0);
        let mut frames = ParticleFrames::default();
        frames.set(0, r, Dofs::parse("x").unwrap());
        let mut v = vec![Vec3::new(1.0, 2.0, 3.0)];
        frames.hold(&mut v);
        assert!(v[0].dot(&r.column(0)).abs() < 1e-15);
        let free = Vec3::new(1.0, 2.0, 3.0).dot(&r.column(1));
        assert!((v[0].dot(&r.column(1)) - free).abs() < 1e-15);
        assert_eq!(v[0].z, 3.0);
    }

    #[test]
    fn a_skewed_basis_is_refused() {
        let skewed = Mat3::new(1.0, 0.1, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0);
        assert!(matches!(
            check_orthonormal(&skewed),
            Err(FrameError::NotOrthonormal { .. })
        ));
        assert_eq!(check_orthonormal(&about_z(17.0)), Ok(()));
    }

    #[test]
    fn an_axis_fix_and_a_frame_merge_into_their_span() {
        let mut frames = ParticleFrames::default();
        let r = about_z(30.0);
        // The frame holds its e₁ (in the x–y plane); an axis fix holds z.
        let (basis, held) = {
            frames.set(0, r, Dofs::parse("x").unwrap());
            frames.merged(0, Dofs::parse("z").unwrap(), &Mat3::identity(), Dofs::NONE)
        };
        let mut v = vec![Vec3::new(1.0, 2.0, 3.0)];
        let mut only = ParticleFrames::default();
        only.set(0, basis, held);
        only.hold(&mut v);
        let free = r.column(1);
        let expected = Vec3::new(1.0, 2.0, 3.0).dot(&free) * free;
        assert!((v[0] - expected).amax() < 1e-14, "{} vs {expected}", v[0]);
    }
}
