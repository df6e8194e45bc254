//! Beam-bonded DEM (paper 001), in 2D: the bonded particles and their Timoshenko beam bonds,
//! the contacts of discs after breakage, the packings of a rectangle and the watch that ends a
//! run once the body has failed.

pub mod beam_bond;
pub(crate) mod bond_tangent;
pub mod bonded_particles;
pub mod collapse_watch;
pub mod particle_packing;
pub mod unbonded_contact;
