//! The candidate lists of the contact model as a part of their own: the broad phase's
//! candidate pairs and wall contacts (with their tangential springs), the spheres that are
//! partners of some candidate, where and when the lists were built (the skin check's
//! reference), the displacement bound's anchor (`displacement.rs`), and the rebuild count.

use super::displacement::Anchor;
use super::spatial_order::{permuted, SphereOrder};
use crate::dem::contact_list::ContactList;
use qdem_core::checkpoint::same_count;
use qdem_core::{checkpoint::CheckpointError, checkpoint::Decoder, checkpoint::Encoder, Vec3};

/// The candidate lists and their build.
#[derive(Default)]
pub(super) struct Candidates {
    pairs: ContactList,
    wall_contacts: ContactList,
    /// The spheres that are partners of some candidate (pair or wall contact), ascending.
    partners: Vec<u32>,
    /// Every sphere's centre at the last build.
    built_at: Vec<Vec3>,
    built_time: f64,
    built: bool,
    /// The rigid bodies' poses at the step the displacement check's bound starts from
    /// (`displacement.rs`).
    anchor: Option<Anchor>,
    rebuilds: u64,
    /// Whether the lists were rebuilt since [`Candidates::take_rebuilt`] last asked.
    rebuilt: bool,
}

impl Candidates {
    /// The candidate pairs.
    #[inline]
    pub(super) fn pairs(&self) -> &ContactList {
        &self.pairs
    }

    /// The candidate pairs, to evaluate or change.
    #[inline]
    pub(super) fn pairs_mut(&mut self) -> &mut ContactList {
        &mut self.pairs
    }

    /// The wall candidates.
    #[inline]
    pub(super) fn wall_contacts(&self) -> &ContactList {
        &self.wall_contacts
    }

    /// The wall candidates, to evaluate or change.
    #[inline]
    pub(super) fn wall_contacts_mut(&mut self) -> &mut ContactList {
        &mut self.wall_contacts
    }

    /// The spheres that are partners of some candidate, ascending.
    #[inline]
    pub(super) fn partners(&self) -> &[u32] {
        &self.partners
    }

    /// Every sphere's centre at the last build.
    #[inline]
    pub(super) fn built_at(&self) -> &[Vec3] {
        &self.built_at
    }

    /// When the lists were last built.
    #[inline]
    pub(super) fn built_time(&self) -> f64 {
        self.built_time
    }

    /// Whether the lists were built for these `spheres` spheres (at `built_at`).
    #[inline]
    pub(super) fn built_for(&self, spheres: usize) -> bool {
        self.built && self.built_at.len() == spheres
    }

    /// Number of builds of the lists.
    pub(super) fn rebuilds(&self) -> u64 {
        self.rebuilds
    }

    /// Whether the lists were rebuilt since the last call.
    pub(super) fn take_rebuilt(&mut self) -> bool {
        std::mem::take(&mut self.rebuilt)
    }

    /// The displacement bound's anchor, if any.
    #[inline]
    pub(super) fn anchor(&self) -> Option<&Anchor> {
        self.anchor.as_ref()
    }

    /// Sets (or drops) the displacement bound's anchor.
    pub(super) fn set_anchor(&mut self, anchor: Option<Anchor>) {
        self.anchor = anchor;
    }

    /// The partners of the candidates of `spheres` spheres, from the lists.
    pub(super) fn index_partners(&mut self, spheres: usize) {
        let mut touches = vec![false; spheres];
        for c in &self.pairs.items {
            touches[c.first as usize] = true;
            touches[c.second as usize] = true;
        }
        for c in &self.wall_contacts.items {
            touches[c.first as usize] = true;
        }
        self.partners = (0..touches.len() as u32)
            .filter(|&s| touches[s as usize])
            .collect();
    }

    /// After new lists: where (`center`) and when they were built, one more build, and no
    /// anchor yet.
    pub(super) fn built(&mut self, center: &[Vec3], time: f64) {
        self.anchor = None;
        self.built_at = center.to_vec();
        self.built_time = time;
        self.built = true;
        self.rebuilds += 1;
        self.rebuilt = true;
    }

    /// Saves the build (flag, time, positions, count) and the lists, the spheres by their
    /// stable ids (`order`: `spatial_order.rs`), each pair as it is oriented here.
    pub(super) fn save(
        &self,
        out: &mut Encoder,
        order: &SphereOrder,
        pair_shift: impl Fn(usize) -> Vec3,
    ) {
        out.bool(self.built);
        out.f64(self.built_time);
        let built_at: Vec<Vec3> = (0..self.built_at.len() as u32)
            .map(|id| self.built_at[order.slot(id) as usize])
            .collect();
        out.vec3s(&built_at);
        out.u64(self.rebuilds);
        self.pairs.save(out, |s| order.id(s), true, pair_shift);
        let walls = &self.wall_contacts;
        walls.save(out, |s| order.id(s), false, |k| walls.shift(k));
    }

    /// Restores what [`Candidates::save`] saved, for `spheres` spheres and `walls` walls;
    /// the partners are indexed by the caller.
    pub(super) fn restore(
        &mut self,
        input: &mut Decoder<'_>,
        spheres: usize,
        walls: usize,
    ) -> Result<(), CheckpointError> {
        self.built = input.bool("the build flag")?;
        self.built_time = input.f64("the build time")?;
        self.built_at = input.vec3s("the build positions")?;
        // The displacement bound's anchor is not kept: the next check is exact.
        self.anchor = None;
        if self.built {
            same_count("contact spheres", spheres, self.built_at.len())?;
        }
        self.rebuilds = input.u64("the rebuild count")?;
        self.pairs = ContactList::restore(input, spheres, spheres)?;
        self.wall_contacts = ContactList::restore(input, spheres, walls)?;
        Ok(())
    }

    /// Renumbers the spheres (`spatial_order.rs`): slot `s` takes the build position of slot
    /// `from[s]`, and the sphere of slot `t` in a list goes to slot `to[t]`, each pair with
    /// its lower slot first and the lists sorted again.
    pub(super) fn renumber(&mut self, from: &[u32], to: &[u32]) {
        if self.built_at.len() == from.len() {
            self.built_at = permuted(&self.built_at, from);
        }
        self.pairs.renumber(to, true);
        self.wall_contacts.renumber(to, false);
        self.partners.clear();
    }

    /// Each pair with its lower sphere first, and the lists sorted, for `spheres` spheres
    /// (after a restore: a checkpoint keeps each pair as its run numbered it).
    pub(super) fn sort_lists(&mut self, spheres: usize) {
        let same: Vec<u32> = (0..spheres as u32).collect();
        self.pairs.renumber(&same, true);
        self.wall_contacts.renumber(&same, false);
    }

    /// Marks the lists out of date: they are rebuilt at the next evaluation.
    pub(super) fn invalidate(&mut self) {
        self.built = false;
    }

    /// Lists carrying `pairs` and `wall_contacts` (their springs, not yet evaluated).
    pub(super) fn set_lists(&mut self, pairs: ContactList, wall_contacts: ContactList) {
        (self.pairs, self.wall_contacts) = (pairs, wall_contacts);
    }
}
