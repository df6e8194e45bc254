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
                t[k] = -l * (d[k] / l).round();
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
                t[k] = -l * ((x[k] - self.origin[k]) / l).floor();
            }
        }
        t
    }

    /// Moves every group whose anchor has left the cell back into it, all its particles
    /// (positions and reference positions) by the same whole periods. Returns how many groups
    /// moved.
    pub fn wrap_bodies(&self, state: &mut State, groups: &[WrapGroup]) -> usize {
        let mut moved = 0;
        for group in groups {
            let shift = self.shift_into(&state.position[group.anchor]);
            if shift == Vec3::zeros() {
                continue;
            }
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
