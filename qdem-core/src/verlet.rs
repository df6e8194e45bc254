//! Explicit velocity Verlet, the integrator of paper 000 §2.4.
//!
//! v_{n+½} = v_n + ½∆t a_n; x_{n+1} = x_n + ∆t v_{n+½};
//! a_{n+1} = M⁻¹ f(t_{n+1}, x_{n+1}, v_{n+½}); v_{n+1} = v_{n+½} + ½∆t a_{n+1}.
//! Viscous forces see the half-step velocity, as in explicit FE codes, which is what the step
//! bound of [`crate::stable_step`] assumes. Fixed directions keep zero velocity.

use crate::error::CoreError;
use crate::model::Model;
use crate::state::State;
use crate::stepper::{check_masses, compute_accelerations, Stepper, PARTICLE_CHUNK};
use crate::Vec3;
use rayon::prelude::*;

/// Velocity Verlet with a fixed step.
#[derive(Clone, Debug)]
pub struct Verlet {
    dt: f64,
    force: Vec<Vec3>,
}

impl Verlet {
    /// A Verlet stepper with step `dt` (s).
    pub fn new(dt: f64) -> Verlet {
        Verlet {
            dt,
            force: Vec::new(),
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
        check_masses(state)?;
        compute_accelerations(state, models, &mut self.force)
    }

    fn step(&mut self, state: &mut State, models: &mut [Box<dyn Model>]) -> Result<(), CoreError> {
        let dt = self.dt;
        half_kick(state, dt);
        state
            .position
            .par_iter_mut()
            .zip(state.velocity.par_iter())
            .with_min_len(PARTICLE_CHUNK)
            .for_each(|(x, v)| *x += dt * v);
        state.time += dt;
        compute_accelerations(state, models, &mut self.force)?;
        half_kick(state, dt);
        Ok(())
    }
}
