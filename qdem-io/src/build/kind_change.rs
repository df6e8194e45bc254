//! A body's kind chosen per stage: a scene that `start_from`s a checkpoint may integrate a
//! `[[body]]` or the `[ballast]` stones rigid where the checkpoint's scene had them deformable,
//! or the other way round (forming a bed needs the stones' shapes and contacts, loading it
//! needs their elasticity).
//!
//! The particles of both scenes differ only in the rigid bodies' centre particles, which come
//! after every mesh node (`build_bodies`): a body's nodes keep their indices. Which bodies were
//! rigid in the checkpoint's scene is read from the checkpoint itself: a body (a stone) was
//! rigid when the next saved centre particle sits at the centre of mass of its tetrahedra in
//! the saved reference positions, where the build put it ([`saved_kinds`]).
//!
//! - **Rigid → deformable** ([`to_deformable`]): the nodes keep the saved rigid motion of the
//!   reference, x = c + R s (so the tetrahedra are unstressed: the strain of Eq. 4 of paper 000,
//!   (F Fᵀ − I)/2, is zero for a rotation), and move with v = v_c + ω' × (x − c̄), c̄ the centre
//!   of the lumped masses and ω' = I_l⁻¹ L' with I_l their inertia about c̄, L' chosen so that
//!   the nodes carry the rigid body's momentum M v_c and angular momentum M c × v_c + L
//!   exactly (ω' = ω when the lumped inertia equals the solid's).
//! - **Deformable → rigid** ([`to_rigid`]): the centre at the nodes' centre of mass c̄ with
//!   their mean velocity, the orientation the best-fit rotation R of the saved nodes onto the
//!   reference (the mass-weighted Kabsch fit: R = U diag(1, 1, det U Vᵀ) Vᵀ for
//!   Σ m (x − c̄)(X − C̄)ᵀ = U Σ Vᵀ), the angular momentum the nodes' Σ m (x − c̄) × (v − v_c).
//!   Momentum and angular momentum are kept; the strain energy and the kinetic energy of the
//!   deformation are dropped, and reported.

use crate::build::{BodyInfo, BodyKind, PlacedMesh};
use crate::scene::Scene;
use nalgebra::{Matrix3, UnitQuaternion};
use qdem_core::checkpoint::SavedState;
use qdem_core::step::rigid_body::{place_body_members, point_inertia, tet_mass_properties};
use qdem_core::{continuum::Material, continuum::TetBody, step::Model, step::State, Vec3};
use std::ops::Range;

/// A part of a body that is one rigid body when the body is rigid: a `[[body]]`, or a stone.
pub(crate) struct Piece {
    /// Its mesh nodes in the state.
    pub(crate) nodes: Range<usize>,
    /// Its tetrahedra, as state particle indices.
    pub(crate) tets: Vec<[u32; 4]>,
    /// Its rigid-body index and centre particle in this scene, when rigid here.
    pub(crate) rigid: Option<(usize, usize)>,
}

/// A body whose kind a scene chooses: a `[[body]]` (one piece) or the `[ballast]` (a piece per
/// stone).
pub(crate) struct Unit {
    /// How messages name it.
    pub(crate) what: String,
    /// Its pieces, in the order their rigid bodies are laid out.
    pub(crate) pieces: Vec<Piece>,
    /// Its material.
    pub(crate) material: Material,
}

impl Unit {
    /// Whether it is rigid in this scene.
    pub(crate) fn rigid(&self) -> bool {
        self.pieces.iter().any(|p| p.rigid.is_some())
    }

    /// How a message names the piece holding particle `i`.
    pub(crate) fn name_of(&self, i: usize) -> Option<String> {
        let k = self.pieces.iter().position(|p| p.nodes.contains(&i))?;
        Some(match self.pieces.len() {
            1 => self.what.clone(),
            _ => format!("{} stone {}", self.what, k + 1),
        })
    }
}

/// The bodies of a built scene as units, in the order of their rigid bodies.
pub(crate) fn units(
    scene: &Scene,
    meshes: &[PlacedMesh],
    bodies: &[BodyInfo],
    ballast: Option<&super::ballast::BallastInfo>,
) -> Vec<Unit> {
    let refs = scene.refs();
    let mut units = Vec::with_capacity(bodies.len());
    for (k, (body, placed)) in bodies.iter().zip(meshes).enumerate() {
        let tets = super::offset_tets(&placed.mesh, placed.particles.start);
        let (material, stones) = match (k < scene.bodies.len(), ballast) {
            (true, _) => (refs.body_materials[k], None),
            (false, Some(info)) => (refs.ballast_material.expect("validated"), Some(info)),
            (false, None) => continue,
        };
        let material = super::core_material(&scene.materials[material]);
        let pieces = match (stones, &body.kind) {
            (Some(info), kind) => {
                let first = match kind {
                    BodyKind::Stones { first, .. } => Some(*first),
                    _ => None,
                };
                (info.stones.iter().zip(&info.tets).enumerate())
                    .map(|(s, (nodes, own))| Piece {
                        nodes: nodes.clone(),
                        tets: tets[own.clone()].to_vec(),
                        rigid: first.map(|f| (f + s, info.centers[s])),
                    })
                    .collect()
            }
            (None, kind) => vec![Piece {
                nodes: body.particles.clone(),
                tets,
                rigid: match kind {
                    BodyKind::Rigid { body, center, .. } => Some((*body, *center)),
                    _ => None,
                },
            }],
        };
        let what = match stones {
            Some(_) => format!("[ballast] `{}`", body.name),
            None => format!("body `{}`", body.name),
        };
        units.push(Unit {
            what,
            pieces,
            material,
        });
    }
    units
}

/// Whether each unit was rigid in the checkpoint's scene (module docs): its pieces' centres
/// follow, from particle `first_center` on, at the centres of mass of their tetrahedra in the
/// saved reference, within `same` (a distance that removes whole periodic cells).
pub(crate) fn saved_kinds(
    units: &[Unit],
    saved: &SavedState,
    first_center: usize,
    same: impl Fn(Vec3, Vec3) -> bool,
) -> Vec<bool> {
    let mut next = first_center;
    units
        .iter()
        .map(|u| {
            let rigid = u.pieces.iter().enumerate().all(|(k, p)| {
                let center = tet_mass_properties(&saved.reference, &p.tets, u.material.density).1;
                saved
                    .reference
                    .get(next + k)
                    .is_some_and(|&c| same(c, center))
            });
            if rigid {
                next += u.pieces.len();
            }
            rigid
        })
        .collect()
}

/// Turns a piece that was rigid (centre particle `center`, rigid body `body` of `saved`) into
/// deformable nodes (module docs); `state` holds the saved positions of its nodes and the
/// lumped masses of this scene.
pub(crate) fn to_deformable(
    piece: &Piece,
    (center, body): (usize, usize),
    saved: &SavedState,
    state: &mut State,
) {
    let nodes = piece.nodes.clone();
    let mass = &state.mass[nodes.clone()];
    let total: f64 = mass.iter().sum();
    let x = &state.position[nodes.clone()];
    let c_bar = x
        .iter()
        .zip(mass)
        .fold(Vec3::zeros(), |a, (p, &m)| a + m * p)
        / total;
    let (c, v) = (saved.position[center], saved.velocity[center]);
    let spin = saved.angular_momentum[body] + total * (c - c_bar).cross(&v);
    let inertia = point_inertia(c_bar, x, mass);
    let omega = inertia
        .lu()
        .solve(&spin)
        .unwrap_or(saved.angular_velocity[body]);
    for i in nodes {
        state.velocity[i] = v + omega.cross(&(state.position[i] - c_bar));
        state.acceleration[i] = Vec3::zeros();
    }
}

/// Turns a piece that was deformable (its nodes' saved motion in `saved`) into its rigid body
/// of this scene (module docs), placing its members. Returns the kinetic energy of the
/// deformation dropped: the nodes' less the rigid body's (J).
pub(crate) fn to_rigid(piece: &Piece, density: f64, saved: &SavedState, state: &mut State) -> f64 {
    let (body, center) = piece.rigid.expect("a piece turned rigid is rigid here");
    let nodes = piece.nodes.clone();
    let mass = lumped_mass(&saved.reference, &piece.tets, nodes.clone(), density);
    let total: f64 = mass.iter().sum();
    let weigh = |v: &[Vec3]| {
        v[nodes.clone()]
            .iter()
            .zip(&mass)
            .fold(Vec3::zeros(), |a, (p, &m)| a + m * p)
            / total
    };
    let (c, v, c0) = (
        weigh(&saved.position),
        weigh(&saved.velocity),
        weigh(&saved.reference),
    );
    let (mut l, mut h, mut kinetic) = (Vec3::zeros(), Matrix3::zeros(), 0.0);
    for (i, &m) in nodes.zip(&mass) {
        let (r, u) = (saved.position[i] - c, saved.velocity[i]);
        l += m * r.cross(&(u - v));
        h += m * r * (saved.reference[i] - c0).transpose();
        kinetic += 0.5 * m * u.norm_squared();
    }
    let fit = best_fit_rotation(&h);
    let rigid = &mut state.rigid;
    rigid.orientation[body] = fit * rigid.orientation[body];
    rigid.set_angular_momentum(body, l);
    state.position[center] = c;
    state.velocity[center] = v;
    state.acceleration[center] = Vec3::zeros();
    place_body_members(state, body);
    let after = 0.5 * state.mass[center] * v.norm_squared() + state.rigid.body_kinetic_energy(body);
    kinetic - after
}

/// The strain energy of the tetrahedra `tets` of `material` at the saved positions (J).
pub(crate) fn strain_energy(
    name: &str,
    tets: Vec<[u32; 4]>,
    material: Material,
    saved: &SavedState,
) -> f64 {
    let Ok(body) = TetBody::new(name, &saved.reference, tets, material) else {
        return 0.0;
    };
    let mut at = State::at_rest(saved.reference.clone());
    at.position.clone_from(&saved.position);
    body.potential_energy(&at).unwrap_or(0.0)
}

/// Each node's lumped mass, a quarter of each of its tetrahedra's (`TetBody::lump_mass`).
fn lumped_mass(
    reference: &[Vec3],
    tets: &[[u32; 4]],
    nodes: Range<usize>,
    density: f64,
) -> Vec<f64> {
    let mut mass = vec![0.0; nodes.len()];
    for t in tets {
        let x = t.map(|n| reference[n as usize]);
        let volume = (x[1] - x[0]).cross(&(x[2] - x[0])).dot(&(x[3] - x[0])) / 6.0;
        for &n in t {
            mass[n as usize - nodes.start] += 0.25 * density * volume;
        }
    }
    mass
}

/// The rotation R maximising Σ m (x − c̄)·R (X − C̄) for the mass-weighted covariance
/// `h` = Σ m (x − c̄)(X − C̄)ᵀ: U diag(1, 1, det U Vᵀ) Vᵀ from its singular values.
fn best_fit_rotation(h: &Matrix3<f64>) -> UnitQuaternion<f64> {
    let svd = h.svd(true, true);
    let (u, vt) = (svd.u.expect("asked for"), svd.v_t.expect("asked for"));
    let mut d = Matrix3::identity();
    d[(2, 2)] = (u * vt).determinant().signum();
    let r = u * d * vt;
    UnitQuaternion::from_matrix(&r)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_best_fit_of_a_rotated_cloud_is_its_rotation() {
        let q = UnitQuaternion::from_scaled_axis(Vec3::new(0.3, -1.1, 0.7));
        let points = [
            Vec3::new(1.0, 0.0, 0.0),
            Vec3::new(0.0, 2.0, 0.0),
            Vec3::new(0.0, 0.0, 3.0),
            Vec3::new(-1.0, -2.0, -3.0),
        ];
        let h = points
            .iter()
            .fold(Matrix3::zeros(), |a, p| a + (q * p) * p.transpose());
        assert!(best_fit_rotation(&h).angle_to(&q) < 1e-14);
    }
}
