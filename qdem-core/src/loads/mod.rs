//! Loads: [`gravity::Gravity`], [`nodal_load::NodalLoad`] (with the pressures and tractions
//! [`surface_load`] lumps to the nodes) and the [`time_function`]s that scale them.

pub mod gravity;
pub mod nodal_load;
pub mod surface_load;
pub mod time_function;

pub use gravity::Gravity;
pub use nodal_load::NodalLoad;
pub use time_function::Cyclic;
pub use time_function::TimeFunction;
