//! The decomposition of a run over ranks (MPI processes, or threads in tests), behind one
//! seam: a [`crate::world::World`] owns a [`ParallelRuntime`] (single-process by default,
//! decomposed after [`crate::world::World::decompose`]) and every collective of a step runs there,
//! around the stepper's force evaluations and integrations, never inside a model.
//!
//! - [`Communicator`]: the collectives a decomposed run needs (MPI in `qdem`, threads in
//!   tests: `thread_ranks`, with the `thread-ranks` feature);
//! - [`decomposition`]: who owns what (the deformable bodies' blocks, the free particles'
//!   runs) and the figures of it per rank ([`RankFigures`]), weighing each model's items by
//!   their fixed shares or by their measured cost ([`WorkWeights`]);
//! - [`ParallelRuntime`]: what a step exchanges (the models' forces through their facets,
//!   the state after each integration, the gathers, the failure agreement, the hooks'
//!   decisions, the re-partitions), with the state share (`state_share.rs`), the particles a
//!   rank steps ([`ParticleRuns`]) and the contacts' ghost records (`ghosts.rs`); it is the
//!   steppers' [`crate::step::seam::Seam`];
//! - [`Reads`] and the [`Facets`] of a split model ([`split`]): what a model declares of a
//!   decomposed run.

pub mod communicator;
pub mod decomposition;
mod ghosts;
mod runtime;
mod state_share;
#[cfg(feature = "thread-ranks")]
pub mod thread_ranks;
mod work_weights;

pub use communicator::Communicator;
pub use decomposition::RankFigures;
pub use runtime::ParallelRuntime;
pub use work_weights::WorkWeights;
