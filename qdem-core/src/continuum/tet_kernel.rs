//! The QDEM tetrahedron kernel (paper 000 Eqs. 1–11): from the four particle positions and
//! velocities of a tetrahedron to the Kelvin–Voigt Cauchy stress and the force on each particle.
//!
//! - Eq. 1: F = dx · dX⁻¹, with dX, dx the matrices of the three edge vectors from vertex 0.
//! - Eqs. 2–4: B = F Fᵀ, ε = (B − I)/2, T_E = λ_E tr(ε) I + 2 μ_E ε.
//! - Eqs. 5–7: L = dv · dx⁻¹, D = sym L, T_D = λ_D tr(D) I + 2 μ_D D.
//! - Eq. 8: T = T_E + T_D.
//! - Eqs. 9–11: the force on each particle is the traction of T summed over the interface
//!   triangles of its subdomain. For a homogeneous T this sum has a closed form: particle j
//!   receives T · A_j / 3, with A_j the current outward area vector of the face opposite j
//!   (the subdomain's internal interfaces close the surface whose outer part is one third of
//!   each face that touches j). With the edge matrix dx = [d₁ d₂ d₃] the area vectors are
//!   A₁ = −½ d₂×d₃, A₂ = −½ d₃×d₁, A₃ = −½ d₁×d₂, A₀ = −(A₁+A₂+A₃), i.e. the columns of
//!   −½ cof(dx). The literal 12-triangle construction lives in [`crate::continuum::tet_subdomain`] as the
//!   test oracle; this closed form runs in the hot loop.

use crate::{Mat3, Vec3};

/// Edge matrix [x₁−x₀, x₂−x₀, x₃−x₀] of a tetrahedron (columns).
#[inline(always)]
pub fn edge_matrix(x: &[Vec3; 4]) -> Mat3 {
    Mat3::from_columns(&[x[1] - x[0], x[2] - x[0], x[3] - x[0]])
}

/// Deformation gradient F = dx · dX⁻¹ of Eq. 1, from the current positions and the inverse of
/// the reference edge matrix.
#[inline(always)]
pub fn deformation_gradient(x: &[Vec3; 4], dm_inv: &Mat3) -> Mat3 {
    edge_matrix(x) * dm_inv
}

/// Elastic Cauchy stress of Eq. 2 with the left Green–Lagrange strain ε = (F Fᵀ − I)/2 (Eq. 4).
#[inline(always)]
pub fn elastic_stress(f: &Mat3, lambda: f64, mu: f64) -> Mat3 {
    let eps = (f * f.transpose() - Mat3::identity()) * 0.5;
    Mat3::from_diagonal_element(lambda * eps.trace()) + eps * (2.0 * mu)
}

/// Viscous Cauchy stress of Eq. 7 from the velocity gradient L (Eq. 5), using D = sym L (Eq. 6).
#[inline(always)]
pub fn viscous_stress(l: &Mat3, lambda_d: f64, mu_d: f64) -> Mat3 {
    let d = (l + l.transpose()) * 0.5;
    Mat3::from_diagonal_element(lambda_d * d.trace()) + d * (2.0 * mu_d)
}

/// Cofactor matrix of an edge matrix, cof(dx) = [d₂×d₃, d₃×d₁, d₁×d₂] (columns);
/// cof(dx) = det(dx) · dx⁻ᵀ.
#[inline(always)]
pub fn cofactor(dx: &Mat3) -> Mat3 {
    let (d1, d2, d3) = (dx.column(0), dx.column(1), dx.column(2));
    Mat3::from_columns(&[d2.cross(&d3), d3.cross(&d1), d1.cross(&d2)])
}

/// Velocity gradient L = dv · dx⁻¹ of Eq. 5, from the velocity differences and the cofactor
/// matrix and determinant of the current edge matrix.
#[inline(always)]
pub fn velocity_gradient(v: &[Vec3; 4], cof: &Mat3, det: f64) -> Mat3 {
    edge_matrix(v) * cof.transpose() / det
}

/// Closed form of Eqs. 9–10: the force on each particle, T · A_j / 3, given the cofactor of
/// the current edge matrix (so that A = −½ cof). The four forces sum to zero.
#[inline(always)]
pub fn vertex_forces(t: &Mat3, cof: &Mat3) -> [Vec3; 4] {
    let f = t * cof * (-1.0 / 6.0);
    let f1: Vec3 = f.column(0).into();
    let f2: Vec3 = f.column(1).into();
    let f3: Vec3 = f.column(2).into();
    [-(f1 + f2 + f3), f1, f2, f3]
}

/// Stress and forces of one tetrahedron from its current positions (and velocities when the
/// material is viscous).
#[inline(always)]
pub fn tet_stress(
    x: &[Vec3; 4],
    v: Option<&[Vec3; 4]>,
    dm_inv: &Mat3,
    elastic: (f64, f64),
    viscous: (f64, f64),
) -> (Mat3, Mat3) {
    let dx = edge_matrix(x);
    let f = dx * dm_inv;
    let mut t = elastic_stress(&f, elastic.0, elastic.1);
    let cof = cofactor(&dx);
    if let Some(v) = v {
        let det = dx.column(0).dot(&cof.column(0));
        t += viscous_stress(&velocity_gradient(v, &cof, det), viscous.0, viscous.1);
    }
    (t, cof)
}

/// A symmetric 3×3 tensor by its six components, for the hot loop.
#[derive(Clone, Copy, Debug)]
struct Sym3 {
    xx: f64,
    yy: f64,
    zz: f64,
    xy: f64,
    yz: f64,
    xz: f64,
}

impl Sym3 {
    fn trace(&self) -> f64 {
        self.xx + self.yy + self.zz
    }

    /// The isotropic law of Eqs. 2 and 7: λ tr(e) I + 2μ e.
    fn lame(&self, lambda: f64, mu: f64) -> Sym3 {
        let (p, two_mu) = (lambda * self.trace(), 2.0 * mu);
        Sym3 {
            xx: p + two_mu * self.xx,
            yy: p + two_mu * self.yy,
            zz: p + two_mu * self.zz,
            xy: two_mu * self.xy,
            yz: two_mu * self.yz,
            xz: two_mu * self.xz,
        }
    }

    fn add(&self, o: &Sym3) -> Sym3 {
        Sym3 {
            xx: self.xx + o.xx,
            yy: self.yy + o.yy,
            zz: self.zz + o.zz,
            xy: self.xy + o.xy,
            yz: self.yz + o.yz,
            xz: self.xz + o.xz,
        }
    }

    fn mul(&self, a: &Vec3) -> Vec3 {
        Vec3::new(
            self.xx * a.x + self.xy * a.y + self.xz * a.z,
            self.xy * a.x + self.yy * a.y + self.yz * a.z,
            self.xz * a.x + self.yz * a.y + self.zz * a.z,
        )
    }
}

/// The strain ε = (F Fᵀ − I)/2 of Eq. 4 from the edge vectors d and dX⁻¹ (F = [d₁ d₂ d₃] dX⁻¹).
#[inline(always)]
fn green_strain(d: &[Vec3; 3], dm_inv: &Mat3) -> Sym3 {
    // Row r of F is Σ_k d_k[r] · (row k of dX⁻¹).
    let row = |r: usize| -> Vec3 {
        (0..3).fold(Vec3::zeros(), |acc, k| {
            acc + dm_inv.row(k).transpose() * d[k][r]
        })
    };
    let (f0, f1, f2) = (row(0), row(1), row(2));
    Sym3 {
        xx: 0.5 * (f0.dot(&f0) - 1.0),
        yy: 0.5 * (f1.dot(&f1) - 1.0),
        zz: 0.5 * (f2.dot(&f2) - 1.0),
        xy: 0.5 * f0.dot(&f1),
        yz: 0.5 * f1.dot(&f2),
        xz: 0.5 * f0.dot(&f2),
    }
}

/// The rate of deformation D = sym(dv · dx⁻¹) of Eqs. 5–6, with dx⁻¹ = cofᵀ / det:
/// D = sym(Σ_k dv_k ⊗ c_k) / det.
#[inline(always)]
fn rate_of_deformation(dv: &[Vec3; 3], c: &[Vec3; 3], inv_det: f64) -> Sym3 {
    let l = |i: usize, j: usize| dv[0][i] * c[0][j] + dv[1][i] * c[1][j] + dv[2][i] * c[2][j];
    let h = 0.5 * inv_det;
    Sym3 {
        xx: inv_det * l(0, 0),
        yy: inv_det * l(1, 1),
        zz: inv_det * l(2, 2),
        xy: h * (l(0, 1) + l(1, 0)),
        yz: h * (l(1, 2) + l(2, 1)),
        xz: h * (l(0, 2) + l(2, 0)),
    }
}

/// The hot-loop form of [`tet_stress`] and [`vertex_forces`] (Eqs. 1–10): the forces on the
/// four particles and 6 × the current volume (whose sign tells an inverted tetrahedron),
/// with the symmetric tensors kept as six components. `v` is read only when `VISCOUS`.
#[inline(always)]
pub fn tet_forces<const VISCOUS: bool>(
    x: &[Vec3; 4],
    v: &[Vec3; 4],
    dm_inv: &Mat3,
    elastic: (f64, f64),
    viscous: (f64, f64),
) -> ([Vec3; 4], f64) {
    let d = [x[1] - x[0], x[2] - x[0], x[3] - x[0]];
    // Columns of cof(dx): the area vectors A_j = −½ c_j of the faces opposite vertices 1–3.
    let c = [d[1].cross(&d[2]), d[2].cross(&d[0]), d[0].cross(&d[1])];
    let six_volume = d[0].dot(&c[0]);
    let mut t = green_strain(&d, dm_inv).lame(elastic.0, elastic.1);
    if VISCOUS {
        let dv = [v[1] - v[0], v[2] - v[0], v[3] - v[0]];
        let rate = rate_of_deformation(&dv, &c, 1.0 / six_volume);
        t = t.add(&rate.lame(viscous.0, viscous.1));
    }
    let f = c.map(|cj| t.mul(&cj) * (-1.0 / 6.0));
    ([-(f[0] + f[1] + f[2]), f[0], f[1], f[2]], six_volume)
}

/// Von Mises equivalent stress √(3/2 s:s) of a Cauchy stress, s its deviator.
pub fn von_mises(t: &Mat3) -> f64 {
    let s = t - Mat3::from_diagonal_element(t.trace() / 3.0);
    (1.5 * s.norm_squared()).sqrt()
}

/// Elastic strain energy of a tetrahedron, V₀ (λ/2 tr(ε)² + μ ε:ε), with ε = (FFᵀ − I)/2 and
/// V₀ its reference volume. Exact for the small-strain limit in which Eq. 2 is hyperelastic.
pub fn strain_energy(f: &Mat3, volume: f64, lambda: f64, mu: f64) -> f64 {
    let eps = (f * f.transpose() - Mat3::identity()) * 0.5;
    volume * (0.5 * lambda * eps.trace().powi(2) + mu * eps.norm_squared())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn unit_tet() -> [Vec3; 4] {
        [Vec3::zeros(), Vec3::x(), Vec3::y(), Vec3::z()]
    }

    #[test]
    fn hydrostatic_tension_pulls_each_vertex_toward_the_opposite_face() {
        let x = unit_tet();
        let t = Mat3::identity() * 6.0;
        let f = vertex_forces(&t, &cofactor(&edge_matrix(&x)));
        // Face opposite vertex 1 is the x = 0 face with area 1/2: force = 6 · (−½ x̂) / 3.
        assert_eq!(f[1], Vec3::new(-1.0, 0.0, 0.0));
        assert_eq!(f[3], Vec3::new(0.0, 0.0, -1.0));
        assert_eq!(f[0], Vec3::new(1.0, 1.0, 1.0));
    }

    #[test]
    fn velocity_gradient_recovers_a_linear_velocity_field() {
        let x = [
            Vec3::new(0.1, 0.2, 0.0),
            Vec3::new(1.3, 0.1, 0.2),
            Vec3::new(0.2, 0.9, -0.1),
            Vec3::new(0.0, 0.3, 1.1),
        ];
        let l = Mat3::new(0.3, -1.0, 0.2, 0.5, 0.1, -0.7, 0.4, 0.9, -0.2);
        let v = x.map(|p| l * p);
        let dx = edge_matrix(&x);
        let got = velocity_gradient(&v, &cofactor(&dx), dx.determinant());
        assert!((got - l).norm() < 1e-14);
    }
}
