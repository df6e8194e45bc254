//! The literal subdomain construction of paper 000 §2 and Eqs. 9–10, kept as the test oracle
//! of the closed-form force in [`crate::continuum::tet_kernel::vertex_forces`].
//!
//! The tetrahedron is split into four equal-volume subdomains, one per vertex, by twelve
//! triangles: for each edge (j, k) with the other two vertices l, m, the interface between the
//! subdomains of j and k is the quadrilateral (ec_jk, fc_jkl, vc, fc_jkm) of the edge centroid,
//! the two face centroids and the volume centroid, made of the triangles
//! ⟨ec_jk, fc_jkl, fc_jkm⟩ and ⟨vc, fc_jkl, fc_jkm⟩ (process 2 of §2). Eq. 9 gives the force of
//! the homogeneous stress T on a triangle with edge vectors a, b as ½ T (a × b); Eq. 10 sums
//! them per subdomain. The traction T n with n pointing out of the subdomain of j is the force
//! the neighbour exerts on j, so j receives +½ T(a×b) and k the opposite.

use crate::{Mat3, Vec3};

/// Forces on the four particles of a tetrahedron under the homogeneous Cauchy stress `t`,
/// computed triangle by triangle over the twelve interface triangles (Eqs. 9–10).
pub fn subdomain_forces(x: &[Vec3; 4], t: &Mat3) -> [Vec3; 4] {
    let vc = (x[0] + x[1] + x[2] + x[3]) / 4.0;
    let face_centroid = |a: usize, b: usize, c: usize| (x[a] + x[b] + x[c]) / 3.0;
    let mut forces = [Vec3::zeros(); 4];
    for j in 0..4 {
        for k in (j + 1)..4 {
            let mut others = (0..4).filter(|&i| i != j && i != k);
            let (l, m) = (others.next().unwrap(), others.next().unwrap());
            let ec = (x[j] + x[k]) / 2.0;
            let (fl, fm) = (face_centroid(j, k, l), face_centroid(j, k, m));
            // The two triangles of the quadrilateral ec → fl → vc → fm, consistently oriented.
            let mut area = 0.5 * ((fl - ec).cross(&(fm - ec)) + (fm - vc).cross(&(fl - vc)));
            // Orient the interface normal out of j's subdomain, towards k.
            if area.dot(&(x[k] - x[j])) < 0.0 {
                area = -area;
            }
            let f = t * area;
            forces[j] += f;
            forces[k] -= f;
        }
    }
    forces
}
