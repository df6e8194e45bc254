//! Rolling resistance: the elastic–plastic spring torque of Ai, Chen, Rotter & Ooi (2011),
//! "Assessment of rolling resistance models in discrete element simulations", Powder
//! Technology 206, 269–282, model C (the "elastic–plastic spring–dashpot" model, Iwashita &
//! Oda 1998), without its dashpot, as LIGGGHTS 3.8 `rolling_friction epsd2` has it.
//!
//! Per contact a rolling spring torque M_r is kept. Each step it grows with the relative
//! rolling rotation (Ai et al. Eq. 15, incrementally):
//!
//! M_r ← M_r + k_r ω_r,t ∆t,  ω_r,t = ω_r − n (n · ω_r),  ω_r = ω_a − ω_b (ω_b = 0 for a wall),
//!
//! with the rolling stiffness of `epsd2`, k_r = k_t R*² (k_t the contact's tangential stiffness
//! at this step, R* the reduced radius; Ai et al. Eq. 16 uses 2.25 k_n μ_r² R*², LIGGGHTS's
//! `epsd`), and is capped at the full mobilisation torque (Ai et al. Eq. 17)
//!
//! |M_r| ≤ M_m = μ_r R* F_n⁺,
//!
//! scaled back to M_m (its direction kept) when the trial exceeds it. Sphere a feels −M_r and
//! sphere b +M_r, so the pair adds no moment about the contact. Once the spring is at its cap
//! the torque is model A's constant μ_r R* F_n against the relative rolling (Ai et al. Eq. 4);
//! below it the spring holds a sphere at rest without the chatter of model A.
//!
//! Where this differs from LIGGGHTS `epsd2`: the kept torque is first carried into the current
//! tangent plane (its normal component removed, its length kept), as the tangential spring is
//! ([`crate::dem::laws::coulomb`]), so a contact whose normal turns keeps a rolling torque
//! and gains no twisting one; LIGGGHTS leaves the history in its old plane. The cap reads F_n⁺
//! (the normal force, zero when it pulls), LIGGGHTS |F_n|.

use qdem_core::Vec3;

/// The rolling resistance of a contact (`[contact] rolling_friction`).
///
/// ```
/// use qdem_contact::RollingResistance;
/// use qdem_core::Vec3;
///
/// // A sphere of R* = 0.01 m rolling about y on a floor (n = −z from the sphere into it),
/// // pressed with 10 N: the torque caps at μ_r R* F_n = 0.1 · 0.01 · 10 = 0.01 N m.
/// let rolling = RollingResistance { coefficient: 0.1 };
/// let mut spring = Vec3::zeros();
/// let (normal, spin) = (-Vec3::z(), Vec3::new(0.0, 5.0, 0.0));
/// for _ in 0..1000 {
///     rolling.update(&normal, 0.01, &spin, 10.0, 1e5, &mut spring, 1e-4);
/// }
/// assert!((spring - Vec3::new(0.0, 0.01, 0.0)).norm() < 1e-15);
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RollingResistance {
    /// The coefficient of rolling friction μ_r (dimensionless, ≥ 0).
    pub coefficient: f64,
}

impl RollingResistance {
    /// Updates the rolling spring torque `spring` (M_r, as it acts against sphere a: a feels
    /// −M_r, b +M_r) of a contact with unit normal `normal`, reduced radius `radius`, relative
    /// angular velocity `spin` = ω_a − ω_b, normal force `normal_force` (compressive positive)
    /// and tangential stiffness `tangential_stiffness`, over a step `dt` (module doc).
    #[inline]
    #[allow(clippy::too_many_arguments)]
    pub fn update(
        &self,
        normal: &Vec3,
        radius: f64,
        spin: &Vec3,
        normal_force: f64,
        tangential_stiffness: f64,
        spring: &mut Vec3,
        dt: f64,
    ) {
        let length_squared = spring.norm_squared();
        if length_squared > 0.0 {
            let projected = *spring - normal * normal.dot(spring);
            let projected_squared = projected.norm_squared();
            *spring = match projected_squared > 0.0 {
                true => projected * (length_squared / projected_squared).sqrt(),
                false => Vec3::zeros(),
            };
        }
        let rolling = spin - normal * normal.dot(spin);
        *spring += (tangential_stiffness * radius * radius * dt) * rolling;
        let limit = self.coefficient * radius * normal_force.max(0.0);
        let magnitude_squared = spring.norm_squared();
        if magnitude_squared > limit * limit {
            *spring *= limit / magnitude_squared.sqrt();
        }
    }

    /// The rolling stiffness k_r = k_t R*² (N m/rad) of a contact of tangential stiffness
    /// `tangential_stiffness` and reduced radius `radius`.
    pub fn stiffness(tangential_stiffness: f64, radius: f64) -> f64 {
        tangential_stiffness * radius * radius
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_spring_grows_with_the_rolling_rotation_alone_and_caps_at_mu_r_r_fn() {
        // k_t = 1e4 N/m, R* = 0.02 m: k_r = 4 N m/rad. A relative spin of 2 rad/s about x
        // plus a twist of 3 rad/s about the normal z, for 1 ms: M_r = 4 · 2 · 1e-3 = 8e-3 N m
        // about x; the twist adds nothing. The cap μ_r R* F_n = 0.5 · 0.02 · 1 = 0.01 N m is
        // reached after 1.25 ms and held, along the rolling.
        let rolling = RollingResistance { coefficient: 0.5 };
        let (n, spin) = (Vec3::z(), Vec3::new(2.0, 0.0, 3.0));
        let mut m = Vec3::zeros();
        for _ in 0..10 {
            rolling.update(&n, 0.02, &spin, 1.0, 1e4, &mut m, 1e-4);
        }
        assert!((m - Vec3::new(8e-3, 0.0, 0.0)).norm() < 1e-15, "{m:?}");
        for _ in 0..10 {
            rolling.update(&n, 0.02, &spin, 1.0, 1e4, &mut m, 1e-4);
        }
        assert!((m - Vec3::new(0.01, 0.0, 0.0)).norm() < 1e-15, "{m:?}");
        // Rolling back unloads the spring elastically from the cap.
        rolling.update(&n, 0.02, &-spin, 1.0, 1e4, &mut m, 1e-4);
        assert!(
            (m - Vec3::new(0.01 - 8e-4, 0.0, 0.0)).norm() < 1e-15,
            "{m:?}"
        );
        // A contact that pulls (F_n < 0) carries no rolling torque.
        rolling.update(&n, 0.02, &spin, -1.0, 1e4, &mut m, 1e-4);
        assert_eq!(m, Vec3::zeros());
    }

    #[test]
    fn the_spring_turns_with_the_normal_and_keeps_its_length() {
        let rolling = RollingResistance { coefficient: 1.0 };
        let mut m = Vec3::new(0.3, 0.0, 0.0);
        let n = Vec3::new(0.6, 0.0, 0.8);
        rolling.update(&n, 1.0, &Vec3::zeros(), 1.0, 1.0, &mut m, 1e-3);
        assert!(m.dot(&n).abs() < 1e-15);
        assert!((m.norm() - 0.3).abs() < 1e-15);
    }
}
