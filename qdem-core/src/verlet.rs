//! Explicit velocity Verlet, the integrator of paper 000 §2.4.
//!
//! v_{n+½} = v_n + ½∆t a_n; x_{n+1} = x_n + ∆t v_{n+½};
//! a_{n+1} = M⁻¹ f(t_{n+1}, x_{n+1}, v_{n+½}); v_{n+1} = v_{n+½} + ½∆t a_{n+1}.
//! Viscous forces see the half-step velocity, as in explicit FE codes, which is what the step
//! bound of [`mod@crate::stable_step`] assumes. Fixed directions keep zero velocity.
//!
//! Rigid bodies ([`crate::rigid_body`]) ride along: their angular momentum gets the same two
//! half kicks from the torque and their orientation the drift, and their members are placed
//! after each. An optional local damping ([`crate::local_damping`]) acts on the summed forces
//! before they become accelerations.

use crate::checkpoint::{same_count, CheckpointError, Decoder, Encoder};
use crate::error::CoreError;
use crate::local_damping;
use crate::model::Model;
use crate::newmark::predict;
use crate::rigid_body::place_members;
use crate::stages::{Stage, StageTimes};
use crate::state::State;
use crate::stepper::{
    check_finite_torque, check_masses, refuse_spin, set_accelerations, sum_forces, Stepper,
    PARTICLE_CHUNK,
};
use crate::Vec3;
use rayon::prelude::*;

/// Velocity Verlet with a fixed step.
///
/// ```
/// use qdem_core::{Gravity, Model, State, Stepper, Vec3, Verlet};
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
/// # Ok::<(), qdem_core::CoreError>(())
/// ```
#[derive(Clone, Debug)]
pub struct Verlet {
    dt: f64,
    local_damping: f64,
    force: Vec<Vec3>,
    torque: Vec<Vec3>,
}

impl Verlet {
    /// A Verlet stepper with step `dt` (s).
    pub fn new(dt: f64) -> Verlet {
        Verlet {
            dt,
            local_damping: 0.0,
            force: Vec::new(),
            torque: Vec::new(),
        }
    }

    /// The same stepper with local non-viscous damping of fraction `alpha` (PFC's 0.7 for
    /// quasi-static packing; 0 turns it off).
    pub fn with_local_damping(mut self, alpha: f64) -> Verlet {
        self.local_damping = alpha;
        self
    }

    /// Forces, local damping, accelerations.
    fn evaluate(
        &mut self,
        state: &mut State,
        models: &mut [Box<dyn Model>],
        stages: &mut StageTimes,
    ) -> Result<(), CoreError> {
        sum_forces(state, models, &mut self.force, &mut self.torque, stages);
        if self.local_damping > 0.0 {
            local_damping::apply(state, &mut self.force, &mut self.torque, self.local_damping);
        }
        set_accelerations(state, &self.force)?;
        check_finite_torque(state, &self.torque)
    }

    /// The half kick of the rotations and the placing of the members.
    fn kick_rigid(&self, state: &mut State) {
        if !state.rigid.is_empty() {
            state.rigid.kick(&self.torque, 0.5 * self.dt);
            place_members(state);
        }
    }

    /// The force buffer of the last evaluation (N per particle).
    pub fn forces(&self) -> &[Vec3] {
        &self.force
    }
}

/// v += ½∆t a over all particles.
fn half_kick(state: &mut State, dt: f64) {
    let half = 0.5 * dt;
    state
        .velocity
        .par_iter_mut()
        .zip(state.acceleration.par_iter())
        .with_min_len(PARTICLE_CHUNK)
        .for_each(|(v, a)| *v += half * a);
}

impl Stepper for Verlet {
    fn name(&self) -> &str {
        "verlet"
    }

    fn dt(&self) -> f64 {
        self.dt
    }

    fn initialize(
        &mut self,
        state: &mut State,
        models: &mut [Box<dyn Model>],
    ) -> Result<(), CoreError> {
        refuse_spin(state, "verlet")?;
        check_masses(state)?;
        if !state.rigid.is_empty() {
            place_members(state);
        }
        self.evaluate(state, models, &mut StageTimes::off())
    }

    /// The rigid bodies' torques of the last evaluation, which the next step's first half
    /// kick uses.
    fn save(&self, out: &mut Encoder) -> Result<(), CheckpointError> {
        out.tag("verlet");
        out.vec3s(&self.torque);
        Ok(())
    }

    fn resume(
        &mut self,
        state: &mut State,
        _models: &mut [Box<dyn Model>],
        input: &mut Decoder<'_>,
    ) -> Result<(), CoreError> {
        refuse_spin(state, "verlet")?;
        check_masses(state)?;
        input.tag("verlet")?;
        let torque = input.vec3s("rigid-body torques")?;
        same_count("rigid-body torques", state.rigid.len(), torque.len())?;
        self.torque = torque;
        Ok(())
    }

    fn step_timed(
        &mut self,
        state: &mut State,
        models: &mut [Box<dyn Model>],
        stages: &mut StageTimes,
    ) -> Result<(), CoreError> {
        let dt = self.dt;
        // The kick and the drift in one pass: Newmark's predictor with β = 0, γ = ½ is
        // x += ∆t (v + ½∆t a), v += ½∆t a, bit for bit.
        predict(state, dt, 0.0, 0.5);
        if !state.rigid.is_empty() {
            state.rigid.kick_and_rotate(&self.torque, dt);
            place_members(state);
        }
        stages.mark(Stage::Predict);
        self.evaluate(state, models, stages)?;
        half_kick(state, dt);
        self.kick_rigid(state);
        stages.mark(Stage::Integrate);
        Ok(())
    }
}
