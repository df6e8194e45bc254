//! The particle size distribution of a `[granular]` sample by mass, as a sieve analysis
//! reports it (railway ballast gradings, EN 13450, are by mass).
//!
//! **Sieve size of a clump.** A stone passes a square aperture when its cross-section across
//! its longest axis does; qdem takes the smallest square aperture a stone passes to be its
//! second-largest extent: the extents are measured along the principal axes of the spheres'
//! union (the eigenvectors of Σ r³ [(x − x̄)(x − x̄)ᵀ + r²/5 I] over its spheres, a sphere's
//! weight its volume), each the span of the spheres' surfaces along the axis; a one-sphere
//! stone's is its diameter. (The generator's sieve size d gives a stone whose intermediate
//! semi-axis is d/2 · U(0.7, 1.0), so a generated stone measures at or below its d.)
//!
//! **By mass.** The fraction passing a size is the mass of the stones of at most that sieve
//! size over the sample's mass; `[granular] grading` draws sizes by number, which the curve
//! by number beside it shows (by mass with `grading_basis = "mass"`).

use nalgebra::SymmetricEigen;
use qdem_core::{Mat3, Vec3};

/// The sieve size (m) of a stone of spheres at `centers` with `radii` (module docs).
pub fn sieve_size(centers: &[Vec3], radii: &[f64]) -> f64 {
    let weights: Vec<f64> = radii.iter().map(|r| r.powi(3)).collect();
    let total: f64 = weights.iter().sum();
    let mean = centers
        .iter()
        .zip(&weights)
        .map(|(c, w)| *w * c)
        .sum::<Vec3>()
        / total;
    let mut spread = Mat3::zeros();
    for ((c, r), w) in centers.iter().zip(radii).zip(&weights) {
        let d = c - mean;
        spread += *w * (d * d.transpose() + 0.2 * r * r * Mat3::identity());
    }
    let axes = SymmetricEigen::new(spread).eigenvectors;
    let mut extents: Vec<f64> = axes
        .column_iter()
        .map(|axis| {
            let (lo, hi) = centers.iter().zip(radii).fold(
                (f64::INFINITY, f64::NEG_INFINITY),
                |(lo, hi), (c, r)| {
                    let at = c.dot(&axis);
                    (lo.min(at - r), hi.max(at + r))
                },
            );
            hi - lo
        })
        .collect();
    extents.sort_by(f64::total_cmp);
    extents[1]
}

/// The grading of stones (sieve size m, mass kg): per stone in order of size, its size, its
/// mass and the fractions of the sample's mass and number at or below its size.
pub fn grading_by_mass(stones: &[(f64, f64)]) -> Vec<[f64; 4]> {
    let mut sorted = stones.to_vec();
    sorted.sort_by(|a, b| a.0.total_cmp(&b.0));
    let total: f64 = sorted.iter().map(|s| s.1).sum();
    let count = sorted.len() as f64;
    let mut passing = 0.0;
    sorted
        .iter()
        .enumerate()
        .map(|(k, &(size, mass))| {
            passing += mass;
            [size, mass, passing / total, (k + 1) as f64 / count]
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_sphere_sieves_at_its_diameter_and_a_row_of_spheres_at_their_width() {
        let one = sieve_size(&[Vec3::new(1.0, 2.0, 3.0)], &[0.01]);
        assert!((one - 0.02).abs() < 1e-15);
        // Three equal spheres in a row along a tilted axis: extents 6r along it, 2r across.
        let axis = Vec3::new(1.0, 1.0, 0.0).normalize();
        let centers: Vec<Vec3> = (-1..=1).map(|k| 0.02 * k as f64 * axis).collect();
        let row = sieve_size(&centers, &[0.01; 3]);
        assert!((row - 0.02).abs() < 1e-12, "{row}");
        // A flat triangle of spheres: the second extent is its in-plane width.
        let centers = [
            Vec3::new(0.0, 0.0, 0.0),
            Vec3::new(0.04, 0.0, 0.0),
            Vec3::new(0.02, 0.01, 0.0),
        ];
        let flat = sieve_size(&centers, &[0.01; 3]);
        assert!((flat - 0.03).abs() < 1e-12, "{flat}");
    }

    #[test]
    fn the_grading_by_mass_weighs_each_stone() {
        let g = grading_by_mass(&[(0.04, 3.0), (0.02, 1.0)]);
        assert_eq!(g[0], [0.02, 1.0, 0.25, 0.5]);
        assert_eq!(g[1], [0.04, 3.0, 1.0, 1.0]);
    }
}
