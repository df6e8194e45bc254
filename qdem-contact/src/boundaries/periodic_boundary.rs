//! Periodic boundaries along any of the three axes (paper 003 §4, Eq. 1).
//!
//! A periodic axis k has an origin o_k and a period L_k. Paper 003 creates a ghost particle at
//! x_o ± L (Eq. 1) when a particle touches a boundary; the ghost has the original's velocity and
//! its force goes to the original. Here the ghost is implicit: a pair's separation is taken as
//! its *minimum image*, d_k − L_k·round(d_k / L_k), so two spheres near opposite boundaries
//! touch through the boundary exactly as an original and its ghost would, the contact force
//! reaching both originals, with no copies to keep in step. Because only differences modulo L
//! enter, results do not depend on where the packing sits along a periodic axis (translation
//! invariance, up to round-off).
//!
//! Bodies are wrapped as wholes ([`PeriodicBox::wrap_bodies`]): when a body's anchor particle
//! leaves [o_k, o_k + L_k), every particle of the body (a deformable body's nodes, a rigid
//! body's centre and members) moves by ±L_k together with its reference position, so a body
//! straddling a boundary is never torn apart and its displacement field stays continuous.

use crate::error::ContactError;
use qdem_core::{step::State, Vec3};

/// `s.round()` (half away from zero), bit for bit, without the library call that baseline
/// x86-64 makes of it (no SSE4.1 `roundsd`): the minimum image takes it for every candidate
/// pair at every step. The cast truncates toward zero and s − trunc(s) is exact, so the
/// remainder decides the rounding without error; the sign of a zero result follows `s` as
/// `round` has it. Beyond 2^52 every double is whole, and NaN goes to `round` itself.
#[inline]
fn round_half_away(s: f64) -> f64 {
    if s.is_nan() || s.abs() >= 4.5e15 {
        return s.round();
    }
    let whole = ((s as i64) as f64).copysign(s);
    let rest = s - whole;
    if rest >= 0.5 {
        whole + 1.0
    } else if rest <= -0.5 {
        whole - 1.0
    } else {
        whole
    }
}

/// `s.floor()`, bit for bit, without the library call (as [`round_half_away`]): every body's
/// anchor is tested against the cell at every step, and nearly every anchor is inside it,
/// where `s` lies in [0, 1) and its floor is the zero of its sign, by two comparisons.
#[inline]
fn floor_inline(s: f64) -> f64 {
    if (0.0..1.0).contains(&s) {
        return 0.0f64.copysign(s);
    }
    if s.is_nan() || s.abs() >= 4.5e15 {
        return s.floor();
    }
    let whole = ((s as i64) as f64).copysign(s);
    if s - whole < 0.0 {
        whole - 1.0
    } else {
        whole
    }
}

/// The periodic axes of a scene.
#[derive(Clone, Debug, PartialEq)]
pub struct PeriodicBox {
    origin: Vec3,
    length: [Option<f64>; 3],
}

/// A set of particles that wrap together, decided by one of them.
#[derive(Clone, Debug, PartialEq)]
pub struct WrapGroup {
    /// The particle whose position decides when the group wraps (a rigid body's centre, the
    /// node nearest a deformable body's centroid).
    pub anchor: usize,
    /// Every particle of the group, the anchor included.
    pub particles: Vec<usize>,
}

impl PeriodicBox {
    /// Periodic along the axes with a period in `length` (m), with cells starting at `origin`.
    /// Refused unless at least one axis is periodic and every period is positive and finite.
    pub fn new(origin: Vec3, length: [Option<f64>; 3]) -> Result<PeriodicBox, ContactError> {
        let bad = length
            .iter()
            .enumerate()
            .find(|(_, l)| l.is_some_and(|l| !(l.is_finite() && l > 0.0)));
        if let Some((axis, l)) = bad {
            return Err(ContactError::BadPeriod {
                axis: AXES[axis],
                length: l.unwrap_or_default(),
            });
        }
        if length.iter().all(Option::is_none) || !origin.iter().all(|v| v.is_finite()) {
            return Err(ContactError::NoPeriodicAxis);
        }
        Ok(PeriodicBox { origin, length })
    }

    /// The period along `axis`, if it is periodic.
    pub fn length(&self, axis: usize) -> Option<f64> {
        self.length[axis]
    }

    /// The lower corner of the periodic cell (only its periodic components matter).
    pub fn origin(&self) -> Vec3 {
        self.origin
    }

    /// The minimum image of the separation `d` = x_b − x_a: d minus the whole periods that
    /// bring each periodic component into [−L/2, L/2].
    #[inline]
    pub fn minimum_image(&self, d: Vec3) -> Vec3 {
        d + self.image_shift(&d)
    }

    /// The translation t (whole periods per axis) with d + t the minimum image of `d`.
    #[inline]
    pub fn image_shift(&self, d: &Vec3) -> Vec3 {
        let mut t = Vec3::zeros();
        for k in 0..3 {
            if let Some(l) = self.length[k] {
                t[k] = -l * round_half_away(d[k] / l);
            }
        }
        t
    }

    /// The translation (whole periods per axis) that brings `x` into the cell [o, o + L).
    #[inline]
    pub fn shift_into(&self, x: &Vec3) -> Vec3 {
        let mut t = Vec3::zeros();
        for k in 0..3 {
            if let Some(l) = self.length[k] {
                t[k] = -l * floor_inline((x[k] - self.origin[k]) / l);
            }
        }
        t
    }

    /// Whether `x` lies in the cell along every periodic axis, (x_k − o_k)/L_k in [0, 1):
    /// exactly where [`PeriodicBox::shift_into`] is zero (the floor of a quotient is ±0 there
    /// and nowhere else, NaN included), by two comparisons an axis.
    #[inline]
    pub(crate) fn contains(&self, x: &Vec3) -> bool {
        (0..3).all(|k| {
            self.length[k].is_none_or(|l| (0.0..1.0).contains(&((x[k] - self.origin[k]) / l)))
        })
    }

    /// Moves every group whose anchor has left the cell back into it, all its particles
    /// (positions and reference positions) by the same whole periods. Returns how many groups
    /// moved.
    pub fn wrap_bodies(&self, state: &mut State, groups: &[WrapGroup]) -> usize {
        let mut moved = 0;
        for group in groups {
            let anchor = state.position[group.anchor];
            if self.contains(&anchor) {
                continue;
            }
            let shift = self.shift_into(&anchor);
            for &p in &group.particles {
                state.position[p] += shift;
                state.reference[p] += shift;
            }
            moved += 1;
        }
        moved
    }

    /// Refuses a period shorter than twice `reach` (the largest distance at which two spheres
    /// interact, skin included): the minimum image would then be ambiguous.
    pub fn check_reach(&self, reach: f64) -> Result<(), ContactError> {
        for (k, axis) in AXES.iter().enumerate() {
            if let Some(l) = self.length[k] {
                if l <= 2.0 * reach {
                    return Err(ContactError::PeriodTooShort {
                        axis: *axis,
                        length: l,
                        reach,
                    });
                }
            }
        }
        Ok(())
    }
}

/// Axis names for messages.
const AXES: [char; 3] = ['x', 'y', 'z'];

#[cfg(test)]
mod tests {
    use super::*;

    fn along_x(l: f64) -> PeriodicBox {
        PeriodicBox::new(Vec3::new(-1.0, 0.0, 0.0), [Some(l), None, None]).unwrap()
    }

    #[test]
    fn minimum_image_brings_a_separation_within_half_a_period() {
        let p = along_x(2.0);
        // Spheres at x = −0.9 and 0.95 in a cell [−1, 1): 1.85 apart directly, 0.15 through
        // the boundary.
        let d = p.minimum_image(Vec3::new(1.85, 0.3, -5.0));
        assert!((d - Vec3::new(-0.15, 0.3, -5.0)).norm() < 1e-15);
        // Non-periodic components are left alone, and so is a separation already minimal.
        assert_eq!(
            p.minimum_image(Vec3::new(0.4, 9.0, 0.0)),
            Vec3::new(0.4, 9.0, 0.0)
        );
        assert_eq!(
            p.image_shift(&Vec3::new(-3.1, 0.0, 0.0)),
            Vec3::new(4.0, 0.0, 0.0)
        );
    }

    #[test]
    fn the_inline_rounding_is_round_and_floor_bit_for_bit() {
        let mut cases = vec![
            0.0,
            -0.0,
            0.5,
            -0.5,
            1.5,
            -1.5,
            2.5,
            -2.5,
            0.49999999999999994,
            -0.49999999999999994,
            1.0 - f64::EPSILON,
            4503599627370495.5,
            4.5e15,
            -4.5e15,
            1e300,
            f64::INFINITY,
            f64::NEG_INFINITY,
            f64::MIN_POSITIVE,
            -f64::MIN_POSITIVE,
        ];
        // A fixed sequence (xorshift) of values over many magnitudes, and their halves.
        let mut x = 0x9E37_79B9_7F4A_7C15_u64;
        for _ in 0..100_000 {
            x ^= x << 13;
            x ^= x >> 7;
            x ^= x << 17;
            let v = f64::from_bits(x);
            if v.is_finite() {
                cases.push(v);
            }
            let scaled = (x >> 11) as f64 / (1u64 << 53) as f64 * 8.0 - 4.0;
            cases.push(scaled);
            cases.push((scaled * 2.0).round() / 2.0);
        }
        for s in cases {
            assert_eq!(round_half_away(s).to_bits(), s.round().to_bits(), "{s:e}");
            assert_eq!(floor_inline(s).to_bits(), s.floor().to_bits(), "{s:e}");
        }
        assert!(round_half_away(f64::NAN).is_nan() && floor_inline(f64::NAN).is_nan());
    }

    #[test]
    fn the_cell_contains_a_point_exactly_where_it_takes_no_shift() {
        // Along x in [−1, 1) and z in [0, 0.5), y not periodic: points on, just inside and
        // just outside each face, far away, and NaN. The cell contains a point if and only if
        // the shift into it is zero, so the wrap may skip the shift for contained anchors.
        let p = PeriodicBox::new(Vec3::new(-1.0, 0.0, 0.0), [Some(2.0), None, Some(0.5)]).unwrap();
        let edges = |lo: f64, hi: f64| {
            let (below, above) = (|v: f64| v.next_down(), |v: f64| v.next_up());
            vec![
                lo,
                below(lo),
                above(lo),
                hi,
                below(hi),
                above(hi),
                -0.0,
                0.3,
                7.0,
                -7.0,
                f64::NAN,
            ]
        };
        let (mut inside, mut outside) = (0, 0);
        for x in edges(-1.0, 1.0) {
            for z in edges(0.0, 0.5) {
                for y in [0.0, 1e9] {
                    let at = Vec3::new(x, y, z);
                    let still = p.shift_into(&at) == Vec3::zeros();
                    assert_eq!(p.contains(&at), still, "{at:?}");
                    match still {
                        true => inside += 1,
                        false => outside += 1,
                    }
                }
            }
        }
        assert!(
            inside > 10 && outside > 100,
            "{inside} inside, {outside} outside"
        );
    }

    #[test]
    fn bodies_wrap_whole_with_their_reference() {
        let p = along_x(2.0);
        // A body of three particles whose anchor has crossed x = 1 while one node is still
        // inside: all three move by −2, reference included.
        let mut s = State::at_rest(vec![
            Vec3::new(1.05, 0.0, 0.0),
            Vec3::new(0.95, 0.0, 0.0),
            Vec3::new(1.15, 0.0, 0.0),
            Vec3::new(0.0, 0.0, 0.0),
        ]);
        let groups = [
            WrapGroup {
                anchor: 0,
                particles: vec![0, 1, 2],
            },
            WrapGroup {
                anchor: 3,
                particles: vec![3],
            },
        ];
        assert_eq!(p.wrap_bodies(&mut s, &groups), 1);
        assert!((s.position[1].x + 1.05).abs() < 1e-15);
        assert!((s.position[2].x + 0.85).abs() < 1e-15);
        assert_eq!(s.displacement(1), Vec3::zeros());
        assert_eq!(s.position[3], Vec3::zeros());
        // Its internal distances are untouched.
        assert!(((s.position[2] - s.position[1]).norm() - 0.2).abs() < 1e-12);
    }

    #[test]
    fn too_short_or_bad_periods_are_refused() {
        assert!(along_x(0.5).check_reach(0.3).is_err());
        assert!(along_x(0.7).check_reach(0.3).is_ok());
        assert!(PeriodicBox::new(Vec3::zeros(), [None, Some(-1.0), None]).is_err());
        assert!(PeriodicBox::new(Vec3::zeros(), [None, None, None]).is_err());
    }
}
