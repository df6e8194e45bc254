//! The record types an output reads of a [`DemContacts`](crate::DemContacts) between steps
//! (the queries that make them are `dem_contacts/output_queries.rs`): each contact sphere
//! where it is ([`SphereRecord`]), and each touching contact as a segment with its force
//! split into normal and tangential parts ([`TouchingContact`]).
//!
//! Both are produced serially, in sphere and contact-list order, from what the last force
//! evaluation left in the model, so reading them neither changes nor slows a step, and they
//! are the same for any number of threads.

use qdem_core::Vec3;

/// One contact sphere at the end of a step.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SphereRecord {
    /// The particle at its centre.
    pub particle: usize,
    /// Its radius (m).
    pub radius: f64,
    /// The body it belongs to (index into the body names).
    pub body: usize,
    /// Its centre (m).
    pub center: Vec3,
    /// The velocity of its centre (m/s).
    pub velocity: Vec3,
    /// The angular velocity of what carries it (its rigid body or its rotating particle);
    /// `None` for a sphere that does not turn (a vertex of a deformable body).
    pub spin: Option<Vec3>,
    /// The contact force the model applied to it at the last evaluation (N): the sum over
    /// its touching contacts, ghost scales of a time-delayed boundary included.
    pub force: Vec3,
}

/// The other partner of a touching contact.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Partner {
    /// A contact sphere (its index), after the first in the sphere order.
    Sphere(usize),
    /// A wall (its index in the model's walls).
    Wall(usize),
}

/// One touching contact at the last evaluation.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TouchingContact {
    /// The first partner, a contact sphere (its index).
    pub first: usize,
    /// The second partner.
    pub second: Partner,
    /// The first sphere's centre (m).
    pub from: Vec3,
    /// The second sphere's centre, at the periodic image the first touches; for a wall,
    /// the wall's point nearest the first sphere's centre (m).
    pub to: Vec3,
    /// Unit normal from the first partner towards the second.
    pub normal: Vec3,
    /// Normal part (f·n) n of the force on the first partner (N); the second feels its
    /// opposite.
    pub normal_force: Vec3,
    /// Tangential part f − (f·n) n of the force on the first partner (N).
    pub tangential_force: Vec3,
    /// The factor a time-delayed boundary applied to the force on the first partner, and
    /// the one on the second (both 1 for a contact not through the delayed boundary, and
    /// for a wall contact).
    pub scales: (f64, f64),
}

impl TouchingContact {
    /// The whole force on the first partner (N), before any ghost scale.
    #[must_use]
    pub fn force(&self) -> Vec3 {
        self.normal_force + self.tangential_force
    }
}
