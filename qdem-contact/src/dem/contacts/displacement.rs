//! The displacement check of the candidate lists in proportion to the bodies and free
//! spheres, not to every sphere.
//!
//! The lists are rebuilt when the largest displacement of a sphere since the last build,
//! max_s |x_s − x_s⁰|, outgrows the skin ([`DemContacts::outgrew_skin`]). Reading it exactly
//! takes one pass over every sphere's centre each step: on a ballast of rigid stones, 279,074
//! member spheres for 584 candidates. A sphere on a rigid body sits at x_s = c + R o_s (its
//! member's offset o_s turned by the body's orientation R from its centre c), so if at some
//! earlier step T (an *anchor*: a build, or a step whose check was exact) every sphere was
//! within M_T of its build position, then over the body's spheres
//!
//! |x_s − x_s⁰| ≤ M_T + |c − c_T| + |(R R_Tᵀ − I) R_T o_s| ≤ M_T + |c − c_T| + 2 sin(θ/2) ρ_T,
//!
//! with θ the angle of the rotation R R_Tᵀ since the anchor (2 sin(θ/2) = 2 |Im(q q_T⁻¹)| for
//! the unit quaternions q, q_T) and ρ_T the largest |x_s − c| of the body's spheres at the
//! anchor: one bound per body. The spheres on no rigid body (vertices of deformable bodies,
//! grains) are read exactly. Rounding makes the computed centres differ from the exact rigid
//! motion by a few units in the last place of |c| + ρ; the bound adds [`ROUNDING_MARGIN`] of
//! that, and of itself, which is many orders of magnitude more.
//!
//! The bound only decides whether the exact pass is needed: while it is below the skin's
//! limit the lists are kept, as the exact largest displacement (no larger) would keep them;
//! once it reaches the limit, the exact pass decides, as before, and its step becomes the
//! next anchor. So the lists are rebuilt at exactly the same steps as with the exact check,
//! and the outputs do not change. The anchor is not saved in a checkpoint: a resumed run
//! checks exactly once, then anchors there.

use super::*;
use nalgebra::UnitQuaternion;

/// The relative margin added to the displacement bound for rounding: the computed positions
/// and displacements differ from the exact rigid motion by about 10⁻¹⁵ relative.
pub(super) const ROUNDING_MARGIN: f64 = 1e-9;

/// The rigid bodies' poses at the anchor step, and the spheres on no rigid body.
#[derive(Clone, Debug, Default)]
pub(super) struct Anchor {
    /// M_T: no sphere was farther than this from its build position at the anchor (m).
    moved: f64,
    /// The rigid bodies that carry spheres, ascending.
    bodies: Vec<u32>,
    /// Per listed body: its centre c_T at the anchor.
    center: Vec<Vec3>,
    /// Per listed body: its orientation q_T at the anchor.
    orientation: Vec<UnitQuaternion<f64>>,
    /// Per listed body: the largest distance ρ_T of one of its spheres from its centre at
    /// the anchor.
    reach: Vec<f64>,
    /// The spheres on no rigid body, ascending.
    free: Vec<u32>,
}

impl DemContacts {
    /// Anchors the bound at `state`, where no sphere is farther than `moved` from its build
    /// position (0 right after a build). Without rigid bodies there is nothing to bound.
    pub(super) fn anchor(&mut self, state: &State, moved: f64) {
        self.candidates.set_anchor(None);
        if state.rigid.is_empty() || self.spheres.rigid().iter().all(|&r| r == NOT_RIGID) {
            return;
        }
        let mut reach = vec![None; state.rigid.len()];
        let mut free = Vec::new();
        for (s, &b) in self.spheres.rigid().iter().enumerate() {
            if b == NOT_RIGID {
                free.push(s as u32);
                continue;
            }
            let c = state.position[state.rigid.center[b as usize]];
            let arm = (state.position[self.spheres.particle()[s] as usize] - c).norm();
            let r: &mut Option<f64> = &mut reach[b as usize];
            *r = Some(r.map_or(arm, |r| r.max(arm)));
        }
        let mut anchor = Anchor {
            moved,
            free,
            ..Anchor::default()
        };
        for (b, r) in reach.iter().enumerate() {
            let Some(r) = *r else { continue };
            anchor.bodies.push(b as u32);
            anchor.center.push(state.position[state.rigid.center[b]]);
            anchor.orientation.push(state.rigid.orientation[b]);
            anchor.reach.push(r);
        }
        self.candidates.set_anchor(Some(anchor));
    }

    /// A bound, no smaller than the exact pass's value, on the largest displacement of a
    /// sphere since the last build (module doc); `None` without an anchor.
    pub(super) fn displacement_bound(&self, state: &State) -> Option<f64> {
        let anchor = self.candidates.anchor()?;
        let mut bound = 0.0f64;
        for (k, &b) in anchor.bodies.iter().enumerate() {
            let b = b as usize;
            let c = state.position[state.rigid.center[b]];
            let turn = state.rigid.orientation[b] * anchor.orientation[k].inverse();
            let (c_t, reach) = (anchor.center[k], anchor.reach[k]);
            let moved = anchor.moved + (c - c_t).norm() + 2.0 * turn.imag().norm() * reach;
            let scale = c.norm() + c_t.norm() + reach;
            bound = bound.max(moved + ROUNDING_MARGIN * (moved + scale));
        }
        let free = anchor.free.iter().map(|&s| {
            let s = s as usize;
            (state.position[self.spheres.particle()[s] as usize] - self.candidates.built_at()[s])
                .norm_squared()
        });
        Some(bound.max(free.fold(0.0, f64::max).sqrt()))
    }

    /// The largest distance a sphere has moved since the last build, read from every sphere
    /// (infinite before a build).
    pub(super) fn exact_displacement(&self, state: &State) -> f64 {
        let (particle, built_at) = (self.spheres.particle(), &self.candidates.built_at());
        if !self.lists_built() {
            return f64::INFINITY;
        }
        built_at
            .par_iter()
            .with_min_len(SPHERE_CHUNK)
            .enumerate()
            .map(|(s, at)| (state.position[particle[s] as usize] - at).norm_squared())
            .reduce(|| 0.0, f64::max)
            .sqrt()
    }

    /// The largest displacement since the last build when the lists are read by their
    /// partners only, or a bound on it when that bound already keeps the lists: either way,
    /// [`DemContacts::outgrew_skin`] decides as it would on the exact value. A step that
    /// checks exactly and keeps the lists becomes the anchor.
    pub(super) fn displacement(&mut self, state: &State) -> f64 {
        if let Some(bound) = self.displacement_bound(state) {
            if !self.outgrew_skin(bound, state.time) {
                return bound;
            }
        }
        let moved = self.exact_displacement(state);
        if !self.outgrew_skin(moved, state.time) {
            self.anchor(state, moved);
        }
        moved
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::dem::laws::linear_spring::LinearSpring;
    use qdem_core::Mat3;

    /// Two rigid bodies of eight corner members each (a 0.1 m cube), one at the origin and
    /// one at x = 1 m, and a free particle at x = −1 m, with a sphere on every member and
    /// on the free particle: no pair is a candidate, so the check runs on the bound.
    fn bodies_and_a_grain() -> (State, DemContacts) {
        let corners: Vec<Vec3> = (0..8)
            .map(|i| 0.05 * Vec3::new(sign(i & 1), sign(i & 2), sign(i & 4)))
            .collect();
        let mut points = vec![Vec3::zeros()];
        points.extend(corners.iter().copied());
        points.push(Vec3::x());
        points.extend(corners.iter().map(|c| c + Vec3::x()));
        points.push(-Vec3::x());
        let mut state = State::at_rest(points);
        state.mass = vec![1.0; state.len()];
        let inertia = Mat3::from_diagonal(&Vec3::new(1e-3, 2e-3, 3e-3));
        let a: Vec<usize> = (1..9).collect();
        let b: Vec<usize> = (10..18).collect();
        state.add_rigid_body("a", 0, &a, inertia).unwrap();
        state.add_rigid_body("b", 9, &b, inertia).unwrap();
        let sphere = |particle, body| ContactSphere {
            particle,
            radius: 0.01,
            body,
            material: 0,
        };
        let mut spheres: Vec<ContactSphere> = a.iter().map(|&p| sphere(p, 0)).collect();
        spheres.extend(b.iter().map(|&p| sphere(p, 1)));
        spheres.push(sphere(18, 2));
        let settings = ContactSettings {
            law: ContactLaw::Linear(LinearSpring {
                normal_stiffness: 1e5,
                tangential_stiffness: 1e5,
                damping_ratio: 0.0,
            }),
            friction: 0.5,
            skin: 0.002,
        };
        let names = ["a", "b", "grain"].map(String::from).to_vec();
        let contacts = DemContacts::new(&state, &spheres, names, &[(1e9, 0.25)], settings, vec![]);
        (state, contacts)
    }

    fn sign(bit: usize) -> f64 {
        if bit == 0 {
            -1.0
        } else {
            1.0
        }
    }

    #[test]
    fn a_turning_body_rebuilds_the_lists_when_a_member_sphere_crosses_half_the_skin() {
        // Body a turns (its corners move up to 2 sin(θ/2) |arm|), body b drifts, the grain
        // jitters; the lists must be rebuilt exactly at the steps where the largest
        // displacement of a sphere since the last build reaches half the skin, read here
        // from every sphere, while the check itself runs on the bodies' bound.
        let (mut state, mut contacts) = bodies_and_a_grain();
        let n = state.len();
        let (mut force, mut torque) = (vec![Vec3::zeros(); n], vec![Vec3::zeros(); n + 2]);
        let sphere_particles = contacts.spheres.particle().to_vec();
        let positions = |state: &State| -> Vec<Vec3> {
            sphere_particles
                .iter()
                .map(|&p| state.position[p as usize])
                .collect()
        };
        contacts.add_forces(&state, &mut force, &mut torque);
        let (mut built, mut expected, mut on_bound) = (positions(&state), 1, 0);
        let dt = 1e-3;
        for step in 0..600 {
            let k = step as f64;
            let spin = Vec3::new(0.3, 0.2 * (0.01 * k).cos(), 1.0 + 0.5 * (0.03 * k).sin());
            state.rigid.set_angular_velocity(0, spin);
            state.rigid.rotate(dt);
            state.position[9].y += 3e-5 * (0.02 * k).cos();
            state.position[18].z = -1e-4 * (0.05 * k).sin();
            qdem_core::step::rigid_body::place_members(&mut state);
            state.time += dt;
            let exact = positions(&state)
                .iter()
                .zip(&built)
                .map(|(x, b)| (x - b).norm())
                .fold(0.0, f64::max);
            if let Some(bound) = contacts.displacement_bound(&state) {
                assert!(bound >= exact, "step {step}: bound {bound} < {exact}");
                on_bound += (2.0 * bound < contacts.settings.skin) as usize;
            }
            contacts.add_forces(&state, &mut force, &mut torque);
            if 2.0 * exact >= contacts.settings.skin {
                expected += 1;
                built = positions(&state);
            }
            assert_eq!(contacts.rebuilds(), expected, "step {step}");
        }
        assert!(expected > 20, "{expected} rebuilds");
        assert!(
            on_bound > 300,
            "the bound kept the lists on {on_bound} of 600 steps"
        );
    }

    #[test]
    fn a_wrapped_body_is_beyond_any_bound() {
        // A body moved by a whole period (as the periodic wrap moves it) outgrows the skin.
        let (mut state, mut contacts) = bodies_and_a_grain();
        let n = state.len();
        let (mut force, mut torque) = (vec![Vec3::zeros(); n], vec![Vec3::zeros(); n + 2]);
        contacts.add_forces(&state, &mut force, &mut torque);
        state.time += 1e-3;
        contacts.add_forces(&state, &mut force, &mut torque);
        assert_eq!(contacts.rebuilds(), 1);
        assert!(contacts.displacement_bound(&state).is_some());
        state.position[0].y += 0.6;
        qdem_core::step::rigid_body::place_members(&mut state);
        state.time += 1e-3;
        contacts.add_forces(&state, &mut force, &mut torque);
        assert_eq!(contacts.rebuilds(), 2);
    }
}
