//! Loads: [`gravity::Gravity`], [`nodal_load::NodalLoad`] and the [`time_function`]s that
//! scale them.

pub mod gravity;
pub mod nodal_load;
pub mod time_function;
