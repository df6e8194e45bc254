//! The run stage: the run loop ([`runner`]) that steps a built [`crate::build::Simulation`]'s
//! [`qdem_core::World`] and hands every step to one recorder per output (`record`), the
//! checkpoints of a run ([`checkpoint`], the run record's encoding in `run_record`) and the
//! fingerprints of the files a checkpoint depends on ([`inputs`]).

pub mod checkpoint;
pub mod inputs;
pub(crate) mod record;
pub(crate) mod run_record;
pub mod runner;
