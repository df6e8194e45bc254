//! The tangential spring with a Coulomb slider shared by both contact laws (paper 000 §4: "the
//! Voigt model with a frictional slider"; paper 003 §3: the Mohr–Coulomb limit).
//!
//! The spring elongation ξ is kept per contact. Each step it is first carried into the current
//! tangent plane (its normal component removed, its length kept), then grows by the tangential
//! relative displacement v_t ∆t. The trial force is F_t = −k_t ξ − c_t v_t; if |F_t| exceeds
//! μ F_n (F_n ≥ 0 the normal force), the contact slides: F_t is scaled back to μ F_n and ξ is
//! reset so that the spring alone carries that force, ξ = −F_t/k_t.
//!
//! The cap holds spring and dashpot together (|F_t| ≤ μ F_n⁺, Coulomb's law for the whole
//! tangential force), where LIGGGHTS 3.8 caps the spring only and adds the dashpot beyond the
//! limit. The reset leaves the dashpot out of the spring: LIGGGHTS's ξ = −(F_t + c_t v_t)/k_t,
//! with a dashpot c_t |v_t| above μ F_n (a fast slide at first contact, while F_n is small),
//! turns the spring against the slip, so the next trial force falls below the limit and the
//! sliding contact sticks for a few steps (F_t/F_n 0.125 for μ = 0.5). With ξ = −F_t/k_t the
//! next trial force is the last sliding force plus k_t v_t ∆t + c_t v_t along the slip, so a
//! contact that keeps sliding stays at μ F_n⁺ at every step.

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
        -sliding / stiffness
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
    fn a_sliding_impact_keeps_the_coulomb_force_at_every_step() {
        // Hertz–Mindlin, E = 50 MPa and ν = 0.25 on a rigid plane, a sphere of d = 10 mm and
        // 1.36 g with restitution 0.5 (ζ = 0.2155), sliding at 3.5 m/s throughout while it
        // approaches at 1 m/s: Coulomb's law gives |F_t| = μ F_n at every step with F_n > 0.
        // Before the reset left the dashpot out of the spring, the second step read
        // F_t/F_n = 0.017.
        let law = crate::dem::laws::hertz_mindlin::HertzMindlin {
            damping_ratio: 0.2155,
        };
        let e = crate::dem::laws::contact_law::PairElasticity::new((50e6, 0.25), None);
        let (dt, mu) = (1e-7, 0.5);
        let mut xi = Vec3::zeros();
        let mut sliding_steps = 0;
        for k in 1..=400 {
            let g = PairGeometry {
                overlap: 1.0 * k as f64 * dt,
                normal: -Vec3::z(),
                velocity: Vec3::new(3.5, 0.0, -1.0),
                radius: 0.005,
                mass: 1.36e-3,
                friction: mu,
            };
            let f = law.force(&g, &e, &mut xi, dt);
            let (f_n, f_t) = (f.z, f.xy().norm());
            if f_n > 0.0 {
                assert!(
                    (f_t - mu * f_n).abs() <= 1e-12 * f_n,
                    "step {k}: {}",
                    f_t / f_n
                );
                sliding_steps += 1;
            }
        }
        assert_eq!(sliding_steps, 400);
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
