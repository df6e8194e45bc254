//! [`PeriodicWrap`]: the post-step hook of a periodic cell (paper 003 §2): after every step,
//! each body whose anchor has left the cell moves back into it whole, by whole periods
//! ([`PeriodicBox::wrap_bodies`]).

use crate::periodic_boundary::{PeriodicBox, WrapGroup};
use qdem_core::{Halt, Model, PostStep, State};

/// Wraps groups of particles (whole bodies) back into a periodic cell after every step.
#[derive(Clone, Debug)]
pub struct PeriodicWrap {
    /// The cell.
    pub cell: PeriodicBox,
    /// The groups that wrap together.
    pub groups: Vec<WrapGroup>,
}

impl PostStep for PeriodicWrap {
    fn name(&self) -> &str {
        "periodic wrap"
    }

    fn after_step(&mut self, state: &mut State, _models: &[Box<dyn Model>]) -> Option<Halt> {
        self.cell.wrap_bodies(state, &self.groups);
        None
    }
}
