//! The shape of one generated stone: its spheres in its own frame (long axis x, intermediate y,
//! short z), before [`crate::samples::clump_sample`] turns and places it. Two rules, chosen by
//! [`ClumpShape`]; U(p, q) denotes a uniform draw from the seeded [`SplitMix64`], and the draws
//! are made in the order listed.
//!
//! Both rules start alike, for a stone of nominal size d (the sieve size asked for):
//! - k spheres, k a uniform integer in `spheres_per_stone` (inclusive); k = 1 gives a plain
//!   sphere of radius d/2 at the origin and draws nothing more;
//! - semi-axes a = d/2·U(1.0, 1.3), b = d/2·U(0.7, 1.0), c = d/2·U(0.5, 0.75), so
//!   c ≤ b ≤ a ≤ 0.65·d.
//!
//! Every sphere of either rule lies in the ball of radius a about the stone's origin.
//!
//! **Scaled to measure d.** The spheres the rule draws do not measure d: the sieve size of their
//! union ([`crate::samples::sieve`], its middle extent) is closer to 2b, or less, and at the
//! Network Rail grading the unscaled stones passed 63% by mass at 31.5 mm where the curve asks
//! 13%. So [`ClumpShape::clump`] then scales every centre and radius about the origin by
//! d / s, s the sieve size of the drawn union: the stone measures d exactly (up to rounding;
//! the sieve size is invariant under the turn and the placement that follow). A plain sphere
//! measures its diameter d already (the factor is exactly 1). The rule is scale-free, so the
//! scaled stone's shape, and its mass over d³, do not depend on d. Scaling up a long, thin
//! stone makes it long: its longest extent (at most 2a ≤ 1.3 d before scaling) over its middle
//! one (at least the largest sphere's diameter, 2·0.85·c ≥ 0.425 d) is at most 3.06, so a
//! scaled stone spans at most 3.06 d. Measured over 2,000 stones of each shape, the
//! longest span over d is 1.39–1.97 for elongated stones of 3–5 spheres (10th to 90th
//! percentile; median 1.65, largest 2.59) and 1.14–1.55 for angular ones of 5–7 (median 1.32,
//! largest 1.97); before scaling it was at most 1.3.
//!
//! # Elongated ([`ClumpShape::Elongated`], the default)
//! An elongated, flaky stone: a row of spheres along the long axis.
//! - sphere radii r_i = c·U(0.85, 1.0);
//! - centres x_i spread evenly along the long axis from −(a − r_i) to +(a − r_i), plus a jitter
//!   of up to a tenth of the spacing, clamped to |x_i| ≤ a − r_i; across, y_i = (b − r_i)·U(−1, 1)
//!   (no offset if b < r_i), z_i = 0. The offset y_i is then clamped so that
//!   |(x_i, y_i)| + r_i ≤ a (the end spheres therefore sit on the axis).
//!
//! Per sphere the draws are r_i, the jitter, then y_i.
//!
//! # Angular ([`ClumpShape::Angular`])
//! A stone with corners, like crushed ballast: a core sphere and k − 1 smaller corner spheres
//! pushed out towards the surface of the ellipsoid of semi-axes a, b, c.
//! - sphere 0, the core: radius r_0 = c·U(0.85, 1.0), at the origin;
//! - the corner directions u_i, i = 0 … n − 1 with n = k − 1: a Fibonacci lattice on the unit
//!   sphere, z_i = 1 − 2(i + 0.5)/n at azimuth i·π(3 − √5), all turned by one uniformly random
//!   rotation (drawn once, after r_0);
//! - corner i (sphere i + 1): radius r = c·U(0.45, 0.7), then a reach s = U(0.8, 1.0) (irregular
//!   vertex distances), centre s·((a − r)·u_x, (b − r)·u_y, (c − r)·u_z).
//!
//! Since r < c ≤ b ≤ a, the centre lies within s·(a − r) ≤ a − r of the origin, so the corner
//! lies in the ball of radius a. A corner must overlap the core for the stone to be one body,
//! which the draws alone do not ensure: for a long, thin stone (a = 0.65·d, c = 0.25·d) a corner
//! on the long axis sits up to 0.54·d out while the core and corner radii may sum to 0.33·d. A
//! corner farther than r_0 + 0.9·r from the origin is therefore pulled in along its direction to
//! that distance: it overlaps the core by at least a tenth of its radius. Pulling in only
//! shortens the centre, so the ball bound holds.
//!
//! The random rotation is Shoemake's random unit quaternion (`random_rotation`), as for the
//! turn [`crate::samples::clump_sample`] gives every stone.

use crate::bonded::particle_packing::SplitMix64;
use crate::samples::sieve::sieve_size;
use nalgebra::{Quaternion, UnitQuaternion};
use qdem_core::Vec3;

/// Long-axis semi-axis over d/2: U(1.0, 1.3).
const LONG_AXIS: [f64; 2] = [1.0, 1.3];
/// Intermediate semi-axis over d/2: U(0.7, 1.0).
const MID_AXIS: [f64; 2] = [0.7, 1.0];
/// Short semi-axis over d/2: U(0.5, 0.75).
const SHORT_AXIS: [f64; 2] = [0.5, 0.75];
/// Sphere radius over the short semi-axis: U(0.85, 1.0) (an elongated stone's spheres, an
/// angular stone's core).
const RADIUS_FACTOR: [f64; 2] = [0.85, 1.0];
/// Largest jitter of a centre along the long axis, as a fraction of the spacing.
const JITTER: f64 = 0.1;
/// An angular stone's corner radius over the short semi-axis: U(0.45, 0.7).
const CORNER_RADIUS: [f64; 2] = [0.45, 0.7];
/// An angular stone's corner reach, the fraction of the way out to the ellipsoid: U(0.8, 1.0).
const CORNER_REACH: [f64; 2] = [0.8, 1.0];
/// Least overlap of a corner with the core, over the corner's radius.
const CORNER_OVERLAP: f64 = 0.1;

/// How a generated stone's spheres are arranged (module docs); `shape` of `[granular]`.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum ClumpShape {
    /// A row of spheres along the long axis: an elongated, flaky stone.
    #[default]
    Elongated,
    /// A core sphere with corner spheres out towards an ellipsoid: a stone with corners.
    Angular,
}

impl ClumpShape {
    /// Centres (in the stone's frame) and radii of a clump of sieve size `size` with a number of
    /// spheres in `spheres` (inclusive), drawn from `rng` by the shape's rule and scaled so that
    /// its sieve size ([`sieve_size`]) is `size` (module docs).
    pub(crate) fn clump(
        self,
        size: f64,
        spheres: [usize; 2],
        rng: &mut SplitMix64,
    ) -> (Vec<Vec3>, Vec<f64>) {
        let (mut centers, mut radii) = self.drawn(size, spheres, rng);
        let scale = size / sieve_size(&centers, &radii);
        centers.iter_mut().for_each(|c| *c *= scale);
        radii.iter_mut().for_each(|r| *r *= scale);
        (centers, radii)
    }

    /// The clump as the rule draws it for the nominal size `size`, before scaling (module docs).
    fn drawn(self, size: f64, spheres: [usize; 2], rng: &mut SplitMix64) -> (Vec<Vec3>, Vec<f64>) {
        match self {
            ClumpShape::Elongated => elongated_shape(size, spheres, rng),
            ClumpShape::Angular => angular_shape(size, spheres, rng),
        }
    }
}

/// Uniform in [lo, hi).
fn uniform_in(rng: &mut SplitMix64, [lo, hi]: [f64; 2]) -> f64 {
    lo + (hi - lo) * rng.uniform()
}

/// A uniform integer in the inclusive range.
fn integer_in(rng: &mut SplitMix64, [lo, hi]: [usize; 2]) -> usize {
    lo + (rng.next_u64() % (hi - lo + 1) as u64) as usize
}

/// The draws both rules start with (module docs): the number of spheres k and the semi-axes
/// a, b, c; `None` for a one-sphere stone, which draws nothing more.
fn count_and_axes(
    size: f64,
    spheres: [usize; 2],
    rng: &mut SplitMix64,
) -> Option<(usize, [f64; 3])> {
    let k = integer_in(rng, spheres);
    if k == 1 {
        return None;
    }
    let half = 0.5 * size;
    let a = half * uniform_in(rng, LONG_AXIS);
    let b = half * uniform_in(rng, MID_AXIS);
    let c = half * uniform_in(rng, SHORT_AXIS);
    Some((k, [a, b, c]))
}

/// Centres (in the stone's frame) and radii of an elongated clump of sieve size `size` (module
/// docs).
fn elongated_shape(size: f64, spheres: [usize; 2], rng: &mut SplitMix64) -> (Vec<Vec3>, Vec<f64>) {
    let Some((k, [a, b, c])) = count_and_axes(size, spheres, rng) else {
        return (vec![Vec3::zeros()], vec![0.5 * size]);
    };
    let mut centers = Vec::with_capacity(k);
    let mut radii = Vec::with_capacity(k);
    for i in 0..k {
        let r = c * uniform_in(rng, RADIUS_FACTOR);
        // r ≤ 0.75·d/2 < a, so the reach is positive.
        let reach = a - r;
        let spacing = 2.0 * reach / (k - 1) as f64;
        let jitter = JITTER * spacing * uniform_in(rng, [-1.0, 1.0]);
        let x = (-reach + spacing * i as f64 + jitter).clamp(-reach, reach);
        let across = (b - r).max(0.0) * uniform_in(rng, [-1.0, 1.0]);
        // Keep |(x, y)| + r ≤ a: the clump stays in the ball of radius a.
        let limit = (reach * reach - x * x).max(0.0).sqrt();
        centers.push(Vec3::new(x, across.clamp(-limit, limit), 0.0));
        radii.push(r);
    }
    (centers, radii)
}

/// Centres (in the stone's frame) and radii of an angular clump of sieve size `size`: the core,
/// then the corners (module docs).
fn angular_shape(size: f64, spheres: [usize; 2], rng: &mut SplitMix64) -> (Vec<Vec3>, Vec<f64>) {
    let Some((k, [a, b, c])) = count_and_axes(size, spheres, rng) else {
        return (vec![Vec3::zeros()], vec![0.5 * size]);
    };
    let core = c * uniform_in(rng, RADIUS_FACTOR);
    let turn = random_rotation(rng);
    let mut centers = Vec::with_capacity(k);
    let mut radii = Vec::with_capacity(k);
    centers.push(Vec3::zeros());
    radii.push(core);
    let n = (k - 1) as f64;
    let golden_angle = std::f64::consts::PI * (3.0 - 5f64.sqrt());
    for i in 0..k - 1 {
        let z = 1.0 - 2.0 * (i as f64 + 0.5) / n;
        let across = (1.0 - z * z).max(0.0).sqrt();
        let azimuth = golden_angle * i as f64;
        let u = turn * Vec3::new(across * azimuth.cos(), across * azimuth.sin(), z);
        let r = c * uniform_in(rng, CORNER_RADIUS);
        let reach = uniform_in(rng, CORNER_REACH);
        // r < c ≤ b ≤ a: every factor is positive and |centre| ≤ reach·(a − r) ≤ a − r.
        let mut centre = reach * Vec3::new((a - r) * u.x, (b - r) * u.y, (c - r) * u.z);
        // Pulled in to overlap the core by CORNER_OVERLAP·r at least (module docs).
        let farthest = core + (1.0 - CORNER_OVERLAP) * r;
        let distance = centre.norm();
        if distance > farthest {
            centre *= farthest / distance;
        }
        centers.push(centre);
        radii.push(r);
    }
    (centers, radii)
}

/// A uniformly random rotation (Shoemake's random unit quaternion).
pub(crate) fn random_rotation(rng: &mut SplitMix64) -> UnitQuaternion<f64> {
    let tau = 2.0 * std::f64::consts::PI;
    let (u1, u2, u3) = (rng.uniform(), rng.uniform(), rng.uniform());
    let (s1, s2) = ((1.0 - u1).sqrt(), u1.sqrt());
    UnitQuaternion::new_normalize(Quaternion::new(
        s2 * (tau * u3).cos(),
        s1 * (tau * u2).sin(),
        s1 * (tau * u2).cos(),
        s2 * (tau * u3).sin(),
    ))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Sizes across a ballast grading, each with many seeds.
    fn angular_clumps(spheres: [usize; 2]) -> Vec<(f64, Vec<Vec3>, Vec<f64>)> {
        let mut rng = SplitMix64(17);
        (0..2000)
            .map(|i| {
                let d = 0.0224 + 0.0406 * (i % 50) as f64 / 49.0;
                let (centers, radii) = ClumpShape::Angular.drawn(d, spheres, &mut rng);
                (d, centers, radii)
            })
            .collect()
    }

    #[test]
    fn angular_clumps_follow_the_rule() {
        let mut pulled = 0;
        let mut corners = 0;
        for (d, centers, radii) in angular_clumps([2, 8]) {
            let k = centers.len();
            assert!((2..=8).contains(&k), "{k} spheres");
            assert_eq!(radii.len(), k);
            // The core at the origin, c·U(0.85, 1) with c = d/2·U(0.5, 0.75).
            assert_eq!(centers[0], Vec3::zeros());
            let core = radii[0];
            assert!(
                core >= 0.85 * 0.25 * d && core <= 0.375 * d,
                "core {core} at d {d}"
            );
            for (x, &r) in centers.iter().zip(&radii) {
                // Inside the ball of radius a ≤ 0.65 d (rounding only: 1e-12 relative).
                assert!(x.norm() + r <= 0.65 * d * (1.0 + 1e-12), "{x} {r} at d {d}");
            }
            for (x, &r) in centers.iter().zip(&radii).skip(1) {
                // Corner radius c·U(0.45, 0.7), below the core's c·0.85.
                assert!(
                    r >= 0.45 * 0.25 * d && r < 0.7 * 0.375 * d,
                    "corner {r} at d {d}"
                );
                assert!(r < core);
                // Overlaps the core by a tenth of its radius at least (1e-12: rounding).
                let depth = core + r - x.norm();
                assert!(
                    depth >= 0.1 * r * (1.0 - 1e-12),
                    "depth {depth} of {r} at d {d}"
                );
                corners += 1;
                if depth < 0.1 * r * (1.0 + 1e-9) {
                    pulled += 1;
                }
            }
        }
        // The pull-in is for extreme draws, not the rule: most corners keep their draw.
        assert!(
            pulled * 4 < corners,
            "{pulled} of {corners} corners pulled in"
        );
    }

    #[test]
    fn angular_corners_spread_around_the_core() {
        // Eight corners on a turned Fibonacci lattice: the mean of their unit directions stays
        // near the origin (0.09 at most over these 50 stones, the ellipsoid's squashing and
        // the reaches included); corners crowded into one hemisphere would leave 0.5 or more.
        for (_, centers, _) in angular_clumps([9, 9]).iter().take(50) {
            let mean = centers[1..].iter().map(|x| x.normalize()).sum::<Vec3>() / 8.0;
            assert!(mean.norm() < 0.25, "corners lean {mean}");
        }
    }

    #[test]
    fn a_one_sphere_angular_stone_is_the_plain_sphere_and_draws_alike() {
        let mut a = SplitMix64(3);
        let mut b = SplitMix64(3);
        for _ in 0..20 {
            let angular = ClumpShape::Angular.clump(0.04, [1, 1], &mut a);
            assert_eq!(angular, (vec![Vec3::zeros()], vec![0.02]));
            assert_eq!(angular, ClumpShape::Elongated.clump(0.04, [1, 1], &mut b));
        }
        assert_eq!(a.0, b.0);
    }

    #[test]
    fn angular_clumps_are_seeded() {
        let again = angular_clumps([2, 8]);
        assert_eq!(angular_clumps([2, 8]), again);
        let mut rng = SplitMix64(18);
        let other = ClumpShape::Angular.drawn(again[0].0, [2, 8], &mut rng);
        assert_ne!((other.0, other.1), (again[0].1.clone(), again[0].2.clone()));
    }
}
