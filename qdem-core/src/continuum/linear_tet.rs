//! Small-strain linear-tetrahedron FEM on the same mesh: the mesh-independent oracle of the
//! QDEM kernel (paper 000 §3.1 compares QDEM with FrontISTR on the same linear tetrahedra and
//! finds 0.0008%). In the small-strain limit Eqs. 1–10 reduce to K u with the linear-tet
//! stiffness K_e = V Gᵀ D G, so a static QDEM run must settle at K⁻¹ f.
//!
//! This is an independent implementation (reference geometry, engineering strain, no
//! B = FFᵀ): K·u is applied element by element without assembling K, and K u = f is solved by
//! conjugate gradients with a Jacobi preconditioner on the free degrees of freedom.

use crate::continuum::material::Lame;
use crate::continuum::tet_kernel::edge_matrix;
use crate::step::state::Dofs;
use crate::{Mat3, Vec3};

/// A linear-tetrahedron stiffness operator on a mesh.
pub struct LinearTets {
    tets: Vec<[u32; 4]>,
    /// Per tetrahedron: reference volume and the gradients of N₀..N₃.
    grads: Vec<(f64, [Vec3; 4])>,
    lame: Lame,
    nodes: usize,
}

/// The result of a static solve.
#[derive(Clone, Debug)]
pub struct StaticSolution {
    /// Displacement per node (m).
    pub displacement: Vec<Vec3>,
    /// CG iterations.
    pub iterations: usize,
    /// Final ‖r‖/‖f‖.
    pub relative_residual: f64,
}

impl LinearTets {
    /// The operator of `tets` (positively oriented) over `reference` positions.
    pub fn new(reference: &[Vec3], tets: &[[u32; 4]], lame: Lame) -> LinearTets {
        let grads = tets
            .iter()
            .map(|t| {
                let dm = edge_matrix(&t.map(|n| reference[n as usize]));
                let inv: Mat3 = dm.try_inverse().expect("non-degenerate tetrahedron");
                let g: [Vec3; 3] = std::array::from_fn(|k| inv.row(k).transpose());
                (
                    dm.determinant() / 6.0,
                    [-(g[0] + g[1] + g[2]), g[0], g[1], g[2]],
                )
            })
            .collect();
        LinearTets {
            tets: tets.to_vec(),
            grads,
            lame,
            nodes: reference.len(),
        }
    }

    /// K·u (internal force of the displacement u).
    pub fn apply(&self, u: &[Vec3], out: &mut [Vec3]) {
        out.iter_mut().for_each(|v| *v = Vec3::zeros());
        let Lame { lambda, mu } = self.lame;
        for (tet, (volume, g)) in self.tets.iter().zip(&self.grads) {
            let mut h = Mat3::zeros();
            for (n, gj) in tet.iter().zip(g) {
                h += u[*n as usize] * gj.transpose();
            }
            let eps = (h + h.transpose()) * 0.5;
            let sigma = Mat3::from_diagonal_element(lambda * eps.trace()) + eps * (2.0 * mu);
            for (n, gj) in tet.iter().zip(g) {
                out[*n as usize] += *volume * sigma * gj;
            }
        }
    }

    /// The diagonal of K.
    fn diagonal(&self) -> Vec<Vec3> {
        let Lame { lambda, mu } = self.lame;
        let mut d = vec![Vec3::zeros(); self.nodes];
        for (tet, (volume, g)) in self.tets.iter().zip(&self.grads) {
            for (n, gj) in tet.iter().zip(g) {
                let k = gj.map(|c| volume * (mu * gj.norm_squared() + (lambda + mu) * c * c));
                d[*n as usize] += k;
            }
        }
        d
    }

    /// Solves K u = f with u = 0 in the `fixed` directions, to ‖r‖ ≤ `tolerance`·‖f‖.
    pub fn solve(&self, f: &[Vec3], fixed: &[Dofs], tolerance: f64) -> StaticSolution {
        let free = |v: &mut [Vec3]| {
            for (x, d) in v.iter_mut().zip(fixed) {
                for axis in 0..3 {
                    if d.contains(axis) {
                        x[axis] = 0.0;
                    }
                }
            }
        };
        let dot = |a: &[Vec3], b: &[Vec3]| a.iter().zip(b).map(|(x, y)| x.dot(y)).sum::<f64>();
        let inv_diag: Vec<Vec3> = self.diagonal().iter().map(|d| d.map(|c| 1.0 / c)).collect();
        let precondition = |r: &[Vec3]| -> Vec<Vec3> {
            r.iter()
                .zip(&inv_diag)
                .map(|(r, d)| r.component_mul(d))
                .collect()
        };
        let mut u = vec![Vec3::zeros(); self.nodes];
        let mut r = f.to_vec();
        free(&mut r);
        let norm_f = dot(&r, &r).sqrt();
        let mut z = precondition(&r);
        let mut p = z.clone();
        let mut rz = dot(&r, &z);
        let mut kp = vec![Vec3::zeros(); self.nodes];
        let mut iterations = 0;
        while dot(&r, &r).sqrt() > tolerance * norm_f && iterations < 100 * self.nodes {
            self.apply(&p, &mut kp);
            free(&mut kp);
            let alpha = rz / dot(&p, &kp);
            for i in 0..self.nodes {
                u[i] += alpha * p[i];
                r[i] -= alpha * kp[i];
            }
            z = precondition(&r);
            let rz_next = dot(&r, &z);
            let beta = rz_next / rz;
            rz = rz_next;
            for i in 0..self.nodes {
                p[i] = z[i] + beta * p[i];
            }
            iterations += 1;
        }
        let relative_residual = dot(&r, &r).sqrt() / norm_f;
        StaticSolution {
            displacement: u,
            iterations,
            relative_residual,
        }
    }
}
