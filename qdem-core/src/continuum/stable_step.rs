//! A rigorous explicit stable-step bound for QDEM tetrahedra with lumped mass.
//!
//! The largest eigenvalue of M⁻¹K is bounded by the largest element eigenvalue of
//! M_e⁻¹K_e, with M_e = (ρV/4) I the element's share of the lumped mass (the element eigenvalue
//! inequality). For the linear tetrahedron with shape-function gradients g_j (the 3×4 matrix G)
//! and displacements U (3×4), uᵀK_e u = V (2μ ε:ε + λ tr(ε)²) with ∇u = U Gᵀ, and
//! ε:ε ≤ |U Gᵀ|² ≤ |U|² λ_max(G Gᵀ), tr(ε)² ≤ |U|² |G|² (Cauchy–Schwarz), so
//!
//!   λ_max(K_e) ≤ V (2μ λ_max(G Gᵀ) + max(λ, 0) |G|²),
//!
//! which is attained by the dilatational mode of a regular tetrahedron. The same bound applies
//! to the viscous damping matrix with (λ_D, μ_D). With ω² and c the bounds of M⁻¹K and M⁻¹C,
//! central difference (Verlet with the damping force at the half-step velocity) is stable for
//!
//!   ∆t ≤ (2/ω)(√(1+ζ²) − ζ) = 2 / (√(ω² + c²/4) + c/2),  ζ = c/(2ω)
//!
//! (Belytschko, Liu & Moran, Box 6.1), which decreases in both ω and c, so upper bounds give a
//! safe step. The bound is exact mode by mode for stiffness-proportional viscosity; for other
//! viscosity ratios it takes the worst stiffness and the worst damping together.

use crate::continuum::material::Lame;
use crate::Mat3;

/// Upper bound of the largest eigenvalue of M_e⁻¹K_e of one tetrahedron (1/s²), given the
/// inverse reference edge matrix (whose rows are the gradients of N₁, N₂, N₃), the density and
/// a Lamé pair. With a viscous pair (Pa s) it bounds M_e⁻¹C_e (1/s) instead.
pub fn element_rate_bound(dm_inv: &Mat3, density: f64, lame: Lame) -> f64 {
    let rows = dm_inv.transpose();
    let (g1, g2, g3) = (rows.column(0), rows.column(1), rows.column(2));
    let g0 = -(g1 + g2 + g3);
    let ggt = g0 * g0.transpose() + g1 * g1.transpose() + g2 * g2.transpose() + g3 * g3.transpose();
    let largest = ggt
        .symmetric_eigenvalues()
        .iter()
        .fold(0.0f64, |a, &b| a.max(b));
    // λ_max(K_e)/(ρV/4): the volume cancels.
    4.0 * (2.0 * lame.mu.max(0.0) * largest + lame.lambda.max(0.0) * ggt.trace()) / density
}

/// Critical step 2/(√(ω² + c²/4) + c/2) for a bound ω² of M⁻¹K and c of M⁻¹C.
pub fn critical_step(omega_squared: f64, damping_rate: f64) -> f64 {
    2.0 / ((omega_squared + 0.25 * damping_rate * damping_rate).sqrt() + 0.5 * damping_rate)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn damping_shortens_the_step_as_the_closed_form_says() {
        let omega = 1000.0f64;
        let zeta = 0.3f64;
        let expected = 2.0 / omega * ((1.0 + zeta * zeta).sqrt() - zeta);
        let got = critical_step(omega * omega, 2.0 * zeta * omega);
        assert!((got / expected - 1.0).abs() < 1e-14);
        assert_eq!(critical_step(omega * omega, 0.0), 2.0 / omega);
    }
}
