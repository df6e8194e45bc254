//! The tangential spring with a Coulomb slider shared by both contact laws (paper 000 §4: "the
//! Voigt model with a frictional slider"; paper 003 §3: the Mohr–Coulomb limit).
//!
//! The spring elongation ξ is kept per contact. Each step it is first carried into the current
//! tangent plane (its normal component removed, its length kept), then grows by the tangential
//! relative displacement v_t ∆t. The trial force is F_t = −k_t ξ − c_t v_t; if |F_t| exceeds
//! μ F_n (F_n ≥ 0 the normal force), the contact slides: F_t is scaled back to μ F_n and ξ is
//! reset to the elongation that gives that force, ξ = −(F_t + c_t v_t)/k_t, as LIGGGHTS does.

use crate::dem::laws::contact_law::PairGeometry;
use qdem_core::Vec3;

/// The tangential force on a for the contact `g` with normal force `normal_force`, spring
/// `stiffness` and dashpot `damping`, and the updated spring elongation `history`.
#[inline(always)]
pub fn tangential_force(
    g: &PairGeometry,
    normal_force: f64,
    stiffness: f64,
    damping: f64,
    history: &mut Vec3,
    dt: f64,
) -> Vec3 {
    let (normal, velocity, friction) = (&g.normal, &g.velocity, g.friction);
    let v_t = velocity - normal * normal.dot(velocity);
    let length_squared = history.norm_squared();
    if length_squared > 0.0 {
        let projected = *history - normal * normal.dot(history);
        let projected_squared = projected.norm_squared();
        *history = if projected_squared > 0.0 {
            projected * (length_squared / projected_squared).sqrt()
        } else {
            Vec3::zeros()
        };
    }
    *history += v_t * dt;
    let trial = -stiffness * *history - damping * v_t;
    let limit = friction * normal_force.max(0.0);
    let magnitude_squared = trial.norm_squared();
    if magnitude_squared <= limit * limit {
        return trial;
    }
    let sliding = trial * (limit / magnitude_squared.sqrt());
    *history = if stiffness > 0.0 {
        -(sliding + damping * v_t) / stiffness
    } else {
        Vec3::zeros()
    };
    sliding
}

#[cfg(test)]
mod tests {
    use super::*;

    fn contact(normal: Vec3, velocity: Vec3, friction: f64) -> PairGeometry {
        PairGeometry {
            overlap: 1e-3,
            normal,
            velocity,
            radius: 1.0,
            mass: 1.0,
            friction,
        }
    }

    #[test]
    fn sticks_below_the_limit_and_slides_at_it() {
        let g = contact(Vec3::z(), Vec3::new(1.0, 0.0, 0.5), 0.5);
        let mut xi = Vec3::zeros();
        let f = tangential_force(&g, 100.0, 1e3, 0.0, &mut xi, 0.01);
        assert!((f - Vec3::new(-10.0, 0.0, 0.0)).norm() < 1e-12);
        for _ in 0..10 {
            tangential_force(&g, 100.0, 1e3, 0.0, &mut xi, 0.01);
        }
        let f = tangential_force(&g, 100.0, 1e3, 0.0, &mut xi, 0.01);
        assert!((f.norm() - 50.0).abs() < 1e-12);
        assert!((xi.norm() - 0.05).abs() < 1e-15);
    }

    #[test]
    fn the_spring_turns_with_the_normal_and_keeps_its_length() {
        let mut xi = Vec3::new(0.0, 0.0, 0.0);
        tangential_force(
            &contact(Vec3::z(), Vec3::x(), 10.0),
            1.0,
            1.0,
            0.0,
            &mut xi,
            0.1,
        );
        let n = Vec3::new(0.6, 0.0, 0.8);
        tangential_force(
            &contact(n, Vec3::zeros(), 10.0),
            1.0,
            1.0,
            0.0,
            &mut xi,
            0.1,
        );
        assert!(xi.dot(&n).abs() < 1e-15);
        assert!((xi.norm() - 0.1).abs() < 1e-15);
    }
}
