//! The nodal stresses of `vtu/state_NNNNN.vtu`: at each particle, the average of the stress
//! tensors of the tetrahedra around it, each weighted by its reference volume, what a
//! finite-element user reads at a bore or a hole. A particle's tetrahedra are all of its own
//! body, so the average is per body; a particle no tetrahedron has (a rigid body's centre, a
//! sphere, a disc) reads zero. The sums run in tetrahedron order, so the result does not
//! depend on the thread count.

use qdem_core::Vec3;
use qdem_mesh::signed_volume6;

/// Per particle of `reference`, the volume-weighted mean of the `stress` (six components,
/// xx, yy, zz, xy, yz, xz, one per tetrahedron of `tets`) of the tetrahedra around it.
pub(crate) fn nodal_stress(
    reference: &[Vec3],
    tets: &[[u32; 4]],
    stress: &[[f64; 6]],
) -> Vec<[f64; 6]> {
    let mut sum = vec![[0.0; 6]; reference.len()];
    let mut volume = vec![0.0; reference.len()];
    for (tet, sigma) in tets.iter().zip(stress) {
        let v = tet_volume(reference, tet);
        for &n in tet {
            let n = n as usize;
            volume[n] += v;
            for (s, c) in sum[n].iter_mut().zip(sigma) {
                *s += v * c;
            }
        }
    }
    for (s, v) in sum.iter_mut().zip(&volume) {
        if *v > 0.0 {
            s.iter_mut().for_each(|c| *c /= v);
        }
    }
    sum
}

/// The volume of tetrahedron `tet` in the reference configuration (m³).
fn tet_volume(reference: &[Vec3], tet: &[u32; 4]) -> f64 {
    (signed_volume6(&tet.map(|n| reference[n as usize].into())) / 6.0).abs()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Two tetrahedra sharing a face: the shared nodes read the volume-weighted mean of the
    /// two stresses, the others their own tetrahedron's, an unused particle zero.
    #[test]
    fn a_shared_node_reads_the_volume_weighted_mean() {
        let reference = [
            Vec3::new(0.0, 0.0, 0.0),
            Vec3::new(1.0, 0.0, 0.0),
            Vec3::new(0.0, 1.0, 0.0),
            Vec3::new(0.0, 0.0, 1.0),
            Vec3::new(0.0, 0.0, -3.0),
            Vec3::new(9.0, 9.0, 9.0),
        ];
        // Volumes 1/6 and 3/6.
        let tets = [[0, 1, 2, 3], [0, 2, 1, 4]];
        let stress = [
            [4.0, 0.0, 0.0, 0.0, 0.0, 8.0],
            [0.0, 0.0, 0.0, 0.0, 0.0, 0.0],
        ];
        let nodal = nodal_stress(&reference, &tets, &stress);
        // (4 · 1/6) / (1/6 + 3/6) = 1 and (8 · 1/6) / (4/6) = 2, to the rounding of 1/6.
        let want = [1.0, 0.0, 0.0, 0.0, 0.0, 2.0];
        assert!(nodal[0]
            .iter()
            .zip(want)
            .all(|(a, b)| (a - b).abs() < 1e-15));
        assert_eq!(nodal[3], stress[0]);
        assert_eq!(nodal[4], stress[1]);
        assert_eq!(nodal[5], [0.0; 6]);
    }
}
