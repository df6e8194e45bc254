//! The contact model: contact spheres on bodies, walls, and the step pipeline
//! broad phase → narrow phase → contact forces → per-sphere sums.
//!
//! Paper 000 §4 puts a sphere at each surface vertex of a QDEM body, used only for contact;
//! a rigid body's spheres sit on its members or at its centre ([`qdem_core::step::rigid_body`]); a
//! one-sphere grain is a particle that rotates ([`qdem_core::step::ParticleSpin`]).
//! Spheres of one body never interact. Each evaluation runs the stages of `stages.rs`, the
//! same on one process and on a rank of a decomposed run:
//! 1. reads the sphere centres from their particles,
//! 2. rebuilds the pair and wall candidate lists if some sphere (or wall) moved more than the
//!    skin allows ([`crate::dem::broad_phase`]), carrying the tangential springs of surviving
//!    pairs over (on rigid bodies, a bound per body spares reading every sphere:
//!    `displacement.rs`),
//! 3. runs the pair kernel (`pair_kernel.rs`): the law of every candidate pair and wall
//!    contact, each force and its moment about the sphere's centre added straight into
//!    per-sphere sums, in parallel over fixed runs of spheres (no atomics, so results do not
//!    depend on the thread or rank count), each sum then added to its particle force and the
//!    moment to the sphere's rigid body or rotating particle. With a time-delayed boundary
//!    (whose ghost scales follow from this very evaluation's forces) or a servo wall (whose
//!    load sets its velocity) a reduction over the ranks reads the forces between the law
//!    and the sums.
//!
//! The contact point is at x_a + (r_a − δ/2) n; its velocity includes the rigid body's (or
//! the rotating particle's) spin, v + ω × (x_cp − x). Tangential springs grow by the relative
//! displacement over the time since the previous evaluation, so the model needs no step size.
//!
//! With periodic axes ([`DemContacts::with_periodic`]) separations are minimum images, so a
//! pair touches through the boundary as an original and its ghost would (paper 003 Eq. 1);
//! the pair keeps the image translation of its second sphere for the moment about that
//! sphere. With a time delay ([`DemContacts::with_time_delay`]) the force on a sphere from a
//! ghost beyond the left boundary of the delay axis is scaled by the left ghost scale, and
//! from one beyond the right boundary by the right one (paper 003 Eqs. 6–7); the average
//! magnitude of the contact forces through the boundary, F_Ave_current, is measured at every
//! evaluation, before the scaling, and drives [`TimeDelayedBoundary`].
//!
//! The model is composed of parts, each a struct with one job, its own data and its own
//! file, which the stages call through methods (what two parts share is passed as an
//! argument): `spheres.rs` the sphere records (particles, radii, bodies, carriers, centres,
//! the narrow phase's records, body names, pair elasticity), by *slot*, their place in the
//! spatial order that `spatial_order.rs` gives them at every build of the lists (outside the
//! engine a sphere keeps its stable id, the builder's index); `candidates.rs` the candidate
//! lists and their build (partners, build positions and time, the displacement bound's
//! anchor of `displacement.rs`, the rebuild count); `pair_kernel.rs` the pair kernel, with
//! its plan and per-sphere sums; `walls.rs` the walls (their elasticity, the narrow phase
//! against a wall) with their servos, `servo_loads.rs`; `time_delay.rs` the time-delayed
//! boundary (its reduction and ghost scales); `split.rs` one rank's part in a decomposed
//! run, whose stages the world's exchange runs ([`qdem_core::parallel`]); `tunnelling.rs`
//! the check, at each rebuild of the lists, for a sphere gone through a wall or into
//! another body; `rolling.rs` the rolling resistance of the contacts; and `stages.rs` where
//! the evaluations stand. The other files hold what
//! [`DemContacts`] does with them: this one the narrow phase and the [`Model`] facet;
//! `stable_step.rs` the step estimated from the contacts present and its check at each
//! rebuild; `build.rs` its construction; `stages.rs` the stages of one evaluation;
//! `pipeline.rs` the reading of the spheres and the building of the candidate lists;
//! `displacement.rs` the displacement check's bound for rigid bodies; `output_queries.rs`
//! what the outputs read; `persistence.rs` what a checkpoint keeps; `linearized.rs` the
//! touching contacts as springs for a modal analysis.

use crate::boundaries::periodic_boundary::PeriodicBox;
use crate::boundaries::time_delayed_boundary::{GhostScales, TimeDelayedBoundary};
use crate::dem::broad_phase::{find_pairs, SphereSet};
use crate::dem::contact_list::{Contact, ContactList};
use crate::dem::contact_view::{Partner, SphereRecord, TouchingContact};
use crate::dem::laws::contact_law::{ContactLaw, PairElasticity, PairGeometry, SpherePair};
use crate::dem::laws::rolling_resistance::RollingResistance;
use crate::dem::spring_blocks::{add_spring, spring, Attachment};
use crate::dem::walls::wall::Wall;
use crate::error::ContactError;
use candidates::Candidates;
use pair_kernel::KernelPlan;
use qdem_core::checkpoint::same_count;
use qdem_core::continuum::stable_step::critical_step;
use qdem_core::{
    checkpoint::CheckpointError, checkpoint::Decoder, checkpoint::Encoder, step::Dofs,
    step::Linearized, step::Model, step::Persistence, step::Persistent, step::Reads, step::State,
    step::Tangent, Vec3,
};
use rayon::prelude::*;
use spatial_order::SphereOrder;
use spheres::{SphereColumns, Spheres};
use split::ContactPart;
use stages::Evaluation;
use time_delay::{pair_scales, TimeDelay};
use walls::Walls;

pub use persistence::{CarriedSprings, SavedSpring, SavedSprings, SavedWall};
pub use stable_step::{
    impact_overlap, rayleigh_time, FLOOR_CONTACTS, FLOOR_OVERLAP, OVERLAP_MARGIN,
};
pub use tunnelling::BodySurface;
use tunnelling::PassageCheck;

mod build;
mod candidates;
mod displacement;
mod linearized;
mod output_queries;
mod pair_kernel;
mod persistence;
mod pipeline;
mod rolling;
mod run_threads;
mod servo_loads;
mod spatial_order;
mod spheres;
mod split;
mod stable_step;
mod stages;
mod time_delay;
mod tunnelling;
mod walls;

/// Marks a sphere that is no part of a rigid body, or whose moments go nowhere.
const NOT_RIGID: u32 = u32::MAX;

/// Spheres per parallel task of the wall candidates' search and of the passage check
/// (about 30 µs of work each: a task much shorter than waking a worker, tens of µs on the
/// 2-core benchmark machine, makes a parallel loop slower than a serial one).
const CONTACT_CHUNK: usize = 2048;

/// Spheres per parallel task when reading their centres (a copy: a few ns each).
const SPHERE_CHUNK: usize = 16384;

/// The fewest spheres whose centres a thread of a team reads in a phase of its own (a phase
/// posted to a spinning worker costs about a microsecond).
const TEAM_SPHERES: usize = 1024;

/// A candidate contact's work at each evaluation (the read of its partners, the narrow
/// phase, the law and its share of the sums) in units of one particle's step (prediction
/// and integration): on the 10⁵ falling grains split over 2 ranks (docs/scaling.md) a rank's
/// contact stage took about 60 ns per candidate and its prediction and integration about 18
/// ns per particle.
const CANDIDATE_WORK: f64 = 3.0;

/// A contact sphere's work at each evaluation, without its candidates, in units of one
/// particle's step: on the paper-size loading step (docs/ballast.md, one thread, a quiet
/// machine, `qdem check`'s 20 steps) the contact stage took 2.17 ms for 42,073 spheres and
/// 7,837 candidates, against 9 ns a particle's step: less `CANDIDATE_WORK` per candidate,
/// 5 steps a sphere. About half a step is the read of its centre and the check of its
/// displacement (docs/BENCHMARKS.md, the ballast's contact stage); the rest is its share
/// of the rebuild of the lists among those 20 steps (about 3,200 instructions a sphere), so
/// a run that rebuilds less often spends less per sphere.
const SPHERE_WORK: f64 = 5.0;

/// One contact sphere as the builder describes it.
#[derive(Clone, Copy, Debug)]
pub struct ContactSphere {
    /// The particle at its centre.
    pub particle: usize,
    /// Its radius (m).
    pub radius: f64,
    /// The body it belongs to (index into the body names).
    pub body: usize,
    /// The body's elastic constants (index into the materials), used by Hertz–Mindlin.
    pub material: usize,
}

/// The scene-wide contact settings.
#[derive(Clone, Debug)]
pub struct ContactSettings {
    /// The law.
    pub law: ContactLaw,
    /// Friction coefficient between spheres of different bodies.
    pub friction: f64,
    /// Skin distance of the candidate lists (m).
    pub skin: f64,
}

/// What the narrow phase reads of one sphere, kept together so that a pair touches two
/// cache lines per sphere rather than one per array.
#[derive(Clone, Copy, Debug, Default)]
pub(crate) struct SphereNow {
    /// Centre x (m).
    pub(crate) center: Vec3,
    /// Velocity of the centre v (m/s).
    pub(crate) velocity: Vec3,
    /// Angular velocity ω (rad/s), zero for a sphere that does not turn.
    pub(crate) spin: Vec3,
    /// Radius r (m).
    pub(crate) radius: f64,
    /// Mass of the particle or body that carries it (kg).
    pub(crate) mass: f64,
    /// Index of its elastic constants.
    pub(crate) material: u32,
}

/// The narrow phase, a pure function of two sphere records: the contact of spheres a and b,
/// b's image translated by `shift` (zero except through a periodic boundary), or `None` when
/// they are apart. With d = x_b + shift − x_a: overlap δ = r_a + r_b − |d|, normal n = d/|d|,
/// the contact point at x_a + (r_a − δ/2) n, and the velocity of a's contact point relative to
/// b's, v_a − v_b + (r_a − δ/2) ω_a × n + (r_b − δ/2) ω_b × n; R* = r_a r_b/(r_a + r_b),
/// m* = m_a m_b/(m_a + m_b) ([`SpherePair::geometry`]).
#[inline(always)]
pub(crate) fn narrow_phase(
    a: &SphereNow,
    b: &SphereNow,
    shift: Vec3,
    friction: f64,
) -> Option<PairGeometry> {
    touching_pair(a, b, shift, friction).map(|pair| pair.geometry())
}

/// The narrow phase's test: the spheres a and b (b's image translated by `shift`) as a
/// [`SpherePair`] when they overlap, `None` when they are apart (|d| ≥ r_a + r_b) or
/// concentric.
#[inline(always)]
pub(crate) fn touching_pair(
    a: &SphereNow,
    b: &SphereNow,
    shift: Vec3,
    friction: f64,
) -> Option<SpherePair> {
    let d = b.center + shift - a.center;
    let distance_squared = d.norm_squared();
    let reach = a.radius + b.radius;
    if distance_squared >= reach * reach || distance_squared == 0.0 {
        return None;
    }
    Some(SpherePair {
        separation: d,
        distance_squared,
        radii: (a.radius, b.radius),
        masses: (a.mass, b.mass),
        velocity: a.velocity - b.velocity,
        spins: (a.spin, b.spin),
        friction,
    })
}

/// Contact spheres, walls and their contacts: a [`Model`].
///
/// ```
/// use qdem_contact::{
///     ContactLaw, ContactSettings, ContactSphere, DemContacts, LinearSpring, PlaneWall, Wall,
///     WallShape,
/// };
/// use qdem_core::{step::Model, step::State, Vec3};
///
/// // Two spheres of radius 0.01 m on particles of bodies 0 and 1, overlapping by 1 mm, the
/// // second also resting 0.5 mm into a floor z = 0.
/// let (top, bottom) = (Vec3::new(0.0, 0.0, 0.0285), Vec3::new(0.0, 0.0, 0.0095));
/// let mut state = State::at_rest(vec![top, bottom]);
/// state.mass = vec![0.01, 0.01];
/// let spheres: Vec<ContactSphere> = (0..2)
///     .map(|i| ContactSphere { particle: i, radius: 0.01, body: i, material: 0 })
///     .collect();
/// let floor = Wall {
///     shape: WallShape::Plane(PlaneWall::new(Vec3::zeros(), Vec3::z(), Vec3::zeros())),
///     friction: 0.5,
/// };
/// let k = 1e5;
/// let settings = ContactSettings {
///     law: ContactLaw::Linear(LinearSpring {
///         normal_stiffness: k,
///         tangential_stiffness: k,
///         damping_ratio: 0.0,
///     }),
///     friction: 0.5,
///     skin: 0.001,
/// };
/// let names = vec!["top".to_string(), "bottom".to_string()];
/// let materials = [(1e9, 0.25)];
/// let mut contacts = DemContacts::new(&state, &spheres, names, &materials, settings, vec![floor]);
/// let mut force = vec![Vec3::zeros(); 2];
/// contacts.add_forces(&state, &mut force, &mut []);
/// assert_eq!(contacts.contacts(), 2);
/// // The pair pushes the spheres apart with k δ; the floor pushes the lower one up.
/// assert!((force[0].z - k * 1e-3).abs() < 1e-9);
/// assert!((force[1].z - (k * 5e-4 - k * 1e-3)).abs() < 1e-9);
/// ```
pub struct DemContacts {
    /// The model's name.
    name: String,
    /// The sphere records (`spheres.rs`), by slot.
    spheres: Spheres,
    /// The spheres' slots in spatial order and their stable ids (`spatial_order.rs`).
    order: SphereOrder,
    /// The candidate lists and their build (`candidates.rs`).
    candidates: Candidates,
    /// The law, the friction between spheres and the skin.
    settings: ContactSettings,
    /// The walls, their elasticity and their servos (`walls.rs`).
    walls: Walls,
    /// Where the evaluations stand (`stages.rs`).
    evaluation: Evaluation,
    /// The pair kernel's plan for the current lists and its per-sphere sums
    /// (`pair_kernel.rs`).
    kernel: KernelPlan,
    /// The periodic axes, if any.
    periodic: Option<PeriodicBox>,
    /// The time-delayed boundary, if any (`time_delay.rs`).
    time_delay: Option<TimeDelay>,
    /// This rank's part, in a run decomposed with a halo exchange.
    split: Option<ContactPart>,
    /// The check for spheres gone through a wall or into another body (`tunnelling.rs`).
    passage: PassageCheck,
    /// The rolling resistance of every contact, if any (`rolling.rs`).
    rolling: Option<RollingResistance>,
    /// The first contact found at a rebuild to need a shorter step than the run's
    /// (`stable_step.rs`).
    step_short: Option<stable_step::StepNeed>,
}

/// r_a r_b / (r_a + r_b).
#[inline]
fn reduced(a: f64, b: f64) -> f64 {
    a * b / (a + b)
}

impl Model for DemContacts {
    fn name(&self) -> &str {
        &self.name
    }

    /// The stages of a rank's evaluation on one process (`stages.rs`); a rank of a
    /// decomposed run runs the same stages through its split facet (`split.rs`).
    fn add_forces(&mut self, state: &State, force: &mut [Vec3], torque: &mut [Vec3]) {
        self.evaluate_one_rank(state, force, torque);
    }

    /// Split in a decomposed run ([`qdem_core::step::split::Facets`], `split.rs`): a rank reads
    /// its own spheres and receives the ghosts it declares.
    fn reads(&mut self) -> Reads<'_> {
        Reads::Split(self)
    }

    /// The step estimated from the contacts touching at `state` (`stable_step.rs`): a true
    /// bound of the linearised system's highest frequency for those contacts, at
    /// [`OVERLAP_MARGIN`] times their overlaps, every carrier counted with at least
    /// [`FLOOR_CONTACTS`] contacts at the floor overlap. Carriers held in every direction are
    /// left out.
    fn stable_dt(&self, state: &State) -> Option<f64> {
        self.estimated_step(state)
    }

    /// The step one contact touching at `state` cannot be stepped above, whatever the others
    /// (`stable_step.rs`); a step between it and [`Model::stable_dt`] is warned of only.
    fn unstable_above(&self, state: &State) -> Option<f64> {
        self.unstable_step(state)
    }

    fn potential_energy(&self, state: &State) -> Option<f64> {
        let law = &self.settings.law;
        let pairs = self
            .candidates
            .pairs()
            .with_shifts()
            .filter_map(|(c, mut shift)| {
                self.pair_contact(c, &mut shift)
                    .map(|(g, e)| law.energy(&g, &e, &c.history))
            });
        let walls = self
            .candidates
            .wall_contacts()
            .items
            .iter()
            .filter_map(|c| {
                self.wall_contact(state.time, c.first as usize, c.second as usize)
                    .map(|(g, e)| law.energy(&g, &e, &c.history))
            });
        let springs: f64 = pairs.chain(walls).sum();
        match self.rolling_energy(state.time) {
            Some(rolling) => Some(springs + rolling),
            None => Some(springs),
        }
    }

    fn persistence(&self) -> Persistence<'_> {
        Persistence::Saved(self)
    }

    fn prepare(&mut self, settings: &qdem_core::step::StepSettings) {
        self.passage.set_step(settings.dt);
        if self.lists_built() {
            self.check_step_need(self.candidates.built_time());
        }
    }

    /// A sphere found through a wall or inside another body at the last rebuild of the
    /// lists (`tunnelling.rs`), or a contact found there to need a shorter step than the
    /// run's (`stable_step.rs`).
    fn failure(&self, state: &State) -> Option<qdem_core::error::CoreError> {
        self.passage_failure(state.time)
            .or_else(|| self.step_failure())
    }

    fn persistent_mut(&mut self) -> Option<&mut dyn Persistent> {
        Some(self)
    }

    /// The contacts touching at the last evaluation, as sticking springs
    /// (`spring_blocks.rs`), attached through the arm to the contact point to the
    /// rotation of a sphere that turns (a rigid body's, a rotating particle's). The contacts
    /// give no [`Model::linearized`] facet: an implicit step would need the events of contacts
    /// opening and closing.
    fn modal_stiffness(&self) -> Option<&dyn Linearized> {
        Some(self)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn sphere(center: Vec3, radius: f64, spin: Vec3) -> SphereNow {
        SphereNow {
            center,
            radius,
            spin,
            mass: 1.0,
            ..SphereNow::default()
        }
    }

    #[test]
    fn the_narrow_phase_sees_the_overlap_normal_and_the_contact_points_spin() {
        // r_a = 0.02, r_b = 0.01, centres 0.025 apart along x: δ = 0.005, the contact point
        // 0.0175 from a and 0.0075 from b. a spins at 10 rad/s about z, b at −10: a's point
        // moves at 10 · 0.0175 = 0.175 m/s along y, b's at 0.075 along y.
        let a = sphere(Vec3::zeros(), 0.02, Vec3::new(0.0, 0.0, 10.0));
        let b = sphere(Vec3::new(0.025, 0.0, 0.0), 0.01, Vec3::new(0.0, 0.0, -10.0));
        let g = narrow_phase(&a, &b, Vec3::zeros(), 0.3).unwrap();
        assert!((g.overlap - 0.005).abs() < 1e-15);
        assert_eq!(g.normal, Vec3::x());
        assert!((g.velocity - Vec3::new(0.0, 0.1, 0.0)).norm() < 1e-15);
        assert!((g.radius - 0.02 / 3.0).abs() < 1e-17);
        assert_eq!((g.mass, g.friction), (0.5, 0.3));
        // The same pair through a periodic boundary of period 1: b's image at x = −0.025.
        let far = sphere(Vec3::new(0.975, 0.0, 0.0), 0.01, Vec3::zeros());
        let g = narrow_phase(&a, &far, Vec3::new(-1.0, 0.0, 0.0), 0.3).unwrap();
        assert!((g.normal + Vec3::x()).norm() < 1e-12);
        assert!((g.overlap - 0.005).abs() < 1e-12);
        assert!(narrow_phase(&a, &far, Vec3::zeros(), 0.3).is_none());
    }
}
