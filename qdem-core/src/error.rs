//! Errors of the core: bad bodies, bad time functions, bad steps and unstable runs.

use crate::checkpoint::CheckpointError;
use thiserror::Error;

/// Everything the core refuses, each message naming the offending item and the fix.
#[derive(Debug, Error)]
pub enum CoreError {
    /// A material constant out of range.
    #[error("body `{body}`: {source}")]
    Material {
        /// Body name.
        body: String,
        /// What is wrong.
        source: MaterialError,
    },
    /// A tetrahedron with zero or negative reference volume.
    #[error(
        "body `{body}`: tetrahedron {tet} has reference volume {volume:e} m^3 (must be positive): \
         reorient or remove it (the mesh reader reorients inverted tetrahedra; a zero volume \
         means coincident or coplanar nodes)"
    )]
    BadTet {
        /// Body name.
        body: String,
        /// Tetrahedron index within the body.
        tet: usize,
        /// Its signed volume.
        volume: f64,
    },
    /// A tetrahedron refers to a particle that does not exist.
    #[error(
        "body `{body}`: tetrahedron {tet} refers to particle {node}, but there are only {count}"
    )]
    NodeOutOfRange {
        /// Body name.
        body: String,
        /// Tetrahedron index.
        tet: usize,
        /// The particle index.
        node: u32,
        /// The number of particles.
        count: usize,
    },
    /// A body without tetrahedra.
    #[error("body `{0}` has no tetrahedra")]
    EmptyBody(String),
    /// A time function that is not piecewise linear in non-decreasing time.
    #[error("time function: {0}")]
    TimeFunction(String),
    /// A user-given time step above the stable bound.
    #[error(
        "dt = {dt:e} s is above the stable bound {bound:e} s (limited by {limiter}); use dt = \
         \"auto\" or a value of at most {bound:e}"
    )]
    StepTooLarge {
        /// Requested step.
        dt: f64,
        /// Stable bound.
        bound: f64,
        /// The model that limits the step.
        limiter: String,
    },
    /// An automatic step (`dt = "auto"`) where the models give no finite bound to take it
    /// from: none bounds the step (no stiffness: rigid bodies, loads and gravity only), or the
    /// bound is NaN.
    #[error("{}", no_bound_message(*bound, limiter))]
    NoStableBound {
        /// The smallest bound of the models: infinite when none gives one, or NaN.
        bound: f64,
        /// The model that gives it (empty when none does).
        limiter: String,
    },
    /// An implicit or static scheme given no step and no default for it.
    #[error(
        "an implicit or static step has no stable bound to take dt from, and none was given; \
         fix: give [run] dt in seconds"
    )]
    ImplicitNeedsStep,
    /// A particle with zero mass that is not fixed in every direction.
    #[error(
        "particle {particle} has no mass and is not fully fixed: every particle must belong to a \
         tetrahedron of positive volume"
    )]
    Massless {
        /// Particle index.
        particle: usize,
    },
    /// A non-finite acceleration appeared.
    #[error(
        "the run became unstable at t = {time:e} s: particle {particle} has a non-finite \
         acceleration; the step is probably too large or a tetrahedron inverted"
    )]
    NonFinite {
        /// Simulated time.
        time: f64,
        /// First offending particle.
        particle: usize,
    },
    /// A tetrahedron turned inside out.
    #[error(
        "body `{body}`: tetrahedron {tet} turned inside out at t = {time:.6e} s (det F = \
         {det:.3e}, must stay positive): the deformation there is more than its mesh can carry"
    )]
    Inverted {
        /// Body name.
        body: String,
        /// Tetrahedron index within the body.
        tet: usize,
        /// det F, the ratio of its current to its reference volume.
        det: f64,
        /// Simulated time.
        time: f64,
    },
    /// Newmark parameters outside the range of paper 001 Eq. 16.
    #[error(
        "newmark: beta = {beta} and gamma = {gamma} are outside 0 <= gamma <= 1, \
         0 <= 2 beta <= 1 (paper 001 Eq. 16); use beta = 0.25, gamma = 0.5 (average \
         acceleration) or beta = 0, gamma = 0.5 (central difference)"
    )]
    NewmarkParameters {
        /// β.
        beta: f64,
        /// γ.
        gamma: f64,
    },
    /// An implicit or static solve met a model that cannot give its tangent.
    #[error(
        "model `{model}` gives no tangent stiffness, so it cannot be stepped implicitly or \
         solved statically: use an explicit stepper (verlet, or newmark with beta = 0)"
    )]
    NoTangent {
        /// The model's name.
        model: String,
    },
    /// The matrix of an implicit or static solve is not positive definite.
    #[error(
        "the {what} matrix ({dofs} free degrees of freedom) is not positive definite: {detail}"
    )]
    NotPositiveDefinite {
        /// Which matrix: "stiffness" or "effective".
        what: &'static str,
        /// Number of free degrees of freedom.
        dofs: usize,
        /// The particle whose pivot failed, where the factorisation tells it.
        particle: Option<usize>,
        /// The model (body) that owns that particle, if any does.
        body: Option<String>,
        /// The diagnosis: the failing pivot, the bodies free to move rigidly, and the fix.
        detail: String,
    },
    /// A deformable body of a static (or massless implicit) solve that its constraints leave
    /// free to move rigidly, so the system is singular.
    #[error(
        "body `{body}` is not constrained against rigid motion ({modes} of its 6 rigid-body \
         modes are free), so the {what} matrix is singular: {fix}"
    )]
    Unconstrained {
        /// The body's name.
        body: String,
        /// How many independent rigid-body motions (of 3 translations and 3 rotations) its
        /// fixed directions leave free.
        modes: usize,
        /// Which matrix: "stiffness" or "effective".
        what: &'static str,
        /// What to do about it.
        fix: &'static str,
    },
    /// A rigid body without positive mass or principal moments of inertia.
    #[error(
        "rigid body `{body}` has mass {mass:e} kg and principal moments {inertia:?} kg m^2; \
         all must be positive: give it a mesh with volume or contact spheres of positive radius"
    )]
    BadRigidBody {
        /// Body name.
        body: String,
        /// Its mass.
        mass: f64,
        /// Its principal moments of inertia.
        inertia: [f64; 3],
    },
    /// A stepper that cannot integrate rigid bodies met one.
    #[error(
        "the {stepper} stepper cannot integrate rigid bodies (the scene has {count}); use \
         integrator = \"verlet\""
    )]
    RigidNeedsVerlet {
        /// The stepper's name.
        stepper: String,
        /// Number of rigid bodies.
        count: usize,
    },
    /// A step left the run in an impossible state, found by the world's failure check.
    #[error(
        "the run became unstable at step {step} (t = {time:.6e} s): {detail}. The step was dt \
         = {dt:.4e} s; the stable bound at this state is {bound:.4e} s (set by {limiter}): \
         {}",
        cause.as_deref().map_or_else(|| unstable_advice(*dt, *bound), String::clone)
    )]
    Unstable {
        /// The step that failed (1 for the first).
        step: u64,
        /// Simulated time after it.
        time: f64,
        /// What went wrong, and where (particle, body, element).
        detail: String,
        /// The step size.
        dt: f64,
        /// The stable bound at this state.
        bound: f64,
        /// The model that sets it (a boxed `str`, as `cause` is boxed, to keep the error small).
        limiter: Box<str>,
        /// The cause and its fix where the caller, who knows the scene, finds one (a load
        /// that no step can resolve); `None` gives [`unstable_advice`] of the step and the
        /// bound. Boxed (a thin pointer) to keep the error as small as it was without it.
        cause: Option<Box<String>>,
    },
    /// A contact sphere went through a wall or into another body, found by the contact
    /// model's pass-through check ([`crate::step::Model::failure`]): the step may be stable and
    /// the result still wrong.
    #[error(
        "a body passes through at step {step} (t = {time:.6e} s, dt = {dt:.4e} s): {detail} {fix}"
    )]
    PassThrough {
        /// The step that found it (1 for the first).
        step: u64,
        /// Simulated time after it.
        time: f64,
        /// The step size.
        dt: f64,
        /// The sphere, the wall or body, and its speed.
        detail: String,
        /// What to change (a caller that knows a deeper cause, a load no step resolves, puts
        /// that here instead).
        fix: String,
    },
    /// A contact found, at a rebuild of the contact lists, to need a shorter step than the
    /// run's: its own oscillation, whatever the other contacts do, is unstable at the run's
    /// step ([`crate::step::Model::failure`]).
    #[error(
        "{contact} needs dt <= {needed:.4e} s (2/omega of that contact alone, a step above \
         which no run is stable), and the run steps at dt = {dt:.4e} s"
    )]
    ContactStep {
        /// The contact: its two spheres and bodies (or the wall), overlap and reduced mass.
        contact: String,
        /// The step it needs (s).
        needed: f64,
        /// The run's step (s).
        dt: f64,
    },
    /// The sparse linear algebra failed for a reason other than definiteness.
    #[error("sparse factorisation failed: {0}")]
    Sparse(String),
    /// A checkpoint that cannot be written or read for this scene.
    #[error("checkpoint: {0}")]
    Checkpoint(#[from] CheckpointError),
    /// A scene that cannot be decomposed over processes (an implicit or static run, a particle
    /// shared by two bodies).
    #[error("cannot decompose the run over processes: {0}")]
    Decomposition(String),
}

/// Why `dt = "auto"` has no step to choose: no model bounds it (`bound` infinite), or the
/// bound `limiter` gives is NaN.
fn no_bound_message(bound: f64, limiter: &str) -> String {
    if bound.is_nan() {
        format!(
            "dt = \"auto\" cannot choose a step: the stable bound of `{limiter}` is NaN, so \
             some mass or stiffness of it is zero or not a finite number (a zero density, a \
             zero or infinite stiffness, a particle with no volume around it); fix: check \
             the density, young and contact stiffness of `{limiter}`, or give [run] dt in \
             seconds"
        )
    } else {
        "dt = \"auto\" cannot choose a step: no model of the scene bounds it (nothing has a \
         stiffness that limits an explicit step: no deformable body, no contact, no bond; \
         rigid bodies, gravity and loads alone do not), so the bound is infinite; fix: give \
         [run] dt in seconds, small enough to resolve the motion (e.g. a hundredth of the \
         time its fastest change takes)"
            .to_string()
    }
}

/// What to do about an instability, given the step and its bound.
pub fn unstable_advice(dt: f64, bound: f64) -> String {
    if dt > bound {
        format!("the step is above the bound: use dt = \"auto\" or dt <= {bound:.4e} s")
    } else {
        "the step is within the bound, so the cause is physical: a load or a contact \
         stiffness too large for the mesh there (reduce it or refine the mesh), or a contact \
         pushing a vertex through its body (finer contact spheres)"
            .to_string()
    }
}

/// A material constant outside its physical range.
#[derive(Debug, Error, PartialEq)]
pub enum MaterialError {
    /// ρ ≤ 0 or not finite.
    #[error("density must be a positive number of kg/m^3, got {0}")]
    Density(f64),
    /// E ≤ 0 or not finite.
    #[error("young must be a positive number of Pa, got {0}")]
    Young(f64),
    /// ν outside (−1, 0.5).
    #[error(
        "poisson must lie in (-1, 0.5), got {0}; incompressible materials are not supported by \
         an explicit step: use 0.49 at most"
    )]
    Poisson(f64),
    /// A negative or non-finite viscosity.
    #[error("{name} must be a non-negative number of Pa s, got {value}")]
    Viscosity {
        /// Which viscosity.
        name: &'static str,
        /// The value given.
        value: f64,
    },
}
