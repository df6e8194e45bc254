//! The bonded contact of beam-bonded DEM: a Timoshenko beam between two particle centres
//! (paper 001 Eqs. 7, 8, 10, 11), in 2D (each particle has u, v, θ).
//!
//! In the bond's local frame (axis n from particle i to particle j, normal t = e_z × n) the
//! end displacements u_L = (u_i·n, u_i·t, θ_i, u_j·n, u_j·t, θ_j) give the end forces
//! f_L = K_b u_L (Eq. 10) with the 6×6 beam matrix of Eq. 7:
//!
//! - axial: k_a = AE/l on (u_j − u_i)·n;
//! - bending and shear: k₁ = 12EI/(l³(1+ϕ)), k₂ = 6EI/(l²(1+ϕ)), k₃ = (4+ϕ)EI/(l(1+ϕ)),
//!   k₄ = (2−ϕ)EI/(l(1+ϕ)), ϕ the shear coefficient of Timoshenko's theory.
//!
//! The transformation of Eq. 4 (T_b) is the rotation by the bond's reference direction; the
//! formulation is linear (small displacements and rotations), as in the paper.
//!
//! Damping (Eq. 8) uses c = 2ξ√(k m_r) per local direction with the reduced mass m_r (and
//! 2ξ√(k₃ J_r) for the rotation). The paper writes these on the diagonal only, which would damp
//! the absolute motion of the two particles (a rigid translation of a bonded body would be
//! slowed); here each c acts on the *relative* velocity of the two ends (the matrix
//! [[c, −c], [−c, c]] per direction), which has the same diagonal and damps deformation only.
//!
//! The bond's stress (Eq. 11) is, at either end, the larger of the tensile fibre stress
//! N/A + |M|/W and the mean shear stress 3|V|/(2A); the bond breaks when it reaches the bond's
//! strength. The same structure extends to 3D with the 12×12 beam (a second bending plane and
//! torsion): [`BeamBond`] keeps its frame and section, not 2D-specific state.

/// Cross-section of a bond: what Eqs. 7 and 11 need.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BeamSection {
    /// Area A (m²).
    pub area: f64,
    /// Second moment of area I (m⁴).
    pub inertia: f64,
    /// Section modulus W = I/(h/2) (m³).
    pub modulus: f64,
    /// Timoshenko shear coefficient ϕ = 12EI/(κGAl²) (dimensionless).
    pub shear_factor: f64,
}

/// A Timoshenko beam bond between particles `i` and `j` with its stiffness, damping and
/// strength.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BeamBond {
    /// First particle.
    pub i: u32,
    /// Second particle.
    pub j: u32,
    /// Unit vector from i to j in the reference configuration (x, y).
    pub axis: [f64; 2],
    /// Length l between the centres (m).
    pub length: f64,
    /// The section.
    pub section: BeamSection,
    /// k_a, k₁, k₂, k₃, k₄ of Eq. 7.
    pub stiffness: [f64; 5],
    /// Relative-velocity dashpots (axial, transverse, rotational) of Eq. 8.
    pub damping: [f64; 3],
    /// Strength (Pa): the bond breaks when [`BeamBond::stress`] reaches it.
    pub strength: f64,
}

/// Generalised displacement (or velocity) of one particle in 2D: x, y and the rotation θ.
pub type Dof2 = [f64; 3];

impl BeamBond {
    /// A bond of Young's modulus `young` with `section` between particles `i` at `xi` and `j`
    /// at `xj` with masses `m` and moments of inertia `jr`, damping ratio `zeta`.
    #[allow(clippy::too_many_arguments)]
    pub fn new(
        (i, xi): (u32, [f64; 2]),
        (j, xj): (u32, [f64; 2]),
        young: f64,
        section: BeamSection,
        masses: [f64; 2],
        inertias: [f64; 2],
        zeta: f64,
        strength: f64,
    ) -> BeamBond {
        let d = [xj[0] - xi[0], xj[1] - xi[1]];
        let length = d[0].hypot(d[1]);
        let axis = [d[0] / length, d[1] / length];
        let phi = section.shear_factor;
        let ei = young * section.inertia;
        let stiffness = [
            section.area * young / length,
            12.0 * ei / (length.powi(3) * (1.0 + phi)),
            6.0 * ei / (length.powi(2) * (1.0 + phi)),
            (4.0 + phi) * ei / (length * (1.0 + phi)),
            (2.0 - phi) * ei / (length * (1.0 + phi)),
        ];
        let m_r = masses[0] * masses[1] / (masses[0] + masses[1]);
        let j_r = inertias[0] * inertias[1] / (inertias[0] + inertias[1]);
        let damping = [
            2.0 * zeta * (stiffness[0] * m_r).sqrt(),
            2.0 * zeta * (stiffness[1] * m_r).sqrt(),
            2.0 * zeta * (stiffness[3] * j_r).sqrt(),
        ];
        BeamBond {
            i,
            j,
            axis,
            length,
            section,
            stiffness,
            damping,
            strength,
        }
    }

    /// The local end displacements u_L = T_bᵀ L_bᵀ u (Eq. 10's argument).
    #[inline]
    pub fn to_local(&self, ui: &Dof2, uj: &Dof2) -> [f64; 6] {
        let [c, s] = self.axis;
        [
            c * ui[0] + s * ui[1],
            -s * ui[0] + c * ui[1],
            ui[2],
            c * uj[0] + s * uj[1],
            -s * uj[0] + c * uj[1],
            uj[2],
        ]
    }

    /// Local end forces f_L = K_b u_L (Eq. 10): the forces and moments the bond needs at its
    /// ends to hold the displacement; the bond pushes the particles with −f_L.
    #[inline]
    pub fn local_forces(&self, u: &[f64; 6]) -> [f64; 6] {
        let [ka, k1, k2, k3, k4] = self.stiffness;
        let axial = ka * (u[0] - u[3]);
        let dv = u[1] - u[4];
        let shear = k1 * dv + k2 * (u[2] + u[5]);
        [
            axial,
            shear,
            k2 * dv + k3 * u[2] + k4 * u[5],
            -axial,
            -shear,
            k2 * dv + k4 * u[2] + k3 * u[5],
        ]
    }

    /// Local damping forces C_b u̇_L for local end velocities `w` (relative dashpots).
    #[inline]
    pub fn local_damping_forces(&self, w: &[f64; 6]) -> [f64; 6] {
        let [cn, ct, cr] = self.damping;
        let (a, t, r) = (cn * (w[0] - w[3]), ct * (w[1] - w[4]), cr * (w[2] - w[5]));
        [a, t, r, -a, -t, -r]
    }

    /// Rotates local end forces back to the global x, y (and moment) of particle i and j.
    #[inline]
    pub fn to_global(&self, f: &[f64; 6]) -> [Dof2; 2] {
        let [c, s] = self.axis;
        [
            [c * f[0] - s * f[1], s * f[0] + c * f[1], f[2]],
            [c * f[3] - s * f[4], s * f[3] + c * f[4], f[5]],
        ]
    }

    /// The bond's stress (Eq. 11) from its local end forces: the largest of the tensile fibre
    /// stress N/A + |M|/W at either end and the shear stress 3|V|/(2A) (Pa).
    #[inline]
    pub fn stress(&self, f: &[f64; 6]) -> f64 {
        let s = &self.section;
        let tension = f[3] / s.area;
        let bending = f[2].abs().max(f[5].abs()) / s.modulus;
        let shear = 1.5 * f[1].abs() / s.area;
        (tension + bending).max(shear)
    }

    /// The 6×6 stiffness matrix of Eq. 7 in local coordinates.
    pub fn local_stiffness(&self) -> [[f64; 6]; 6] {
        columns(|e| self.local_forces(e))
    }

    /// The 6×6 damping matrix (relative dashpots) in local coordinates.
    pub fn local_damping(&self) -> [[f64; 6]; 6] {
        columns(|e| self.local_damping_forces(e))
    }
}

/// The matrix of a linear map of 6-vectors, column by column.
pub(crate) fn columns(map: impl Fn(&[f64; 6]) -> [f64; 6]) -> [[f64; 6]; 6] {
    let mut a = [[0.0; 6]; 6];
    for col in 0..6 {
        let mut e = [0.0; 6];
        e[col] = 1.0;
        for (r, value) in map(&e).iter().enumerate() {
            a[r][col] = *value;
        }
    }
    a
}

/// The 6×6 rotation T_b of Eq. 4 for a bond along `axis`: global = T · local.
pub fn rotation(axis: [f64; 2]) -> [[f64; 6]; 6] {
    let [c, s] = axis;
    let mut t = [[0.0; 6]; 6];
    for end in 0..2 {
        let o = 3 * end;
        t[o][o] = c;
        t[o][o + 1] = -s;
        t[o + 1][o] = s;
        t[o + 1][o + 1] = c;
        t[o + 2][o + 2] = 1.0;
    }
    t
}

/// T · A · Tᵀ for 6×6 matrices: a local bond matrix in global coordinates (Eq. 4).
pub fn to_global_matrix(a: &[[f64; 6]; 6], axis: [f64; 2]) -> [[f64; 6]; 6] {
    let t = rotation(axis);
    let mut ta = [[0.0; 6]; 6];
    for r in 0..6 {
        for c in 0..6 {
            ta[r][c] = (0..6).map(|k| t[r][k] * a[k][c]).sum();
        }
    }
    let mut out = [[0.0; 6]; 6];
    for r in 0..6 {
        for c in 0..6 {
            out[r][c] = (0..6).map(|k| ta[r][k] * t[c][k]).sum();
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    fn bond(axis_angle: f64) -> BeamBond {
        let section = BeamSection {
            area: 0.01,
            inertia: 0.01f64.powi(3) / 12.0 * 100.0,
            modulus: 0.01f64.powi(2) / 6.0 * 100.0,
            shear_factor: 0.6,
        };
        let (c, s) = (axis_angle.cos(), axis_angle.sin());
        BeamBond::new(
            (0, [0.0, 0.0]),
            (1, [0.02 * c, 0.02 * s]),
            30e9,
            section,
            [1.0, 2.0],
            [1e-4, 2e-4],
            0.1,
            6e6,
        )
    }

    /// The matrix of Eq. 7 is symmetric and has exactly the three rigid modes of a plane body
    /// (two translations and a rotation) in its null space.
    #[test]
    fn stiffness_is_symmetric_with_rigid_modes_in_its_null_space() {
        let b = bond(0.3);
        let k = to_global_matrix(&b.local_stiffness(), b.axis);
        for r in 0..6 {
            for c in 0..6 {
                assert!((k[r][c] - k[c][r]).abs() <= 1e-9 * k[0][0], "({r},{c})");
            }
        }
        // Rigid rotation ω about particle i: u_j = ω e_z × (x_j − x_i), θ = ω.
        let (dx, dy) = (b.length * b.axis[0], b.length * b.axis[1]);
        let modes = [
            [1.0, 0.0, 0.0, 1.0, 0.0, 0.0],
            [0.0, 1.0, 0.0, 0.0, 1.0, 0.0],
            [0.0, 0.0, 1.0, -dy, dx, 1.0],
        ];
        for mode in modes {
            for row in &k {
                let f: f64 = row.iter().zip(&mode).map(|(a, b)| a * b).sum();
                assert!(f.abs() <= 1e-9 * k[0][0], "{f}");
            }
        }
    }

    /// A cantilevered bond (i clamped) under a tip force P deflects P l³/(3EI) + P l/(κGA),
    /// the Timoshenko cantilever, when ϕ = 12EI/(κGA l²).
    #[test]
    fn tip_deflection_is_timoshenkos() {
        let b = bond(0.0);
        let [_, k1, k2, k3, _] = b.stiffness;
        // Free end j: [k1, -k2; -k2, k3] [v; θ] = [P; 0].
        let p = 1e3;
        let det = k1 * k3 - k2 * k2;
        let v = k3 * p / det;
        let (l, ei) = (b.length, 30e9 * b.section.inertia);
        let kga = 12.0 * ei / (b.section.shear_factor * l * l);
        let expected = p * l.powi(3) / (3.0 * ei) + p * l / kga;
        assert!((v - expected).abs() <= 1e-12 * expected, "{v} {expected}");
    }

    /// Pure tension σ = N/A; pure bending |M|/W; shear 3V/(2A).
    #[test]
    fn stress_follows_eq_11() {
        let b = bond(1.0);
        let stretch = b.to_local(&[0.0; 3], &[1e-6 * b.axis[0], 1e-6 * b.axis[1], 0.0]);
        let f = b.local_forces(&stretch);
        let expected = 30e9 * 1e-6 / b.length;
        assert!((b.stress(&f) - expected).abs() <= 1e-9 * expected);
        let squeeze = b.to_local(&[0.0; 3], &[-1e-6 * b.axis[0], -1e-6 * b.axis[1], 0.0]);
        assert!(b.stress(&b.local_forces(&squeeze)) < 1.0);
        let bend = [0.0, 0.0, 1e-4, 0.0, 0.0, -1e-4];
        let f = b.local_forces(&bend);
        let m = (b.stiffness[3] - b.stiffness[4]) * 1e-4;
        assert!((b.stress(&f) - m / b.section.modulus).abs() <= 1e-9 * b.stress(&f));
    }

    /// The dashpots leave a rigid translation undamped.
    #[test]
    fn damping_acts_on_relative_velocity_only() {
        let b = bond(0.7);
        let f = b.local_damping_forces(&b.to_local(&[1.0, -2.0, 0.5], &[1.0, -2.0, 0.5]));
        assert!(f.iter().all(|&x| x.abs() < 1e-12));
    }
}
