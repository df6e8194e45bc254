//! The sieve size of a stone of spheres: the one definition the generator
//! ([`crate::samples::clump_shape`] scales every clump to measure its drawn size) and the
//! `grading.csv` record share.
//!
//! **A stone passes a square sieve of aperture a when its middle extent is at most a.** A
//! stone falls through a square mesh long axis first, so what must pass the aperture is its
//! cross-section across its long axis, whose larger side is the intermediate (middle)
//! dimension: the sieve size of a particle is taken as its intermediate dimension, the
//! convention of the long, intermediate and short axis measurements of particle shape
//! (reviewed by Blott & Pye 2008, "Particle shape: a review and new methods of characterization
//! and classification", Sedimentology 55(1):31–63). The passage of a flat stone through the
//! aperture's diagonal, which lets through a stone up to √2 times wider, is not modelled.
//!
//! **The extents.** The principal axes of the spheres' union are the eigenvectors of
//! Σ r³ [(x − x̄)(x − x̄)ᵀ + r²/5 I] over its spheres (a sphere weighs its volume, x̄ the
//! volume-weighted mean centre); the extent along an axis is the span of the spheres' surfaces
//! along it, max (x·e + r) − min (x·e − r); the sieve size is the middle one of the three. A
//! one-sphere stone's is its diameter. The definition is invariant under rotation, translation
//! and scaling (scaled by f, a stone's sieve size is f times its own), which is what lets the
//! generator scale a clump to any size.

use nalgebra::SymmetricEigen;
use qdem_core::{Mat3, Vec3};

/// The sieve size (m) of a stone of spheres at `centers` with `radii` (module docs).
///
/// ```
/// use qdem_contact::samples::sieve::sieve_size;
/// use qdem_core::Vec3;
/// // Two touching spheres of radius 1 cm in a row: 4 cm long, 2 cm across.
/// let centers = [Vec3::new(0.0, 0.0, 0.0), Vec3::new(0.02, 0.0, 0.0)];
/// assert!((sieve_size(&centers, &[0.01, 0.01]) - 0.02).abs() < 1e-12);
/// ```
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
}
