//! The run stage: the run loop ([`runner`]) that steps a built [`crate::build::Simulation`]'s
//! [`qdem_core::world::World`] and hands every step to one recorder per output (`record`), the
//! checkpoints of a run ([`checkpoint`], the run record's encoding in `run_record`) and the
//! fingerprints of the files a checkpoint depends on ([`inputs`]); a fresh run's removal of
//! an earlier run's outputs in its folder (`fresh_start`); the watch that stops two bodies
//! passing through each other ([`contact_watch`]); the load named as an instability's cause
//! when no step could resolve it (`load_cause`).

pub mod checkpoint;
pub mod contact_watch;
mod fresh_start;
pub mod inputs;
mod load_cause;
pub(crate) mod record;
pub(crate) mod run_record;
pub mod runner;
