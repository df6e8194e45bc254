//! The interpenetration watch: after every step of a run with contact spheres, every
//! touching pair of spheres of two bodies is checked for an overlap deeper than the smaller
//! sphere's radius. A contact spring holds two bodies apart only while its spheres overlap
//! by less than their radii: past that a sphere's centre is inside the other sphere, and
//! once the centres cross the normal turns round and the contact pulls the bodies through
//! each other. Two rubber blocks of `fixtures/contact/collision.toml` thrown at each other at
//! ±40 m/s did that, silently, at the scene's dt and at a tenth of it alike (the centres end
//! 1.68 m and −1.89 m from where they started, against −0.2 m and 0 m, both ways): the
//! contact is too soft, or its spheres too small, for the speed; the step is not the cause.
//! The run stops with [`Interpenetration`], naming the bodies, the overlap, their approach
//! speed and the fix; a smaller dt is the fix only when the approach per step is a sizeable
//! part of the radius (above [`STEP_FRACTION`]) and no load is beyond what the bodies carry
//! (`load_cause`: at ±400 m/s the rubber blocks meet at twice their wave speed, and the
//! velocity, not the step, is named).
//!
//! What it does not see: a sphere that slips between two spheres of the other body (the
//! spheres sit at the surface vertices only, and leave gaps where the vertices are more than
//! two radii apart) without ever overlapping one by a radius: the contacts' pass-through
//! check (`qdem-contact/src/dem/contacts/tunnelling.rs`, at each rebuild of the lists) stops
//! that once the sphere is deeper than its radius in the other body. No normal run comes
//! near the test: the deepest overlap of the fixture scenes is a fraction of a radius
//! (docs/reliability.md). Reading the contacts changes nothing in the state, so outputs stay
//! the same. It watches the scenes of two or more `[[body]]`s with contact spheres and no
//! `[granular]` or `[ballast]` stones: reading every touching contact after every step
//! (through the output view, before [`qdem_contact::DemContacts::deepest_pair`]) cost the
//! 2,000 grains of `fixtures/contact/grains.toml` a quarter of their run time (1.24× and
//! 1.29×, A B A B), where stones, not bodies, touch: a stone's sphere deep in another body's
//! is stopped instead by the contacts' pass-through check at each rebuild of the lists
//! (`qdem-contact/src/dem/contacts/tunnelling.rs`), on one process and over ranks. A run
//! decomposed over MPI ranks has no watch (each rank sees only its own contacts).

use crate::build::{BodyInfo, Simulation};
use crate::run::load_cause::load_cause;
use qdem_core::Vec3;
use thiserror::Error;

/// Two bodies that pass through each other: what the run stops with.
#[derive(Debug, Error)]
#[error(
    "bodies `{first}` and `{second}` pass through each other at step {step} (t = {time:.6e} s): \
     two of their contact spheres overlap by {overlap:.3e} m, more than the sphere radius \
     {radius:.3e} m, so the contact no longer holds them apart; the bodies move at \
     {speed:.3e} m/s against each other ({per_step:.3e} m per step of dt = {dt:.3e} s, \
     {fraction:.2} of the radius). {fix}"
)]
pub struct Interpenetration {
    /// The first body's name.
    pub first: String,
    /// The second body's name.
    pub second: String,
    /// The step.
    pub step: u64,
    /// The time (s).
    pub time: f64,
    /// The overlap (m).
    pub overlap: f64,
    /// The smaller sphere radius (m).
    pub radius: f64,
    /// The bodies' relative speed (m/s).
    pub speed: f64,
    /// Their relative motion per step (m).
    pub per_step: f64,
    /// The step (s).
    pub dt: f64,
    /// The motion per step over the radius.
    pub fraction: f64,
    /// What to change.
    pub fix: String,
}

/// Above this relative motion per step, as a fraction of the sphere radius, a smaller dt is
/// the fix.
pub const STEP_FRACTION: f64 = 0.5;

/// The watch of a run: each sphere's radius, particle and body, and the body names.
pub(crate) struct ContactWatch {
    radius: Vec<f64>,
    particle: Vec<usize>,
    body: Vec<usize>,
    names: Vec<String>,
}

impl ContactWatch {
    /// The watch of `sim`, or `None` unless two or more `[[body]]`s carry contact spheres
    /// and no stones do (see the module docs).
    pub(crate) fn new(sim: &Simulation) -> Option<ContactWatch> {
        let bodies = sim
            .scene
            .bodies
            .iter()
            .filter(|b| b.contact_radius.is_some());
        if bodies.count() < 2 || sim.granular.is_some() || sim.ballast.is_some() {
            return None;
        }
        let contacts = sim.contacts()?;
        let spheres: Vec<_> = contacts.sphere_records(&sim.world.state).collect();
        Some(ContactWatch {
            radius: spheres.iter().map(|s| s.radius).collect(),
            particle: spheres.iter().map(|s| s.particle).collect(),
            body: spheres.iter().map(|s| s.body).collect(),
            names: contacts.body_names().to_vec(),
        })
    }

    /// After `step`: the touching pair of spheres that overlaps most for its size, if by more than the
    /// smaller radius, as an [`Interpenetration`].
    pub(crate) fn check(&self, sim: &Simulation, step: u64) -> Result<(), Box<Interpenetration>> {
        let Some(contacts) = sim.contacts() else {
            return Ok(());
        };
        match contacts.deepest_pair() {
            Some((a, b, overlap)) if overlap > self.radius[a].min(self.radius[b]) => {
                Err(Box::new(self.report(sim, step, (a, b), overlap)))
            }
            _ => Ok(()),
        }
    }

    /// The `[[body]]` of sphere `s`, if it belongs to one (not to a stone).
    fn body_of<'s>(&self, sim: &'s Simulation, s: usize) -> Option<&'s BodyInfo> {
        let name = &self.names[self.body[s]];
        sim.bodies.iter().find(|b| &b.name == name)
    }

    /// The report of spheres `a` and `b` overlapping by `overlap`. The speed is the bodies'
    /// (their particles' mean velocities), since the contact has slowed the two spheres.
    fn report(
        &self,
        sim: &Simulation,
        step: u64,
        (a, b): (usize, usize),
        overlap: f64,
    ) -> Interpenetration {
        let state = &sim.world.state;
        let velocity = |s: usize| {
            self.body_of(sim, s)
                .map_or(state.velocity[self.particle[s]], |body| {
                    let v = &state.velocity[body.particles.clone()];
                    v.iter().sum::<Vec3>() / v.len().max(1) as f64
                })
        };
        let speed = (velocity(a) - velocity(b)).norm();
        let radius = self.radius[a].min(self.radius[b]);
        let dt = sim.world.dt();
        let fraction = speed * dt / radius;
        let fix = if let Some(cause) = load_cause(sim) {
            cause
        } else if fraction > STEP_FRACTION {
            format!(
                "fix: a smaller step, dt <= {:.3e} s (a tenth of the radius per step at this \
                 speed), or a lower speed",
                0.1 * radius / speed
            )
        } else {
            format!(
                "fix: larger contact spheres (contact_radius), a stiffer contact ([contact] \
                 normal_stiffness, or the bodies' young with hertz-mindlin), or a lower speed; \
                 a smaller dt does not help here, the motion per step is only {fraction:.2} of \
                 the radius"
            )
        };
        Interpenetration {
            first: self.names[self.body[a]].clone(),
            second: self.names[self.body[b]].clone(),
            step,
            time: state.time,
            overlap,
            radius,
            speed,
            per_step: speed * dt,
            dt,
            fraction,
            fix,
        }
    }
}
