//! [`BuildError`]: why a scene could not be turned into a simulation, each variant naming the
//! scene file (or the data file) and saying how to fix it.

use qdem_core::error::CoreError;
use qdem_mesh::MeshError;
use std::path::PathBuf;
use thiserror::Error;

/// Why a scene could not be turned into a simulation.
#[derive(Debug, Error)]
pub enum BuildError {
    /// A mesh could not be read or lacks a group.
    #[error(transparent)]
    Mesh(#[from] MeshError),
    /// The core refused a body, a ramp or the time step.
    #[error("{scene}: {source}")]
    Core {
        /// The scene file.
        scene: PathBuf,
        /// What the core refused.
        source: CoreError,
    },
    /// A fix or load names a physical group the body's mesh does not have.
    #[error(
        "{scene}: {what}: the mesh {mesh} has no physical group `{group}`{candidates}; fix: \
         name one of them, or select particles with box = [[xmin, ymin, zmin], [xmax, ymax, zmax]]"
    )]
    MissingGroup {
        /// The scene file.
        scene: PathBuf,
        /// `[[fix]] #N on body `name`` or the same for a load.
        what: String,
        /// The mesh file.
        mesh: String,
        /// The requested group.
        group: String,
        /// `; did you mean `…`?` if a name is close, then `(available: …)`.
        candidates: String,
    },
    /// The contact set-up is refused (initial overlap, a bad wall, a sphere too large).
    #[error("{scene}: {source}")]
    Contact {
        /// The scene file.
        scene: PathBuf,
        /// What is wrong.
        source: Box<qdem_contact::ContactError>,
    },
    /// The start is refused by the contact set-up: two bodies overlap, a body penetrates a
    /// wall or starts inside another; `fix` names the scene keys of their tables.
    #[error("{scene}: {source}; in this scene: {fix}")]
    InitialOverlap {
        /// The scene file.
        scene: PathBuf,
        /// What the contact set-up refused.
        source: Box<qdem_contact::ContactError>,
        /// The keys to change, table by table.
        fix: String,
    },
    /// A body's contact radius is too large for it.
    #[error(
        "{scene}: body `{body}`: contact_radius = {radius} m is more than half its smallest \
         extent {extent:.4e} m, so its spheres stick out through the opposite side: use a \
         radius of at most {limit:.4e} m"
    )]
    ContactRadius {
        /// The scene file.
        scene: PathBuf,
        /// The body.
        body: String,
        /// Its contact radius.
        radius: f64,
        /// Its smallest bounding-box extent.
        extent: f64,
        /// Half that extent.
        limit: f64,
    },
    /// A `[[probe]] stone` beyond the sample's stones.
    #[error(
        "{scene}: [[probe]] {probe:?}: stone = {stone}, but the [granular] sample has {count} \
         stones; give a number from 1 to {count}, or a point"
    )]
    ProbeStone {
        /// The scene file.
        scene: PathBuf,
        /// The probe.
        probe: String,
        /// The stone asked for (from 1).
        stone: usize,
        /// The stones there are.
        count: usize,
    },
    /// A `[granular]` sample or its generation is refused.
    #[error("{scene}: [granular]: {source}")]
    Granular {
        /// The scene file.
        scene: PathBuf,
        /// What is wrong.
        source: qdem_contact::samples::clump_sample::SampleError,
    },
    /// `[granular] refill` cannot hold the sample's stones.
    #[error("{scene}: [granular] refill: {source}")]
    Refill {
        /// The scene file.
        scene: PathBuf,
        /// What is wrong.
        source: super::refill::RefillError,
    },
    /// A body's `rest_on` finds no stone beneath it.
    #[error(
        "{scene}: body `{body}`: rest_on: no stone lies beneath its contact spheres, so it has \
         nothing to rest on; fix: translate the body over the sample, or drop rest_on"
    )]
    RestOn {
        /// The scene file.
        scene: PathBuf,
        /// The body.
        body: String,
    },
    /// A body's `pose_from` file has no row for it (or for its `pose_body`).
    #[error(
        "{scene}: pose_from: {path} has no pose for a body `{body}`; fix: name the body (or \
         its pose_body) as in the run that wrote the file, or drop pose_from"
    )]
    PoseMissing {
        /// The scene file.
        scene: PathBuf,
        /// The body whose pose was looked for.
        body: String,
        /// The poses file.
        path: PathBuf,
    },
    /// A poses file is malformed.
    #[error(
        "{path}:{line}: {message} (a poses file is CSV `body,x,y,z,qw,qx,qy,qz`, one row per \
         rigid body, as a run writes it)"
    )]
    Poses {
        /// The file.
        path: PathBuf,
        /// Line number (1-based; 0 when the file could not be read).
        line: usize,
        /// What is wrong.
        message: String,
    },
    /// A stones file is malformed.
    #[error(
        "{path}:{line}: {message} (a stones file is CSV `stone,x,y,z,radius`, one row per sphere)"
    )]
    Sample {
        /// The file.
        path: PathBuf,
        /// Line number (1-based; 0 when the file could not be read).
        line: usize,
        /// What is wrong.
        message: String,
    },
    /// `[ballast]` stones cannot be made or placed.
    #[error("{scene}: [ballast]: {message}")]
    Ballast {
        /// The scene file.
        scene: PathBuf,
        /// What is wrong and how to fix it.
        message: String,
    },
    /// A load's series file is malformed.
    #[error(
        "{path}:{line}: {message} (a series file is CSV with a header row, time in s in the \
         first column, rows in non-decreasing time)"
    )]
    Series {
        /// The file.
        path: PathBuf,
        /// Line number (1-based; 0 when the file could not be read).
        line: usize,
        /// What is wrong.
        message: String,
    },
    /// `[run] start_from` cannot be used.
    #[error("{scene}: [run] start_from {checkpoint}: {message}")]
    StartFrom {
        /// The scene file.
        scene: PathBuf,
        /// The checkpoint.
        checkpoint: PathBuf,
        /// What is wrong and how to fix it.
        message: String,
    },
    /// A `[[fix]]`'s local frame cannot hold a node: a node on a cylindrical frame's axis,
    /// or a node two fixes hold in oblique directions (`super::fix_frames`).
    #[error("{scene}: {message}")]
    FixFrame {
        /// The scene file.
        scene: PathBuf,
        /// The fixes, the node, and the fix.
        message: String,
    },
    /// A fix or load selects no particle.
    #[error("{scene}: {what} on body `{body}` selects no particle: {fix}")]
    EmptySelection {
        /// The scene file.
        scene: PathBuf,
        /// `[[fix]]` or `[[load]]` with its index.
        what: String,
        /// The body.
        body: String,
        /// How to fix it.
        fix: &'static str,
    },
    /// A `pressure` or `traction` whose selection is not a face of the body: a volume group
    /// (every node of the body, so the whole closed boundary), or nodes with no boundary
    /// triangle among them (a point or a line).
    #[error("{scene}: {what} on body `{body}`: {message}")]
    NotAFace {
        /// The scene file.
        scene: PathBuf,
        /// `[[load]] #N`.
        what: String,
        /// The body.
        body: String,
        /// What the selection holds, what the load would do, and the fix.
        message: String,
    },
    /// A count whose particles would need more memory than the machine has, refused before
    /// they are allocated ([`super::memory`]).
    #[error("{scene}: {message}")]
    Memory {
        /// The scene file.
        scene: PathBuf,
        /// The key and count, the particles, the memory they need, the machine's, the fix.
        message: String,
    },
    /// A `[bonded] critical_fraction` whose explicit step is above the rigorous stable bound.
    #[error(
        "{scene}: [bonded]: critical_fraction = {fraction} gives dt = {fraction} x the bonds' \
         critical step of paper 001 Eq. 28 ({critical:.4e} s) = {dt:.4e} s, above the \
         rigorous stable bound {bound:.4e} s (set by `{limiter}`); fix: give \
         critical_fraction <= {:.4} (the bound over the critical step), or remove it to take \
         the step from [run] dt",
        // Rounded down, so that the fraction named gives a step within the bound.
        (bound / critical * 1e4).floor() / 1e4
    )]
    CriticalFraction {
        /// The scene file.
        scene: PathBuf,
        /// `critical_fraction`.
        fraction: f64,
        /// Eq. 28's critical step (s).
        critical: f64,
        /// The step it gives (s).
        dt: f64,
        /// The rigorous bound (s).
        bound: f64,
        /// The model that sets the bound.
        limiter: String,
    },
    /// A time step that cannot advance the run: zero, subnormal, not finite, or so small
    /// against `t_end` that the time stops advancing or the step count does not fit.
    #[error("{scene}: [run]: {message}")]
    Step {
        /// The scene file.
        scene: PathBuf,
        /// The step, what is wrong with it and how to fix it.
        message: String,
    },
}
