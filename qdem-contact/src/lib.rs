//! # qdem-contact
//!
//! Contact between bodies for qdem, as in DEM: spheres at body vertices (paper 000 §4),
//! linear Voigt springs with a Coulomb slider or Hertz–Mindlin with a Mohr–Coulomb limit
//! (paper 003 §3), plane and triangulated walls, found by a deterministic cell-grid broad
//! phase. The crate is laid out by area:
//!
//! - [`dem`]: the contact engine. [`DemContacts`] is the [`qdem_core::step::Model`] that owns
//!   the spheres, walls and contact lists, and runs the stages of an evaluation (broad phase,
//!   narrow phase, law, per-sphere sums) for one process and for a rank of a decomposed run
//!   alike ([`dem::contacts`]). Beside it: the laws ([`dem::laws`]), the walls
//!   ([`dem::walls`], with the stress-controlled servo), the cell grid ([`dem::broad_phase`])
//!   and what an output reads of the contacts ([`dem::contact_view`]).
//! - [`bonded`]: beam-bonded DEM (paper 001), in 2D: [`BondedParticles`] with Timoshenko beam
//!   bonds that break, the contacts of discs after breakage, the packings of a rectangle and
//!   the bond section λ, and the [`CollapseWatch`] that ends a bonded run once its body has
//!   failed.
//! - [`boundaries`]: box-test boundaries (paper 003): periodic cells with minimum-image
//!   contacts, bodies wrapped back into the cell ([`PeriodicWrap`], a post-step hook), and the
//!   time-delayed boundary (Eqs. 2–7: ghost forces scaled by the neighbour cells' load phase).
//! - [`samples`]: pre-processing, before a run: ballast-like stones as rigid clumps of spheres
//!   with a grading, their shapes and their mass properties.
//!
//! Rigid bodies are integrated by qdem-core ([`qdem_core::step::rigid_body`]); their spheres
//! add the moment of each contact force about the sphere's centre to the body's torque.

#![warn(missing_docs)]

pub mod bonded;
pub mod boundaries;
pub mod dem;
pub mod error;
pub mod samples;

pub use bonded::beam_bond::{BeamBond, BeamSection};
pub use bonded::bonded_particles::{BondSettings, BondedMaterial, BondedParticles};
pub use bonded::collapse_watch::CollapseWatch;
pub use bonded::particle_packing::{lattice_section, LatticeSection, Packing, PackingKind};
pub use bonded::unbonded_contact::{UnbondedLaw, UnbondedPair};
pub use boundaries::periodic_boundary::{PeriodicBox, WrapGroup};
pub use boundaries::periodic_wrap::PeriodicWrap;
pub use boundaries::time_delayed_boundary::{GhostScales, LoadCycle, TimeDelayedBoundary};
pub use dem::contact_view::{Partner, SphereRecord, TouchingContact};
pub use dem::contacts::{
    impact_overlap, rayleigh_time, FLOOR_CONTACTS, FLOOR_OVERLAP, OVERLAP_MARGIN,
};
pub use dem::contacts::{CarriedSprings, ContactSettings, ContactSphere, DemContacts};
pub use dem::contacts::{SavedSpring, SavedSprings, SavedWall};
pub use dem::laws::contact_law::{ContactLaw, PairElasticity, PairGeometry};
pub use dem::laws::hertz_mindlin::HertzMindlin;
pub use dem::laws::linear_spring::LinearSpring;
pub use dem::laws::rolling_resistance::RollingResistance;
pub use dem::walls::mesh_wall::MeshWall;
pub use dem::walls::plane_wall::PlaneWall;
pub use dem::walls::servo_wall::Servo;
pub use dem::walls::wall::{Wall, WallShape};
pub use error::ContactError;
