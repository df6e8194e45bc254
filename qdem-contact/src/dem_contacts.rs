//! The contact model: contact spheres on bodies, walls, and the step pipeline
//! broad phase → narrow phase → contact forces → gather.
//!
//! Paper 000 §4 puts a sphere at each surface vertex of a QDEM body, used only for contact;
//! a rigid body's spheres sit on its members or at its centre ([`qdem_core::rigid_body`]); a
//! one-sphere grain is a particle that rotates ([`qdem_core::ParticleSpin`]).
//! Spheres of one body never interact. Each evaluation
//! 1. reads the sphere centres from their particles,
//! 2. rebuilds the pair and wall candidate lists if some sphere (or wall) moved more than the
//!    skin allows ([`crate::broad_phase`]), carrying the tangential springs of surviving
//!    pairs over,
//! 3. evaluates the law of every candidate pair and wall contact in parallel into per-contact
//!    buffers,
//! 4. gathers them per sphere over a fixed incidence list (no atomics, so results do not depend
//!    on the thread count) and adds them, in sphere order, to the particle forces, and the
//!    moment of each contact force about its sphere's centre to the sphere's rigid body or
//!    rotating particle.
//!
//! The contact point is at x_a + (r_a − δ/2) n; its velocity includes the rigid body's (or
//! the rotating particle's) spin, v + ω × (x_cp − x). Tangential springs grow by the relative displacement over the time since
//! the previous evaluation, so the model needs no step size.
//!
//! With periodic axes ([`DemContacts::with_periodic`]) separations are minimum images, so a
//! pair touches through the boundary as an original and its ghost would (paper 003 Eq. 1);
//! the pair keeps the image translation of its second sphere for the moment about that
//! sphere. With a time delay ([`DemContacts::with_time_delay`]) the force on a sphere from a
//! ghost beyond the left boundary of the delay axis is scaled by the left ghost scale, and
//! from one beyond the right boundary by the right one (paper 003 Eqs. 6–7); the average
//! magnitude of the contact forces through the boundary, F_Ave_current, is measured at every
//! evaluation, before the scaling, and drives [`TimeDelayedBoundary`].

use crate::broad_phase::{find_pairs, SphereSet};
use crate::contact_law::{ContactLaw, PairElasticity, PairGeometry};
use crate::contact_list::{Contact, ContactList};
use crate::contact_split::ContactSplit;
use crate::contact_springs::{add_spring, spring, Attachment};
use crate::contact_view::{Partner, SphereRecord, TouchingContact};
use crate::error::ContactError;
use crate::periodic_boundary::PeriodicBox;
use crate::time_delayed_boundary::{GhostScales, TimeDelayedBoundary};
use crate::wall::Wall;
use qdem_core::checkpoint::same_count;
use qdem_core::stable_step::critical_step;
use qdem_core::{
    CheckpointError, Decoder, Dofs, Encoder, Linearized, Model, Ownership, ParticleReads,
    Persistence, Persistent, SplitModel, State, Tangent, Vec3,
};
use rayon::prelude::*;

/// Marks a sphere that is no part of a rigid body, or whose moments go nowhere.
const NOT_RIGID: u32 = u32::MAX;

/// Contacts per parallel task of the narrow phase and law, and spheres per task of the gather
/// (about 30 µs of work each: a task much shorter than waking a worker, tens of µs on the
/// 2-core benchmark machine, makes a parallel loop slower than a serial one).
const CONTACT_CHUNK: usize = 2048;

/// Spheres per parallel task when reading their centres (a copy: a few ns each).
const SPHERE_CHUNK: usize = 16384;

/// A candidate contact's work at each evaluation (the read of its partners, the narrow
/// phase, the law and its share of the sums) in units of one particle's step (prediction
/// and integration): on the 10⁵ falling grains split over 2 ranks (docs/scaling.md) a rank's
/// contact stage took about 60 ns per candidate and its prediction and integration about 18
/// ns per particle.
const CANDIDATE_WORK: f64 = 3.0;

/// Overlap, as a fraction of the reduced radius, at which the stable step evaluates Hertz's
/// stiffness (which grows as √δ).
pub const REFERENCE_OVERLAP: f64 = 0.05;

/// Contacts per sphere assumed by the stable-step bound.
pub const COORDINATION: f64 = 6.0;

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
/// m* = m_a m_b/(m_a + m_b).
#[inline]
pub(crate) fn narrow_phase(
    a: &SphereNow,
    b: &SphereNow,
    shift: Vec3,
    friction: f64,
) -> Option<PairGeometry> {
    let d = b.center + shift - a.center;
    let distance_squared = d.norm_squared();
    let reach = a.radius + b.radius;
    if distance_squared >= reach * reach || distance_squared == 0.0 {
        return None;
    }
    let distance = distance_squared.sqrt();
    let overlap = reach - distance;
    let normal = d / distance;
    let half = 0.5 * overlap;
    let spin = (a.radius - half) * a.spin + (b.radius - half) * b.spin;
    Some(PairGeometry {
        overlap,
        normal,
        velocity: a.velocity - b.velocity + spin.cross(&normal),
        radius: reduced(a.radius, b.radius),
        mass: a.mass * b.mass / (a.mass + b.mass),
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
/// use qdem_core::{Model, State, Vec3};
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
    name: String,
    particle: Vec<u32>,
    radius: Vec<f64>,
    body: Vec<u32>,
    rigid: Vec<u32>,
    turn: Vec<u32>,
    lever: Vec<f64>,
    bound_mass: Vec<f64>,
    body_names: Vec<String>,
    materials: usize,
    elasticity: Vec<PairElasticity>,
    wall_elasticity: Vec<PairElasticity>,
    settings: ContactSettings,
    walls: Vec<Wall>,
    last_time: Option<f64>,
    /// Every sphere's centre at the last evaluation.
    center: Vec<Vec3>,
    /// What the narrow phase reads of each sphere, current for the partners of candidates.
    now: Vec<SphereNow>,
    built_at: Vec<Vec3>,
    built_time: f64,
    built: bool,
    pairs: ContactList,
    wall_contacts: ContactList,
    incidence_start: Vec<u32>,
    incidence: Vec<u32>,
    wall_start: Vec<u32>,
    /// The spheres that are partners of some candidate (pair or wall contact), ascending.
    partners: Vec<u32>,
    sphere_force: Vec<(Vec3, Vec3)>,
    rebuilds: u64,
    periodic: Option<PeriodicBox>,
    time_delay: Option<TimeDelay>,
    /// This rank's part, in a run decomposed with a halo exchange.
    split: Option<ContactSplit>,
    /// Whether the lists were rebuilt since [`SplitModel::rebuilt`] last asked.
    rebuilt: bool,
}

/// A time-delayed periodic boundary along one periodic axis, and its latest state.
struct TimeDelay {
    axis: usize,
    boundary: TimeDelayedBoundary,
    scales: GhostScales,
    boundary_force: f64,
}

/// Scales of the forces on the first and second sphere of a pair whose second sphere's image
/// was translated by `shift` along the delay axis: a negative shift means the second sphere
/// sits near the right boundary and its image beyond the left one, so the first sphere feels
/// a left ghost and the second (through the image of the first beyond the right boundary) a
/// right ghost; a positive shift is the mirror case; zero is an ordinary pair.
#[inline]
fn pair_scales(shift: f64, scales: &GhostScales) -> (f64, f64) {
    if shift < 0.0 {
        (scales.left, scales.right)
    } else if shift > 0.0 {
        (scales.right, scales.left)
    } else {
        (1.0, 1.0)
    }
}

/// Whether the segment from a to b (coordinates relative to a plane) crosses the plane, or,
/// with a `period`, one of its copies a whole number of periods away.
#[inline]
fn crosses(a: f64, b: f64, period: Option<f64>) -> bool {
    match period {
        Some(l) => {
            let below = (a / l).floor() * l;
            b < below || b >= below + l
        }
        None => (a < 0.0) != (b < 0.0),
    }
}

impl DemContacts {
    /// Contacts between `spheres` (of bodies `body_names`, with elastic constants (E, ν) per
    /// material) and against `walls`, at the state's current configuration.
    pub fn new(
        state: &State,
        spheres: &[ContactSphere],
        body_names: Vec<String>,
        materials: &[(f64, f64)],
        settings: ContactSettings,
        walls: Vec<Wall>,
    ) -> DemContacts {
        // The rigid body of each sphere: through a member, or at the body's centre.
        let mut body_of_center = vec![NOT_RIGID; state.len()];
        for (b, &c) in state.rigid.center.iter().enumerate() {
            body_of_center[c] = b as u32;
        }
        let rigid: Vec<u32> = spheres
            .iter()
            .map(|s| {
                state
                    .rigid
                    .body_of_member(s.particle)
                    .map_or(body_of_center[s.particle], |b| b as u32)
            })
            .collect();
        let carrier = |s: &ContactSphere, r: u32| match r {
            NOT_RIGID => s.particle,
            b => state.rigid.center[b as usize],
        };
        let mass: Vec<f64> = spheres
            .iter()
            .zip(&rigid)
            .map(|(s, &r)| state.mass[carrier(s, r)])
            .collect();
        let turns = |p: usize| state.spin.fixed.get(p).is_some_and(|f| *f != Dofs::ALL);
        let turn: Vec<u32> = spheres
            .iter()
            .zip(&rigid)
            .map(|(s, &r)| match r {
                NOT_RIGID if turns(s.particle) => (state.rigid.len() + s.particle) as u32,
                r => r,
            })
            .collect();
        let lever = spheres
            .iter()
            .zip(&rigid)
            .map(|(s, &r)| match r {
                NOT_RIGID if turns(s.particle) => {
                    s.radius * s.radius / state.spin.inertia[s.particle]
                }
                NOT_RIGID => 0.0,
                b if state.rigid.spin_fixed[b as usize] => 0.0,
                b => {
                    let arm = state.position[s.particle] - state.position[carrier(s, r)];
                    (arm.norm() + s.radius).powi(2) / state.rigid.inertia[b as usize].min()
                }
            })
            .collect();
        let elasticity = materials
            .iter()
            .flat_map(|a| materials.iter().map(|b| PairElasticity::new(*a, Some(*b))))
            .collect();
        let wall_elasticity = materials
            .iter()
            .map(|a| PairElasticity::new(*a, None))
            .collect();
        // A carrier held in every direction (and, for a rigid body, in rotation) cannot
        // oscillate: it does not limit the step (infinite mass in the bound below).
        let held = |s: &ContactSphere, r: u32| {
            let c = carrier(s, r);
            let still = match r {
                NOT_RIGID => !turns(s.particle),
                b => state.rigid.spin_fixed[b as usize],
            };
            state.fixed[c] == Dofs::ALL && still
        };
        let bound_mass: Vec<f64> = spheres
            .iter()
            .zip(&rigid)
            .zip(&mass)
            .map(|((s, &r), &m)| if held(s, r) { f64::INFINITY } else { m })
            .collect();
        let now: Vec<SphereNow> = spheres
            .iter()
            .zip(&mass)
            .map(|(s, &m)| SphereNow {
                radius: s.radius,
                mass: m,
                material: s.material as u32,
                ..SphereNow::default()
            })
            .collect();
        DemContacts {
            name: "contact".to_string(),
            particle: spheres.iter().map(|s| s.particle as u32).collect(),
            radius: spheres.iter().map(|s| s.radius).collect(),
            body: spheres.iter().map(|s| s.body as u32).collect(),
            rigid,
            turn,
            lever,
            bound_mass,
            body_names,
            materials: materials.len(),
            elasticity,
            wall_elasticity,
            settings,
            walls,
            last_time: None,
            center: vec![Vec3::zeros(); spheres.len()],
            now,
            built_at: Vec::new(),
            built_time: 0.0,
            built: false,
            pairs: ContactList::default(),
            wall_contacts: ContactList::default(),
            incidence_start: Vec::new(),
            incidence: Vec::new(),
            wall_start: Vec::new(),
            partners: Vec::new(),
            sphere_force: vec![(Vec3::zeros(), Vec3::zeros()); spheres.len()],
            rebuilds: 0,
            periodic: None,
            time_delay: None,
            split: None,
            rebuilt: false,
        }
    }

    /// Makes the contacts periodic along the axes of `periodic`; refused when a period is not
    /// longer than twice the reach of the largest spheres (two radii plus the skin).
    pub fn with_periodic(mut self, periodic: PeriodicBox) -> Result<DemContacts, ContactError> {
        let r_max = self.radius.iter().cloned().fold(0.0, f64::max);
        periodic.check_reach(2.0 * r_max + self.settings.skin)?;
        self.periodic = Some(periodic);
        self.built = false;
        Ok(self)
    }

    /// Scales the forces from ghosts beyond the boundaries of periodic `axis` by `boundary`'s
    /// ghost scales (paper 003 §5). Needs [`DemContacts::with_periodic`] along that axis first.
    pub fn with_time_delay(
        mut self,
        axis: usize,
        boundary: TimeDelayedBoundary,
    ) -> Result<DemContacts, ContactError> {
        if self
            .periodic
            .as_ref()
            .and_then(|p| p.length(axis))
            .is_none()
        {
            return Err(ContactError::TimeDelayNotPeriodic {
                axis: ['x', 'y', 'z'][axis.min(2)],
            });
        }
        self.time_delay = Some(TimeDelay {
            axis,
            boundary,
            scales: GhostScales::PERIODIC,
            boundary_force: 0.0,
        });
        Ok(self)
    }

    /// The ghost scales (left, right) of the last evaluation and the average magnitude of the
    /// contact forces through the delayed boundary it measured; `None` without a time delay.
    pub fn time_delay_state(&self) -> Option<(GhostScales, f64)> {
        self.time_delay
            .as_ref()
            .map(|t| (t.scales, t.boundary_force))
    }

    /// The average magnitude of the touching pairs' forces across the plane x\[axis\] = `at`
    /// (serial, in pair order): a pair crosses it when its two sphere centres, the second at
    /// the image it touches, lie on either side. In a periodic cell the plane repeats every
    /// period, so a section at a cell face measures what the boundary force does; in a box
    /// several cells long it measures the force through an inner face (paper 003's premise
    /// for Eqs. 4–5 is a statement about that force).
    pub fn section_force(&self, axis: usize, at: f64) -> f64 {
        let period = self.periodic.as_ref().and_then(|p| p.length(axis));
        self.mean_pair_force(|c| {
            let a = self.center[c.first as usize][axis] - at;
            let b = self.center[c.second as usize][axis] + c.shift[axis] - at;
            crosses(a, b, period)
        })
    }

    /// The average magnitude of the forces of the touching pairs c for which `counted(c)`
    /// (serial, in pair order, so it does not depend on the thread count); 0 without any.
    fn mean_pair_force(&self, counted: impl Fn(&Contact) -> bool) -> f64 {
        let (mut sum, mut count) = (0.0, 0usize);
        for c in &self.pairs.items {
            if c.force != Vec3::zeros() && counted(c) {
                sum += c.force.norm();
                count += 1;
            }
        }
        if count == 0 {
            0.0
        } else {
            sum / count as f64
        }
    }

    /// x_b − x_a, the minimum image when periodic, and the translation of b's image.
    #[inline]
    fn separation(&self, a: usize, b: usize) -> (Vec3, Vec3) {
        let d = self.center[b] - self.center[a];
        match &self.periodic {
            Some(p) => {
                let shift = p.image_shift(&d);
                (d + shift, shift)
            }
            None => (d, Vec3::zeros()),
        }
    }

    /// Number of contact spheres.
    pub fn spheres(&self) -> usize {
        self.particle.len()
    }

    /// Number of walls.
    pub fn walls(&self) -> usize {
        self.walls.len()
    }

    /// Number of candidate pairs and wall candidates in the current lists.
    pub fn candidates(&self) -> usize {
        self.pairs.len() + self.wall_contacts.len()
    }

    /// Number of touching contacts (sphere–sphere and sphere–wall) at the last evaluation.
    pub fn contacts(&self) -> usize {
        self.pairs
            .items
            .iter()
            .chain(&self.wall_contacts.items)
            .filter(|c| c.force != Vec3::zeros())
            .count()
    }

    /// The walls.
    pub fn wall_list(&self) -> &[Wall] {
        &self.walls
    }

    /// The names of the bodies the spheres belong to ([`SphereRecord::body`] indexes them).
    pub fn body_names(&self) -> &[String] {
        &self.body_names
    }

    /// Every contact sphere at `state` (the state the last evaluation saw, after the step),
    /// in sphere order, with the contact force the model applied to it.
    pub fn sphere_records<'a>(
        &'a self,
        state: &'a State,
    ) -> impl Iterator<Item = SphereRecord> + 'a {
        let bodies = state.rigid.len();
        (0..self.particle.len()).map(move |s| {
            let particle = self.particle[s] as usize;
            let spin = match self.turn[s] as usize {
                t if t == NOT_RIGID as usize => None,
                b if b < bodies => Some(state.rigid.angular_velocity[b]),
                t => Some(state.spin.velocity[t - bodies]),
            };
            SphereRecord {
                particle,
                radius: self.radius[s],
                body: self.body[s] as usize,
                center: state.position[particle],
                velocity: state.velocity[particle],
                spin,
                force: self.sphere_force[s].0,
            }
        })
    }

    /// Every contact that touched at the last evaluation: the pairs in list order, then the
    /// wall contacts. Summed per sphere (+f on the first partner times its scale, −f on the
    /// second times its scale), their forces are [`SphereRecord::force`].
    pub fn touching(&self) -> impl Iterator<Item = TouchingContact> + '_ {
        let time = self.last_time.unwrap_or(0.0);
        let delay = self.time_delay.as_ref().map(|t| (t.axis, t.scales));
        let pairs = self.pairs.items.iter().filter(|c| c.force != Vec3::zeros());
        let pairs = pairs.map(move |c| {
            let (a, b) = (c.first as usize, c.second as usize);
            let (from, to) = (self.center[a], self.center[b] + c.shift);
            let scales = delay.map_or((1.0, 1.0), |(axis, s)| pair_scales(c.shift[axis], &s));
            split(
                a,
                Partner::Sphere(b),
                from,
                to,
                (to - from).normalize(),
                c.force,
                scales,
            )
        });
        let walls = self
            .wall_contacts
            .items
            .iter()
            .filter(|c| c.force != Vec3::zeros());
        let walls = walls.map(move |c| {
            let (s, w) = (c.first as usize, c.second as usize);
            let from = self.center[s];
            let (overlap, normal) = self.walls[w].overlap(&from, self.radius[s], time);
            let to = from + (self.radius[s] - overlap) * normal;
            split(s, Partner::Wall(w), from, to, normal, c.force, (1.0, 1.0))
        });
        pairs.chain(walls)
    }

    /// The spheres of other ranks whose motion this rank receives at each evaluation, in a
    /// run decomposed with split contacts ([`SplitModel`]); 0 otherwise.
    pub fn ghosts(&self) -> usize {
        self.split.as_ref().map_or(0, ContactSplit::ghosts)
    }

    /// How many times the candidate lists were rebuilt.
    pub fn rebuilds(&self) -> u64 {
        self.rebuilds
    }

    /// Fails if two bodies, or a body and a wall, overlap at the current configuration by more
    /// than `tolerance` times the reduced radius (the sphere radius for walls).
    pub fn check_initial_overlaps(
        &mut self,
        state: &State,
        tolerance: f64,
    ) -> Result<(), ContactError> {
        self.read_centers(state);
        self.rebuild(state.time);
        for c in &self.pairs.items {
            let (a, b) = (c.first as usize, c.second as usize);
            let radius = reduced(self.radius[a], self.radius[b]);
            let overlap = self.radius[a] + self.radius[b] - self.separation(a, b).0.norm();
            if overlap > tolerance * radius {
                return Err(ContactError::InitialOverlap {
                    a: self.body_names[self.body[a] as usize].clone(),
                    b: self.body_names[self.body[b] as usize].clone(),
                    overlap,
                    radius,
                    tolerance: 100.0 * tolerance,
                    at_a: self.center[a].into(),
                    at_b: self.center[b].into(),
                });
            }
        }
        for c in &self.wall_contacts.items {
            let (s, w) = (c.first as usize, c.second as usize);
            let (overlap, _) = self.walls[w].overlap(&self.center[s], self.radius[s], state.time);
            if overlap > tolerance * self.radius[s] {
                return Err(ContactError::InitialWallOverlap {
                    body: self.body_names[self.body[s] as usize].clone(),
                    wall: w + 1,
                    overlap,
                    radius: self.radius[s],
                    tolerance: 100.0 * tolerance,
                    at: self.center[s].into(),
                });
            }
        }
        Ok(())
    }

    /// Copies every sphere's centre out of the state, in sphere order, and the narrow phase's
    /// record ([`read_motion`]) of the partners of candidates: in the same pass when most
    /// spheres are partners (a packing), else in a pass over the partners alone (most spheres
    /// of a ballast stone touch nothing); returns the largest distance a sphere has moved
    /// since the last build (infinite before it).
    fn read_centers(&mut self, state: &State) -> f64 {
        let (every, built) = (self.reads_every_sphere(), self.lists_built());
        let (particle, built_at, turn) = (&self.particle, &self.built_at, &self.turn);
        let moved = self
            .center
            .par_iter_mut()
            .zip(self.now.par_iter_mut())
            .with_min_len(SPHERE_CHUNK)
            .enumerate()
            .map(|(s, (center, now))| {
                *center = state.position[particle[s] as usize];
                if every {
                    read_motion(state, *center, particle[s], turn[s], now);
                }
                if built {
                    (*center - built_at[s]).norm_squared()
                } else {
                    f64::INFINITY
                }
            })
            .reduce(|| 0.0, f64::max);
        if !every {
            self.read_partners(state);
        }
        moved.sqrt()
    }

    /// Whether [`DemContacts::read_centers`] fills every sphere's narrow-phase record in its
    /// pass: before the first build, and when most spheres are partners of candidates.
    fn reads_every_sphere(&self) -> bool {
        !self.lists_built() || 2 * self.partners.len() >= self.particle.len()
    }

    /// Whether the candidate lists were built for these spheres (at `built_at`).
    fn lists_built(&self) -> bool {
        self.built && self.built_at.len() == self.particle.len()
    }

    /// The narrow phase's record of every partner of a candidate, from `state`; serial: it
    /// runs only when fewer than half the spheres were partners (in the read, and once after
    /// a rebuild of such lists, for the new partners).
    fn read_partners(&mut self, state: &State) {
        let partners = std::mem::take(&mut self.partners);
        self.read_motions(state, &partners);
        self.partners = partners;
    }

    /// The narrow phase's record ([`read_motion`]) of `spheres` from `state`.
    fn read_motions(&mut self, state: &State, spheres: &[u32]) {
        for &s in spheres {
            let s = s as usize;
            let (particle, turn) = (self.particle[s], self.turn[s]);
            read_motion(state, self.center[s], particle, turn, &mut self.now[s]);
        }
    }

    /// Whether some pair outside the lists may have come within reach since the last build,
    /// given the largest distance a sphere has moved.
    fn needs_rebuild(&self, moved: f64, time: f64) -> bool {
        let wall_moved = self
            .walls
            .iter()
            .map(|w| w.velocity().norm() * (time - self.built_time).abs())
            .fold(0.0, f64::max);
        2.0 * moved >= self.settings.skin || moved + wall_moved >= self.settings.skin
    }

    /// Broad phase: new candidate lists and the incidence of pairs per sphere.
    fn rebuild(&mut self, time: f64) {
        let skin = self.settings.skin;
        let center = self.center.clone();
        let set = SphereSet {
            center: &center,
            radius: &self.radius,
            body: &self.body,
            periodic: self.periodic.as_ref(),
        };
        self.pairs.rebuild(find_pairs(&set, skin));
        let wall_keys = self.wall_keys((0..center.len()).into_par_iter(), time);
        self.wall_contacts.rebuild(wall_keys);
        self.finish_build(time);
    }

    /// The wall candidates of `spheres` (ascending), sorted by sphere then wall.
    fn wall_keys(
        &self,
        spheres: impl IndexedParallelIterator<Item = usize>,
        time: f64,
    ) -> Vec<(u32, u32)> {
        let (walls, skin) = (&self.walls, self.settings.skin);
        let (radius, center) = (&self.radius, &self.center);
        spheres
            .with_min_len(CONTACT_CHUNK)
            .flat_map_iter(|s| {
                walls.iter().enumerate().filter_map(move |(w, wall)| {
                    wall.is_candidate(&center[s], radius[s], skin, time)
                        .then_some((s as u32, w as u32))
                })
            })
            .collect()
    }

    /// After new candidate lists: the incidence, and where and when they were built.
    fn finish_build(&mut self, time: f64) {
        self.build_incidence();
        self.built_at = self.center.clone();
        self.built_time = time;
        self.built = true;
        self.rebuilds += 1;
        self.rebuilt = true;
    }

    /// For each sphere, its pairs (2k for the first partner of pair k, 2k + 1 for the second)
    /// in ascending pair order, and the start of its run of wall contacts.
    fn build_incidence(&mut self) {
        let n = self.particle.len();
        let mut start = vec![0u32; n + 1];
        for c in &self.pairs.items {
            start[c.first as usize + 1] += 1;
            start[c.second as usize + 1] += 1;
        }
        for i in 0..n {
            start[i + 1] += start[i];
        }
        let mut fill = start.clone();
        let mut incidence = vec![0u32; 2 * self.pairs.len()];
        for (k, c) in self.pairs.items.iter().enumerate() {
            let (a, b) = (c.first, c.second);
            incidence[fill[a as usize] as usize] = 2 * k as u32;
            fill[a as usize] += 1;
            incidence[fill[b as usize] as usize] = 2 * k as u32 + 1;
            fill[b as usize] += 1;
        }
        let mut wall_start = vec![0u32; n + 1];
        for c in &self.wall_contacts.items {
            wall_start[c.first as usize + 1] += 1;
        }
        for i in 0..n {
            wall_start[i + 1] += wall_start[i];
        }
        self.partners = (0..n as u32)
            .filter(|&s| {
                let s = s as usize;
                start[s + 1] > start[s] || wall_start[s + 1] > wall_start[s]
            })
            .collect();
        self.incidence_start = start;
        self.incidence = incidence;
        self.wall_start = wall_start;
    }

    /// The geometry and elasticity of the pair of spheres of `contact`, with the image
    /// translation of its second sphere (written into `contact`); `None` when apart.
    #[inline]
    fn pair_contact(&self, contact: &mut Contact) -> Option<(PairGeometry, PairElasticity)> {
        let (a, b) = (contact.first as usize, contact.second as usize);
        let (sa, sb) = (&self.now[a], &self.now[b]);
        contact.shift = self.separation(a, b).1;
        let geometry = narrow_phase(sa, sb, contact.shift, self.settings.friction)?;
        let e = self.elasticity[sa.material as usize * self.materials + sb.material as usize];
        Some((geometry, e))
    }

    /// The geometry and elasticity of the contact of sphere s with wall w: the contact point
    /// at x + (r − δ/2) n, its velocity v + (r − δ/2) ω × n against the wall's; `None` when
    /// apart.
    #[inline]
    fn wall_contact(
        &self,
        time: f64,
        s: usize,
        w: usize,
    ) -> Option<(PairGeometry, PairElasticity)> {
        let wall = &self.walls[w];
        let sphere = &self.now[s];
        let (overlap, normal) = wall.overlap(&sphere.center, sphere.radius, time);
        if overlap <= 0.0 || normal == Vec3::zeros() {
            return None;
        }
        let lever = sphere.radius - 0.5 * overlap;
        let geometry = PairGeometry {
            overlap,
            normal,
            velocity: sphere.velocity + lever * sphere.spin.cross(&normal) - wall.velocity(),
            radius: sphere.radius,
            mass: sphere.mass,
            friction: wall.friction,
        };
        Some((geometry, self.wall_elasticity[sphere.material as usize]))
    }

    /// Narrow phase and law over the pairs and the wall contacts, one parallel region: the
    /// wall contacts are a task beside the pairs' (one record per contact).
    fn evaluate(&mut self, time: f64, dt: f64) {
        let (mut pairs, mut walls) = (
            std::mem::take(&mut self.pairs),
            std::mem::take(&mut self.wall_contacts),
        );
        let this = &*self;
        rayon::join(
            || this.evaluate_list(&mut pairs, time, dt, false),
            || this.evaluate_list(&mut walls, time, dt, true),
        );
        (self.pairs, self.wall_contacts) = (pairs, walls);
    }

    /// Narrow phase and law over one list, in parallel, one record per contact.
    fn evaluate_list(&self, list: &mut ContactList, time: f64, dt: f64, walls: bool) {
        let law = &self.settings.law;
        list.items
            .par_iter_mut()
            .with_min_len(CONTACT_CHUNK)
            .for_each(|contact| {
                let touching = if walls {
                    self.wall_contact(time, contact.first as usize, contact.second as usize)
                } else {
                    self.pair_contact(contact)
                };
                match touching {
                    Some((g, e)) => {
                        let force = law.force(&g, &e, &mut contact.history, dt);
                        contact.touch(force, &g.normal, g.overlap);
                    }
                    None => contact.part(),
                }
            });
    }

    /// The average magnitude of the touching pairs' forces through the boundaries of `axis`.
    fn boundary_force(&self, axis: usize) -> f64 {
        self.mean_pair_force(|c| c.shift[axis] != 0.0)
    }

    /// Measures the boundary force and updates the ghost scales of a time-delayed boundary;
    /// with `split`, this rank's part, over every rank's pairs (a collective).
    fn update_time_delay(&mut self, time: f64, split: Option<&mut ContactSplit>) {
        let Some(axis) = self.time_delay.as_ref().map(|t| t.axis) else {
            return;
        };
        let measured = match split {
            None => self.boundary_force(axis),
            Some(split) => split.mean_force_of(&self.pairs, |c| c.shift[axis] != 0.0),
        };
        let delay = self.time_delay.as_mut().expect("checked above");
        delay.boundary_force = measured;
        delay.scales = delay.boundary.update(time, measured);
    }

    /// Per-sphere sums of contact forces, and their moments about the sphere's centre for
    /// spheres that turn (of rigid bodies, rotating particles), in a fixed order; forces from
    /// delayed ghosts scaled.
    fn gather(&mut self) {
        let mut sphere_force = std::mem::take(&mut self.sphere_force);
        sphere_force
            .par_iter_mut()
            .with_min_len(CONTACT_CHUNK)
            .enumerate()
            .for_each(|(s, out)| *out = self.sphere_sum(s));
        self.sphere_force = sphere_force;
    }

    /// Sphere `s`'s sum of contact forces, and their moment about its centre if it turns,
    /// over its incidence in ascending pair order, then its wall contacts.
    #[inline]
    fn sphere_sum(&self, s: usize) -> (Vec3, Vec3) {
        let (pairs, walls) = (&self.pairs.items, &self.wall_contacts.items);
        let (start, incidence, wall_start) =
            (&self.incidence_start, &self.incidence, &self.wall_start);
        let delay = self.time_delay.as_ref().map(|t| (t.axis, t.scales));
        let (mut f, mut t) = (Vec3::zeros(), Vec3::zeros());
        let (spins, radius) = (self.turn[s] != NOT_RIGID, self.radius[s]);
        for &e in &incidence[start[s] as usize..start[s + 1] as usize] {
            let c = &pairs[(e / 2) as usize];
            let first = e % 2 == 0;
            let scale = match &delay {
                Some((axis, scales)) => {
                    let (a, b) = pair_scales(c.shift[*axis], scales);
                    if first {
                        a
                    } else {
                        b
                    }
                }
                None => 1.0,
            };
            f += if first { scale } else { -scale } * c.force;
            if spins {
                t += c.moment(radius, scale);
            }
        }
        for c in &walls[wall_start[s] as usize..wall_start[s + 1] as usize] {
            f += c.force;
            if spins {
                t += c.moment(radius, 1.0);
            }
        }
        (f, t)
    }

    /// Adds sphere `s`'s contact force `f` to its particle and its moment `t` to the rigid
    /// body or rotating particle it turns with.
    #[inline]
    fn apply(&self, s: usize, f: &Vec3, t: &Vec3, force: &mut [Vec3], torque: &mut [Vec3]) {
        force[self.particle[s] as usize] += f;
        if self.turn[s] != NOT_RIGID {
            torque[self.turn[s] as usize] += t;
        }
    }
}

/// A touching contact of sphere `first` with `second` along the segment `from`–`to`, its
/// force `force` on the first split along the unit normal `normal`.
fn split(
    first: usize,
    second: Partner,
    from: Vec3,
    to: Vec3,
    normal: Vec3,
    force: Vec3,
    scales: (f64, f64),
) -> TouchingContact {
    let normal_force = force.dot(&normal) * normal;
    TouchingContact {
        first,
        second,
        from,
        to,
        normal,
        normal_force,
        tangential_force: force - normal_force,
        scales,
    }
}

/// Sets the centre `center`, velocity and spin of `now`, the sphere on `particle` that turns
/// with `turn` (its rigid body's or its particle's angular velocity, zero for a vertex of a
/// deformable body), from `state`.
#[inline]
fn read_motion(state: &State, center: Vec3, particle: u32, turn: u32, now: &mut SphereNow) {
    let bodies = state.rigid.len();
    now.center = center;
    now.velocity = state.velocity[particle as usize];
    now.spin = match turn as usize {
        t if t == NOT_RIGID as usize => Vec3::zeros(),
        b if b < bodies => state.rigid.angular_velocity[b],
        t => state.spin.velocity[t - bodies],
    };
}

/// The entries `indices` of `values`.
fn pick<T: Copy>(indices: &[u32], values: &[T]) -> Vec<T> {
    indices.iter().map(|&i| values[i as usize]).collect()
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

    fn add_forces(&mut self, state: &State, force: &mut [Vec3], torque: &mut [Vec3]) {
        let dt = self.last_time.map_or(0.0, |t| state.time - t);
        self.last_time = Some(state.time);
        if self.split.is_some() {
            return self.add_split_forces(state, dt, force, torque);
        }
        let moved = self.read_centers(state);
        if self.needs_rebuild(moved, state.time) {
            let read_every = self.reads_every_sphere();
            self.rebuild(state.time);
            if !read_every {
                self.read_partners(state);
            }
        }
        self.evaluate(state.time, dt);
        self.update_time_delay(state.time, None);
        self.gather();
        for (s, (f, t)) in self.sphere_force.iter().enumerate() {
            self.apply(s, f, t, force, torque);
        }
    }

    /// Reads only what a rank steps itself once split ([`SplitModel`]), and fetches its
    /// ghosts.
    fn particle_reads(&self) -> ParticleReads {
        ParticleReads::Local
    }

    fn split_model(&mut self) -> Option<&mut dyn SplitModel> {
        Some(self)
    }

    /// The critical step 2/(√(ω² + γ²/4) + γ/2) of Gershgorin's bounds on M⁻¹K and M⁻¹C
    /// ([`qdem_core::stable_step::critical_step`]) for the worst carrier of spheres: ω² =
    /// 2 Σ k (1/m + ℓ²/I), γ = 2 Σ c (1/m + ℓ²/I) with c = 2ζ√(k m), summed over the contacts
    /// a carrier can have at once: [`COORDINATION`] for a vertex sphere of a deformable body or
    /// a rigid single sphere, one per sphere for a rigid body with several (all of them may
    /// rest on one wall). k is the stiffest of the normal and tangential springs (Hertz's at an
    /// overlap of [`REFERENCE_OVERLAP`] of the radius), m the carrier's mass, ℓ the lever arm
    /// of a contact on a rigid body about its centre and I its smallest principal moment (ℓ = 0
    /// for a body whose rotation is held). Carriers held in every direction are left out.
    fn stable_dt(&self, _state: &State) -> Option<f64> {
        let law = &self.settings.law;
        let zeta = law.damping_ratio();
        let n_rigid = self
            .rigid
            .iter()
            .filter(|&&r| r != NOT_RIGID)
            .map(|&r| r as usize + 1)
            .max()
            .unwrap_or(0);
        let mut per_body = vec![(0.0, 0.0, 0usize); n_rigid];
        let mut worst = (0.0f64, 0.0f64);
        for s in 0..self.particle.len() {
            let r = self.radius[s];
            let sphere = &self.now[s];
            let e = self.wall_elasticity[sphere.material as usize];
            let (kn, kt) = law.stiffness(REFERENCE_OVERLAP * r, r, &e);
            let k = kn.max(kt);
            let mass = self.bound_mass[s];
            if mass.is_infinite() {
                continue;
            }
            let compliance = 1.0 / mass + self.lever[s];
            let (w, g) = (k * compliance, 2.0 * zeta * (k * mass).sqrt() * compliance);
            match self.rigid[s] {
                NOT_RIGID => worst = (worst.0.max(COORDINATION * w), worst.1.max(COORDINATION * g)),
                b => {
                    let entry = &mut per_body[b as usize];
                    *entry = (entry.0 + w, entry.1 + g, entry.2 + 1);
                }
            }
        }
        for (w, g, count) in per_body {
            let scale = if count == 1 { COORDINATION } else { 1.0 };
            worst = (worst.0.max(scale * w), worst.1.max(scale * g));
        }
        let (omega_squared, damping_rate) = (2.0 * worst.0, 2.0 * worst.1);
        (omega_squared > 0.0).then(|| critical_step(omega_squared, damping_rate))
    }

    fn potential_energy(&self, state: &State) -> Option<f64> {
        let law = &self.settings.law;
        let pairs = self.pairs.items.iter().filter_map(|c| {
            self.pair_contact(&mut c.clone())
                .map(|(g, e)| law.energy(&g, &e, &c.history))
        });
        let walls = self.wall_contacts.items.iter().filter_map(|c| {
            self.wall_contact(state.time, c.first as usize, c.second as usize)
                .map(|(g, e)| law.energy(&g, &e, &c.history))
        });
        Some(pairs.chain(walls).sum())
    }

    fn persistence(&self) -> Persistence<'_> {
        Persistence::Saved(self)
    }

    fn persistent_mut(&mut self) -> Option<&mut dyn Persistent> {
        Some(self)
    }

    /// The contacts touching at the last evaluation, as sticking springs
    /// (`contact_springs.rs`), attached through the arm to the contact point to the
    /// rotation of a sphere that turns (a rigid body's, a rotating particle's). The contacts
    /// give no [`Model::linearized`] facet: an implicit step would need the events of contacts
    /// opening and closing.
    fn modal_stiffness(&self) -> Option<&dyn Linearized> {
        Some(self)
    }
}

impl DemContacts {
    /// Where sphere `s`'s side of a contact attaches, the contact point at `arm` from its
    /// centre.
    fn attachment(&self, state: &State, s: usize, arm: Vec3) -> Attachment {
        let bodies = state.rigid.len();
        let node = match self.turn[s] {
            NOT_RIGID => None,
            t if (t as usize) < bodies => Some(state.body_rotation_node(t as usize)),
            t => Some(state.len() + t as usize - bodies),
        };
        Attachment {
            particle: self.particle[s] as usize,
            turn: node.map(|n| (n, arm)),
        }
    }
}

/// One rank's part of the contacts ([`crate::contact_split`]).
impl DemContacts {
    /// [`Model::add_forces`] of one rank's part: its own spheres read, the ghosts received
    /// (every sphere at a rebuild, which the ranks agree on), the rank's contacts evaluated,
    /// and each own sphere's sum added.
    fn add_split_forces(
        &mut self,
        state: &State,
        dt: f64,
        force: &mut [Vec3],
        torque: &mut [Vec3],
    ) {
        let mut split = self.split.take().expect("a split contact set");
        if split.whole {
            self.cut_to_rank(&mut split);
        }
        let moved = split.max_over_ranks(self.read_own_centers(state, &split.own));
        if self.needs_rebuild(moved, state.time) {
            split.share_all(&mut self.now, &mut self.center);
            self.rebuild_near(&split, state.time);
            self.learn_partners(&mut split);
        }
        self.read_motions(state, &split.partners);
        split.share_ghosts(&mut self.now, &mut self.center);
        self.evaluate(state.time, dt);
        self.update_time_delay(state.time, Some(&mut split));
        let this = &*self;
        let mut sums = std::mem::take(&mut split.sums);
        sums.resize(split.partners.len(), (Vec3::zeros(), Vec3::zeros()));
        sums.par_iter_mut()
            .zip(&split.partners)
            .with_min_len(CONTACT_CHUNK)
            .for_each(|(sum, &s)| *sum = this.sphere_sum(s as usize));
        for (&s, (f, t)) in split.partners.iter().zip(&sums) {
            self.apply(s as usize, f, t, force, torque);
            self.sphere_force[s as usize] = (*f, *t);
        }
        split.sums = sums;
        self.split = Some(split);
    }

    /// Reads the centres of the spheres `own` from `state`; returns the largest distance one
    /// has moved since the last build (infinite before it).
    fn read_own_centers(&mut self, state: &State, own: &[u32]) -> f64 {
        let built = self.lists_built();
        let mut moved: f64 = if built { 0.0 } else { f64::INFINITY };
        for &s in own {
            let s = s as usize;
            let center = state.position[self.particle[s] as usize];
            if built {
                moved = moved.max((center - self.built_at[s]).norm_squared());
            }
            self.center[s] = center;
        }
        moved.sqrt()
    }

    /// After new lists: the ghosts this rank receives (a collective), the own spheres whose
    /// motion the lists read, and zero force on the own spheres that touch nothing now.
    fn learn_partners(&mut self, split: &mut ContactSplit) {
        split.set_ghosts(&self.ghosts_of(split));
        split.partners = self
            .partners
            .iter()
            .copied()
            .filter(|&s| split.owns(s))
            .collect();
        for &s in &split.own {
            self.sphere_force[s as usize] = (Vec3::zeros(), Vec3::zeros());
        }
    }

    /// The broad phase of one rank, once it holds every sphere's centre: the pairs that touch
    /// a sphere it owns, found among the spheres within reach of the box around its own
    /// (along a periodic axis, those with an image there), and its own spheres' wall
    /// candidates; the springs of the pairs that stay are kept.
    fn rebuild_near(&mut self, split: &ContactSplit, time: f64) {
        let reach = 2.0 * self.radius.iter().cloned().fold(0.0, f64::max) + self.settings.skin;
        let (mut low, mut high) = (Vec3::repeat(f64::INFINITY), Vec3::repeat(f64::NEG_INFINITY));
        for &s in &split.own {
            low = low.inf(&self.center[s as usize]);
            high = high.sup(&self.center[s as usize]);
        }
        let (start, width) = (
            low.add_scalar(-reach),
            high - low + Vec3::repeat(2.0 * reach),
        );
        let period = |k: usize| self.periodic.as_ref().and_then(|p| p.length(k));
        let within = |k: usize, x: f64| match period(k) {
            Some(l) if width[k] < l => (x - start[k]).rem_euclid(l) <= width[k],
            Some(_) => true,
            None => x >= start[k] && x - start[k] <= width[k],
        };
        let near: Vec<u32> = (0..self.center.len() as u32)
            .filter(|&s| (0..3).all(|k| within(k, self.center[s as usize][k])))
            .collect();
        self.rebuild_among(split, &near, time);
    }

    /// [`DemContacts::rebuild_near`] among the spheres `near` (ascending).
    fn rebuild_among(&mut self, split: &ContactSplit, near: &[u32], time: f64) {
        let skin = self.settings.skin;
        let (center, radius, body) = (
            pick(near, &self.center),
            pick(near, &self.radius),
            pick(near, &self.body),
        );
        let set = SphereSet {
            center: &center,
            radius: &radius,
            body: &body,
            periodic: self.periodic.as_ref(),
        };
        let keys = find_pairs(&set, skin)
            .into_iter()
            .map(|(a, b)| (near[a as usize], near[b as usize]))
            .filter(|&(a, b)| split.owns(a) || split.owns(b))
            .collect();
        self.pairs.rebuild(keys);
        let own = split.own.par_iter().map(|&s| s as usize);
        let wall_keys = self.wall_keys(own, time);
        self.wall_contacts.rebuild(wall_keys);
        self.finish_build(time);
    }

    /// The partners of this rank's pairs that other ranks own, ascending.
    fn ghosts_of(&self, split: &ContactSplit) -> Vec<u32> {
        let mut ghosts: Vec<u32> = self
            .pairs
            .items
            .iter()
            .flat_map(|c| [c.first, c.second])
            .filter(|&s| !split.owns(s))
            .collect();
        ghosts.sort_unstable();
        ghosts.dedup();
        ghosts
    }

    /// Cuts lists that hold every rank's contacts (after a merge, a restore) down to this
    /// rank's, and asks for their ghosts: a collective.
    fn cut_to_rank(&mut self, split: &mut ContactSplit) {
        self.pairs.items.retain(|c| split.keeps(c, false));
        self.wall_contacts.items.retain(|c| split.keeps(c, true));
        self.build_incidence();
        self.learn_partners(split);
        split.whole = false;
    }
}

impl SplitModel for DemContacts {
    /// The particles of every sphere (those of deformable bodies already have owners).
    fn free_particles(&self) -> Vec<usize> {
        self.particle.iter().map(|&p| p as usize).collect()
    }

    fn split(&mut self, split: Option<Ownership>) {
        self.split = split.map(|(owner, comm)| {
            let mut part = ContactSplit::new(&self.particle, &owner, comm);
            part.whole = true;
            part
        });
    }

    /// Merges the ranks' lists, receives every sphere's record of the last evaluation, and
    /// sums every sphere's contacts as one process does.
    fn gather(&mut self) {
        let Some(mut split) = self.split.take() else {
            return;
        };
        if !split.whole {
            self.pairs = split.merge(&self.pairs);
            self.wall_contacts = split.merge(&self.wall_contacts);
            split.share_all(&mut self.now, &mut self.center);
            self.build_incidence();
            self.gather();
            split.whole = true;
        }
        self.split = Some(split);
    }

    fn rebuilt(&mut self) -> bool {
        std::mem::take(&mut self.rebuilt)
    }

    /// `CANDIDATE_WORK` (three) per candidate contact this rank evaluates.
    fn work(&self) -> f64 {
        CANDIDATE_WORK * self.candidates() as f64
    }

    /// Half of `CANDIDATE_WORK` per candidate pair to each partner's particle, all of it
    /// per wall candidate.
    fn add_costs(&self, cost: &mut [f64]) {
        let half = 0.5 * CANDIDATE_WORK;
        for c in &self.pairs.items {
            cost[self.particle[c.first as usize] as usize] += half;
            cost[self.particle[c.second as usize] as usize] += half;
        }
        for c in &self.wall_contacts.items {
            cost[self.particle[c.first as usize] as usize] += CANDIDATE_WORK;
        }
    }
}

impl Linearized for DemContacts {
    /// The springs of the contacts touching at the last evaluation, at the geometry it saw.
    fn add_tangent(&self, state: &State, tangent: &mut Tangent) {
        let law = &self.settings.law;
        for c in &self.pairs.items {
            let (a, b) = (c.first as usize, c.second as usize);
            let (sa, sb) = (&self.now[a], &self.now[b]);
            let shift = self.separation(a, b).1;
            let Some(g) = narrow_phase(sa, sb, shift, self.settings.friction) else {
                continue;
            };
            let e = self.elasticity[sa.material as usize * self.materials + sb.material as usize];
            let (kn, kt) = law.stiffness(g.overlap, g.radius, &e);
            let half = 0.5 * g.overlap;
            let pa = self.attachment(state, a, (sa.radius - half) * g.normal);
            let pb = self.attachment(state, b, -(sb.radius - half) * g.normal);
            add_spring(tangent, pa, Some(pb), &spring(&g.normal, kn, kt));
        }
        let time = self.last_time.unwrap_or(0.0);
        for c in &self.wall_contacts.items {
            let (s, w) = (c.first as usize, c.second as usize);
            let Some((g, e)) = self.wall_contact(time, s, w) else {
                continue;
            };
            let (kn, kt) = law.stiffness(g.overlap, g.radius, &e);
            let arm = (self.now[s].radius - 0.5 * g.overlap) * g.normal;
            let side = self.attachment(state, s, arm);
            add_spring(tangent, side, None, &spring(&g.normal, kn, kt));
        }
    }
}

impl Persistent for DemContacts {
    /// The candidate lists with their tangential springs, where and when they were built, and
    /// the time-delayed boundary's estimates: everything but the sphere centres, which are
    /// read from the state.
    fn save(&self, out: &mut Encoder) {
        out.tag("contact");
        out.option_f64(self.last_time);
        out.bool(self.built);
        out.f64(self.built_time);
        out.vec3s(&self.built_at);
        out.u64(self.rebuilds);
        self.pairs.save(out);
        self.wall_contacts.save(out);
        out.bool(self.time_delay.is_some());
        if let Some(delay) = &self.time_delay {
            out.f64(delay.scales.left);
            out.f64(delay.scales.right);
            out.f64(delay.boundary_force);
            delay.boundary.save(out);
        }
    }
    fn restore(&mut self, input: &mut Decoder<'_>) -> Result<(), CheckpointError> {
        input.tag("contact")?;
        let spheres = self.particle.len();
        self.last_time = input.option_f64("the last evaluation time")?;
        self.built = input.bool("the build flag")?;
        self.built_time = input.f64("the build time")?;
        self.built_at = input.vec3s("the build positions")?;
        if self.built {
            same_count("contact spheres", spheres, self.built_at.len())?;
        }
        self.rebuilds = input.u64("the rebuild count")?;
        self.pairs = ContactList::restore(input, spheres, spheres)?;
        self.wall_contacts = ContactList::restore(input, spheres, self.walls.len())?;
        let delayed = input.bool("the time-delay flag")?;
        same_count(
            "time-delayed boundaries",
            self.time_delay.is_some() as usize,
            delayed as usize,
        )?;
        if let Some(delay) = &mut self.time_delay {
            delay.scales = GhostScales {
                left: input.f64("the left ghost scale")?,
                right: input.f64("the right ghost scale")?,
            };
            delay.boundary_force = input.f64("the boundary force")?;
            delay.boundary.restore(input)?;
        }
        self.build_incidence();
        if let Some(split) = &mut self.split {
            split.whole = true;
        }
        Ok(())
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
