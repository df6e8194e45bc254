//! Rigid bodies: six degrees of freedom for bodies a scene declares rigid, so that scenes which
//! need no deformation do not pay for it (paper 003 §3 models its ballast as rigid clumps).
//!
//! A rigid body is a *centre particle* of the [`State`] at its centre of mass, carrying the
//! body's mass and its translational degrees of freedom (integrated like any particle), plus a
//! rotation stored here: the orientation q of its principal frame, its principal moments of
//! inertia I, and its angular momentum L and velocity ω = R I⁻¹ Rᵀ L in the world frame.
//! The body's mesh nodes stay in the state as massless *members* whose positions and
//! velocities follow the pose, x = c + R s and v = v_c + ω × R s, so that contact spheres,
//! probes, loads and output see them like any particle. Forces that models put on members
//! reach the body as a force and a torque about c ([`reduce_member_forces`]).
//!
//! Rotation is integrated in the leapfrog form of velocity Verlet: L_{n+½} = L_n + ½∆t τ_n,
//! q_{n+1} = exp(ω_{½}∆t) q_n with ω_{½} taken at the half-way orientation,
//! L_{n+1} = L_{n+½} + ½∆t τ_{n+1}. Without torque L is conserved exactly and a body with equal
//! principal moments spins at a constant rate.

use crate::error::CoreError;
use crate::step::rigid_constraints::PointHolds;
use crate::step::state::State;
use crate::{Mat3, Vec3};
use nalgebra::{Rotation3, SymmetricEigen, UnitQuaternion};
use rayon::prelude::*;

/// Marks a particle that is no member of any rigid body.
const NO_BODY: u32 = u32::MAX;

/// The rotational state of every rigid body of a scene, one entry per body in each array,
/// and the members that follow each body.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct RigidBodies {
    /// The centre particle of each body: at the centre of mass, with the body's mass.
    pub center: Vec<usize>,
    /// Orientation of each body's principal frame (body → world).
    pub orientation: Vec<UnitQuaternion<f64>>,
    /// Principal moments of inertia about the centre of mass (kg m²).
    pub inertia: Vec<Vec3>,
    /// Angular momentum about the centre of mass, world frame (kg m²/s).
    pub angular_momentum: Vec<Vec3>,
    /// Angular velocity, world frame (rad/s), kept equal to R I⁻¹ Rᵀ L.
    pub angular_velocity: Vec<Vec3>,
    /// Bodies whose rotation is held fixed (a body fixed in all three directions).
    pub spin_fixed: Vec<bool>,
    /// Members held at points in some directions ([`crate::step::rigid_constraints`]).
    pub holds: PointHolds,
    member_start: Vec<usize>,
    member: Vec<usize>,
    member_body: Vec<u32>,
    offset: Vec<Vec3>,
    owner: Vec<u32>,
}

impl RigidBodies {
    /// Number of rigid bodies.
    pub fn len(&self) -> usize {
        self.center.len()
    }

    /// Whether the scene has no rigid body.
    pub fn is_empty(&self) -> bool {
        self.center.is_empty()
    }

    /// The rigid body particle `i` is a member of, if any.
    #[inline]
    pub fn body_of_member(&self, i: usize) -> Option<usize> {
        match self.owner.get(i) {
            Some(&b) if b != NO_BODY => Some(b as usize),
            _ => None,
        }
    }

    /// The member particles of body `b`.
    pub fn members(&self, b: usize) -> &[usize] {
        &self.member[self.member_start[b]..self.member_start[b + 1]]
    }

    /// The slot of particle `i` among the members (the index of its offset), if it is one.
    pub(crate) fn member_slot(&self, i: usize) -> Option<usize> {
        let b = self.body_of_member(i)?;
        let slots = self.member_start[b]..self.member_start[b + 1];
        slots.into_iter().find(|&slot| self.member[slot] == i)
    }

    /// The offset s of member slot `slot` from its body's centre, in the body's principal
    /// frame (its arm is R s).
    pub(crate) fn offset(&self, slot: usize) -> Vec3 {
        self.offset[slot]
    }

    /// Rotational kinetic energy ½ Σ ω·L (J).
    pub fn kinetic_energy(&self) -> f64 {
        (0..self.len()).map(|b| self.body_kinetic_energy(b)).sum()
    }

    /// Body `b`'s rotational kinetic energy ½ ω·L (J).
    pub fn body_kinetic_energy(&self, b: usize) -> f64 {
        0.5 * self.angular_velocity[b].dot(&self.angular_momentum[b])
    }

    /// Position and velocity of member slot `slot` from its body's pose.
    #[inline]
    fn placed(&self, slot: usize, position: &[Vec3], velocity: &[Vec3]) -> (Vec3, Vec3) {
        let b = self.member_body[slot] as usize;
        let c = self.center[b];
        let arm = self.orientation[b] * self.offset[slot];
        (
            position[c] + arm,
            velocity[c] + self.angular_velocity[b].cross(&arm),
        )
    }

    /// α_b = I_w⁻¹ (τ − ω × L): body `b`'s angular acceleration under the torque `torque`
    /// (Euler's equations in the world frame, I_w = R I Rᵀ); zero when its spin is fixed.
    pub fn angular_acceleration(&self, b: usize, torque: Vec3) -> Vec3 {
        if self.spin_fixed[b] {
            return Vec3::zeros();
        }
        let gyroscopic = self.angular_velocity[b].cross(&self.angular_momentum[b]);
        spin(
            &self.orientation[b],
            &self.inertia[b],
            &(torque - gyroscopic),
        )
    }

    /// The acceleration of the point at `arm` from body `b`'s centre (world frame) under the
    /// torque `torque`, the centre accelerating at `center`: the rigid motion's
    /// a_c + α × r + ω × (ω × r), the last term −|ω|² r⊥ (r⊥ the part of r across ω).
    pub fn point_acceleration(&self, b: usize, torque: Vec3, center: Vec3, arm: Vec3) -> Vec3 {
        let w = self.angular_velocity[b];
        center + self.angular_acceleration(b, torque).cross(&arm) + w.cross(&w.cross(&arm))
    }

    /// Sets L_b (world frame) and the angular velocity that follows from it.
    pub fn set_angular_momentum(&mut self, b: usize, l: Vec3) {
        self.angular_momentum[b] = l;
        self.angular_velocity[b] = self.omega_from(b, &l);
    }

    /// Sets ω_b (world frame) and the angular momentum R I Rᵀ ω.
    pub fn set_angular_velocity(&mut self, b: usize, w: Vec3) {
        let r = self.orientation[b];
        let l = r * self.inertia[b].component_mul(&(r.inverse() * w));
        self.set_angular_momentum(b, l);
    }

    fn omega_from(&self, b: usize, l: &Vec3) -> Vec3 {
        spin(&self.orientation[b], &self.inertia[b], l)
    }

    /// L += h τ for every body whose spin is free, then ω from L.
    pub fn kick(&mut self, torque: &[Vec3], h: f64) {
        let (orientation, inertia) = (&self.orientation, &self.inertia);
        self.angular_momentum
            .par_iter_mut()
            .zip(self.angular_velocity.par_iter_mut())
            .zip(self.spin_fixed.par_iter())
            .with_min_len(BODY_CHUNK)
            .enumerate()
            .for_each(|(b, ((l, w), &fixed))| {
                if fixed {
                    *l = Vec3::zeros();
                    *w = Vec3::zeros();
                    return;
                }
                *l += h * torque[b];
                *w = spin(&orientation[b], &inertia[b], l);
            });
    }

    /// [`RigidBodies::kick`] by ½∆t followed by [`RigidBodies::rotate`] by ∆t, in one pass:
    /// the first half of a Verlet step.
    pub fn kick_and_rotate(&mut self, torque: &[Vec3], dt: f64) {
        let (inertia, fixed) = (&self.inertia, &self.spin_fixed);
        self.orientation
            .par_iter_mut()
            .zip(self.angular_velocity.par_iter_mut())
            .zip(self.angular_momentum.par_iter_mut())
            .with_min_len(BODY_CHUNK)
            .enumerate()
            .for_each(|(b, ((q, w), l))| {
                if fixed[b] {
                    *l = Vec3::zeros();
                    *w = Vec3::zeros();
                    return;
                }
                *l += 0.5 * dt * torque[b];
                *w = spin(q, &inertia[b], l);
                rotate_one(q, w, &inertia[b], l, dt);
            });
    }

    /// q ← exp(ω_{½}∆t) q for every body, with ω_{½} the angular velocity at the half-way
    /// orientation exp(ω∆t/2) q under the (drift-constant) L; then ω at the new orientation.
    /// Exact for equal principal moments (a sphere: ω is constant and one exponential
    /// suffices), second order otherwise.
    pub fn rotate(&mut self, dt: f64) {
        let (inertia, momentum) = (&self.inertia, &self.angular_momentum);
        self.orientation
            .par_iter_mut()
            .zip(self.angular_velocity.par_iter_mut())
            .with_min_len(BODY_CHUNK)
            .enumerate()
            .for_each(|(b, (q, w))| rotate_one(q, w, &inertia[b], &momentum[b], dt));
    }
}

/// The rotation of one body over ∆t under constant L (see [`RigidBodies::rotate`]).
#[inline]
fn rotate_one(q: &mut UnitQuaternion<f64>, w: &mut Vec3, moments: &Vec3, l: &Vec3, dt: f64) {
    if moments.x == moments.y && moments.y == moments.z {
        *q = exp_map(dt * *w) * *q;
        return;
    }
    let half = exp_map(0.5 * dt * *w) * *q;
    *q = exp_map(dt * spin(&half, moments, l)) * *q;
    *w = spin(q, moments, l);
}

/// The rotation by the angle |v| about v, as a unit quaternion. Below 10⁻³ rad (every step
/// of a stable run) the series cos(θ/2) = 1 − θ²/8 + θ⁴/384, sin(θ/2)/θ = ½ − θ²/48 + θ⁴/3840
/// is exact to round-off and avoids the trigonometric calls.
#[inline]
fn exp_map(v: Vec3) -> UnitQuaternion<f64> {
    let t2 = v.norm_squared();
    if t2 >= 1e-6 {
        return UnitQuaternion::from_scaled_axis(v);
    }
    let c = 1.0 - t2 / 8.0 + t2 * t2 / 384.0;
    let s = 0.5 - t2 / 48.0 + t2 * t2 / 3840.0;
    UnitQuaternion::new_normalize(nalgebra::Quaternion::new(c, s * v.x, s * v.y, s * v.z))
}

/// Bodies per parallel task.
const BODY_CHUNK: usize = 1024;

/// ω = R I⁻¹ Rᵀ L; L/I for equal principal moments.
#[inline]
fn spin(orientation: &UnitQuaternion<f64>, moments: &Vec3, momentum: &Vec3) -> Vec3 {
    if moments.x == moments.y && moments.y == moments.z {
        return momentum / moments.x;
    }
    orientation * (orientation.inverse() * momentum).component_div(moments)
}

impl State {
    /// Turns particle `center` into the centre of a rigid body of mass `state.mass[center]`,
    /// with `inertia` the inertia tensor (kg m², world axes) about that particle at the current
    /// configuration, and `members` the particles that follow the body (made massless here).
    /// Returns the body's index.
    pub fn add_rigid_body(
        &mut self,
        name: &str,
        center: usize,
        members: &[usize],
        inertia: Mat3,
    ) -> Result<usize, CoreError> {
        let (moments, axes) = principal_axes(inertia);
        let positive = |v: f64| v.is_finite() && v > 0.0;
        if !positive(moments.min()) || !positive(self.mass[center]) {
            return Err(CoreError::BadRigidBody {
                body: name.to_string(),
                mass: self.mass[center],
                inertia: moments.into(),
            });
        }
        let n = self.len();
        let rigid = &mut self.rigid;
        if rigid.owner.len() < n {
            rigid.owner.resize(n, NO_BODY);
        }
        let b = rigid.center.len();
        if rigid.member_start.is_empty() {
            rigid.member_start.push(0);
        }
        let c = self.position[center];
        for &m in members {
            rigid.owner[m] = b as u32;
            rigid.member.push(m);
            rigid.member_body.push(b as u32);
            rigid.offset.push(axes.inverse() * (self.position[m] - c));
            self.mass[m] = 0.0;
        }
        rigid.member_start.push(rigid.member.len());
        rigid.center.push(center);
        rigid.orientation.push(axes);
        rigid.inertia.push(moments);
        rigid.angular_momentum.push(Vec3::zeros());
        rigid.angular_velocity.push(Vec3::zeros());
        rigid.spin_fixed.push(false);
        place_body_members(self, b);
        Ok(b)
    }
}

/// Principal moments and the rotation from the principal frame to the world frame.
fn principal_axes(inertia: Mat3) -> (Vec3, UnitQuaternion<f64>) {
    let eigen = SymmetricEigen::new(inertia);
    let mut axes = eigen.eigenvectors;
    if axes.determinant() < 0.0 {
        axes.column_mut(2).neg_mut();
    }
    let rotation = Rotation3::from_matrix_unchecked(axes);
    (
        eigen.eigenvalues,
        UnitQuaternion::from_rotation_matrix(&rotation),
    )
}

/// Puts every member at x = c + R s with velocity v = v_c + ω × R s.
pub fn place_members(state: &mut State) {
    let State {
        rigid,
        position,
        velocity,
        ..
    } = state;
    // In place and in one serial pass: a member's pose reads only its body's centre, which is
    // no member, and a pass of a few flops per member is cheaper than waking a worker (and
    // allocates nothing).
    for (slot, &m) in rigid.member.iter().enumerate() {
        let (x, v) = rigid.placed(slot, position, velocity);
        position[m] = x;
        velocity[m] = v;
    }
}

/// [`place_members`], keeping each member's arm R s in `arms` (by member slot) for
/// [`place_member_velocities`]; body by body, each body's pose read once.
pub fn place_members_keeping_arms(state: &mut State, arms: &mut Vec<Vec3>) {
    let State {
        rigid,
        position,
        velocity,
        ..
    } = state;
    arms.resize(rigid.member.len(), Vec3::zeros());
    for b in 0..rigid.len() {
        let c = rigid.center[b];
        let (q, w) = (rigid.orientation[b], rigid.angular_velocity[b]);
        let (x_c, v_c) = (position[c], velocity[c]);
        let slots = rigid.member_start[b]..rigid.member_start[b + 1];
        let members = rigid.member[slots.clone()]
            .iter()
            .zip(&rigid.offset[slots.clone()]);
        for ((&m, offset), kept) in members.zip(&mut arms[slots]) {
            let arm = q * offset;
            position[m] = x_c + arm;
            velocity[m] = v_c + w.cross(&arm);
            *kept = arm;
        }
    }
}

/// Puts every member's velocity at v = v_c + ω × R s, with the arms R s that
/// [`place_members_keeping_arms`] kept at the current pose: after a kick, which changes the
/// bodies' velocities but not their poses, so the members' positions stand. The same bits as
/// [`place_members`].
pub fn place_member_velocities(state: &mut State, arms: &[Vec3]) {
    let State {
        rigid, velocity, ..
    } = state;
    debug_assert_eq!(arms.len(), rigid.member.len(), "arms kept at this pose");
    for b in 0..rigid.len() {
        let (w, v_c) = (rigid.angular_velocity[b], velocity[rigid.center[b]]);
        let slots = rigid.member_start[b]..rigid.member_start[b + 1];
        for (&m, arm) in rigid.member[slots.clone()].iter().zip(&arms[slots]) {
            velocity[m] = v_c + w.cross(arm);
        }
    }
}

/// Puts the members of body `b` alone at x = c + R s with velocity v = v_c + ω × R s (a body
/// whose pose was just set, the others untouched).
pub fn place_body_members(state: &mut State, b: usize) {
    let State {
        rigid,
        position,
        velocity,
        ..
    } = state;
    for slot in rigid.member_start[b]..rigid.member_start[b + 1] {
        let (x, v) = rigid.placed(slot, position, velocity);
        let m = rigid.member[slot];
        position[m] = x;
        velocity[m] = v;
    }
}

/// Moves the forces models put on members onto their bodies: the centre particle receives
/// Σ f and the body the torque Σ (x − c) × f. Member forces are zeroed. `torque` starts with
/// the bodies' torques (the particles' moments that may follow are left alone).
pub fn reduce_member_forces(state: &State, force: &mut [Vec3], torque: &mut [Vec3]) {
    let rigid = &state.rigid;
    if rigid.member.is_empty() {
        return;
    }
    for (b, body_torque) in torque.iter_mut().take(rigid.len()).enumerate() {
        let c = rigid.center[b];
        let (mut total, mut moment) = (Vec3::zeros(), Vec3::zeros());
        for &m in rigid.members(b) {
            let f = std::mem::take(&mut force[m]);
            total += f;
            moment += (state.position[m] - state.position[c]).cross(&f);
        }
        force[c] += total;
        *body_torque += moment;
    }
}

/// Mass (kg), centre of mass and inertia tensor about it (kg m², world axes) of a solid of
/// `density` filling the tetrahedra `tets` over `points`: the exact integrals over each
/// tetrahedron, ∫ r rᵀ dV = V/20 (Σ rᵢ rᵢᵀ + (Σ rᵢ)(Σ rᵢ)ᵀ) with r relative to the centre.
pub fn tet_mass_properties(points: &[Vec3], tets: &[[u32; 4]], density: f64) -> (f64, Vec3, Mat3) {
    let corners = |t: &[u32; 4]| t.map(|n| points[n as usize]);
    let volume = |x: &[Vec3; 4]| (x[1] - x[0]).cross(&(x[2] - x[0])).dot(&(x[3] - x[0])) / 6.0;
    let (mut total, mut moment) = (0.0, Vec3::zeros());
    for t in tets {
        let x = corners(t);
        let v = volume(&x);
        total += v;
        moment += v * (x[0] + x[1] + x[2] + x[3]) / 4.0;
    }
    let center = moment / total;
    let mut second = Mat3::zeros();
    for t in tets {
        let x = corners(t).map(|p| p - center);
        let sum = x[0] + x[1] + x[2] + x[3];
        let own = x
            .iter()
            .fold(Mat3::zeros(), |acc, r| acc + r * r.transpose());
        second += volume(&corners(t)) / 20.0 * (own + sum * sum.transpose());
    }
    let second = density * second;
    let inertia = Mat3::identity() * second.trace() - second;
    (density * total, center, inertia)
}

/// The inertia tensor about `center` of point masses `mass` at `points`.
pub fn point_inertia(center: Vec3, points: &[Vec3], mass: &[f64]) -> Mat3 {
    points.iter().zip(mass).fold(Mat3::zeros(), |acc, (x, &m)| {
        let r = x - center;
        acc + m * (Mat3::identity() * r.norm_squared() - r * r.transpose())
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn body_with_members() -> State {
        // A centre particle with two massless members on the x axis.
        let mut s = State::at_rest(vec![
            Vec3::zeros(),
            Vec3::new(1.0, 0.0, 0.0),
            Vec3::new(-1.0, 0.0, 0.0),
        ]);
        s.mass = vec![2.0, 1.0, 1.0];
        let inertia = Mat3::from_diagonal(&Vec3::new(0.1, 2.0, 3.0));
        s.add_rigid_body("b", 0, &[1, 2], inertia).unwrap();
        s
    }

    #[test]
    fn members_follow_a_rotation_and_lose_their_mass() {
        let mut s = body_with_members();
        assert_eq!(s.mass, vec![2.0, 0.0, 0.0]);
        s.rigid.set_angular_velocity(0, Vec3::new(0.0, 0.0, 1.0));
        s.rigid.rotate(std::f64::consts::FRAC_PI_2);
        place_members(&mut s);
        assert!((s.position[1] - Vec3::new(0.0, 1.0, 0.0)).norm() < 1e-14);
        assert!((s.velocity[1] - Vec3::new(-1.0, 0.0, 0.0)).norm() < 1e-14);
        assert_eq!(s.rigid.body_of_member(2), Some(0));
        assert_eq!(s.rigid.body_of_member(0), None);
    }

    #[test]
    fn velocities_from_kept_arms_are_those_of_a_full_placing() {
        // A turned, moving body placed keeping its arms, then kicked: the velocities from the
        // kept arms are a full placing's bit for bit, and the positions stand.
        let mut s = body_with_members();
        s.velocity[0] = Vec3::new(0.3, -0.2, 0.1);
        s.rigid.set_angular_velocity(0, Vec3::new(0.7, -1.1, 0.4));
        s.rigid.rotate(0.37);
        let mut arms = Vec::new();
        place_members_keeping_arms(&mut s, &mut arms);
        let mut full = s.clone();
        place_members(&mut full);
        assert!(full == s);
        s.rigid.kick(&[Vec3::new(0.2, 0.5, -0.3)], 0.01);
        s.velocity[0] += Vec3::new(0.01, 0.02, 0.03);
        let mut full = s.clone();
        place_members(&mut full);
        place_member_velocities(&mut s, &arms);
        assert!(full == s);
        assert_ne!(s.velocity[1], s.velocity[0]);
    }

    #[test]
    fn member_forces_become_force_and_torque() {
        let s = body_with_members();
        let mut force = vec![Vec3::zeros(), Vec3::new(0.0, 1.0, 0.0), Vec3::zeros()];
        let mut torque = vec![Vec3::zeros()];
        reduce_member_forces(&s, &mut force, &mut torque);
        assert_eq!(force[0], Vec3::new(0.0, 1.0, 0.0));
        assert_eq!(force[1], Vec3::zeros());
        assert!((torque[0] - Vec3::new(0.0, 0.0, 1.0)).norm() < 1e-15);
    }

    #[test]
    fn a_cube_of_tetrahedra_has_the_cube_inertia() {
        // The unit cube split into 6 tetrahedra around its diagonal.
        let points: Vec<Vec3> = (0..8)
            .map(|i| Vec3::new((i & 1) as f64, ((i >> 1) & 1) as f64, ((i >> 2) & 1) as f64))
            .collect();
        let tets = [
            [0, 1, 3, 7],
            [0, 1, 7, 5],
            [0, 5, 7, 4],
            [0, 3, 2, 7],
            [0, 2, 6, 7],
            [0, 6, 4, 7],
        ];
        let (mass, center, inertia) = tet_mass_properties(&points, &tets, 2.0);
        assert!((mass - 2.0).abs() < 1e-14);
        assert!((center - Vec3::repeat(0.5)).norm() < 1e-14);
        let expected = Mat3::identity() * (2.0 * 2.0 / 12.0);
        assert!((inertia - expected).norm() < 1e-14, "{inertia}");
    }

    #[test]
    fn the_series_exponential_matches_the_exact_one() {
        for angle in [0.0, 1e-9, 1e-5, 9.9e-4, 1.1e-3, 0.5] {
            let v = Vec3::new(0.3, -0.5, 0.8).normalize() * angle;
            let exact = UnitQuaternion::from_scaled_axis(v);
            assert!((exp_map(v).coords - exact.coords).norm() < 1e-16, "{angle}");
        }
    }

    #[test]
    fn a_massless_or_flat_body_is_refused() {
        let mut s = State::at_rest(vec![Vec3::zeros()]);
        s.mass[0] = 1.0;
        let flat = Mat3::from_diagonal(&Vec3::new(0.0, 1.0, 1.0));
        assert!(s.add_rigid_body("b", 0, &[], flat).is_err());
    }
}
