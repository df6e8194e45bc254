//! The particle size distribution of a `[granular]` sample by mass, as a sieve analysis
//! reports it (railway ballast gradings, EN 13450, are by mass).
//!
//! **Sieve size of a clump.** [`sieve_size`], shared with the generator (which scales every
//! clump so that it measures the size it was drawn at): a stone passes a square sieve of
//! aperture a when its middle extent, along the principal axes of its spheres' union, is at
//! most a ([`qdem_contact::samples::sieve`] has the definition and its reference).
//!
//! **By mass.** The fraction passing a size is the mass of the stones of at most that sieve
//! size over the sample's mass; `[granular] grading` draws sizes by number, which the curve
//! by number beside it shows (by mass with `grading_basis = "mass"`).

pub use qdem_contact::samples::sieve::sieve_size;

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
    fn the_grading_by_mass_weighs_each_stone() {
        let g = grading_by_mass(&[(0.04, 3.0), (0.02, 1.0)]);
        assert_eq!(g[0], [0.02, 1.0, 0.25, 0.5]);
        assert_eq!(g[1], [0.04, 3.0, 1.0, 1.0]);
    }
}
