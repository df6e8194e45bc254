//! Errors of the contact crate: every message names the bodies, spheres or wall at fault and
//! says what to change.

use thiserror::Error;

/// What the contact model refuses.
#[derive(Debug, Error)]
pub enum ContactError {
    /// Two bodies interpenetrate at the start beyond the tolerance.
    #[error(
        "bodies `{a}` and `{b}` overlap by {overlap:.3e} m at the start (spheres at {at_a:?} and \
         {at_b:?}), more than {tolerance:.0}% of their reduced radius {radius:.3e} m; fix: move \
         them apart (`translate` in [[body]]) or use a smaller `contact_radius`"
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
         more than {tolerance:.0}% of the contact radius {radius:.3e} m; fix: move the body \
         (`translate`) or the wall (`point`)"
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
    /// A triangulated wall parry3d could not build.
    #[error("wall `{wall}`: its triangle mesh is unusable: {reason}")]
    MeshWall {
        /// The wall.
        wall: String,
        /// What parry3d said.
        reason: String,
    },
}
