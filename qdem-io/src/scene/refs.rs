//! The references between a scene's tables, resolved to indices when the scene is validated.
//!
//! A `[[fix]]`, `[[load]]` or `[[probe]]` names its body and a `[[body]]`, `[granular]`,
//! `[ballast]` or `[bonded]` names its material; validation checks that each name is defined
//! and keeps what it found here, so that building a simulation indexes instead of looking the
//! names up again (and has no "cannot happen" case for a name that is missing).
//!
//! # Why a separate struct
//!
//! The schema types are what serde reads, and what a user writes; indices in them would need
//! `#[serde(skip)]` fields that mean nothing until validation fills them, in seven types, and
//! every struct literal of those types would have to make them up. One [`Refs`] beside the
//! tables, filled by validation in one place and read by the builders, keeps the schema exactly
//! the file format and the resolved references in one place. A scene whose names are changed in
//! code after parsing is resolved again by [`Scene::validated`](super::Scene::validated).

use super::schema::CyclicLoad;

/// Indices that validation resolved from the names in a scene (module docs).
///
/// Body indices count the `[[body]]`s in file order, then the `[ballast]` or `[bonded]` body:
/// the order in which a build lays the bodies out.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Refs {
    /// Per `[[body]]`: the index of its material in [`Scene::materials`](super::Scene::materials).
    pub body_materials: Vec<usize>,
    /// Per `[[fix]]`: the index of its body.
    pub fix_bodies: Vec<usize>,
    /// Per `[[load]]`: the index of its body.
    pub load_bodies: Vec<usize>,
    /// Per `[[probe]]`: what it samples.
    pub probe_targets: Vec<ProbeTarget>,
    /// The index of the `[granular]` material.
    pub granular_material: Option<usize>,
    /// The index of the `[ballast]` material.
    pub ballast_material: Option<usize>,
    /// The index of the `[bonded]` material.
    pub bonded_material: Option<usize>,
    /// The cycle of the load `[periodic.time_delay]` follows: the first `[[load]]` with
    /// `cyclic` on its body.
    pub time_delay_cycle: Option<CyclicLoad>,
}

/// What a `[[probe]]` names in `body`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ProbeTarget {
    /// A body: its index.
    Body(usize),
    /// The `[granular]` sample.
    Granular,
}
