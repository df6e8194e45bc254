//! Sample generation, before a run: ballast-like stones as rigid clumps of spheres with a
//! grading ([`clump_sample`]), their shapes ([`clump_shape`]), mass properties
//! ([`clump_mass`]) and sieve size ([`sieve`]).

pub mod clump_mass;
pub mod clump_sample;
pub mod clump_shape;
pub mod sieve;
