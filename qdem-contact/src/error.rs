//! Errors of the contact crate: every message names the bodies, spheres or wall at fault and
//! says what to change.

use thiserror::Error;

/// What the contact model refuses.
#[derive(Debug, Error)]
pub enum ContactError {
    /// Only a plane wall can be stress-controlled.
    #[error(
        "wall {wall} (from 1) is not a plane: only a plane wall can be stress-controlled; fix: \
         give it `point` and `normal`, or drop its `servo`"
    )]
    ServoNotPlane {
        /// The wall, from 1.
        wall: usize,
    },
    /// A beam lattice cannot represent the material's Poisson's ratio.
    #[error(
        "bonded body `{body}`: a triangular beam lattice represents Poisson's ratios from about \
         0.16 to below 1/3 (bonds with a non-negative shear coefficient), not {poisson}; fix: \
         give `poisson` in that range"
    )]
    LatticePoisson {
        /// Body name.
        body: String,
        /// The ratio asked for.
        poisson: f64,
    },
    /// The rectangle is too small for the element size.
    #[error(
        "bonded body `{body}`: the rectangle {size:?} m holds fewer than two rows or columns at \
         element size {element_size} m; fix: use a smaller `element_size`"
    )]
    TooCoarse {
        /// Body name.
        body: String,
        /// Rectangle size.
        size: [f64; 2],
        /// Element size.
        element_size: f64,
    },
    /// Two bodies interpenetrate at the start beyond the tolerance.
    #[error(
        "bodies `{a}` and `{b}` overlap by {overlap:.3e} m at the start (spheres at {at_a:?} and \
         {at_b:?}), more than {tolerance:.2}% of their reduced radius {radius:.3e} m; fix: move \
         them apart, use smaller contact spheres or allow a larger initial overlap"
    )]
    InitialOverlap {
        /// First body.
        a: String,
        /// Second body.
        b: String,
        /// The overlap (m).
        overlap: f64,
        /// Reduced radius of the pair (m).
        radius: f64,
        /// Tolerance in percent of the reduced radius.
        tolerance: f64,
        /// Centre of the sphere of `a`.
        at_a: [f64; 3],
        /// Centre of the sphere of `b`.
        at_b: [f64; 3],
    },
    /// A body penetrates a wall at the start beyond the tolerance.
    #[error(
        "body `{body}` penetrates wall {wall} by {overlap:.3e} m at the start (sphere at {at:?}), \
         more than {tolerance:.2}% of the contact radius {radius:.3e} m; fix: move the body or \
         the wall, or allow a larger initial overlap"
    )]
    InitialWallOverlap {
        /// The body.
        body: String,
        /// Wall number (1-based, scene order).
        wall: usize,
        /// The overlap (m).
        overlap: f64,
        /// The sphere's radius (m).
        radius: f64,
        /// Tolerance in percent.
        tolerance: f64,
        /// Centre of the sphere.
        at: [f64; 3],
    },
    /// A body starts inside another body or a mesh wall.
    #[error(
        "body `{body}` starts inside {inside}: the centre of its contact sphere at {at:?} is \
         {depth:.3e} m inside it (the sphere radius is {radius:.3e} m), where no contact \
         holds the two apart; fix: place it outside {inside}"
    )]
    InitialInside {
        /// The body.
        body: String,
        /// What it is inside: "body `name`" or "wall #k".
        inside: String,
        /// How far inside (m).
        depth: f64,
        /// The sphere radius (m).
        radius: f64,
        /// Centre of the sphere.
        at: [f64; 3],
    },
    /// A triangulated wall parry3d could not build.
    #[error("wall `{wall}`: its triangle mesh is unusable: {reason}")]
    MeshWall {
        /// The wall.
        wall: String,
        /// What parry3d said.
        reason: String,
    },
    /// A period that is not a positive length.
    #[error("periodic axis {axis}: the period {length} m is not a positive length; fix: give `length` > 0 for every axis in `axes`")]
    BadPeriod {
        /// The axis.
        axis: char,
        /// The period given (m).
        length: f64,
    },
    /// A periodic box without a periodic axis, or with a non-finite origin.
    #[error("a periodic box needs at least one periodic axis and a finite origin; fix: set `axes` (e.g. \"y\") and `origin`")]
    NoPeriodicAxis,
    /// A period too short for the spheres that interact across it.
    #[error(
        "periodic axis {axis}: the period {length} m is not longer than twice the contact reach \
         {reach:.4} m (two sphere radii plus the skin), so a sphere could touch another and its \
         image at once; fix: a longer period, or smaller spheres or skin"
    )]
    PeriodTooShort {
        /// The axis.
        axis: char,
        /// The period (m).
        length: f64,
        /// Largest interaction distance (m).
        reach: f64,
    },
    /// A time delay along an axis that is not periodic.
    #[error("a time-delayed boundary along {axis} needs that axis periodic; fix: add it to `axes` in [periodic]")]
    TimeDelayNotPeriodic {
        /// The axis.
        axis: char,
    },
    /// A rolling friction coefficient that is negative or not a number.
    #[error("rolling friction {coefficient} is not a non-negative number; fix: set `rolling_friction` in [contact] to μ_r ≥ 0 (0 or absent: none)")]
    RollingFriction {
        /// The coefficient given.
        coefficient: f64,
    },
}
