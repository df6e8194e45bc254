//! Ballast-like stones as rigid clumps of overlapping spheres, for the box test of paper 003
//! (railway ballast of a given grading deposited under gravity into a box). This module only
//! makes the initial loose arrangement and the clumps' mass properties; the deposition itself is
//! simulated elsewhere.
//!
//! # Sizes
//! Every stone's sieve size d is drawn by inverse-transform sampling of the cumulative
//! [`Grading`]: d = [`Grading::size_at`]\(u), u uniform in [0, 1) from the seeded
//! [`SplitMix64`]. The curve is therefore sampled **by number**: the fraction of *stones* finer
//! than d follows the curve, not the fraction of *mass* a sieve analysis reports. Large stones
//! weigh more, so the generated sample is somewhat coarser by mass than the curve.
//!
//! # Shape
//! A stone of sieve size d is an elongated, flaky clump built in its own frame (long axis x,
//! intermediate y, short z), U(p, q) denoting a uniform draw:
//! - semi-axes a = d/2·U(1.0, 1.3), b = d/2·U(0.7, 1.0), c = d/2·U(0.5, 0.75);
//! - k spheres, k a uniform integer in `spheres_per_stone` (inclusive);
//! - sphere radii r_i = c·U(0.85, 1.0);
//! - centres x_i spread evenly along the long axis from −(a − r_i) to +(a − r_i), plus a jitter
//!   of up to a tenth of the spacing, clamped to |x_i| ≤ a − r_i; across, y_i = (b − r_i)·U(−1, 1)
//!   (no offset if b < r_i), z_i = 0. The offset y_i is then clamped so that
//!   |(x_i, y_i)| + r_i ≤ a: every clump lies in the ball of radius a ≤ 0.65·d about its
//!   origin, whatever its rotation (the end spheres therefore sit on the axis);
//! - k = 1 gives a plain sphere of radius d/2 at the origin.
//!
//! The clump is then turned about its origin by a uniformly random rotation (a random unit
//! quaternion, Shoemake's method).
//!
//! # Placement
//! Shelf packing of the stones' own axis-aligned bounding boxes (after their rotation), from the
//! region's lower corner upward: stones go side by side along x, a row full starts the next row
//! along y (as deep as the row's deepest box), a layer full starts the next layer along z (as
//! high as the layer's highest box), with a gap g = 0.02·d_max between boxes and g/2 from the
//! region's faces. Boxes never overlap, so stones never do, and every sphere lies inside the
//! region. This is some five times denser than a lattice of cells sized for the largest stone,
//! so a deposition column is short. A region too small is refused
//! ([`SampleError::RegionTooSmall`], with the height that would do). Everything is a
//! deterministic function of the seed.
//!
//! # Mass properties
//! [`clump_mass_properties`] (in [`crate::clump_mass`], re-exported here): exact for a
//! one-sphere stone, a grid integration with a stated error bound for a clump.

pub use crate::clump_mass::{clump_mass_properties, MassProperties};
use crate::particle_packing::SplitMix64;
use nalgebra::{Quaternion, UnitQuaternion};
use qdem_core::Vec3;

/// Long-axis semi-axis over d/2: U(1.0, 1.3).
const LONG_AXIS: [f64; 2] = [1.0, 1.3];
/// Intermediate semi-axis over d/2: U(0.7, 1.0).
const MID_AXIS: [f64; 2] = [0.7, 1.0];
/// Short semi-axis over d/2: U(0.5, 0.75).
const SHORT_AXIS: [f64; 2] = [0.5, 0.75];
/// Sphere radius over the short semi-axis: U(0.85, 1.0).
const RADIUS_FACTOR: [f64; 2] = [0.85, 1.0];
/// Largest jitter of a centre along the long axis, as a fraction of the spacing.
const JITTER: f64 = 0.1;
/// A stone's extent over its sieve size, at most (2a/d ≤ 1.3).
const EXTENT: f64 = 1.3;
/// Gap between cells' usable boxes over the largest size.
const GAP: f64 = 0.02;

/// What [`Grading::new`], [`generate_stones`] and [`clump_mass_properties`] refuse; every
/// message says what to change.
#[derive(Debug, thiserror::Error)]
pub enum SampleError {
    /// Fewer than two grading points.
    #[error(
        "a grading needs at least two points (sieve size in m, mass fraction passing), {given} \
         given; fix: give the curve from the smallest size (passing 0) to the largest (passing 1)"
    )]
    GradingTooShort {
        /// Number of points given.
        given: usize,
    },
    /// A sieve size is not positive and finite.
    #[error(
        "grading point {index}: sieve size {size} m must be positive and finite; fix: give sizes \
         in metres (e.g. 0.0315 for 31.5 mm)"
    )]
    GradingSize {
        /// Index of the point.
        index: usize,
        /// The size given.
        size: f64,
    },
    /// The sieve sizes do not increase strictly.
    #[error(
        "grading point {index}: sieve size {size} m is not larger than the previous one, \
         {previous} m; fix: list the sizes strictly increasing"
    )]
    GradingNotIncreasing {
        /// Index of the point.
        index: usize,
        /// The previous size.
        previous: f64,
        /// The size given.
        size: f64,
    },
    /// A fraction passing is outside [0, 1].
    #[error(
        "grading point {index}: fraction passing {fraction} is not in [0, 1]; fix: give mass \
         fractions, not percentages (e.g. 0.3 for 30 %)"
    )]
    GradingFraction {
        /// Index of the point.
        index: usize,
        /// The fraction given.
        fraction: f64,
    },
    /// The fractions passing decrease.
    #[error(
        "grading point {index}: fraction passing {fraction} is less than the previous one, \
         {previous}; fix: a cumulative curve never decreases, give the fractions non-decreasing"
    )]
    GradingDecreasing {
        /// Index of the point.
        index: usize,
        /// The previous fraction.
        previous: f64,
        /// The fraction given.
        fraction: f64,
    },
    /// The curve does not start at 0 or does not end at 1.
    #[error(
        "the grading must start at fraction passing 0 and end at 1, but goes from {first} to \
         {last}; fix: add a point at the smallest size passing 0 and one at the largest passing 1"
    )]
    GradingEnds {
        /// Fraction passing at the smallest size.
        first: f64,
        /// Fraction passing at the largest size.
        last: f64,
    },
    /// The range of spheres per stone is empty or starts at 0.
    #[error(
        "spheres per stone [{min}, {max}] is not a range of at least one sphere; fix: give \
         1 ≤ min ≤ max, e.g. [3, 5] ([1, 1] for plain spheres)"
    )]
    SphereCount {
        /// Least number asked for.
        min: usize,
        /// Largest number asked for.
        max: usize,
    },
    /// The region's corners are not finite or not ordered.
    #[error(
        "the region's upper corner {upper:?} m must be finite and above its lower corner \
         {lower:?} m in x, y and z; fix: give [lower, upper]"
    )]
    Region {
        /// Lower corner given.
        lower: [f64; 3],
        /// Upper corner given.
        upper: [f64; 3],
    },
    /// The region is narrower than the largest stone in x or y.
    #[error(
        "the region is {width} m × {depth} m in plan, narrower than the largest stone's box of \
         {cell} m (1.3 × the largest sieve size plus a gap); fix: make it at least {cell} m wide \
         and deep"
    )]
    RegionTooNarrow {
        /// Extent in x.
        width: f64,
        /// Extent in y.
        depth: f64,
        /// The largest stone's extent bound (m).
        cell: f64,
    },
    /// The region holds fewer stones than asked.
    #[error(
        "the region holds {fit} stones but {count} were asked; fix: make it at least {tall:.3} m \
         tall with the same plan, or ask for at most {fit} stones",
        tall = round_up_to_mm(.needed_height)
    )]
    RegionTooSmall {
        /// Stones asked for.
        count: usize,
        /// Stones the region holds.
        fit: usize,
        /// Height that would hold `count` stones with the same plan (m), estimated from the
        /// height the first `fit` took, plus a layer of the largest stones.
        needed_height: f64,
    },
    /// The density is not positive and finite.
    #[error("density {density} kg/m³ must be positive and finite; fix: give it in kg/m³")]
    Density {
        /// The density given.
        density: f64,
    },
    /// The stone has no spheres or invalid ones.
    #[error("invalid stone: {reason}; fix: give as many finite centres as positive radii")]
    Stone {
        /// What is wrong.
        reason: String,
    },
}

/// `length` (m) rounded up to a millimetre, for messages that must not understate a size.
fn round_up_to_mm(length: &f64) -> f64 {
    (length * 1000.0 - 1e-6).ceil() / 1000.0
}

/// Cumulative grading curve: (sieve size d in m, mass fraction passing in [0, 1]); sizes
/// strictly increasing, fractions non-decreasing, first 0 and last 1.
#[derive(Clone, Debug, PartialEq)]
pub struct Grading {
    /// Sieve sizes (m), strictly increasing.
    sizes: Vec<f64>,
    /// Fractions passing, non-decreasing from 0 to 1.
    passing: Vec<f64>,
}

impl Grading {
    /// The curve through `points` (sieve size in m, fraction passing), checked as described on
    /// [`Grading`].
    pub fn new(points: Vec<(f64, f64)>) -> Result<Grading, SampleError> {
        if points.len() < 2 {
            return Err(SampleError::GradingTooShort {
                given: points.len(),
            });
        }
        for (index, &(size, fraction)) in points.iter().enumerate() {
            check_grading_point(index, size, fraction)?;
            if index > 0 {
                let (previous, previous_fraction) = points[index - 1];
                if size <= previous {
                    return Err(SampleError::GradingNotIncreasing {
                        index,
                        previous,
                        size,
                    });
                }
                if fraction < previous_fraction {
                    return Err(SampleError::GradingDecreasing {
                        index,
                        previous: previous_fraction,
                        fraction,
                    });
                }
            }
        }
        let (first, last) = (points[0].1, points[points.len() - 1].1);
        if first != 0.0 || last != 1.0 {
            return Err(SampleError::GradingEnds { first, last });
        }
        let (sizes, passing) = points.into_iter().unzip();
        Ok(Grading { sizes, passing })
    }

    /// Size at a given passing fraction u in [0, 1], linear interpolation (inverse of the
    /// curve): the smallest size whose fraction passing reaches u. u is clamped to [0, 1].
    pub fn size_at(&self, u: f64) -> f64 {
        if u.is_nan() || u <= 0.0 {
            return self.sizes[0];
        }
        let u = u.min(1.0);
        // passing[0] = 0 < u ≤ 1 = passing[last], so 1 ≤ j and passing[j − 1] < u ≤ passing[j].
        let j = self
            .passing
            .iter()
            .position(|&f| f >= u)
            .unwrap_or(self.passing.len() - 1);
        let (f0, f1) = (self.passing[j - 1], self.passing[j]);
        let (d0, d1) = (self.sizes[j - 1], self.sizes[j]);
        d0 + (d1 - d0) * (u - f0) / (f1 - f0)
    }

    /// The largest sieve size (m), passing 1.
    pub fn largest(&self) -> f64 {
        self.sizes[self.sizes.len() - 1]
    }

    /// The smallest sieve size (m), passing 0.
    pub fn smallest(&self) -> f64 {
        self.sizes[0]
    }
}

/// One grading point's size and fraction, each on its own.
fn check_grading_point(index: usize, size: f64, fraction: f64) -> Result<(), SampleError> {
    if !(size.is_finite() && size > 0.0) {
        return Err(SampleError::GradingSize { index, size });
    }
    if !(0.0..=1.0).contains(&fraction) {
        return Err(SampleError::GradingFraction { index, fraction });
    }
    Ok(())
}

/// What to generate.
#[derive(Clone, Debug)]
pub struct SampleSpec {
    /// Lower and upper corner of the box to fill (m).
    pub region: [Vec3; 2],
    /// Number of stones.
    pub count: usize,
    /// The grading the sieve sizes are drawn from (by number, see the module docs).
    pub grading: Grading,
    /// Inclusive range of spheres per stone, e.g. [3, 5]; [1, 1] gives plain spheres.
    pub spheres_per_stone: [usize; 2],
    /// Seed of every random draw.
    pub seed: u64,
}

/// One stone: its spheres in world coordinates (centre, radius).
#[derive(Clone, Debug, PartialEq)]
pub struct Stone {
    /// Sphere centres (m).
    pub centers: Vec<Vec3>,
    /// Sphere radii (m), one per centre.
    pub radii: Vec<f64>,
}

/// `spec.count` stones of the shape and placement described in the module docs, in cell order
/// (x fastest, then y, then z); deterministic for a seed.
pub fn generate_stones(spec: &SampleSpec) -> Result<Vec<Stone>, SampleError> {
    Ok(generate_sized(spec)?
        .into_iter()
        .map(|(_, stone)| stone)
        .collect())
}

/// The stones with the sieve size each was drawn at.
fn generate_sized(spec: &SampleSpec) -> Result<Vec<(f64, Stone)>, SampleError> {
    let [min, max] = spec.spheres_per_stone;
    if min == 0 || min > max {
        return Err(SampleError::SphereCount { min, max });
    }
    let mut shelf = Shelf::new(spec.region, spec.grading.largest(), spec.count)?;
    let mut rng = SplitMix64(spec.seed);
    let mut stones = Vec::with_capacity(spec.count);
    for _ in 0..spec.count {
        let size = spec.grading.size_at(rng.uniform());
        let (centers, radii) = clump_shape(size, spec.spheres_per_stone, &mut rng);
        let rotation = random_rotation(&mut rng);
        let centers = centers.iter().map(|c| rotation * c).collect();
        let mut stone = Stone { centers, radii };
        let [low, high] = bounding_box(&stone);
        let Some(corner) = shelf.place(high - low) else {
            return Err(shelf.too_small(stones.len(), spec.count));
        };
        for c in &mut stone.centers {
            *c += corner - low;
        }
        stones.push((size, stone));
    }
    Ok(stones)
}

/// The axis-aligned bounding box of a stone's spheres.
fn bounding_box(stone: &Stone) -> [Vec3; 2] {
    let spheres = stone.centers.iter().zip(&stone.radii);
    let low = spheres
        .clone()
        .fold(Vec3::repeat(f64::INFINITY), |l, (c, r)| {
            l.inf(&(c - Vec3::repeat(*r)))
        });
    let high = spheres.fold(Vec3::repeat(f64::NEG_INFINITY), |h, (c, r)| {
        h.sup(&(c + Vec3::repeat(*r)))
    });
    [low, high]
}

/// Shelf packing of boxes into the region (module docs).
struct Shelf {
    lower: Vec3,
    upper: Vec3,
    gap: f64,
    /// The largest stone's extent bound plus the gap (m).
    cell: f64,
    /// Where the next box goes.
    cursor: Vec3,
    /// Depth of the current row and height of the current layer.
    row_depth: f64,
    layer_height: f64,
    /// Layers started.
    layers: usize,
}

impl Shelf {
    /// The packing of `region` for stones up to sieve size `largest`.
    fn new(region: [Vec3; 2], largest: f64, count: usize) -> Result<Shelf, SampleError> {
        let [lower, upper] = region;
        let extent = upper - lower;
        if !(lower.iter().chain(upper.iter()).all(|v| v.is_finite())
            && extent.iter().all(|&e| e > 0.0))
        {
            return Err(SampleError::Region {
                lower: lower.into(),
                upper: upper.into(),
            });
        }
        let gap = GAP * largest;
        let cell = EXTENT * largest + gap;
        if count > 0 && (extent.x < cell || extent.y < cell) {
            return Err(SampleError::RegionTooNarrow {
                width: extent.x,
                depth: extent.y,
                cell,
            });
        }
        let margin = Vec3::repeat(0.5 * gap);
        Ok(Shelf {
            lower: lower + margin,
            upper: upper - margin,
            gap,
            cell,
            cursor: lower + margin,
            row_depth: 0.0,
            layer_height: 0.0,
            layers: 1,
        })
    }

    /// The lower corner for a box of `size`, or `None` when the region is full.
    fn place(&mut self, size: Vec3) -> Option<Vec3> {
        if self.cursor.x + size.x > self.upper.x {
            self.cursor.x = self.lower.x;
            self.cursor.y += self.row_depth + self.gap;
            self.row_depth = 0.0;
        }
        if self.cursor.y + size.y > self.upper.y {
            self.cursor.x = self.lower.x;
            self.cursor.y = self.lower.y;
            self.cursor.z += self.layer_height + self.gap;
            self.layer_height = 0.0;
            self.layers += 1;
        }
        if self.cursor.z + size.z > self.upper.z {
            return None;
        }
        let corner = self.cursor;
        self.cursor.x += size.x + self.gap;
        self.row_depth = self.row_depth.max(size.y);
        self.layer_height = self.layer_height.max(size.z);
        Some(corner)
    }

    /// The error for a region that took `fit` of `count` stones.
    fn too_small(&self, fit: usize, count: usize) -> SampleError {
        // Layers as full as those so far (the last, partial one included, so an
        // overestimate), as high on average, plus one of the largest stones.
        let layers = self.layers as f64;
        let per_layer = (fit as f64 / layers).max(1.0);
        let mean_height = (self.cursor.z + self.layer_height - self.lower.z) / layers;
        let needed = (count as f64 / per_layer).ceil() * (mean_height + self.gap);
        SampleError::RegionTooSmall {
            count,
            fit,
            needed_height: needed + self.cell + self.gap,
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

/// Centres (in the stone's frame) and radii of a clump of sieve size `size` (module docs).
fn clump_shape(size: f64, spheres: [usize; 2], rng: &mut SplitMix64) -> (Vec<Vec3>, Vec<f64>) {
    let k = integer_in(rng, spheres);
    let half = 0.5 * size;
    if k == 1 {
        return (vec![Vec3::zeros()], vec![half]);
    }
    let a = half * uniform_in(rng, LONG_AXIS);
    let b = half * uniform_in(rng, MID_AXIS);
    let c = half * uniform_in(rng, SHORT_AXIS);
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

/// A uniformly random rotation (Shoemake's random unit quaternion).
fn random_rotation(rng: &mut SplitMix64) -> UnitQuaternion<f64> {
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

    /// Railway ballast 31.5/63 (EN 13450-like), sizes in m.
    fn ballast() -> Grading {
        Grading::new(vec![
            (0.0224, 0.0),
            (0.0315, 0.03),
            (0.040, 0.2),
            (0.050, 0.6),
            (0.063, 1.0),
        ])
        .unwrap()
    }

    fn spec(upper: [f64; 3], count: usize, spheres: [usize; 2], seed: u64) -> SampleSpec {
        SampleSpec {
            region: [Vec3::zeros(), Vec3::from(upper)],
            count,
            grading: ballast(),
            spheres_per_stone: spheres,
            seed,
        }
    }

    #[test]
    fn stones_are_seeded_disjoint_inside_the_region_and_of_the_asked_sphere_counts() {
        let s = spec([0.5, 0.5, 0.4], 120, [3, 5], 11);
        let stones = generate_stones(&s).unwrap();
        assert_eq!(stones.len(), 120);
        assert_eq!(stones, generate_stones(&s).unwrap());
        let other = generate_stones(&SampleSpec {
            seed: 12,
            ..s.clone()
        })
        .unwrap();
        assert_ne!(stones, other);
        let [lower, upper] = s.region;
        for stone in &stones {
            assert!((3..=5).contains(&stone.centers.len()));
            assert_eq!(stone.centers.len(), stone.radii.len());
            for (c, r) in stone.centers.iter().zip(&stone.radii) {
                for a in 0..3 {
                    assert!(c[a] - r >= lower[a] && c[a] + r <= upper[a], "{c} {r}");
                }
            }
        }
        for (i, a) in stones.iter().enumerate() {
            for b in &stones[i + 1..] {
                for (ca, ra) in a.centers.iter().zip(&a.radii) {
                    for (cb, rb) in b.centers.iter().zip(&b.radii) {
                        assert!(
                            (ca - cb).norm() > ra + rb,
                            "stones overlap at {ca} and {cb}"
                        );
                    }
                }
            }
        }
    }

    #[test]
    fn clumps_follow_the_shape_rule() {
        let s = spec([0.5, 0.5, 0.4], 120, [3, 5], 5);
        for (d, stone) in generate_sized(&s).unwrap() {
            assert!((s.grading.smallest()..=s.grading.largest()).contains(&d));
            for (i, (ci, ri)) in stone.centers.iter().zip(&stone.radii).enumerate() {
                // r = c·U(0.85, 1), c = d/2·U(0.5, 0.75).
                assert!(
                    *ri >= 0.85 * 0.25 * d && *ri <= 0.375 * d,
                    "radius {ri} at d {d}"
                );
                // Within the ball of radius a ≤ 0.65 d: any two surfaces within 1.3 d.
                for (cj, rj) in stone.centers.iter().zip(&stone.radii).skip(i + 1) {
                    assert!((ci - cj).norm() + ri + rj <= EXTENT * d * (1.0 + 1e-12));
                }
            }
        }
    }

    #[test]
    fn drawn_sizes_reproduce_the_grading_by_number() {
        // 2000 stones in 13 × 13 × 12 cells of 1.32 × 63 mm.
        let median_of = |mut sizes: Vec<f64>| {
            sizes.sort_by(f64::total_cmp);
            0.5 * (sizes[999] + sizes[1000])
        };
        let expected = ballast().size_at(0.5);
        assert!((expected - 0.0475).abs() < 1e-12);
        // Plain spheres have radius d/2, so the public output shows the drawn sizes.
        let spheres = generate_stones(&spec([1.1, 1.1, 1.0], 2000, [1, 1], 3)).unwrap();
        let from_spheres = median_of(spheres.iter().map(|s| 2.0 * s.radii[0]).collect());
        let clumps = generate_sized(&spec([1.1, 1.1, 1.0], 2000, [3, 5], 3)).unwrap();
        let from_clumps = median_of(clumps.iter().map(|&(d, _)| d).collect());
        // Standard error of the median: sqrt(1/(4n)) / F'(d) = 0.0112 / (40 /m) = 0.28 mm, 0.6%:
        // 5% is over 8 standard errors.
        for median in [from_spheres, from_clumps] {
            assert!((median / expected - 1.0).abs() < 0.05, "median {median} m");
        }
    }

    #[test]
    fn size_at_inverts_the_curve() {
        let g = ballast();
        assert_eq!(g.size_at(0.0), 0.0224);
        assert_eq!(g.size_at(1.0), 0.063);
        assert!((g.size_at(0.4) - 0.045).abs() < 1e-15);
        // A flat stretch (no stones between 0.03 and 0.04) is skipped.
        let flat = Grading::new(vec![(0.02, 0.0), (0.03, 0.5), (0.04, 0.5), (0.05, 1.0)]).unwrap();
        assert!((flat.size_at(0.5) - 0.03).abs() < 1e-15);
        assert!((flat.size_at(0.75) - 0.045).abs() < 1e-15);
    }

    #[test]
    fn too_small_a_region_says_how_many_fit_and_how_tall_it_must_be() {
        let err = generate_stones(&spec([0.5, 0.5, 0.3], 2000, [3, 5], 1)).unwrap_err();
        let SampleError::RegionTooSmall {
            fit, needed_height, ..
        } = err
        else {
            panic!("{err}")
        };
        assert!(fit > 0 && fit < 2000, "{fit}");
        // The height asked for holds them all.
        let tall = spec([0.5, 0.5, needed_height], 2000, [3, 5], 1);
        assert_eq!(generate_stones(&tall).unwrap().len(), 2000);
        assert!(
            err.to_string().contains(&format!("holds {fit} stones")),
            "{err}"
        );
        let narrow = generate_stones(&spec([0.05, 0.5, 0.3], 1, [1, 1], 1)).unwrap_err();
        assert!(
            matches!(narrow, SampleError::RegionTooNarrow { .. }),
            "{narrow}"
        );
        let upside_down = generate_stones(&spec([0.5, -0.5, 0.3], 1, [1, 1], 1)).unwrap_err();
        assert!(
            matches!(upside_down, SampleError::Region { .. }),
            "{upside_down}"
        );
    }

    #[test]
    fn bad_gradings_and_inputs_are_refused() {
        let bad = |points: Vec<(f64, f64)>| Grading::new(points).unwrap_err();
        assert!(matches!(
            bad(vec![(0.02, 0.0)]),
            SampleError::GradingTooShort { given: 1 }
        ));
        assert!(matches!(
            bad(vec![(0.04, 0.0), (0.03, 1.0)]),
            SampleError::GradingNotIncreasing { index: 1, .. }
        ));
        assert!(matches!(
            bad(vec![(0.02, 0.0), (0.03, 0.6), (0.04, 0.4), (0.05, 1.0)]),
            SampleError::GradingDecreasing { index: 2, .. }
        ));
        assert!(matches!(
            bad(vec![(0.02, 0.0), (0.03, 60.0)]),
            SampleError::GradingFraction { index: 1, .. }
        ));
        assert!(matches!(
            bad(vec![(0.02, 0.1), (0.03, 1.0)]),
            SampleError::GradingEnds { .. }
        ));
        assert!(matches!(
            bad(vec![(0.02, 0.0), (0.03, 0.9)]),
            SampleError::GradingEnds { .. }
        ));
        assert!(matches!(
            bad(vec![(0.0, 0.0), (0.03, 1.0)]),
            SampleError::GradingSize { index: 0, .. }
        ));
        for spheres in [[0, 3], [5, 3]] {
            let err = generate_stones(&spec([0.5, 0.5, 0.5], 1, spheres, 1)).unwrap_err();
            assert!(matches!(err, SampleError::SphereCount { .. }), "{err}");
        }
        let stone = Stone {
            centers: vec![Vec3::zeros()],
            radii: vec![0.01],
        };
        assert!(matches!(
            clump_mass_properties(&stone, 0.0),
            Err(SampleError::Density { .. })
        ));
        let empty = Stone {
            centers: vec![],
            radii: vec![],
        };
        assert!(matches!(
            clump_mass_properties(&empty, 2600.0),
            Err(SampleError::Stone { .. })
        ));
    }
}
