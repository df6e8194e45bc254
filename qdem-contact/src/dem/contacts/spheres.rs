//! The sphere records of the contact model as a part of their own: per contact sphere its
//! particle, radius, body, the rigid body or rotating particle it turns with, its carrier's
//! mass and lever for the stable step, whether its carriers are its alone, and what the
//! narrow phase reads of it now (centre, velocity, spin: [`SphereNow`]), read from the
//! state at each evaluation; with them the names of their bodies and the elastic constants
//! of each pair of their materials.

use super::spatial_order::permuted;
use super::{SphereNow, NOT_RIGID, SPHERE_CHUNK, TEAM_SPHERES};
use crate::dem::laws::contact_law::PairElasticity;
use qdem_core::step::team::{self, Team};
use qdem_core::{step::State, Vec3};
use rayon::prelude::*;

/// The contact spheres' records, by sphere.
pub(super) struct Spheres {
    particle: Vec<u32>,
    radius: Vec<f64>,
    body: Vec<u32>,
    /// The rigid body of each sphere, [`NOT_RIGID`] for none.
    rigid: Vec<u32>,
    /// The rotation each sphere's moment goes to (a rigid body, then the rotating
    /// particles), [`NOT_RIGID`] for none.
    turn: Vec<u32>,
    /// Per sphere, whether its particle and rotation are its alone (`pair_kernel.rs`).
    exclusive: Vec<bool>,
    /// ℓ²/I of the carrier, for the stable step.
    lever: Vec<f64>,
    /// The carrier's mass for the stable step (infinite when held).
    bound_mass: Vec<f64>,
    /// Every sphere's centre at the last evaluation.
    center: Vec<Vec3>,
    /// What the narrow phase reads of each sphere, current for the partners of candidates.
    now: Vec<SphereNow>,
    /// The names of the bodies (`body` indexes them).
    body_names: Vec<String>,
    /// Number of materials.
    materials: usize,
    /// The elastic constants of each pair of materials, row by row.
    elasticity: Vec<PairElasticity>,
}

/// What [`Spheres::new`] takes, per sphere.
pub(super) struct SphereColumns<'a> {
    pub(super) particle: Vec<u32>,
    pub(super) radius: Vec<f64>,
    pub(super) body: Vec<u32>,
    pub(super) rigid: Vec<u32>,
    pub(super) turn: Vec<u32>,
    pub(super) exclusive: Vec<bool>,
    pub(super) lever: Vec<f64>,
    pub(super) bound_mass: Vec<f64>,
    pub(super) now: Vec<SphereNow>,
    pub(super) body_names: Vec<String>,
    /// The elastic constants (E, ν) of each material.
    pub(super) materials: &'a [(f64, f64)],
}

impl Spheres {
    /// The records of `columns`, every centre at the origin until the first read.
    pub(super) fn new(columns: SphereColumns<'_>) -> Spheres {
        let n = columns.particle.len();
        let materials = columns.materials;
        let elasticity = materials
            .iter()
            .flat_map(|a| materials.iter().map(|b| PairElasticity::new(*a, Some(*b))))
            .collect();
        Spheres {
            particle: columns.particle,
            radius: columns.radius,
            body: columns.body,
            rigid: columns.rigid,
            turn: columns.turn,
            exclusive: columns.exclusive,
            lever: columns.lever,
            bound_mass: columns.bound_mass,
            center: vec![Vec3::zeros(); n],
            now: columns.now,
            body_names: columns.body_names,
            materials: materials.len(),
            elasticity,
        }
    }

    /// Renumbers the spheres (`spatial_order.rs`): slot `s` takes the records of slot
    /// `from[s]`.
    pub(super) fn permute(&mut self, from: &[u32]) {
        self.particle = permuted(&self.particle, from);
        self.radius = permuted(&self.radius, from);
        self.body = permuted(&self.body, from);
        self.rigid = permuted(&self.rigid, from);
        self.turn = permuted(&self.turn, from);
        self.exclusive = permuted(&self.exclusive, from);
        self.lever = permuted(&self.lever, from);
        self.bound_mass = permuted(&self.bound_mass, from);
        self.center = permuted(&self.center, from);
        self.now = permuted(&self.now, from);
    }

    /// Number of spheres.
    #[inline]
    pub(super) fn len(&self) -> usize {
        self.particle.len()
    }

    /// The particle of each sphere.
    #[inline]
    pub(super) fn particle(&self) -> &[u32] {
        &self.particle
    }

    /// The radius of each sphere.
    #[inline]
    pub(super) fn radius(&self) -> &[f64] {
        &self.radius
    }

    /// The body of each sphere.
    #[inline]
    pub(super) fn body(&self) -> &[u32] {
        &self.body
    }

    /// The rigid body of each sphere, [`NOT_RIGID`] for none.
    #[inline]
    pub(super) fn rigid(&self) -> &[u32] {
        &self.rigid
    }

    /// The rotation each sphere's moment goes to, [`NOT_RIGID`] for none.
    #[inline]
    pub(super) fn turn(&self) -> &[u32] {
        &self.turn
    }

    /// Whether sphere `s`'s particle and rotation are its alone.
    #[inline]
    pub(super) fn exclusive(&self, s: usize) -> bool {
        self.exclusive[s]
    }

    /// ℓ²/I of each sphere's carrier.
    #[inline]
    pub(super) fn lever(&self) -> &[f64] {
        &self.lever
    }

    /// The mass of each sphere's carrier for the stable step.
    #[inline]
    pub(super) fn bound_mass(&self) -> &[f64] {
        &self.bound_mass
    }

    /// Every sphere's centre at the last evaluation.
    #[inline]
    pub(super) fn center(&self) -> &[Vec3] {
        &self.center
    }

    /// What the narrow phase reads of sphere `s`.
    #[inline(always)]
    pub(super) fn now(&self, s: usize) -> &SphereNow {
        &self.now[s]
    }

    /// What the narrow phase reads of every sphere.
    #[inline]
    pub(super) fn records(&self) -> &[SphereNow] {
        &self.now
    }

    /// The names of the bodies the spheres belong to.
    #[inline]
    pub(super) fn body_names(&self) -> &[String] {
        &self.body_names
    }

    /// The elastic constants of the pair of spheres `a` and `b`.
    #[inline(always)]
    pub(super) fn pair_elasticity(&self, a: &SphereNow, b: &SphereNow) -> PairElasticity {
        self.elasticity[a.material as usize * self.materials + b.material as usize]
    }

    /// Every sphere's centre and narrow-phase record from `state`, in parallel (a phase of
    /// the current team, else a rayon region); returns the largest distance one has moved
    /// from `built_at` (infinite without it).
    pub(super) fn read_every(&mut self, state: &State, built_at: Option<&[Vec3]>) -> f64 {
        team::with_current(|team| match team {
            Some(team) => self.read_every_on(team, state, built_at),
            None => self.read_every_on_rayon(state, built_at),
        })
    }

    /// [`Spheres::read_every`] on `team`: contiguous pieces of at least [`TEAM_SPHERES`]
    /// spheres, one per thread; the largest displacement is the maximum of the pieces'.
    fn read_every_on(&mut self, team: &Team, state: &State, built_at: Option<&[Vec3]>) -> f64 {
        let n = self.center.len();
        let parts = (n / TEAM_SPHERES).clamp(1, team.size());
        let length = n.div_ceil(parts).max(1);
        let (particle, turn) = (&self.particle, &self.turn);
        let pieces: Vec<_> = self
            .center
            .chunks_mut(length)
            .zip(self.now.chunks_mut(length))
            .enumerate()
            .collect();
        let moved = team.run(pieces, |(k, (center, now))| {
            let first = k * length;
            let mut moved: f64 = 0.0;
            for (i, (center, now)) in center.iter_mut().zip(now).enumerate() {
                let s = first + i;
                *center = state.position[particle[s] as usize];
                read_motion(state, *center, particle[s], turn[s], now);
                moved = moved.max(match built_at {
                    Some(built_at) => (*center - built_at[s]).norm_squared(),
                    None => f64::INFINITY,
                });
            }
            moved
        });
        moved.into_iter().fold(0.0, f64::max).sqrt()
    }

    /// [`Spheres::read_every`] as a rayon region.
    fn read_every_on_rayon(&mut self, state: &State, built_at: Option<&[Vec3]>) -> f64 {
        if self.center.len() >= 2 * SPHERE_CHUNK && rayon::current_num_threads() > 1 {
            team::note_rayon_region();
        }
        let (particle, turn) = (&self.particle, &self.turn);
        self.center
            .par_iter_mut()
            .zip(self.now.par_iter_mut())
            .with_min_len(SPHERE_CHUNK)
            .enumerate()
            .map(|(s, (center, now))| {
                *center = state.position[particle[s] as usize];
                read_motion(state, *center, particle[s], turn[s], now);
                match built_at {
                    Some(built_at) => (*center - built_at[s]).norm_squared(),
                    None => f64::INFINITY,
                }
            })
            .reduce(|| 0.0, f64::max)
            .sqrt()
    }

    /// Copies every sphere's centre out of the state.
    pub(super) fn read_every_center(&mut self, state: &State) {
        let particle = &self.particle;
        self.center
            .par_iter_mut()
            .with_min_len(SPHERE_CHUNK)
            .enumerate()
            .for_each(|(s, center)| *center = state.position[particle[s] as usize]);
    }

    /// The centres of the spheres `own` from `state`; returns the largest distance one has
    /// moved from `built_at` (infinite without it).
    pub(super) fn read_centers_of(
        &mut self,
        state: &State,
        own: &[u32],
        built_at: Option<&[Vec3]>,
    ) -> f64 {
        let mut moved: f64 = if built_at.is_some() {
            0.0
        } else {
            f64::INFINITY
        };
        for &s in own {
            let s = s as usize;
            let center = state.position[self.particle[s] as usize];
            if let Some(built_at) = built_at {
                moved = moved.max((center - built_at[s]).norm_squared());
            }
            self.center[s] = center;
        }
        moved.sqrt()
    }

    /// The centres and the narrow phase's records ([`read_motion`]) of `spheres` from `state`.
    pub(super) fn read_motions(&mut self, state: &State, spheres: &[u32]) {
        for &s in spheres {
            let s = s as usize;
            let (particle, turn) = (self.particle[s], self.turn[s]);
            self.center[s] = state.position[particle as usize];
            read_motion(state, self.center[s], particle, turn, &mut self.now[s]);
        }
    }

    /// Sets sphere `s`'s centre, velocity and spin (a ghost's record from its owner).
    pub(super) fn set_motion(&mut self, s: usize, center: Vec3, velocity: Vec3, spin: Vec3) {
        let n = &mut self.now[s];
        n.center = center;
        n.velocity = velocity;
        n.spin = spin;
        self.center[s] = n.center;
    }

    /// Adds sphere `s`'s contact force `f` to its particle and its moment `t` to the rigid
    /// body or rotating particle it turns with.
    #[inline]
    pub(super) fn add_to(
        &self,
        s: usize,
        f: &Vec3,
        t: &Vec3,
        force: &mut [Vec3],
        torque: &mut [Vec3],
    ) {
        force[self.particle[s] as usize] += f;
        if self.turn[s] != NOT_RIGID {
            torque[self.turn[s] as usize] += t;
        }
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
