//! The simulation state: flat, structure-of-arrays storage of every particle's degrees of freedom.
//!
//! Particles are the vertices of the QDEM tetrahedra (paper 000 §2): each carries a position, a
//! velocity, an acceleration, a lumped mass (a quarter of the mass of every tetrahedron that
//! shares it, §2.4) and a per-direction fixity mask. Models read the state and write forces;
//! steppers advance it. All numerical code works on the slices directly.

use crate::step::frames::{FrameError, ParticleFrames};
use crate::step::rigid_body::RigidBodies;
use crate::{Mat3, Vec3};

/// A subset of the three translational directions, stored as a bit mask (x = 1, y = 2, z = 4).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub struct Dofs(u8);

impl Dofs {
    /// No direction.
    pub const NONE: Dofs = Dofs(0);
    /// All three directions.
    pub const ALL: Dofs = Dofs(0b111);

    /// Parses a subset such as `"xz"`; `None` for an empty string, a repeated letter or a
    /// letter other than x, y, z.
    pub fn parse(text: &str) -> Option<Dofs> {
        let mut mask = 0u8;
        for c in text.chars() {
            let bit = match c {
                'x' => 1,
                'y' => 2,
                'z' => 4,
                _ => return None,
            };
            if mask & bit != 0 {
                return None;
            }
            mask |= bit;
        }
        (mask != 0).then_some(Dofs(mask))
    }

    /// The set of the directions flagged in an `[x, y, z]` mask.
    pub fn from_mask(mask: [bool; 3]) -> Dofs {
        Dofs((0..3).filter(|&a| mask[a]).map(|a| 1u8 << a).sum())
    }

    /// Whether direction `axis` (0 = x, 1 = y, 2 = z) is in the set.
    #[inline]
    pub fn contains(self, axis: usize) -> bool {
        self.0 & (1 << axis) != 0
    }

    /// The union of two sets.
    #[inline]
    pub fn union(self, other: Dofs) -> Dofs {
        Dofs(self.0 | other.0)
    }

    /// Whether the set is empty.
    #[inline]
    pub fn is_empty(self) -> bool {
        self.0 == 0
    }
}

/// Degrees of freedom of all particles of a scene, one entry per particle in each array.
///
/// ```
/// use qdem_core::{step::Dofs, step::State, Vec3};
///
/// // Two particles at rest where they were put; masses are the caller's (or a body's
/// // `lump_mass`) to fill in.
/// let mut state = State::at_rest(vec![Vec3::zeros(), Vec3::x()]);
/// state.mass = vec![2.0, 1.0];
/// state.velocity[1] = Vec3::new(0.0, 3.0, 0.0);
/// assert_eq!(state.momentum(), Vec3::new(0.0, 3.0, 0.0));
/// assert_eq!(state.kinetic_energy(), 4.5);
///
/// // Displacements are measured from the reference configuration.
/// state.position[0].x += 0.25;
/// assert_eq!(state.displacement(0), Vec3::new(0.25, 0.0, 0.0));
///
/// // Fixing a particle zeroes its velocity in the fixed directions.
/// state.fix(1, Dofs::ALL);
/// assert_eq!(state.velocity[1], Vec3::zeros());
/// ```
#[derive(Clone, Debug, PartialEq)]
pub struct State {
    /// Simulated time (s).
    pub time: f64,
    /// Reference (initial) positions X (m).
    pub reference: Vec<Vec3>,
    /// Current positions x (m).
    pub position: Vec<Vec3>,
    /// Velocities (m/s).
    pub velocity: Vec<Vec3>,
    /// Accelerations (m/s²), consistent with the forces at `position` and `time`.
    pub acceleration: Vec<Vec3>,
    /// Lumped masses (kg).
    pub mass: Vec<f64>,
    /// Fixed directions per particle: a fixed direction keeps zero velocity and acceleration.
    /// Axes x, y, z; a particle held in a local frame has none here (its held directions are
    /// in `frames`).
    pub fixed: Vec<Dofs>,
    /// The particles held in a local frame ([`State::fix_in_frame`]); empty in most scenes.
    pub frames: ParticleFrames,
    /// Rotation of the rigid bodies (empty when the scene has none).
    pub rigid: RigidBodies,
    /// Rotational degrees of freedom of the particles (empty unless some particles rotate:
    /// bonded-particle DEM, single spheres of a granular sample).
    pub spin: ParticleSpin,
}

/// Rotational degrees of freedom of particles that carry them (the θ of paper 001's particles,
/// with the moment of inertia J of Eq. 9): a small-rotation vector per particle, its rate and
/// acceleration, the moment of inertia of the particle's shape (a disc or a sphere: one value)
/// and the fixed rotation axes. Either every array is empty (no particle rotates) or every
/// array has one entry per particle.
///
/// Rotations are integrated linearly, like translations (small rotations, the setting of the
/// paper's beam matrices); a model that needs finite rotations uses [`crate::step::RigidBodies`].
/// A sphere needs no orientation (its contacts read only ω), so a one-sphere grain rotates
/// here, with θ̇ = ω exact and θ its accumulated rotation vector, which nothing reads.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct ParticleSpin {
    /// Rotation vector θ (rad) about x, y, z.
    pub angle: Vec<Vec3>,
    /// Angular velocity θ̇ (rad/s).
    pub velocity: Vec<Vec3>,
    /// Angular acceleration θ̈ (rad/s²).
    pub acceleration: Vec<Vec3>,
    /// Moment of inertia J (kg m²).
    pub inertia: Vec<f64>,
    /// Fixed rotation axes per particle.
    pub fixed: Vec<Dofs>,
}

impl ParticleSpin {
    /// Appends a particle whose rotation is held in every axis.
    fn push_held(&mut self) {
        self.angle.push(Vec3::zeros());
        self.velocity.push(Vec3::zeros());
        self.acceleration.push(Vec3::zeros());
        self.inertia.push(0.0);
        self.fixed.push(Dofs::ALL);
    }

    /// Number of particles with rotational DOFs (0 or all of them).
    pub fn len(&self) -> usize {
        self.angle.len()
    }

    /// Whether no particle rotates.
    pub fn is_empty(&self) -> bool {
        self.angle.is_empty()
    }

    /// Rotational kinetic energy ½ Σ J θ̇² (J).
    pub fn kinetic_energy(&self) -> f64 {
        self.inertia
            .iter()
            .zip(&self.velocity)
            .map(|(j, w)| 0.5 * j * w.norm_squared())
            .sum()
    }
}

impl State {
    /// A state at rest in the reference configuration, with zero masses and nothing fixed.
    pub fn at_rest(reference: Vec<Vec3>) -> State {
        let n = reference.len();
        State {
            time: 0.0,
            position: reference.clone(),
            reference,
            velocity: vec![Vec3::zeros(); n],
            acceleration: vec![Vec3::zeros(); n],
            mass: vec![0.0; n],
            fixed: vec![Dofs::NONE; n],
            frames: ParticleFrames::default(),
            rigid: RigidBodies::default(),
            spin: ParticleSpin::default(),
        }
    }

    /// Gives every particle rotational DOFs at rest, with moments of inertia `inertia` (one
    /// per particle) and the rotation axes `fixed` fixed for all (`Dofs::parse("xy")` for
    /// particles rotating in the x–y plane only).
    ///
    /// # Panics
    /// If `inertia` does not have one entry per particle.
    pub fn add_spin(&mut self, inertia: Vec<f64>, fixed: Dofs) {
        let n = self.len();
        assert_eq!(inertia.len(), n, "one moment of inertia per particle");
        self.spin = ParticleSpin {
            angle: vec![Vec3::zeros(); n],
            velocity: vec![Vec3::zeros(); n],
            acceleration: vec![Vec3::zeros(); n],
            inertia,
            fixed: vec![fixed; n],
        };
    }

    /// Fixity of every generalised node: the particles' translations, then their rotations
    /// (node `len() + i` is the rotation of particle `i`), the layout of the implicit system.
    /// A particle held in a local frame gives its held local directions (the system numbers
    /// its DOFs in that frame, [`crate::step::frames`]).
    pub fn node_fixity(&self) -> Vec<Dofs> {
        let mut fixity: Vec<Dofs> = self.fixed.iter().chain(&self.spin.fixed).copied().collect();
        for (i, _, held) in self.frames.iter() {
            fixity[i] = held;
        }
        fixity
    }

    /// The generalised node that stands for the small rotation θ (world axes) of rigid body
    /// `b` in a modal analysis's tangent ([`crate::modal::lanczos`]): after the particles'
    /// translations and their rotations ([`State::node_fixity`]). A contact on a sphere of the
    /// body attaches its spring there through the arm to the contact point; implicit solves
    /// refuse rigid bodies and never see it.
    ///
    /// ```
    /// use qdem_core::{step::State, Vec3};
    ///
    /// let state = State::at_rest(vec![Vec3::zeros(); 4]);
    /// assert_eq!(state.body_rotation_node(1), 5);
    /// ```
    pub fn body_rotation_node(&self, b: usize) -> usize {
        self.len() + self.spin.len() + b
    }

    /// Mass of every generalised node: the lumped masses, then the moments of inertia.
    pub fn node_mass(&self) -> Vec<f64> {
        self.mass
            .iter()
            .chain(&self.spin.inertia)
            .copied()
            .collect()
    }

    /// Appends a free particle at `position` (also its reference position) with `velocity`
    /// and `mass`, and returns its index. In a state with particle rotations it gets a
    /// rotation held in every axis ([`State::let_turn`] frees it).
    pub fn push_particle(&mut self, position: Vec3, velocity: Vec3, mass: f64) -> usize {
        self.reference.push(position);
        self.position.push(position);
        self.velocity.push(velocity);
        self.acceleration.push(Vec3::zeros());
        self.mass.push(mass);
        self.fixed.push(Dofs::NONE);
        if !self.spin.is_empty() {
            self.spin.push_held();
        }
        self.len() - 1
    }

    /// Lets particle `p` rotate freely with moment of inertia `inertia` (kg m²): a sphere of
    /// radius r and mass m has J = 2/5 m r². A state without particle rotations gets them
    /// first, held in every axis with zero inertia for every other particle (a tetrahedron's
    /// node, a rigid body's centre), so that only the particles let turn here rotate.
    pub fn let_turn(&mut self, p: usize, inertia: f64) {
        if self.spin.is_empty() {
            self.add_spin(vec![0.0; self.len()], Dofs::ALL);
        }
        self.spin.inertia[p] = inertia;
        self.spin.fixed[p] = Dofs::NONE;
    }

    /// Number of particles.
    pub fn len(&self) -> usize {
        self.position.len()
    }

    /// Degrees of freedom of a tangent over this state: three translations per particle, and
    /// three rotations per particle when the particles rotate.
    pub fn dofs(&self) -> usize {
        3 * (self.len() + self.spin.len())
    }

    /// Whether the state holds no particle.
    pub fn is_empty(&self) -> bool {
        self.position.is_empty()
    }

    /// Copies what a step changes from `source`, a state of the same particles: the time, the
    /// positions, velocities and accelerations, the rigid bodies' rotations and the
    /// particles' rotational DOFs (not the reference, masses or fixity). For saving a state
    /// before a step that may be retaken, and restoring it, without copying (or allocating)
    /// the parts no step changes.
    pub fn copy_motion_from(&mut self, source: &State) {
        self.time = source.time;
        self.position.clone_from(&source.position);
        self.velocity.clone_from(&source.velocity);
        self.acceleration.clone_from(&source.acceleration);
        self.rigid.clone_from(&source.rigid);
        let (spin, from) = (&mut self.spin, &source.spin);
        spin.angle.clone_from(&from.angle);
        spin.velocity.clone_from(&from.velocity);
        spin.acceleration.clone_from(&from.acceleration);
    }

    /// Displacement x − X of particle `i`.
    #[inline]
    pub fn displacement(&self, i: usize) -> Vec3 {
        self.position[i] - self.reference[i]
    }

    /// Adds `dofs` to the fixed directions of particle `i` and zeroes its velocity and
    /// acceleration there.
    pub fn fix(&mut self, i: usize, dofs: Dofs) {
        if self.frames.get(i).is_some() {
            self.hold_in_frame(i, &Mat3::identity(), dofs);
            return;
        }
        self.fixed[i] = self.fixed[i].union(dofs);
        at_rest_in(&mut self.velocity[i], &mut self.acceleration[i], dofs);
    }

    /// Holds particle `i` in the local directions `dofs` of `frame` (columns: the local basis
    /// e₁, e₂, e₃ in world axes, orthonormal): e_k · u = 0 for each k in `dofs`
    /// ([`crate::step::frames`]), and zeroes its velocity and acceleration there. Directions
    /// already held (on axes or in another frame) stay held: the particle is then held in
    /// the span of all of them, in a basis of that span. Holding all three directions is
    /// [`State::fix`] with [`Dofs::ALL`].
    ///
    /// # Errors
    /// [`FrameError::NotOrthonormal`] for a basis that is not orthonormal.
    pub fn fix_in_frame(&mut self, i: usize, frame: Mat3, dofs: Dofs) -> Result<(), FrameError> {
        crate::step::frames::check_orthonormal(&frame)?;
        self.hold_in_frame(i, &frame, dofs);
        Ok(())
    }

    /// [`State::fix_in_frame`] of a checked basis.
    fn hold_in_frame(&mut self, i: usize, frame: &Mat3, dofs: Dofs) {
        if dofs.is_empty() {
            return;
        }
        let (basis, held) = self.frames.merged(i, self.fixed[i], frame, dofs);
        if held == Dofs::ALL {
            self.frames.set(i, basis, Dofs::NONE);
            self.fixed[i] = Dofs::ALL;
            at_rest_in(&mut self.velocity[i], &mut self.acceleration[i], Dofs::ALL);
            return;
        }
        self.fixed[i] = Dofs::NONE;
        self.frames.set(i, basis, held);
        let (v, a) = (&mut self.velocity[i], &mut self.acceleration[i]);
        *v = crate::step::frames::project_free(&basis, held, *v);
        *a = crate::step::frames::project_free(&basis, held, *a);
    }

    /// Zeroes the velocity and acceleration of every fixed direction: of the particles, of
    /// their rotations, and of the rigid bodies whose rotation is held; rigid bodies held at
    /// points are held where they are now ([`State::anchor_holds`]). [`State::fix`] does this
    /// when a direction is fixed; this does it again after motion was written from elsewhere
    /// (the checkpoint of another scene), so that every fixed direction starts at rest.
    ///
    /// ```
    /// use qdem_core::{step::Dofs, step::State, Vec3};
    ///
    /// let mut state = State::at_rest(vec![Vec3::zeros()]);
    /// state.fix(0, Dofs::parse("z").unwrap());
    /// state.velocity[0] = Vec3::new(1.0, 2.0, 3.0);
    /// state.hold_fixed();
    /// assert_eq!(state.velocity[0], Vec3::new(1.0, 2.0, 0.0));
    /// ```
    pub fn hold_fixed(&mut self) {
        all_at_rest_in(&mut self.velocity, &mut self.acceleration, &self.fixed);
        self.frames.hold(&mut self.velocity);
        self.frames.hold(&mut self.acceleration);
        let spin = &mut self.spin;
        all_at_rest_in(&mut spin.velocity, &mut spin.acceleration, &spin.fixed);
        for b in 0..self.rigid.len() {
            if self.rigid.spin_fixed[b] {
                self.rigid.set_angular_velocity(b, Vec3::zeros());
            }
        }
        if !self.rigid.holds.is_empty() {
            self.anchor_holds();
        }
    }

    /// Kinetic energy ½ Σ m v² + ½ Σ ω·L + ½ Σ J θ̇² (J): members of rigid bodies are massless, so a
    /// rigid body counts once, through its centre particle and its rotation.
    pub fn kinetic_energy(&self) -> f64 {
        self.mass
            .iter()
            .zip(&self.velocity)
            .map(|(m, v)| 0.5 * m * v.norm_squared())
            .sum::<f64>()
            + self.rigid.kinetic_energy()
            + self.spin.kinetic_energy()
    }

    /// Linear momentum Σ m v (kg m/s).
    pub fn momentum(&self) -> Vec3 {
        self.mass
            .iter()
            .zip(&self.velocity)
            .fold(Vec3::zeros(), |p, (m, v)| p + *m * v)
    }
}

/// [`at_rest_in`] for every entry of `velocity` and `acceleration` with its `fixed` directions.
fn all_at_rest_in(velocity: &mut [Vec3], acceleration: &mut [Vec3], fixed: &[Dofs]) {
    for ((v, a), &dofs) in velocity.iter_mut().zip(acceleration).zip(fixed) {
        at_rest_in(v, a, dofs);
    }
}

/// Zeroes `velocity` and `acceleration` in the directions `dofs`.
#[inline]
fn at_rest_in(velocity: &mut Vec3, acceleration: &mut Vec3, dofs: Dofs) {
    for axis in (0..3).filter(|&axis| dofs.contains(axis)) {
        velocity[axis] = 0.0;
        acceleration[axis] = 0.0;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn copying_the_motion_restores_everything_a_step_changes() {
        let mut saved = State::at_rest(vec![Vec3::zeros(), Vec3::x()]);
        saved.add_spin(vec![1.0, 1.0], Dofs::NONE);
        let mut state = saved.clone();
        state.time = 0.5;
        for (k, v) in [
            &mut state.position,
            &mut state.velocity,
            &mut state.acceleration,
        ]
        .into_iter()
        .chain([
            &mut state.spin.angle,
            &mut state.spin.velocity,
            &mut state.spin.acceleration,
        ])
        .enumerate()
        {
            v[1] = Vec3::repeat(k as f64 + 1.0);
        }
        state.copy_motion_from(&saved);
        assert_eq!(state, saved);
    }

    #[test]
    fn dofs_parse_accepts_subsets_and_rejects_bad_text() {
        assert_eq!(Dofs::parse("xyz"), Some(Dofs::ALL));
        let xz = Dofs::parse("zx").unwrap();
        assert!(xz.contains(0) && !xz.contains(1) && xz.contains(2));
        for bad in ["", "xx", "w", "x y"] {
            assert_eq!(Dofs::parse(bad), None, "{bad:?}");
        }
    }

    #[test]
    fn masks_and_text_agree() {
        assert_eq!(
            Dofs::from_mask([true, false, true]),
            Dofs::parse("xz").unwrap()
        );
        assert_eq!(Dofs::from_mask([true; 3]), Dofs::ALL);
        assert!(Dofs::from_mask([false; 3]).is_empty());
    }

    #[test]
    fn fixing_zeroes_only_the_fixed_directions() {
        let mut s = State::at_rest(vec![Vec3::zeros()]);
        s.velocity[0] = Vec3::new(1.0, 2.0, 3.0);
        s.fix(0, Dofs::parse("y").unwrap());
        assert_eq!(s.velocity[0], Vec3::new(1.0, 0.0, 3.0));
    }
}
