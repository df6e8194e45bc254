//! The initial motion of a scene's bodies and stones: `velocity` and `angular_velocity`.
//!
//! A rigid motion about the centre of mass x_c: every particle of a deformable body (or of one
//! `[ballast]` stone) gets v_i = v + ω × (x_i − x_c), x_c the mean of its particles weighted by
//! their lumped masses; a rigid body (a `[[body]]` with `rigid = true`, a `[granular]` clump)
//! gets v at its centre and ω as its angular velocity, its members following
//! ([`qdem_core::step::rigid_body::place_members`]); a one-sphere stone gets v and the spin ω.

use qdem_core::{step::State, Vec3};
use std::ops::Range;

/// The particles of `part` (a deformable body or stone) moving rigidly with `velocity` and the
/// angular velocity `omega` about their centre of mass. Without `omega` every particle gets
/// `velocity` exactly.
pub(crate) fn move_rigidly(state: &mut State, part: Range<usize>, velocity: Vec3, omega: Vec3) {
    if omega == Vec3::zeros() {
        state.velocity[part].fill(velocity);
        return;
    }
    let mass: f64 = state.mass[part.clone()].iter().sum();
    let center = part
        .clone()
        .map(|i| state.position[i] * state.mass[i])
        .sum::<Vec3>()
        / mass;
    for i in part {
        state.velocity[i] = velocity + omega.cross(&(state.position[i] - center));
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_spinning_part_keeps_its_momentum_and_has_angular_momentum_j_omega() {
        // Four equal masses on a square of side 2 about (1, 1, 0) spun about z: the momentum
        // stays m_total v and the angular momentum about the centre is Σ m r² ω = 4·2·ω.
        let mut state = State::at_rest(vec![
            Vec3::new(0.0, 0.0, 0.0),
            Vec3::new(2.0, 0.0, 0.0),
            Vec3::new(2.0, 2.0, 0.0),
            Vec3::new(0.0, 2.0, 0.0),
        ]);
        state.mass.fill(1.0);
        let (v, w) = (Vec3::new(0.5, 0.0, -1.0), Vec3::new(0.0, 0.0, 3.0));
        move_rigidly(&mut state, 0..4, v, w);
        assert!((state.momentum() - 4.0 * v).norm() < 1e-15);
        let c = Vec3::new(1.0, 1.0, 0.0);
        let l: Vec3 = (0..4)
            .map(|i| (state.position[i] - c).cross(&(state.velocity[i] - v)))
            .sum();
        assert!((l - Vec3::new(0.0, 0.0, 8.0 * 3.0)).norm() < 1e-14, "{l}");
    }
}
