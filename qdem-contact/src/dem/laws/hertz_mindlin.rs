//! Hertz–Mindlin contact with a Mohr–Coulomb limit, the law of PFC3D in paper 003 §3, with
//! LIGGGHTS's stiffnesses and damping (`model hertz tangential history`), from each side's E
//! and ν:
//!
//! - normal: F_n = (4/3) E* √R* δ^{3/2} + γ_n δ̇, with S_n = 2E*√(R*δ) the tangent stiffness;
//! - tangential: spring k_t = S_t = 8G*√(R*δ) on the elongation ξ, F_t = −k_t ξ − γ_t v_t,
//!   spring and dashpot together limited by μ F_n⁺ ([`crate::dem::laws::coulomb`]; LIGGGHTS caps the
//!   spring alone);
//! - optional damping γ = 2√(5/6) ζ √(S m*), which is LIGGGHTS's −2√(5/6) β √(S m*) with its
//!   β = ln e/√(ln² e + π²) = −ζ.

use crate::dem::laws::contact_law::{PairElasticity, PairGeometry};
use crate::dem::laws::coulomb::tangential_force;
use qdem_core::Vec3;

/// Hertz–Mindlin with Coulomb friction.
#[derive(Clone, Debug, PartialEq)]
pub struct HertzMindlin {
    /// Damping ratio ζ (0 for none).
    pub damping_ratio: f64,
}

/// 2√(5/6), the damping prefactor of LIGGGHTS's Hertz model.
pub(crate) const DAMPING_PREFACTOR: f64 = 1.825_741_858_350_553_8;

impl HertzMindlin {
    /// Tangent stiffnesses (S_n, S_t) = (2E*√(R*δ), 8G*√(R*δ)) (N/m).
    #[inline]
    pub fn stiffness(overlap: f64, radius: f64, e: &PairElasticity) -> (f64, f64) {
        let contact_radius = (radius * overlap.max(0.0)).sqrt();
        (
            2.0 * e.e_star * contact_radius,
            8.0 * e.g_star * contact_radius,
        )
    }

    /// The force on a.
    #[inline(always)]
    pub fn force(&self, g: &PairGeometry, e: &PairElasticity, history: &mut Vec3, dt: f64) -> Vec3 {
        let (s_n, s_t) = Self::stiffness(g.overlap, g.radius, e);
        let (gamma_n, gamma_t) = if self.damping_ratio > 0.0 {
            let scale = DAMPING_PREFACTOR * self.damping_ratio * g.mass.sqrt();
            (scale * s_n.sqrt(), scale * s_t.sqrt())
        } else {
            (0.0, 0.0)
        };
        let rate = g.velocity.dot(&g.normal);
        let normal = (2.0 / 3.0) * s_n * g.overlap + gamma_n * rate;
        let tangential = tangential_force(g, normal, s_t, gamma_t, history, dt);
        tangential - normal * g.normal
    }

    /// (8/15) E* √R* δ^{5/2} + ½ k_t |ξ|² (J).
    pub fn energy(&self, g: &PairGeometry, e: &PairElasticity, history: &Vec3) -> f64 {
        let (s_n, s_t) = Self::stiffness(g.overlap, g.radius, e);
        (4.0 / 15.0) * s_n * g.overlap * g.overlap + 0.5 * s_t * history.norm_squared()
    }
}
