//! The linear Voigt contact of paper 000 §4: a normal spring k_n, a tangential spring k_t with a
//! Coulomb slider ([`crate::dem::laws::coulomb`]), and no dashpot by default (the viscosity of a QDEM body
//! is in its bulk, Eq. 7). An optional damping ratio ζ adds dashpots c = 2ζ√(k m*) in both
//! directions; a head-on impact then rebounds with restitution e = exp(−ζπ/√(1 − ζ²)), since
//! the force is not clipped at zero and contact ends when the overlap does.

use crate::dem::laws::contact_law::PairGeometry;
use crate::dem::laws::coulomb::tangential_force;
use qdem_core::Vec3;

/// Linear spring–dashpot with Coulomb friction.
#[derive(Clone, Debug, PartialEq)]
pub struct LinearSpring {
    /// Normal stiffness k_n (N/m).
    pub normal_stiffness: f64,
    /// Tangential stiffness k_t (N/m).
    pub tangential_stiffness: f64,
    /// Damping ratio ζ of both dashpots (0 for none).
    pub damping_ratio: f64,
}

impl LinearSpring {
    /// The force on a: −(k_n δ + c_n δ̇) n plus the tangential force.
    #[inline]
    pub fn force(&self, g: &PairGeometry, history: &mut Vec3, dt: f64) -> Vec3 {
        let rate = g.velocity.dot(&g.normal);
        let (c_n, c_t) = if self.damping_ratio > 0.0 {
            let scale = 2.0 * self.damping_ratio * g.mass.sqrt();
            (
                scale * self.normal_stiffness.sqrt(),
                scale * self.tangential_stiffness.sqrt(),
            )
        } else {
            (0.0, 0.0)
        };
        let normal = self.normal_stiffness * g.overlap + c_n * rate;
        let tangential = tangential_force(g, normal, self.tangential_stiffness, c_t, history, dt);
        tangential - normal * g.normal
    }

    /// ½ k_n δ² + ½ k_t |ξ|² (J).
    pub fn energy(&self, g: &PairGeometry, history: &Vec3) -> f64 {
        0.5 * self.normal_stiffness * g.overlap * g.overlap
            + 0.5 * self.tangential_stiffness * history.norm_squared()
    }
}
