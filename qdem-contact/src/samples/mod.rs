//! Sample generation, before a run: ballast-like stones as rigid clumps of spheres with a
//! grading ([`clump_sample`]), their shapes ([`clump_shape`]) and mass properties
//! ([`clump_mass`]).

pub mod clump_mass;
pub mod clump_sample;
pub mod clump_shape;
