//! Explicit velocity Verlet, the integrator of paper 000 §2.4.
//!
//! v_{n+½} = v_n + ½∆t a_n; x_{n+1} = x_n + ∆t v_{n+½};
//! a_{n+1} = M⁻¹ f(t_{n+1}, x_{n+1}, v_{n+½}); v_{n+1} = v_{n+½} + ½∆t a_{n+1}.
//! Viscous forces see the half-step velocity, as in explicit FE codes, which is what the step
//! bound of [`mod@crate::continuum::stable_step`] assumes. Fixed directions keep zero velocity.
//!
//! Particle rotations ([`crate::step::ParticleSpin`]: a one-sphere grain, a bonded particle) are
//! integrated the same way, ω_{n+½} = ω_n + ½∆t M_n/J, θ_{n+1} = θ_n + ∆t ω_{n+½},
//! ω_{n+1} = ω_{n+½} + ½∆t M_{n+1}/J. Rigid bodies ([`crate::step::rigid_body`]) ride along: their
//! angular momentum gets the same two half kicks from the torque and their orientation the
//! drift, and their members are placed after each; bodies held at points
//! ([`crate::step::rigid_constraints`]) get the forces that hold them before the second half
//! kick, their pose corrected after the drift and their velocity projected after each kick. An
//! optional local damping
//! ([`crate::solvers::local_damping`]) acts on the summed forces before they become accelerations.
//!
//! A step is two sweeps over the particles besides the forces
//! (`qdem-core/src/solvers/verlet_sweeps.rs`): the first half kick with the drift and the zeroing of
//! the force sums, and, after the forces, a deferred uniform field (gravity), local damping,
//! the accelerations, the second half kick and the finiteness check. In a run decomposed with
//! a halo exchange ([`Seam::stepped`]) the sweeps cover only the rank's own
//! particles and its halo ([`crate::step::local_particles`]), and the force sums are
//! zeroed whole by [`Seam::sum_forces`]. With a team of threads installed
//! ([`crate::step::team`]) a step holds it, and the sweeps run as its phases.

use crate::checkpoint::{same_count, CheckpointError, Decoder, Encoder};
use crate::error::CoreError;
use crate::solvers::local_damping;
use crate::solvers::verlet_sweeps::{self, DofArrays, KickSettings, Particles};
use crate::step::model::Model;
use crate::step::rigid_body::RigidBodies;
use crate::step::rigid_body::{place_member_velocities, place_members, place_members_keeping_arms};
use crate::step::seam::Seam;
use crate::step::stages::{Stage, StageTimes};
use crate::step::state::State;
use crate::step::stepper::{check_finite_torque, check_masses, hold_in_frames, Stepper};
use crate::step::team;
use crate::Vec3;

/// Velocity Verlet with a fixed step.
///
/// ```
/// use qdem_core::{loads::Gravity, step::Model, step::State, step::Stepper, Vec3, solvers::Verlet};
///
/// // A particle dropped from rest: under a constant force velocity Verlet is exact.
/// let mut state = State::at_rest(vec![Vec3::zeros()]);
/// state.mass[0] = 2.0;
/// let g = Vec3::new(0.0, 0.0, -9.81);
/// let mut models: Vec<Box<dyn Model>> = vec![Box::new(Gravity::new(g))];
/// let mut verlet = Verlet::new(1e-3);
/// verlet.initialize(&mut state, &mut models)?;
/// for _ in 0..500 {
///     verlet.step(&mut state, &mut models)?;
/// }
/// let t = state.time;
/// assert!((t - 0.5).abs() < 1e-12);
/// assert!((state.position[0] - 0.5 * g * t * t).norm() < 1e-12);
/// assert!((state.velocity[0] - g * t).norm() < 1e-12);
/// # Ok::<(), qdem_core::error::CoreError>(())
/// ```
#[derive(Clone, Debug)]
pub struct Verlet {
    dt: f64,
    local_damping: f64,
    force: Vec<Vec3>,
    torque: Vec<Vec3>,
    /// The rigid bodies' share of `torque` (the first entries).
    rigid_bodies: usize,
    /// The members' arms R s at this step's pose, kept by the prediction for the kick.
    arms: Vec<Vec3>,
}

impl Verlet {
    /// A Verlet stepper with step `dt` (s).
    pub fn new(dt: f64) -> Verlet {
        Verlet {
            dt,
            local_damping: 0.0,
            force: Vec::new(),
            torque: Vec::new(),
            rigid_bodies: 0,
            arms: Vec::new(),
        }
    }

    /// The same stepper with local non-viscous damping of fraction `alpha` (PFC's 0.7 for
    /// quasi-static packing; 0 turns it off).
    pub fn with_local_damping(mut self, alpha: f64) -> Verlet {
        self.local_damping = alpha;
        self
    }

    /// Forces, local damping, accelerations, and with `kick` = `Some(h)` the kick v += h a
    /// (ω += h θ̈ for the particles' rotations) in the same sweep
    /// ([`verlet_sweeps::kick`]); with `zeroed`, into force sums the drift sweep zeroed.
    fn evaluate(
        &mut self,
        state: &mut State,
        models: &mut [Box<dyn Model>],
        (stages, seam): (&mut StageTimes, &mut dyn Seam),
        kick: Option<f64>,
        zeroed: bool,
    ) -> Result<(), CoreError> {
        let field = deferred_field(state, models);
        let summed = match field {
            Some(_) => models.len() - 1,
            None => models.len(),
        };
        let (force, torque) = (&mut self.force, &mut self.torque);
        match zeroed {
            true => seam.add_forces(state, &mut models[..summed], force, torque, stages),
            false => seam.sum_forces(state, &mut models[..summed], force, torque, stages),
        }
        self.rigid_bodies = state.rigid.len();
        let (rigid, moment) = self.torque.split_at_mut(self.rigid_bodies);
        if self.local_damping > 0.0 {
            for (t, w) in rigid.iter_mut().zip(&state.rigid.angular_velocity) {
                local_damping::damp(t, w, self.local_damping);
            }
        }
        let settings = KickSettings {
            h: kick,
            field,
            damping: self.local_damping,
        };
        let ranges = verlet_sweeps::cover(state.len(), seam.computed());
        let (particles, rigid_bodies) = particles(state, &mut self.force, moment);
        let (bad, bad_spin) = verlet_sweeps::kick(particles, &ranges, rigid_bodies, settings);
        hold_in_frames(state);
        let time = state.time;
        match bad.min(bad_spin) {
            usize::MAX => check_finite_torque(state, rigid),
            _ => Err(CoreError::NonFinite {
                time,
                particle: if bad != usize::MAX { bad } else { bad_spin },
            }),
        }
    }

    /// Predicts, evaluates the forces and integrates (paper 000 §2.4): the kick and the drift
    /// in one sweep with the zeroing of the force sums ([`verlet_sweeps::drift`]), the forces,
    /// then the accelerations with the second half kick.
    fn advance(
        &mut self,
        state: &mut State,
        models: &mut [Box<dyn Model>],
        stages: &mut StageTimes,
        seam: &mut dyn Seam,
    ) -> Result<(), CoreError> {
        let dt = self.dt;
        let stepped = seam.stepped();
        // After a resume the force sums are not there yet.
        self.force.resize(state.len(), Vec3::zeros());
        self.torque
            .resize(state.rigid.len() + state.spin.len(), Vec3::zeros());
        // A rank of a decomposed run sums into particles beyond those it steps: its sums are
        // zeroed whole before the forces.
        let zero = stepped.is_none();
        let ranges = verlet_sweeps::cover(state.len(), stepped);
        let bodies = state.rigid.len().min(self.torque.len());
        let (rigid, moment) = self.torque.split_at_mut(bodies);
        let (particles, _) = particles(state, &mut self.force, moment);
        verlet_sweeps::drift(particles, &ranges, dt, zero);
        state.time += dt;
        if !state.rigid.is_empty() {
            state.rigid.kick_and_rotate(rigid, dt);
            rigid.fill(Vec3::zeros());
            if !state.rigid.holds.is_empty() {
                state.hold_pose();
                state.hold_velocities();
            }
            place_members_keeping_arms(state, &mut self.arms);
        }
        stages.mark(Stage::Predict);
        self.evaluate(state, models, (stages, seam), Some(0.5 * dt), zero)?;
        self.kick_rigid(state);
        stages.mark(Stage::Integrate);
        Ok(())
    }

    /// The half kick of the rotations and the members' new velocities (the kick leaves the
    /// poses, and so the members' positions and arms, as the prediction placed them); the
    /// forces that hold bodies at points before it and the projection of their velocities
    /// after it ([`crate::step::rigid_constraints`]).
    fn kick_rigid(&mut self, state: &mut State) {
        if state.rigid.is_empty() {
            return;
        }
        let h = 0.5 * self.dt;
        let held = !state.rigid.holds.is_empty();
        if held {
            let torque = &mut self.torque[..self.rigid_bodies];
            state.hold_forces(&mut self.force, torque, Some(h));
        }
        state.rigid.kick(&self.torque, h);
        if held {
            state.hold_velocities();
        }
        place_member_velocities(state, &self.arms);
    }

    /// The force buffer of the last evaluation (N per particle).
    pub fn forces(&self) -> &[Vec3] {
        &self.force
    }
}

impl Stepper for Verlet {
    fn name(&self) -> &str {
        "verlet"
    }

    fn dt(&self) -> f64 {
        self.dt
    }

    fn initialize_in(
        &mut self,
        state: &mut State,
        models: &mut [Box<dyn Model>],
        seam: &mut dyn Seam,
    ) -> Result<(), CoreError> {
        check_masses(state)?;
        if !state.rigid.is_empty() {
            place_members(state);
        }
        self.evaluate(state, models, (&mut StageTimes::off(), seam), None, false)?;
        if !state.rigid.holds.is_empty() {
            let torque = &mut self.torque[..self.rigid_bodies];
            state.hold_forces(&mut self.force, torque, None);
            state.hold_velocities();
            place_members(state);
        }
        Ok(())
    }

    /// The torques of the last evaluation: the rigid bodies', which the next step's first
    /// half kick uses, then zeros in place of the particles' moments, which the next
    /// evaluation rewrites before anything reads them (a rank of a decomposed run holds
    /// only its own particles' moments, so writing them would make its checkpoint differ
    /// from one process's).
    fn save(&self, out: &mut Encoder) -> Result<(), CheckpointError> {
        out.tag("verlet");
        let mut torque = self.torque[..self.rigid_bodies].to_vec();
        torque.resize(self.torque.len(), Vec3::zeros());
        out.vec3s(&torque);
        Ok(())
    }

    fn resume(
        &mut self,
        state: &mut State,
        _models: &mut [Box<dyn Model>],
        input: &mut Decoder<'_>,
    ) -> Result<(), CoreError> {
        check_masses(state)?;
        input.tag("verlet")?;
        let torque = input.vec3s("torques")?;
        same_count(
            "torques",
            state.rigid.len() + state.spin.len(),
            torque.len(),
        )?;
        self.torque = torque;
        self.rigid_bodies = state.rigid.len();
        Ok(())
    }

    fn rigid_torques_mut(&mut self) -> &mut [Vec3] {
        let bodies = self.rigid_bodies.min(self.torque.len());
        &mut self.torque[..bodies]
    }

    fn forces(&self) -> &[Vec3] {
        &self.force
    }

    fn forces_mut(&mut self) -> &mut [Vec3] {
        &mut self.force
    }

    fn rigid_torques(&self) -> &[Vec3] {
        &self.torque[..self.rigid_bodies.min(self.torque.len())]
    }

    fn steps_in_part(&self) -> bool {
        true
    }

    /// One integration a step: its completion shares the new motion without an agreement
    /// (the world's failure check agrees on the step's outcome). The step holds the thread's
    /// team, if one is installed ([`team::hold`]), so that its sweeps and the models' phases
    /// cost at most one wake-up.
    fn step_timed(
        &mut self,
        state: &mut State,
        models: &mut [Box<dyn Model>],
        stages: &mut StageTimes,
        seam: &mut dyn Seam,
    ) -> Result<(), CoreError> {
        let advanced = team::hold(|| self.advance(state, models, stages, seam));
        seam.complete(state, stages, advanced, false)
    }
}

/// The uniform field of the last model ([`Model::uniform_acceleration`]), which the kick
/// sweep then adds in place of the model: its sum is the same, the field's force coming last,
/// unless rigid bodies' members add into their centres after the models.
fn deferred_field(state: &State, models: &[Box<dyn Model>]) -> Option<Vec3> {
    match models.last() {
        Some(last) if state.rigid.is_empty() => last.uniform_acceleration(),
        _ => None,
    }
}

/// The state's particles with the force sums `force` and the particles' moment sums
/// `moment` (empty when they do not rotate), for the sweeps; and the rigid bodies.
fn particles<'a>(
    state: &'a mut State,
    force: &'a mut [Vec3],
    moment: &'a mut [Vec3],
) -> (Particles<'a>, &'a RigidBodies) {
    let translation = DofArrays {
        x: &mut state.position,
        v: &mut state.velocity,
        a: &mut state.acceleration,
        load: force,
        inertia: &state.mass,
        fixed: &state.fixed,
    };
    let spin = &mut state.spin;
    let rotation = (!spin.is_empty()).then(|| DofArrays {
        x: &mut spin.angle,
        v: &mut spin.velocity,
        a: &mut spin.acceleration,
        load: moment,
        inertia: &spin.inertia,
        fixed: &spin.fixed,
    });
    let particles = Particles {
        translation,
        rotation,
    };
    (particles, &state.rigid)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::loads::Gravity;
    use crate::step::state::Dofs;

    /// A constant moment on particle 0 about z, and a constant force on it along x.
    struct Twist {
        moment: f64,
        push: f64,
    }

    impl Model for Twist {
        fn name(&self) -> &str {
            "twist"
        }

        fn add_forces(&mut self, state: &State, force: &mut [Vec3], torque: &mut [Vec3]) {
            force[0].x += self.push;
            torque[state.rigid.len()].z += self.moment;
        }
    }

    #[test]
    fn a_rotating_particle_under_a_constant_moment_turns_exactly() {
        // J = 2/5 m r² of a 1 kg sphere of radius 0.1 m; under constant M and F velocity
        // Verlet is exact: ω = M t/J, θ = M t²/(2J), v = F t/m; the second particle's
        // rotation is held.
        let mut state = State::at_rest(vec![Vec3::zeros(), Vec3::x()]);
        state.mass = vec![1.0, 1.0];
        let j = 0.4 * 0.01;
        state.let_turn(0, j);
        assert_eq!(state.spin.fixed[1], Dofs::ALL);
        let (m, f) = (2e-3, 3.0);
        let mut models: Vec<Box<dyn Model>> = vec![Box::new(Twist { moment: m, push: f })];
        let mut verlet = Verlet::new(1e-3);
        verlet.initialize(&mut state, &mut models).unwrap();
        for _ in 0..400 {
            verlet.step(&mut state, &mut models).unwrap();
        }
        let t = state.time;
        let (w, theta) = (state.spin.velocity[0], state.spin.angle[0]);
        assert!((w.z - m * t / j).abs() < 1e-12 * (m * t / j), "{w:?}");
        assert!((theta.z - m * t * t / (2.0 * j)).abs() < 1e-12, "{theta:?}");
        assert_eq!((w.x, w.y), (0.0, 0.0));
        assert!((state.velocity[0].x - f * t).abs() < 1e-12);
        assert_eq!(state.spin.velocity[1], Vec3::zeros());
        let energy = 0.5 * j * (m * t / j).powi(2) + 0.5 * (f * t).powi(2);
        assert!((state.kinetic_energy() - energy).abs() < 1e-12 * energy);
    }

    /// Springs of stiffness `k` from every particle to the origin, a damper on its rotation
    /// and two moments from each spring force (forces and moments that depend on the state,
    /// so that round-off anywhere shows up).
    struct Anchors {
        k: f64,
    }

    impl Model for Anchors {
        fn name(&self) -> &str {
            "anchors"
        }

        fn add_forces(&mut self, state: &State, force: &mut [Vec3], torque: &mut [Vec3]) {
            let bodies = state.rigid.len();
            for (i, (f, x)) in force.iter_mut().zip(&state.position).enumerate() {
                let spring = -self.k * x;
                *f += spring;
                torque[bodies + i] += x.cross(&spring) - 0.1 * state.spin.velocity[i];
            }
        }
    }

    /// 9,000 particles (more than two sweep tasks) at scattered places, moving and turning,
    /// some with fixed directions or axes, under the springs and gravity (deferred to the
    /// kick sweep when last), with local damping.
    fn scattered(gravity_last: bool) -> (State, Vec<Box<dyn Model>>) {
        let n = 9000;
        let wave = |i: usize, k: f64| (0.37 * i as f64 + k).sin();
        let points = (0..n).map(|i| Vec3::new(wave(i, 0.0), wave(i, 1.0), wave(i, 2.0)));
        let mut state = State::at_rest(points.collect());
        for i in 0..n {
            state.mass[i] = 1.0 + 0.5 * wave(i, 3.0);
            state.velocity[i] = Vec3::new(wave(i, 4.0), wave(i, 5.0), wave(i, 6.0));
            state.let_turn(i, 0.01 * state.mass[i]);
            state.spin.velocity[i] = Vec3::new(wave(i, 7.0), 0.0, wave(i, 8.0));
        }
        for i in (0..n).step_by(7) {
            state.fix(i, Dofs::parse("z").expect("an axis"));
            state.spin.fixed[i] = Dofs::parse("x").expect("an axis");
        }
        state.hold_fixed();
        let gravity: Box<dyn Model> = Box::new(Gravity::new(Vec3::new(0.0, 0.0, -9.81)));
        let anchors: Box<dyn Model> = Box::new(Anchors { k: 50.0 });
        let models = match gravity_last {
            true => vec![anchors, gravity],
            false => vec![gravity, anchors],
        };
        (state, models)
    }

    fn run(threads: usize, gravity_last: bool, steps: usize) -> (State, Vec<Vec3>) {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .expect("a pool");
        pool.install(|| {
            let (mut state, mut models) = scattered(gravity_last);
            let mut verlet = Verlet::new(1e-3).with_local_damping(0.3);
            verlet.initialize(&mut state, &mut models).expect("finite");
            for _ in 0..steps {
                verlet.step(&mut state, &mut models).expect("finite");
            }
            (state, verlet.forces().to_vec())
        })
    }

    #[test]
    fn the_sweeps_give_the_same_bits_on_any_thread_count_and_with_gravity_deferred() {
        // Two threads cut each sweep in two tasks; gravity as the last model is added by the
        // kick sweep, as the first model by its own add_forces into zeroed sums: for a sum of
        // two terms both orders give the same bits, so all four runs must agree bit for bit.
        let (one, forces) = run(1, true, 30);
        assert!(one.kinetic_energy() > 0.0 && one.kinetic_energy().is_finite());
        for (threads, last) in [(2, true), (1, false), (2, false)] {
            let (state, f) = run(threads, last, 30);
            assert!(state == one, "{threads} threads, gravity last: {last}");
            assert!(f == forces, "{threads} threads, gravity last: {last}");
        }
        // The fixed directions stayed at rest; gravity is in the force sums (the reaction
        // of a fixed direction included).
        assert_eq!(one.velocity[7].z, 0.0);
        assert_eq!(one.spin.velocity[14].x, 0.0);
        let spring = -50.0 * one.position[3];
        let free = spring + one.mass[3] * Vec3::new(0.0, 0.0, -9.81);
        assert!((forces[3] - free).norm() <= 0.3 * free.norm() + 1e-12);
    }

    #[test]
    fn the_sweeps_on_a_team_give_the_same_bits_in_one_phase_each() {
        // 9,000 particles: a team of two cuts each sweep in two tasks of TEAM_TASK or more,
        // one phase each (the drift, the kick) and no rayon region; the particles' arithmetic
        // does not depend on the cut, so the bits are those of one rayon thread.
        let (one, forces) = run(1, true, 30);
        let team = crate::step::team::Team::new(2);
        let (state, f, regions) = team.install(|| {
            let (mut state, mut models) = scattered(true);
            let mut verlet = Verlet::new(1e-3).with_local_damping(0.3);
            verlet.initialize(&mut state, &mut models).expect("finite");
            let before = crate::step::team::counts();
            for _ in 0..30 {
                verlet.step(&mut state, &mut models).expect("finite");
            }
            let after = crate::step::team::counts();
            (state, verlet.forces().to_vec(), (before, after))
        });
        assert!(state == one && f == forces);
        let (before, after) = regions;
        assert_eq!(after.phases - before.phases, 2 * 30);
        assert_eq!(after.regions - before.regions, 2 * 30);
        assert_eq!(after.holds - before.holds, 30);
    }

    /// A force that turns non-finite on one particle.
    struct Poison(usize);

    impl Model for Poison {
        fn name(&self) -> &str {
            "poison"
        }

        fn add_forces(&mut self, _state: &State, force: &mut [Vec3], _torque: &mut [Vec3]) {
            force[self.0].y = f64::NAN;
        }
    }

    #[test]
    fn a_non_finite_acceleration_names_its_particle_on_any_thread_count() {
        for threads in [1, 2] {
            let pool = rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .expect("a pool");
            let error = pool.install(|| {
                let (mut state, mut models) = scattered(true);
                models.insert(0, Box::new(Poison(8000)));
                Verlet::new(1e-3).initialize(&mut state, &mut models)
            });
            match error {
                Err(CoreError::NonFinite { particle, .. }) => assert_eq!(particle, 8000),
                other => panic!("{threads} threads: {other:?}"),
            }
        }
    }
}
