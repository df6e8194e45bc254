//! `[granular] refill`: a walled box's whole sample. Cut out of a periodic cell's sample, a
//! box with walls across the cell's ends could keep only the stones wholly inside it and drop
//! those astride the ends (about a tenth of the box test's crib); `refill` keeps them all:
//! each stone that does not lie wholly inside the refill box's x–y extent is moved into it by
//! what it overhangs, plus a gap, and stacked above the sample, to be poured back under
//! gravity in a deposition run. The box then holds the same stones (count, sizes and mass) as
//! the periodic cell.
//!
//! Stacking: the moved stones, in sample order, go one after another, each at the lowest
//! height z ≥ z₀ (the box's lower z) at which its axis-aligned bounding box clears, by the gap
//! g, every stacked box whose x–y extent overlaps its own:
//! z_bottom = max(z₀, max over those of z_top + g). Boxes never overlap, so stones never do;
//! the sample's other stones must lie wholly below z₀, and the stack wholly below the box's
//! upper z. The gap is [`GAP`] of the largest moved stone's extent, as in a generation's
//! shelf packing.

use qdem_contact::samples::clump_sample::Stone;
use qdem_core::Vec3;

/// The gap between stacked boxes, and between a moved stone and the box's sides, as a
/// fraction of the largest moved stone's extent.
pub const GAP: f64 = 0.02;

/// Why a sample cannot be refilled into its box; every message says what to change.
#[derive(Debug, PartialEq, thiserror::Error)]
pub enum RefillError {
    /// A stone is wider than the box along x or y.
    #[error(
        "stone {stone} is {extent:.4} m across along {axis}, wider than the refill box \
         ({width:.4} m with its gaps); fix: widen refill along {axis}"
    )]
    TooWide {
        /// The stone (from 1, in sample order).
        stone: usize,
        /// `"x"` or `"y"`.
        axis: &'static str,
        /// The stone's extent (m).
        extent: f64,
        /// The box's width less two gaps (m).
        width: f64,
    },
    /// A stone the refill leaves in place reaches above the stack's floor.
    #[error(
        "stone {stone} reaches z = {top:.4} m, above the refill box's lower z = {floor} m, \
         where the moved stones are stacked; fix: raise refill's lower z above the sample"
    )]
    SampleAboveFloor {
        /// The stone (from 1, in sample order).
        stone: usize,
        /// Its highest point (m).
        top: f64,
        /// The box's lower z (m).
        floor: f64,
    },
    /// The stack reaches above the box.
    #[error(
        "the {moved} stones moved in stack up to z = {top:.4} m, above the refill box's upper \
         z = {ceiling} m; fix: raise refill's upper z to at least {top:.4}"
    )]
    StackTooHigh {
        /// The stones moved.
        moved: usize,
        /// The stack's top (m).
        top: f64,
        /// The box's upper z (m).
        ceiling: f64,
    },
}

/// The axis-aligned bounding box of a stone's spheres.
fn bounds(stone: &Stone) -> [Vec3; 2] {
    let spheres = stone.centers.iter().zip(&stone.radii);
    spheres.fold(
        [Vec3::repeat(f64::INFINITY), Vec3::repeat(f64::NEG_INFINITY)],
        |[lo, hi], (c, &r)| {
            [
                lo.inf(&(c - Vec3::repeat(r))),
                hi.sup(&(c + Vec3::repeat(r))),
            ]
        },
    )
}

/// Whether a stone's box lies inside `[lo, hi]` along x and y.
fn inside_xy([lo, hi]: &[Vec3; 2], [blo, bhi]: &[Vec3; 2]) -> bool {
    (0..2).all(|k| blo[k] >= lo[k] && bhi[k] <= hi[k])
}

/// The shift along x and y that brings a box `[blo, bhi]` inside `[lo, hi]` by `gap` from
/// every side it overhangs (zero along an axis where it lies inside).
fn shift_xy(
    stone: usize,
    [lo, hi]: &[Vec3; 2],
    [blo, bhi]: &[Vec3; 2],
    gap: f64,
) -> Result<Vec3, RefillError> {
    let mut shift = Vec3::zeros();
    for (k, axis) in [(0, "x"), (1, "y")] {
        let (extent, width) = (bhi[k] - blo[k], hi[k] - lo[k] - 2.0 * gap);
        if extent > width {
            return Err(RefillError::TooWide {
                stone,
                axis,
                extent,
                width,
            });
        }
        if blo[k] < lo[k] {
            shift[k] = lo[k] + gap - blo[k];
        } else if bhi[k] > hi[k] {
            shift[k] = hi[k] - gap - bhi[k];
        }
    }
    Ok(shift)
}

/// Whether two boxes' x–y extents, each grown by `gap`, overlap.
fn overlap_xy(a: &[Vec3; 2], b: &[Vec3; 2], gap: f64) -> bool {
    (0..2).all(|k| a[0][k] < b[1][k] + gap && b[0][k] < a[1][k] + gap)
}

/// `stones` with those not wholly inside `refill`'s x–y extent moved into it and stacked from
/// its lower z (module docs); returns the stones, in their order, and how many moved.
pub fn refill(
    stones: Vec<Stone>,
    refill: [[f64; 3]; 2],
) -> Result<(Vec<Stone>, usize), RefillError> {
    let area = [Vec3::from(refill[0]), Vec3::from(refill[1])];
    let boxes: Vec<[Vec3; 2]> = stones.iter().map(bounds).collect();
    let moving: Vec<bool> = boxes.iter().map(|b| !inside_xy(&area, b)).collect();
    let gap = GAP
        * boxes
            .iter()
            .zip(&moving)
            .filter(|(_, &m)| m)
            .map(|([lo, hi], _)| (hi - lo).max())
            .fold(0.0, f64::max);
    for (k, b) in boxes.iter().enumerate() {
        if !moving[k] && b[1].z > area[0].z {
            return Err(RefillError::SampleAboveFloor {
                stone: k + 1,
                top: b[1].z,
                floor: area[0].z,
            });
        }
    }
    let mut stacked: Vec<[Vec3; 2]> = Vec::new();
    let mut out = Vec::with_capacity(stones.len());
    for (k, (mut stone, b)) in stones.into_iter().zip(&boxes).enumerate() {
        if moving[k] {
            let mut shift = shift_xy(k + 1, &area, b, gap)?;
            let moved = [b[0] + shift, b[1] + shift];
            let floor = stacked
                .iter()
                .filter(|s| overlap_xy(s, &moved, gap))
                .map(|s| s[1].z + gap)
                .fold(area[0].z, f64::max);
            shift.z = floor - b[0].z;
            stacked.push([b[0] + shift, b[1] + shift]);
            for c in &mut stone.centers {
                *c += shift;
            }
        }
        out.push(stone);
    }
    let top = stacked.iter().map(|s| s[1].z).fold(area[0].z, f64::max);
    if top > area[1].z {
        return Err(RefillError::StackTooHigh {
            moved: stacked.len(),
            top,
            ceiling: area[1].z,
        });
    }
    Ok((out, stacked.len()))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn ball(c: [f64; 3], r: f64) -> Stone {
        Stone {
            centers: vec![Vec3::from(c)],
            radii: vec![r],
        }
    }

    /// Whether two stones' spheres overlap.
    fn touch(a: &Stone, b: &Stone) -> bool {
        a.centers.iter().zip(&a.radii).any(|(ca, ra)| {
            b.centers
                .iter()
                .zip(&b.radii)
                .any(|(cb, rb)| (ca - cb).norm() < ra + rb)
        })
    }

    const BOX: [[f64; 3]; 2] = [[0.0, 0.7, 0.5], [0.3, 1.4, 2.0]];

    #[test]
    fn the_stones_astride_the_ends_are_moved_inside_and_stacked_clear_of_each_other() {
        // Two stones inside, three astride y = 0.7 or 1.4 at the same x: each moved inside by
        // its overhang plus the gap, stacked one on another without overlap, all kept.
        let stones = vec![
            ball([0.1, 1.0, 0.1], 0.05),
            ball([0.1, 0.69, 0.1], 0.05),
            ball([0.2, 1.2, 0.3], 0.05),
            ball([0.1, 0.72, 0.2], 0.04),
            ball([0.12, 1.41, 0.4], 0.05),
        ];
        let (out, moved) = refill(stones.clone(), BOX).unwrap();
        assert_eq!(moved, 3);
        assert_eq!(out.len(), 5);
        let gap = GAP * 0.1;
        // Unmoved stones keep their place, bit for bit.
        assert_eq!(out[0].centers, stones[0].centers);
        assert_eq!(out[2].centers, stones[2].centers);
        // The first moved one: inside y = 0.7 by the gap, its bottom on the floor.
        let c = out[1].centers[0];
        assert!((c.y - 0.05 - (0.7 + gap)).abs() < 1e-12, "{c:?}");
        assert!((c.z - 0.05 - 0.5).abs() < 1e-12, "{c:?}");
        // The second overlaps it in x-y: stacked a gap above it.
        let c2 = out[3].centers[0];
        assert!((c2.z - 0.04 - (0.6 + gap)).abs() < 1e-12, "{c2:?}");
        // The third is at the other end: on the floor.
        let c3 = out[4].centers[0];
        assert!((c3.y + 0.05 - (1.4 - gap)).abs() < 1e-12, "{c3:?}");
        assert!((c3.z - 0.05 - 0.5).abs() < 1e-12, "{c3:?}");
        for (i, a) in out.iter().enumerate() {
            for b in &out[i + 1..] {
                assert!(!touch(a, b));
            }
        }
        // The radii and the stones' shapes are kept: the mass is the same.
        for (a, b) in out.iter().zip(&stones) {
            assert_eq!(a.radii, b.radii);
        }
    }

    #[test]
    fn a_refill_that_cannot_hold_the_stones_is_refused_with_the_fix() {
        let wide = vec![ball([0.15, 0.7, 0.1], 0.2)];
        let e = refill(wide, BOX).unwrap_err();
        assert!(
            matches!(
                e,
                RefillError::TooWide {
                    stone: 1,
                    axis: "x",
                    ..
                }
            ),
            "{e}"
        );
        let high = vec![ball([0.15, 1.0, 0.48], 0.05), ball([0.15, 0.7, 0.1], 0.05)];
        let e = refill(high, BOX).unwrap_err();
        assert!(e.to_string().contains("raise refill's lower z"), "{e}");
        let low_ceiling = [[0.0, 0.7, 0.5], [0.3, 1.4, 0.55]];
        let e = refill(vec![ball([0.15, 0.7, 0.1], 0.05)], low_ceiling).unwrap_err();
        assert!(
            matches!(e, RefillError::StackTooHigh { moved: 1, .. }),
            "{e}"
        );
    }
}
