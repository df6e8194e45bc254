//! [`CollapseWatch`]: the post-step hook that ends a bonded run once its body has failed.
//! Linear beam bonds and small-displacement contacts (paper 001 §2) hold while every particle
//! stays within a fraction of a particle spacing of where it started; beyond, the body has
//! collapsed or come apart and its results mean nothing, so the run stops there with complete
//! outputs.

use crate::bonded::bonded_particles::BondedParticles;
use qdem_core::{step::model::find_model, step::Halt, step::Model, step::PostStep, step::State};

/// Halts a run when a particle of its [`BondedParticles`] has moved more than `limit`.
#[derive(Clone, Debug)]
pub struct CollapseWatch {
    /// The displacement (m) past which the body counts as failed.
    pub limit: f64,
}

impl CollapseWatch {
    /// A watch at `spacings` particle spacings (two radii of particle 0) of `body`.
    pub fn for_body(body: &BondedParticles, spacings: f64) -> CollapseWatch {
        CollapseWatch {
            limit: spacings * 2.0 * body.radii()[0],
        }
    }
}

impl PostStep for CollapseWatch {
    fn name(&self) -> &str {
        "collapse watch"
    }

    /// The particle that moved furthest beyond the limit, if any.
    fn after_step(&mut self, state: &mut State, models: &[Box<dyn Model>]) -> Option<Halt> {
        let body = find_model::<BondedParticles>(models)?;
        let (particle, value) = body.beyond_small_displacement(state, self.limit)?;
        Some(Halt {
            hook: self.name().to_string(),
            time: state.time,
            particle,
            value,
        })
    }
}
