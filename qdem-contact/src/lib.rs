//! # qdem-contact
//!
//! Contact between bodies for qdem, as in DEM: spheres at body vertices (paper 000 §4),
//! linear Voigt springs with a Coulomb slider or Hertz–Mindlin with a Mohr–Coulomb limit
//! (paper 003 §3), plane and triangulated walls, found by a deterministic cell-grid broad phase.
//!
//! - [`DemContacts`]: the [`qdem_core::step::Model`] that owns the spheres, walls and contact lists
//!   and runs broad phase → narrow phase → forces → gather each evaluation.
//! - [`broad_phase`]: the cell grid with a skin.
//! - [`contact_view`]: what an output reads of the spheres and touching contacts.
//! - [`contact_law`], [`linear_spring`], [`hertz_mindlin`], [`coulomb`]: the laws.
//! - [`plane_wall`], [`mesh_wall`], [`wall`]: the walls.
//!
//! Beam-bonded DEM (paper 001), in 2D: [`BondedParticles`] with [`beam_bond`] (Timoshenko
//! beam bonds that break), [`unbonded_contact`] (contacts of discs after breakage) and
//! [`particle_packing`] (lattices of a rectangle and the bond section λ).
//!
//! Box tests (paper 003): [`periodic_boundary`] (periodic cells, minimum-image contacts,
//! bodies wrapped whole), [`time_delayed_boundary`] (Eqs. 2–7: ghost forces scaled by the
//! neighbour cells' load phase) and [`clump_sample`] (ballast-like stones as rigid clumps with
//! a grading, shaped by [`clump_shape`]).
//!
//! Post-step hooks of a [`qdem_core::world::World`]: [`PeriodicWrap`] (bodies wrapped back into a
//! periodic cell) and [`CollapseWatch`] (a bonded run ends once its body has failed).
//!
//! Rigid bodies are integrated by qdem-core ([`qdem_core::step::rigid_body`]); their spheres add the
//! moment of each contact force about the sphere's centre to the body's torque.

#![warn(missing_docs)]

pub mod beam_bond;
mod bond_tangent;
pub mod bonded_particles;
pub mod broad_phase;
pub mod clump_mass;
pub mod clump_sample;
pub mod clump_shape;
pub mod collapse_watch;
pub mod contact_law;
mod contact_list;
pub mod contact_view;
pub mod coulomb;
pub mod dem_contacts;
pub mod error;
pub mod hertz_mindlin;
pub mod linear_spring;
pub mod mesh_wall;
pub mod particle_packing;
pub mod periodic_boundary;
pub mod periodic_wrap;
pub mod plane_wall;
pub mod servo_wall;
mod spring_blocks;
pub mod time_delayed_boundary;
pub mod unbonded_contact;
pub mod wall;

pub use beam_bond::{BeamBond, BeamSection};
pub use bonded_particles::{BondSettings, BondedMaterial, BondedParticles};
pub use collapse_watch::CollapseWatch;
pub use contact_law::{ContactLaw, PairElasticity, PairGeometry};
pub use contact_view::{Partner, SphereRecord, TouchingContact};
pub use dem_contacts::{CarriedSprings, ContactSettings, ContactSphere, DemContacts};
pub use dem_contacts::{SavedSpring, SavedSprings};
pub use error::ContactError;
pub use hertz_mindlin::HertzMindlin;
pub use linear_spring::LinearSpring;
pub use mesh_wall::MeshWall;
pub use particle_packing::{lattice_section, LatticeSection, Packing, PackingKind};
pub use periodic_boundary::{PeriodicBox, WrapGroup};
pub use periodic_wrap::PeriodicWrap;
pub use plane_wall::PlaneWall;
pub use servo_wall::Servo;
pub use time_delayed_boundary::{GhostScales, LoadCycle, TimeDelayedBoundary};
pub use unbonded_contact::{UnbondedLaw, UnbondedPair};
pub use wall::{Wall, WallShape};
