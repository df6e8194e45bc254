//! Local non-viscous damping, as in PFC (paper 003 §3: "a non-viscous damping force reducing
//! the acceleration of the particles by 70%"): every component of the unbalanced force on a
//! particle is reduced by a fraction α of its magnitude against that component of the velocity,
//! f_k ← f_k − α |f_k| sgn(v_k), and likewise the torque on a rigid body against its angular
//! velocity and the moment on a rotating particle against its rate. It dissipates energy without a viscosity scale, for quasi-static packing; it is
//! not physical damping and is off unless a scene asks for it.

use crate::step::state::State;
use crate::Vec3;

/// Applies local damping with fraction `alpha` (0 ≤ α < 1) to the forces and torques of one
/// evaluation, against the velocities the forces were evaluated with.
pub fn apply(state: &State, force: &mut [Vec3], torque: &mut [Vec3], alpha: f64) {
    for (f, v) in force.iter_mut().zip(&state.velocity) {
        damp(f, v, alpha);
    }
    let (rigid, particles) = torque.split_at_mut(state.rigid.len().min(torque.len()));
    for (t, w) in rigid.iter_mut().zip(&state.rigid.angular_velocity) {
        damp(t, w, alpha);
    }
    for (t, w) in particles.iter_mut().zip(&state.spin.velocity) {
        damp(t, w, alpha);
    }
}

/// f_k ← f_k − α |f_k| sgn(v_k) for each component k.
#[inline]
pub(crate) fn damp(f: &mut Vec3, v: &Vec3, alpha: f64) {
    for k in 0..3 {
        let sign = if v[k] > 0.0 {
            1.0
        } else if v[k] < 0.0 {
            -1.0
        } else {
            0.0
        };
        f[k] -= alpha * f[k].abs() * sign;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn opposes_motion_by_the_fraction_and_leaves_rest_alone() {
        let mut s = State::at_rest(vec![Vec3::zeros(); 2]);
        s.velocity[0] = Vec3::new(1.0, -1.0, 0.0);
        let mut force = vec![Vec3::new(10.0, 10.0, 10.0), Vec3::new(-4.0, 0.0, 0.0)];
        apply(&s, &mut force, &mut [], 0.7);
        assert_eq!(force[0], Vec3::new(3.0, 17.0, 10.0));
        assert_eq!(force[1], Vec3::new(-4.0, 0.0, 0.0));
    }
}
